"""One thread policy for the linear algebra (issue 19): the single place that sizes the thread
pools vfem's work runs on.

Two pools serve vfem, and each, left alone, starts a thread per core:

* the **dense BLAS** of NumPy and SciPy (OpenBLAS in their wheels): the contact flexibility's
  small dense blocks, the pair matrix of the contact correction, the Schur complement's inverse.
  These are many small operations inside the contact iteration, where threads cost more than
  they give;
* the **sparse factorization**: MKL's OpenMP threads under PARDISO (and the BLAS under CHOLMOD
  and MUMPS), where the large work is.

Both pools spinning at once oversubscribe the cores: on the shared 2-core machine the Hertz
example at 20k dofs took 2.76 s with the default pools and 0.17 s with one thread each (issue 19).
The policy: the dense BLAS on **one** thread, the sparse factorization on ``threads`` (default
:func:`default_threads`: the cores this process may use), so the two never compete. Small sparse
work stays on one thread even so: PARDISO on matrices below 20,000 dofs, every phase alike
(``vfem.linalg.pardiso.ONE_THREAD_BELOW``, measured there), which two threads only slow down,
ten times over when another process holds the other core.
``vfem --threads N`` (or the ``VFEM_THREADS`` environment variable) sets ``threads``; ``off``
leaves the pools as the libraries set them. The library applies the default once, when an
analysis is set up, unless :func:`apply` was called.

Measured on the 2-core machine (2026-11-25, quiet; ``python benchmarks/threads.py``, which
prints the current figures), Hertz with PARDISO, medians of 3 alternating runs: at 119k dofs the
library defaults 2.82 s, every pool on one thread 2.72 s, this policy 2.51 s; at 465k dofs
9.82 s, 10.30 s and 9.38 s. The policy is the fastest of the three at both sizes; on a loaded
machine the defaults fare far worse (the figures above from issue 19).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterator
from contextlib import contextmanager

from .errors import InputError

log = logging.getLogger(__name__)

#: what :func:`apply` set: ``{"threads": n, "dense": 1}``, or None before it ran
_applied: dict | None = None


def default_threads() -> int:
    """The cores this process may use (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # not on Linux
        return max(1, os.cpu_count() or 1)


def requested(value: str | int | None = None) -> int | None:
    """The thread count ``value`` asks for (``--threads``; else ``VFEM_THREADS``; else the
    default), checked: a whole number >= 1, or ``"off"`` (None: leave the pools as the
    libraries set them)."""
    source = "--threads"
    if value is None:
        value, source = os.environ.get("VFEM_THREADS"), "VFEM_THREADS"
    if value is None or value == "":
        return default_threads()
    if str(value).strip().lower() == "off":
        return None
    try:
        n = int(value)
    except (TypeError, ValueError):
        n = 0
    if n < 1 or str(value).strip() != str(n):
        raise InputError(f"{source} must be a whole number of threads >= 1 (or off), got "
                         f"{value!r}")
    return n


def apply(threads: int | None = None) -> dict:
    """Size the pools (see the module docstring): the dense BLAS on one thread, the sparse
    factorization on ``threads`` (default: :func:`requested`). Returns what it set. A library
    loaded later (MKL, when PARDISO is first used) takes the setting as it loads
    (:func:`after_loading`)."""
    global _applied
    n = requested(threads)
    if n is None:  # "off": the pools as the libraries set them
        _applied = {"threads": None, "dense": None}
        log.info("threads: the pools left as the libraries set them (off)")
        return dict(_applied)
    _applied = {"threads": n, "dense": 1}
    os.environ["MKL_NUM_THREADS"] = str(n)  # read by MKL when it loads (PARDISO)
    _limit_loaded()
    log.info("threads: %d for the sparse factorization, 1 for the dense BLAS", n)
    return dict(_applied)


def ensure() -> dict:
    """:func:`apply` the default policy if nothing has applied one yet (what an analysis does
    when it is set up); returns what is in force."""
    return dict(_applied) if _applied is not None else apply()


def sparse_threads() -> int:
    """The sparse factorization's threads under the policy in force (0 when it is off or none
    was applied: the libraries' own setting)."""
    if _applied is None or _applied["threads"] is None:
        return 0
    return int(_applied["threads"])


def after_loading() -> None:
    """Call when a library with its own thread pool has just loaded (MKL under PARDISO): the
    policy in force applies to it too."""
    if _applied is not None and _applied["threads"] is not None:
        _limit_loaded()


def _limit_loaded() -> None:
    """Set the loaded pools with threadpoolctl (OpenBLAS to 1, MKL and OpenMP to ``threads``);
    without threadpoolctl, only libraries loaded after this read the environment."""
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover - a dependency; kept working without it
        log.info("threadpoolctl is not installed: the thread policy applies to libraries "
                 "loaded from now on only")
        return
    n = _applied["threads"]
    pools = ThreadpoolController()
    for api, count in (("openblas", 1), ("mkl", n), ("openmp", n)):
        selected = pools.select(internal_api=api)
        if selected.lib_controllers:
            selected.limit(limits=count)  # in force until changed (not a context here)


#: the order of a dense matrix from which one operation on it (an inverse, a factorization)
#: runs on the policy's threads rather than one: a long contact surface's flexibility
DENSE_THREADS_FROM = 2000
#: ... and up to this order only: the threaded Cholesky (potrf) of the OpenBLAS SciPy ships
#: (0.3.30) crashes the process (a segmentation fault) above about 16,000 on two threads
#: (measured: 14,500 fine, 16,400 and 17,342 crash; one thread is fine at 17,342)
DENSE_THREADS_UPTO = 14_000


@contextmanager
def dense_threads(order: int) -> Iterator[None]:
    """The dense BLAS on the policy's ``threads`` while one large dense operation runs (a
    matrix of :data:`DENSE_THREADS_FROM` <= ``order`` <= :data:`DENSE_THREADS_UPTO`: the
    inverse of a long contact surface's Schur complement, the pair matrix over it), one thread
    again after; nothing for smaller ones, whose many calls inside the contact iteration
    threads would slow (and whose bits stay those of one thread), nor for larger ones.
    Measured: the strip of ``benchmarks/strip.py`` at 16,000 contact dofs inverts its two
    blocks in 12.5 s on both cores against 22 s on one."""
    n = None if _applied is None else _applied["threads"]
    if n is None or n <= 1 or not DENSE_THREADS_FROM <= order <= DENSE_THREADS_UPTO:
        yield
        return
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover
        yield
        return
    with ThreadpoolController().select(internal_api="openblas").limit(limits=n):
        yield


def info() -> list[dict]:
    """The loaded thread pools as threadpoolctl reports them (library, API, threads)."""
    try:
        from threadpoolctl import threadpool_info
    except ImportError:  # pragma: no cover
        return []
    return [{"library": i.get("internal_api"), "api": i.get("user_api"),
             "threads": i.get("num_threads")} for i in threadpool_info()]


__all__ = ["after_loading", "apply", "default_threads", "dense_threads", "ensure", "info",
           "requested"]
