"""Parametric meshes graded towards a contact point.

Contact needs small elements where the bodies touch and can afford large ones elsewhere. The
meshes here take a size function ``h(d) = min(h_contact + growth * d, h_max)`` of the distance
``d`` from the point of first contact, so the number of contact candidates stays small while the
bulk can be refined independently.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial import Delaunay, cKDTree
from skfem import MeshQuad, MeshTri


def size_function(h_contact: float, growth: float, h_max: float, plateau: float = 0.0
                  ) -> Callable:
    """h(d): ``h_contact`` up to distance ``plateau``, then growing linearly up to ``h_max``."""
    return lambda d: np.minimum(
        h_contact + growth * np.maximum(np.asarray(d, dtype=float) - plateau, 0.0), h_max)


def march(length: float, h: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Positions 0 = s_0 < ... < s_n = length with spacing following ``h(s)``.

    The spacing is stretched uniformly so the last interval ends exactly at ``length``.
    """
    s = [0.0]
    while s[-1] < length:
        s.append(s[-1] + float(h(s[-1])))
    s = np.array(s)
    if len(s) > 2 and (s[-1] - length) > 0.5 * (s[-1] - s[-2]):
        s = s[:-1]  # drop a short last interval rather than keep a sliver
    return s * (length / s[-1])


def graded_quarter_disk(radius: float, h_contact: float, h_max: float,
                        growth: float = 0.15, plateau: float = 0.0) -> MeshTri:
    """The lower-right quarter of a disc of centre (0, radius), touching the x-axis at the origin.

    Triangles of size ``h_contact`` within ``plateau`` of the origin, growing beyond. Named
    boundaries: ``contact`` (the arc), ``symmetry`` (x = 0) and ``top`` (y = radius).
    """
    R = radius
    h = size_function(h_contact, growth, h_max, plateau)

    # Boundary points, spaced by h of their distance from the origin.
    s_arc = march(0.5 * np.pi * R, lambda s: h(2 * R * np.sin(s / (2 * R))))
    theta = -0.5 * np.pi + s_arc / R
    arc = np.column_stack([R * np.cos(theta), R + R * np.sin(theta)])
    arc[0] = (0.0, 0.0)
    arc[-1] = (R, R)
    ys = march(R, h)
    sym = np.column_stack([np.zeros_like(ys), ys])
    xs = march(R, lambda x: h(np.hypot(x, R)))
    top = np.column_stack([xs, np.full_like(xs, R)])
    boundary = np.unique(np.round(np.vstack([arc, sym, top]), 14), axis=0)

    # Interior points on half rings around the origin, clipped to the domain.
    interior = []
    rho = float(h(0.0))
    while rho < np.sqrt(2) * R:
        lo = np.arccos(min(1.0, R / rho))  # below the top edge y = R
        hi = np.arccos(min(1.0, rho / (2 * R)))  # above the arc
        if hi > lo:
            n = max(1, int(round(rho * (hi - lo) / float(h(rho)))))
            phi = lo + (hi - lo) * np.arange(1, n) / n
            interior.append(np.column_stack([rho * np.sin(phi), rho * np.cos(phi)]))
        rho += float(h(rho))
    pts = np.vstack(interior) if interior else np.zeros((0, 2))
    d_b, _ = cKDTree(boundary).query(pts)
    pts = pts[d_b > 0.6 * h(np.hypot(pts[:, 0], pts[:, 1]))]
    p = np.vstack([boundary, pts])
    t = _delaunay(p)
    mesh = MeshTri(p.T.copy(), t.T.copy())
    tol = 1e-9 * R
    return mesh.with_boundaries({
        "symmetry": lambda x: x[0] < tol,
        "top": lambda x: x[1] > R - tol,
        "contact": lambda x: (x[0] > tol) & (x[1] < R - tol),
    })


def graded_layer(width: float, thickness: float, h_contact: float, h_max: float,
                 growth: float = 0.15, plateau: float = 0.0, layers: int = 2) -> MeshQuad:
    """A rectangular layer [0, width] x [-thickness, 0] of quadrilaterals graded towards x = 0.

    Named boundaries: ``contact`` (top, y = 0), ``bottom``, ``symmetry`` (x = 0), ``right``.
    """
    x = march(width, size_function(h_contact, growth, h_max, plateau))
    y = np.linspace(-thickness, 0.0, layers + 1)
    mesh = MeshQuad.init_tensor(x, y)
    tol = 1e-9 * max(width, thickness)
    return mesh.with_boundaries({
        "contact": lambda p: p[1] > -tol,
        "bottom": lambda p: p[1] < -thickness + tol,
        "symmetry": lambda p: p[0] < tol,
        "right": lambda p: p[0] > width - tol,
    })


def _delaunay(p: np.ndarray) -> np.ndarray:
    """Delaunay triangles of a convex point set, without degenerate ones, counter-clockwise."""
    t = Delaunay(p).simplices
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    area = 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                  - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    scale = np.max(np.linalg.norm(b - a, axis=1)) ** 2
    keep = np.abs(area) > 1e-12 * scale
    t = t[keep]
    t[area[keep] < 0] = t[area[keep] < 0][:, [0, 2, 1]]
    return t
