"""What the invariants read of 2D bodies (:class:`~vfem.contact.invariants.kind.SurfaceKind`
``PLANE``): their boundary polygons (:mod:`.polygon`), small kinematics' linearised reading of a
depth (:func:`linearised_depth`, invariant (b)) and the tension measures (:func:`tension`,
invariant (c), nodal and consistent: :mod:`vfem.contact.invariants.check`'s docstring). The 3D
counterparts are in :mod:`.check3d`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..search import project_points
from .check3d import CORNER_ANGLE
from .kind import SurfaceKind
from .measures import nodal_tension
from .polygon import _Boundary, _Polygon, _scatter_add

if TYPE_CHECKING:
    from ...bodies import Body


def linearised_depth(reference: list[_Polygon], i: int, j: int, node: np.ndarray,
                     cur: list[_Polygon]) -> tuple[np.ndarray, np.ndarray]:
    """Small kinematics: the depth of body i's boundary ``node`` (local numbers) into body
    j as linear theory reads it. With X_c the closest point on j's undeformed surface and
    u_c the displacement there (linear along the segment), r = X + u - (X_c + u_c) is the
    node's offset from it; the depth is -n . r with n the outward normal of the segment,
    and where X_c is a vertex, |r| with the sign of -r . (the sum of the vertex's two
    normals): a node beside a corner is not read along the extension of one of its
    facets. A node that lies on a vertex of j (distance 0: a tie) is read against the
    facet that faces its own surface (the face of a punch, not its side). Off the
    vertices the depth is the smaller of the readings along j's facet normal and along
    i's own outward normal (the formulation may measure along either, or between them;
    after a slip they differ by the slip times the angle between the surfaces).

    Returns the depth and its second-order allowance: the slip along j's facet times the
    angle the facet has turned through (linear theory holds the gap at the material point
    the node faced undeformed, and cannot do better; measured on the wedge, 30 % strain:
    a slip of 1.9e-3 on a facet turned 0.023 rad put a plate node 2.4e-5 inside). The slip
    is counted from the closest point plus the undeformed distance times the tangent of the
    angle between the surfaces (the material point faced along the node's own normal)."""
    ri, rj = reference[i], reference[j]
    keep = rj.surface
    seg_nodes = rj.b.segments[keep]
    A, B = (e[keep] for e in rj.ends)
    normals = rj.unit_normals[keep]
    vertex_normal = rj._get("surface_vertex_normals", lambda: _scatter_add(
        len(rj.x), seg_nodes, normals))
    # a node on a vertex of j's surface (the block's node under a punch's corner) is read
    # against the facet that faces its own surface, not the other one through the vertex
    seg, t, dist, tf = project_points(ri.x[node], A, B, point_normals=ri.normals[node],
                                      free=True)
    c = A[seg] + t[:, None] * (B[seg] - A[seg])
    uj = cur[j].x - rj.x
    ends = seg_nodes[seg]
    uc = (1 - t)[:, None] * uj[ends[:, 0]] + t[:, None] * uj[ends[:, 1]]
    r = cur[i].x[node] - (c + uc)
    # linear theory measures the gap along one normal per pair; which one (j's facet's,
    # i's own, or a blend of the two, as the paired formulation's common normal) is a
    # choice of the formulation, and after a slip s along surfaces that meet at an angle
    # the readings differ by s times that angle: a penetration counts only if both
    # surfaces' normals see it
    # (not along i's own normal at a convex corner of i, turning by more than
    # CORNER_ANGLE: its nodal normal is only a bisector there, along which no contact is
    # measured, and a slide along j's facet read along it is a large false gap; a block's
    # corner slid 0.016 along a quarter disk's flank, 1.3e-5 inside it, read 7.4e-3 outside)
    own = np.einsum("ij,ij->i", r, ri.normals[node])
    own[ri.turning[node] > CORNER_ANGLE] = np.inf
    depth = np.minimum(-np.einsum("ij,ij->i", r, normals[seg]), own)
    # or along j's smoothed normal there (its vertex normals, the mean of the adjacent
    # facets' unit normals, interpolated along the facet: the usual normal field of
    # node-to-segment contact, tilted off a straight facet next to a kink)
    unit = vertex_normal / np.maximum(np.linalg.norm(vertex_normal, axis=1), 1e-300)[:, None]
    tt = np.clip(t, 0.0, 1.0)[:, None]
    smooth = (1 - tt) * unit[ends[:, 0]] + tt * unit[ends[:, 1]]
    smooth /= np.maximum(np.linalg.norm(smooth, axis=1), 1e-300)[:, None]
    depth = np.minimum(depth, -np.einsum("ij,ij->i", r, smooth))
    at = np.where(t <= 0, ends[:, 0], ends[:, 1])
    # beside a vertex: outside the strip of the nearest facet (a node right under a vertex
    # of a straight stretch lies on both strips' edges and is read along the normal; read
    # as a distance, its slip along the surface would count as depth)
    vertex = ((tf < -1e-9) | (tf > 1 + 1e-9)) & (dist > 1e-12 * np.maximum(
        np.linalg.norm(B[seg] - A[seg], axis=1), 1e-300))
    outside = np.einsum("ij,ij->i", r, vertex_normal[at]) > 0
    depth[vertex] = np.where(outside, -1.0, 1.0)[vertex] * np.linalg.norm(r, axis=1)[vertex]
    # second order: linear theory holds the gap at the material point the node faced
    # undeformed; after a slip s along a facet that has turned through theta, the node
    # sits s * theta off the facet as it now lies, whichever normal is read
    d0 = B[seg] - A[seg]
    d1 = cur[j].x[ends[:, 1]] - cur[j].x[ends[:, 0]]
    theta = np.abs(np.arctan2(d0[:, 0] * d1[:, 1] - d0[:, 1] * d1[:, 0],
                              np.einsum("ij,ij->i", d0, d1)))
    slip = np.abs(np.einsum("ij,ij->i", r, d0)) / np.maximum(
        np.linalg.norm(d0, axis=1), 1e-300)
    # the material point a formulation pairs the node with lies between the closest point
    # and the point along the node's own normal: dist * tan(beta) apart, beta the angle
    # between the two surfaces' normals
    cos_beta = np.clip(-np.einsum("ij,ij->i", normals[seg], ri.normals[node]), 1e-3, 1.0)
    slip = slip + dist * np.sqrt(1.0 - cos_beta**2) / cos_beta
    # and a quadratic facet's sag: the formulation interpolates over it quadratically, this
    # check linearly over its two half chords; they part by up to an eighth of the
    # displacements' second difference |u_a - 2 u_m + u_b| / 8 along the normal (random
    # quadratic models 2d-75, 2d-122, 2d-297 stopped 13-27 % beyond a tolerance of 3e-7)
    sag = np.zeros(len(node))
    nf = len(rj.b.facets)
    if rj.b.facets.shape[1] == 3:
        f = rj.b.facets[keep[seg] % nf]
        bend = uj[f[:, 0]] - 2.0 * uj[f[:, 2]] + uj[f[:, 1]]
        sag = 0.125 * np.abs(np.einsum("ij,ij->i", bend, normals[seg]))
    return depth, np.where(vertex, 0.0, slip * theta) + sag


def tension(bodies: list[Body], tolerance: Callable[[Body], float], least: float,
            F: list[np.ndarray], own: list[_Polygon], measure: str = "nodal"
            ) -> tuple[float, float, dict | None]:
    """(c) on 2D bodies, by the ``measure`` (``"nodal"`` or ``"consistent"``): the largest
    tensile measure relative to the model's largest (0 where none), its tolerance and where it
    is (``{"body", "node", "value"}``, or None), as :func:`.check3d.tension` returns them.
    ``tolerance(body)``: a body's tolerance; ``least``: the tolerance where no body sets one
    (the consistent measure's, for every body)."""
    if measure == "consistent":
        return _tension_consistent(bodies, least, F, own)
    return nodal_tension(bodies, tolerance, least, F, own, _nodal_measure)


def _nodal_measure(g: _Polygon, f: np.ndarray) -> np.ndarray:
    """F·n at every node of a 2D boundary (its own normals); on quadratic facets a vertex with
    the midpoints of its facets (weights 1 - phi_far_end >= 0 on each facet), a midpoint alone
    (4 t (1 - t) >= 0)."""
    fn = np.einsum("ij,ij->i", f, g.normals)
    if g.b.facets.shape[1] == 3:
        mid = g.b.facets[:, 2]
        patch = fn.copy()
        for col in (0, 1):
            np.add.at(patch, g.b.facets[:, col], fn[mid])
        patch[mid] = fn[mid]
        fn = patch
    return fn


def _tension_consistent(bodies: list[Body], least: float, F: list[np.ndarray],
                        own: list[_Polygon]) -> tuple[float, float, dict | None]:
    """The consistent measure (kept for comparison): the pressure recovered by the boundary
    mass matrix over the facets whose nodes all carry force, its most negative value."""
    recovered = []
    for b, f, g in zip(bodies, F, own):
        fn = np.einsum("ij,ij->i", f, g.normals)
        carries = np.linalg.norm(f, axis=1) > 0
        # the facets whose every node carries force: where the traction is not zero
        fac = g.b.facets[carries[g.b.facets].all(axis=1)]
        if not len(fac):
            continue
        used = np.unique(fac)
        local = np.full(len(f), -1)
        local[used] = np.arange(len(used))
        M = _boundary_mass(b.section, g.x, fac, local, len(used))
        p = spla.spsolve(M.tocsc(), -fn[used])
        recovered.append((b, g.b.nodes[used], np.atleast_1d(p)))
    scale = max((float(np.abs(p).max(initial=0.0)) for _, _, p in recovered), default=0.0)
    if scale == 0:
        return 0.0, least, None
    worst = None
    for b, nodes, p in recovered:
        k = int(np.argmin(p))
        if p[k] < 0 and (worst is None or -p[k] > worst[0]):
            worst = (float(-p[k]), b.name, int(nodes[k]), float(p[k]))
    if worst is None:
        return 0.0, least, None
    return worst[0] / scale, least, {"body": worst[1], "node": worst[2], "value": worst[3]}


def _boundary_mass(section, x: np.ndarray, facets: np.ndarray, local: np.ndarray, n: int
                   ) -> sp.csr_matrix:
    """The mass matrix ∫φφᵀ over straight boundary facets (2 or 3 nodes: ends, midpoint),
    in the measure of the body's section (:meth:`~vfem.bodies.section.Section.facet_mass`)."""
    k = facets.shape[1]
    rows = np.repeat(local[facets], k, axis=1).ravel()
    cols = np.tile(local[facets], (1, k)).ravel()
    vals = section.facet_mass(x, facets).ravel()
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


#: 2D bodies: boundary polygons, both tension measures, every body read at every state
PLANE = SurfaceKind(name="2D", boundary=_Boundary.of, surface=_Polygon,
                    linearised_depth=linearised_depth, tension=tension,
                    tension_measures=("nodal", "consistent"), skips_untouched=False)
