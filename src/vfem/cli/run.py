"""``vfem run`` (a built-in example or an input file) and ``vfem check``: the results folder made
ready, the solve under the progress display, the closing report."""

from __future__ import annotations

import inspect
import logging
import os
import shlex
import sys
from pathlib import Path

from .. import linalg, parallel
from ..errors import InputError
from ..io.folders import ResultsFolder, default_folder, run_description
from .builtin import build_parameters, example_module
from .progress import Progress

log = logging.getLogger("vfem")


SOLVER_HELP = ("linear-algebra backend: auto (the fastest installed), superlu, pardiso, cholmod "
               "or mumps (docs/benchmarks.md)")


def cmd_run(args) -> int:
    from ..io.replot import defer

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
    if is_input_file(args.example):
        return run_input_file(args)
    example = example_module(args.example, ", or an input file (.toml)")
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
    folder's record, comes after them (:func:`results_line`)."""
    from ..io import verification
    from ..io.runner import invariants_line, reaction_lines

    steps = summary.get("steps") or []
    return [*lines, *("  " + x for x in (*reaction_lines(steps), invariants_line(steps)) if x),
            *verification.lines(summary.get("verification") or [])]


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
    target = args.example if not is_input_file(args.example) else str(
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
        print("\n".join(results_line(report(summary), out)))
        if summary.get("figures_not_drawn"):  # no matplotlib, or --no-figures (draw_run)
            print(f"vfem: figures not drawn: {summary['figures_not_drawn']}", file=sys.stderr)
        for note in summary.get("figures_notes") or ():  # a figure left out, and why
            print(f"vfem: not drawn: {note}", file=sys.stderr)
    if not summary["converged"]:
        print(f"vfem: the analysis did not converge: "
              f"{summary.get('message') or 'see summary.json for each case'}",
              file=sys.stderr)
        return 1
    return 0


#: What the closing screen says of a results folder's files, in this order (those present).
_RESULT_FILES = (("summary.json", ""), ("results.pvd", " for ParaView"), ("contact.csv", ""),
                 ("reactions.csv", ""))


def results_line(lines: list[str], out: Path) -> list[str]:
    """The report and its ``results:`` line, made from the files this run wrote in ``out``
    (its record, :mod:`vfem.io.folders`): never a file it did not write (a run that stopped
    early has no figures; another run's sub-folder is not this one's)."""
    from ..io.folders import read_record

    record = read_record(out) or {}
    owned = set(record.get("files") or [])
    names = [n + note for n, note in _RESULT_FILES if n in owned]
    names += sorted(n for n in owned if "/" not in n and n.endswith(".png"))
    cases = sorted({n.split("/")[0] + "/" for n in owned if "/" in n
                    and not n.startswith("checkpoint/")})
    return [*lines, f"  results: {out}/ (" + ", ".join(names + cases) + ")"]


def is_input_file(target: str) -> bool:
    return target.endswith(".toml") or Path(target).is_file()


def _load_input(path: str, assignments: list[str] = ()):
    from ..io.input import load as load_input

    return load_input(path, assignments)


def _checked_model(path: str, assignments: list[str] = ()):
    """The input file's description and its model, every check done (nothing solved);
    ``assignments``: ``--set KEY=VALUE`` changes to the file's keys (checked like the file)."""
    from ..config import check

    config = _load_input(path, assignments)
    try:
        return config, check(config, Path(path).parent)
    except InputError as exc:
        changes = " with --set " + " --set ".join(assignments) if assignments else ""
        raise InputError(f"{path}{changes}: {exc}") from None


def run_input_file(args) -> int:
    from ..io import runner

    # bad input (the --set changes included) reported before anything is written
    config, model = _checked_model(args.example, args.set or [])
    out = _results_directory(args, Path(config.output.directory) if config.output.directory
                             else default_folder(config.name, args.set or []))
    factors = config.steps.factors()
    if not args.quiet:
        print(f"vfem: {config.name} ({args.example}), {len(factors)} "
              f"step{'s' if len(factors) > 1 else ''}, results in {out}/", flush=True)
        if any(b.section.name == "axisymmetric" for b in model.bodies):
            print("vfem: axisymmetric bodies (x = r, y = z): forces, reactions and contact "
                  "forces are per full circle (the ring's whole force, 2 pi r ds)", flush=True)
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
