"""The ``vfem`` command: run built-in examples and input files, check and export input files,
redraw figures, benchmark.

Exit status: 0 success; 1 the analysis did not converge (results of converged steps are kept);
2 bad input (one message naming the problem, no traceback).
"""

from __future__ import annotations

import argparse
import dataclasses
import difflib
import inspect
import json
import logging
import os
import shlex
import shutil
import signal
import sys
import textwrap
from pathlib import Path

from . import linalg, parallel, threads
from .contact.settings import ContactSettings
from .errors import InputError, VfemError
from .examples import EXAMPLES, load
from .io.folders import ResultsFolder, default_folder, run_description
from .schema import NOT_YET

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


CONTACT_KEYS = {f.name for f in dataclasses.fields(ContactSettings)}


def build_parameters(example: str, assignments: list[str]):
    """The example's parameters with ``key=value`` overrides applied. ``contact.KEY`` is
    accepted for the example's parameters that are contact settings (``contact.method``)."""
    cls = load(example).Parameters
    params = cls()
    names = [f.name for f in dataclasses.fields(cls)]
    changes = {}
    for item in assignments:
        if "=" not in item:
            raise InputError(f"--set expects key=value, got {item!r}")
        key, value = (s.strip() for s in item.split("=", 1))
        if key.startswith("contact.") and key[len("contact."):] in names and \
                key[len("contact."):] in CONTACT_KEYS:
            key = key[len("contact."):]  # the example's parameter that is this contact setting
        if key not in names and key.split(".")[-1] in NOT_YET:
            raise InputError(f"--set {key}: not a parameter of {example}: "
                             f"{NOT_YET[key.split('.')[-1]]}")
        if key not in names:
            close = difflib.get_close_matches(key, names, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f"; valid keys: {', '.join(names)}"
            raise InputError(f"--set: {example} has no parameter {key!r}{hint}")
        current = getattr(params, key)
        if current is None:
            current = 0.0
        changes[key] = _parse_value(value, current, key, cls)
    return dataclasses.replace(params, **changes)


class Progress:
    """A progress bar over the steps (redrawn in place on a terminal, a line per step
    otherwise): load factor, the step's contact iterations and its final errors."""

    def __init__(self, load_factors=None, enabled: bool = True, stream=None):
        self.factors = list(load_factors or [])
        self.total = len(self.factors)
        self.enabled = enabled
        self.stream = stream or sys.stdout
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.done = 0  # scheduled steps completed (a cut step completes only at its target)
        self.steps_seen = 0  # converged steps, cut ones included
        self.label = ""  # the case under way, in a run of several (wedge): "case 3: "
        self.after_step = None  # called after each converged step (the results folder's record)

    def start_case(self, name: str) -> None:
        """A run of several analyses (the wedge's cases) starts the next one, ``name``: its
        progress lines are prefixed with it and count its steps from the start."""
        if self.enabled and self.tty and self.steps_seen:
            self.stream.write("\n")
        self.label = f"{name}: "
        self.done = self.steps_seen = 0

    def __call__(self, step) -> None:
        if self.after_step is not None:
            self.after_step()
        if not self.enabled:
            return
        self.steps_seen += 1
        if self.done < self.total and step.load_factor == self.factors[self.done]:
            self.done += 1
        h = step.history[-1] if step.history else None
        pen = h.max_penetration if h else 0.0
        eq = h.max_equilibrium_error if h else 0.0
        text = (f"step {step.step:3d}  load factor {step.load_factor:7.4f}  "
                f"{step.iterations:3d} iterations  penetration {pen:.2e}  "
                f"equilibrium error {eq:.2e}" + (f"  ({step.cuts} cuts)" if step.cuts else ""))
        if self.total:
            width = 20
            part = 0.0  # how far a cut step has come towards its scheduled target
            if self.done < self.total:
                prev = self.factors[self.done - 1] if self.done else 0.0
                part = min(1.0, max(0.0, (step.load_factor - prev)
                                    / (self.factors[self.done] - prev)))
            filled = round(width * (self.done + part) / self.total)
            text = f"[{'#' * filled}{'.' * (width - filled)}] {text}"
        text = self.label + text
        if self.tty:
            self.stream.write("\r\033[K  " + text)
            self.stream.flush()
        else:
            print("  " + text, file=self.stream, flush=True)

    def iteration(self, record) -> None:
        """On a terminal, the contact iteration under way and its errors (Analysis.run)."""
        if not (self.enabled and self.tty):
            return
        self.stream.write(f"\r\033[K  {self.label}step {self.steps_seen + 1:3d}  iteration "
                          f"{record.iteration:3d}  penetration {record.max_penetration:.2e}  "
                          f"equilibrium error {record.max_equilibrium_error:.2e}")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled and self.tty:
            self.stream.write("\n")
            self.stream.flush()


def _is_input_file(target: str) -> bool:
    return target.endswith(".toml") or Path(target).is_file()


def _load_input(path: str, assignments: list[str] = ()):
    from .io.input import load as load_input

    return load_input(path, assignments)


def _example(name: str, alternatives: str = ""):
    """The module of a built-in example; an unknown name is refused with the closest one."""
    if not name.strip():
        raise InputError("no model given: name a built-in example "
                         f"({', '.join(EXAMPLES)}) or an input file (.toml)")
    if name not in EXAMPLES and Path(name).is_dir():
        raise InputError(f"{name} is a folder: give an input file (.toml) or a built-in example "
                         f"({', '.join(EXAMPLES)}); to redraw a results folder's figures: "
                         f"vfem plot {name}")
    if name not in EXAMPLES:
        close = difflib.get_close_matches(name, EXAMPLES, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise InputError(f"unknown example {name!r}{hint}; available: {', '.join(EXAMPLES)}"
                         + alternatives)
    return load(name)


SOLVER_HELP = ("linear-algebra backend: auto (the fastest installed), superlu, pardiso, cholmod "
               "or mumps (docs/benchmarks.md)")


def cmd_run(args) -> int:
    from .io.replot import defer

    # for this run only: main() may run several in one process, and a library call after it
    # (an example's run()) must draw its figures again (a test that ran `vfem run
    # --no-figures` in the same process left them deferred)
    defer(args.no_figures)
    try:
        return _cmd_run(args)
    finally:
        defer(False)


def _cmd_run(args) -> int:
    chosen = linalg.use(args.solver)
    log.info("linear solver %s -> %s", args.solver, chosen)
    if _is_input_file(args.example):
        return run_input_file(args)
    example = _example(args.example, ", or an input file (.toml)")
    params = build_parameters(args.example, args.set or [])
    if hasattr(example, "validate"):
        example.validate(params)  # bad input is reported before anything is written
    out = _results_directory(args, default_folder(args.example, args.set or []))
    resume = {}
    if args.resume:
        if "resume" not in inspect.signature(example.run).parameters:
            raise InputError(f"--resume: the {args.example} example runs in one go and cannot "
                             "be resumed; run it again")
        resume = {"resume": True}
    if not args.quiet:
        print(f"vfem: {args.example}, results in {out}/", flush=True)
    progress = Progress(None, not args.quiet)
    return _solve_and_report(lambda: example.run(params, out, on_step=progress, **resume),
                             progress, lambda summary: _with_invariants(
                                 example.report(summary), summary), args.quiet, args, out)


def _with_invariants(lines: list[str], summary: dict) -> list[str]:
    """A built-in example's closing lines, then each body's contact force and support
    reactions and how they balance (:func:`vfem.io.runner.reaction_lines`) and the invariants
    line of its steps (:func:`vfem.io.runner.invariants_line`); the results line, made from the
    folder's record, comes after them (:func:`_results_line`)."""
    from .io.runner import invariants_line, reaction_lines

    steps = summary.get("steps") or []
    return [*lines, *("  " + x for x in (*reaction_lines(steps), invariants_line(steps)) if x)]


def _writable_folder(out: Path, what: str) -> None:
    """Refuse, before anything is solved, an output folder that is a file or cannot be made or
    written (one message naming the path; the run would otherwise fail after its first step)."""
    if out.exists() and not out.is_dir():
        raise InputError(f"{what} {out}: a file, not a folder; name a folder for the results")
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".vfem-write-test-{os.getpid()}"  # several processes (MPI ranks)
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise InputError(f"{what} {out}: cannot write there ({exc.strerror or exc})") from None


def _results_directory(args, default: Path) -> Path:
    """Where a run writes: ``--resume DIR`` (which must hold an earlier run), else ``--out``,
    else ``default``; made ready for the run (:class:`vfem.io.folders.ResultsFolder`: an
    earlier run's files cleared, another model's refused without ``--overwrite``)."""
    out = _results_location(args, default)
    out = parallel.scratch_folder(out, bool(args.resume))  # rank 0's alone under MPI
    target = args.example if not _is_input_file(args.example) else str(
        Path(args.example).resolve())
    args.folder = ResultsFolder(out, run_description(args.command_line, target, args.set or []))
    args.folder.prepare(overwrite=args.overwrite, resume=bool(args.resume))
    return out


def _results_location(args, default: Path) -> Path:
    if args.out is not None and not args.out.strip():
        raise InputError("--out: an empty name; name a folder for the results")
    if not args.resume:
        out = Path(args.out or default)
        _writable_folder(out, "--out" if args.out else "the results folder")
        return out
    if args.out and Path(args.out) != Path(args.resume):
        raise InputError("--resume continues in its own results directory; leave out --out")
    if not any(Path(args.resume).glob("**/checkpoint")):
        raise InputError(f"--resume {args.resume}: no checkpoints there (a results directory "
                         "written by vfem run holds a checkpoint folder)")
    return Path(args.resume)


def _solve_and_report(solve, progress: Progress, report, quiet: bool, args, out: Path) -> int:
    """Run ``solve()`` (-> summary) under the progress display, print ``report(summary)``;
    exit status 1 if the analysis did not converge. Interrupted (Ctrl-C, SIGTERM): say where
    the completed steps are and how to continue, exit status 130."""
    folder = args.folder
    progress.after_step = folder.update
    refused = False  # bad input found before solving (a --resume of another model): no trace
    try:
        summary = solve()
    except KeyboardInterrupt:
        summary = None
    except InputError:
        refused = True
        raise
    finally:
        progress.close()
        if not refused:
            folder.update()
            folder.stamp_summary()
    if summary is None:
        sets = "".join(f" --set {shlex.quote(a)}" for a in (args.set or []))
        if any(out.glob("**/checkpoint/step*.npz")):
            print(f"vfem: interrupted; the steps completed are in {out}/. Continue with: vfem "
                  f"run {args.example}{sets} --resume {out}", file=sys.stderr)
        else:
            print(f"vfem: interrupted before the first step was completed: nothing to resume; "
                  f"run it again: vfem run {args.example}{sets}"
                  + (f" --out {shlex.quote(str(out))}" if args.out else ""), file=sys.stderr)
        return 130
    summary["run"] = folder.run
    if not quiet:
        print("\n".join(_results_line(report(summary), out)))
        if summary.get("figures_not_drawn"):  # no matplotlib, or --no-figures (draw_run)
            print(f"vfem: figures not drawn: {summary['figures_not_drawn']}", file=sys.stderr)
    if not summary["converged"]:
        print(f"vfem: the analysis did not converge: "
              f"{summary.get('message') or 'see summary.json for each case'}",
              file=sys.stderr)
        return 1
    return 0


#: What the closing screen says of a results folder's files, in this order (those present).
_RESULT_FILES = (("summary.json", ""), ("results.pvd", " for ParaView"), ("contact.csv", ""),
                 ("reactions.csv", ""))


def _results_line(lines: list[str], out: Path) -> list[str]:
    """The report and its ``results:`` line, made from the files this run wrote in ``out``
    (its record, :mod:`vfem.io.folders`): never a file it did not write (a run that stopped
    early has no figures; another run's sub-folder is not this one's)."""
    from .io.folders import read_record

    record = read_record(out) or {}
    owned = set(record.get("files") or [])
    names = [n + note for n, note in _RESULT_FILES if n in owned]
    names += sorted(n for n in owned if "/" not in n and n.endswith(".png"))
    cases = sorted({n.split("/")[0] + "/" for n in owned if "/" in n
                    and not n.startswith("checkpoint/")})
    return [*lines, f"  results: {out}/ (" + ", ".join(names + cases) + ")"]


def _checked_model(path: str, assignments: list[str] = ()):
    """The input file's description and its model, every check done (nothing solved);
    ``assignments``: ``--set KEY=VALUE`` changes to the file's keys (checked like the file)."""
    from .config import check

    config = _load_input(path, assignments)
    try:
        return config, check(config, Path(path).parent)
    except InputError as exc:
        changes = " with --set " + " --set ".join(assignments) if assignments else ""
        raise InputError(f"{path}{changes}: {exc}") from None


def run_input_file(args) -> int:
    from .io import runner

    # bad input (the --set changes included) reported before anything is written
    config, model = _checked_model(args.example, args.set or [])
    out = _results_directory(args, Path(config.output.directory) if config.output.directory
                             else default_folder(config.name, args.set or []))
    factors = config.steps.factors()
    if not args.quiet:
        print(f"vfem: {config.name} ({args.example}), {len(factors)} "
              f"step{'s' if len(factors) > 1 else ''}, results in {out}/", flush=True)
    progress = Progress(factors, not args.quiet)
    return _solve_and_report(
        lambda: runner.run(config, out, model=model, on_step=progress, source=args.example,
                           resume=bool(args.resume)),
        progress, lambda summary: runner.report(summary, out), args.quiet, args, out)


def cmd_check(args) -> int:
    config, model = _checked_model(args.file, args.set or [])
    if not args.quiet:
        n, steps = len(model.bodies), len(model.load_factors)
        print(f"vfem: {args.file}: model {config.name!r} is valid — "
              f"{n} {'body' if n == 1 else 'bodies'} ("
              + ", ".join(f"{b.name}: {b.npoints} nodes" for b in model.bodies)
              + f"), {steps} {'step' if steps == 1 else 'steps'}"
              + ("; with one body there is no contact to solve" if n == 1 else ""))
    return 0


def example_configs(name: str, assignments: list[str]) -> dict:
    """The built-in example's model(s) as configurations, by key."""
    example = _example(name)
    params = build_parameters(name, assignments)
    if hasattr(example, "validate"):
        example.validate(params)  # what run would refuse is not exported either
    if hasattr(example, "configs"):
        return example.configs(params)
    if hasattr(example, "config"):
        return {name: example.config(params)}
    raise InputError(f"the {name} example is the 1D analogy of the method (two springs), not a "
                     "model of bodies: it has no input file")


def export_header(example: str, assignments: list[str]) -> str:
    """The comment lines at the top of a file ``vfem export`` writes: the example, its title
    (the first paragraph of its module's docstring, whole), the command that wrote it and the
    one that solves it. Plain text, as a TOML comment is read: no Markdown (the backticks
    around the commands read as part of them, and ended before the ``--set`` options)."""
    doc = (load(example).__doc__ or example).strip()
    title = " ".join(doc.split("\n\n")[0].split()).replace("``", "")
    sets = "".join(f" --set {shlex.quote(a)}" for a in assignments)
    return "\n".join([f"vfem input file: the built-in example '{example}'.",
                      *textwrap.wrap(title, 96),
                      f"Written by: vfem export {example}{sets}",
                      f"vfem run <this file> solves the same model as: vfem run {example}{sets}",
                      "Keys: docs/input.md."])


def cmd_export(args) -> int:
    from .io.input import dumps

    configs = example_configs(args.example, args.set or [])
    header = export_header(args.example, args.set or [])
    if len(configs) == 1 and not args.out:
        print(dumps(next(iter(configs.values())), header), end="")
        return 0
    if not args.out:
        raise InputError(f"the {args.example} example has {len(configs)} models; give --out "
                         "DIR to write one file each")
    out = Path(args.out)
    if len(configs) == 1:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(dumps(next(iter(configs.values())), header), encoding="utf-8")
        written = [out]
    else:
        out.mkdir(parents=True, exist_ok=True)
        written = []
        for key, config in configs.items():
            path = out / f"{key}.toml"
            path.write_text(dumps(config, header + f"\nThis file: {config.name}."),
                            encoding="utf-8")
            written.append(path)
    if not args.quiet:
        print(f"vfem: wrote {', '.join(str(p) for p in written)}")
    return 0


def cmd_reference(args) -> int:
    from .io.input import reference

    print(reference(), end="")
    return 0


def cmd_plot(args) -> int:
    from .io.replot import plot_results, unfinished_example

    why = unfinished_example(Path(args.results))  # an example's own figures cannot be drawn
    if why and not args.quiet:
        print(f"vfem: {why}", file=sys.stderr)
    written = plot_results(Path(args.results))
    if not args.quiet:
        print(f"vfem: wrote {', '.join(str(p) for p in written)}" if written else
              f"vfem: {args.results}: no figures to draw (its run drew none)")
    return 0


def _bench_sphere(args) -> int:
    """``vfem bench sphere``: the sphere example at each size, each case in its own process
    (its peak memory its own): dofs, contact dofs, time, ratio to a plain linear solve of the
    same bodies with the same backend, iterations, p_max error, peak memory; with
    ``--calculix``, CalculiX on the same mesh right after vfem's case (its time, increments,
    iterations and p_max error beside vfem's)."""
    from .tools import bench

    for option in ("patch", "whole_run", "plot"):
        if getattr(args, option):
            raise InputError(f"vfem bench sphere: --{option.replace('_', '-')} is for hertz only")
    if args.methods != ["vfem"] or args.variant != "paired":
        raise InputError("vfem bench sphere: the paired vfem method only (3D contact)")
    if args.calculix and shutil.which("ccx") is None:
        raise InputError("--calculix: ccx is not installed (Debian: apt install calculix-ccx)")
    solvers = args.solver or ["auto"]
    backends = linalg.available() if "all" in solvers else [linalg.resolve(s) for s in solvers]
    sizes = ([{"level": level} for level in args.levels] if args.levels
             else [{"dofs": bench.parse_size(d)} for d in (args.dofs or ["30k", "300k"])])
    say = None if args.quiet else print
    if say:
        say(bench.SPHERE_HEADER)
    rows, ccx_rows = [], []
    for size in sizes:
        for backend in backends:
            row = (bench._case("sphere", {**size, "backend": backend}) if args.in_process
                   else bench.run_isolated("sphere", **size, backend=backend))
            rows.append(row)
            if say:
                say(bench.format_sphere_row(row))
        if args.calculix:  # right after vfem on the same mesh (its first backend's row)
            ccx_rows.append(bench.sphere_calculix_row(
                size, rows[-len(backends)], threads=args.ccx_threads,
                timeout=args.ccx_timeout))
            if say:
                say(bench.SPHERE_CALCULIX_HEADER)
                say(bench.format_sphere_calculix_row(ccx_rows[-1]))
    if args.json:
        keep = {"sphere": rows, "calculix": ccx_rows} if args.calculix else rows
        Path(args.json).write_text(json.dumps(keep, indent=2) + "\n", encoding="utf-8")
    if args.markdown:
        text = bench.sphere_markdown(rows)
        if ccx_rows:
            text += "\n" + bench.sphere_calculix_markdown(ccx_rows)
        Path(args.markdown).write_text(text, encoding="utf-8")
    return 0


def cmd_bench(args) -> int:
    from .tools import bench

    if args.example not in ("hertz", "sphere"):
        raise InputError(f"no benchmark for {args.example!r}; available: hertz, sphere")
    if args.example == "sphere":
        return _bench_sphere(args)
    if args.plot:
        from .io.plots import require_matplotlib

        require_matplotlib()  # before the benchmark, not after it
    solvers = args.solver or ["auto"]
    backends = linalg.available() if "all" in solvers else [linalg.resolve(s) for s in solvers]
    if args.levels:
        sizes = [{"level": level} for level in args.levels]
    else:
        sizes = [{"dofs": bench.parse_size(d)} for d in (args.dofs or ["10k", "100k"])]
    say = None if args.quiet else print
    if args.whole_run:
        rows = []
        if say:
            say(bench.WHOLE_RUN_HEADER)
        for size in sizes:
            for backend in backends:
                rows.append(bench.run_isolated("run", **size, backend=backend))
                if say:
                    say(bench.format_whole_run(rows[-1]))
        if args.json:
            Path(args.json).write_text(json.dumps(rows, indent=2) + "\n", encoding="utf-8")
        return 0
    rows = bench.speed_benchmark(sizes, backends, args.methods, variant=args.variant,
                                 isolate=not args.in_process, print_row=say)
    table = {"hertz": rows}
    if args.patch:
        if say:
            say(f"{'method':>10} {'patch error':>12} {'iterations':>10}")
        table["patch"] = []
        for method in args.methods:
            row = bench.run_isolated("patch", method=method, backend=backends[0])
            table["patch"].append(row)
            if say:
                say(f"{method:>10} {row['patch_error']:>12.2e} {row['patch_iterations']:>10}")
    if args.calculix:
        if shutil.which("ccx") is None:
            raise InputError("--calculix: ccx is not installed (Debian: apt install "
                             "calculix-ccx)")
        table["calculix"] = bench.calculix_rows(sizes, print_row=say, backend=backends[0],
                                                threads=args.ccx_threads,
                                                timeout=args.ccx_timeout)
    if args.markdown:
        Path(args.markdown).write_text(bench.markdown(table), encoding="utf-8")
    if args.json:
        keep = table if (args.patch or args.calculix) else rows
        Path(args.json).write_text(json.dumps(keep, indent=2) + "\n", encoding="utf-8")
    if args.plot:
        from .io.plots import benchmark_times

        benchmark_times(Path(args.plot), rows, "Hertz: time against dofs")
    return 0


def cmd_study(args) -> int:
    from .io.plots import convergence, require_matplotlib
    from .tools.bench import speed_benchmark

    if args.example != "hertz":
        raise InputError(f"no study for {args.example!r}; available: hertz")
    require_matplotlib()  # its figure is its result: refused before the study, not after it
    out = Path(args.out or Path("results") / "hertz_study")
    out.mkdir(parents=True, exist_ok=True)
    series = {}
    for name, variant, order, levels in (
            ("linear, paired", "paired", 1, args.levels),
            ("linear, thesis", "thesis", 1, args.levels),
            ("quadratic, paired", "paired", 2, args.quadratic_levels)):
        if not args.quiet:
            print(f"vfem: hertz refinement study, {name}")
        series[name] = speed_benchmark([{"level": level} for level in levels], [None], ["vfem"],
                                       variant=variant, order=order, isolate=False,
                                       print_row=None if args.quiet else print)
    (out / "study.json").write_text(json.dumps(series, indent=2) + "\n", encoding="utf-8")
    convergence(out / "convergence.png", series,
                "Hertz (thesis §5.2) under refinement: error against Hertz's theory")
    if not args.quiet:
        print(f"vfem: wrote {out}/study.json and {out}/convergence.png")
    return 0


def _terminated(signum, frame) -> None:
    """SIGTERM (a job scheduler, ``kill``): stop as Ctrl-C does (every file is written under a
    temporary name and renamed, so an interrupted write leaves the completed steps whole)."""
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="vfem", description=(
        "Contact between deformable bodies by the virtual finite element method."))
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="log more (-v: info, -vv: debug)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print only errors")
    parser.add_argument("--threads", metavar="N",
                        help="threads of the sparse factorization (the dense linear algebra "
                             "runs on one), or off to leave the pools alone; default: "
                             "VFEM_THREADS, else the cores this process may use")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a built-in example or an input file")
    run.add_argument("example", metavar="EXAMPLE|FILE",
                     help=f"a built-in example ({', '.join(EXAMPLES)}) or an input file (.toml)")
    run.add_argument("--out", help="results directory (default results/<name>)")
    run.add_argument("--set", action="append", metavar="KEY=VALUE",
                     help="change a parameter of a built-in example, or a key of the input "
                          "file (dotted: contact.variant=thesis, "
                          "bodies.punch.material.youngs_modulus=1e10; repeatable)")
    run.add_argument("--overwrite", action="store_true",
                     help="replace the results of another model in the results folder")
    run.add_argument("--solver", default="auto", metavar="NAME", help=SOLVER_HELP)
    run.add_argument("--no-figures", action="store_true",
                     help="write the results but not the figures (vfem plot RESULTS_DIR draws "
                          "the same figures later): matplotlib's fixed second kept out of the run")
    run.add_argument("--resume", metavar="RESULTS_DIR",
                     help="continue an interrupted run of the same model from the last step "
                          "completed in RESULTS_DIR (its results directory)")
    run.add_argument("--ranks", type=int, metavar="N",
                     help="spread the bodies over N MPI processes: launches mpiexec -n N with "
                          "this command (needs the mpi extra: pip install -e \".[mpi]\"; "
                          "docs/scaling.md)")
    check = sub.add_parser("check", help="check an input file without solving")
    check.add_argument("file", help="the input file (.toml)")
    check.add_argument("--set", action="append", metavar="KEY=VALUE",
                       help="change a key of the input file first (as vfem run; repeatable)")
    export = sub.add_parser("export", help="write a built-in example as an input file")
    export.add_argument("example", help=", ".join(e for e in EXAMPLES if e != "springs"))
    export.add_argument("--out", help="the file (default: print it), or a folder for an "
                                      "example of several models")
    export.add_argument("--set", action="append", metavar="KEY=VALUE",
                        help="change a parameter of the example first (repeatable)")
    sub.add_parser("reference", help="print the input-file key reference (docs/input.md)")
    plot = sub.add_parser("plot", help="redraw the figures of a results folder without solving")
    plot.add_argument("results", help="the results folder (holding results.pvd)")
    bench = sub.add_parser("bench", help="time an example at several refinements")
    bench.add_argument("example", help="hertz or sphere")
    bench.add_argument("--dofs", nargs="+", metavar="SIZE",
                       help="about this many dofs: 10k, 100k, 1M or a number (default 10k 100k)")
    bench.add_argument("--levels", type=int, nargs="+",
                       help="refinement levels of the example instead of --dofs")
    bench.add_argument("--solver", nargs="+", metavar="NAME",
                       help="backends to compare: all, auto (default) or names")
    bench.add_argument("--methods", nargs="+", default=["vfem"],
                       choices=("vfem", "penalty", "lagrange", "augmented"),
                       help="contact methods to compare (default vfem)")
    bench.add_argument("--patch", action="store_true",
                       help="also the patch-test error of each method")
    bench.add_argument("--calculix", action="store_true",
                       help="also CalculiX (ccx) on the same meshes, one thread")
    bench.add_argument("--ccx-threads", type=int, default=1, metavar="N",
                       help="ccx's threads with --calculix (default 1)")
    bench.add_argument("--ccx-timeout", type=float, default=600.0, metavar="SECONDS",
                       help="stop ccx after this long with --calculix (default 600; sphere: its "
                            "row marked timed out, hertz: an error)")
    bench.add_argument("--plot", help="draw time against dofs to this PNG")
    bench.add_argument("--markdown", help="also write the tables to this Markdown file")
    bench.add_argument("--whole-run", action="store_true",
                       help="time the whole run (mesh, solve, VTU, summary, figures) against "
                            "a plain linear solve that writes the same VTU, with its phases")
    bench.add_argument("--in-process", action="store_true",
                       help="run every case in this process (no peak memory per case)")
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
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(argv)
    args.command_line = "vfem " + " ".join(shlex.quote(a) for a in argv)
    if getattr(args, "ranks", None) is not None:
        return _launch_ranks(args, argv)
    ranks = _join_ranks(args)
    if ranks is None:
        return 2
    if ranks.parallel:
        status = 1
        try:
            status = _main(args)
        finally:
            if status != 0 and not ranks.root:
                _tell_rank_failure(ranks)
            ranks.finish(status)
        return status
    return _main(args)


