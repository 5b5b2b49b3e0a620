"""Invariant (b) at O(contact) per step, its answers unchanged (vfem.contact.invariants).

* The edges' and vertices' normal sums, vectorised (``Surface3.edge_normals``,
  ``feature_normals``, ``scatter_add``), equal the straightforward per-triangle sums bit for bit,
  three triangles on an edge included (their order of addition kept).
* The pre-filter (``InvariantCheck._may_enter``) keeps every node that lies inside the other
  body: on random displacements (rigid moves up to the bodies' size, noise of any scale), a
  node pushed far into the other body, bodies that overlap undeformed (an interference fit)
  and quarter models (symmetry planes, which ``inside`` reads as boundary); 2D (linear and
  quadratic facets) and 3D. The filtered check's record equals the unfiltered one's.
* It does skip: at rest, a curved body on a flat one asks of the nodes at the touching point,
  not of every node in the other's box; and in 2D, with fewer nodes in the box than
  ``_Polygon.bound_from``, it asks them all (the tests here apply it to any number).
"""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
from skfem import MeshQuad

import models
from vfem.bodies import Body, Support
from vfem.contact.invariants.cached_boundary import scatter_add
from vfem.contact.invariants.check import InvariantCheck
from vfem.contact.invariants.check3d import FEATURE, Boundary3, Surface3
from vfem.contact.invariants.polygon import _Polygon
from vfem.materials import LinearElastic
from vfem.mesh.parametric import graded_half_disk
from vfem.mesh.solids import box, cylinder

pytest.importorskip("hypothesis", reason="these tests need hypothesis: pip install -e .[test]")

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

MAT = LinearElastic(1000.0, 0.3)
TOL = 1e-8
DRAWS = settings(derandomize=True, deadline=None, database=None, max_examples=25,
                 suppress_health_check=[HealthCheck.too_slow])


@pytest.fixture(autouse=True)
def bound_always(monkeypatch):
    """The 2D models here are small: the bound applied however few nodes are in the box
    (``bound_from``: below it, 2D asks them all, cheaper there)."""
    monkeypatch.setattr(_Polygon, "bound_from", 0)


class Unfiltered(InvariantCheck):
    """The check as it was: every node in the other body's box asked."""

    def _may_enter(self, i, j, near, cur, ref):
        return near


# -- models ---------------------------------------------------------------------------------


def disk_on_block(order: int = 1) -> list[Body]:
    """A half disk (radius 1, curved side down) touching a block's top at the origin."""
    block = Body("block", models.rect(MeshQuad, -1.5, 1.5, -0.5, 0.0, 12, 3), MAT,
                 supports=(Support("bottom"),), order=order)
    disk = Body("disk", graded_half_disk(1.0, 0.1, 0.3), MAT, order=order)
    return [block, disk]


def overlapping_blocks() -> list[Body]:
    """An interference fit: the upper block's lowest 0.05 lies inside the lower one."""
    lower = Body("lower", models.rect(MeshQuad, 0.0, 1.0, -0.5, 0.0, 8, 4), MAT,
                 supports=(Support("bottom"),))
    upper = Body("upper", models.rect(MeshQuad, 0.2, 0.8, -0.05, 0.45, 5, 4), MAT)
    return [lower, upper]


def sphere_on_box(quarter: bool = True) -> list[Body]:
    """A sphere-ended cylinder (tetrahedra) touching a box's top at the origin; with
    ``quarter`` both are quarter models held by rollers on x = 0 and y = 0 (symmetry planes)."""
    rollers = (Support("left", ("x",)), Support("front", ("y",))) if quarter else ()
    lo, width = (0.0, 1.0) if quarter else (-1.0, 2.0)
    block = Body("block", box(lo, lo, -0.5, width, width, 0.5, nx=5, ny=5, nz=2), MAT,
                 supports=(Support("bottom"), *rollers))
    sphere = Body("sphere", cylinder(0.5, 0.4, end_radius=1.0, h=0.15, quarter=quarter,
                                     tetrahedra=True), MAT, supports=rollers)
    return [block, sphere]


def at_rest(bodies) -> dict:
    return {b.name: SimpleNamespace(displacement=np.zeros((b.npoints, b.dim)),
                                    contact_force=np.zeros((b.npoints, b.dim)))
            for b in bodies}


