"""Closest points on 3D surface facets (vfem.contact.geometry.facets3d; issue 21, C5 of the 3D
plan).

The reference is independent of the module: each facet's map is rebuilt from scikit-fem's own
shape functions (``ElementTriP1/Quad1/TriP2/Quad2.lbasis``) as a polynomial, the closest point
found by brute force on a fine grid of local coordinates and refined with
``scipy.optimize.minimize`` (SLSQP, the triangle's ξ + η ≤ 1 as a constraint), then
``scipy.optimize.least_squares`` (which resolves distances near 0)."""

import numpy as np
import pytest
from scipy.optimize import least_squares, minimize
from scipy.spatial import cKDTree
from skfem import ElementQuad1, ElementQuad2, ElementTriP1, ElementTriP2

from vfem.contact.geometry import facets3d
from vfem.contact.geometry.closest3d import closest_on_facets
from vfem.contact.geometry.facets3d import (
    KINDS,
    check_facets,
    closest_on_triangles,
    facet_shape,
    outside,
    shape_functions,
)

ELEMENTS = {3: ElementTriP1(), 4: ElementQuad1(), 6: ElementTriP2(), 9: ElementQuad2()}
SIMPLEX = {3: True, 4: False, 6: True, 9: False}


# --- the reference: scikit-fem's basis as polynomials, a grid, SLSQP -------------------------

def _powers(k):
    if k == 3:
        return [(0, 0), (1, 0), (0, 1)]
    if k == 4:
        return [(0, 0), (1, 0), (0, 1), (1, 1)]
    if k == 6:
        return [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]
    return [(a, b) for a in range(3) for b in range(3)]


def _coefficients(k, X):
    """(nf, monomials, 3): each facet's map x(ξ, η) = Σ c_ab ξ^a η^b, fitted exactly to
    scikit-fem's basis functions (the monomials span the element's space)."""
    S = np.random.default_rng(1).random((40, 2)) * (0.5 if SIMPLEX[k] else 1.0)
    phi = np.stack([ELEMENTS[k].lbasis(S.T, i)[0] for i in range(k)], 1)
    M = np.stack([S[:, 0] ** a * S[:, 1] ** b for a, b in _powers(k)], 1)
    T = np.linalg.lstsq(M, phi, rcond=None)[0]
    assert np.allclose(M @ T, phi, atol=1e-13)
    return np.einsum("mk,fkd->fmd", T, X)


def _map(k, coef, xi):
    """Positions and the two tangents x_ξ, x_η at xi (..., 2) of facets with coefficients
    coef (..., monomials, 3)."""
    u, v = xi[..., 0], xi[..., 1]
    pw = _powers(k)
    M = np.stack([u ** a * v ** b for a, b in pw], -1)
    Mu = np.stack([a * u ** max(a - 1, 0) * v ** b for a, b in pw], -1)
    Mv = np.stack([b * u ** a * v ** max(b - 1, 0) for a, b in pw], -1)
    return tuple(np.einsum("...m,...md->...d", W, coef) for W in (M, Mu, Mv))


