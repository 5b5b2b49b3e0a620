"""The tangent basis at the nodes of a contact surface (issue 38: the dimension lives in the
geometry): dim - 1 unit tangents per node, from its unit normal, which the friction reads its
tangential traction values and slips along (:mod:`vfem.contact.laws`)."""

from __future__ import annotations

import numpy as np


def tangents(normal: np.ndarray, axes: np.ndarray | None = None) -> list[np.ndarray]:
    """The unit tangent directions at nodes with unit ``normal`` (n, dim), one per direction of
    the tangent space (dim - 1 of them), which is all the tangential code reads.

    2D: the normal turned by +90 degrees, (-n_y, n_x). 3D (issue 21, C13): ``t1`` the unit
    projection on the tangent plane of the global axis least aligned with the normal
    (:func:`tangent_axes`; or ``axes``, one per node, where given), ``t2 = n x t1``. Taken from
    the undeformed normals, so a node's tangents are fixed; where a symmetry plane through the
    contact (a roller) holds an axis, the axis is the tangent ``t1`` (a normal within the plane
    has no component along it) and the plane's motion stays one tangential unknown, which
    :data:`~vfem.contact.formulations.friction.HELD` finds. Under large kinematics the normals turn:
    ``axes`` kept from the undeformed ones make the tangents a smooth function of the current normal
    (the least aligned axis itself jumps between two axes as a normal near a third tilts)."""
    if normal.shape[1] == 2:
        return [np.column_stack([-normal[:, 1], normal[:, 0]])]
    axis = tangent_axes(normal) if axes is None else axes
    rows = np.arange(len(normal))
    t1 = -normal[rows, axis, None] * normal
    t1[rows, axis] += 1.0
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    return [t1, np.cross(normal, t1)]


def tangent_axes(normal: np.ndarray) -> np.ndarray:
    """3D: per node, the global axis least aligned with its unit ``normal`` (ties within 1e-12:
    the lowest axis), whose projection on the tangent plane is the first tangent
    (:func:`tangents`)."""
    size = np.abs(normal)
    return np.argmax(size <= size.min(axis=1, keepdims=True) + 1e-12, axis=1)
