"""What a contact facet is: the facet-kind layer of the contact surfaces (issue 21, C4 of the 3D
plan).

Everything that knows the shape of a facet — its shape functions and their derivatives, its
outward normal, the closest point on a set of such facets, where a patch of them ends and when a
point lies beyond it, where a facet is read against the other surface, and the quadrature of the
overlap of two surfaces for the exact transfer — lives behind one object, a :class:`FacetKind`,
held by each :class:`~vfem.contact.geometry.surface.ContactSurface` as ``kind``. The contact core
(pairing, paired, large, large friction, transfer) reaches facets through it (or through the
surface's methods that delegate to it), so it never branches on the dimension.

* :class:`Segment` (``order`` 1 or 2): the 2- and 3-node facets of a 2D surface, straight or a
  parabola through the midpoint. Local coordinates ``xi`` are one number per point, 0 at the
  facet's first node and 1 at its second.

* :class:`Triangle` and :class:`Quad` (``order`` 1 or 2): the 3-/6-node and 4-/9-node facets
  of a 3D surface (T3, T6, Q4, Q9 of :mod:`vfem.contact.geometry.facets3d`, whose kernels they
  call), ``xi`` two numbers per point in scikit-fem's reference domains. Their patch boundary is an
  edge table. Their overlap quadrature is :mod:`vfem.contact.geometry.overlap3d`'s (linear facets
  only); the friction anchor's material points are not theirs yet (C13 of the 3D plan).

Callers treat ``xi`` and the patch boundary as opaque.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import scipy.sparse as sp
from skfem.quadrature import get_quadrature
from skfem.refdom import RefLine

from ..search import normal_of_tangent, outward_normals, project_points
from . import closest3d, facets3d

#: Where a facet is read against the other surface
#: (:func:`~vfem.contact.geometry.pairing.read_facets`), in a segment's local coordinate: its
#: midpoint and near its ends. A facet partly under the other body, its midpoint just past the
#: other's corner, faces that corner's side at its midpoint only (read there alone, such a facet was
#: dropped and the contact missed altogether: a punch overhanging a block's edge,
#: tests/test_fuzz_placement.py).
FACET_READINGS = (0.5, 0.05, 0.95)


class FacetKind(Protocol):
    """The interface of a kind of facet (:class:`Segment`, :class:`Triangle`, :class:`Quad`):
    a protocol each kind keeps, not a class they derive from.

    Arrays: ``x`` (n, dim) nodal positions of a surface (local node numbers), ``facets`` (nf,
    nodes) its facets' local node numbers (oriented: the outward normal is the kind's),
    ``seg`` facet numbers (rows of ``facets``), ``xi`` local coordinates of points on facets
    ((n,) for segments, (n, 2) for triangles and quadrilaterals; opaque to callers).
    """

    #: the dimension of the space (columns of ``x``)
    dim: int
    #: 1 for linear facets, 2 for quadratic ones
    order: int
    #: the vertices of a facet (its first ``corners`` nodes)
    corners: int
    #: the nodes of a facet (the columns of ``facets``)
    nodes: int
    #: the local coordinates at which a facet is read against the other surface, one row each
    readings: np.ndarray
    #: where a corner's shape function integrates to zero over its facet (quadratic triangles,
    #: T6: a uniform pressure puts no force on a corner, and a varying one a force of either
    #: sign), each corner with the midpoints of its two edges, as columns of ``facets``: its
    #: nodal force cannot tell whether it is in contact, nor its tributary read its pressure
    #: (:func:`vfem.contact.formulations.group.quadratic_status`, ``consistent_pressure``); empty
    #: elsewhere
    weightless_corners: tuple[tuple[int, int, int], ...] = ()

    def shape(self, xi: np.ndarray) -> np.ndarray:
        """(n, nodes) shape functions at ``xi``, in the column order of ``facets``."""
        ...

    def derivatives(self, xi: np.ndarray) -> np.ndarray:
        """Derivatives of :meth:`shape` with respect to ``xi``."""
        ...

    def traction_shape(self, xi: np.ndarray) -> np.ndarray:
        """(n, nodes) the functions that interpolate a contact traction from its nodal values
        (the paired variant's unknowns, thesis §4.4: the traction varies between the contact
        nodes): by default the facet's own shape functions."""

    def orient(self, p: np.ndarray, fn: np.ndarray, centroid: np.ndarray) -> None:
        """Reorder, in place, the rows of ``fn`` (point numbers of ``p`` (dim, np)) whose
        normal points into their element (``centroid`` (nf, dim)), so every normal is outward."""
        ...

    def curve(self, x: np.ndarray, facets: np.ndarray, xi: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
        """Position and Jacobian dx/dxi at ``xi`` of the facets (rows) ``facets``."""
        ...

    def surface_map(self, x: np.ndarray, facets: np.ndarray, xi: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
        """(pos, jn): position and the Jacobian times the unit outward normal (its norm the
        measure per unit reference measure) at ``xi`` of the facets (rows) ``facets``."""
        ...

    def facet_normals(self, x: np.ndarray, facets: np.ndarray) -> np.ndarray:
        """(nf, dim) unit outward normals of the facets' chords (rows ``facets``)."""
        ...

    def closest(self, points: np.ndarray, x: np.ndarray, facets: np.ndarray, ids: np.ndarray,
                point_normals: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Closest point on the facets ``ids`` (rows of ``facets``) for each point: (facet
        number, xi, distance, unit outward normal there, xi_free: unclamped)."""
        ...

    def strictly_inside(self, xi_free: np.ndarray) -> np.ndarray:
        """Whether unclamped local coordinates lie inside the facet, off its boundary."""
        ...

    def patch_boundary(self, facets: np.ndarray, patch: np.ndarray, nc: int):
        """The boundary of the patch ``patch`` (facet numbers) of a surface of ``nc`` candidate
        nodes, in the form :meth:`beyond` and :meth:`on_boundary` read (opaque to callers)."""
        ...

    def boundary_nodes(self, facets: np.ndarray, boundary, nc: int) -> np.ndarray:
        """(nc,) the candidate nodes on a patch boundary (:meth:`patch_boundary`)."""
        ...

    def beyond(self, facets: np.ndarray, seg: np.ndarray, xi_free: np.ndarray, boundary
               ) -> np.ndarray:
        """Points whose closest point on a patch (on facet ``seg`` at unclamped ``xi_free``) is
        on its boundary and that lie outside the facet there: not over the patch."""
        ...

    def on_boundary(self, facets: np.ndarray, seg: np.ndarray, xi_free: np.ndarray, boundary
                    ) -> np.ndarray:
        """Points whose closest point on a patch is (to 1e-9) a vertex on its boundary."""
        ...

    def overlap_quadrature(self, sf, fpatch: np.ndarray, sc, cpatch: np.ndarray,
                           cnormals: np.ndarray, reach: float, xf: np.ndarray, xc: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Quadrature over the part of patch ``fpatch`` of surface ``sf`` (this kind) that lies
        over patch ``cpatch`` of ``sc`` (nodal normals ``cnormals``; points farther than
        ``reach`` face something else), positions ``xf``, ``xc``: (facet (q,), xi, weight
        (q,)), the weights times the undeformed measure of ``sf``."""
        ...

    def material_points(self, facets: np.ndarray, seg: np.ndarray, interp: np.ndarray
                        ) -> np.ndarray:
        """Points on facets ``seg`` (their interpolation rows ``interp``) as material points
        of the surface (what a friction anchor keeps)."""
        ...

    def material_positions(self, x: np.ndarray, facets: np.ndarray, points: np.ndarray
                           ) -> np.ndarray:
        """Where :meth:`material_points` ``points`` are at positions ``x``."""
        ...


def facet_shape(t: np.ndarray, order: int) -> np.ndarray:
    """(n, order + 1) shape functions of a straight 2- or 3-node facet at local coordinates t:
    the ends (t = 0, 1) first, then the midpoint."""
    if order == 1:
        return np.column_stack([1 - t, t])
    return np.column_stack([(1 - t) * (1 - 2 * t), t * (2 * t - 1), 4 * t * (1 - t)])


def facet_shape_derivative(t: np.ndarray, order: int) -> np.ndarray:
    """(n, order + 1) derivatives d/dt of :func:`facet_shape`."""
    if order == 1:
        return np.column_stack([-np.ones_like(t), np.ones_like(t)])
    return np.column_stack([4 * t - 3, 4 * t - 1, 4 - 8 * t])


_SECOND = np.array([[4.0], [4.0], [-8.0]])  # second derivatives of the 3-node shape functions


class Segment:
    """2- or 3-node facets of a 2D surface (``order`` 1 or 2), oriented so that ``(t_y, -t_x)``
    of the tangent is the outward normal. The patch boundary is (nc,) True at the patch's end
    vertices (vertices on one facet of it)."""

    dim = 2
    corners = 2
    weightless_corners: tuple[tuple[int, int, int], ...] = ()

    def __init__(self, order: int):
        self.order = order
        self.nodes = order + 1
        self.readings = np.asarray(FACET_READINGS, dtype=float)

    def __repr__(self) -> str:
        return f"Segment({self.order})"

    def __eq__(self, other) -> bool:
        return isinstance(other, Segment) and other.order == self.order

    def __hash__(self) -> int:
        return hash(("Segment", self.order))

    def shape(self, xi: np.ndarray) -> np.ndarray:
        return facet_shape(np.asarray(xi, dtype=float), self.order)

    def traction_shape(self, xi: np.ndarray) -> np.ndarray:
        """On a 3-node facet, linear between consecutive nodes (end, midpoint, end: the
        facet's two halves), not the quadratic shape functions (issue 37, item 3).

        **Why**: a quadratic interpolant of nodal values >= 0 dips below zero between them,
        by up to 1/8 of a neighbour's value where a contact zone ends (one node touching at
        first contact: the whole zone ends there), and the nodal forces it gives both bodies
        are then tensile; measured: 26 of 67 quadratic random models stopped on invariant
        (c), "no tension", several at first touch. Piecewise-linear values >= 0 are >= 0
        everywhere, so each vertex's share of the forces (its own plus half of each adjacent
        midpoint's, the integral of the traction against the linear hat) is never tensile. A
        uniform traction is still represented exactly (the hats sum to one), so the patch
        test holds. The same choice as the piecewise-linear multipliers on subdivided
        quadratic facets of the mortar literature (Puso, Laursen and Solberg 2008)."""
        if self.order == 1:
            return self.shape(xi)
        t = np.asarray(xi, dtype=float)
        return np.column_stack([np.maximum(0.0, 1.0 - 2.0 * t), np.maximum(0.0, 2.0 * t - 1.0),
                                1.0 - np.abs(2.0 * t - 1.0)])

    def derivatives(self, xi: np.ndarray) -> np.ndarray:
        return facet_shape_derivative(xi, self.order)

    def orient(self, p: np.ndarray, fn: np.ndarray, centroid: np.ndarray) -> None:
        a, b = p[:, fn[:, 0]].T, p[:, fn[:, 1]].T
        normal = normal_of_tangent(b - a)
        flip = np.einsum("ij,ij->i", normal, 0.5 * (a + b) - centroid) < 0
        fn[flip, :2] = fn[flip][:, 1::-1]

    def curve(self, x, facets, xi):
        nodes = x[facets]  # (n, k, 2)
        pos = np.einsum("nk,nkd->nd", self.shape(xi), nodes)
        tangent = np.einsum("nk,nkd->nd", self.derivatives(xi), nodes)
        return pos, tangent

    def surface_map(self, x, facets, xi):
        pos, tangent = self.curve(x, facets, xi)
        return pos, normal_of_tangent(tangent)

    def facet_normals(self, x, facets):
        return outward_normals(x[facets[:, 0]], x[facets[:, 1]])

    def closest(self, points, x, facets, ids, point_normals=None):
        """The chords give the facet, a first t and ``t_free``, the unclamped coordinate along
        the chord (outside [0, 1]: the point lies beyond that end of the facet); on curved
        facets a few Newton steps then find the closest point on the curve. Ties between facets
        are broken by ``point_normals`` (:func:`~vfem.contact.search.closest.project_points`)."""
        a, b = x[facets[ids, 0]], x[facets[ids, 1]]
        local, t, dist, t_free = project_points(points, a, b, point_normals, free=True)
        seg = ids[local] if len(ids) else local
        pos, tangent = self.curve(x, facets[seg], t)
        if self.order == 2 and len(seg):
            for _ in range(4):
                second = np.einsum("k,nkd->nd", _SECOND[:, 0],
                                   x[facets[seg]])  # d2x/dt2, constant on a facet
                r = pos - points
                f = np.einsum("nd,nd->n", r, tangent)
                df = np.einsum("nd,nd->n", tangent, tangent) + np.einsum("nd,nd->n", r, second)
                t = np.clip(t - f / np.where(df > 0, df, 1.0), 0.0, 1.0)
                pos, tangent = self.curve(x, facets[seg], t)
            dist = np.linalg.norm(points - pos, axis=1)
        normal = normal_of_tangent(tangent)
        normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
        return seg, t, dist, normal, t_free

    def strictly_inside(self, xi_free):
        return (xi_free > 1e-9) & (xi_free < 1 - 1e-9)

    def patch_boundary(self, facets, patch, nc):
        return np.bincount(facets[patch, :2].ravel(), minlength=nc)[:nc] == 1

    def boundary_nodes(self, facets, boundary, nc):
        return boundary

    def beyond(self, facets, seg, xi_free, boundary):
        e = facets[seg]
        return (((xi_free < -1e-9) & boundary[e[:, 0]])
                | ((xi_free > 1 + 1e-9) & boundary[e[:, 1]]))

    def on_boundary(self, facets, seg, xi_free, boundary):
        e = facets[seg]
        return (((xi_free <= 1e-9) & boundary[e[:, 0]])
                | ((xi_free >= 1 - 1e-9) & boundary[e[:, 1]]))

    def overlap_quadrature(self, sf, fpatch, sc, cpatch, cnormals, reach, xf, xc):
        """The fine facets split where the projection onto the coarse patch passes one of its
        vertices (seen along its nodal normal), and 3-node ones at their midpoints, with a
        Gauss rule exact to degree 5 on each piece: exact for the piecewise polynomial
        integrand (degree 4 at most, with quadratic elements) on straight facets. On curved
        (quadratic) facets the points and weights follow the curve; the splits are found on
        the chords. The weights are times the fine side's undeformed length (the traction is
        nominal) and its body's section's weight there (:meth:`ContactSurface.weight`)."""
        fa, fb = xf[sf.facets[:, 0]], xf[sf.facets[:, 1]]
        fa, fb = fa[fpatch], fb[fpatch]
        d = fb - fa
        # the coarse patch's vertices seen along their normals: where they split the fine facets
        verts = np.unique(sc.facets[cpatch, :2])
        vn = cnormals[verts]
        P = xc[verts]
        # solve fa + s d = P + tau vn for every (facet, coarse vertex)
        det = d[:, None, 0] * (-vn[None, :, 1]) - d[:, None, 1] * (-vn[None, :, 0])
        rx = P[None, :, 0] - fa[:, None, 0]
        ry = P[None, :, 1] - fa[:, None, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (rx * (-vn[None, :, 1]) - ry * (-vn[None, :, 0])) / det
            tau = (d[:, None, 0] * ry - d[:, None, 1] * rx) / det
        ok = np.isfinite(s) & (s > 1e-12) & (s < 1 - 1e-12) & (np.abs(tau) < reach)
        X, W = get_quadrature(RefLine, 5)
        xi, w = X[0], W
        # each fine facet's pieces between its ends and its cuts, in order along it (all
        # facets at once: the cuts sorted per row, repeated cuts giving empty pieces that are
        # dropped)
        # (a 3-node facet is also cut at its midpoint, where its traction's slope changes:
        # :meth:`traction_shape`)
        mids = np.full((len(fpatch), self.order - 1), 0.5)
        cuts = np.sort(np.hstack([np.zeros((len(fpatch), 1)), np.ones((len(fpatch), 1)), mids,
                                  np.where(ok, s, np.nan)]), axis=1)  # NaN (no cut) last
        lo, hi = cuts[:, :-1], cuts[:, 1:]
        piece = hi > lo  # False where either is NaN
        row = np.broadcast_to(np.arange(len(fpatch))[:, None], piece.shape)[piece]
        lo, hi = lo[piece], hi[piece]
        sloc = (lo[:, None] + (hi - lo)[:, None] * xi[None, :]).ravel()
        wts = ((hi - lo)[:, None] * w[None, :]).ravel()
        fac = np.repeat(np.asarray(fpatch)[row], len(xi))
        pos, tangent = self.curve(sf.X, sf.facets[fac], sloc)
        # the fine side's undeformed measure: its length times its body's section's weight
        # there (1, or 2πr on a body of revolution: :meth:`ContactSurface.weight`)
        wts = wts * np.linalg.norm(tangent, axis=1) * sf.weight(pos)
        return fac, sloc, wts

    def material_points(self, facets, seg, interp):
        """``facet + t`` (t clipped below 1, so the facet is its integer part)."""
        t = interp[np.arange(len(seg)), facets[seg, 1]]
        t = (t.toarray() if sp.issparse(t) else np.asarray(t)).ravel()
        return seg + np.clip(t, 0.0, 1.0 - 1e-12)

    def material_positions(self, x, facets, points):
        seg = np.floor(points).astype(int)
        t = (points - seg)[:, None]
        ends = facets[seg]
        return (1.0 - t) * x[ends[:, 0]] + t * x[ends[:, 1]]


class _Facet3D:
    """Facets of a 3D surface: the kernels of :mod:`vfem.contact.geometry.facets3d` (``geometry``,
    its :class:`~vfem.contact.geometry.facets3d.FacetShape`) behind the :class:`FacetKind`
    interface. A facet is oriented when its corners run counter-clockwise seen from outside:
    ``x_ξ × x_η`` is then the outward normal. ``xi`` is (n, 2). The patch boundary is an
    (nf, edges) table: True where an edge (in ``geometry.edges``' order) of a patch facet is an
    edge of no other facet of the patch (facets off the patch: all False)."""

    dim = 3
    weightless_corners: tuple[tuple[int, int, int], ...] = ()
    #: the name of the kind (``Triangle``, ``Quad``)
    name = ""
    #: nodes per facet by order
    _NODES: dict[int, int] = {}
    #: the column order of a facet turned over (its normal reversed), by nodes per facet
    _REVERSED: dict[int, tuple[int, ...]] = {}

    def __init__(self, order: int):
        if order not in (1, 2):
            raise ValueError(f"{self.name} facets are of order 1 or 2, got {order!r}")
        self.order = order
        self.nodes = self._NODES[order]
        self.geometry = facets3d.KINDS[self.nodes]
        self.corners = self.geometry.corners
        if order == 2 and self.corners == 3:  # the 6-node triangle: its corners weigh nothing
            self.weightless_corners = tuple(
                (c, *(mid for a, b, mid in self.geometry.edges if c in (a, b)))
                for c in range(3))
        centre = np.asarray(self.geometry.centre)
        # the centre and points 0.9 of the way from it to each corner (2D: 0.5, 0.05, 0.95)
        self.readings = np.vstack([centre, centre + 0.9 * (self.geometry.vertices - centre)])

    def __repr__(self) -> str:
        return f"{self.name}({self.order})"

    def __eq__(self, other) -> bool:
        return type(other) is type(self) and other.order == self.order

    def __hash__(self) -> int:
        return hash((self.name, self.order))

    def shape(self, xi: np.ndarray) -> np.ndarray:
        return facets3d.shape_functions(self.geometry, xi)[0]

    def traction_shape(self, xi: np.ndarray) -> np.ndarray:
        """The facet's own shape functions."""
        return self.shape(xi)

    def derivatives(self, xi: np.ndarray) -> np.ndarray:
        """(n, nodes, 2): d/dξ and d/dη of :meth:`shape`."""
        return facets3d.shape_functions(self.geometry, xi)[1]

    def chord_normals(self, corners: np.ndarray) -> np.ndarray:
        """(nf, 3) unit normals of facets' chords from their corners (nf, corners, 3): a
        triangle's ``(b − a) × (c − a)``, a quadrilateral's diagonals' ``(c − a) × (d − b)``
        (its bilinear normal at the centre)."""
        if self.corners == 3:
            n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        else:
            n = np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1])
        return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]

    def orient(self, p, fn, centroid):
        corners = p[:, fn[:, : self.corners]].transpose(1, 2, 0)  # (nf, corners, 3)
        normal = self.chord_normals(corners)
        flip = np.einsum("ij,ij->i", normal, corners.mean(axis=1) - centroid) < 0
        fn[flip] = fn[flip][:, list(self._REVERSED[self.nodes])]

    def curve(self, x, facets, xi):
        """Position (n, 3) and Jacobian (n, 3, 2) (columns x_ξ, x_η)."""
        facets = np.asarray(facets)
        return facets3d.facet_map(x, facets, np.arange(len(facets)), np.reshape(xi, (-1, 2)))

    def surface_map(self, x, facets, xi):
        pos, J = self.curve(x, facets, xi)
        return pos, np.cross(J[:, :, 0], J[:, :, 1])

    def facet_normals(self, x, facets):
        return self.chord_normals(np.asarray(x)[np.asarray(facets)[:, : self.corners]])

    def material_points(self, facets, seg, interp):
        """(n, 1 + nodes): the facet, then its nodes' shape function values at the point
        (the large-kinematics friction's anchors, issue 21): the point moves with them."""
        seg = np.asarray(seg)
        weights = interp[np.arange(len(seg))[:, None], facets[seg]]
        weights = weights.toarray() if sp.issparse(weights) else np.asarray(weights)
        return np.column_stack([seg.astype(float), weights])

    def material_positions(self, x, facets, points):
        seg = points[:, 0].astype(int)
        return np.einsum("ij,ijd->id", points[:, 1:], np.asarray(x)[facets[seg]])

    def areas(self, x: np.ndarray, facets: np.ndarray, intorder: int = 6) -> np.ndarray:
        """(nf,) the facets' areas: ∫ |x_ξ × x_η| by scikit-fem's Gauss rule of degree
        ``intorder`` on the reference domain (exact on flat facets with straight edges)."""
        from skfem.refdom import RefQuad, RefTri

        X, W = get_quadrature(RefTri if self.corners == 3 else RefQuad, intorder)
        nf, nq = len(facets), len(W)
        if nf == 0:
            return np.zeros(0)
        xi = np.tile(X.T, (nf, 1))
        _, jn = self.surface_map(x, np.repeat(np.asarray(facets), nq, axis=0), xi)
        return (np.linalg.norm(jn, axis=1).reshape(nf, nq) * W[None, :]).sum(axis=1)

    def closest(self, points, x, facets, ids, point_normals=None):
        """:func:`~vfem.contact.geometry.closest3d.closest_on_facets` on the facets ``ids``: its
        facet (a row of ``facets``), ``xi``, distance, unit outward normal and ``xi_free``."""
        ids = np.asarray(ids, dtype=np.int64)
        proj = closest3d.closest_on_facets(points, x, np.asarray(facets)[ids], point_normals)
        seg = ids[proj.facet] if len(ids) else proj.facet
        return seg, proj.xi, proj.distance, proj.normal, proj.xi_free

    def strictly_inside(self, xi_free):
        return ~facets3d.outside(self.geometry, np.reshape(xi_free, (-1, 2)),
                                 -facets3d.OUTSIDE).any(axis=1)

    def edge_nodes(self, facets: np.ndarray) -> np.ndarray:
        """(nf, edges, 2) the corner nodes of each facet's edges (``geometry.edges``' order)."""
        ends = np.array([e[:2] for e in self.geometry.edges])
        return np.asarray(facets)[:, ends]

    def patch_boundary(self, facets, patch, nc):
        patch = np.asarray(patch, dtype=np.int64)
        ends = np.sort(self.edge_nodes(facets[patch]), axis=2)  # (patch, edges, 2)
        edges = ends.reshape(-1, ends.shape[2])
        out = np.zeros((len(facets), len(self.geometry.edges)), dtype=bool)
        if len(edges):
            _, inverse, counts = np.unique(edges, axis=0, return_inverse=True,
                                           return_counts=True)
            out[patch] = (counts[inverse.ravel()] == 1).reshape(len(patch), -1)
        return out

    def boundary_nodes(self, facets, boundary, nc):
        """(nc,) True at the corners of the patch's boundary edges."""
        out = np.zeros(nc, dtype=bool)
        out[self.edge_nodes(facets)[boundary].ravel()] = True
        return out

    def beyond(self, facets, seg, xi_free, boundary):
        """Past (by more than 1e-9 in local coordinates) an edge of facet ``seg`` that is on the
        patch boundary (:func:`~vfem.contact.geometry.facets3d.outside`)."""
        past = facets3d.outside(self.geometry, np.reshape(xi_free, (-1, 2)))
        return (past & boundary[seg]).any(axis=1)

    def on_boundary(self, facets, seg, xi_free, boundary):
        """At (to 1e-9) or past an edge of facet ``seg`` that is on the patch boundary: the
        closest point on the patch is on its boundary (3D's boundary is edges, 2D's end
        vertices)."""
        at = facets3d.outside(self.geometry, np.reshape(xi_free, (-1, 2)), -facets3d.OUTSIDE)
        return (at & boundary[seg]).any(axis=1)

    def linear_pieces(self, facets: np.ndarray):
        """The facets as linear pieces for the overlap's clipping: (pieces (m, 3 or 4) node
        numbers, parent (m,) the row of ``facets`` each comes from, origin (m, 2) and axes
        (m, 2, 2): the piece's local coordinates mapped affinely into its parent's,
        ``xi = origin + axes @ xi_piece``). Linear facets are their own piece; a quadratic
        triangle (T6) is its four corner-and-midpoint triangles, exact where its edges are
        straight, second order on a curved one."""
        facets = np.asarray(facets)
        m = len(facets)
        if self.order == 1:
            return (facets[:, : self.corners], np.arange(m), np.zeros((m, 2)),
                    np.broadcast_to(np.eye(2), (m, 2, 2)).copy())
        # T6: corners 0, 1, 2, midpoints 3 (0-1), 4 (1-2), 5 (0-2); each piece counter-
        # clockwise as its parent, given by its corners in the parent's coordinates
        local = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [4, 5, 3]])
        ref = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5],
                        [0.0, 0.5]])
        pieces = facets[:, local].reshape(-1, 3)  # parent-major: facet f's pieces 4f..4f+3
        parent = np.repeat(np.arange(m), 4)
        c = ref[local]  # (4, 3, 2)
        axes = np.stack([c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]], axis=2)  # columns: d/dxi_p
        return pieces, parent, np.tile(c[:, 0], (m, 1)), np.tile(axes, (m, 1, 1))

    def overlap_quadrature(self, sf, fpatch, sc, cpatch, cnormals, reach, xf, xc):
        """:func:`~vfem.contact.geometry.overlap3d.overlap_quadrature` on the facets of ``fpatch``
        against those of ``cpatch`` whose bounding spheres come within ``reach``
        (:func:`~vfem.contact.geometry.overlap3d.candidate_pairs`): each coarse facet projected
        along the fine facet's normal onto its plane (not along ``cnormals``: exact on a flat
        interface, second order on a curved one, overlap3d's docstring), clipped by the fine
        facet, fanned into triangles with a Gauss rule exact for ``phi_f phi_f`` and ``phi_f
        psi_c`` on flat parallelograms and triangles. The weights are the fine side's measure
        at ``xf``, rescaled to its undeformed measure (the traction is nominal) where ``xf``
        is not the undeformed ``sf.X``. Linear facets (T3, Q4) only."""
        from . import overlap3d
        for kind in (self, sc.kind):
            if kind.order != 1 and not kind.geometry.simplex:
                raise NotImplementedError(
                    f"the 3D overlap quadrature takes linear facets (T3, Q4) and quadratic "
                    f"triangles (T6), got {kind!r}: contact of quadratic hexahedra (Q9 facets) "
                    "is not implemented yet")
        fpatch = np.asarray(fpatch, dtype=np.int64)
        cpatch = np.asarray(cpatch, dtype=np.int64)
        comp, parent, origin, axes = self.linear_pieces(sf.facets[fpatch])
        opp = sc.kind.linear_pieces(sc.facets[cpatch])[0]
        quadratic = self.order == 2 or sc.kind.order == 2
        pairs = overlap3d.candidate_pairs(xf, comp, xc, opp, reach)
        q = overlap3d.overlap_quadrature(xf, comp, xc, opp, pairs, max_distance=reach,
                                         degree=4 if quadratic else None)
        piece = q.comp_facet
        fac = fpatch[parent[piece]]
        xi = origin[piece] + np.einsum("pij,pj->pi", axes[piece], q.comp_xi)
        wts = q.weight
        if len(fac) and not np.array_equal(xf[: sf.nc], sf.X[: sf.nc]):
            _, now = self.surface_map(xf, sf.facets[fac], xi)
            _, ref = self.surface_map(sf.X, sf.facets[fac], xi)
            now = np.linalg.norm(now, axis=1)
            wts = wts * np.linalg.norm(ref, axis=1) / np.where(now > 0, now, 1.0)
        return fac, xi, wts