def brute_force(k, x, facets, points, grid=160):
    """Distance from each point to the nearest facet: the nearest of a (grid + 1)² lattice of
    local coordinates on each facet, then SLSQP from it on every facet whose lattice comes
    within its spacing of the nearest (so on the facet that holds the closest point)."""
    coef = _coefficients(k, x[facets])
    s = np.linspace(0.0, 1.0, grid + 1)
    U, V = np.meshgrid(s, s, indexing="ij")
    inside = np.ones_like(U, dtype=bool) if not SIMPLEX[k] else U + V <= 1 + 1e-12
    nf = len(facets)
    d_grid = np.empty((len(points), nf))
    best_xi = np.empty((len(points), nf, 2))
    spacing = np.empty(nf)
    steps = [(1, 0), (0, 1), (1, -1)] + ([] if SIMPLEX[k] else [(1, 1)])
    for f in range(nf):
        P = _map(k, coef[f], np.stack([U, V], -1))[0]
        # every point of the facet is within the longest lattice step of a lattice point
        spacing[f] = max(np.linalg.norm(_step(P, inside, di, dj), axis=-1).max()
                         for di, dj in steps)
        flat = np.column_stack([U[inside], V[inside]])
        d_grid[:, f], j = cKDTree(P[inside]).query(points)
        best_xi[:, f] = flat[j]
    pw = _powers(k)
    out = np.full(len(points), np.inf)
    nearest = d_grid.min(axis=1)
    cons = ([{"type": "ineq", "fun": lambda s: 1 - s[0] - s[1],
              "jac": lambda s: np.array([-1.0, -1.0])}] if SIMPLEX[k] else [])
    for i, f in zip(*np.nonzero(d_grid <= nearest[:, None] + spacing[None] + 1e-12)):
        c, p = coef[f], points[i]

        def fun(s, c=c, p=p):
            u, v = s
            M = np.array([u ** a * v ** b for a, b in pw])
            Mu = np.array([a * u ** (a - 1) * v ** b if a else 0.0 for a, b in pw])
            Mv = np.array([b * u ** a * v ** (b - 1) if b else 0.0 for a, b in pw])
            r = M @ c - p
            return 0.5 * r @ r, np.array([r @ (Mu @ c), r @ (Mv @ c)])

        res = minimize(fun, best_xi[i, f], jac=True, method="SLSQP", bounds=[(0, 1), (0, 1)],
                       constraints=cons, options={"ftol": 1e-16, "maxiter": 200})
        xi = np.clip(res.x, 0.0, 1.0)
        if SIMPLEX[k] and xi.sum() > 1:
            xi = xi / xi.sum()
        candidates = [d_grid[i, f], np.linalg.norm(_map(k, c, xi)[0] - p)]
        out[i] = min(out[i], *candidates)
        if candidates[1] > 1e-4:
            continue
        # SLSQP's stopping test is absolute in ½|x − p|² (~1e-16): near the facet, finish
        # with least squares on x − p itself, with bounds and (where that ends inside) without

        def residual(s, c=c, p=p):
            return _map(k, c, s)[0] - p

        for method in ("dogbox", "lm"):
            bounds = (0, 1) if method == "dogbox" else (-np.inf, np.inf)
            fit = least_squares(residual, xi, bounds=bounds, method=method, ftol=1e-15,
                                xtol=1e-15, gtol=1e-15)
            s_ = fit.x
            if (s_ >= -1e-9).all() and (s_ <= 1 + 1e-9).all() and (
                    not SIMPLEX[k] or s_.sum() <= 1 + 1e-9):
                s_ = np.clip(s_, 0, 1)
                if SIMPLEX[k] and s_.sum() > 1:
                    s_ = s_ / s_.sum()
                candidates.append(np.linalg.norm(residual(s_)))
        out[i] = min(out[i], *candidates)
    return out


def _step(P, inside, di, dj):
    """Distances between lattice neighbours (i, j) and (i + di, j + dj), both on the facet."""
    n = P.shape[0]
    i0, i1 = 0, n - di
    j0, j1 = max(0, -dj), n - max(0, dj)
    a, b = P[i0:i1, j0:j1], P[i0 + di:i1 + di, j0 + dj:j1 + dj]
    both = inside[i0:i1, j0:j1] & inside[i0 + di:i1 + di, j0 + dj:j1 + dj]
    return (a - b)[both]


# --- geometry ----------------------------------------------------------------------------------

