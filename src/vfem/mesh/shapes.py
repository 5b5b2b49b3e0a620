"""Parametric meshes for the wedge, block and gasket examples of the thesis (§5.3 to §5.5).

Each generator returns a scikit-fem mesh with named boundaries, its elements counter-clockwise
(triangle meshes are built with ``sort_t=False`` so that skfem keeps that order). Sizes follow
the conventions of :mod:`vfem.mesh.parametric`: ``h(d) = min(h_contact + growth * (d - plateau),
h_max)`` of the distance ``d`` from the point of first contact.

* **Wedge** (§5.3): "a wide shallow wedge is driven slightly into a flat plate. The flat plate is
  of unit thickness and is rigidly fixed on its lower surface. The wedge varies from unit thickness
  at the outer edges to a thickness of 1.3 at the center ... The central portion of the wedge has
  an imposed downward motion of 0.3 ... only the right half is modelled." The thesis gives no
  width; :func:`wedge_plate` and :func:`wedge` default to a half-width of 5 (slope 0.06, total
  width ten times the centre thickness: "wide" and "shallow"). Note that the rise of the lower
  face, 1.3 - 1.0 = 0.3, equals the imposed motion: the linear prediction overlaps the plate over
  the whole half-width whatever that width is, the outer edge just reaching the plate's top.
* **Block** (§5.4): "a larger block is forced against a smaller, fixed block ... the sharp
  corners of the smaller block". :func:`block` is a rectangle of quadrilaterals (or triangles),
  uniform or graded towards given lines (such as the other block's corners).
* **Gasket** (§5.5): "a soft gasket of semicircular section and a similar stiff gasket against
  which the soft one is pushed ... The back side of each gasket has all of its displacements
  prescribed. Both gaskets have unit radius and a thickness of 0.1. There is a vertical offset of
  0.25 between the centers and a horizontal separation of 0.2. They are forced together by a
  prescribed horizontal motion of their backs such that each moves 0.25." :func:`gasket` is the
  half annulus, :func:`gasket_pair` the two placed as the thesis describes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np
from scipy.spatial import Delaunay, QhullError, cKDTree
from skfem import MeshQuad, MeshTri

from .parametric import check_count, farther_than, layer_boundaries, march, size_function
from .topology import named_boundaries, share_topology

__all__ = [
    "annulus", "block", "disk", "gasket", "gasket_pair", "graded_nodes", "rectangle", "wedge",
    "wedge_grid", "wedge_plate", "wedge_plate_grid",
]

#: Unit vector of each gasket opening (the side its two cut ends, the back, face).
OPENINGS = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "up": (0.0, 1.0), "down": (0.0, -1.0)}


# ---------------------------------------------------------------------------------------------
# Wedge example (thesis §5.3)
# ---------------------------------------------------------------------------------------------

def wedge_plate(half_width: float = 5.0, thickness: float = 1.0, h_contact: float = 0.05,
                h_max: float = 0.25, growth: float = 0.1, plateau: float = 0.0) -> MeshTri:
    """The right half of the wedge example's plate, ``[0, half_width] x [-thickness, 0]``.

    Triangles of size ``h_contact`` near the origin, where the wedge's point first touches,
    growing with the distance from it up to ``h_max``. Triangles rather than a tensor grid of
    quadrilaterals because the plate deforms through its whole thickness (case 1 of §5.3 puts
    all the deflection in the plate) and a tensor grid graded towards a point is stretched far
    from it. ``h_max`` stays moderate by default because, in the stiff-wedge case, contact
    spreads over the whole top face (see the module notes).

    Named boundaries: ``contact`` (top, y = 0), ``bottom`` (y = -thickness, fixed in the
    thesis), ``symmetry`` (x = 0) and ``right`` (x = half_width).
    """
    W, T = float(half_width), float(thickness)
    if not (W > 0 and T > 0):
        raise ValueError(f"need half_width > 0 and thickness > 0, got {W} and {T}")
    h = size_function(h_contact, growth, h_max, plateau)
    mesh = _graded_trapezoid(W, lower=(-T, -T), upper=(0.0, 0.0), focus=(0.0, 0.0), h=h)
    return layer_boundaries(mesh, W, T)


def wedge(half_width: float = 5.0, edge_thickness: float = 1.0, centre_thickness: float = 1.3,
          h_contact: float = 0.05, h_max: float = 0.25, growth: float = 0.1,
          plateau: float = 0.0, loaded_width: float | None = None) -> MeshTri:
    """The right half of the shallow wedge of §5.3, its point touching the plate at the origin.

    The lower face is the straight line from the tip (0, 0) to (half_width, rise), rise =
    centre_thickness - edge_thickness; the top face is flat at y = centre_thickness, so the
    wedge is ``centre_thickness`` thick at the centre and ``edge_thickness`` at its outer edge.
    Triangles of size ``h_contact`` near the tip, growing with the distance from it up to
    ``h_max``.

    The thesis loads "the central portion of the wedge" by a downward motion of 0.3 without
    saying how wide that portion is; ``loaded_width`` (default ``half_width / 5``, i.e. the
    middle fifth of the full wedge) is the part of the top face, measured from the centre
    plane, that carries it. A node sits exactly at x = loaded_width.

    Named boundaries: ``contact`` (the inclined lower face), ``symmetry`` (x = 0),
    ``top_loaded`` (top face, 0 <= x <= loaded_width), ``top`` (the rest of the top face) and
    ``right`` (the outer edge x = half_width).
    """
    W, T = float(half_width), float(centre_thickness)
    rise = T - float(edge_thickness)
    if not 0.0 < rise < T:
        raise ValueError("need 0 < edge_thickness < centre_thickness")
    b = W / 5.0 if loaded_width is None else float(loaded_width)
    if not 0.0 < b <= W:
        raise ValueError(f"loaded_width must lie in (0, half_width], got {b}")
    h = size_function(h_contact, growth, h_max, plateau)
    mesh = _graded_trapezoid(W, lower=(0.0, rise), upper=(T, T), focus=(0.0, 0.0), h=h,
                             upper_breaks=(b,) if b < W else ())
    tol = 1e-9 * max(W, T)
    on_top = lambda x: x[1] > T - tol  # noqa: E731
    return named_boundaries(mesh, {
        "contact": lambda x: (x[1] < T - tol) & (x[0] > tol) & (x[0] < W - tol),
        "symmetry": lambda x: x[0] < tol,
        "top_loaded": lambda x: on_top(x) & (x[0] < b),
        "top": lambda x: on_top(x) & (x[0] > b),
        "right": lambda x: x[0] > W - tol,
    })


def wedge_plate_grid(half_width: float = 5.0, thickness: float = 1.0, columns: int = 15,
                     rows: int = 3, loaded_width: float | None = None) -> MeshQuad:
    """The wedge example's plate as the thesis meshed it: ``columns`` x ``rows`` quadrilaterals.

    Columns are uniform on either side of x = ``loaded_width`` (default ``half_width / 5``),
    where the wedge's prescribed motion ends, so the two bodies' grids line up as in thesis
    Fig. 5.4. Named boundaries as :func:`wedge_plate`.
    """
    W, T = float(half_width), float(thickness)
    if not (W > 0 and T > 0):
        raise ValueError(f"need half_width > 0 and thickness > 0, got {W} and {T}")
    x = _wedge_columns(W, loaded_width, columns)
    tol = 1e-9 * max(W, T)
    return named_boundaries(_mapped_quads(x, lambda s: -T + 0 * s, lambda s: 0 * s, rows), {
        "contact": lambda q: q[1] > -tol,
        "bottom": lambda q: q[1] < -T + tol,
        "symmetry": lambda q: q[0] < tol,
        "right": lambda q: q[0] > W - tol,
    })


def wedge_grid(half_width: float = 5.0, edge_thickness: float = 1.0,
               centre_thickness: float = 1.3, columns: int = 15, rows: int = 3,
               loaded_width: float | None = None) -> MeshQuad:
    """The wedge of §5.3 as the thesis meshed it: ``columns`` x ``rows`` quadrilaterals whose
    rows follow the inclined lower face. Named boundaries as :func:`wedge`."""
    W, T = float(half_width), float(centre_thickness)
    rise = T - float(edge_thickness)
    if not 0.0 < rise < T:
        raise ValueError("need 0 < edge_thickness < centre_thickness")
    b = W / 5.0 if loaded_width is None else float(loaded_width)
    x = _wedge_columns(W, loaded_width, columns)
    tol = 1e-9 * max(W, T)
    on_top = lambda q: q[1] > T - tol  # noqa: E731
    mesh = _mapped_quads(x, lambda s: rise * s / W, lambda s: T + 0 * s, rows)
    return named_boundaries(mesh, {
        "contact": lambda q: (q[1] < T - tol) & (q[0] > tol) & (q[0] < W - tol),
        "symmetry": lambda q: q[0] < tol,
        "top_loaded": lambda q: on_top(q) & (q[0] < b),
        "top": lambda q: on_top(q) & (q[0] > b),
        "right": lambda q: q[0] > W - tol,
    })


def _wedge_columns(W: float, loaded_width: float | None, n: int) -> np.ndarray:
    """``n`` columns on [0, W], uniform on either side of the loaded width's end."""
    b = W / 5.0 if loaded_width is None else float(loaded_width)
    if not 0.0 < b <= W:
        raise ValueError(f"loaded_width must lie in (0, half_width], got {b}")
    check_count(n + 1.0, "columns")
    if n < 1 or (b < W and n < 2):
        raise ValueError(f"columns must be at least {1 if b == W else 2} (one on each side of "
                         f"loaded_width), got {n}")
    if b < W:
        n1 = min(max(1, round(n * b / W)), n - 1)  # columns under the loaded part
        return np.concatenate([np.linspace(0.0, b, n1 + 1), np.linspace(b, W, n - n1 + 1)[1:]])
    return np.linspace(0.0, W, n + 1)


