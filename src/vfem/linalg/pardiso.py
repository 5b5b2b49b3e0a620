"""Intel MKL PARDISO (found through the ``pypardiso`` package, which ships MKL).

Called directly through ctypes rather than through pypardiso's own solver class, for two
features that class does not expose: the symmetric positive definite matrix type (half the
matrix, Cholesky) and PARDISO's Schur complement (``iparm[35]``). With ``trailing`` dofs,
PARDISO factorizes the whole matrix and returns the dense Schur complement on the trailing dofs in
the same pass (``iparm[35] = 2``; with ``1`` it skips the trailing block and its solves are good
to only about 1e-5); the Schur complement's inverse is the flexibility contact needs.
"""

from __future__ import annotations

import ctypes
import os

import numpy as np
import scipy.sparse as sp

from ..threads import after_loading, dense_threads, sparse_threads
from .common import spd_inverse_in_place

_P64 = ctypes.POINTER(ctypes.c_int64)
_P32 = ctypes.POINTER(ctypes.c_int32)
_pardiso = None
_runtime_lib = None  # MKL's runtime library (ctypes), once loaded
_set_local = None  # its mkl_set_num_threads_local, False if it has none

#: PARDISO's error codes (MKL reference, "pardiso"), for messages
ERRORS = {-1: "input inconsistent", -2: "not enough memory", -3: "reordering problem",
          -4: "zero pivot (the matrix is singular or not positive definite)",
          -5: "unclassified internal error", -6: "reordering failed", -7: "diagonal matrix "
          "is singular", -8: "32-bit integer overflow", -9: "not enough memory for OOC",
          -10: "error opening OOC files", -11: "read/write error with OOC files"}


def _mkl_rt() -> str | None:
    """MKL's runtime library as the ``mkl`` wheel (pypardiso's dependency) lists it among its
    files, or ``PYPARDISO_MKL_RT``; None if neither names one that exists. Found in 15 ms,
    where pypardiso's search walks the whole installation: 0.85 s at the start of every run
    (issue 19: a third of a 100k-dof Hertz run's wall time)."""
    given = os.environ.get("PYPARDISO_MKL_RT")
    if given:
        return given
    try:
        from importlib.metadata import PackageNotFoundError, files

        listed = files("mkl") or []
    except (ImportError, PackageNotFoundError):
        return None
    found = sorted((str(f.locate()) for f in listed if f.name.startswith("libmkl_rt")
                    or f.name.startswith("mkl_rt")), key=len)
    return next((path for path in found if os.path.isfile(path)), None)


#: PARDISO works on one thread for matrices of fewer dofs than this (issue 19), all its phases:
#: the analysis, the factorizations and the back-substitutions of one matrix on the same
#: threads (MKL's PARDISO crashed in a factorization that took over an analysis after solves
#: on fewer threads: ``tests/test_linalg.py``). Measured on the 2-core machine, idle
#: (2026-11-25, a plane-strain block with a Schur complement on its top): at 3,872 dofs a solve
#: took 0.25 ms on one thread and 0.75 ms on two, the factorization the same; at 24,080 dofs
#: 1.65 against 2.08 ms, the factorization 29-34 against 23-31 ms; at 160,200 dofs the solves
#: alike, the factorization 360 against 255-280 ms. With the other core busy (another
#: process), a small factorization on two threads was ten times slower: the large contact
#: iteration of the sliding example spent 7.6 s in PARDISO instead of 0.7 s.
ONE_THREAD_BELOW = 20_000


def _local_threads():
    """MKL's ``mkl_set_num_threads_local`` (threads for the calling thread's next calls;
    returns the previous setting, 0 for the global one), or None if MKL has none."""
    global _set_local
    if _set_local is None:
        try:
            f = _runtime().MKL_Set_Num_Threads_Local
            f.argtypes, f.restype = [ctypes.c_int], ctypes.c_int
            _set_local = f
        except (AttributeError, OSError):
            _set_local = False
    return _set_local or None


def _runtime():
    """MKL's runtime library (ctypes), as :func:`_library` loads it."""
    _library()
    return _runtime_lib


