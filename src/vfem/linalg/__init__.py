"""Sparse factorization behind one small interface.

``factorize(A)`` returns an object with ``solve(b)`` for a vector or a block of columns. SciPy's
SuperLU is always there; faster backends plug in here (issue: speed) without the rest of vfem
knowing which one runs.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

log = logging.getLogger(__name__)


class SuperLUFactorization:
    """SciPy SuperLU with a symmetric ordering (the stiffness is symmetric positive definite)."""

    name = "superlu"

    def __init__(self, A: sp.spmatrix):
        self.shape = A.shape
        self._lu = spla.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A",
                             options={"SymmetricMode": True})

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(np.asarray(b, dtype=float))


BACKENDS = {"superlu": SuperLUFactorization}


def factorize(A: sp.spmatrix, backend: str = "superlu"):
    """Factorize the sparse matrix ``A`` with the named backend."""
    try:
        cls = BACKENDS[backend]
    except KeyError:
        from ..errors import InputError

        raise InputError(
            f"unknown linear solver {backend!r}; available: {', '.join(sorted(BACKENDS))}"
        ) from None
    return cls(A)