def _mapped_quads(x: np.ndarray, lower, upper, rows: int) -> MeshQuad:
    """Quadrilaterals between y = lower(x) and y = upper(x) on the columns ``x``, counter-
    clockwise, ``rows`` of them evenly spaced at each x."""
    if rows < 1:
        raise ValueError(f"rows must be at least 1, got {rows}")
    check_count(len(x) * (rows + 1.0), "columns x rows")
    s = np.linspace(0.0, 1.0, rows + 1)
    X, S = np.meshgrid(x, s, indexing="ij")
    Y = lower(X) + S * (upper(X) - lower(X))
    i, j = np.meshgrid(np.arange(len(x) - 1), np.arange(rows), indexing="ij")
    k = (i * (rows + 1) + j).ravel()
    t = np.vstack([k, k + rows + 1, k + rows + 2, k + 1])
    return MeshQuad(np.vstack([X.ravel(), Y.ravel()]), t)


def _graded_trapezoid(width: float, lower: tuple[float, float], upper: tuple[float, float],
                      focus: tuple[float, float], h: Callable,
                      upper_breaks: Sequence[float] = ()) -> MeshTri:
    """Triangles of ``{0 <= x <= width, lower(x) <= y <= upper(x)}``, sized ``h(|p - focus|)``.

    ``lower`` and ``upper`` are the faces' heights at x = 0 and x = width (straight faces).
    Boundary nodes are marched along each side from its end nearer the focus; interior nodes
    lie on rings about the focus (as in :func:`~vfem.mesh.parametric.graded_quarter_disk`).
    ``upper_breaks`` are x positions that must be nodes of the upper face.

    The connectivity is the Delaunay triangulation of the nodes mapped to the rectangle
    ``(x, eta)``, eta = (y - lower) / (upper - lower), where the boundary nodes have exactly
    collinear coordinates. On an inclined face, rounding can put a node a hair outside the
    hull of its neighbours; Delaunay then makes a sliver there, and dropping the sliver would
    leave the node in no triangle.
    """
    W = width
    f = np.asarray(focus, dtype=float)
    lo = lambda x: lower[0] + (lower[1] - lower[0]) * x / W  # noqa: E731
    up = lambda x: upper[0] + (upper[1] - upper[0]) * x / W  # noqa: E731
    corners = np.array([[0.0, lower[0]], [W, lower[1]], [W, upper[1]], [0.0, upper[0]]])
    size = lambda q: h(np.linalg.norm(np.atleast_2d(q) - f, axis=1))  # noqa: E731

    # Boundary nodes as (x, eta): the four corners, then each side's own nodes.
    xe = [np.array([[0.0, 0.0], [W, 0.0], [W, 1.0], [0.0, 1.0]])]
    sides = [(corners[0], corners[1], (0.0, 0.0), (W, 0.0), ()),
             (corners[1], corners[2], (W, 0.0), (W, 1.0), ()),
             (corners[3], corners[2], (0.0, 1.0), (W, 1.0), tuple(upper_breaks)),
             (corners[0], corners[3], (0.0, 0.0), (0.0, 1.0), ())]
    for a, b, ta, tb, breaks in sides:
        s = _side_parameters(a, b, size, [x / W for x in breaks])
        s = s[(s > 0.0) & (s < 1.0)]
        xe.append(np.column_stack([ta[0] + s * (tb[0] - ta[0]), ta[1] + s * (tb[1] - ta[1])]))
    bnd_xe = np.vstack(xe)
    bnd = np.column_stack([bnd_xe[:, 0], lo(bnd_xe[:, 0])
                           + bnd_xe[:, 1] * (up(bnd_xe[:, 0]) - lo(bnd_xe[:, 0]))])

    # Interior nodes on rings about the focus, kept if well inside the domain.
    reach = np.max(np.linalg.norm(corners - f, axis=1))
    rings, rho, count = [], float(h(0.0)), float(len(bnd))
    while rho < reach:
        hr = float(h(rho))
        count += 2.0 * np.pi * rho / hr
        check_count(count, "the element sizes")
        n = max(2, int(np.ceil(2.0 * np.pi * rho / hr)))
        phi = 2.0 * np.pi * np.arange(n) / n
        rings.append(f + rho * np.column_stack([np.cos(phi), np.sin(phi)]))
        rho += hr
    pts = np.vstack(rings)
    x, y = pts[:, 0], pts[:, 1]
    hp = size(pts)
    inside = (x > 0.0) & (x < W) & (y > lo(x)) & (y < up(x))
    pts, hp = pts[inside], hp[inside]
    d_side = np.min([_distance_to_segment(pts, corners[i], corners[(i + 1) % 4])
                     for i in range(4)], axis=0)
    keep = (d_side > 0.45 * hp) & farther_than(bnd, pts, 0.6 * hp)
    pts = pts[keep]

    p = np.vstack([bnd, pts])
    eta = (p[:, 1] - lo(p[:, 0])) / (up(p[:, 0]) - lo(p[:, 0]))
    eta[: len(bnd)] = bnd_xe[:, 1]  # exact 0 / 1 on the lower / upper faces
    xe_all = np.column_stack([p[:, 0], eta * 0.5 * (upper[0] - lower[0] + upper[1] - lower[1])])
    t = _triangulate(xe_all, p)
    return MeshTri(p.T.copy(), t.T.copy(), sort_t=False)