def _library():
    """PARDISO's entry point in MKL's runtime library (located by pypardiso)."""
    global _pardiso, _runtime_lib
    if _pardiso is None:
        # MKL's OpenMP threads otherwise spin for 200 ms after each call, fighting NumPy's
        # BLAS threads for the cores in the dense work between calls (measured: the contact
        # flexibility's Cholesky 7x slower on 2 cores); read when MKL's OpenMP starts
        os.environ.setdefault("KMP_BLOCKTIME", "0")
        path = _mkl_rt()
        if path is not None:
            _runtime_lib = ctypes.CDLL(path)
        else:  # pypardiso's own search (the whole of sys.prefix: about a second)
            import pypardiso

            _runtime_lib = pypardiso.PyPardisoSolver().libmkl
        f = _runtime_lib.pardiso
        f.argtypes = [_P64, _P32, _P32, _P32, _P32, _P32, ctypes.c_void_p, _P32, _P32, _P32,
                      _P32, _P32, _P32, ctypes.c_void_p, ctypes.c_void_p, _P32]
        f.restype = None
        _pardiso = f
        after_loading()  # MKL's pool under the thread policy (vfem.threads)
    return _pardiso


def available() -> bool:
    try:
        _library()
    except Exception:  # noqa: BLE001 - not installed, or MKL not loadable: not available
        return False
    return True


def _i32(value: int):
    return np.array([value], dtype=np.int32)


