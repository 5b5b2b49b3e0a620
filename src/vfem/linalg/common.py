"""What the backends share: the inverse of the Schur complement on the contact dofs."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla


def _potri_upper(F: np.ndarray) -> np.ndarray:
    """The inverse of the symmetric positive definite matrix whose upper triangle is that of
    the Fortran-ordered ``F`` (Cholesky, LAPACK potrf then potri, over ``F`` where LAPACK's
    wrapper can): valid in the upper triangle of what it returns."""
    c, info = sla.lapack.dpotrf(F, lower=False, overwrite_a=True, clean=True)
    if info != 0:
        raise np.linalg.LinAlgError(
            f"the stiffness on the contact dofs is not positive definite (LAPACK potrf info "
            f"{info}); is the body held?")
    inv, info = sla.lapack.dpotri(c, lower=False, overwrite_c=True)
    if info != 0:
        raise np.linalg.LinAlgError(f"inverting the contact stiffness failed (potri info {info})")
    return inv


def spd_inverse(S: np.ndarray) -> np.ndarray:
    """The inverse of a symmetric positive definite dense matrix (Cholesky, LAPACK potri),
    symmetric to the last bit; about twice as fast as a general inverse."""
    inv = _potri_upper(np.array(S, dtype=float, order="F"))
    return np.triu(inv) + np.triu(inv, 1).T


def mirror(A: np.ndarray, from_upper: bool, block: int = 1024) -> None:
    """Copy one triangle of the square C-ordered ``A`` onto the other, in place, block by block
    (no temporary the size of ``A``): the upper onto the lower with ``from_upper``, else the
    lower onto the upper."""
    m = len(A)
    for j in range(0, m, block):
        e = min(j + block, m)
        if from_upper:
            A[e:, j:e] = A[j:e, e:].T
        else:
            A[j:e, e:] = A[e:, j:e].T
        D = A[j:e, j:e]
        D[...] = (np.triu(D) + np.triu(D, 1).T) if from_upper else (np.tril(D) + np.tril(D, -1).T)


def spd_inverse_in_place(S: np.ndarray) -> np.ndarray:
    """:func:`spd_inverse` of the symmetric positive definite ``S`` (C-ordered, its upper
    triangle read) computed in ``S``'s own memory, which it returns: the same LAPACK calls on
    the same values, so the same bits, without the three or four dense copies (issue 19, item 4:
    a long contact surface's dense block is the set-up's peak memory)."""
    if not (S.flags.c_contiguous and S.dtype == np.float64):
        return spd_inverse(np.triu(S) + np.triu(S, 1).T)
    mirror(S, from_upper=True)
    F = S.T  # Fortran-ordered, the same values (S is symmetric now)
    inv = _potri_upper(F)
    if not np.shares_memory(inv, S):  # LAPACK's wrapper copied after all
        F[...] = inv
    # the inverse is in F's upper triangle, which is S's lower
    mirror(S, from_upper=False)
    return S