def _tell_rank_failure(ranks) -> None:
    """A rank other than 0 failed: give rank 0 the time to report a failure every rank shares
    (it then stops them all), else tell this rank's own message on the real stderr."""
    import time

    time.sleep(parallel.ABORT_GRACE_S)
    said = sys.stderr.getvalue() if hasattr(sys.stderr, "getvalue") else ""
    for line in said.splitlines():
        print(f"vfem (rank {ranks.rank}): {line}", file=sys.__stderr__, flush=True)


def _launch_ranks(args, argv: list[str]) -> int:
    """``vfem run --ranks N ...``: the same command under ``mpiexec -n N`` (vfem.parallel);
    one rank runs in this process."""
    n = args.ranks
    if n < 1:
        print(f"vfem: error: --ranks must be a whole number >= 1, got {n}", file=sys.stderr)
        return 2
    rest = _without_ranks(argv)
    if n == 1:
        return main(rest)
    if parallel.launched_size() > 1:
        print("vfem: error: --ranks inside an MPI launch (mpiexec already started "
              f"{parallel.launched_size()} ranks): leave out --ranks", file=sys.stderr)
        return 2
    launcher = parallel.launcher()
    if launcher is None:
        print("vfem: error: --ranks needs MPI: mpi4py and an mpiexec (pip install -e "
              "\".[mpi]\", which brings Open MPI's); or run one process without --ranks",
              file=sys.stderr)
        return 2
    command, env = parallel.launch_command(launcher, n, [sys.executable, "-m", "vfem", *rest])
    import subprocess

    try:
        return subprocess.call(command, env=env)
    except KeyboardInterrupt:
        return 130


