"""Closest-point projection onto facets: where virtual nodes are (thesis §4.5, Fig. 4.4)."""

from __future__ import annotations

import numpy as np


def project_points(points: np.ndarray, a: np.ndarray, b: np.ndarray,
                   max_pairs: int = 4_000_000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest point on a set of segments for each point, vectorised over points and segments.

    Args:
        points: (m, 2) query points.
        a, b: (s, 2) segment ends.

    Returns:
        (segment, t, distance): the nearest segment of each point, the local coordinate of the
        closest point on it (0 at ``a``, 1 at ``b``) and the distance.
    """
    m, s = len(points), len(a)
    seg = np.zeros(m, dtype=int)
    tt = np.zeros(m)
    dist = np.full(m, np.inf)
    if s == 0 or m == 0:
        return seg, tt, dist
    d = b - a
    L2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    step = max(1, max_pairs // s)
    for lo in range(0, m, step):
        P = points[lo:lo + step, None, :]
        t = np.clip(np.einsum("msk,sk->ms", P - a[None], d) / L2, 0.0, 1.0)
        diff = P - (a[None] + t[..., None] * d[None])
        d2 = np.einsum("msk,msk->ms", diff, diff)
        j = np.argmin(d2, axis=1)
        rows = np.arange(len(j))
        seg[lo:lo + step] = j
        tt[lo:lo + step] = t[rows, j]
        dist[lo:lo + step] = np.sqrt(d2[rows, j])
    return seg, tt, dist


def outward_normals(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Unit outward normals (t_y, -t_x) of oriented facets (see ``ContactSurface``)."""
    t = b - a
    n = np.column_stack([t[:, 1], -t[:, 0]])
    return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
