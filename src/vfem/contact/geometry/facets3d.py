"""The facets of a 3D contact surface (issue 21, commit C5 of the 3D plan): their kinds, shape
functions, maps and normals, the checks of a facet set, the bounds of a facet's warp and
curvature, and the candidate facets of each query point, on which
:mod:`vfem.contact.geometry.closest3d` finds the closest points.

**Facets.** One kind per call, told by the number of nodes per facet (``facets.shape[1]``):

====  =========================  ==========================  ==============================
k     kind                       reference domain            node order (scikit-fem's)
====  =========================  ==========================  ==============================
3     linear triangle (T3)       ξ, η ≥ 0, ξ + η ≤ 1          ``ElementTriP1``: (0,0) (1,0) (0,1)
4     bilinear quadrilateral     [0, 1]²                      ``ElementQuad1``: (0,0) (1,0)
      (Q4), possibly warped                                   (1,1) (0,1)
6     quadratic triangle (T6)    as T3                        ``ElementTriP2``: the corners,
                                                              then the midpoints of the edges
                                                              0-1, 1-2, 0-2
9     quadratic quadrilateral    [0, 1]²                      ``ElementQuad2``: the corners,
      (Q9)                                                    the midpoints of 0-1, 1-2, 2-3,
                                                              0-3, the centre
====  =========================  ==========================  ==============================

The reference domains are scikit-fem's (``RefTri``, ``RefQuad`` = [0, 1]², not [-1, 1]²), so
``xi`` can be handed to scikit-fem's elements as it is. A facet is *oriented* when its corners
run counter-clockwise seen from outside the body: its outward normal is then
``x_ξ × x_η / |x_ξ × x_η|`` (a T3's ``(b − a) × (c − a)``), the 3D form of 2D's ``(t_y, −t_x)``.

**The closest point** (:func:`~vfem.contact.geometry.closest3d.closest_on_facets`: exact on
linear triangles, safeguarded Newton on bilinear and quadratic facets) and its ties are
:mod:`vfem.contact.geometry.closest3d`'s; this module holds the facets' kinds, shape functions,
maps and normals, the checks of a facet set, the bounds of a facet's warp and curvature, and the
candidates.

**Candidates.** Given as (point, facet) index pairs, or every pair (``pairs="all"``), or found
here (``pairs=None``): every facet whose bounding sphere (centred at a point *on* the facet)
reaches as near as the point's nearest such centre. Up to :data:`DIRECT_PAIRS` point-facet
pairs they are found from all distances at once, above it with a KD-tree on the centres; both
give the same candidates, so the same answer.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.spatial import cKDTree

from .kept import Kept

#: up to this many point-facet pairs the candidates come from all centre distances at once,
#: above it from a KD-tree on the facets' centres (as
#: :data:`vfem.contact.search.closest.DIRECT_PAIRS`)
DIRECT_PAIRS = 8192

#: two distances within this fraction of the largest facet are a tie
TIE = 1e-9

#: unclamped coordinates this far outside the reference domain put a point beyond an edge
OUTSIDE = 1e-9

#: a facet is degenerate where a corner's two edges span less than this fraction of the square
#: of the facet's longest corner-to-corner distance (zero area)
DEGENERATE = 1e-12


@dataclass(frozen=True)
class FacetShape:
    """The reference shape of a 3D surface facet: its nodes, reference domain and edges (the
    geometry that :class:`vfem.contact.geometry.facets.Triangle` and ``Quad``, the facet kinds the
    contact code sees, wrap; named apart from :class:`~vfem.contact.geometry.facets.FacetKind`).

    Attributes:
        name: "T3", "Q4", "T6" or "Q9".
        nodes: nodes per facet.
        corners: 3 (triangles) or 4 (quadrilaterals).
        order: 1 or 2.
        edges: per reference edge (in scikit-fem's order, ``RefTri.facets`` /
            ``RefQuad.facets``) its two corner nodes and its midside node (-1 on linear facets).
        centre: reference coordinates of the facet's centre (a point on the facet).
    """

    name: str
    nodes: int
    corners: int
    order: int
    edges: tuple[tuple[int, int, int], ...]
    centre: tuple[float, float]

    @property
    def simplex(self) -> bool:
        return self.corners == 3

    @property
    def vertices(self) -> np.ndarray:
        """(corners, 2) reference coordinates of the corners."""
        if self.simplex:
            return np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        return np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


_TRI_EDGES = ((0, 1), (1, 2), (0, 2))
_QUAD_EDGES = ((0, 1), (1, 2), (2, 3), (0, 3))

T3 = FacetShape("T3", 3, 3, 1, tuple((a, b, -1) for a, b in _TRI_EDGES), (1 / 3, 1 / 3))
Q4 = FacetShape("Q4", 4, 4, 1, tuple((a, b, -1) for a, b in _QUAD_EDGES), (0.5, 0.5))
T6 = FacetShape("T6", 6, 3, 2, tuple((a, b, 3 + i) for i, (a, b) in enumerate(_TRI_EDGES)),
               (1 / 3, 1 / 3))
Q9 = FacetShape("Q9", 9, 4, 2, tuple((a, b, 4 + i) for i, (a, b) in enumerate(_QUAD_EDGES)),
               (0.5, 0.5))

#: the facet kinds by nodes per facet
KINDS = {3: T3, 4: Q4, 6: T6, 9: Q9}


def facet_shape(facets: np.ndarray) -> FacetShape:
    """The kind of (nf, k) facets, from k."""
    k = np.shape(facets)[1] if np.ndim(facets) == 2 else None
    if k not in KINDS:
        raise ValueError(f"3D facets must have 3, 4, 6 or 9 nodes each (T3, Q4, T6, Q9), "
                         f"got an array of shape {np.shape(facets)}")
    return KINDS[k]


class FacetProjection(NamedTuple):
    """Per query point: the nearest facet and the closest point on it.

    Attributes:
        facet: (m,) index of the facet (into the ``facets`` given), -1 for a point with no
            candidate facet (then ``distance`` is inf and the float fields NaN).
        xi: (m, 2) local coordinates of the closest point (in the reference domain).
        point: (m, 3) the closest point, ``x(xi)``.
        distance: (m,) distance from the point to it.
        normal: (m, 3) unit outward normal of the facet at ``xi``.
        xi_free: (m, 2) unclamped local coordinates (module docstring; :func:`outside`).
    """

    facet: np.ndarray
    xi: np.ndarray
    point: np.ndarray
    distance: np.ndarray
    normal: np.ndarray
    xi_free: np.ndarray


# ---------------------------------------------------------------------------------------------
# shape functions


def _line(order: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """1D Lagrange functions on [0, 1] at nodes 0, 1 (and 1/2): values, first and second
    derivatives, each (n, order + 1)."""
    if order == 1:
        one = np.ones_like(s)
        return (np.column_stack([1 - s, s]), np.column_stack([-one, one]),
                np.zeros((len(s), 2)))
    one = np.ones_like(s)
    return (np.column_stack([(1 - s) * (1 - 2 * s), s * (2 * s - 1), 4 * s * (1 - s)]),
            np.column_stack([4 * s - 3, 4 * s - 1, 4 - 8 * s]),
            np.column_stack([4 * one, 4 * one, -8 * one]))


#: a quadrilateral's nodes as (index of the 1D function in ξ, in η)
_TENSOR = {4: ((0, 0), (1, 0), (1, 1), (0, 1)),
           9: ((0, 0), (1, 0), (1, 1), (0, 1), (2, 0), (1, 2), (2, 1), (0, 2), (2, 2))}


def shape_functions(kind: FacetShape, xi: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shape functions of ``kind`` at (n, 2) local coordinates: values (n, k), first
    derivatives (n, k, 2) (d/dξ, d/dη) and second derivatives (n, k, 3) (ξξ, ξη, ηη).
    Equal to scikit-fem's ``ElementTriP1/ElementQuad1/ElementTriP2/ElementQuad2`` bases."""
    xi = np.asarray(xi, dtype=float).reshape(-1, 2)
    x, y = xi[:, 0], xi[:, 1]
    n = len(xi)
    if kind.simplex:
        if kind.order == 1:
            N = np.column_stack([1 - x - y, x, y])
            dN = np.broadcast_to(np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]), (n, 3, 2))
            return N, dN.copy(), np.zeros((n, 3, 3))
        L = 1 - x - y
        N = np.column_stack([L * (2 * L - 1), x * (2 * x - 1), y * (2 * y - 1),
                             4 * L * x, 4 * x * y, 4 * L * y])
        zero = np.zeros(n)
        dx = np.column_stack([1 - 4 * L, 4 * x - 1, zero, 4 * (L - x), 4 * y, -4 * y])
        dy = np.column_stack([1 - 4 * L, zero, 4 * y - 1, -4 * x, 4 * x, 4 * (L - y)])
        second = np.array([[4.0, 4.0, 4.0], [4.0, 0.0, 0.0], [0.0, 0.0, 4.0],
                           [-8.0, -4.0, 0.0], [0.0, 4.0, 0.0], [0.0, -4.0, -8.0]])
        return N, np.stack([dx, dy], axis=2), np.broadcast_to(second, (n, 6, 3)).copy()
    fx, dfx, ddfx = _line(kind.order, x)
    fy, dfy, ddfy = _line(kind.order, y)
    i, j = np.array(_TENSOR[kind.nodes]).T
    N = fx[:, i] * fy[:, j]
    dN = np.stack([dfx[:, i] * fy[:, j], fx[:, i] * dfy[:, j]], axis=2)
    d2N = np.stack([ddfx[:, i] * fy[:, j], dfx[:, i] * dfy[:, j], fx[:, i] * ddfy[:, j]],
                   axis=2)
    return N, dN, d2N