def moved(bodies, seed: int, rigid: float, noise: float) -> dict:
    """Each body translated by up to ``rigid`` and turned by up to ``rigid`` radians about
    its centroid, plus per-node noise of up to ``noise``."""
    rng = np.random.default_rng(seed)
    fields = at_rest(bodies)
    for b in bodies:
        X = b.points.T
        c = X.mean(axis=0)
        angle = rng.uniform(-rigid, rigid)
        rot = np.eye(b.dim)
        rot[:2, :2] = [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
        u = (X - c) @ rot.T + c - X + rng.uniform(-rigid, rigid, b.dim)
        u += rng.uniform(-noise, noise, X.shape)
        fields[b.name].displacement[:] = u
    return fields


def record(inv) -> str:
    out = inv.record()
    out.pop("seconds")
    return json.dumps(out, sort_keys=True)


def surfaces(check: InvariantCheck, fields: dict) -> tuple[list, list]:
    """The current and undeformed surfaces of a state, as ``InvariantCheck.__call__`` builds
    them."""
    ref = check.reference
    cur = [check.kind.surface(r.b, r.x + np.asarray(fields[b.name].displacement)[r.b.nodes])
           for b, r in zip(check.bodies, ref)]
    return cur, ref


def assert_keeps_every_inside_node(check: InvariantCheck, fields: dict) -> int:
    """Every boundary node of a body inside another (``inside`` on the current surfaces) is
    among those ``_may_enter`` keeps of all its nodes; the filtered check's record is the
    unfiltered one's. Returns the number of nodes inside."""
    cur, ref = surfaces(check, fields)
    found = 0
    for i, j in check.pairs:
        every = np.arange(len(cur[i].x))
        pair = check._undeformed.get((i, j))
        unseen = every if pair is None else every[~pair.seen]
        if unseen.size:  # a node's first time in the box: asked as it stands
            assert np.isin(unseen, check._may_enter(i, j, every, cur, ref)).all()
        kept = check._may_enter(i, j, every, cur, ref)
        inside = every[cur[j].inside(cur[i].x)]
        assert np.isin(inside, kept).all(), (i, j, np.setdiff1d(inside, kept))
        assert np.all(np.diff(kept) > 0)  # a subset, in order
        found += len(inside)
    unfiltered = Unfiltered(check.bodies, check.pairs, TOL)
    assert record(check(fields)) == record(unfiltered(fields))
    return found


# -- the normals' sums ----------------------------------------------------------------------


def _edge_normals_by_dict(s: Surface3) -> dict:
    """The sums as they were computed: a dict over every triangle's sides, in order."""
    out: dict = {}
    for f, tri in enumerate(s.b.triangles):
        for k in range(3):
            key = (min(tri[k], tri[(k + 1) % 3]), max(tri[k], tri[(k + 1) % 3]))
            out[key] = out.get(key, 0.0) + s.unit_normals[f]
    return out


def _feature_normals_by_loop(s: Surface3, tri, lam, vertex):
    out = s.unit_normals[tri].copy()
    zero = lam <= FEATURE
    nodes = s.b.triangles[tri]
    edges = _edge_normals_by_dict(s)
    for m in np.flatnonzero(zero.any(axis=1)):
        z = np.flatnonzero(zero[m])
        if len(z) >= 2:
            out[m] = vertex[nodes[m, 3 - z.sum()]]
        else:
            e = nodes[m, [(z[0] + 1) % 3, (z[0] + 2) % 3]]
            out[m] = edges[(min(e), max(e))]
    return out


def _check_sums(s: Surface3, rng) -> None:
    reference = _edge_normals_by_dict(s)
    half, count, opposite = s.b.edges
    t = s.b.triangles
    assert count == len(reference)
    got = s.edge_normals
    for f in range(len(t)):
        for k in range(3):
            key = (min(t[f, k], t[f, (k + 1) % 3]), max(t[f, k], t[f, (k + 1) % 3]))
            assert np.array_equal(got[half[3 * f + k]], reference[key])
            # the side opposite corner k + 2
            assert opposite[f, (k + 2) % 3] == half[3 * f + k]
    # vertex pseudonormals: np.add.at over the corners, as they were summed
    pseudo = np.zeros_like(s.x)
    for k in range(3):
        np.add.at(pseudo, t[:, k], s.angles[:, k, None] * s.unit_normals)
    assert np.array_equal(s.pseudonormals, pseudo)
    # feature normals at points on faces, edges and vertices of random triangles
    m = 400
    tri = rng.integers(0, len(t), m)
    lam = rng.dirichlet(np.ones(3), m)
    lam[rng.random((m, 3)) < 0.3] = 0.0
    lam[:, 0] = np.where(lam.sum(axis=1) == 0, 1.0, lam[:, 0])
    lam /= lam.sum(axis=1, keepdims=True)
    assert np.array_equal(s.feature_normals(tri, lam, s.pseudonormals),
                          _feature_normals_by_loop(s, tri, lam, s.pseudonormals))


@pytest.mark.parametrize("tetrahedra", [False, True])
def test_edge_and_vertex_normals_equal_the_per_triangle_sums(tetrahedra):
    body = Body("b", box(0, 0, 0, 1, 0.7, 0.4, nx=4, ny=3, nz=2, tetrahedra=tetrahedra), MAT)
    check = InvariantCheck([body], [], TOL)
    rng = np.random.default_rng(3)
    ref = check.reference[0]
    s = Surface3(ref.b, ref.x + rng.normal(scale=0.02, size=ref.x.shape))
    _check_sums(s, rng)


def test_three_triangles_on_an_edge_are_summed_in_their_order():
    """An edge (0, 1) shared by three triangles (not a closed surface: the sums alone)."""
    triangles = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 3]])
    rng = np.random.default_rng(7)
    x = rng.normal(size=(5, 3)) * [1.0, 1e-3, 1e3]
    b = Boundary3(nodes=np.arange(5), triangles=triangles, owner=np.arange(4),
                  facets=triangles, mirror=np.zeros(4, dtype=bool),
                  segments=np.zeros((0, 2), dtype=np.int64), large=False)
    _check_sums(Surface3(b, x), rng)


