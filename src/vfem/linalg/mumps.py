"""MUMPS through the ``python-mumps`` package (sequential MUMPS, ``libmumps-seq-dev``).

python-mumps drives MUMPS's unsymmetric LU only, so it does twice the work of a Cholesky on the
stiffness; what it adds is MUMPS's Schur complement: with ``trailing`` dofs one factorization
returns the dense Schur complement on them, and full solves go through it.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .common import spd_inverse


def available() -> bool:
    try:
        import mumps  # noqa: F401
    except Exception:  # noqa: BLE001 - not installed, or libmumps not loadable
        return False
    return True


class MumpsFactorization:
    """MUMPS's LU factorization, with its Schur complement on the trailing dofs."""

    name = "mumps"

    def __init__(self, A: sp.spmatrix, trailing: np.ndarray | None = None,
                 groups: np.ndarray | None = None, spd: bool = True):
        import mumps

        self.shape = A.shape
        A = sp.coo_matrix(A)
        self.trailing_inverse = None
        self._ctx = mumps.Context()
        self._schur = trailing is not None and len(trailing) > 0
        if not self._schur:
            self._ctx.factor(A)
            return
        S = self._ctx.schur(np.asarray(trailing, dtype=int), A)
        self.trailing_inverse = spd_inverse(0.5 * (S + S.T)) if spd else np.linalg.inv(S)

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        if self._schur:  # python-mumps solves one right-hand side at a time here
            if b.ndim == 1:
                return np.asarray(self._ctx.solve_schur(b), dtype=float)
            return np.column_stack([np.asarray(self._ctx.solve_schur(c), dtype=float)
                                    for c in b.T])
        return np.asarray(self._ctx.solve(b), dtype=float)
