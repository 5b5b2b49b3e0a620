"""CHOLMOD (SuiteSparse) through scikit-sparse: supernodal Cholesky.

scikit-sparse 0.4.16 builds against Debian's SuiteSparse (``libsuitesparse-dev``); CHOLMOD is
only as fast as the BLAS under it (OpenBLAS: ``libopenblas0-pthread``, several times faster than
the reference BLAS). With ``trailing`` dofs: CHOLMOD's own fill-reducing order with those dofs
moved last, a factorization in that order, and the Schur complement ``S = L22 L22^T`` from the
trailing block of the factor.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .common import spd_inverse


def available() -> bool:
    try:
        import sksparse.cholmod  # noqa: F401
    except Exception:  # noqa: BLE001 - not installed, or its SuiteSparse not loadable
        return False
    return True


class CholmodFactorization:
    """CHOLMOD's Cholesky factorization; positive definite matrices only."""

    name = "cholmod"

    def __init__(self, A: sp.spmatrix, trailing: np.ndarray | None = None,
                 groups: np.ndarray | None = None, spd: bool = True):
        from sksparse.cholmod import CholmodError

        if not spd:
            raise ValueError("cholmod factorizes positive definite matrices only")
        try:
            self._factorize(A, trailing)
        except CholmodError as exc:  # not positive definite, out of memory, ...
            raise np.linalg.LinAlgError(str(exc)) from exc

    def _factorize(self, A: sp.spmatrix, trailing: np.ndarray | None) -> None:
        from sksparse.cholmod import analyze, cholesky

        self.shape = A.shape
        A = sp.csc_matrix(A)
        self.trailing_inverse = None
        self.order = None
        if trailing is None or len(trailing) == 0:
            self._factor = cholesky(A)
            return
        trailing = np.asarray(trailing, dtype=int)
        n, m = A.shape[0], len(trailing)
        P = analyze(A).P()
        last = np.zeros(n, dtype=bool)
        last[trailing] = True
        order = np.concatenate([P[~last[P]], trailing])
        self.order = order
        self._factor = cholesky(A[order][:, order].tocsc(), ordering_method="natural")
        L22 = self._factor.L()[n - m:, n - m:].toarray()
        self.trailing_inverse = spd_inverse(L22 @ L22.T)

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        if self.order is None:
            return self._factor(b)
        x = np.empty_like(b)
        x[self.order] = self._factor(b[self.order])
        return x
