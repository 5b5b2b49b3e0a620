"""A 2D body's boundary as invariant (b) reads it (:class:`_Polygon`): its oriented boundary
segments, undeformed once, and at each state the deformed polygon — whether a point lies inside
(the sign of its distance along the facet's normal there, or along the mean of the two facets'
normals at a vertex: exact for any polygon, holes included), how deep, and how the boundary
turns near a node (the faceting allowance). The 3D counterpart is
:class:`~vfem.contact.invariants.check3d.Surface3`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from ..search import project_points
from .cached_boundary import CachedBoundary, scatter_add

if TYPE_CHECKING:
    from ...bodies import Body


@dataclass
class _Boundary:
    """One body's boundary, from its undeformed mesh (computed once). Arrays of nodes are
    over the boundary nodes (``nodes``: their point numbers), in that local numbering."""

    nodes: np.ndarray  # (nb,) point numbers of every boundary node
    segments: np.ndarray  # (ns, 2) local numbers, oriented: outward normal (t_y, -t_x)
    facets: np.ndarray  # (nf, 2 or 3) local numbers of the facets (ends, midpoint), oriented
    mirror: np.ndarray  # (ns,) bool: the segment lies on a symmetry plane of the model
    large: bool  # the body is analysed under large kinematics
    #: (ns,) the mesh's boundary facet each segment is (part of): a pair's side reads its own
    facet_of: np.ndarray | None = None

    @classmethod
    def of(cls, body: Body) -> _Boundary:
        mesh = body.mesh
        X = body.points
        bf = mesh.boundary_facets()
        fp = body.facet_points(bf).copy()
        if len(bf):
            elem = mesh.f2t[0, bf]
            centroid = X[:, mesh.t[:, elem]].mean(axis=1).T
            a, b = X[:, fp[:, 0]].T, X[:, fp[:, 1]].T
            t = b - a
            normal = np.column_stack([t[:, 1], -t[:, 0]])
            flip = np.einsum("ij,ij->i", normal, 0.5 * (a + b) - centroid) < 0
            fp[flip, :2] = fp[flip][:, 1::-1]
        mirror = np.isin(bf, symmetry_facets(body))
        facet_of = np.asarray(bf)
        if fp.shape[1] == 3:  # quadratic: a facet is two chords through its midpoint
            segments = np.vstack([fp[:, [0, 2]], fp[:, [2, 1]]])
            mirror = np.concatenate([mirror, mirror])
            facet_of = np.concatenate([facet_of, facet_of])
        else:
            segments = fp
        nodes, local = np.unique(segments, return_inverse=True)
        lookup = np.full(body.npoints, -1)
        lookup[nodes] = np.arange(len(nodes))
        return cls(nodes=nodes, segments=local.reshape(segments.shape), facets=lookup[fp],
                   mirror=mirror, large=body.large, facet_of=facet_of)


def symmetry_facets(body: Body) -> np.ndarray:
    """Facets on a symmetry plane (:meth:`~vfem.bodies.Body.symmetry_planes`): the model
    continues across them as their mirror image, so they are no surface that contact sees."""
    return np.concatenate([np.zeros(0, dtype=np.int64)]
                          + [facets for facets, _ in body.symmetry_planes()])


class _Polygon(CachedBoundary):
    """A body's boundary at positions ``x`` ((nb, 2), local numbering); what is asked is
    computed on first use."""

    #: a point costs ``inside`` some 10 us, the bound some 0.1 ms a pair: on the examples'
    #: 2D pairs (9 to 100 nodes in the other's box, few of them ruled out) invariant (b)
    #: took 7 to 25 % longer with the bound than asking them all
    bound_from = 128

    @property
    def ends(self) -> tuple[np.ndarray, np.ndarray]:
        return self._get("ends", lambda: (self.x[self.b.segments[:, 0]],
                                          self.x[self.b.segments[:, 1]]))

    @property
    def lengths(self) -> np.ndarray:
        return self._get("lengths", lambda: np.linalg.norm(self.ends[1] - self.ends[0], axis=1))

    @property
    def unit_normals(self) -> np.ndarray:
        def make():
            a, b = self.ends
            d = b - a
            return np.column_stack([d[:, 1], -d[:, 0]]) / np.maximum(self.lengths,
                                                                     1e-300)[:, None]
        return self._get("unit_normals", make)

    def inside(self, pts: np.ndarray) -> np.ndarray:
        """Which of ``pts`` (m, 2) lie inside the polygon (on it counts as inside): the sign
        of the distance to the closest point along the facet's normal, or at a vertex along
        the sum of its facets' unit normals."""
        return self.side(pts)[0]

    def side(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Which of ``pts`` (m, 2) lie inside the polygon (:meth:`inside`), and their distance
        to it (every segment, symmetry planes included). A point's answer does not depend on
        the other points asked with it."""
        a, b = self.ends
        seg, t, dist = project_points(pts, a, b)[:3]
        n = self.unit_normals
        vertex_normal = self._get("vertex_normals", lambda: _scatter_add(
            len(self.x), self.b.segments, n))
        at = np.where(t <= 0, self.b.segments[seg, 0], self.b.segments[seg, 1])
        end = (t <= 0) | (t >= 1)
        c = a[seg] + t[:, None] * (b[seg] - a[seg])
        direction = np.where(end[:, None], vertex_normal[at], n[seg])
        return np.einsum("ij,ij->i", pts - c, direction) <= 1e-12 * np.maximum(
            self.lengths[seg], 1e-300), dist

    def behind(self, own: np.ndarray, other: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """A body's side against its other side (self-contact, issue 42): the nodes of the
        segments ``own`` (mask (ns,)), but those of ``other``, that lie behind the segments
        ``other`` and over them — (nodes, depth, the closest segment's length, its two
        nodes), None where there are none. Behind: along the closest segment's outward
        normal, or at a vertex between two of ``other``'s segments the sum of theirs. Over:
        on a segment, at such a vertex, or at an end of ``other`` no further than its line's
        foot (a node beyond the ends is not over it: there the boundary turns away)."""
        theirs = self.b.segments[other]
        if not len(theirs) or not own.any():
            return None
        nodes = np.setdiff1d(np.unique(self.b.segments[own]), theirs)
        a, b = self.x[theirs[:, 0]], self.x[theirs[:, 1]]
        seg, t, dist, free = project_points(self.x[nodes], a, b, free=True)
        d = b - a
        length = np.maximum(np.linalg.norm(d, axis=1), 1e-300)
        normal = np.column_stack([d[:, 1], -d[:, 0]]) / length[:, None]
        count = np.zeros(len(self.x))
        vertex = np.zeros((len(self.x), 2))
        for col in (0, 1):
            np.add.at(count, theirs[:, col], 1.0)
            np.add.at(vertex, theirs[:, col], normal)
        at = np.where(t <= 0, theirs[seg, 0], theirs[seg, 1])
        end = (t <= 0) | (t >= 1)
        c = a[seg] + t[:, None] * d[seg]
        inner = count[at] > 1  # a vertex between two of the other side's segments
        direction = np.where((end & inner)[:, None], vertex[at], normal[seg])
        behind = np.einsum("ij,ij->i", self.x[nodes] - c, direction) < 0
        hit = behind & (~end | inner | (np.abs(free - t) <= 1e-9))
        if not hit.any():
            return None
        return nodes[hit], dist[hit], length[seg[hit]], theirs[seg[hit]]

    def depth(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distance of ``pts`` to the surface segments, the length of the closest one and
        its two nodes (local numbers)."""
        a, b = self.ends
        keep = self.surface
        seg, _, dist = project_points(pts, a[keep], b[keep])[:3]
        return dist, self.lengths[keep][seg], self.b.segments[keep][seg]

    @property
    def turning(self) -> np.ndarray:
        """(nb,) the signed exterior angle at each node (> 0 convex, < 0 concave). Where one
        of a node's segments lies on a symmetry plane, the other's mirror image takes its
        place (the node on the plane is no corner of the whole model)."""
        def make():
            a, b = self.ends
            d = b - a
            seg, mirror = self.b.segments, self.b.mirror
            d_in = np.zeros_like(self.x)
            d_out = np.zeros_like(self.x)
            d_in[seg[~mirror, 1]] = d[~mirror]
            d_out[seg[~mirror, 0]] = d[~mirror]
            plane = np.zeros_like(self.x)  # the symmetry plane's direction at its nodes
            plane[seg[mirror, 0]] = d[mirror]
            plane[seg[mirror, 1]] = d[mirror]
            on = np.linalg.norm(plane, axis=1) > 0
            t = plane / np.maximum(np.linalg.norm(plane, axis=1), 1e-300)[:, None]
            # the mirror image of a segment arriving along w leaves along w - 2 (w.t) t
            miss_out = on & ~d_out.any(axis=1)
            miss_in = on & ~d_in.any(axis=1)
            d_out[miss_out] = (d_in - 2 * np.einsum("ij,ij->i", d_in, t)[:, None] * t)[miss_out]
            d_in[miss_in] = (d_out - 2 * np.einsum("ij,ij->i", d_out, t)[:, None] * t)[miss_in]
            cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
            return np.arctan2(cross, np.einsum("ij,ij->i", d_in, d_out))
        return self._get("turning", make)

    def turning_within(self, nodes: np.ndarray, radius: np.ndarray) -> np.ndarray:
        """The convex turning of the boundary near each of ``nodes`` (local numbers): the sum
        of the convex turning angles of the boundary nodes within ``radius`` (per node) of it.
        A facet of another surface whose ends lie on this one spans that much of it; concave
        turns there (the bottom of an indentation next to its convex shoulder) do not lower
        what the convex ones can protrude."""
        tree = self._get("tree", lambda: cKDTree(self.x))
        turn = np.maximum(self.turning, 0.0)
        out = np.zeros(len(nodes))
        for k, near in enumerate(tree.query_ball_point(self.x[nodes], radius)):
            out[k] = turn[near].sum()
        return out

    @property
    def adjacent(self) -> np.ndarray:
        """(nb,) the longer of the surface segments at each node."""
        def make():
            out = np.zeros(len(self.x))
            keep = ~self.b.mirror
            for col in (0, 1):
                np.maximum.at(out, self.b.segments[keep, col], self.lengths[keep])
            return out
        return self._get("adjacent", make)

    @property
    def normals(self) -> np.ndarray:
        """(nb, 2) the outward unit normal at each node (the mean of its surface segments'
        normals, weighted by their lengths; on a symmetry plane, its component along the
        plane)."""
        def make():
            a, b = self.ends
            d = b - a
            n = np.column_stack([d[:, 1], -d[:, 0]])
            seg, mirror = self.b.segments, self.b.mirror
            out = _scatter_add(len(self.x), seg[~mirror], n[~mirror])
            plane = np.zeros_like(self.x)
            for col in (0, 1):
                plane[seg[mirror, col]] = d[mirror]
            on = np.flatnonzero(plane.any(axis=1) & out.any(axis=1))
            t = plane[on] / np.linalg.norm(plane[on], axis=1)[:, None]
            out[on] = np.einsum("ij,ij->i", out[on], t)[:, None] * t
            norm = np.linalg.norm(out, axis=1)
            return out / np.where(norm > 0, norm, 1.0)[:, None]
        return self._get("normals", make)


def _scatter_add(n: int, segments: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(n, 2): each segment's value added at both its ends (at every first end, then at every
    second)."""
    return scatter_add(n, segments.T, np.vstack([values, values]))