def _without_ranks(argv: list[str]) -> list[str]:
    """``argv`` without its ``--ranks N`` (or ``--ranks=N``)."""
    out, skip = [], False
    for a in argv:
        if skip:
            skip = False
        elif a == "--ranks":
            skip = True
        elif not a.startswith("--ranks="):
            out.append(a)
    return out


def _join_ranks(args):
    """Join the MPI run this process was launched in (``mpiexec -n N vfem ...``), if any:
    the threads split between the ranks on a machine, and every rank but 0 silent (it writes
    its results to a scratch folder of its own and prints nothing unless it fails alone). None:
    refused (printed)."""
    try:
        ranks = parallel.start()
    except ImportError as exc:
        print(f"vfem: error: {exc}", file=sys.stderr)
        return None
    if ranks.parallel:  # (the threads: split between a machine's ranks, parallel.start)
        if not ranks.root:
            import io

            sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - for the life of the process
            sys.stderr = io.StringIO()  # told only if this rank alone fails (Ranks.finish)
    return ranks


def _main(args) -> int:
    """The command ``args`` names, its errors turned into one line and an exit status."""
    level = (logging.WARNING if args.verbose == 0 else
             logging.INFO if args.verbose == 1 else logging.DEBUG)
    logging.basicConfig(level=logging.ERROR if args.quiet else level,
                        format="%(levelname)s %(name)s: %(message)s")
    logging.getLogger("skfem").setLevel(max(logging.WARNING, level))
    try:
        previous = signal.signal(signal.SIGTERM, _terminated)
    except ValueError:  # not the main thread (vfem.cli.main called from a worker): no handler
        previous = None
    try:
        threads.apply(args.threads)  # one thread policy for every command (vfem.threads)
        command = {"run": cmd_run, "check": cmd_check, "export": cmd_export, "plot": cmd_plot,
                   "reference": cmd_reference,
                   "bench": cmd_bench, "study": cmd_study}[args.command]
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
    except OSError as exc:  # the file system: a path that cannot be read or written
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"vfem: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except Exception as exc:  # a bug: one line, no traceback unless asked for (-vv)
        if args.verbose >= 2:
            raise
        print(f"vfem: internal error: {type(exc).__name__}: {exc} (a bug in vfem: please "
              "report it with the input; -vv shows the traceback)", file=sys.stderr)
        return 1
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