def _side_parameters(a: np.ndarray, b: np.ndarray, size: Callable,
                     breaks: Sequence[float]) -> np.ndarray:
    """Parameters 0 = s_0 < ... < s_n = 1 of nodes on segment a-b spaced by ``size``.

    The segment is split at ``breaks`` (parameters in (0, 1)); each piece is marched from its
    end where ``size`` is smaller, so the spacing grows away from the focus.
    """
    cuts = np.unique(np.concatenate([[0.0, 1.0], np.clip(breaks, 0.0, 1.0)]))
    out = [np.zeros(1)]
    L = float(np.linalg.norm(b - a))
    for s0, s1 in zip(cuts[:-1], cuts[1:]):
        p0, p1 = a + s0 * (b - a), a + s1 * (b - a)
        length = (s1 - s0) * L
        if float(size(p0)[0]) <= float(size(p1)[0]):
            u = march(length, lambda s, p0=p0, p1=p1, length=length:
                      size(p0 + (s / length) * (p1 - p0))[0])
            s = s0 + (s1 - s0) * u / length
        else:
            u = march(length, lambda s, p0=p0, p1=p1, length=length:
                      size(p1 + (s / length) * (p0 - p1))[0])
            s = s1 - (s1 - s0) * u[::-1] / length
        s[0], s[-1] = s0, s1
        out.append(s[1:])
    return np.concatenate(out)


