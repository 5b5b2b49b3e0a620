"""The built-in meshes made faster (issue 19, item 6) are the meshes they were.

The shapes now build scikit-fem's facet topology once (:mod:`vfem.mesh.topology`), name their
boundaries on the boundary facets only, and prune the nearest-node searches that thin out the
interior nodes (:func:`vfem.mesh.parametric.farther_than`). Each is compared here, bit for
bit, with the straightforward computation it replaced: scikit-fem's own ``facets``, ``t2f``,
``f2t`` and ``with_boundaries``, and an unbounded ``cKDTree`` query.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial import Delaunay, cKDTree
from skfem import Mesh, MeshQuad, MeshTri

from vfem.config import SHAPES
from vfem.mesh import parametric, quadratic, shapes
from vfem.mesh.topology import CACHED, facet_topology, named_boundaries, with_topology

#: Small parameters for every built-in shape (each makes a few hundred elements at most).
SMALL = {
    "rectangle": dict(x0=1.0, y0=-2.0, width=3.0, height=1.0, nx=7, ny=3),
    "rectangle_tri": dict(x0=1.0, y0=-2.0, width=3.0, height=1.0, nx=7, ny=3, triangles=True),
    "block": dict(x0=0.0, y0=-0.5, width=0.5, height=0.5, h=0.1, h_fine=0.02, growth=0.3,
                  fine_x=(0.5,), fine_y=(0.0,), symmetry="left"),
    "block_tri": dict(x0=0.0, y0=0.0, width=1.0, height=2.0, h=0.3, h_fine=0.05,
                      fine_x=(0.3, 0.7), triangles=True),
    "graded_quarter_disk": dict(radius=1.0, h_contact=0.01, h_max=0.1, growth=0.15,
                                plateau=0.05),
    "graded_quarter_disk_plain": dict(radius=2.0, h_contact=0.02, h_max=0.2),
    "graded_layer": dict(width=1.0, thickness=0.1, h_contact=0.005, h_max=0.05, plateau=0.02),
    "wedge": dict(h_contact=0.05, h_max=0.25, plateau=0.2),
    "wedge_plate": dict(h_contact=0.05, h_max=0.25),
    "wedge_grid": dict(columns=15, rows=3),
    "wedge_plate_grid": dict(columns=15, rows=3, loaded_width=5.0),
    "gasket": dict(centre=(1.0, 2.0), opening="up", n_around=40, n_through=2),
    "rounded_punch": dict(x0=-1.0, y0=1.0, width=1.2, height=0.6, radius=1.0, nx=12, ny=4),
    "filleted_punch": dict(h_tangent=0.01, n_arc=5),
    "cylinder_section": dict(radius=0.6, height=0.5, end_radius=1.0, h_contact=0.02, h=0.1,
                             growth=0.3, plateau=0.1),
}


def shape_of(case: str) -> str:
    return next(s for s in sorted(SHAPES, key=len, reverse=True) if case.startswith(s))


def skfem_topology(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """scikit-fem's own facets, t2f and f2t of the mesh's elements (a copy without caches)."""
    fresh = replace(mesh)
    assert not any(hasattr(fresh, name) for name in CACHED)
    return fresh.facets, fresh.t2f, fresh.f2t


def assert_same_arrays(a, b) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.dtype == y.dtype and x.shape == y.shape
        assert np.array_equal(x, y)


def reference(monkeypatch, case: str) -> Mesh:
    """The shape made the straightforward way: skfem's ``with_boundaries`` on every facet,
    no shared topology, unbounded nearest-node searches."""
    with monkeypatch.context() as m:
        for module in (parametric, shapes):
            m.setattr(module, "named_boundaries", lambda mesh, tests: mesh.with_boundaries(tests))
            m.setattr(module, "farther_than",
                      lambda points, q, limit: cKDTree(points).query(q)[0] > limit)
        m.setattr(shapes, "share_topology", lambda source, copy: copy)
        return SHAPES[shape_of(case)](**SMALL[case])


@pytest.mark.parametrize("case", sorted(SMALL))
def test_shapes_equal_the_straightforward_computation(monkeypatch, case):
    fast = SHAPES[shape_of(case)](**SMALL[case])
    ref = reference(monkeypatch, case)
    assert type(fast) is type(ref)
    assert fast.p.dtype == ref.p.dtype and np.array_equal(fast.p, ref.p)
    assert fast.t.dtype == ref.t.dtype and np.array_equal(fast.t, ref.t)
    assert list(fast.boundaries) == list(ref.boundaries)
    for name in ref.boundaries:
        assert_same_arrays([fast.boundaries[name]], [ref.boundaries[name]])
    # the topology the fast mesh carries is scikit-fem's
    assert all(hasattr(fast, name) for name in CACHED)
    assert_same_arrays([fast.facets, fast.t2f, fast.f2t], skfem_topology(fast))


@pytest.mark.parametrize("case", sorted(SMALL))
def test_boundaries_partition_the_boundary(case):
    mesh = SHAPES[shape_of(case)](**SMALL[case])
    named = np.concatenate([np.asarray(f) for f in mesh.boundaries.values()])
    assert all(len(f) for f in mesh.boundaries.values())
    assert len(named) == len(np.unique(named))  # disjoint
    assert np.array_equal(np.sort(named), mesh.boundary_facets())  # and covering


def test_quarter_disk_boundaries_lie_where_named():
    R = 1.0
    mesh = parametric.graded_quarter_disk(R, 0.01, 0.1, plateau=0.05)
    ends = lambda name: mesh.p[:, mesh.facets[:, mesh.boundaries[name]]]  # noqa: E731
    assert np.allclose(np.hypot(*ends("contact") - np.array([0.0, R])[:, None, None]), R)
    assert np.all(ends("symmetry")[0] == 0.0)
    assert np.all(ends("top")[1] == R)


def test_rectangle_sides_have_their_facet_counts():
    mesh = shapes.rectangle(0.0, 0.0, 2.0, 1.0, nx=7, ny=3)
    assert {k: len(v) for k, v in mesh.boundaries.items()} == {
        "top": 7, "bottom": 7, "left": 3, "right": 3}


def random_triangulation(n: int, seed: int) -> MeshTri:
    rng = np.random.default_rng(seed)
    p = rng.random((n, 2))
    t = Delaunay(p).simplices.T
    return MeshTri(p.T, t[rng.permutation(3)][:, rng.permutation(t.shape[1])], sort_t=False)


@pytest.mark.parametrize("mesh", [
    random_triangulation(300, 0),
    random_triangulation(1000, 1),
    MeshTri.init_sqsymmetric().refined(2),
    MeshQuad.init_tensor(np.linspace(0, 1, 7), np.linspace(0, 2, 4)),
    MeshQuad().refined(3),
], ids=["delaunay300", "delaunay1000", "sqsymmetric", "tensor", "quad"])
def test_facet_topology_is_scikit_fems(mesh):
    ours = facet_topology(mesh.t, mesh.elem.refdom.facets)
    assert_same_arrays(ours, skfem_topology(mesh))
    # and with_topology puts exactly that into scikit-fem's caches
    copy = with_topology(replace(mesh))
    assert_same_arrays([copy.facets, copy.t2f, copy.f2t], ours)


def test_named_boundaries_equal_with_boundaries():
    mesh = random_triangulation(500, 2)
    tests = {"left": lambda x: x[0] < 0.5, "low": lambda x: x[1] < 0.3,
             "none": lambda x: x[0] > 2.0}
    ours = named_boundaries(mesh, tests)
    ref = mesh.with_boundaries(tests)
    assert list(ours.boundaries) == list(ref.boundaries)
    for name in tests:
        assert_same_arrays([ours.boundaries[name]], [ref.boundaries[name]])
    assert_same_arrays([ours.facets, ours.t2f, ours.f2t], skfem_topology(ref))


def test_farther_than_is_the_unbounded_query():
    rng = np.random.default_rng(3)
    points, q = rng.random((400, 2)), rng.random((2000, 2))
    d = cKDTree(points).query(q)[0]
    # limits around the distances themselves, ties included: the comparison is at its edge
    limit = d * rng.choice([0.5, 1.0, np.nextafter(1.0, 0.0), np.nextafter(1.0, 2.0), 3.0],
                           size=len(d))
    assert np.array_equal(parametric.farther_than(points, q, limit), d > limit)
    # every point exactly at its limit, the farthest one at the largest: never farther
    assert not parametric.farther_than(points, q, d).any()
    assert parametric.farther_than(points, np.zeros((0, 2)), np.zeros(0)).shape == (0,)


def test_curved_keeps_the_topology_and_boundaries():
    mesh = parametric.graded_quarter_disk(1.0, 0.02, 0.1)
    m2 = quadratic.curved(mesh, "contact", (0.0, 1.0), 1.0)
    assert all(hasattr(m2, name) for name in CACHED)
    assert_same_arrays([m2.facets, m2.t2f, m2.f2t], skfem_topology(m2))
    assert list(m2.boundaries) == list(mesh.boundaries)
    mid = m2.doflocs[:, mesh.nvertices + mesh.boundaries["contact"]]
    assert np.allclose(np.hypot(mid[0], mid[1] - 1.0), 1.0)


def test_a_mesh_without_elements_is_left_to_scikit_fem():
    """A degenerate mesh (a fuzzed input file: a block at x0 = 1e300) has no elements; its
    facets are left to scikit-fem's own path and its own error, as before the fast build."""
    empty = MeshTri(np.zeros((2, 3)), np.zeros((3, 0), dtype=np.int64))
    assert with_topology(empty) is empty
    assert not hasattr(empty, "_f2t")
