"""Candidate selection and the initial-overlap check in 3D (issue 21, C7 of the 3D plan):
``select_candidate_facets`` with bodies driven together by their prescribed displacements or a
platen (ray-triangle ``platen_approach``), ``check_initial_overlap`` naming the node and its
(x, y, z), and ``locate_in_simplices`` (point location in tetrahedra) against brute-force
barycentric coordinates. 3D bodies that may touch are still refused by ``check_capabilities``
(the formulation is C10), so these functions are tested directly."""

import re

import numpy as np
import pytest

from vfem.bodies import Body, Platen, PrescribedDisplacement, Support
from vfem.contact.geometry import ContactPairs
from vfem.contact.geometry.bodymesh import exterior_facets, locate_in_simplices, simplices
from vfem.contact.geometry.placement import (
    check_initial_overlap,
    platen_approach,
    predicted_translation,
    select_candidate_facets,
)
from vfem.contact.geometry.surface import ContactSurface
from vfem.errors import InputError
from vfem.materials import LinearElastic
from vfem.mesh.solids import box

MAT = LinearElastic(200.0, 0.3)
PAIR = ContactPairs.every(2)
DISTANCE = 0.1


def _lower(cells="hex", nz=3):
    mesh = box(0.0, 0.0, 0.0, 1.0, 1.0, 1.0, nx=6, ny=6, nz=nz, tetrahedra=cells == "tet")
    return Body("lower", mesh, MAT, supports=(Support("bottom"),))


def _upper(cells="tet", z0=1.5, drop=None, platen=None):
    mesh = box(0.35, 0.35, z0, 0.3, 0.3, 0.4, nx=2, ny=2, nz=2, tetrahedra=cells == "tet")
    prescribed = () if drop is None else (PrescribedDisplacement("top", "z", -drop),)
    return Body("upper", mesh, MAT, prescribed=prescribed, platen=platen)


def _centres(body, facets):
    return body.mesh.p[:, body.mesh.facets[:, facets]].mean(axis=1).T


def _facing(bodies, selected):
    """The selected facets: the lower's top under the upper (not all of it, none of its sides)
    and the upper's bottom (with the foot of its sides), not the far faces."""
    lower, upper = bodies
    top, bottom = lower.mesh.boundaries["top"], upper.mesh.boundaries["bottom"]
    assert len(selected[0]) and len(selected[1])
    assert set(selected[0]) <= set(top)
    # the upper's bottom, and of its sides only the facets along the bottom's rim (within the
    # search distance plus their size); not its top
    assert set(bottom) <= set(selected[1])
    assert (_centres(upper, selected[1])[:, 2] < 1.5 + 0.2).all()
    c = _centres(lower, top)
    under = top[np.all((c[:, :2] > 0.35) & (c[:, :2] < 0.65), axis=1)]
    assert len(under) and set(under) <= set(selected[0])
    assert len(selected[0]) < len(top)  # not the whole top face: the far facets stay out


@pytest.mark.parametrize(("low", "up"), [("hex", "tet"), ("tet", "hex")])
def test_boxes_driven_together_find_each_others_facing_faces(low, up):
    bodies = [_lower(low), _upper(up, drop=0.5)]
    np.testing.assert_array_equal(predicted_translation(bodies[1], 1.0), [0.0, 0.0, -0.5])
    np.testing.assert_array_equal(predicted_translation(bodies[0], 1.0), [0.0, 0.0, 0.0])
    # undeformed, 0.5 apart: nothing within the search distance
    apart = select_candidate_facets(bodies, PAIR, DISTANCE)
    assert not len(apart[0]) and not len(apart[1])
    # driven together over the schedule: the facing faces, not the far ones
    _facing(bodies, select_candidate_facets(bodies, PAIR, DISTANCE, load_factors=(1.0,)))


def test_a_platen_body_finds_the_flat():
    """A force-driven body (a platen pushing the upper box down) is looked at where it first
    meets the lower box: the ray-triangle distance of the 3D ``platen_approach``."""
    bodies = [_lower("hex"), _upper("tet", platen=Platen("top", "z", -1.0))]
    selected = select_candidate_facets(bodies, PAIR, DISTANCE, load_factors=(1.0,))
    # the platen's own face is not a candidate
    assert not set(selected[1]) & set(bodies[1].mesh.boundaries["top"])
    _facing(bodies, selected)


