"""Parametric meshes graded towards a contact point.

Contact needs small elements where the bodies touch and can afford large ones elsewhere. The
meshes here take a size function ``h(d) = min(h_contact + growth * d, h_max)`` of the distance
``d`` from the point of first contact, so the number of contact candidates stays small while the
bulk can be refined independently.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial import Delaunay, QhullError, cKDTree
from skfem import MeshQuad, MeshTri

from .topology import named_boundaries

#: The most nodes a built-in shape makes. Far more is a slip in its parameters (a size of 1e-9,
#: a count of 1e9) much more often than a wish, and would take minutes or all the memory just to
#: mesh; what the solver can afford is estimated separately (:mod:`vfem.memory`).
MAX_NODES = 2_000_000
#: The most nodes :func:`march` puts on one line (it steps in Python: about a second).
MAX_LINE_NODES = 200_000


def check_count(count: float, what: str) -> None:
    """Refuse (``ValueError``) parameters that would make more than :data:`MAX_NODES` nodes."""
    if not count <= MAX_NODES:  # also NaN
        raise ValueError(f"{what} would make about {count:.3g} nodes, more than the "
                         f"{MAX_NODES:,} a built-in shape may have; check its sizes and counts")


def size_function(h_contact: float, growth: float, h_max: float, plateau: float = 0.0
                  ) -> Callable:
    """h(d): ``h_contact`` up to distance ``plateau``, then growing linearly up to ``h_max``.

    Raises ``ValueError`` unless the sizes are positive and ``growth`` and ``plateau`` are not
    negative: a size that shrinks to zero would never finish a mesh."""
    if not (h_contact > 0 and h_max > 0):
        raise ValueError(f"element sizes must be positive, got h_contact = {h_contact}, "
                         f"h_max = {h_max}")
    if not (growth >= 0 and plateau >= 0):
        raise ValueError(f"growth and plateau must not be negative, got growth = {growth}, "
                         f"plateau = {plateau}")
    return lambda d: np.minimum(
        h_contact + growth * np.maximum(np.asarray(d, dtype=float) - plateau, 0.0), h_max)


def march(length: float, h: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Positions 0 = s_0 < ... < s_n = length with spacing following ``h(s)`` (positive).

    The spacing is stretched uniformly so the last interval ends exactly at ``length``.
    """
    if not 0 < length < np.inf:
        raise ValueError(f"lengths must be positive, got {length}")
    if not float(h(0.0)) >= 1e-9 * length:  # a size round-off cannot resolve, or NaN
        raise ValueError(f"element size {float(h(0.0)):.3g} is too small for a line of length "
                         f"{length:.6g} (less than 1e-9 of it); check the sizes")
    s = [0.0]
    while s[-1] < length:
        if len(s) > MAX_LINE_NODES:
            raise ValueError(f"the element sizes would put more than {MAX_LINE_NODES:,} nodes "
                             f"on a line of length {length:.6g}; check the sizes")
        s.append(s[-1] + float(h(s[-1])))
    s = np.array(s)
    if len(s) > 2 and (s[-1] - length) > 0.5 * (s[-1] - s[-2]):
        s = s[:-1]  # drop a short last interval rather than keep a sliver
    return s * (length / s[-1])


#: Depth of each layer of the structured contact zone of :func:`graded_quarter_disk` over the
#: spacing of the arc's nodes. Below 1, so that Delaunay's choice in each cell is not a tie
#: (at 1 its cells are squares with a centre node, whose four-way split is ambiguous and falls
#: either way by round-off); the pressure is smooth, without a dip at x = 0, for any value
#: from 0.6 to 0.97 (docs/method.md §6 gives p_max against it).
LAYER_RATIO = 0.9


