"""What the backends share: the inverse of the Schur complement on the contact dofs."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla


def spd_inverse(S: np.ndarray) -> np.ndarray:
    """The inverse of a symmetric positive definite dense matrix (Cholesky, LAPACK potri),
    symmetric to the last bit; about twice as fast as a general inverse."""
    S = np.array(S, dtype=float, order="F")
    c, info = sla.lapack.dpotrf(S, lower=False, overwrite_a=True, clean=True)
    if info != 0:
        raise np.linalg.LinAlgError(
            f"the stiffness on the contact dofs is not positive definite (LAPACK potrf info "
            f"{info}); is the body held?")
    inv, info = sla.lapack.dpotri(c, lower=False, overwrite_c=True)
    if info != 0:
        raise np.linalg.LinAlgError(f"inverting the contact stiffness failed (potri info {info})")
    return np.triu(inv) + np.triu(inv, 1).T