def _distance_to_segment(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point of ``q`` (n, 2) from the segment a-b."""
    ab = b - a
    s = np.clip((q - a) @ ab / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(q - (a + s[:, None] * ab), axis=1)


def _triangulate(q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Delaunay triangles of the convex point set ``q``, oriented counter-clockwise in ``p``.

    ``q`` are the points in the coordinates used for the connectivity, ``p`` the same points
    where the mesh lives. Degenerate triangles (zero area in ``q``) are dropped; every point
    must still belong to some triangle. Raises ``ValueError`` where the parameters make no
    such triangulation (e.g. a body too thin for its element sizes).
    """
    try:
        t = Delaunay(q).simplices
    except QhullError as exc:
        raise ValueError(f"the nodes cannot be triangulated ({str(exc).splitlines()[0]})"
                         ) from None
    keep = np.abs(_polygon_areas(q.T, t.T)) > 1e-12 * np.ptp(q, axis=0).max() ** 2
    t = t[keep]
    area = _polygon_areas(p.T, t.T)
    t[area < 0] = t[area < 0][:, [0, 2, 1]]
    if np.any(np.abs(area) <= 1e-12 * np.ptp(p, axis=0).max() ** 2):
        raise ValueError("degenerate triangle in the mapped triangulation")
    if len(np.unique(t)) != len(p):
        raise ValueError("a mesh node belongs to no triangle")
    return t


def _polygon_areas(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Signed areas (shoelace) of the elements ``t`` (nodes, n) of points ``p`` (2, m).

    Positive for counter-clockwise elements; a quadrilateral's area is exact for any shape.
    """
    x, y = p[0][t], p[1][t]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0)


# ---------------------------------------------------------------------------------------------
# Block example (thesis §5.4)
# ---------------------------------------------------------------------------------------------

def graded_nodes(a: float, b: float, h: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Nodes a = x_0 < ... < x_n = b whose spacing follows the size function ``h(x)``.

    The nodes equidistribute ``N(x) = int_a^x dx / h``: n = ceil(N(b)) intervals, node k where
    N = k N(b) / n. Unlike :func:`~vfem.mesh.parametric.march`, the spacing may shrink and grow
    again along the interval (grading towards both ends, or towards an interior point).
    """
    xs = np.linspace(a, b, 4001)
    inv = 1.0 / np.asarray(h(xs), dtype=float)
    N = np.concatenate([[0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * np.diff(xs))])
    check_count(N[-1], "the element sizes along a line")
    n = max(1, int(np.ceil(N[-1] - 1e-6)))
    x = np.interp(np.arange(n + 1) * N[-1] / n, N, xs)
    x[0], x[-1] = a, b
    return x


def block(x0: float, y0: float, width: float, height: float, h: float, *,
          h_fine: float | None = None, growth: float = 0.2, fine_x: Sequence[float] = (),
          fine_y: Sequence[float] = (), symmetry: str | None = None,
          triangles: bool = False, plateau: float = 0.0) -> MeshQuad | MeshTri:
    """The rectangle ``[x0, x0 + width] x [y0, y0 + height]`` as a tensor grid of elements.

    Uniform with spacing at most ``h``, or, given ``h_fine``, graded: the column widths are
    ``h_fine`` at the lines x = ``fine_x`` (for instance the other block's corners) and grow
    with ``growth`` per unit distance up to ``h``; the row heights likewise towards
    y = ``fine_y`` (for instance the contact face), ``h_fine`` within ``plateau`` of them (a
    contact zone's width: default 0). Lines of ``fine_x``/``fine_y`` inside the rectangle are
    grid lines. Quadrilaterals unless ``triangles`` (each split in two).

    Named boundaries: ``top``, ``bottom``, ``left`` and ``right``; with ``symmetry`` = "left"
    or "right" that side is named ``symmetry`` instead (half model about a vertical plane).
    """
    x1, y1 = x0 + width, y0 + height
    if width <= 0 or height <= 0:
        raise ValueError("width and height must be positive")
    if symmetry not in (None, "left", "right"):
        raise ValueError(f"symmetry must be None, 'left' or 'right', got {symmetry!r}")
    x = _grid_line(x0, x1, h, h_fine, growth, fine_x, plateau)
    y = _grid_line(y0, y1, h, h_fine, growth, fine_y, plateau)
    check_count(float(len(x)) * len(y), "block")
    grid = (MeshTri if triangles else MeshQuad).init_tensor(x, y)
    t = _counter_clockwise(grid.p, grid.t)  # init_tensor's quadrilaterals are clockwise
    mesh = MeshTri(grid.p, t, sort_t=False) if triangles else MeshQuad(grid.p, t)
    tol = 1e-9 * max(width, height)
    names = {"left": "left", "right": "right"}
    if symmetry is not None:
        names[symmetry] = "symmetry"
    return named_boundaries(mesh, {
        "top": lambda p: p[1] > y1 - tol,
        "bottom": lambda p: p[1] < y0 + tol,
        names["left"]: lambda p: p[0] < x0 + tol,
        names["right"]: lambda p: p[0] > x1 - tol,
    })


def rectangle(x0: float = 0.0, y0: float = 0.0, width: float = 1.0, height: float = 1.0,
              nx: int = 1, ny: int = 1, triangles: bool = False) -> MeshQuad | MeshTri:
    """The rectangle ``[x0, x0 + width] x [y0, y0 + height]`` as ``nx`` x ``ny`` equal
    quadrilaterals (each split in two triangles with ``triangles``), counter-clockwise.

    Named boundaries: ``top``, ``bottom``, ``left`` and ``right``.
    """
    if width <= 0 or height <= 0 or nx < 1 or ny < 1:
        raise ValueError("need width, height > 0 and nx, ny >= 1")
    check_count((nx + 1.0) * (ny + 1.0), "rectangle")
    x = np.linspace(x0, x0 + width, int(nx) + 1)
    y = np.linspace(y0, y0 + height, int(ny) + 1)
    grid = (MeshTri if triangles else MeshQuad).init_tensor(x, y)
    t = _counter_clockwise(grid.p, grid.t)
    mesh = MeshTri(grid.p, t, sort_t=False) if triangles else MeshQuad(grid.p, t)
    tol = 1e-9 * max(width, height)
    return named_boundaries(mesh, {
        "top": lambda p: p[1] > y0 + height - tol,
        "bottom": lambda p: p[1] < y0 + tol,
        "left": lambda p: p[0] < x0 + tol,
        "right": lambda p: p[0] > x0 + width - tol,
    })


def rounded_punch(x0: float = 0.0, y0: float = 0.0, width: float = 1.0, height: float = 1.0,
                  radius: float = 1.0, nx: int = 16, ny: int = 8) -> MeshQuad:
    """A punch with a circular face: ``nx`` x ``ny`` quadrilaterals between the arc of radius
    ``radius`` whose lowest point is ``(x0, y0)`` and the flat top ``y = y0 + height``, for
    ``|x - x0| <= width / 2``. Columns are equally spaced in x; rows are graded towards the face
    (each twice as close to the face as the one above is, in ratio 1.25).

    Named boundaries: ``face`` (the arc), ``top``, ``left`` and ``right``.
    """
    half = 0.5 * width
    if width <= 0 or radius < half or nx < 1 or ny < 1:
        raise ValueError("need width > 0, radius >= width / 2 and nx, ny >= 1")
    check_count((nx + 1.0) * (ny + 1.0), "rounded_punch")
    sag = radius - np.sqrt(radius**2 - half**2)
    if height <= sag:
        raise ValueError(f"height must exceed the arc's sag {sag:.6g}")
    xi = np.linspace(-half, half, int(nx) + 1)
    g = 1.25 ** np.arange(int(ny))
    eta = np.concatenate([[0.0], np.cumsum(g) / g.sum()])
    bottom = radius - np.sqrt(radius**2 - xi**2)
    X, E = np.meshgrid(xi, eta, indexing="ij")
    Y = bottom[:, None] + (height - bottom[:, None]) * E
    grid = MeshQuad.init_tensor(xi, eta)  # connectivity of the (nx+1) x (ny+1) grid
    # init_tensor numbers points x-fastest or y-fastest: map each grid point to (X, Y) by value
    ix = np.rint(np.interp(grid.p[0], xi, np.arange(len(xi)))).astype(int)
    iy = np.rint(np.interp(grid.p[1], eta, np.arange(len(eta)))).astype(int)
    pts = np.vstack([x0 + X[ix, iy], y0 + Y[ix, iy]])
    t = _counter_clockwise(pts, grid.t)
    mesh = MeshQuad(pts, t)
    tol = 1e-9 * max(width, height)
    mesh = named_boundaries(mesh, {
        "top": lambda p: p[1] > y0 + height - tol,
        "left": lambda p: p[0] < x0 - half + tol,
        "right": lambda p: p[0] > x0 + half - tol,
    })
    on_face = iy == 0  # the arc's points (chord midpoints are off the arc)
    bnd = mesh.boundary_facets()
    face = bnd[on_face[mesh.facets[0, bnd]] & on_face[mesh.facets[1, bnd]]]
    return share_topology(mesh, replace(mesh, _boundaries={**mesh.boundaries, "face": face}))


def filleted_punch(x0: float = 0.0, y0: float = 0.0, width: float = 1.0, height: float = 0.5,
                   radius: float = 0.1, n_flat: int = 16, n_arc: int = 4, rows: int = 8,
                   grading: float = 1.25, h_tangent: float | None = None) -> MeshQuad:
    """A flat punch with rounded corners: the rectangle ``|x - x0| <= width / 2``,
    ``y0 <= y <= y0 + height`` whose two bottom corners are circular arcs of radius ``radius``
    tangent to the face and to the sides, in quadrilaterals. The flat part of the face has
    ``n_flat`` facets between the tangent points ``x0 -+ (width / 2 - radius)`` (nodes exactly
    there) and each arc ``n_arc`` facets (nodes on the arc): equal ones, or, given
    ``h_tangent``, facets that long at the tangent points growing geometrically away from them
    (where a contact zone ends on a slightly indented arc). Below the arcs' centres ``n_arc``
    rows follow the face around the corners, graded towards it in ratio ``grading``; above them
    ``rows - n_arc`` rows continue the grading geometrically to the top. Each corner holds one
    interior node of three elements (a grid of quadrilaterals cannot turn a smooth corner
    without one). The mesh is symmetric about x = x0.

    Named boundaries: ``face`` (the flat part and the two arcs: what may touch), ``left`` and
    ``right`` (the vertical sides above the arcs) and ``top``.
    """
    a, r, h, g = 0.5 * width, radius, height, grading
    if not all(np.isfinite(v) for v in (x0, y0, width, height, radius, grading)):
        raise ValueError(f"need finite x0, y0, width, height, radius and grading, got {x0}, "
                         f"{y0}, {width}, {height}, {radius} and {grading}")
    if not (width > 0 and 0 < r < a and h > r):
        raise ValueError("need width > 0, 0 < radius < width / 2 and height > radius, got "
                         f"{width}, {radius} and {height}")
    if not (n_flat >= 1 and n_arc >= 2 and rows > n_arc and g > 0):
        raise ValueError(f"need n_flat >= 1, n_arc >= 2, rows > n_arc and grading > 0, got "
                         f"{n_flat}, {n_arc}, {rows} and {grading}")
    check_count((n_flat + 2.0 * n_arc + 1.0) * (rows + 1.0), "filleted_punch")
    n_flat, n_arc, rows = int(n_flat), int(n_arc), int(rows)
    longest = min(2 * (a - r) / n_flat, 0.5 * np.pi * r / n_arc)
    if h_tangent is not None and not 0 < h_tangent <= longest:
        raise ValueError(f"h_tangent must lie in (0, {longest:.6g}] (the equal facets' length), "
                         f"got {h_tangent}")
    with np.errstate(all="ignore"):  # sizes beyond round-off: refused when the nodes are made
        return _filleted_punch(x0, y0, a, r, h, g, n_flat, n_arc, rows, h_tangent)


def _filleted_punch(x0: float, y0: float, a: float, r: float, h: float, g: float, n_flat: int,
                    n_arc: int, rows: int, h_tangent: float | None) -> MeshQuad:
    """:func:`filleted_punch` of checked parameters (a: the half-width)."""
    if h_tangent is None:
        u = np.linspace(-(a - r), a - r, n_flat + 1)
        phi = 0.5 * np.pi * np.arange(n_arc + 1) / n_arc  # from the flat's tangent point
    else:  # facets h_tangent q^(distance in facets from the nearest tangent point), q >= 1
        i = np.arange(n_flat)
        u = -(a - r) + _fitted(lambda q: h_tangent * q ** np.minimum(i, n_flat - 1 - i),
                               2 * (a - r))
        phi = _fitted(lambda q: h_tangent / r * q ** np.arange(n_arc), 0.5 * np.pi)
    u = 0.5 * (u - u[::-1])  # symmetric about 0
    phi = 1.5 * np.pi - phi
    m1 = min(max(int(np.argmin(np.abs(phi - 1.25 * np.pi))), 1), n_arc - 1)
    k, m2 = m1, n_arc - m1  # the arc's facets on the flat's side and on the side's; k: rows of
    # the layer that follows the face around a corner
    w = _geometric(n_arc, r, g)  # offsets from the face of the rows below the arcs' centres
    t = w[: k + 1]
    lower_v = np.concatenate([t, t[-1] + _geometric(m2, r - t[-1], g)[1:]])
    lower_u = np.concatenate([t, t[-1] + _geometric(m1, r - t[-1], g)[1:]])
    upper_v = r + _continued(lower_v[-1] - lower_v[-2], rows - n_arc, h - r)
    # the middle: columns on the flat's nodes, all the rows
    v = np.concatenate([lower_v, upper_v[1:]])
    middle = np.array(np.meshgrid(u, v, indexing="ij"))
    # the left corner: the layer along the arc (i from the flat's tangent point to the side's,
    # j into the body), its inner edge the lines Q1-P-Q2 about the centre c, then the block
    # c, Q1, P, Q2 inside it (P: the node of three elements, its angles near 120 degrees)
    c = np.array([-a + r, r])
    rho = r - t[-1]
    e = np.array([np.cos(phi), np.sin(phi)])
    e[:, 0], e[:, -1] = (0.0, -1.0), (-1.0, 0.0)
    q1, q2 = c + rho * e[:, 0], c + rho * e[:, -1]
    p_mid = c + min(np.sqrt(2.0) * (3 + np.sqrt(3)) / 6 * rho, rho + 0.5 * t[-1]) * e[:, m1]
    inner = np.empty(n_arc + 1)  # distance from c to the lines Q1-P-Q2 along e
    for i in range(n_arc + 1):
        A, B = (q1, p_mid) if i <= m1 else (p_mid, q2)
        d = B - A
        inner[i] = ((A[0] - c[0]) * d[1] - (A[1] - c[1]) * d[0]) / (e[0, i] * d[1]
                                                                   - e[1, i] * d[0])
    inner[0], inner[-1] = rho, rho
    radius_ij = r - np.outer(r - inner, t / t[-1])  # (i, j)
    layer = c[:, None, None] + radius_ij[None] * e[:, :, None]
    layer[:, :, 0] = c[:, None] + r * e  # the arc itself
    bottom = np.array([-a + lower_u[k:], np.full(m1 + 1, r)])  # Q2 -> c
    top = layer[:, m1::-1, k]  # P -> Q1
    left = layer[:, n_arc:m1 - 1:-1, k]  # Q2 -> P (m1 >= 1)
    right = np.array([np.full(m2 + 1, -a + r), lower_v[n_arc:k - 1:-1]])  # c -> Q1 (k >= 1)
    corner = _transfinite(bottom, top, left, right)
    side = np.array(np.meshgrid(-a + lower_u, upper_v, indexing="ij"))
    mirror = np.array([-1.0, 1.0])[:, None, None]
    blocks = [middle, layer, corner, side, mirror * layer, mirror * corner, mirror * side]
    face_blocks = (0, 1, 4)  # the face: row 0 of these blocks
    points, quads, face, n = [], [], [], 0
    for b, X in enumerate(blocks):
        idx = n + np.arange(X.shape[1] * X.shape[2]).reshape(X.shape[1:])
        quads.append(np.vstack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(),
                                idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()]))
        points.append(X.reshape(2, -1))
        if b in face_blocks:
            face.append(idx[:, 0])
        n += idx.size
    p = np.hstack(points)
    if not np.isfinite(p).all():
        raise ValueError("the parameters make coordinates that are not finite numbers; check "
                         "the sizes and the grading")
    tol = 1e-9 * max(2 * a, h)
    rep = np.arange(p.shape[1])  # the first of the nodes at one position stands for them all
    pairs = cKDTree(p.T).query_pairs(tol, output_type="ndarray")
    np.minimum.at(rep, pairs[:, 1], pairs[:, 0])
    keep, new = np.unique(rep, return_inverse=True)
    p = p[:, keep] + np.array([[x0], [y0]])
    t4 = new[np.hstack(quads)]
    on_face = np.zeros(p.shape[1], dtype=bool)
    on_face[new[np.concatenate(face)]] = True
    mesh = named_boundaries(MeshQuad(p, _counter_clockwise(p, t4)), {
        "top": lambda q: q[1] > y0 + h - tol,
        "left": lambda q: q[0] < x0 - a + tol,
        "right": lambda q: q[0] > x0 + a - tol,
    })
    bnd = mesh.boundary_facets()
    face_facets = bnd[on_face[mesh.facets[0, bnd]] & on_face[mesh.facets[1, bnd]]]
    return share_topology(mesh, replace(mesh, _boundaries={**mesh.boundaries,
                                                           "face": face_facets}))