def _triangles(body):
    mesh = body.mesh
    f = exterior_facets(body)
    corners = mesh.p[:, mesh.facets[:, f]].transpose(2, 1, 0)
    split = [(0, 1, 2)] if corners.shape[1] == 3 else [(0, 1, 2), (0, 2, 3)]
    return tuple(np.vstack([corners[:, s[k]] for s in split]) for k in range(3))


@pytest.mark.parametrize("up", ["tet", "hex"])
def test_platen_approach_is_the_ray_distance_in_3d(up):
    lower, upper = _lower("hex"), _upper(up, z0=1.5)
    moving, fixed = _triangles(upper), _triangles(lower)
    assert platen_approach(moving, fixed, np.array([0.0, 0.0, -1.0])) == pytest.approx(0.5)
    assert platen_approach(moving, fixed, np.array([0.0, 0.0, 1.0])) == np.inf
    beside = tuple(c + [2.0, 0.0, 0.0] for c in moving)
    assert platen_approach(beside, fixed, np.array([0.0, 0.0, -1.0])) == np.inf
    # a corner of the fixed body under the middle of a moving face: its ray (upwards) hits it
    spike = tuple(c + [0.0, 0.0, 0.0] for c in fixed)
    wide = tuple(c * [4.0, 4.0, 1.0] - [1.5, 1.5, 0.0] for c in moving)
    assert platen_approach(wide, spike, np.array([0.0, 0.0, -1.0])) == pytest.approx(0.5)


def _surfaces(bodies):
    lower, upper = bodies
    return [ContactSurface.build(lower, lower.mesh.boundaries["top"]),
            ContactSurface.build(upper, upper.mesh.boundaries["bottom"])]


@pytest.mark.parametrize(("low", "up"), [("hex", "tet"), ("tet", "hex")])
def test_a_box_started_deeper_than_the_rind_is_refused(low, up):
    bodies = [_lower(low, nz=4), _upper(up, z0=0.6)]  # rind 0.25 deep, overlap 0.4
    with pytest.raises(InputError) as info:
        check_initial_overlap(_surfaces(bodies), PAIR)
    message = str(info.value)
    assert "start deeply interpenetrated" in message and "Move the bodies apart" in message
    found = re.search(r"node (\d+) of '(\w+)', at \(([^)]*)\), lies ([\d.e-]+) inside", message)
    assert found, message
    node, name, where = int(found[1]), found[2], found[3]
    xyz = np.array([float(v) for v in where.split(",")])
    assert len(xyz) == 3
    body = bodies[[b.name for b in bodies].index(name)]
    np.testing.assert_allclose(body.points[:, node], xyz, rtol=1e-5)
    assert float(found[4]) == pytest.approx(0.4)
    # an overlap within the rind (0.25 deep; tetrahedra: a third of it, volume / area) is allowed
    check_initial_overlap(_surfaces([_lower(low, nz=4), _upper(up, z0=0.95)]), PAIR)


def _brute(x, tets, points):
    """(m, nt) the smallest barycentric coordinate of each point in each tetrahedron."""
    T = x[tets]  # (nt, 4, 3)
    A = np.transpose(T[:, 1:] - T[:, :1], (0, 2, 1))  # (nt, 3, 3)
    rhs = points[:, None, :] - T[None, :, 0]  # (m, nt, 3)
    lam = np.linalg.solve(A[None], rhs[..., None])[..., 0]
    return np.minimum(lam.min(axis=2), 1 - lam.sum(axis=2))


