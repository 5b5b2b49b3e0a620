"""The invariants (b) and (c) of :mod:`vfem.contact.invariants.check` on 3D bodies (issue 21, C9).

The same checks as in 2D, on a body's boundary of triangles (a quadrilateral split in two
along its first diagonal) in place of its boundary polygon:

* **inside**: the sign of (p − c)·n at the point's closest point c on the other body's deformed
  boundary, n the angle-weighted pseudonormal of the closest feature (the face's normal inside
  a triangle, the sum of the two faces' normals on an edge, the angle-weighted sum of the
  faces' normals at a vertex: exact for a closed surface, Bærentzen & Aanæs 2005); the whole
  closed boundary is used, symmetry planes included.
* **depth**: the distance to the boundary without its symmetry planes (roller supports held
  normal to a flat boundary, any axis, :func:`~vfem.contact.invariants.polygon.symmetry_facets`);
  the facet's size L is its longest side.
* **allowance** (L/2)·tan(α/2), α twice the largest angle between the node's normal and the
  normal of a boundary node within L of it on the convex side (the 2D "convex turning within
  L": a box's edge turns 90°), at most 90°, the allowance at most the longer of L/2 and the
  node's own facets' sides. A node on a symmetry plane takes its normal's component along the
  plane (the mirrored model's).
* **linearised depth** under small kinematics: the node's offset r from its closest point on
  the other undeformed surface moved with the surface's displacement (interpolated linearly on
  the triangle), read along the facet's normal and along the node's own normal (the smaller;
  not the node's own at a convex edge or corner of its body, :data:`CORNER_ANGLE`);
  beside an edge or a vertex (the node's projection on the facet's plane outside it, not across
  an edge on a symmetry plane, where the facet's mirror image continues it), |r| signed by the
  feature's pseudonormal; the second-order allowance the slip times the angle the facet
  has turned through.
* **tension**: F·n with n the angle-weighted nodal normal (undeformed under small kinematics)
  of the body's contact boundaries where it names them (:attr:`Surface3.tension_normals`).

Linear facets only: quadratic 3D bodies in contact, and the "consistent" tension measure in
3D, are refused with NotImplementedError (docs/errors.md). The loop of (b) over the pairs is
:meth:`~vfem.contact.invariants.check.InvariantCheck._interpenetration`, shared with 2D: a
:class:`Surface3` answers the questions a 2D boundary polygon does.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from ..geometry import closest_on_facets, kind_of
from .cached_boundary import CachedBoundary, scatter_add
from .kind import SurfaceKind
from .measures import nodal_tension
from .polygon import symmetry_facets

if TYPE_CHECKING:
    from ...bodies import Body

#: a feature of a triangle: the barycentric coordinates below this (relative) are on its edge
FEATURE = 1e-9

#: radians: a boundary node whose own surface turns convexly by more than this is a corner or
#: an edge of its body (a block's corner, a box's edge), whose nodal normal is only a bisector: the
#: linearised depth is not read along it (the formulation's edge angle, chosen alike: a faceted
#: curve turns less per facet)
CORNER_ANGLE = np.radians(60.0)


@dataclass
class Boundary3:
    """One 3D body's boundary from its undeformed mesh (computed once), in a local numbering
    of its boundary nodes (``nodes``: their point numbers)."""

    nodes: np.ndarray  # (nb,)
    triangles: np.ndarray  # (nt, 3) local numbers, counter-clockwise seen from outside
    owner: np.ndarray  # (nt,) the facet (row of ``facets``) each triangle is part of
    facets: np.ndarray  # (nf, 3 or 4) local numbers of the facets (a T6's pieces), oriented
    mirror: np.ndarray  # (nt,) bool: the triangle lies on a symmetry plane
    segments: np.ndarray  # (ne, 2) the facets' sides (local numbers): the nodes' neighbours
    large: bool
    #: quadratic triangles: each corner with each midpoint of its facets' edges from it,
    #: (m, 2) local numbers (unique), for (c)'s measure; None on linear facets
    corner_mid: np.ndarray | None = None
    #: (nt,) bool: the triangle lies on one of the body's contact boundaries
    #: (``contact_boundaries``); None where it names none (every boundary may touch)
    contact: np.ndarray | None = None
    #: (nt,) the mesh's boundary facet each triangle is part of: a pair's side reads its own
    facet_of: np.ndarray | None = None

    @classmethod
    def of(cls, body: Body, symmetry: np.ndarray) -> Boundary3:
        """``symmetry``: the body's facets on a symmetry plane
        (:func:`vfem.contact.invariants.polygon.symmetry_facets`)."""
        mesh = body.mesh
        bf = mesh.boundary_facets()
        fp = body.facet_points(bf).copy()
        if body.order != 1 and fp.shape[1] != 6:
            raise NotImplementedError(
                f"the invariants of 3D contact on body {body.name!r}: quadratic hexahedra are "
                "not supported yet (linear facets and quadratic triangles only)")
        kind = kind_of(3, fp)
        if len(bf):
            elem = mesh.f2t[0, bf]
            centroid = body.points[:, mesh.t[:, elem]].mean(axis=1).T
            kind.orient(body.points, fp, centroid)
        # a quadratic triangle is read as its four corner-and-midpoint triangles (the contact's
        # own pieces, FacetKind.linear_pieces): exact where its edges are straight; on a curved
        # one the faceting allowance covers the pieces' sag
        corner_mid = None
        if fp.shape[1] == 6:  # T6: corner 0 with midpoints 3 (0-1) and 5 (0-2), and so on
            corner_mid = np.unique(np.vstack([fp[:, [c, m]] for c, m in
                                              ((0, 3), (0, 5), (1, 3), (1, 4), (2, 4), (2, 5))]),
                                   axis=0)
        fp, piece_of = kind.linear_pieces(fp)[:2]
        split = [(0, 1, 2)] if fp.shape[1] == 3 else [(0, 1, 2), (0, 2, 3)]
        tri = np.vstack([fp[:, s] for s in split])
        owner = np.tile(np.arange(len(fp)), len(split))
        mirror = np.isin(bf, symmetry)[piece_of][owner]
        contact = None
        if body.contact_boundaries is not None:
            named = [mesh.boundaries[n] for n in body.contact_boundaries if n in mesh.boundaries]
            contact = np.isin(bf, np.concatenate(named or [np.zeros(0, np.int64)])
                              )[piece_of][owner]
        k = fp.shape[1]
        sides = np.vstack([fp[:, [c, (c + 1) % k]] for c in range(k)])
        sides = np.unique(np.sort(sides, axis=1), axis=0)
        nodes, local = np.unique(fp, return_inverse=True)
        lookup = np.full(body.npoints, -1)
        lookup[nodes] = np.arange(len(nodes))
        return cls(nodes=nodes, triangles=lookup[tri], owner=owner,
                   facets=local.reshape(fp.shape), mirror=mirror,
                   segments=lookup[sides].reshape(-1, 2), large=body.large,
                   corner_mid=None if corner_mid is None else lookup[corner_mid],
                   contact=contact, facet_of=np.asarray(bf)[piece_of][owner])

    @cached_property
    def edges(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The triangles' edges, from the topology alone (once per boundary; the positions
        change at every state, these do not): ``(half, count, opposite)``, with ``half``
        (3 nt,) the edge of each triangle's side k (corners k, k + 1) triangle by triangle,
        ``count`` the number of edges and ``opposite`` (nt, 3) the edge opposite each
        corner (side k is opposite corner k + 2). An edge is its two nodes, unordered."""
        t, nb = self.triangles, len(self.nodes)
        a, b = t.ravel(), np.roll(t, -1, axis=1).ravel()
        _, half = np.unique(np.minimum(a, b) * nb + np.maximum(a, b), return_inverse=True)
        half = half.ravel()
        return half, int(half.max(initial=-1)) + 1, half.reshape(-1, 3)[:, [1, 2, 0]]