def _evaluate(kind: FacetShape, X: np.ndarray, xi: np.ndarray):
    """Position (n, 3), Jacobian (n, 3, 2) and second derivatives (n, 3, 3) (ξξ, ξη, ηη) of
    facets with node coordinates X (n, k, 3) at xi (n, 2)."""
    N, dN, d2N = shape_functions(kind, xi)
    return ((N[:, None, :] @ X)[:, 0], np.swapaxes(np.swapaxes(dN, 1, 2) @ X, 1, 2),
            np.swapaxes(np.swapaxes(d2N, 1, 2) @ X, 1, 2))


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.sqrt(_dot(v, v)), 1e-300)[..., None]


def facet_map(x: np.ndarray, facets: np.ndarray, facet: np.ndarray, xi: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """Positions (n, 3) and Jacobians (n, 3, 2) (columns x_ξ, x_η) of ``facets[facet]`` (node
    coordinates ``x``) at local coordinates ``xi`` (n, 2)."""
    kind = facet_shape(facets)
    pos, J, _ = _evaluate(kind, np.asarray(x, dtype=float)[np.asarray(facets)[facet]], xi)
    return pos, J


def facet_normals(x: np.ndarray, facets: np.ndarray, facet: np.ndarray, xi: np.ndarray
                  ) -> np.ndarray:
    """Unit outward normals ``x_ξ × x_η / |x_ξ × x_η|`` (n, 3) of oriented facets (corners
    counter-clockwise seen from outside) at local coordinates ``xi``."""
    _, J = facet_map(x, facets, facet, xi)
    return _unit(np.cross(J[:, :, 0], J[:, :, 1]))


def outside(kind: FacetShape, xi_free: np.ndarray, eps: float = OUTSIDE) -> np.ndarray:
    """(n, edges) whether each point lies past each reference edge of its facet (edges in
    ``kind.edges``' order): a triangle's edge 0-1 is η = 0, 1-2 is ξ + η = 1, 0-2 is ξ = 0; a
    quadrilateral's 0-1 is η = 0, 1-2 is ξ = 1, 2-3 is η = 1, 0-3 is ξ = 0."""
    u, v = xi_free[:, 0], xi_free[:, 1]
    if kind.simplex:
        return np.column_stack([v < -eps, u + v > 1 + eps, u < -eps])
    return np.column_stack([v < -eps, u > 1 + eps, v > 1 + eps, u < -eps])


# ---------------------------------------------------------------------------------------------
# facet checks and bounds


def check_facets(x: np.ndarray, facets: np.ndarray) -> None:
    """Refuse facets the closest point is not defined on: non-finite coordinates, corners that
    coincide or lie in a line (zero area), a quadrilateral folded over its diagonal (bow-tie).

    Raises:
        ValueError: naming how many, the first facet, its nodes and corners.
    """
    kind = facet_shape(facets)
    facets = np.asarray(facets)
    if len(facets) == 0:
        return
    C = np.asarray(x, dtype=float)[facets[:, :kind.corners]]
    bad = ~np.isfinite(C).all(axis=(1, 2))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{int(bad.sum())} facet(s) with a coordinate that is not a finite "
                         f"number (the first: facet {i}, nodes {facets[i].tolist()}, corners at "
                         f"{_corners(C[i])})")
    nxt, prv = np.roll(np.arange(kind.corners), -1), np.roll(np.arange(kind.corners), 1)
    at = np.cross(C[:, nxt] - C, C[:, prv] - C)  # (nf, corners, 3) normal at each corner
    diff = C[:, :, None] - C[:, None]
    size2 = _dot(diff, diff).max(axis=(1, 2))
    zero = (np.sqrt(_dot(at, at)) <= DEGENERATE * size2[:, None]).any(axis=1)
    if zero.any():
        i = int(np.flatnonzero(zero)[0])
        raise ValueError(f"{int(zero.sum())} degenerate facet(s) of zero area (the first: facet "
                         f"{i}, nodes {facets[i].tolist()}, corners at {_corners(C[i])}): "
                         "corners that coincide or lie in a line have no closest point or "
                         "normal; fix the mesh")
    folded = (_dot(at, at.sum(axis=1)[:, None]) <= 0).any(axis=1)
    if folded.any():
        i = int(np.flatnonzero(folded)[0])
        raise ValueError(f"{int(folded.sum())} folded quadrilateral facet(s) (the first: facet "
                         f"{i}, nodes {facets[i].tolist()}, corners at {_corners(C[i])}): a "
                         "corner lies past the diagonal of the others (a bow-tie), so the "
                         "normal flips inside the facet; fix the mesh")