def surface(k, n=3, warp=0.2, seed=0):
    """A curved surface of n x n cells over [0, 2]² (conforming, oriented with +z roughly
    outward): quadrilaterals, or each split into two triangles; quadratic facets take their
    midside and centre nodes from the same map; ``warp`` moves every node up or down by up to
    that fraction of a cell (so the quadrilaterals are warped and the quadratic facets
    wavy)."""
    rng = np.random.default_rng(seed)
    m = 2 * n + 1
    U, V = np.meshgrid(np.linspace(0, 2, m), np.linspace(0, 2, m), indexing="ij")
    x = np.stack([U + 0.15 * np.sin(2.0 * V), V + 0.1 * np.sin(3.0 * U),
                  0.5 * np.sin(1.7 * U) * np.cos(1.3 * V)], -1).reshape(-1, 3)
    x[:, 2] += warp * rng.uniform(-1, 1, len(x)) * (2.0 / n)

    def node(i, j):
        return i * m + j

    facets = []
    for i in range(0, 2 * n, 2):
        for j in range(0, 2 * n, 2):
            c = [node(i, j), node(i + 2, j), node(i + 2, j + 2), node(i, j + 2)]
            mids = [node(i + 1, j), node(i + 2, j + 1), node(i + 1, j + 2), node(i, j + 1)]
            centre = node(i + 1, j + 1)
            if k == 4:
                facets.append(c)
            elif k == 9:
                facets.append(c + mids + [centre])
            elif k == 3:
                facets += [[c[0], c[1], c[2]], [c[0], c[2], c[3]]]
            else:
                facets += [[c[0], c[1], c[2], mids[0], mids[1], centre],
                           [c[0], c[2], c[3], centre, mids[2], mids[3]]]
    used = np.unique(facets)
    renumber = np.full(len(x), -1)
    renumber[used] = np.arange(len(used))
    return x[used], renumber[np.array(facets)]


