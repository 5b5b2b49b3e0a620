"""The platen's bordered system, which every formulation's compatibility correction solves
(:func:`bordered_solve`): a leaf module, so that the formulations and the matrix-free operator
(:mod:`vfem.contact.matrix_free`) share it without importing each other."""

from __future__ import annotations

import numpy as np


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