def graded_quarter_disk(radius: float, h_contact: float, h_max: float,
                        growth: float = 0.15, plateau: float = 0.0) -> MeshTri:
    """The lower-right quarter of a disc of centre (0, radius), touching the x-axis at the origin.

    Triangles of size ``h_contact`` within ``plateau`` of the origin, growing beyond. Named
    boundaries: ``contact`` (the arc), ``symmetry`` (x = 0) and ``top`` (y = radius).

    Within ``plateau`` of the origin the nodes lie in layers parallel to the arc, at the arc
    nodes' angles, with a node at the centre of each cell between two layers: every cell is
    split into four triangles the same way, symmetrically about its centre, so the surface
    has the same neighbourhood at every node, the one on the symmetry plane included (nodes on
    rings about the origin, as beyond the plateau, make the origin a centre of a fan of
    triangles whose contact pressure read 2 % low at 12 facets across the contact half-width).
    """
    R = radius
    if not R > 0:
        raise ValueError(f"radius must be positive, got {R}")
    h = size_function(h_contact, growth, h_max, plateau)

    # Boundary points, spaced by h of their distance from the origin.
    s_arc = march(0.5 * np.pi * R, lambda s: h(2 * R * np.sin(s / (2 * R))))
    theta = -0.5 * np.pi + s_arc / R
    arc = np.column_stack([R * np.cos(theta), R + R * np.sin(theta)])
    arc[0] = (0.0, 0.0)
    arc[-1] = (R, R)
    ys = march(R, h)
    # the contact zone's layers (none without a plateau): depths under the arc
    step = LAYER_RATIO * float(s_arc[1])
    depths = step * np.arange(1, int(min(plateau, 0.5 * R) / step) + 1) if plateau > 0 else []
    depths = np.asarray(depths, dtype=float)
    if len(depths):
        ys = np.concatenate([[0.0], depths, ys[ys > depths[-1] + 0.75 * float(h(depths[-1]))]])
    sym = np.column_stack([np.zeros_like(ys), ys])
    xs = march(R, lambda x: h(np.hypot(x, R)))
    top = np.column_stack([xs, np.full_like(xs, R)])
    boundary = np.unique(np.round(np.vstack([arc, sym, top]), 14), axis=0)
    count = len(s_arc) + len(ys) + len(xs)

    # The layers: cell corners at the arc nodes' angles, cell centres between.
    layers = []
    middle = 0.5 * (theta[1:] + theta[:-1])
    for d0, d1 in zip(np.r_[0.0, depths[:-1]], depths):
        for d, angles in ((d1, theta[1:]), (0.5 * (d0 + d1), middle)):
            q = np.column_stack([(R - d) * np.cos(angles), R + (R - d) * np.sin(angles)])
            layers.append(q[np.hypot(q[:, 0], q[:, 1]) <= plateau])
            count += len(layers[-1])
            check_count(count, "graded_quarter_disk")
    layered = np.vstack(layers) if layers else np.zeros((0, 2))

    # Interior points on half rings around the origin, clipped to the domain.
    interior = []
    rho = float(h(0.0))
    while rho < np.sqrt(2) * R:
        lo = np.arccos(min(1.0, R / rho))  # below the top edge y = R
        hi = np.arccos(min(1.0, rho / (2 * R)))  # above the arc
        if hi > lo:
            count += rho * (hi - lo) / float(h(rho))
            check_count(count, "graded_quarter_disk")
            n = max(1, int(round(rho * (hi - lo) / float(h(rho)))))
            phi = lo + (hi - lo) * np.arange(1, n) / n
            interior.append(np.column_stack([rho * np.sin(phi), rho * np.cos(phi)]))
        rho += float(h(rho))
    pts = np.vstack(interior) if interior else np.zeros((0, 2))
    size = h(np.hypot(pts[:, 0], pts[:, 1]))
    keep = farther_than(boundary, pts, 0.6 * size)
    if len(layered):
        keep &= farther_than(layered, pts, 0.8 * size)
    p = np.vstack([boundary, layered, pts[keep]])
    t = _delaunay(p)
    mesh = MeshTri(p.T.copy(), t.T.copy())
    tol = 1e-9 * R
    return named_boundaries(mesh, {
        "symmetry": lambda x: x[0] < tol,
        "top": lambda x: x[1] > R - tol,
        "contact": lambda x: (x[0] > tol) & (x[1] < R - tol),
    })


