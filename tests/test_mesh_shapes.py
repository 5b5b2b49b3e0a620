"""Meshes of the wedge, block and gasket examples (thesis §5.3-§5.5): geometry and boundaries."""

from __future__ import annotations

import numpy as np
import pytest
from skfem import Basis, ElementQuad1, ElementTriP1, ElementVector, MeshTri, asm
from skfem.models.elasticity import lame_parameters, linear_elasticity

from vfem.mesh import block, gasket, gasket_pair, graded_nodes, wedge, wedge_plate

TOL = 1e-12


def signed_areas(mesh) -> np.ndarray:
    """Shoelace areas of the elements in their node order (> 0: counter-clockwise)."""
    x, y = mesh.p[0][mesh.t], mesh.p[1][mesh.t]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0)


def facet_points(mesh, name: str) -> np.ndarray:
    """(2, 2, nf): both end points of each facet of boundary ``name``."""
    return mesh.p[:, mesh.facets[:, mesh.boundaries[name]]]


def assert_valid(mesh, names: set[str]) -> None:
    """Oriented, conforming, boundaries named and partitioning the boundary, usable by skfem."""
    assert np.all(signed_areas(mesh) > 0)
    assert len(np.unique(mesh.t)) == mesh.p.shape[1]  # every node in some element
    bnd = mesh.boundary_facets()
    # A conforming mesh of a simply connected domain: the boundary is one closed loop.
    assert len(np.unique(mesh.facets[:, bnd])) == len(bnd)
    assert set(mesh.boundaries) == names
    assert all(len(f) > 0 for f in mesh.boundaries.values())
    named = np.concatenate(list(mesh.boundaries.values()))
    assert len(named) == len(np.unique(named))
    assert np.array_equal(np.sort(named), np.sort(bnd))
    # Plane elasticity assembles and rigid motions carry no force.
    e = ElementTriP1() if isinstance(mesh, MeshTri) else ElementQuad1()
    basis = Basis(mesh, ElementVector(e))
    K = asm(linear_elasticity(*lame_parameters(1.0, 0.3)), basis)
    x, y = basis.doflocs
    for u in (basis.zeros() + (np.arange(basis.N) % 2 == 0), np.where(
            np.arange(basis.N) % 2 == 0, -y, x)):
        assert np.abs(K @ u).max() < 1e-9 * abs(K).max()


def near_far_areas(mesh, focus, near: float, far: float) -> tuple[float, float]:
    """Mean element area with centroid within ``near`` of ``focus`` and beyond ``far``."""
    c = mesh.p[:, mesh.t].mean(axis=1)
    d = np.hypot(c[0] - focus[0], c[1] - focus[1])
    a = signed_areas(mesh)
    return a[d < near].mean(), a[d > far].mean()


# ----- wedge (§5.3) -----------------------------------------------------------------------------

def test_wedge_plate_geometry_and_boundaries():
    W, T = 5.0, 1.0
    m = wedge_plate(W, T, h_contact=0.05, h_max=0.25, growth=0.1)
    assert_valid(m, {"contact", "bottom", "symmetry", "right"})
    assert signed_areas(m).sum() == pytest.approx(W * T, abs=1e-10)
    assert np.allclose(facet_points(m, "contact")[1], 0.0, atol=TOL)
    assert np.allclose(facet_points(m, "bottom")[1], -T, atol=TOL)
    assert np.allclose(facet_points(m, "symmetry")[0], 0.0, atol=TOL)
    assert np.allclose(facet_points(m, "right")[0], W, atol=TOL)
    near, far = near_far_areas(m, (0.0, 0.0), 0.3, 3.0)
    assert near < 0.1 * far
    # The contact facet at the origin has the requested size.
    pts = facet_points(m, "contact")
    lengths = np.abs(pts[0, 1] - pts[0, 0])
    first = lengths[np.argmin(pts[0].min(axis=0))]
    assert first == pytest.approx(0.05, rel=0.2)
    assert lengths.max() == pytest.approx(0.25, rel=0.2)


