"""``vfem run --ranks N``: the same command under ``mpiexec -n N`` (:mod:`vfem.parallel`), and
a rank joining the MPI run it was launched in."""

from __future__ import annotations

import os
import sys

from .. import parallel
from .progress import TTY_ENV


def tell_rank_failure(ranks) -> None:
    """A rank other than 0 failed: give rank 0 the time to report a failure every rank shares
    (it then stops them all), else tell this rank's own message on the real stderr."""
    import time

    time.sleep(parallel.ABORT_GRACE_S)
    said = sys.stderr.getvalue() if hasattr(sys.stderr, "getvalue") else ""
    for line in said.splitlines():
        print(f"vfem (rank {ranks.rank}): {line}", file=sys.__stderr__, flush=True)


def launch_ranks(args, argv: list[str], main) -> int:
    """``vfem run --ranks N ...``: the same command under ``mpiexec -n N`` (vfem.parallel);
    one rank runs in this process, and ``--ranks 1`` is ``main`` (the command) without it."""
    n = args.ranks
    if n < 1:
        print(f"vfem: error: --ranks must be a whole number >= 1, got {n}", file=sys.stderr)
        return 2
    rest = without_ranks(argv)
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
    # whether the user's screen is a terminal: mpiexec hands the ranks a pseudo-terminal of its
    # own, so a rank cannot tell that its output goes to a file (progress.TTY_ENV)
    env[TTY_ENV] = "1" if getattr(sys.stdout, "isatty", lambda: False)() else "0"
    import subprocess

    try:
        return subprocess.call(command, env=env)
    except KeyboardInterrupt:
        return 130


def without_ranks(argv: list[str]) -> list[str]:
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


def join_ranks(args):
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
