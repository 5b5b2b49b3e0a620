"""Bodies spread over MPI ranks (issue 22): each rank factorizes and solves only its own bodies.

vfem's structure is made for it: every body has its own stiffness and factorization, and the
bodies meet only through their contact data. Under ``mpiexec -n N vfem run MODEL`` (or
``vfem run --ranks N MODEL``, which launches it) every rank runs the same analysis on the same
model, step by step and iteration by iteration, and takes the same decisions (step cuts,
invariants, the end); the work is spread (issue 40):

* on the rank that owns a body (:meth:`Ranks.place`: largest bodies first, each to the least
  loaded rank): its stiffness (the others assemble its dofs, supports and loads only), its
  factorization and every back-substitution through it, its load cases, its compliance
  densities, its part of the pair matrix W (:meth:`Ranks.total`), each step's fields,
  reactions and strain screen;
* on one rank per pair: the candidate search, the initial-overlap check, the pair's geometry,
  invariant (b) of the pair; the facets' mass matrices one body a rank;
* on every rank alike: the contact problem on W (its complementarity solves) and the rest of
  the invariants.

A body that Newton's method corrects (large kinematics, or a plastic material: the contact
formulation of ``vfem.contact.formulations.large``) is kept on every rank: its trial and
converged displacements and its material's state (which the pairing on the current geometry
reads on every rank), each computed alike from the same numbers. Its owner alone factorizes
its tangent and solves with it (:meth:`vfem.bodies.mechanics.LargeMechanics._shared_system`:
the correction, the tangent flexibility on the contact dofs and the platen's terms sent to
every rank, every body's owner at once, :func:`vfem.bodies.mechanics.prefetch`), and
equilibrates it at the end of a step, the others taking its trial state
(:meth:`vfem.nonlinear.NonlinearBody.adopt`). A model with such a body reads the linear
bodies' flexibility on every rank too (as the thesis variant does).

What each rank computed comes to the others (:meth:`Ranks.map`, :meth:`Ranks.share`), so every
rank holds the same numbers, and the answers are the serial run's to round-off (W's parts are
summed rank by rank; tests/test_mpi.py: 1e-10, 3e-14 measured). :meth:`Ranks.own` times each
rank's share of the spread work (``Ranks.busy``): the rest of a run is what every rank does
alike (``benchmarks/ranks.py``, docs/scaling.md).

What crosses between ranks:

* at set-up, per body, what the contact iteration reads of it: its displacement under each load
  case and under a unit platen motion, the platen's reactions and stiffness, and on the dense
  route of the thesis variant its flexibility on its contact dofs (:meth:`Ranks.share`); per
  pair its geometry; W (m x m, reduced to rank 0 and broadcast);
* per contact iteration on the matrix-free route, each body's motion under its contact forces
  at its condensed dofs (:meth:`Ranks.map`: every owner solves its own bodies at once, then they
  are exchanged);
* per converged step, each body's fields and reactions from its owner;
* per Newton iteration of a model with a body that Newton's method corrects, each such body's
  correction (ndofs), tangent flexibility (condensed x candidate dofs) and platen terms from
  its owner, and its response to the change of its contact forces (ndofs).

Rank 0 writes the results and prints; the others write nothing. Serial runs never import
mpi4py (:func:`current` is a one-rank :class:`Ranks` unless the process was started by an MPI
launcher with more than one rank).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable, Iterable

import numpy as np

from .executor import SERIAL

log = logging.getLogger(__name__)

#: seconds a failed rank other than 0 waits before stopping the run, for rank 0 to report a
#: failure they share (``vfem.cli``, before :meth:`Ranks.finish`)
ABORT_GRACE_S = 3.0

#: the environment variables MPI launchers set to the number of ranks (Open MPI, MPICH/Hydra)
SIZE_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS")


class Ranks:
    """The ranks of a run and which body each owns; one rank (``comm`` None) is the serial
    run, where every body is its own and nothing is sent."""

    def __init__(self, comm=None):
        self.comm = comm
        self.rank = 0 if comm is None else comm.Get_rank()
        self.size = 1 if comm is None else comm.Get_size()
        self.owner: list[int] = []
        #: while set (:meth:`map`), a shared factorization solves on its owner only
        self.local = False
        #: this rank's scratch results folder (ranks other than 0, :func:`scratch_folder`)
        self.scratch = None
        #: seconds this rank spent on its own share of the work that is spread over the
        #: ranks (each body's on its owner, each pair's on one rank: :meth:`own`); the rest of
        #: a run's time on a rank is done by every rank alike, or waiting for the others
        #: (``benchmarks/ranks.py``'s replicated fraction, issue 40)
        self.busy = 0.0
        self._depth = 0

    @property
    def parallel(self) -> bool:
        return self.size > 1

    @property
    def root(self) -> bool:
        """Whether this is rank 0 (the one that writes and prints)."""
        return self.rank == 0

    def place(self, sizes: Iterable[int]) -> list[int]:
        """Each body's rank, balanced by its size (dofs): the largest first, each to the rank
        with the least so far (ties: the lower rank). The same on every rank."""
        sizes = list(sizes)
        load = [0] * self.size
        owner = [0] * len(sizes)
        for i in sorted(range(len(sizes)), key=lambda i: (-sizes[i], i)):
            r = min(range(self.size), key=lambda r: (load[r], r))
            owner[i] = r
            load[r] += sizes[i]
        self.owner = owner
        return owner

    def mine(self, i: int) -> bool:
        """Whether body ``i`` is this rank's."""
        return not self.owner or self.owner[i] == self.rank

    def own(self, compute: Callable, *args) -> object:
        """``compute(*args)``, this rank's share of spread work, timed into :attr:`busy`
        (the outermost call only: a share within a share is counted once)."""
        if self._depth:
            return compute(*args)
        self._depth += 1
        t = time.perf_counter()
        try:
            return compute(*args)
        finally:
            self.busy += time.perf_counter() - t
            self._depth -= 1

    def share(self, i: int, make: Callable[[], object]) -> object:
        """``make()`` on body ``i``'s owner, its value on every rank; an error raised there is
        raised on every rank (the same type and message where it can be rebuilt)."""
        if not self.parallel:
            return make()
        value = error = None
        if self.mine(i):
            try:
                value = self.own(make)
            except Exception as e:  # noqa: BLE001 - carried to every rank, raised there
                error = e
        value, error = self.comm.bcast((value, error), root=self.owner[i])
        if error is not None:
            raise error
        return value

    def map(self, indices: Iterable[int], compute: Callable[[int], object],
            owners: list[int] | None = None) -> dict:
        """``compute(i)`` for every body ``i`` of ``indices``, each on its owner (or on rank
        ``owners[i]``: work that is no body's, spread), all owners at once; every rank gets
        every value. In serial, simply in order."""
        indices = list(indices)
        if not self.parallel or (owners is None and not self.owner):
            # (no bodies placed: a run every rank does whole, a baseline's)
            return {i: self.own(compute, i) for i in indices}

        def owner(i: int) -> int:
            return owners[i] if owners is not None else self.owner[i]

        out, errors = {}, {}
        self.local = True
        try:
            for i in indices:
                if owner(i) == self.rank:
                    try:
                        out[i] = self.own(compute, i)
                    except Exception as e:  # noqa: BLE001 - carried to every rank
                        errors[i] = e
        finally:
            self.local = False
        for i in indices:
            value, error = self.comm.bcast((out.get(i), errors.get(i)), root=owner(i))
            if error is not None:
                raise error
            out[i] = value
        return out

    def total(self, indices: Iterable[int], compute: Callable[[int], np.ndarray],
              shape: tuple[int, ...]) -> np.ndarray:
        """The sum over ``indices`` of ``compute(i)`` (arrays of ``shape``), each computed on
        body ``i``'s owner and summed there with the others it owns, the owners' sums added
        on rank 0 (``MPI_Reduce``) and sent from it to every rank, so that every rank holds the
        same numbers (its decisions depend on them). What crosses is one array of ``shape``
        per rank, not every body's (issue 40: the pair matrix W, each body's part on its
        owner). An error raised on an owner is raised on every rank. In serial, in order."""
        indices = list(indices)
        if not self.parallel or not self.owner:
            return SERIAL.total(indices, lambda i: self.own(compute, i), shape)
        partial, error = np.zeros(shape), None
        self.local = True
        try:
            for i in indices:
                if self.owner[i] == self.rank:
                    partial += self.own(compute, i)
        except Exception as e:  # noqa: BLE001 - carried to every rank
            error = e
        finally:
            self.local = False
        errors = [e for e in self.comm.allgather(error) if e is not None]
        if errors:
            raise errors[0]
        from mpi4py import MPI

        out = np.zeros(shape) if self.root else None
        self.comm.Reduce(partial, out, op=MPI.SUM, root=0)
        if not self.root:
            out = partial  # (its own sum no longer needed: the buffer the total comes into)
        self.comm.Bcast(out, root=0)
        return out

    def finish(self, status: int) -> None:
        """The end of a rank's command with exit status ``status``: its scratch folder
        removed; a rank that failed while others may still wait for it stops them all
        (``MPI_Abort``: a failure on one rank alone, writing its results say, must not leave
        the others waiting for ever); a rank that succeeded waits for the others. (The CLI
        lets rank 0 tell a failure every rank shares first, :data:`ABORT_GRACE_S`.)"""
        if not self.parallel:
            return
        if self.scratch is not None:
            import shutil

            shutil.rmtree(self.scratch, ignore_errors=True)
        if status != 0:
            import sys

            sys.stdout.flush()
            sys.stderr.flush()
            self.comm.Abort(status)
        self.comm.Barrier()

    def agree(self, value: object) -> object:
        """Rank 0's ``value`` on every rank (what must be the same everywhere: a time, a
        choice made from a measurement)."""
        return value if not self.parallel else self.comm.bcast(value, root=0)