class PardisoFactorization:
    """MKL PARDISO: Cholesky for the stiffness, Bunch-Kaufman for saddle points (``spd=False``)."""

    name = "pardiso"
    #: :func:`vfem.linalg.factorize` may hand it the factorization of a matrix of the same
    #: pattern, whose analysis (ordering, symbolic factorization) it then takes over
    reuses_analysis = True

    def __init__(self, A: sp.spmatrix, trailing: np.ndarray | None = None,
                 groups: np.ndarray | None = None, spd: bool = True,
                 analysis: PardisoFactorization | None = None, symmetric: bool = True):
        self.shape = A.shape
        # symmetric matrices: the upper triangle; an unsymmetric one (``symmetric=False``, a
        # saddle point with friction's ties) whole, factorized by LU (PARDISO's mtype 11)
        U = sp.triu(A, format="csr") if symmetric else sp.csr_matrix(A)
        U.sort_indices()
        self.n = U.shape[0]
        self._a = np.ascontiguousarray(U.data, dtype=float)
        self._ia = U.indptr.astype(np.int32)
        self._ja = U.indices.astype(np.int32)
        self._pt = np.zeros(64, dtype=np.int64)
        self._mtype = (2 if spd else -2) if symmetric else 11
        iparm = np.zeros(64, dtype=np.int32)
        iparm[0] = 1  # these values, not the defaults
        iparm[1] = 2  # METIS nested dissection
        iparm[9] = 8  # pivot perturbation 1e-8 (indefinite only)
        iparm[10] = iparm[12] = 0 if spd else 1  # scaling and matching for saddle points
        iparm[17] = -1  # report the factor's nonzeros (factor_entries: vfem.memory's model)
        iparm[34] = 1  # zero-based indices
        self._iparm = iparm
        self._perm = np.zeros(self.n, dtype=np.int32)
        self.trailing_inverse = None
        m = 0
        whole = None
        if trailing is not None and len(trailing) == self.n and spd:
            # every dof trailing (a body whose every free dof is a contact dof: one layer of
            # elements touched on both faces, a tiny body): the flexibility is the whole
            # inverse, taken dense below; PARDISO's Schur mode on the whole matrix read
            # outside its arrays (a segmentation fault in mkl_pds_lp64_permutetips in about
            # half the runs of one test sequence, MKL 2025; issue 40)
            whole, trailing = np.asarray(trailing, dtype=int), None  # (in the order given)
        if trailing is not None and len(trailing) and spd:
            trailing = np.asarray(trailing, dtype=int)
            self._perm[trailing] = 1
            iparm[35] = 2  # Schur complement on the marked dofs, returned dense in x
            m = len(trailing)
        self._marked = self._perm.copy()  # PARDISO writes into perm
        x = np.zeros(max(self.n, m * m))
        if self._same_pattern(analysis):
            # the same sparsity and Schur set (a body's tangent in the next iteration): take
            # over the analysis, whose ordering (METIS, 4/5 of the time of a factorization
            # of a few thousand dofs) is the same, and factorize the new values (phase 22)
            self._pt, analysis._pt = analysis._pt, None
            self._iparm = iparm = analysis._iparm
            self._call(22, np.zeros(self.n), x, 1)
        else:
            self._call(12, np.zeros(self.n), x, 1)
        self.factor_entries = int(iparm[17])
        #: PARDISO's own count of the memory its factorization keeps (``iparm[15]``, permanent,
        #: and ``iparm[16]``, the factors, in KiB): what vfem.memory's 3D bytes per entry fit
        self.factor_bytes = 1024 * (int(iparm[15]) + int(iparm[16]))
        if m:
            # rows and columns of the Schur complement in increasing dof order
            rank = np.argsort(np.argsort(trailing))
            with dense_threads(m):
                inv = spd_inverse_in_place(x[: m * m].reshape(m, m))  # in PARDISO's output
            del x
            if not np.array_equal(rank, np.arange(m)):
                inv = inv[np.ix_(rank, rank)]
            self.trailing_inverse = inv
        if whole is not None:  # (the same numbers the Schur complement's inverse would be)
            dense = np.ascontiguousarray(sp.csr_matrix(A)[whole][:, whole].toarray(),
                                         dtype=float)
            with dense_threads(len(dense)):
                self.trailing_inverse = spd_inverse_in_place(dense)

    def _same_pattern(self, other: PardisoFactorization | None) -> bool:
        """Whether ``other`` still holds an analysis that fits this matrix."""
        return (isinstance(other, PardisoFactorization) and other._pt is not None
                and other._mtype == self._mtype and other.n == self.n
                and np.array_equal(other._ia, self._ia) and np.array_equal(other._ja, self._ja)
                and np.array_equal(other._marked, self._marked))

    def _call(self, phase: int, b: np.ndarray, x: np.ndarray, nrhs: int) -> None:
        if self._pt is None:
            raise RuntimeError("this PARDISO factorization was handed on to a later one "
                               "(analysis=) and can no longer solve")
        small = self.n < ONE_THREAD_BELOW  # every phase of this matrix alike
        local = _local_threads() if small and sparse_threads() > 1 else None
        previous = local(1) if local is not None else None
        try:
            self._pardiso(phase, b, x, nrhs)
        finally:
            if local is not None:
                local(previous)

    def _pardiso(self, phase: int, b: np.ndarray, x: np.ndarray, nrhs: int) -> None:
        err = np.zeros(1, dtype=np.int32)
        _library()(self._pt.ctypes.data_as(_P64), _i32(1).ctypes.data_as(_P32),
                   _i32(1).ctypes.data_as(_P32), _i32(self._mtype).ctypes.data_as(_P32),
                   _i32(phase).ctypes.data_as(_P32), _i32(self.n).ctypes.data_as(_P32),
                   self._a.ctypes.data, self._ia.ctypes.data_as(_P32),
                   self._ja.ctypes.data_as(_P32), self._perm.ctypes.data_as(_P32),
                   _i32(nrhs).ctypes.data_as(_P32), self._iparm.ctypes.data_as(_P32),
                   _i32(0).ctypes.data_as(_P32), b.ctypes.data, x.ctypes.data,
                   err.ctypes.data_as(_P32))
        if err[0] != 0:
            what = ERRORS.get(int(err[0]), "unknown error")
            raise np.linalg.LinAlgError(f"PARDISO phase {phase} failed: {what} (error "
                                        f"{int(err[0])})")

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asfortranarray(b, dtype=float)
        nrhs = 1 if b.ndim == 1 else b.shape[1]
        x = np.zeros_like(b)
        self._call(33, b, x, nrhs)
        return x

    @property
    def cholesky(self) -> bool:
        """Whether this is a Cholesky factorization K = P^T L L^T P with no Schur complement
        kept: what :meth:`forward_solve` needs."""
        return self._mtype == 2 and int(self._iparm[35]) == 0

    def forward_solve(self, b: np.ndarray) -> np.ndarray:
        """L^-1 P ``b`` of a Cholesky factorization (:attr:`cholesky`): the forward half of a
        solve alone (PARDISO's phase 331), so that f^T K^-1 f = |L^-1 P f|^2 at half a
        back-substitution's work (the matrix-free side choice's compliances, issue 40)."""
        if not self.cholesky:
            raise ValueError("forward_solve needs a Cholesky factorization without a Schur "
                             "complement")
        b = np.asfortranarray(b, dtype=float)
        nrhs = 1 if b.ndim == 1 else b.shape[1]
        y = np.zeros_like(b)
        self._call(331, b, y, nrhs)
        return y

    def __del__(self):
        try:
            if self._pt is not None:  # not handed on
                self._call(-1, np.zeros(1), np.zeros(1), 1)  # release PARDISO's memory
        except Exception:  # noqa: BLE001 - interpreter shutting down, or never factorized
            pass