def _geometric(n: int, length: float, ratio: float) -> np.ndarray:
    """n + 1 positions from 0 to ``length``, each interval ``ratio`` times the one before."""
    s = ratio ** (np.arange(n, dtype=float) - (n - 1 if ratio > 1 else 0))  # at most 1
    x = length * np.concatenate([[0.0], np.cumsum(s) / s.sum()])
    x[-1] = length
    return x


def _continued(first: float, n: int, length: float) -> np.ndarray:
    """n + 1 positions from 0 to ``length`` whose intervals are ``first * q**(i + 1)``: a
    geometric grading continuing from an interval ``first``, its ratio q chosen to fit."""
    return _fitted(lambda q: first * q ** np.arange(1, n + 1, dtype=float), length)


def _fitted(sizes: Callable[[float], np.ndarray], length: float) -> np.ndarray:
    """Positions 0, ..., ``length`` whose intervals are ``sizes(q)`` (increasing in q, and
    from q = 0 on) with q found by bisection to fit; the last one exactly ``length``."""
    lo, hi = 0.0, 1.0
    with np.errstate(over="ignore", invalid="ignore"):
        while np.sum(sizes(hi)) < length and hi < 1e300:
            hi *= 2.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if np.sum(sizes(mid)) < length else (lo, mid)
    s = np.asarray(sizes(hi), dtype=float)
    x = np.concatenate([[0.0], np.cumsum(s * (length / s.sum()))])
    x[-1] = length
    return x


