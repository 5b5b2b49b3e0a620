"""The platen's bordered system, which every formulation's compatibility correction solves
(:func:`bordered_solve`), and the dense pair matrix's factors kept while it recurs
(:class:`ReusedFactor`): the solvers' dense linear algebra, below the formulations, so that
they, the complementarity solver and the matrix-free operator
(:mod:`vfem.contact.solvers.matrix_free`) share it without importing each other."""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...threads import dense_threads


def bordered_solve(W: np.ndarray, column: np.ndarray, row: np.ndarray, corner: float,
                   rhs: np.ndarray, extra: float, lu_first: bool = False
                   ) -> tuple[np.ndarray, float]:
    """The corrections ``x`` and the platen motion ``d`` from the bordered system

        [ W    column ] [x]   [rhs  ]
        [ row  corner ] [d] = [extra]

    ``W``: the compatibility conditions' flexibility (penetration change per unit force or
    traction value at the corrected nodes, eq. 4.2.4 in matrix form); ``column``: their change
    per unit platen motion; ``row``: the platen's reaction per unit correction; ``corner``: the
    platen's own stiffness (zero for a body only contact holds); ``extra``: the force the platen
    still lacks. Least squares (the system may be singular: a platen body without a node in
    contact); ``lu_first``: an LU solve first, least squares (an SVD, ten times dearer) only
    where that fails.
    """
    m = len(rhs)
    A = bordered_matrix(W, column, row, corner)
    b = np.concatenate([rhs, [extra]])
    if lu_first:
        try:
            sol = np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            sol = np.linalg.lstsq(A, b, rcond=None)[0]
    else:
        sol = np.linalg.lstsq(A, b, rcond=None)[0]
    return sol[:m], float(sol[m])


def bordered_matrix(W: np.ndarray, column: np.ndarray, row: np.ndarray, corner: float
                    ) -> np.ndarray:
    """The matrix of :func:`bordered_solve`'s system."""
    m = len(W)
    A = np.zeros((m + 1, m + 1))
    A[:m, :m] = W
    A[:m, m] = column
    A[m, :m] = row
    A[m, m] = corner
    return A


class ReusedFactor:
    """The LU factors of the last matrix solved, kept for as long as the matrix recurs.

    Under small kinematics the paired variant's pair matrix over an active set is the same
    whenever that set recurs (its flexibility over every pair node is fixed): in the
    iterations that only adjust the traction values, and in the steps whose contact set holds.
    It is factorized when the set changes, not at every solve (issue 19, item 4: the dense solve
    is O(m^3), seconds at a few thousand nodes). Partial pivoting as ``numpy.linalg.solve``.
    """

    def __init__(self):
        self.key = None
        self.factors = None

    def solve_sparse(self, key, matrix, b: np.ndarray) -> np.ndarray | None:
        """:meth:`solve` for a sparse ``matrix()``: SuperLU's factors (its fill-reducing
        ordering, partial pivoting) kept while ``key`` recurs; None when singular."""
        key = ("sparse", key)  # (never a dense factorization's key)
        if key != self.key:
            self.key = None
            try:
                self.factors = spla.splu(sp.csc_matrix(matrix()))
            except RuntimeError:  # "Factor is exactly singular"
                self.factors = None
            self.key = key
        if self.factors is None:
            return None
        return self.factors.solve(b)

    def solve(self, key, matrix, b: np.ndarray) -> np.ndarray | None:
        """The solution of ``matrix() x = b``, ``matrix`` called only when ``key`` is new;
        None when the matrix is singular (an exactly zero pivot)."""
        if key != self.key:
            A = matrix()
            with dense_threads(len(A)), warnings.catch_warnings():
                warnings.simplefilter("ignore", sla.LinAlgWarning)  # singular: None, below
                lu, piv = sla.lu_factor(A, check_finite=False, overwrite_a=True)
            self.key = key
            self.factors = None if (np.diag(lu) == 0.0).any() else (lu, piv)
        if self.factors is None:
            return None
        return sla.lu_solve(self.factors, b, check_finite=False)