def _corners(c: np.ndarray) -> str:
    return "[" + ", ".join("(" + ", ".join(f"{v:.6g}" for v in row) + ")" for row in c) + "]"


def chord_deviation(kind: FacetShape, X: np.ndarray) -> np.ndarray:
    """(n,) an upper bound of |x(ξ) − x_c(ξ)| over the facet, x_c the piecewise linear map on
    its chord triangles (corners 0-1-2 and 0-2-3 of a quadrilateral, the corners of a
    triangle): the distance from any point to the facet and to its chord triangles differ by
    at most this. X: (n, k, 3) node coordinates.

    A bilinear map differs from the chord triangles' by −η(1 − ξ) q (ξ ≥ η) or −ξ(1 − η) q,
    q = x0 − x1 + x2 − x3: at most |q|/4. A quadratic facet adds its hierarchical bubbles,
    the edges' δ = x_mid − (x_a + x_b)/2 times 4λ_aλ_b (T6: Σ ≤ 4/3, each ≤ 1) or
    4s(1 − s) times the linear function across (Q9: opposite edges' sum ≤ 1), and a Q9's
    centre's x8 − mean(corners) − Σδ/2 times 16ξ(1 − ξ)η(1 − η) ≤ 1."""
    dev = np.zeros(len(X))
    if kind.corners == 4:
        dev += 0.25 * np.linalg.norm(X[:, 0] - X[:, 1] + X[:, 2] - X[:, 3], axis=1)
    if kind.order == 2:
        delta = np.stack([X[:, m] - 0.5 * (X[:, a] + X[:, b]) for a, b, m in kind.edges], 1)
        size = np.linalg.norm(delta, axis=2)
        if kind.corners == 3:
            dev += np.minimum(size.sum(axis=1), 4 / 3 * size.max(axis=1))
        else:
            dev += np.maximum(size[:, 0], size[:, 2]) + np.maximum(size[:, 1], size[:, 3])
            centre = X[:, 8] - X[:, :4].mean(axis=1) - 0.5 * delta.sum(axis=1)
            dev += np.linalg.norm(centre, axis=1)
    return dev