def _barycentric(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(m, 3) barycentric coordinates of the projection of ``p`` on the planes of the
    triangles (a, b, c) (unclamped)."""
    ab, ac, ap = b - a, c - a, p - a
    d00, d01, d11 = (np.einsum("ij,ij->i", u, v) for u, v in ((ab, ab), (ab, ac), (ac, ac)))
    d20, d21 = np.einsum("ij,ij->i", ap, ab), np.einsum("ij,ij->i", ap, ac)
    den = np.maximum(d00 * d11 - d01 * d01, 1e-300)
    s = (d11 * d20 - d01 * d21) / den
    t = (d00 * d21 - d01 * d20) / den
    return np.column_stack([1 - s - t, s, t])


class Surface3(CachedBoundary):
    """A 3D body's boundary at positions ``x`` ((nb, 3), local numbering); what is asked is
    computed on first use (the API of :class:`~vfem.contact.invariants.polygon._Polygon`)."""

    @property
    def corners(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = self.b.triangles
        return self._get("corners", lambda: (self.x[t[:, 0]], self.x[t[:, 1]], self.x[t[:, 2]]))

    @property
    def mirror_edges(self) -> np.ndarray:
        """(nt, 3) bool: the triangle's edge opposite each corner is an edge of a triangle on a
        symmetry plane (the model continues across it as the facet's mirror image)."""
        def make():
            t, m = self.b.triangles, self.b.mirror
            nb = len(self.x)
            key = lambda i, j: np.minimum(i, j) * nb + np.maximum(i, j)  # noqa: E731
            on = np.concatenate([key(t[m, i], t[m, j]) for i, j in ((1, 2), (2, 0), (0, 1))])
            return np.column_stack([np.isin(key(t[:, i], t[:, j]), on)
                                    for i, j in ((1, 2), (2, 0), (0, 1))])
        return self._get("mirror_edges", make)

    @property
    def unit_normals(self) -> np.ndarray:
        def make():
            a, b, c = self.corners
            n = np.cross(b - a, c - a)
            return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
        return self._get("unit_normals", make)

    @property
    def angles(self) -> np.ndarray:
        """(nt, 3) each triangle's angle at its three corners."""
        def make():
            p = self.corners
            out = np.zeros((len(self.b.triangles), 3))
            for k in range(3):
                u, v = p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]
                out[:, k] = np.arctan2(np.linalg.norm(np.cross(u, v), axis=1),
                                       np.einsum("ij,ij->i", u, v))
            return out
        return self._get("angles", make)

    def _vertex_pseudonormals(self, keep: np.ndarray) -> np.ndarray:
        """(nb, 3) the angle-weighted sum of the normals of the triangles ``keep`` at each
        node, added corner by corner (all first corners, then the second, the third)."""
        n, w = self.unit_normals[keep], self.angles[keep]
        return scatter_add(len(self.x), self.b.triangles[keep].T,
                           (w.T[:, :, None] * n).reshape(-1, 3))

    @property
    def pseudonormals(self) -> np.ndarray:
        """(nb, 3) the angle-weighted sum of every boundary triangle's normal at each node."""
        return self._get("pseudonormals", lambda: self._vertex_pseudonormals(
            np.arange(len(self.b.triangles))))

    @property
    def edge_normals(self) -> np.ndarray:
        """(ne, 3) per edge (:attr:`Boundary3.edges`), the sum of the unit normals of the
        triangles sharing it, added triangle by triangle (a vertex's or an edge's sum in one
        order, as a point's feature reads it whichever triangle it is found on)."""
        def make():
            half, count, _ = self.b.edges
            return scatter_add(count, half, np.repeat(self.unit_normals, 3, axis=0))
        return self._get("edge_normals", make)

    @property
    def sizes(self) -> np.ndarray:
        """(nt,) the longest side of each triangle's facet."""
        def make():
            f = self.b.facets
            k = f.shape[1]
            side = np.max([np.linalg.norm(self.x[f[:, (c + 1) % k]] - self.x[f[:, c]], axis=1)
                           for c in range(k)], axis=0)
            return side[self.b.owner]
        return self._get("sizes", make)

    def feature_normals(self, tri: np.ndarray, lam: np.ndarray, vertex: np.ndarray
                        ) -> np.ndarray:
        """(m, 3) the pseudonormal of the feature of triangles ``tri`` (rows of ``triangles``)
        at barycentric coordinates ``lam`` (m, 3): the face's, an edge's, or a vertex's
        (``vertex``: (nb, 3) the vertex pseudonormals to use)."""
        out = self.unit_normals[tri].copy()
        zero = lam <= FEATURE
        count = zero.sum(axis=1)
        # a vertex: the one coordinate not zero (3 minus the sum of the zero ones' places)
        at = np.flatnonzero(count >= 2)
        corner = 3 - (zero[at] * np.arange(3)).sum(axis=1)
        out[at] = vertex[self.b.triangles[tri[at], corner]]
        # an edge: the one opposite the zero coordinate's corner
        at = np.flatnonzero(count == 1)
        if len(at):
            edge = self.b.edges[2][tri[at], np.argmax(zero[at], axis=1)]
            out[at] = self.edge_normals[edge]
        return out

    def _closest(self, pts: np.ndarray, keep: np.ndarray, point_normals=None):
        tri = self.b.triangles[keep]
        pr = closest_on_facets(pts, self.x, tri, point_normals=point_normals)
        lam = np.column_stack([1 - pr.xi.sum(axis=1), pr.xi])
        return keep[pr.facet], lam, pr.point, pr.distance

    def inside(self, pts: np.ndarray) -> np.ndarray:
        """Which of ``pts`` (m, 3) lie inside the closed boundary (on it counts as inside)."""
        return self.side(pts)[0]

    def side(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Which of ``pts`` (m, 3) lie inside the closed boundary (:meth:`inside`), and their
        distance to it (every triangle, symmetry planes included). A point's answer does not
        depend on the other points asked with it."""
        tri, lam, c, dist = self._closest(pts, np.arange(len(self.b.triangles)))
        direction = self.feature_normals(tri, lam, self.pseudonormals)
        return np.einsum("ij,ij->i", pts - c, direction) <= 1e-12 * np.maximum(
            self.sizes[tri], 1e-300), dist

    def behind(self, own: np.ndarray, other: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """A body's side against its other side (self-contact, issue 42; the 2D reading's,
        :meth:`~vfem.contact.invariants.polygon._Polygon.behind`): the nodes of the triangles
        ``own`` (mask (nt,)), but those of ``other``, behind the triangles ``other`` and over
        them — (nodes, depth, the closest facet's size, its triangle's nodes), None where there
        are none. Behind: along the pseudonormal of the closest feature over ``other``'s
        triangles alone (a face's normal, an edge's two, a vertex's angle-weighted sum). Over:
        in a face, on an edge between two of ``other``'s triangles or at a vertex all of whose
        triangles are ``other``'s — or, at ``other``'s border, with the node's foot on the
        closest triangle's plane inside it (a node beyond the border is not over the side:
        there the boundary turns away)."""
        keep = np.flatnonzero(other)
        if not len(keep) or not own.any():
            return None
        tri_all = self.b.triangles
        nodes = np.setdiff1d(np.unique(tri_all[own]), tri_all[keep])
        if not len(nodes):
            return None
        tri, lam, c, dist = self._closest(self.x[nodes], keep)
        # the other side's interior features: edges of two of its triangles, vertices whose
        # triangles are all its
        half, count, opposite = self.b.edges
        mine = np.zeros(count)
        np.add.at(mine, half.reshape(-1, 3)[keep].ravel(), 1.0)
        outside = np.zeros(len(self.x))
        np.add.at(outside, tri_all[~other].ravel(), 1.0)
        zero = lam <= FEATURE
        n_zero = zero.sum(axis=1)
        interior = n_zero == 0  # in the face
        at = np.flatnonzero(n_zero == 1)  # on an edge
        interior[at] = mine[opposite[tri[at], np.argmax(zero[at], axis=1)]] >= 2
        at = np.flatnonzero(n_zero >= 2)  # at a vertex
        corner = 3 - (zero[at] * np.arange(3)).sum(axis=1)
        interior[at] = outside[tri_all[tri[at], corner]] == 0
        direction = self.feature_normals(tri, lam, self._vertex_pseudonormals(keep))
        # at the border: the foot on the closest triangle's plane inside it, read along its
        # face normal
        a, b, cc = (self.x[tri_all[tri, k]] for k in range(3))
        foot = _barycentric(self.x[nodes], a, b, cc).min(axis=1) >= -FEATURE
        border = ~interior & foot
        direction[border] = self.unit_normals[tri[border]]
        behind = np.einsum("ij,ij->i", self.x[nodes] - c, direction) < 0
        hit = behind & (interior | foot)
        if not hit.any():
            return None
        return nodes[hit], dist[hit], self.sizes[tri[hit]], tri_all[tri[hit]]

    def depth(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distance of ``pts`` to the surface triangles, the size of the closest one's facet
        and its three nodes (local numbers)."""
        tri, _, _, dist = self._closest(pts, self.surface)
        return dist, self.sizes[tri], self.b.triangles[tri]

    @property
    def normals(self) -> np.ndarray:
        """(nb, 3) the outward unit normal at each node: the angle-weighted mean of its surface
        triangles' normals; on a symmetry plane, its component along the plane."""
        return self._get("normals", lambda: self._normals_over(~self.b.mirror))

    def _normals_over(self, keep: np.ndarray) -> np.ndarray:
        """(nb, 3) the angle-weighted unit normal of the triangles ``keep`` at each node (zero
        at nodes on none); on a symmetry plane, its component along the plane."""
        out = self._vertex_pseudonormals(keep)
        mirror = np.flatnonzero(self.b.mirror)
        plane = np.zeros_like(self.x)
        for k in range(3):
            plane[self.b.triangles[mirror, k]] = self.unit_normals[mirror]
        on = np.flatnonzero(plane.any(axis=1) & out.any(axis=1))
        m = plane[on]
        out[on] -= np.einsum("ij,ij->i", out[on], m)[:, None] * m
        norm = np.linalg.norm(out, axis=1)
        return out / np.where(norm > 0, norm, 1.0)[:, None]

    @property
    def tension_normals(self) -> np.ndarray:
        """(nb, 3) the normal (c) reads a node's force along: :attr:`normals` over the body's
        contact boundaries' triangles only, where it names some and the node is on one (else
        :attr:`normals`). At a box's corner the whole boundary's normal leans 55 degrees off
        the contact face's, and a frictional force inclined by atan(mu) against a slide read
        positive along it at mu = 1 with a compressive traction (tests/test_large_friction3d.py)."""
        def make():
            out = self.normals
            if self.b.contact is None:
                return out
            faces = self._normals_over(self.b.contact & ~self.b.mirror)
            on = np.linalg.norm(faces, axis=1) > 0
            return np.where(on[:, None], faces, out)
        return self._get("tension_normals", make)

    @property
    def own_turning(self) -> np.ndarray:
        """Per boundary node, twice the largest angle between its normal and the normals of
        its own triangles (not those on a symmetry plane) where the node is convex (its
        triangles' centroids below its tangent plane), else 0: a box's corner or edge turns by
        itself, as a 2D polygon's corner does, however far its neighbours are."""
        def make():
            keep = ~self.b.mirror
            tri, nt = self.b.triangles[keep], self.unit_normals[keep]
            n, x = self.normals, self.x
            angle = np.zeros(len(x))
            below = np.zeros(len(x))
            centroid = x[tri].mean(axis=1)
            for c in range(3):
                p = tri[:, c]
                cos = np.clip(np.einsum("ij,ij->i", nt, n[p]), -1.0, 1.0)
                np.maximum.at(angle, p, np.arccos(cos))
                np.add.at(below, p, np.einsum("ij,ij->i", centroid - x[p], n[p]))
            return np.where(below < 0, 2.0 * angle, 0.0)
        return self._get("own_turning", make)

    def turning_within(self, nodes: np.ndarray, radius: np.ndarray) -> np.ndarray:
        """Twice the largest angle between the normal of each of ``nodes`` and that of a
        boundary node within ``radius`` of it on the convex side ((x_q − x_p)·(n_q − n_p) > 0),
        and at least the node's own turning (:attr:`own_turning`: a corner whose neighbours
        are farther than ``radius``)."""
        tree = self._get("tree", lambda: cKDTree(self.x))
        n = self.normals
        out = self.own_turning[nodes].astype(float)
        near = tree.query_ball_point(self.x[nodes], radius)
        if not len(nodes):
            return out
        # every (node, neighbour) pair at once: rows k repeated by their neighbour counts
        counts = np.fromiter((len(q) for q in near), dtype=np.int64, count=len(nodes))
        k = np.repeat(np.arange(len(nodes)), counts)
        q = np.fromiter((i for row in near for i in row), dtype=np.int64, count=int(counts.sum()))
        p = nodes[k]
        convex = np.einsum("ij,ij->i", self.x[q] - self.x[p], n[q] - n[p]) > 0
        cos = np.clip(np.einsum("ij,ij->i", n[q[convex]], n[p[convex]]), -1.0, 1.0)
        np.maximum.at(out, k[convex], 2.0 * np.arccos(cos))
        return out

    @property
    def adjacent(self) -> np.ndarray:
        """(nb,) the longest side of the surface facets at each node."""
        def make():
            out = np.zeros(len(self.x))
            keep = self.surface if (~self.b.mirror).any() else np.zeros(0, dtype=np.int64)
            for k in range(3):
                np.maximum.at(out, self.b.triangles[keep, k], self.sizes[keep])
            return out
        return self._get("adjacent", make)


def linearised_depth(reference: list[Surface3], i: int, j: int, node: np.ndarray,
                     cur: list[Surface3]) -> tuple[np.ndarray, np.ndarray]:
    """Small kinematics: the depth of body i's boundary ``node`` (local numbers) into body j as
    linear theory reads it, and its second-order allowance (2D:
    :func:`vfem.contact.invariants.plane.linearised_depth`)."""
    ri, rj = reference[i], reference[j]
    keep = rj.surface
    tri, lam, c, dist = rj._closest(ri.x[node], keep, point_normals=ri.normals[node])
    corners = rj.b.triangles[tri]
    uj = cur[j].x - rj.x
    uc = np.einsum("mk,mkd->md", lam, uj[corners])
    r = cur[i].x[node] - (c + uc)
    n = rj.unit_normals[tri]
    # (not along i's own normal at its convex edges and corners: 2D's reading)
    own = np.einsum("ij,ij->i", r, ri.normals[node])
    own[ri.own_turning[node] > CORNER_ANGLE] = np.inf
    depth = np.minimum(-np.einsum("ij,ij->i", r, n), own)
    # or along j's smoothed normal there (its nodal normals interpolated over the facet; 2D:
    # the same)
    smooth = np.einsum("mk,mkd->md", lam, rj.normals[corners])
    smooth /= np.maximum(np.linalg.norm(smooth, axis=1), 1e-300)[:, None]
    depth = np.minimum(depth, -np.einsum("ij,ij->i", r, smooth))
    # beside an edge or a vertex: the node's projection on the facet's plane lies outside it
    a, b, cc = rj.corners
    free = _barycentric(ri.x[node], a[tri], b[tri], cc[tri])
    # (not beside an edge on a symmetry plane: the facet's mirror image continues it there)
    beside = (free < -FEATURE) & ~rj.mirror_edges[tri]
    vertex = beside.any(axis=1) & (dist > 1e-12 * np.maximum(rj.sizes[tri], 1e-300))
    if vertex.any():
        feature = rj.feature_normals(tri, lam, rj._get(
            "surface_pseudonormals", lambda: rj._vertex_pseudonormals(keep)))
        outside = np.einsum("ij,ij->i", r, feature) > 0
        depth[vertex] = np.where(outside, -1.0, 1.0)[vertex] * np.linalg.norm(r, axis=1)[vertex]
    # second order: the slip along the facet times the angle it has turned through
    n1 = cur[j].unit_normals[tri]
    theta = np.arctan2(np.linalg.norm(np.cross(n, n1), axis=1), np.einsum("ij,ij->i", n, n1))
    slip = np.linalg.norm(r - np.einsum("ij,ij->i", r, n)[:, None] * n, axis=1)
    cos_beta = np.clip(-np.einsum("ij,ij->i", n, ri.normals[node]), 1e-3, 1.0)
    slip = slip + dist * np.sqrt(1.0 - cos_beta**2) / cos_beta
    # and a quadrilateral's warp: the formulation interpolates over it bilinearly, this check
    # over its two triangles; they part by up to a quarter of the displacements' twist
    # ((u1 + u3) - (u0 + u2)) / 4 along the normal (a block's node beside a stiff box's corner:
    # 9.0e-7 inside the box's face where the tolerance was 8.3e-7)
    warp = np.zeros(len(node))
    if rj.b.facets.shape[1] == 4:
        f = rj.b.facets[rj.b.owner[tri]]
        twist = uj[f[:, 1]] + uj[f[:, 3]] - uj[f[:, 0]] - uj[f[:, 2]]
        warp = 0.25 * np.abs(np.einsum("ij,ij->i", twist, n))
    return depth, np.where(vertex, 0.0, slip * np.abs(theta)) + warp


def tension(bodies: list[Body], tolerance: Callable[[Body], float], least: float,
            F: list[np.ndarray], own: list[Surface3], measure: str = "nodal"
            ) -> tuple[float, float, dict | None]:
    """(c), the nodal measure, on 3D bodies: F·n at every node of linear facets. On quadratic
    triangles (T6) a corner's shape function L (2 L - 1) is negative near the far edge, so a
    compressive traction can put a tensile force on a corner (none at all under a uniform one);
    but phi_corner + (phi_mid1 + phi_mid2) / 2 = L >= 0 on each facet (the midpoints of its
    two edges from the corner), so the corner is read with half of each such midpoint's force
    (a midpoint's own phi = 4 L x >= 0: alone), and a body with quadratic elements takes the
    quadratic tolerance, as in 2D (:mod:`vfem.contact.invariants.check`'s docstring).

    ``tolerance(body)``: a body's tolerance (``least`` where there are no bodies); ``measure``:
    the nodal one, the only one in 3D (:data:`SOLID`). Returns the
    largest tensile measure over the largest nodal force (0 where none), its tolerance (the
    least of the bodies' where none) and where it is (``{"body", "node", "value"}``, or None).
    """
    return nodal_tension(bodies, tolerance, least, F, own, _nodal_measure)


def _nodal_measure(g: Surface3, f: np.ndarray) -> np.ndarray:
    """F·n at every node of a 3D boundary; a quadratic triangle's corner with half of each
    midpoint of its edges from it (:func:`tension`)."""
    fn = np.einsum("ij,ij->i", f, g.tension_normals)
    if g.b.corner_mid is not None:
        corner, mid = g.b.corner_mid.T
        patch = fn.copy()
        np.add.at(patch, corner, 0.5 * fn[mid])
        patch[mid] = fn[mid]
        fn = patch
    return fn


def _boundary(body: Body) -> Boundary3:
    """A 3D body's boundary, its symmetry planes left out of what contact may touch."""
    return Boundary3.of(body, symmetry_facets(body))


#: 3D bodies: boundaries of triangles and quadrilaterals, the nodal tension measure, a model in
#: which nothing may touch answered without building them
SOLID = SurfaceKind(name="3D", boundary=_boundary, surface=Surface3,
                    linearised_depth=linearised_depth, tension=tension,
                    tension_measures=("nodal",), skips_untouched=True)
