"""Closest-point projection onto facets: where virtual nodes are (thesis §4.5, Fig. 4.4)."""

from __future__ import annotations

import itertools

import numpy as np
from scipy.spatial import cKDTree

#: up to this many point-segment pairs the candidates are found directly, above it by a KD-tree
#: on the segments' midpoints (issue 19: a large-kinematics iteration projects a few dozen
#: points onto a few dozen facets thousands of times, where the tree's set-up and its Python
#: lists were most of the time)
DIRECT_PAIRS = 8192


def project_points(points: np.ndarray, a: np.ndarray, b: np.ndarray,
                   point_normals: np.ndarray | None = None, free: bool = False):
    """Closest point on a set of segments for each point.

    A KD-tree on the segment midpoints limits the candidates: the closest segment's midpoint is
    no farther than the nearest midpoint plus half the longest segment. The exact projection onto
    the candidates is vectorised.

    **Ties** (a point as near to a segment as to its nearest, to 1e-9 of the longest segment,
    e.g. closest to the vertex two segments share; judged against the nearest, as in 3D): with
    ``point_normals`` (the outward normal of the surface the point lies on) the segment whose
    outward normal (``(t_y, -t_x)``) is most opposed to it wins, so the point pairs with the
    facet that faces it; then the one whose segment the point lies over (unclamped t inside
    [0, 1]); then the lowest segment number. The two nodes of a symmetric model that lie over
    mirrored vertices so choose mirrored facets.

    Args:
        points: (m, 2) query points.
        a, b: (s, 2) segment ends.
        point_normals: (m, 2) unit normals at the points, for ties (optional).
        free: also return the unclamped local coordinate (where the point lies along the
            segment's line: outside [0, 1] beyond its ends).

    Returns:
        (segment, t, distance[, t_free]): the nearest segment of each point, the local coordinate
        of the closest point on it (0 at ``a``, 1 at ``b``) and the distance.
    """
    m, s = len(points), len(a)
    if s == 0 or m == 0:
        empty = (np.zeros(m, dtype=int), np.zeros(m), np.full(m, np.inf))
        return empty + (np.zeros(m),) if free else empty
    d = b - a
    L2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    mid = 0.5 * (a + b)
    half = 0.5 * np.sqrt(L2.max()) * (1 + 1e-9) + 1e-300
    if m * s <= DIRECT_PAIRS:
        # few points and segments: every pair's midpoint distance at once, the candidates the
        # tree would give (its set-up and the Python lists it returns cost more here)
        to_mid = np.hypot(points[:, None, 0] - mid[None, :, 0],
                          points[:, None, 1] - mid[None, :, 1])
        pt, sg = np.nonzero(to_mid <= (to_mid.min(axis=1) + half)[:, None])
    else:
        tree = cKDTree(mid)
        d0, _ = tree.query(points)
        lists = tree.query_ball_point(points, d0 + half)
        counts = np.fromiter((len(c) for c in lists), dtype=int, count=m)
        pt = np.repeat(np.arange(m), counts)
        sg = np.fromiter(itertools.chain.from_iterable(lists), dtype=int,
                         count=int(counts.sum()))
    tf = np.einsum("ij,ij->i", points[pt] - a[sg], d[sg]) / L2[sg]
    t = np.clip(tf, 0.0, 1.0)
    diff = points[pt] - (a[sg] + t[:, None] * d[sg])
    dist = np.sqrt(np.einsum("ij,ij->i", diff, diff))
    # distances within 1e-9 of the longest segment of the point's nearest are ties: judged
    # against the nearest, not by fixed bins of the distance. Two distances closer than that
    # fall into neighbouring bins wherever a bin's edge lies between them, so which was
    # "nearer" changed as the point moved by 1e-9. Random model 2d-49 in r-z: the block's
    # facets beside a soft punch's corner read that corner from just inside its bottom
    # facet's strip (distances 2e-11 apart, ties by this rule); as the iterates moved, each
    # facet read the side facet (not facing: out of the pair's patch) or the bottom (in),
    # the nodal normal at the patch's end jumped with it and Newton cycled for good.
    nearest = np.full(m, np.inf)
    np.minimum.at(nearest, pt, dist)
    tied = dist <= nearest[pt] + 1e-9 * np.sqrt(L2.max())
    facing = np.zeros(len(sg))
    if point_normals is not None:
        n = np.column_stack([d[sg, 1], -d[sg, 0]]) / np.sqrt(L2[sg])[:, None]
        facing = np.round(np.einsum("ij,ij->i", point_normals[pt], n), 9)
    outside = (tf < -1e-9) | (tf > 1 + 1e-9)
    # per point, a candidate tied with the nearest, by the tie rules
    order = np.lexsort((sg, outside, facing, ~tied, pt))
    first = order[np.r_[0, np.flatnonzero(np.diff(pt[order])) + 1]]
    out = (sg[first], t[first], dist[first])
    return out + (tf[first],) if free else out


def normal_of_tangent(t: np.ndarray) -> np.ndarray:
    """The (not normalised) outward normals (t_y, -t_x) of a 2D surface's tangents ``t`` (its
    facets oriented so, see ``ContactSurface``): where the 2D geometry turns a tangent into a
    normal (a 3D facet takes the cross product of its two tangents)."""
    return np.column_stack([t[:, 1], -t[:, 0]])


def outward_normals(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Unit outward normals (t_y, -t_x) of oriented facets (see ``ContactSurface``)."""
    n = normal_of_tangent(b - a)
    return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