def bounding_spheres(x: np.ndarray, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(nf, 3) centres (a point on each facet: ``x`` at ``kind.centre``) and (nf,) radii of
    spheres that hold the facets: the farthest corner (a bilinear facet lies in its corners'
    convex hull) plus, on a quadratic facet, its :func:`chord_deviation`."""
    kind = facet_shape(facets)
    X = np.asarray(x, dtype=float)[np.asarray(facets)]
    N, _, _ = shape_functions(kind, np.array([kind.centre]))
    centre = (N[0] @ X) if len(X) else np.zeros((0, 3))
    C = X[:, :kind.corners] - centre[:, None]
    radius = np.sqrt(_dot(C, C)).max(axis=1, initial=0.0)
    if kind.order == 2:
        radius += chord_deviation(kind, X)
    return centre, radius


# ---------------------------------------------------------------------------------------------
# candidates


def _distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a − b| along the last axis, the same arithmetic however the arrays are shaped."""
    d0, d1, d2 = a[..., 0] - b[..., 0], a[..., 1] - b[..., 1], a[..., 2] - b[..., 2]
    return np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


#: KD-tree queries of fewer points than this run on the calling thread: SciPy starts its
#: worker threads afresh for every query, 1-3 ms each, and a pair's set-up makes hundreds of
#: small queries (the bisections of :func:`~.held.held_edges`: 992 queries, 3.4 s of threads
#: started and joined in the four-plate stack of ``benchmarks/ranks.py``; issue 40). Measured
#: on the 2-core machine (2026-12-01, 20,000 facet centres, 16 nearest): 100 points 1.0 ms on
#: one thread and 2.4 ms on all, 1,000 points 5.4 and 9.4 ms, 10,000 points 86 and 80 ms.
#: The answers do not depend on it.
PARALLEL_QUERY = 20_000


def _workers(m: int) -> int:
    return -1 if m >= PARALLEL_QUERY else 1


#: the facet sets whose derived data :func:`kept` keeps (the last ones asked about)
SURFACES_KEPT = 4
_surfaces = Kept(SURFACES_KEPT)


def kept(x: np.ndarray, facets: np.ndarray) -> dict:
    """A dictionary kept for the facet set ``facets`` at positions ``x`` (:class:`~.kept.Kept`:
    the last :data:`SURFACES_KEPT` sets), for what is derived from them alone: their
    validation (:func:`check_facets`), their corners' tie tolerance and the search trees of
    :func:`candidate_pairs`. A pair's set-up and the invariants ask about the same surface
    hundreds of times (the bisections of :func:`~.held.held_edges`: 992 queries in the
    four-plate stack), each of which rebuilt them (issue 40)."""
    return _surfaces.get((np.asarray(x, dtype=float), np.asarray(facets)), dict)


def checked(x: np.ndarray, facets: np.ndarray) -> dict:
    """:func:`check_facets` once per facet set (:func:`kept`); the set's kept dictionary."""
    value = kept(x, facets)
    if "checked" not in value:
        check_facets(x, facets)  # raises: not kept
        value["checked"] = True
    return value


def _facet_trees(x: np.ndarray, facets: np.ndarray) -> tuple:
    """The bounding spheres of ``facets`` at ``x`` (:func:`bounding_spheres`), a KD-tree of
    their centres, and per class of radii (a factor of 2 apart) the members and a KD-tree of
    theirs: what :func:`candidate_pairs` searches, built once per facet set (:func:`kept`)."""
    value = kept(x, facets)
    if "trees" not in value:
        centre, radius = bounding_spheres(x, facets)
        level = np.floor(np.log2(np.maximum(radius, 1e-300) / max(radius.min(), 1e-300)))
        levels = []
        for c in np.unique(level):
            members = np.flatnonzero(level == c)
            levels.append((members, cKDTree(centre[members])))
        value["trees"] = (centre, radius, cKDTree(centre), levels)
    return value["trees"]


def candidate_pairs(points: np.ndarray, x: np.ndarray, facets: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(point, facet) index pairs that may be nearest: every facet whose bounding sphere
    (:func:`bounding_spheres`) comes as near to the point as the nearest facet centre (a point
    on that facet, so no farther than it). All pairs' centre distances at once up to
    :data:`DIRECT_PAIRS` pairs, a KD-tree on the centres above; the same pairs either way,
    sorted by point."""
    points = np.asarray(points, dtype=float)
    m, nf = len(points), len(facets)
    if m == 0 or nf == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    if m * nf <= DIRECT_PAIRS:
        centre, radius = bounding_spheres(x, facets)
        slack = TIE * radius.max() + 1e-300
        dc = _distance(points[:, None], centre[None])
        d0 = dc.min(axis=1)
        pt, fc = np.nonzero(dc - radius[None] <= (d0 + slack)[:, None])
        return pt.astype(np.int64), fc.astype(np.int64)
    # the nearest centre (the tree's first of its 16 nearest), then per class of radii (a
    # factor of 2 apart) the centres within d0 + the class's largest radius, by the tree's k
    # nearest, k doubled for the points whose k-th is still within reach: with one reach for
    # all, the largest facet's radius (a graded mesh's far field) set every point's search,
    # 0.6 GB of pairs for the quadrature points of the sphere at 316k dofs
    centre, radius, tree, levels = _facet_trees(x, facets)
    slack = TIE * radius.max() + 1e-300
    _, j = tree.query(points, k=min(nf, 16), workers=_workers(m))
    d0 = _distance(points, centre[j[:, 0] if j.ndim == 2 else j])
    pts, fcs = [], []
    for members, sub in levels:
        reach = (d0 + radius[members].max() + slack) * (1 + 1e-12) + 1e-300
        todo, k = np.arange(m), min(len(members), 16)
        while len(todo):
            d, jj = sub.query(points[todo], k=k, workers=_workers(len(todo)))
            d, jj = d.reshape(len(todo), -1), jj.reshape(len(todo), -1)
            done = (d[:, -1] > reach[todo]) | (k == len(members))
            rows, cols = np.nonzero(d[done] <= reach[todo][done, None])
            pts.append(todo[done][rows])
            fcs.append(members[jj[done][rows, cols]])
            todo = todo[~done]
            k = min(2 * k, len(members))
    pt, fc = np.concatenate(pts), np.concatenate(fcs)
    keep = _distance(points[pt], centre[fc]) - radius[fc] <= d0[pt] + slack
    pt, fc = pt[keep], fc[keep]
    order = np.lexsort((fc, pt))
    return pt[order], fc[order]


# ---------------------------------------------------------------------------------------------
# kernels


def closest_on_triangles(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray
                         ) -> np.ndarray:
    """(n, 2) local coordinates (ξ, η) (weights of ``b`` and ``c``) of the closest point on
    each triangle (a, b, c) to each point ``p`` (all (n, 3)): Ericson's region classification,
    exact at edges and vertices. The triangles must have non-zero area."""
    ab, ac = b - a, c - a
    d1, d2 = _dot(ab, p - a), _dot(ac, p - a)
    d3, d4 = _dot(ab, p - b), _dot(ac, p - b)
    d5, d6 = _dot(ab, p - c), _dot(ac, p - c)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    # the regions in Ericson's order: the first that holds is the point's
    regions = [(d1 <= 0) & (d2 <= 0),  # vertex a
               (d3 >= 0) & (d4 <= d3),  # vertex b
               (vc <= 0) & (d1 >= 0) & (d3 <= 0),  # edge ab
               (d6 >= 0) & (d5 <= d6),  # vertex c
               (vb <= 0) & (d2 >= 0) & (d6 <= 0),  # edge ac
               (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)]  # edge bc
    with np.errstate(divide="ignore", invalid="ignore"):
        v_ab = d1 / (d1 - d3)  # denominators |ab|², |ac|², |bc|², |ab × ac|²
        w_ac = d2 / (d2 - d6)
        w_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        den = va + vb + vc
        v, w = vb / den, vc / den
    zero, one = np.zeros(len(p)), np.ones(len(p))
    s = np.select(regions, [zero, one, v_ab, zero, zero, 1 - w_bc], v)
    t = np.select(regions, [zero, zero, zero, one, w_ac, w_bc], w)
    return np.column_stack([s, t])


# ---------------------------------------------------------------------------------------------
# the projection


