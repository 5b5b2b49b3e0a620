"""Closest-point projection onto facets: where virtual nodes are (thesis §4.5, Fig. 4.4)."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def project_points(points: np.ndarray, a: np.ndarray, b: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest point on a set of segments for each point.

    A KD-tree on the segment midpoints limits the candidates: the closest segment's midpoint is
    no farther than the nearest midpoint plus half the longest segment. The exact projection onto
    the candidates is vectorised.

    Args:
        points: (m, 2) query points.
        a, b: (s, 2) segment ends.

    Returns:
        (segment, t, distance): the nearest segment of each point, the local coordinate of the
        closest point on it (0 at ``a``, 1 at ``b``) and the distance.
    """
    m, s = len(points), len(a)
    if s == 0 or m == 0:
        return np.zeros(m, dtype=int), np.zeros(m), np.full(m, np.inf)
    d = b - a
    L2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    mid = 0.5 * (a + b)
    tree = cKDTree(mid)
    d0, _ = tree.query(points)
    radius = d0 + 0.5 * np.sqrt(L2.max()) * (1 + 1e-9) + 1e-300
    lists = tree.query_ball_point(points, radius)
    counts = np.fromiter((len(c) for c in lists), dtype=int, count=m)
    pt = np.repeat(np.arange(m), counts)
    sg = np.fromiter((j for c in lists for j in c), dtype=int, count=int(counts.sum()))
    t = np.clip(np.einsum("ij,ij->i", points[pt] - a[sg], d[sg]) / L2[sg], 0.0, 1.0)
    diff = points[pt] - (a[sg] + t[:, None] * d[sg])
    d2 = np.einsum("ij,ij->i", diff, diff)
    # per point, the candidate with the smallest distance (ties: the lowest segment number)
    order = np.lexsort((sg, d2, pt))
    first = order[np.r_[0, np.flatnonzero(np.diff(pt[order])) + 1]]
    return sg[first], t[first], np.sqrt(d2[first])


def outward_normals(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Unit outward normals (t_y, -t_x) of oriented facets (see ``ContactSurface``)."""
    t = b - a
    n = np.column_stack([t[:, 1], -t[:, 0]])
    return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