def random_points(k, x, facets, n, rng):
    """n points of every sort: in the surface's box, near it (above and below, the warped
    facets included), on it, exactly on edges and nodes, far away, and beyond its rim."""
    coef = _coefficients(k, x[facets])
    nf = len(facets)
    lo, hi = x.min(0), x.max(0)
    size = np.linalg.norm(x[facets[:, 0]] - x[facets[:, 1]], axis=1).max()

    def on_facets(count, edge=False):
        f = rng.integers(0, nf, count)
        xi = rng.random((count, 2))
        if SIMPLEX[k]:
            flip = xi.sum(1) > 1
            xi[flip] = 1 - xi[flip]
        if edge:  # put one coordinate on a bound (a triangle's third edge: ξ + η = 1)
            which = rng.integers(0, 3 if SIMPLEX[k] else 4, count)
            xi[which == 0, 1] = 0.0
            xi[which == 1, 0] = 0.0
            if SIMPLEX[k]:
                xi[which == 2, 1] = 1.0 - xi[which == 2, 0]
            else:
                xi[which == 2, 0] = 1.0
                xi[which == 3, 1] = 1.0
        pos, xu, xv = _map(k, coef[f], xi)
        normal = np.cross(xu, xv)
        return pos, normal / np.linalg.norm(normal, axis=1)[:, None]

    parts = []
    parts.append(lo - 0.5 + rng.random((n * 30 // 100, 3)) * (hi - lo + 1.0))
    pos, normal = on_facets(n * 20 // 100)
    parts.append(pos + rng.uniform(-0.4, 0.4, (len(pos), 1)) * size * normal)
    parts.append(on_facets(n * 6 // 100)[0])  # on the facets
    parts.append(on_facets(n * 12 // 100, edge=True)[0])  # on their edges
    parts.append(x[rng.integers(0, len(x), n * 6 // 100)])  # on nodes (corners and midsides)
    direction = rng.normal(size=(n * 8 // 100, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    parts.append(0.5 * (lo + hi) + direction * rng.uniform(5, 50, (len(direction), 1)))
    # beyond the rim: outward (in x or y) from the box's sides, up or down
    rim = x[rng.integers(0, len(x), n - sum(len(p) for p in parts))]
    side = rng.integers(0, 4, len(rim))
    rim[side == 0, 0] = lo[0] - rng.uniform(0, 0.5, (side == 0).sum())
    rim[side == 1, 0] = hi[0] + rng.uniform(0, 0.5, (side == 1).sum())
    rim[side == 2, 1] = lo[1] - rng.uniform(0, 0.5, (side == 2).sum())
    rim[side == 3, 1] = hi[1] + rng.uniform(0, 0.5, (side == 3).sum())
    rim[:, 2] += rng.uniform(-0.5, 0.5, len(rim))
    parts.append(rim)
    return np.vstack(parts)


def _check_projection(k, x, facets, points, res):
    """The answer is a point of the facet it names: x(xi) by scikit-fem's basis, at the
    distance given, with the facet's unit normal there."""
    coef = _coefficients(k, x[facets])
    xi = res.xi
    assert (xi >= 0).all() and (xi <= 1).all()
    if SIMPLEX[k]:
        assert (xi.sum(1) <= 1 + 1e-15).all()
    pos, xu, xv = _map(k, coef[res.facet], xi)
    np.testing.assert_allclose(res.point, pos, atol=1e-13)
    np.testing.assert_allclose(res.distance, np.linalg.norm(points - res.point, axis=1),
                               rtol=1e-14, atol=1e-15)
    normal = np.cross(xu, xv)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    np.testing.assert_allclose(np.linalg.norm(res.normal, axis=1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(res.normal, normal, atol=1e-12)


# --- tests -------------------------------------------------------------------------------------

def test_shape_functions_are_scikit_fems():
    """Node order, reference domains ([0, 1]², the unit triangle) and derivatives as
    scikit-fem's ElementTriP1, ElementQuad1, ElementTriP2, ElementQuad2; second derivatives
    against central differences."""
    rng = np.random.default_rng(0)
    for k, kind in KINDS.items():
        xi = rng.random((9, 2)) * (0.5 if kind.simplex else 1.0)
        N, dN, d2N = shape_functions(kind, xi)
        for i in range(k):
            phi, dphi = ELEMENTS[k].lbasis(xi.T, i)
            np.testing.assert_allclose(N[:, i], phi, atol=1e-14)
            np.testing.assert_allclose(dN[:, i].T, dphi, atol=1e-13)
        np.testing.assert_allclose(kind.vertices, ELEMENTS[k].doflocs[:kind.corners])
        h = 1e-6
        du, dv = np.array([[h, 0.0]]), np.array([[0.0, h]])
        num = np.stack([
            (shape_functions(kind, xi + du)[1][:, :, 0]
             - shape_functions(kind, xi - du)[1][:, :, 0]) / (2 * h),
            (shape_functions(kind, xi + dv)[1][:, :, 0]
             - shape_functions(kind, xi - dv)[1][:, :, 0]) / (2 * h),
            (shape_functions(kind, xi + dv)[1][:, :, 1]
             - shape_functions(kind, xi - dv)[1][:, :, 1]) / (2 * h)], axis=2)
        np.testing.assert_allclose(d2N, num, atol=1e-7)


@pytest.mark.parametrize("count", [400, pytest.param(2500, marks=pytest.mark.slow)])
@pytest.mark.parametrize("k", [pytest.param(3, marks=pytest.mark.slow),
                               pytest.param(4, marks=pytest.mark.slow),
                               pytest.param(6, marks=pytest.mark.slow),
                               pytest.param(9, marks=pytest.mark.slow)])
def test_closest_points_match_brute_force(k, count):
    """2,500 points per kind (10⁴ in all, ``slow``; 400 per kind in the default suite: in the
    box, above and below warped facets, exactly on facets, edges and nodes, far away, beyond
    the rim) against the brute-force reference: the same distance to 1e-10 (found: ~1e-14), on
    the facet named, its unit normal there."""
    rng = np.random.default_rng(k)
    x, facets = surface(k)
    points = random_points(k, x, facets, count, rng)
    res = closest_on_facets(points, x, facets)
    assert (res.facet >= 0).all()
    _check_projection(k, x, facets, points, res)
    reference = brute_force(k, x, facets, points)
    error = res.distance - reference
    assert np.abs(error).max() <= 1e-10, (np.abs(error).max(), points[np.abs(error).argmax()])


@pytest.mark.parametrize(("name", "k", "nodes", "box"), [
    ("saddle", 4, [[0, 0, 0], [1, 0, 2], [1, 1, 0], [0, 1, 2]], (-1.5, 2.5)),
    ("dome", 9, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [.5, 0, .3], [1, .5, .3],
                 [.5, 1, .3], [0, .5, .3], [.5, .5, .6]], (0.2, 0.8)),
    ("saddle", 9, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [.5, 0, .4], [1, .5, -.4],
                   [.5, 1, .4], [0, .5, -.4], [.5, .5, 0]], (-1.5, 2.5)),
    ("wavy", 6, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [.5, .1, .35], [.4, .6, -.3],
                 [.1, .5, .25]], (-1.5, 2.5)),
    ("dome", 6, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [.5, 0, .3], [.5, .5, .3], [0, .5, .3]],
     (0.0, 0.6)),
])
def test_strongly_curved_single_facets(name, k, nodes, box):
    """One facet far from flat (a Q4 twisted by twice its size, domes and saddles whose midside
    nodes stand 0.3-0.4 of its size off the chord), points around it and near its centres of
    curvature (where the distance has several local minima): the brute-force distance."""
    x = np.array(nodes, dtype=float)
    facets = np.arange(k)[None]
    points = box[0] + np.random.default_rng(1).random((600, 3)) * (box[1] - box[0])
    res = closest_on_facets(points, x, facets)
    _check_projection(k, x, facets, points, res)
    error = res.distance - brute_force(k, x, facets, points)
    assert np.abs(error).max() <= 1e-10, (name, np.abs(error).max())


def test_triangles_exact_at_vertices_and_edges():
    """Ericson's regions: a point in a vertex's region gets that vertex's coordinates
    exactly, one in an edge's region the clamped coordinate exactly; a point on the plane over
    the face is its own closest point."""
    rng = np.random.default_rng(3)
    n = 2000
    a, b, c = (rng.normal(size=(n, 3)) for _ in range(3))
    normal = np.cross(b - a, c - a)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    lift = rng.uniform(-1, 1, (n, 1)) * normal
    # vertex regions: points whose closest point is a vertex ((p − a)·(b − a) ≤ 0 and
    # (p − a)·(c − a) ≤ 0 for a), from points scattered around it
    for vertex, others, want in [(a, (b, c), [0, 0]), (b, (a, c), [1, 0]), (c, (a, b), [0, 1])]:
        p = vertex + rng.normal(size=(n, 3))
        region = ((np.einsum("nd,nd->n", p - vertex, others[0] - vertex) <= 0)
                  & (np.einsum("nd,nd->n", p - vertex, others[1] - vertex) <= 0))
        assert region.sum() > 100
        xi = closest_on_triangles(p[region], a[region], b[region], c[region])
        assert (xi == want).all()
    # edge ab's region: over ab, out of the triangle across it
    t = rng.random(n)
    e = b - a
    out = np.cross(e, normal)  # in-plane, pointing away from c
    out *= -np.sign(np.einsum("nd,nd->n", out, c - a))[:, None]
    p = a + t[:, None] * e + rng.random((n, 1)) * out + lift
    xi = closest_on_triangles(p, a, b, c)
    ab = (xi[:, 1] == 0)
    assert ab.all()
    np.testing.assert_allclose(xi[:, 0], t, atol=1e-12)
    # edge bc: ξ + η = 1
    e = c - b
    out = np.cross(e, normal)
    out *= -np.sign(np.einsum("nd,nd->n", out, a - b))[:, None]
    p = b + t[:, None] * e + rng.random((n, 1)) * out + lift
    xi = closest_on_triangles(p, a, b, c)
    np.testing.assert_allclose(xi.sum(1), 1.0, atol=1e-15)
    np.testing.assert_allclose(xi[:, 1], t, atol=1e-12)
    # over the face
    w = rng.dirichlet(np.ones(3), n)
    p = w[:, :1] * a + w[:, 1:2] * b + w[:, 2:] * c + lift
    np.testing.assert_allclose(closest_on_triangles(p, a, b, c), w[:, 1:], atol=1e-11)
    # the nodes themselves
    assert (closest_on_triangles(c, a, b, c) == [0, 1]).all()


def test_quadrilaterals_exact_at_edges_and_vertices():
    """Past a warped quadrilateral's edge or corner the clamped coordinate is exactly 0 or 1
    (the straight edges win ties with the Newton iterate)."""
    x = np.array([[0, 0, 0], [1, 0, 0.3], [1.1, 1, -0.2], [0, 0.9, 0.1]], dtype=float)
    facets = np.array([[0, 1, 2, 3]])
    rng = np.random.default_rng(4)
    t = rng.random(500)
    p = np.vstack([
        x[0] + np.outer(t, x[1] - x[0]) + [0, -0.5, 0] + rng.normal(0, 0.05, (500, 3)),
        x[0] - rng.random((500, 3)) * [1, 1, 0] - [0.1, 0.1, 0],  # past corner 0
        x[2] + rng.random((500, 3)) * [1, 1, 0] + [0.2, 0.2, 0]])  # past corner 2
    res = closest_on_facets(p, x, facets)
    assert (res.xi[:500, 1] == 0).all()
    assert (res.xi[500:1000] == 0).all()
    assert (res.xi[1000:] == 1).all()
    np.testing.assert_array_equal(res.point[500:1000], np.tile(x[0], (500, 1)))


def _box(kind):
    """The unit cube's six faces as facets of ``kind``, corners counter-clockwise seen from
    outside, and each face's outward normal (per facet)."""
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                        [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
    faces = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4],
                      [2, 3, 7, 6], [1, 2, 6, 5], [0, 4, 7, 3]])
    outward = np.array([[0, 0, -1], [0, 0, 1], [0, -1, 0], [0, 1, 0], [1, 0, 0], [-1, 0, 0.0]])
    x = list(corners)

    def mid(*nodes):
        x.append(np.mean([x[i] for i in nodes], axis=0))
        return len(x) - 1

    facets, normals = [], []
    for face, n in zip(faces, outward):
        a, b, c, d = face
        if kind == "T3":
            facets += [[a, b, c], [a, c, d]]
            normals += [n, n]
        elif kind == "Q4":
            facets.append([a, b, c, d])
            normals.append(n)
        elif kind == "T6":
            m = mid(a, c)
            facets += [[a, b, c, mid(a, b), mid(b, c), m], [a, c, d, m, mid(c, d), mid(a, d)]]
            normals += [n, n]
        else:
            facets.append([a, b, c, d, mid(a, b), mid(b, c), mid(c, d), mid(a, d),
                           mid(a, b, c, d)])
            normals.append(n)
    return np.array(x), np.array(facets), np.array(normals)


@pytest.mark.parametrize("kind", ["T3", "Q4", "T6", "Q9"])
def test_box_normals_are_unit_and_outward(kind):
    """Every face of a hand-built cube: the normal at the closest point is the face's outward
    normal; points outside lie on its side, points inside on the other."""
    x, facets, normals = _box(kind)
    rng = np.random.default_rng(5)
    inside = 0.05 + 0.9 * rng.random((3000, 3))
    # outside: past one face (a coordinate below 0 or above 1), over it
    outside_ = rng.random((3000, 3))
    axis = rng.integers(0, 3, 3000)
    past = rng.uniform(0.05, 1.0, 3000)
    outside_[np.arange(3000), axis] = np.where(rng.random(3000) < 0.5, -past, 1 + past)
    for points, sign in [(inside, -1), (outside_, 1)]:
        res = closest_on_facets(points, x, facets)
        np.testing.assert_allclose(np.linalg.norm(res.normal, axis=1), 1.0, rtol=1e-15)
        np.testing.assert_allclose(res.normal, normals[res.facet], atol=1e-14)
        side = np.einsum("nd,nd->n", points - res.point, res.normal)
        assert (sign * side > 0).all()
        np.testing.assert_allclose(np.abs(side), res.distance, rtol=1e-12)


@pytest.mark.parametrize("kind", ["T3", "Q4", "T6", "Q9"])
def test_box_corner_ties_pick_the_facing_face(kind):
    """Points equidistant from two (or three) faces of a cube -- outside an edge, inside near
    it, at a corner -- pair with the face their own normal opposes most, whatever the facets'
    numbering; without normals, with the face they lie over, else the lowest number."""
    x, facets, normals = _box(kind)
    d = 0.1
    points = np.array([[1 + d, 1 + d, 0.5], [1 - d, 1 - d, 0.3], [1 + d, 1 + d, 1 + d],
                       [1.0, 1.0, 0.5], [1.0, 1.0, 1.0]])
    for order in [np.arange(len(facets)), np.arange(len(facets))[::-1]]:
        f = facets[order]
        nf = normals[order]
        x_face = np.flatnonzero((nf == [1, 0, 0]).all(1))
        y_face = np.flatnonzero((nf == [0, 1, 0]).all(1))
        z_face = np.flatnonzero((nf == [0, 0, 1]).all(1))
        for want, own in [(x_face, [-1, -0.3, -0.1]), (y_face, [-0.3, -1, -0.1])]:
            own = np.tile(np.array(own) / np.linalg.norm(own), (len(points), 1))
            res = closest_on_facets(points, x, f, point_normals=own)
            assert np.isin(res.facet, want).all(), (kind, res.facet, want)
        own = np.tile([-0.1, -0.2, -1.0], (len(points), 1))
        res = closest_on_facets(points, x, f, point_normals=own)
        assert np.isin(res.facet[[2, 4]], z_face).all()  # at the corner: the z face
        # no normals: every point lies over all its tied faces (inside, on the edge or the
        # corner) or over none (outside): the lowest facet number of those tied
        res = closest_on_facets(points, x, f)
        each = np.column_stack([closest_on_facets(points, x, f[j:j + 1]).distance
                                for j in range(len(f))])
        tied = each <= each.min(axis=1)[:, None] + 1e-12
        np.testing.assert_array_equal(res.facet, tied.argmax(axis=1))
        assert (tied.sum(axis=1) >= 2).all()


def test_xi_free_is_the_projection_on_the_plane():
    """For flat facets xi_free is the orthogonal projection on the facet's plane in its own
    coordinates (a 2x2 Gram solve, independent of the module's): equal to xi over the facet,
    beyond the edges past which the point lies (``outside``)."""
    rng = np.random.default_rng(6)
    x = np.array([[0, 0, 0], [2, 0.3, 0.1], [0.4, 1.5, -0.2], [2.3, 1.9, 0.0]])
    facets = np.array([[0, 1, 2]])
    p = rng.uniform(-1.5, 3, (4000, 3))
    res = closest_on_facets(p, x, facets)
    e1, e2 = x[1] - x[0], x[2] - x[0]
    G = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
    want = np.linalg.solve(G, np.column_stack([(p - x[0]) @ e1, (p - x[0]) @ e2]).T).T
    np.testing.assert_allclose(res.xi_free, want, atol=1e-12)
    over = ~outside(KINDS[3], want).any(1)
    np.testing.assert_allclose(res.xi[over], want[over], atol=1e-12)
    past = outside(KINDS[3], res.xi_free)
    u, v = want[:, 0], want[:, 1]
    np.testing.assert_array_equal(past, np.column_stack([v < -1e-9, u + v > 1 + 1e-9,
                                                         u < -1e-9]))
    # a flat parallelogram (bilinear = affine): the same in the quadrilateral's coordinates
    xq = np.array([x[0], x[1], x[1] + x[2] - x[0], x[2]])
    res = closest_on_facets(p, xq, np.array([[0, 1, 2, 3]]))
    np.testing.assert_allclose(res.xi_free, want, atol=1e-10)
    # a warped quadrilateral: past the edge ξ = 1 (1-2), xi_free says so
    xw = np.array([[0, 0, 0], [1, 0, 0.3], [1.1, 1, -0.2], [0, 0.9, 0.1]], dtype=float)
    t = rng.random(300)
    beyond = xw[1] + np.outer(t, xw[2] - xw[1]) + [0.4, 0, 0]
    res = closest_on_facets(beyond, xw, np.array([[0, 1, 2, 3]]))
    assert (res.xi[:, 0] == 1).all()
    assert outside(KINDS[4], res.xi_free)[:, 1].all()


@pytest.mark.parametrize("k", [3, 4, 6, 9])
def test_direct_tree_and_all_pairs_agree(k, monkeypatch):
    """Few pairs take the direct candidate search, many the KD-tree (``DIRECT_PAIRS``), or
    every pair: the same facet, coordinates and distance, ties included (points on shared
    nodes, normals deciding)."""
    x, facets = surface(k, n=4, warp=0.1)
    rng = np.random.default_rng(8)
    points = random_points(k, x, facets, 400, rng)
    normals = rng.normal(size=(len(points), 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    monkeypatch.setattr(facets3d, "DIRECT_PAIRS", 10**9)
    direct = closest_on_facets(points, x, facets, normals)
    monkeypatch.setattr(facets3d, "DIRECT_PAIRS", 0)
    tree = closest_on_facets(points, x, facets, normals)
    every = closest_on_facets(points, x, facets, normals, pairs="all")
    for u, v, w in zip(direct, tree, every):
        np.testing.assert_array_equal(u, v)
        np.testing.assert_array_equal(u, w)


def test_given_pairs_and_points_without_candidates():
    x, facets, _ = _box("Q4")
    points = np.array([[0.5, 0.5, 1.2], [0.5, 0.5, -0.3], [3.0, 3.0, 3.0]])
    res = closest_on_facets(points, x, facets, pairs=([0, 1, 1], [1, 1, 0]))
    np.testing.assert_array_equal(res.facet, [1, 0, -1])
    np.testing.assert_allclose(res.distance[:2], [0.2, 0.3])
    assert np.isinf(res.distance[2]) and np.isnan(res.xi[2]).all()
    empty = closest_on_facets(np.zeros((0, 3)), x, facets)
    assert empty.facet.shape == (0,) and empty.xi.shape == (0, 2)


def test_degenerate_facets_are_refused():
    x = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    with pytest.raises(ValueError, match=r"1 degenerate facet\(s\) of zero area \(the first: "
                                         r"facet 1, nodes \[0, 1, 2\]"):
        closest_on_facets(x, x, np.array([[0, 1, 3], [0, 1, 2]]))
    with pytest.raises(ValueError, match="degenerate facet"):  # two nodes at one place
        check_facets(np.vstack([x, x[1]]), np.array([[0, 1, 5, 3]]))
    with pytest.raises(ValueError, match=r"folded quadrilateral facet\(s\).*bow-tie"):
        check_facets(x, np.array([[0, 1, 3, 4]]))
    with pytest.raises(ValueError, match="not a finite number"):
        check_facets(np.vstack([x, [np.nan, 0, 0]]), np.array([[0, 1, 5]]))
    with pytest.raises(ValueError, match="must have 3, 4, 6 or 9 nodes"):
        facet_shape(np.zeros((2, 5), dtype=int))
    with pytest.raises(ValueError, match="pairs must be"):
        closest_on_facets(x, x, np.array([[0, 1, 3]]), pairs="some")
    # a thin but proper triangle is accepted and projected exactly
    thin = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1e-5, 0]])
    res = closest_on_facets(np.array([[0.5, 5e-6, 1.0]]), thin, np.array([[0, 1, 2]]))
    np.testing.assert_allclose(res.distance, [1.0])


def test_tree_search_over_facets_of_many_sizes_finds_the_direct_pairs(monkeypatch):
    """The KD-tree search takes the facets by classes of size (a graded mesh's far-field
    facets would otherwise set every point's search radius): the same (point, facet) pairs
    as the direct search, and the same closest points."""
    from skfem import MeshQuad

    from vfem.contact.geometry.facets3d import candidate_pairs

    g = np.linspace(0.0, 1.0, 13) ** 3  # facets from 1/1728 to 0.42 wide
    m = MeshQuad.init_tensor(g, g)
    x = np.vstack([m.p, 0.1 * np.sin(3.0 * m.p[0]) * m.p[1]]).T  # warped a little
    facets = m.t.T
    rng = np.random.default_rng(5)
    points = np.vstack([x + rng.normal(scale=0.01, size=x.shape),
                        rng.uniform([-0.2, -0.2, -0.3], [1.2, 1.2, 0.4], size=(600, 3))])
    sizes = facets3d.bounding_spheres(x, facets)[1]
    assert sizes.max() > 100 * sizes.min()
    monkeypatch.setattr(facets3d, "DIRECT_PAIRS", 10**9)
    direct = candidate_pairs(points, x, facets)
    near_direct = closest_on_facets(points, x, facets)
    monkeypatch.setattr(facets3d, "DIRECT_PAIRS", 0)
    tree = candidate_pairs(points, x, facets)
    for u, v in zip(direct, tree):
        np.testing.assert_array_equal(u, v)
    for u, v in zip(near_direct, closest_on_facets(points, x, facets)):
        np.testing.assert_array_equal(u, v)