class Triangle(_Facet3D):
    """3-node (``order`` 1) or 6-node (``order`` 2) triangular facets of a 3D surface:
    scikit-fem's ``ElementTriP1``/``ElementTriP2`` node order (the corners, then the middles of
    the edges 0-1, 1-2, 0-2)."""

    name = "Triangle"
    _NODES = {1: 3, 2: 6}
    _REVERSED = {3: (0, 2, 1), 6: (0, 2, 1, 5, 4, 3)}


class Quad(_Facet3D):
    """4-node (``order`` 1, bilinear, possibly warped) or 9-node (``order`` 2) quadrilateral
    facets of a 3D surface: scikit-fem's ``ElementQuad1``/``ElementQuad2`` node order (the
    corners, the middles of the edges 0-1, 1-2, 2-3, 0-3, the centre)."""

    name = "Quad"
    _NODES = {1: 4, 2: 9}
    _REVERSED = {4: (0, 3, 2, 1), 9: (0, 3, 2, 1, 7, 6, 5, 4, 8)}


def kind_of(dim: int, facets: np.ndarray) -> FacetKind:
    """The facet kind of (nf, k) facets of a ``dim``-dimensional surface: ``Segment`` (k = 2,
    3), ``Triangle`` (3, 6) or ``Quad`` (4, 9)."""
    k = np.shape(facets)[1]
    if dim == 2 and k in (2, 3):
        return Segment(k - 1)
    if dim == 3 and k in (3, 6):
        return Triangle(1 if k == 3 else 2)
    if dim == 3 and k in (4, 9):
        return Quad(1 if k == 4 else 2)
    raise ValueError(f"no facet kind of {k} nodes in {dim}D: 2D facets have 2 or 3 nodes, 3D "
                     "facets 3, 4, 6 or 9")