@pytest.mark.parametrize("cells", ["tet", "hex"])
def test_locate_in_simplices_agrees_with_barycentric_coordinates(cells):
    rng = np.random.default_rng(7)
    mesh = box(0.0, 0.0, 0.0, 1.0, 2.0, 1.5, nx=3, ny=4, nz=3, tetrahedra=cells == "tet")
    x = mesh.p.T.copy()
    interior = np.flatnonzero(np.all((x > 1e-9) & (x < np.array([1, 2, 1.5]) - 1e-9), axis=1))
    x[interior] += rng.uniform(-0.08, 0.08, (len(interior), 3))  # irregular elements
    tets = simplices(mesh, mesh.t)
    # random points in and around the box; points on the tetrahedra's faces and corners
    free = rng.uniform([-0.3, -0.3, -0.3], [1.3, 2.3, 1.8], (600, 3))
    k = rng.integers(len(tets), size=300)
    w = rng.dirichlet(np.ones(3), size=300)
    face = rng.integers(4, size=300)
    corners = x[tets[k]]
    others = np.array([[j for j in range(4) if j != f] for f in face])
    on_faces = np.einsum("ij,ijk->ik", w, corners[np.arange(300)[:, None], others])
    points = np.vstack([free, on_faces, x[tets[:50, 0]]])
    found = locate_in_simplices(x, tets, points)
    worst = _brute(x, tets, points)
    best = worst.max(axis=1)
    # a point is found in a tetrahedron that holds it, and exactly the points that one holds
    hit = found >= 0
    assert (worst[np.flatnonzero(hit), found[hit]] >= -1e-12).all()
    assert hit[best >= -1e-12].all()
    assert not hit[best < -1e-12].any()
    assert hit[600:].all()  # every point on a face or corner
    assert (~hit[:600]).sum() > 100 and hit[:600].sum() > 100


def _ray_triangles_all_pairs(points, a, b, c, e):
    """Every point against every triangle (Moeller-Trumbore), the reference."""
    best = np.inf
    for p in points:
        for ta, tb, tc in zip(a, b, c):
            e1, e2 = tb - ta, tc - ta
            pvec = np.cross(e, e2)
            det = e1 @ pvec
            if det == 0:
                continue
            w = p - ta
            qvec = np.cross(w, e1)
            u, v, t = (w @ pvec) / det, (qvec @ e) / det, (qvec @ e2) / det
            if u >= 0 and v >= 0 and u + v <= 1 and t >= 0:
                best = min(best, t)
    return best


@pytest.mark.parametrize("seed", range(4))
def test_the_ray_search_tries_only_the_pairs_that_can_hit_and_finds_every_hit(seed):
    """platen_approach's ray-triangle distance (pairs pruned by the triangles' projected
    circles, issue 40) equals every point tried against every triangle, on wavy grids with
    rays through vertices and edges and oblique rays."""
    from vfem.contact.geometry.placement import _ray_triangles

    rng = np.random.default_rng(seed)
    n = 6
    xs = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(xs, xs)
    P = np.column_stack([X.ravel(), Y.ravel(), 0.1 * rng.standard_normal(X.size)])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    tris = np.array([t for i in range(n) for j in range(n) for t in (
        (idx[i, j], idx[i, j + 1], idx[i + 1, j + 1]),
        (idx[i, j], idx[i + 1, j + 1], idx[i + 1, j]))])
    a, b, c = P[tris[:, 0]], P[tris[:, 1]], P[tris[:, 2]]
    on_grid = np.column_stack([rng.choice(xs, 30), rng.choice(xs, 30), np.full(30, 2.0)])
    scattered = np.column_stack([rng.uniform(-0.2, 1.2, (30, 2)), rng.uniform(1.0, 3.0, 30)])
    oblique = rng.standard_normal(3)
    oblique[2] = -abs(oblique[2]) - 1.0
    for points in (on_grid, scattered):
        for e in (np.array([0.0, 0.0, -1.0]), oblique / np.linalg.norm(oblique)):
            expected = _ray_triangles_all_pairs(points, a, b, c, e)
            got = _ray_triangles(points, a, b, c, e, 1000)
            if points is on_grid and e[2] == -1.0:  # straight down onto the grid: hits
                assert np.isfinite(expected)
            # the reference's sums run in another order: the distance to its round-off
            assert got == expected or abs(got - expected) <= 1e-14 * abs(expected)