def graded_half_disk(radius: float, h_contact: float, h_max: float, growth: float = 0.15,
                     plateau: float = 0.0, flat_side: str = "top") -> MeshTri:
    """The lower half of a disc of centre (0, radius), touching the x-axis at the origin
    (``flat_side`` = "bottom": its mirror image below the axis, the upper half of a disc of
    centre (0, -radius)): :func:`graded_quarter_disk` and its mirror image about x = 0, merged.

    Named boundaries: ``contact`` (the arc) and ``flat`` (the diametral side).
    """
    if flat_side not in ("top", "bottom"):
        raise ValueError(f"flat_side must be 'top' or 'bottom', got {flat_side!r}")
    quarter = graded_quarter_disk(radius, h_contact, h_max, growth, plateau)
    mirror = quarter.p * [[-1.0], [1.0]]
    pts = np.hstack([quarter.p, mirror])
    # the quarter's nodes on x = 0 appear twice: one node each (an exact zero, mirrored)
    _, first, inverse = np.unique(np.round(pts.T / (1e-12 * radius)).astype(np.int64), axis=0,
                                  return_index=True, return_inverse=True)
    t = quarter.t
    cells = inverse.ravel()[np.hstack([t, t[[0, 2, 1]] + mirror.shape[1]])]
    pts = pts[:, first]
    if flat_side == "bottom":
        pts, cells = pts * [[1.0], [-1.0]], cells[[0, 2, 1]]
    mesh = MeshTri(np.ascontiguousarray(pts), np.ascontiguousarray(cells))
    tol = 1e-9 * radius
    flat_y = radius if flat_side == "top" else -radius
    return named_boundaries(mesh, {
        "flat": lambda x: np.abs(x[1] - flat_y) < tol,
        "contact": lambda x: np.abs(x[1] - flat_y) >= tol,
    })


def graded_layer(width: float, thickness: float, h_contact: float, h_max: float,
                 growth: float = 0.15, plateau: float = 0.0, layers: int = 2) -> MeshQuad:
    """A rectangular layer [0, width] x [-thickness, 0] of quadrilaterals graded towards x = 0.

    Named boundaries: ``contact`` (top, y = 0), ``bottom``, ``symmetry`` (x = 0), ``right``.
    """
    if not (thickness > 0 and layers >= 1):
        raise ValueError(f"need thickness > 0 and layers >= 1, got {thickness} and {layers}")
    x = march(width, size_function(h_contact, growth, h_max, plateau))
    check_count(len(x) * (layers + 1.0), "graded_layer")
    y = np.linspace(-thickness, 0.0, layers + 1)
    return layer_boundaries(MeshQuad.init_tensor(x, y), width, thickness)


def layer_boundaries(mesh, width: float, thickness: float):
    """Name the sides of a layer [0, width] x [-thickness, 0]: ``contact`` (top, y = 0),
    ``bottom``, ``symmetry`` (x = 0) and ``right`` (x = width)."""
    tol = 1e-9 * max(width, thickness)
    return named_boundaries(mesh, {
        "contact": lambda p: p[1] > -tol,
        "bottom": lambda p: p[1] < -thickness + tol,
        "symmetry": lambda p: p[0] < tol,
        "right": lambda p: p[0] > width - tol,
    })


def farther_than(points: np.ndarray, q: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """Whether each point of ``q`` (k, 2) lies farther than its ``limit`` from all ``points``.

    The same answer as ``cKDTree(points).query(q)[0] > limit``, faster: the search stops at
    twice the largest limit. A point with no neighbour that near is farther than its limit;
    one with a neighbour within it gets the nearest distance, the same number as unbounded.
    Unbounded, every point far from ``points`` (most interior nodes from the contact zone's
    layers) walked the tree to its far nearest neighbour: 2 s of a million-dof Hertz mesh.
    """
    limit = np.asarray(limit, dtype=float)
    if not len(q):
        return np.zeros(0, dtype=bool)
    bound = 2.0 * float(np.max(limit))
    if not bound < np.inf:  # infinite or NaN limits: search everything, as before
        bound = np.inf
    return cKDTree(points).query(q, distance_upper_bound=bound)[0] > limit


def _delaunay(p: np.ndarray) -> np.ndarray:
    """Delaunay triangles of a convex point set, without degenerate ones, counter-clockwise
    (``ValueError`` if the points make none: sizes that leave too few of them)."""
    try:
        t = Delaunay(p).simplices
    except QhullError as exc:
        raise ValueError(f"the nodes cannot be triangulated ({str(exc).splitlines()[0]})"
                         ) from None
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    area = 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                  - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    scale = np.max(np.linalg.norm(b - a, axis=1)) ** 2
    keep = np.abs(area) > 1e-12 * scale
    t = t[keep]
    t[area[keep] < 0] = t[area[keep] < 0][:, [0, 2, 1]]
    return t