def _transfinite(bottom: np.ndarray, top: np.ndarray, left: np.ndarray, right: np.ndarray
                 ) -> np.ndarray:
    """(2, m + 1, n + 1) grid points between four sides given as nodes (2, m + 1) bottom and
    top, (2, n + 1) left and right, running with the grid's indices (Coons patch; parameters:
    the two opposite sides' relative arc lengths, averaged)."""
    def fraction(x):
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=1), axis=0))])
        return s / s[-1]

    xi = 0.5 * (fraction(bottom) + fraction(top))[:, None]
    eta = 0.5 * (fraction(left) + fraction(right))[None, :]
    B, T = bottom[:, :, None], top[:, :, None]
    L, R = left[:, None, :], right[:, None, :]
    return ((1 - eta) * B + eta * T + (1 - xi) * L + xi * R
            - (1 - xi) * (1 - eta) * bottom[:, :1, None] - xi * (1 - eta) * bottom[:, -1:, None]
            - (1 - xi) * eta * top[:, :1, None] - xi * eta * top[:, -1:, None])


def _grid_line(a: float, b: float, h: float, h_fine: float | None, growth: float,
               fine: Sequence[float], plateau: float = 0.0) -> np.ndarray:
    """Grid positions on [a, b]: uniform (spacing <= h), or graded towards ``fine`` (spacing
    ``h_fine`` within ``plateau`` of them)."""
    if not h > 0:
        raise ValueError(f"the element size h must be positive, got {h}")
    if h_fine is None or len(fine) == 0:
        check_count((b - a) / h, "the element size h")
        return np.linspace(a, b, max(1, int(np.ceil((b - a) / h - 1e-9))) + 1)
    f = np.asarray(fine, dtype=float)
    size = size_function(h_fine, growth, h, plateau)
    hx = lambda x: size(np.min(np.abs(np.asarray(x)[:, None] - f[None, :]), axis=1))  # noqa: E731
    cuts = np.unique(np.concatenate([[a, b], f[(f > a) & (f < b)]]))
    return np.concatenate([graded_nodes(c0, c1, hx)[:-1] for c0, c1 in zip(cuts[:-1], cuts[1:])]
                          + [[b]])


