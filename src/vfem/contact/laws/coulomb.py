"""Coulomb's law node by node, in any dimension (thesis §1.10: friction "modular", a law of its
own beside the contact formulation): the magnitudes of tangential vectors (along the tangents
the geometry gives, :func:`vfem.contact.geometry.tangents`), and the status of each node —
free, stuck within the cone |s| <= mu q, or slipping on it. A tangential array is
``(n, ntan)`` in any dimension: one column per tangent (one in 2D, two in 3D).
"""

from __future__ import annotations

import numpy as np

#: a node's tangential traction counts as on the Coulomb cone when it is within this fraction
#: of mu q of it (the cone is met exactly by the correction; round-off only)
CONE_TOLERANCE = 1e-9


def magnitudes(a: np.ndarray) -> np.ndarray:
    """Per node, the length of a tangential array's (n, ntan) vector: with one tangent |a|
    (the same bits as ``np.abs``), else the row norm."""
    if a.shape[1] == 1:
        return np.abs(a[:, 0])
    return np.sqrt(np.einsum("ij,ij->i", a, a))


def tangent_by_tangent(a: np.ndarray) -> np.ndarray:
    """A tangential array (n, ntan) in the pair matrix's order: tangent by tangent."""
    return a.T.ravel()


def coulomb_status(q: np.ndarray, s: np.ndarray, mu: float) -> np.ndarray:
    """Per node: 0 no contact (q <= 0), 1 stick (|s| inside the cone mu q), 2 slip (on it); s
    (n, ntan)."""
    status = np.zeros(len(q), dtype=int)
    on = q > 0
    slipping = magnitudes(s) >= (1.0 - CONE_TOLERANCE) * mu * q
    status[on & ~slipping] = 1
    status[on & slipping] = 2
    return status
