"""The ``vfem`` command: run built-in examples and input files, check and export input files,
redraw figures, benchmark.

Exit status: 0 success; 1 the analysis did not converge (results of converged steps are kept);
2 bad input (one message naming the problem, no traceback).

This module parses the command line and turns every error into one line and an exit status; the
commands are in their modules: ``run`` and ``check`` (:mod:`.run`), ``export``, ``reference`` and
``plot`` (:mod:`.commands`), ``bench`` and ``study`` (:mod:`.bench`); the progress display
(:mod:`.progress`), the built-in examples by name (:mod:`.builtin`, the package
:mod:`vfem_examples` beside the library) and the launch over MPI ranks (:mod:`.launch`).
"""

from __future__ import annotations

import argparse
import logging
import shlex
import signal
import sys

from vfem_examples import EXAMPLES

from .. import threads
from ..errors import InputError, VfemError
from .bench import cmd_bench, cmd_study
from .builtin import build_parameters
from .commands import cmd_export, cmd_plot, cmd_reference
from .launch import join_ranks, launch_ranks, tell_rank_failure
from .progress import Progress
from .run import SOLVER_HELP, cmd_check, cmd_run
from .verify import cmd_verify

__all__ = ["main", "build_parameters", "Progress"]


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
    verify = sub.add_parser("verify", help="run every built-in example and print how right "
                                           "each is (a check of the install)")
    verify.add_argument("examples", nargs="*", metavar="EXAMPLE",
                        help="only these examples (default: all)")
    verify.add_argument("--slow", action="store_true",
                        help="the refined models the examples name, instead of the defaults")
    verify.add_argument("--out", help="keep the results and verify.json in this folder "
                                      "(default: a temporary one, removed)")
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
        return launch_ranks(args, argv, main)
    ranks = join_ranks(args)
    if ranks is None:
        return 2
    if ranks.parallel:
        status = 1
        try:
            status = _main(args)
        finally:
            if status != 0 and not ranks.root:
                tell_rank_failure(ranks)
            ranks.finish(status)
        return status
    return _main(args)


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
                   "bench": cmd_bench, "study": cmd_study, "verify": cmd_verify}[args.command]
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