@DRAWS
@given(n=st.integers(1, 40), m=st.integers(0, 300), seed=st.integers(0, 2**32 - 1))
def test_scatter_add_is_np_add_at_bit_for_bit(n, m, seed):
    rng = np.random.default_rng(seed)
    index = rng.integers(0, n, m)
    values = rng.normal(size=(m, 3)) * 10.0 ** rng.integers(-8, 9, (m, 1))
    expected = np.zeros((n, 3))
    np.add.at(expected, index, values)
    assert np.array_equal(scatter_add(n, index, values), expected)


# -- the pre-filter -------------------------------------------------------------------------


@pytest.mark.parametrize(("make", "rigid_motions", "examples"), [
    (lambda: disk_on_block(1), [0.0, 1e-4, 0.05, 0.5], None),
    (lambda: disk_on_block(2), [0.0, 1e-4, 0.05, 0.5], None),
    (lambda: sphere_on_box(quarter=True), [0.0, 1e-4, 0.05, 0.3], 12)],
    ids=["2d-linear", "2d-quadratic", "3d"])
def test_random_displacements_keep_every_inside_node(make, rigid_motions, examples):
    bodies = make()
    check = InvariantCheck(bodies, None, TOL)

    @(DRAWS if examples is None else settings(DRAWS, max_examples=examples))
    @given(seed=st.integers(0, 2**32 - 1), rigid=st.sampled_from(rigid_motions),
           noise=st.sampled_from([0.0, 1e-6, 1e-3, 0.05]))
    def draw(seed, rigid, noise):
        assert_keeps_every_inside_node(check, moved(bodies, seed, rigid, noise))

    draw()


def test_a_node_pushed_deep_into_the_other_body_is_found_2d():
    bodies = disk_on_block()
    check = InvariantCheck(bodies, None, TOL)
    fields = moved(bodies, 0, 0.0, 1e-7)
    assert check(fields).where is None or check(fields).penetration < 1e-5
    block = bodies[0]
    X = block.points
    node = int(np.flatnonzero((np.abs(X[0] - 0.5) < 1e-9) & (np.abs(X[1]) < 1e-9))[0])
    fields["block"].displacement[node] = [0.0, 0.6]  # through the disk's arc (0.13 above)
    assert assert_keeps_every_inside_node(check, fields) >= 1
    inv = check(fields)
    assert inv.where["body"] == "block" and inv.where["node"] == node
    assert inv.penetration > 0.3