def test_wedge_geometry_and_boundaries():
    W, e, T = 5.0, 1.0, 1.3
    m = wedge(W, e, T, h_contact=0.05, h_max=0.25, growth=0.1)
    assert_valid(m, {"contact", "symmetry", "top_loaded", "top", "right"})
    assert signed_areas(m).sum() == pytest.approx(W * (T + e) / 2, abs=1e-10)
    x, y = facet_points(m, "contact")
    assert np.allclose(y, (T - e) * x / W, atol=TOL)  # the straight lower face from the tip
    assert np.any(np.all(np.isclose(m.p, 0.0, atol=TOL), axis=0))  # tip is a node
    x, y = facet_points(m, "symmetry")
    assert np.allclose(x, 0.0, atol=TOL) and y.min() == pytest.approx(0.0, abs=TOL)
    x, y = facet_points(m, "right")
    assert np.allclose(x, W, atol=TOL)
    assert (y.min(), y.max()) == pytest.approx((T - e, T), abs=TOL)  # thickness e at the edge
    b = W / 5  # the documented default loaded width
    x, y = facet_points(m, "top_loaded")
    assert np.allclose(y, T, atol=TOL) and x.min() == pytest.approx(0.0, abs=TOL)
    assert x.max() == pytest.approx(b, abs=TOL)  # a node exactly at the end of the load
    x, y = facet_points(m, "top")
    assert np.allclose(y, T, atol=TOL) and x.min() == pytest.approx(b, abs=TOL)
    near, far = near_far_areas(m, (0.0, 0.0), 0.3, 3.0)
    assert near < 0.1 * far


def test_wedge_and_plate_contact_spacing_match_near_the_tip():
    """Both bodies follow the same size function of the distance from the point of contact."""
    kw = dict(h_contact=0.02, h_max=0.2, growth=0.2, plateau=0.1)
    lengths = []
    for m in (wedge(4.0, **kw), wedge_plate(4.0, **kw)):
        x = np.sort(np.unique(facet_points(m, "contact")[0]))
        lengths.append(np.diff(x[x < 0.1]))
    for h in lengths:
        assert np.allclose(h, 0.02, rtol=0.2)


def test_wedge_loaded_width_and_bad_input():
    m = wedge(5.0, loaded_width=1.37)
    x, _ = facet_points(m, "top_loaded")
    assert x.max() == pytest.approx(1.37, abs=TOL)
    with pytest.raises(ValueError):
        wedge(5.0, edge_thickness=1.3, centre_thickness=1.0)
    with pytest.raises(ValueError):
        wedge(5.0, loaded_width=6.0)


# ----- block (§5.4) -----------------------------------------------------------------------------

def test_uniform_block_of_quadrilaterals():
    m = block(-1.0, 0.5, 2.0, 1.0, 0.1)
    assert_valid(m, {"top", "bottom", "left", "right"})
    assert m.t.shape == (4, 200)
    assert signed_areas(m).sum() == pytest.approx(2.0, abs=1e-10)
    assert np.allclose(signed_areas(m), 0.01)
    assert np.allclose(facet_points(m, "top")[1], 1.5, atol=TOL)
    assert np.allclose(facet_points(m, "bottom")[1], 0.5, atol=TOL)
    assert np.allclose(facet_points(m, "left")[0], -1.0, atol=TOL)
    assert np.allclose(facet_points(m, "right")[0], 1.0, atol=TOL)


@pytest.mark.parametrize("triangles", [False, True])
def test_graded_half_block_towards_the_other_blocks_corner(triangles):
    """Half of the larger block, fine at the small block's corner (x = 0.5) and its face."""
    m = block(0.0, 0.0, 1.5, 1.0, 0.2, h_fine=0.02, growth=0.3, fine_x=(0.5,), fine_y=(0.0,),
              symmetry="left", triangles=triangles)
    assert_valid(m, {"top", "bottom", "symmetry", "right"})
    assert signed_areas(m).sum() == pytest.approx(1.5, abs=1e-10)
    assert np.allclose(facet_points(m, "symmetry")[0], 0.0, atol=TOL)
    x = np.unique(facet_points(m, "bottom")[0])
    assert np.any(np.abs(x - 0.5) < TOL)  # the corner's line is a grid line
    dx = np.diff(x)
    assert dx[np.argmin(np.abs(x[:-1] - 0.5))] == pytest.approx(0.02, rel=0.3)
    assert dx.max() == pytest.approx(0.2, rel=0.3)
    near, far = near_far_areas(m, (0.5, 0.0), 0.05, 0.8)
    assert near < 0.05 * far


