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
import time
from pathlib import Path

from .errors import InputError, VfemError
from .examples import EXAMPLES

log = logging.getLogger("vfem")


def _params_class(name: str):
    if name == "springs":
        from .examples.springs import SpringsParameters

        return SpringsParameters
    from .examples.hertz import HertzParameters

    return HertzParameters


def _parse_value(text: str, current, key: str, cls):
    """Turn ``text`` into the type of the parameter (no eval)."""
    t = text.strip()
    if t.lower() in ("none", "null", "default"):
        return None
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
    cls = _params_class(example)
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
    params = build_parameters(args.example, args.set or [])
    out = Path(args.out or Path("results") / args.example)
    start = time.perf_counter()
    if args.example == "springs":
        from .examples.springs import run

        summary = run(params, out)
        if not args.quiet:
            _print_springs(summary)
    else:
        from .examples.hertz import build, run

        build(params).validate()

        def progress(step):
            if not args.quiet:
                h = step.history[-1]
                print(f"  step {step.step:3d}  load factor {step.load_factor:7.4f}  "
                      f"{step.iterations:3d} iterations  penetration {h.max_penetration:.2e}  "
                      f"equilibrium error {h.max_equilibrium_error:.2e}", flush=True)

        if not args.quiet:
            print(f"vfem: hertz, {params.steps} steps, results in {out}/", flush=True)
        summary = run(params, out, on_step=progress)
        if not args.quiet:
            _print_hertz(summary, out, time.perf_counter() - start)
    if not summary["converged"]:
        print(f"vfem: the analysis did not converge: {summary.get('message', '')}",
              file=sys.stderr)
        return 1
    return 0


def _print_springs(s: dict) -> None:
    print("vfem: springs — thesis §4.2.1, two nonlinear springs pressed end to end")
    for step, trace, x, f, gap in zip(s["steps"], s["trace"], s["contact_point"],
                                      s["contact_force"], s["gap"]):
        if x is None:
            print(f"step {step['step']}: no contact, gap {gap:.4f} in")
            continue
        print(f"step {step['step']}: contact point {x:.4f} in, contact force {f:.2f} lb, "
              f"{step['iterations']} iterations")
        for k, it in enumerate(trace, 1):
            print(f"    iteration {k}: penetration {it['penetration']:+.4f} in, "
                  f"compatibility force {it['compatibility_force']:7.2f} lb, "
                  f"equilibrium error {it['equilibrium_error']:+8.2f} lb "
                  f"(A needs {it['reaction_a']:.1f}, B gives {it['reaction_b']:.1f}), "
                  f"equilibrium corrections A {it['equilibrium_force_a']:+.2f} lb, "
                  f"B {it['equilibrium_force_b']:+.2f} lb")


def _print_hertz(s: dict, out: Path, elapsed: float) -> None:
    print(f"vfem: {'converged' if s['converged'] else 'NOT converged'} in {len(s['steps'])} "
          f"steps, {sum(x['iterations'] for x in s['steps'])} contact iterations, "
          f"{s['dofs']} dofs, {elapsed:.1f} s")
    if "hertz" in s:
        h = s["hertz"]
        print(f"  p_max {h['p_max']:.1f} (theory {h['p0_theory']:.1f}, {h['p_max_error']:+.3%})"
              f"   half-width {h['a_estimate']:.5f} (theory {h['a_theory']:.5f})")
        print(f"  RMS error over |x| < a: {h['rms_error_over_p0']:.3%} of p0   "
              f"contact force {h['total_contact_force']:.2f} (applied {h['applied_force']:g})")
    fixed = [x for x in s["steps"] if x.get("stopped_at_fixed_point")]
    if fixed:
        worst = max(fixed, key=lambda x: x["max_penetration"])
        print(f"  note: {len(fixed)} of {len(s['steps'])} steps stopped where the compatibility "
              f"and equilibrium corrections cancel (largest residual penetration "
              f"{worst['max_penetration']:.2e}); see docs/method.md §5")
    print(f"  results: {out}/summary.json, results.pvd (ParaView), pressure.png, deformed.png")


def cmd_bench(args) -> int:
    from .bench import hertz_benchmark

    if args.example != "hertz":
        raise InputError(f"no benchmark for {args.example!r}; available: hertz")
    rows = hertz_benchmark(args.levels, print_row=print)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2) + "\n", encoding="utf-8")
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
    args = parser.parse_args(argv)

    level = (logging.WARNING if args.verbose == 0 else
             logging.INFO if args.verbose == 1 else logging.DEBUG)
    logging.basicConfig(level=logging.ERROR if args.quiet else level,
                        format="%(levelname)s %(name)s: %(message)s")
    logging.getLogger("skfem").setLevel(max(logging.WARNING, level))
    try:
        return cmd_run(args) if args.command == "run" else cmd_bench(args)
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