def _counter_clockwise(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Elements ``t`` (nodes, n) of points ``p`` (2, m), the clockwise ones reversed."""
    t = t.copy()
    cw = _polygon_areas(p, t) < 0
    t[:, cw] = t[::-1, cw]
    return t


# ---------------------------------------------------------------------------------------------
# Gasket example (thesis §5.5)
# ---------------------------------------------------------------------------------------------

def gasket(centre: tuple[float, float] = (0.0, 0.0), radius: float = 1.0,
           thickness: float = 0.1, opening: str = "left", n_around: int = 120,
           n_through: int = 4) -> MeshQuad:
    """A gasket of semicircular section: the half annulus ``radius - thickness <= r <= radius``.

    ``radius`` is the outer radius, that of the contact face. ``opening`` is the side the
    open half faces ("left", "right", "up" or "down"): the material spans the 180 degrees
    centred on the opposite direction, so a gasket opening "left" bulges to the right. Its two
    cut ends lie on the diameter through ``centre``; they are the **back** that the thesis
    prescribes ("The back side of each gasket has all of its displacements prescribed") and
    moves horizontally. Why the ends and not the concave inner face: with the inner face held,
    each gasket could only squeeze through its 0.1 thickness, while the motion the thesis
    imposes (each back 0.25, first overlap at step 5) makes the outer faces overlap by about
    0.28 at the deepest step; held at its ends, each gasket is an arch that bends out of the
    way.

    Structured polar grid of ``n_around`` x ``n_through`` quadrilaterals (straight-sided; for
    faces on the true circles see :func:`vfem.mesh.quadratic.curved`).

    Named boundaries: ``outer`` (r = radius, the contact face), ``inner`` (r = radius -
    thickness) and ``back`` (the two cut ends).
    """
    if opening not in OPENINGS:
        raise ValueError(f"opening must be one of {sorted(OPENINGS)}, got {opening!r}")
    if not 0.0 < thickness < radius:
        raise ValueError("need 0 < thickness < radius")
    if n_around < 1 or n_through < 1:
        raise ValueError(f"need n_around, n_through >= 1, got {n_around} and {n_through}")
    check_count((n_around + 1.0) * (n_through + 1.0), "gasket")
    c = np.asarray(centre, dtype=float)
    o = np.asarray(OPENINGS[opening])
    middle = np.arctan2(-o[1], -o[0])
    theta = middle + np.pi * (np.arange(n_around + 1) / n_around - 0.5)
    r = np.linspace(radius - thickness, radius, n_through + 1)
    # Node (i, j) at angle theta[i], radius r[j]; index i * (n_through + 1) + j.
    R, TH = np.meshgrid(r, theta)
    cos, sin = np.cos(TH).ravel(), np.sin(TH).ravel()
    cos[np.abs(cos) < 1e-15] = 0.0  # exact ends on the diameter
    sin[np.abs(sin) < 1e-15] = 0.0
    p = np.vstack([c[0] + R.ravel() * cos, c[1] + R.ravel() * sin])
    i, j = np.meshgrid(np.arange(n_around), np.arange(n_through), indexing="ij")
    k = (i * (n_through + 1) + j).ravel()
    # Outwards then round: counter-clockwise since e_r x e_theta = +e_z.
    t = np.vstack([k, k + 1, k + n_through + 2, k + n_through + 1])
    mesh = MeshQuad(p, t)
    tol = 1e-9 * radius
    back = lambda x: np.abs((x[0] - c[0]) * o[0] + (x[1] - c[1]) * o[1]) < tol  # noqa: E731
    dist = lambda x: np.hypot(x[0] - c[0], x[1] - c[1])  # noqa: E731
    mid = radius - 0.5 * thickness
    return named_boundaries(mesh, {
        "outer": lambda x: ~back(x) & (dist(x) > mid),
        "inner": lambda x: ~back(x) & (dist(x) < mid),
        "back": back,
    })


def gasket_pair(radius: float = 1.0, thickness: float = 0.1, offset: float = 0.25,
                separation: float = 0.2, n_around: int = 120, n_through: int = 4
                ) -> tuple[MeshQuad, MeshQuad]:
    """The two gaskets of §5.5, bulging towards each other: (left, right).

    The left gasket opens to the left (bulges right), the right one opens to the right; their
    backs move horizontally towards each other. "A vertical offset of 0.25 between the centers"
    is ``offset`` (the right centre is higher), and "a horizontal separation of 0.2" is read as
    the horizontal clearance between the two outermost points of the contact faces, so the
    centres are ``2 radius + separation`` apart horizontally. The centres sit at
    ``(-(radius + separation / 2), -offset / 2)`` and ``(radius + separation / 2, offset / 2)``.

    Check against the thesis: the outer faces touch when the backs have closed by
    ``separation + 2 R - sqrt(4 R^2 - offset^2)`` = 0.2157 for the thesis data, so with each
    back moving 0.025 per step (0.05 closure) the first overlap comes at step 5, and after the
    full 0.25 each (step 10) the faces overlap by 0.28, as the thesis describes.
    """
    dx = radius + 0.5 * separation
    left = gasket((-dx, -0.5 * offset), radius, thickness, "left", n_around, n_through)
    right = gasket((dx, 0.5 * offset), radius, thickness, "right", n_around, n_through)
    return left, right


# ---------------------------------------------------------------------------------------------
# Disk and annulus: a shaft and a hub in section (an interference fit, issue 21)


def disk_map(u: np.ndarray, v: np.ndarray, R: float, blend_from: float = 0.5,
             circle_from: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The plan of :func:`disk` (and of the 3D :func:`vfem.mesh.solids.cylinder`): points
    (u, v) of a square grid on [-1, 1]^2 (or [0, 1]^2) mapped onto the disk of radius ``R``.
    The square rings m = max(|u|, |v|) stay squares inside ``blend_from`` and are circles of
    radius m R from ``circle_from`` on, blended linearly between; a node of a circle sits at an
    angle proportional to its place along its square ring, so the rim's nodes are equally
    spaced in angle where the grid is even."""
    m = np.maximum(np.abs(u), np.abs(v))  # the square ring through the node
    # beta: 0 inside blend_from (the square kept), 1 on the rim (the circle), linear between:
    # the rings stay nested (a ring's diagonal point, m R (sqrt 2 - (sqrt 2 - 1) beta), grows
    # with m while d beta / dm < 1 / (sqrt 2 - 1)), which blend_from < 0.58 keeps
    beta = np.clip((m - blend_from) / (circle_from - blend_from), 0.0, 1.0)
    # the circle's point of a node of ring m: at an angle proportional to the node's place
    # along its square ring (not on the ray through it), so the rim's nodes are equally spaced
    # in angle: facets of equal length, and a ring (solids.ring) with as many facets per turn
    # has its nodes at the same angles (a shaft in a hub: similar polygons, no faceting mismatch)
    flat = np.abs(u) >= np.abs(v)
    safe_u = np.where(u != 0, u, 1.0)
    safe_v = np.where(v != 0, v, 1.0)
    angle = np.where(flat, 0.25 * np.pi * v / safe_u + np.where(u < 0, np.pi, 0.0),
                     0.5 * np.pi - 0.25 * np.pi * u / safe_v + np.where(v < 0, np.pi, 0.0))
    x = R * ((1.0 - beta) * u + beta * m * np.cos(angle))
    y = R * ((1.0 - beta) * v + beta * m * np.sin(angle))
    x[m == 0] = y[m == 0] = 0.0
    return x, y


def disk(radius: float = 1.0, h: float = 0.1, *, quarter: bool = True, half: bool = False,
         blend_from: float = 0.5) -> MeshQuad:
    """The disk of ``radius`` about the origin (with ``quarter``, its part x >= 0, y >= 0; with
    ``half``, its part y >= 0: the cross-section of an O-ring above its plane of symmetry) in
    quadrilaterals: a square grid of spacing about ``h`` mapped onto it as the plan of
    :func:`vfem.mesh.solids.cylinder` (:func:`disk_map`): its rim's nodes at
    equal angles, 2 n per quarter turn for n divisions across, so an :func:`annulus` with as
    many facets per quarter turn has its bore's nodes at the same angles.

    Named boundaries: ``rim`` and, with ``quarter``, ``left`` (x = 0) and ``bottom`` (y = 0);
    with ``half``, ``bottom`` (y = 0).
    """
    if not (radius > 0 and h > 0):
        raise ValueError(f"radius and h must be positive, got {radius} and {h}")
    if half and quarter:
        raise ValueError("give quarter or half, not both (quarter = false with half = true)")
    n = max(1, int(np.ceil(radius / h - 1e-9)))
    check_count((2.0 * n + 1.0) ** 2, "disk")
    line = np.linspace(0.0 if quarter else -1.0, 1.0, n + 1 if quarter else 2 * n + 1)
    mesh = MeshQuad.init_tensor(line, np.linspace(0.0, 1.0, n + 1) if half else line)
    tol = 1e-9
    tests = {"rim": lambda p: np.maximum(np.abs(p[0]), np.abs(p[1])) > 1 - tol}
    if quarter:
        tests.update(left=lambda p: p[0] < tol, bottom=lambda p: p[1] < tol)
    if half:
        tests.update(bottom=lambda p: p[1] < tol)
    mesh = named_boundaries(mesh, tests)
    x, y = disk_map(mesh.p[0], mesh.p[1], radius, blend_from)
    return share_topology(mesh, replace(mesh, doflocs=np.vstack([x, y])))


def annulus(inner_radius: float = 1.0, outer_radius: float = 2.0, *, around: int = 16,
            radial: int = 4, half: bool = False, split: float = 60.0) -> MeshQuad:
    """The quarter annulus x >= 0, y >= 0 between two circles about the origin in
    quadrilaterals: ``around`` divisions per quarter turn (nodes at equal angles), ``radial``
    through the wall. Named boundaries: ``inner``, ``outer``, ``left`` (x = 0) and ``bottom``
    (y = 0).

    With ``half``: the half annulus x >= 0 (a ring's section halved by its vertical plane of
    symmetry: a ring crushed between two plates), ``around`` divisions per quarter turn. Named
    boundaries: ``inner`` and ``outer``; ``top`` and ``bottom`` (the cuts at x = 0, y > 0 and
    y < 0); ``inner_upper`` and ``inner_lower`` (the bore's parts more than ``split`` degrees
    above and below the horizontal: the two sides of the bore that meet when the ring is
    crushed flat, apart from each other, for a self-contact pair); ``foot`` (the outer facet at
    the bottom: a point support that holds the ring's vertical motion)."""
    if not 0 < inner_radius < outer_radius:
        raise ValueError(f"need 0 < inner_radius < outer_radius, got {inner_radius} and "
                         f"{outer_radius}")
    if not (isinstance(around, (int, np.integer)) and isinstance(radial, (int, np.integer))
            and around >= 1 and radial >= 1):
        raise ValueError(f"around and radial must be whole numbers >= 1, got {around} and "
                         f"{radial}")
    if half:
        if not 0.0 < split < 90.0:
            raise ValueError(f"split must lie in (0, 90) degrees, got {split}")
        check_count((2.0 * around + 1.0) * (radial + 1.0), "annulus")
        mesh = MeshQuad.init_tensor(np.linspace(inner_radius, outer_radius, radial + 1),
                                    np.linspace(-0.5 * np.pi, 0.5 * np.pi, 2 * around + 1))
        tol = 1e-9 * outer_radius
        cut, step = np.radians(split), 0.5 * np.pi / around
        mesh = named_boundaries(mesh, {
            "inner": lambda p: p[0] < inner_radius + tol,
            "inner_upper": lambda p: (p[0] < inner_radius + tol) & (p[1] > cut),
            "inner_lower": lambda p: (p[0] < inner_radius + tol) & (p[1] < -cut),
            "outer": lambda p: p[0] > outer_radius - tol,
            "foot": lambda p: (p[0] > outer_radius - tol) & (p[1] < -0.5 * np.pi + step),
            "top": lambda p: p[1] > 0.5 * np.pi - 1e-9,
            "bottom": lambda p: p[1] < -0.5 * np.pi + 1e-9})
        r, t = mesh.p
        return share_topology(mesh, replace(mesh, doflocs=np.vstack([r * np.cos(t),
                                                                     r * np.sin(t)])))
    check_count((around + 1.0) * (radial + 1.0), "annulus")
    mesh = MeshQuad.init_tensor(np.linspace(inner_radius, outer_radius, radial + 1),
                                np.linspace(0.0, 0.5 * np.pi, around + 1))
    tol = 1e-9 * outer_radius
    mesh = named_boundaries(mesh, {
        "inner": lambda p: p[0] < inner_radius + tol, "outer": lambda p: p[0] > outer_radius - tol,
        "bottom": lambda p: p[1] < 1e-9, "left": lambda p: p[1] > 0.5 * np.pi - 1e-9})
    r, t = mesh.p
    return share_topology(mesh, replace(mesh, doflocs=np.vstack([r * np.cos(t), r * np.sin(t)])))