class SharedFactor:
    """A body's factorization on its owner, as every rank sees it: ``solve`` runs on the owner
    and its answer is broadcast (every rank calls it at the same point of the same analysis),
    or, inside :meth:`Ranks.map`, runs on the owner alone."""

    def __init__(self, factor, ranks: Ranks, index: int):
        self.factor = factor  # the owner's; None elsewhere
        self.ranks = ranks
        self.index = index
        self.name = getattr(factor, "name", None)

    def solve(self, b: np.ndarray) -> np.ndarray:
        if self.ranks.local:
            return self.factor.solve(b)
        return self.ranks.share(self.index, lambda: self.factor.solve(b))


def set_up_bodies(ranks: Ranks, bodies, setup: Callable[[int], None],
                  share_flexibility: bool = False) -> None:
    """Set every body up on its owner (``setup(i)``: assemble, factorize, solve its load
    cases), all owners at once; on the other ranks only what every rank reads of it (its
    dofs, supports and loads; not its stiffness: what reads it, a step's fields and
    reactions, runs on the owner, issue 40), then hand them what the contact iteration reads
    of it and a :class:`SharedFactor` in place of its factorization. ``share_flexibility``:
    also its dense flexibility on its contact dofs (a formulation that reads it on every
    rank: the thesis variant); the paired variant reads it on the owner only
    (:meth:`Ranks.map`)."""
    from .bodies.mechanics import LinearMechanics, mechanics_for

    ranks.place([b.dim * b.npoints for b in bodies])
    log.info("MPI: %d ranks; rank %d sets up %s", ranks.size, ranks.rank,
             ", ".join(repr(b.name) for i, b in enumerate(bodies) if ranks.mine(i)) or "nothing")
    fixed = {}
    for i, b in enumerate(bodies):
        if ranks.mine(i):
            try:
                ranks.own(setup, i)
            except Exception as e:  # noqa: BLE001 - raised on every rank by share, below
                b._setup_error = e
        else:
            fixed[i] = b.assemble(stiffness=False)
    for i, b in enumerate(bodies):
        def payload(b=b):
            error = b.__dict__.pop("_setup_error", None)
            if error is not None:
                raise error
            return {"cases": [(c.displacement, getattr(c, "platen_reaction", 0.0))
                              for c in b.load_cases],
                    "u_platen": b.u_platen, "platen_load_reaction": b.platen_load_reaction,
                    "platen_stiffness": b.platen_stiffness,
                    "condensed_flexibility": b.condensed_flexibility if share_flexibility
                    else None, "timings": b.timings}

        data = ranks.share(i, payload)
        if ranks.mine(i):
            b.factor = SharedFactor(b.factor, ranks, i)
            if b.iterates:  # its state on every rank, its tangent's algebra on its owner
                b.mechanics.ranks, b.mechanics.index = ranks, i
            continue
        for case, (u, reaction) in zip(b.load_cases, data["cases"], strict=True):
            case.displacement, case.platen_reaction = u, reaction
        b.u_load = (b.load_cases[0].displacement if len(b.load_cases) == 1
                    else sum(c.displacement for c in b.load_cases))
        b.u_platen = data["u_platen"]
        b.platen_load_reaction = data["platen_load_reaction"]
        b.platen_stiffness = data["platen_stiffness"]
        b.condensed_flexibility = data["condensed_flexibility"]
        b.timings = data["timings"]
        b.factor = SharedFactor(None, ranks, i)
        if b.iterates:  # Newton's body: its state kept on every rank (LargeMechanics)
            b.mechanics = mechanics_for(b, fixed[i])
            b.mechanics.ranks, b.mechanics.index = ranks, i
        else:
            b.mechanics = LinearMechanics(b)