def test_a_node_pushed_deep_into_the_other_body_is_found_3d():
    bodies = sphere_on_box(quarter=True)
    check = InvariantCheck(bodies, None, TOL)
    fields = at_rest(bodies)
    check(fields)  # the undeformed sides kept from a state at rest
    X = bodies[0].points
    top = np.flatnonzero(np.abs(X[2]) < 1e-9)
    node = int(top[np.argmin(np.hypot(X[0, top] - 0.2, X[1, top] - 0.2))])
    fields["block"].displacement[node] = [0.0, 0.0, 0.3]
    assert assert_keeps_every_inside_node(check, fields) >= 1
    inv = check(fields)
    assert inv.where["body"] == "block" and inv.where["node"] == node
    assert inv.penetration > 0.1
    # and the sphere moved down into the block as a whole
    fields = at_rest(bodies)
    fields["sphere"].displacement[:, 2] = -0.05
    assert assert_keeps_every_inside_node(check, fields) > 10
    assert 0.04 < check(fields).penetration <= 0.05 + 1e-12


def test_bodies_overlapping_undeformed_are_always_asked():
    """An interference fit: the nodes inside undeformed are asked whatever the displacements
    (here none, a rigid lift that frees them, and random ones)."""
    bodies = overlapping_blocks()
    check = InvariantCheck(bodies, None, TOL)
    fields = at_rest(bodies)
    assert assert_keeps_every_inside_node(check, fields) > 0
    inv = check(fields)
    assert inv.penetration == pytest.approx(0.05, rel=1e-9)
    fields["upper"].displacement[:, 1] = 0.1
    assert assert_keeps_every_inside_node(check, fields) == 0
    assert check(fields).where is None
    for seed in range(5):
        assert_keeps_every_inside_node(check, moved(bodies, seed, 0.05, 1e-3))


def test_symmetry_planes_count_as_boundary_whole_and_quarter():
    """``inside`` reads a quarter model's symmetry planes as boundary: a node moved across
    one (out of the quarter) is outside, and one moved through the curved face inside; the
    whole model reads the same nodes alike."""
    for quarter in (True, False):
        bodies = sphere_on_box(quarter)
        check = InvariantCheck(bodies, None, TOL)
        fields = moved(bodies, 11, 0.0, 1e-4)
        fields["sphere"].displacement[:, 0] -= 0.05  # the quarter sphere partly past x = 0
        fields["sphere"].displacement[:, 2] -= 0.03
        assert assert_keeps_every_inside_node(check, fields) > 0


def test_the_filter_skips_what_cannot_be_inside():
    """Touching at rest, or both moved by one large translation, the block's top nodes in the
    disk's and the sphere's boxes are farther from them than anything moved: only the
    touching point is asked."""
    for bodies in (disk_on_block(), sphere_on_box()):
        check = InvariantCheck(bodies, None, TOL)
        for shift in (0.0, 0.7):
            fields = at_rest(bodies)
            for b in bodies:
                fields[b.name].displacement[:] = shift * np.arange(1, b.dim + 1)
            cur, ref = surfaces(check, fields)
            i, j = 0, 1  # the block's nodes into the curved body
            lo, hi = cur[j].box
            pad = 1e-9 * np.linalg.norm(hi - lo)
            near = np.flatnonzero(np.all((cur[i].x >= lo - pad) & (cur[i].x <= hi + pad),
                                         axis=1))
            first = check._may_enter(i, j, near, cur, ref)
            kept = check._may_enter(i, j, near, cur, ref)
            assert len(near) >= 9 and len(kept) == 1, (len(near), len(kept))
            assert shift or np.array_equal(first, near)  # the first time: every node
            assert np.allclose(ref[i].x[kept], 0.0)  # the origin
            assert_keeps_every_inside_node(check, fields)


def test_2d_asks_every_node_of_a_small_box(monkeypatch):
    """2D, fewer nodes in the box than ``_Polygon.bound_from``: all asked, bound or not."""
    monkeypatch.undo()
    assert _Polygon.bound_from > 0
    bodies = disk_on_block()
    check = InvariantCheck(bodies, None, TOL)
    fields = at_rest(bodies)
    cur, ref = surfaces(check, fields)
    near = np.arange(len(cur[1].x))  # every node of the disk, into the block
    assert len(near) < _Polygon.bound_from
    for _ in range(2):
        assert np.array_equal(check._may_enter(1, 0, near, cur, ref), near)
    assert check._undeformed == {}
    monkeypatch.setattr(_Polygon, "bound_from", len(near))
    check._may_enter(1, 0, near, cur, ref)
    assert len(check._may_enter(1, 0, near, cur, ref)) < len(near)
