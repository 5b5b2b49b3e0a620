"""The ``vfem`` command: run the built-in examples, benchmark them.

Exit status: 0 success; 1 the analysis did not converge (results of converged steps are kept);
2 bad input (one message naming the problem, no traceback).
"""

from __future__ import annotations

import argparse
import dataclasses
import difflib
import json
import logging
import sys
from pathlib import Path

from .errors import InputError, VfemError
from .examples import EXAMPLES, load

log = logging.getLogger("vfem")


def _parse_value(text: str, current, key: str, cls):
    """Turn ``text`` into the type of the parameter (no eval)."""
    t = text.strip()
    if t.lower() in ("none", "null", "default"):
        return None
    if isinstance(current, str):
        return t  # checked where it is used (e.g. contact.variant names its choices)
    if isinstance(current, bool):
        if t.lower() in ("true", "yes", "1"):
            return True
        if t.lower() in ("false", "no", "0"):
            return False
        raise InputError(f"--set {key}: expected true or false, got {text!r}")
    try:
        return int(t) if isinstance(current, int) else float(t)
    except ValueError:
        raise InputError(f"--set {key}: expected a number, got {text!r}") from None


def build_parameters(example: str, assignments: list[str]):
    """The example's parameters with ``key=value`` overrides applied."""
    cls = load(example).Parameters
    params = cls()
    names = [f.name for f in dataclasses.fields(cls)]
    changes = {}
    for item in assignments:
        if "=" not in item:
            raise InputError(f"--set expects key=value, got {item!r}")
        key, value = (s.strip() for s in item.split("=", 1))
        if key not in names:
            close = difflib.get_close_matches(key, names, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f"; valid keys: {', '.join(names)}"
            raise InputError(f"--set: {example} has no parameter {key!r}{hint}")
        current = getattr(params, key)
        if current is None:
            current = 0.0
        changes[key] = _parse_value(value, current, key, cls)
    return dataclasses.replace(params, **changes)


def cmd_run(args) -> int:
    if args.example not in EXAMPLES:
        close = difflib.get_close_matches(args.example, EXAMPLES, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise InputError(f"unknown example {args.example!r}{hint}; "
                         f"available: {', '.join(EXAMPLES)}")
    example = load(args.example)
    params = build_parameters(args.example, args.set or [])
    if hasattr(example, "validate"):
        example.validate(params)  # bad input is reported before anything is written
    out = Path(args.out or Path("results") / args.example)

    def progress(step):
        if not args.quiet:
            h = step.history[-1]
            print(f"  step {step.step:3d}  load factor {step.load_factor:7.4f}  "
                  f"{step.iterations:3d} iterations  penetration {h.max_penetration:.2e}  "
                  f"equilibrium error {h.max_equilibrium_error:.2e}", flush=True)

    if not args.quiet and args.example == "hertz":
        print(f"vfem: hertz, {params.steps} steps, results in {out}/", flush=True)
    summary = example.run(params, out, on_step=progress)
    if not args.quiet:
        print("\n".join(example.report(summary)))
    if not summary["converged"]:
        print(f"vfem: the analysis did not converge: {summary.get('message', '')}",
              file=sys.stderr)
        return 1
    return 0


def cmd_bench(args) -> int:
    from .bench import hertz_benchmark

    if args.example != "hertz":
        raise InputError(f"no benchmark for {args.example!r}; available: hertz")
    rows = hertz_benchmark(args.levels, print_row=print, variant=args.variant)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2) + "\n", encoding="utf-8")
    return 0


def cmd_study(args) -> int:
    from .bench import hertz_benchmark
    from .io.plots import convergence

    if args.example != "hertz":
        raise InputError(f"no study for {args.example!r}; available: hertz")
    out = Path(args.out or Path("results") / "hertz_study")
    out.mkdir(parents=True, exist_ok=True)
    series = {}
    for name, variant, order, levels in (
            ("linear, paired", "paired", 1, args.levels),
            ("linear, thesis", "thesis", 1, args.levels),
            ("quadratic, paired", "paired", 2, args.quadratic_levels)):
        if not args.quiet:
            print(f"vfem: hertz refinement study, {name}")
        series[name] = hertz_benchmark(levels, print_row=None if args.quiet else print,
                                       variant=variant, order=order)
    (out / "study.json").write_text(json.dumps(series, indent=2) + "\n", encoding="utf-8")
    convergence(out / "convergence.png", series,
                "Hertz (thesis §5.2) under refinement: error against Hertz's theory")
    if not args.quiet:
        print(f"vfem: wrote {out}/study.json and {out}/convergence.png")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="vfem", description=(
        "Contact between deformable bodies by the virtual finite element method."))
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="log more (-v: info, -vv: debug)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print only errors")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a built-in example")
    run.add_argument("example", help=f"one of: {', '.join(EXAMPLES)}")
    run.add_argument("--out", help="results directory (default results/<example>)")
    run.add_argument("--set", action="append", metavar="KEY=VALUE",
                     help="change a parameter of the example (repeatable)")
    bench = sub.add_parser("bench", help="time an example at several refinements")
    bench.add_argument("example", help="hertz")
    bench.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    bench.add_argument("--json", help="also write the table to this JSON file")
    bench.add_argument("--variant", default="paired", choices=("paired", "thesis"),
                       help="contact variant (default paired)")
    study = sub.add_parser("study", help="an example under refinement, both variants, plotted")
    study.add_argument("example", help="hertz")
    study.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2, 3, 4],
                       help="refinement levels with linear elements")
    study.add_argument("--quadratic-levels", type=int, nargs="+", default=[0, 1, 2, 3],
                       help="refinement levels with quadratic elements")
    study.add_argument("--out", help="results directory (default results/hertz_study)")
    args = parser.parse_args(argv)

    level = (logging.WARNING if args.verbose == 0 else
             logging.INFO if args.verbose == 1 else logging.DEBUG)
    logging.basicConfig(level=logging.ERROR if args.quiet else level,
                        format="%(levelname)s %(name)s: %(message)s")
    logging.getLogger("skfem").setLevel(max(logging.WARNING, level))
    try:
        command = {"run": cmd_run, "bench": cmd_bench, "study": cmd_study}[args.command]
        return command(args)
    except InputError as exc:
        print(f"vfem: error: {exc}", file=sys.stderr)
        return 2
    except VfemError as exc:
        print(f"vfem: analysis failed: {exc}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into a pager or head that closed early
        return 0
    except KeyboardInterrupt:
        print("vfem: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