_current = Ranks()


def current() -> Ranks:
    """The ranks of this process's run (one, unless :func:`start` found an MPI launch)."""
    return _current


def launched_size() -> int:
    """The number of ranks an MPI launcher started this process among (1 if none)."""
    for name in SIZE_VARIABLES:
        value = os.environ.get(name, "")
        if value.isdigit():
            return int(value)
    return 1


def start() -> Ranks:
    """Join the MPI run this process was launched in (mpi4py), if it was launched by an MPI
    launcher with more than one rank; else stay serial. Raises ImportError with what to
    install when mpi4py is missing under a parallel launch."""
    global _current
    if launched_size() <= 1 or _current.parallel:
        return _current
    try:
        from mpi4py import MPI
    except ImportError as e:
        raise ImportError("this run was started by an MPI launcher with "
                          f"{launched_size()} ranks, but mpi4py is not installed: "
                          "pip install -e \".[mpi]\" (mpi4py and Open MPI)") from e
    _current = Ranks(MPI.COMM_WORLD)
    # the cores of a machine shared between its ranks (unless VFEM_THREADS says otherwise):
    # two ranks each factorizing on every core would only slow each other down
    local = os.environ.get("OMPI_COMM_WORLD_LOCAL_SIZE", "")
    per_machine = int(local) if local.isdigit() else _current.size
    os.environ.setdefault("VFEM_THREADS", str(max(1, (os.cpu_count() or 1) // per_machine)))
    log.info("MPI: rank %d of %d", _current.rank, _current.size)
    return _current


def scratch_folder(out, resume: bool):
    """Where this rank writes a run's results: ``out`` on rank 0 (and in serial); on the other
    ranks a scratch folder of their own (with ``resume``, a copy of ``out``'s checkpoints,
    taken before rank 0 goes on writing there), removed when the process ends."""
    ranks = current()
    if not ranks.parallel:
        return out
    from pathlib import Path

    if not ranks.root:
        import atexit
        import shutil
        import tempfile

        scratch = Path(tempfile.mkdtemp(prefix=f"vfem-rank{ranks.rank}-"))
        atexit.register(shutil.rmtree, scratch, ignore_errors=True)
        ranks.scratch = scratch  # removed by Ranks.finish too (MPI_Abort skips atexit)
        if resume:
            shutil.copytree(out, scratch, dirs_exist_ok=True)
        out = scratch
    ranks.comm.Barrier()  # every copy taken before rank 0 writes
    return Path(out)


def launcher() -> str | None:
    """The ``mpiexec`` to launch ranks with: beside this Python (the Open MPI wheel puts it
    in the environment's ``bin``), else on the PATH; None without mpi4py or an mpiexec."""
    import importlib.util
    import shutil
    import sys
    from pathlib import Path

    if importlib.util.find_spec("mpi4py") is None:
        return None
    beside = Path(sys.executable).parent / "mpiexec"
    if beside.exists():
        return str(beside)
    return shutil.which("mpiexec")


def launch_command(mpiexec: str, n: int, command: list[str]) -> tuple[list[str], dict]:
    """The command line and environment that run ``command`` on ``n`` ranks: Open MPI's
    ``--oversubscribe`` where ``n`` exceeds the cores, and its consent to run as root where
    this user is root (containers, CI)."""
    env = dict(os.environ)
    out = [mpiexec, "-n", str(n)]
    open_mpi = _is_open_mpi(mpiexec)
    if open_mpi and n > (os.cpu_count() or 1):
        out.append("--oversubscribe")
    if open_mpi and hasattr(os, "geteuid") and os.geteuid() == 0:
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return out + command, env


def _is_open_mpi(mpiexec: str) -> bool:
    import subprocess

    try:
        text = subprocess.run([mpiexec, "--version"], capture_output=True, text=True,
                              timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return False
    return "Open MPI" in text or "OpenRTE" in text


def use(ranks: Ranks) -> Ranks:
    """Make ``ranks`` the current ones (tests; :func:`start` for a run)."""
    global _current
    _current = ranks
    return ranks


__all__ = ["Ranks", "SharedFactor", "current", "launch_command", "launched_size", "launcher",
           "scratch_folder", "set_up_bodies", "start", "use"]