def test_block_rejects_unknown_symmetry_side():
    with pytest.raises(ValueError):
        block(0.0, 0.0, 1.0, 1.0, 0.1, symmetry="top")


def test_graded_nodes_follow_the_size_function():
    x = graded_nodes(0.0, 2.0, lambda s: np.full_like(s, 0.25))
    assert np.allclose(x, np.linspace(0.0, 2.0, 9), atol=1e-12)
    x = graded_nodes(1.0, 3.0, lambda s: 0.01 + 0.2 * np.abs(s - 2.0))
    assert (x[0], x[-1]) == (1.0, 3.0) and np.all(np.diff(x) > 0)
    h = np.diff(x)
    assert h.min() < 0.03 and h[0] > 5 * h.min() and h[-1] > 5 * h.min()


# ----- gasket (§5.5) ----------------------------------------------------------------------------

@pytest.mark.parametrize("opening", ["left", "right", "up", "down"])
def test_gasket_is_a_half_annulus(opening):
    c, R, t, n, k = np.array([0.3, -0.2]), 1.0, 0.1, 60, 3
    m = gasket(tuple(c), R, t, opening, n_around=n, n_through=k)
    assert_valid(m, {"outer", "inner", "back"})
    a = signed_areas(m).sum()
    assert a == pytest.approx(0.5 * n * np.sin(np.pi / n) * (R**2 - (R - t) ** 2), abs=1e-12)
    exact = 0.5 * np.pi * (R**2 - (R - t) ** 2)  # chords cut the arcs: a - exact ~ -(pi/n)^2/6
    assert 0 < (exact - a) / exact < (np.pi / n) ** 2 / 6 * 1.01
    r = lambda q: np.hypot(q[0] - c[0], q[1] - c[1])  # noqa: E731
    assert np.allclose(r(facet_points(m, "outer")), R, atol=TOL)
    assert np.allclose(r(facet_points(m, "inner")), R - t, atol=TOL)
    o = {"left": (-1, 0), "right": (1, 0), "up": (0, 1), "down": (0, -1)}[opening]
    side = lambda q: (q[0] - c[0]) * o[0] + (q[1] - c[1]) * o[1]  # noqa: E731
    back = facet_points(m, "back")
    assert np.allclose(side(back), 0.0, atol=TOL)  # the two cut ends, on the diameter
    assert len(m.boundaries["back"]) == 2 * k
    assert np.all(side(facet_points(m, "outer")) <= TOL)  # bulges away from the opening
    assert np.min(side(facet_points(m, "outer"))) == pytest.approx(-R, abs=TOL)


def test_gasket_pair_matches_the_thesis_layout():
    """Offset 0.25, horizontal clearance 0.2; backs closing 0.025 each per step first overlap
    at step 5, and overlap by about 0.28 at step 10 (thesis §5.5)."""
    left, right = gasket_pair(n_around=40, n_through=2)
    for m in (left, right):
        assert_valid(m, {"outer", "inner", "back"})
    centre = [m.p[:, np.unique(m.facets[:, m.boundaries["back"]])].mean(axis=1)
              for m in (left, right)]
    assert centre[1][1] - centre[0][1] == pytest.approx(0.25, abs=TOL)
    apex_left = left.p[0, np.unique(left.facets[:, left.boundaries["outer"]])].max()
    apex_right = right.p[0, np.unique(right.facets[:, right.boundaries["outer"]])].min()
    assert apex_right - apex_left == pytest.approx(0.2, abs=TOL)
    assert np.all(left.p[0] < apex_right) and np.all(right.p[0] > apex_left)
    dx, dy = centre[1] - centre[0]
    gap = np.array([np.hypot(dx - 2 * 0.025 * s, dy) - 2.0 for s in range(11)])
    assert np.argmax(gap < 0) == 5
    assert -gap[10] == pytest.approx(0.28, abs=0.005)
