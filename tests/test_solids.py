"""Built-in 3D shapes (issue 21): the cylinder with a flat or spherical end (and its r-z
section), and the 3D stiffness assembly they are solved with."""

import math

import numpy as np
import pytest
from skfem import (
    Basis,
    ElementHex1,
    ElementHex2,
    ElementTetP1,
    ElementTetP2,
    ElementVector,
    asm,
)
from skfem.models.elasticity import linear_elasticity

from vfem.bodies.assembly import cell_gradients, cell_mapping, elasticity_stiffness
from vfem.mesh.checks import check_mesh
from vfem.mesh.solids import box, cylinder, cylinder_section


def volume(mesh) -> float:
    b = Basis(mesh, ElementTetP1() if mesh.t.shape[0] == 4 else ElementHex1())
    return float(b.dx.sum())


@pytest.mark.parametrize("tetrahedra", [False, True], ids=["hex", "tet"])
@pytest.mark.parametrize("quarter", [True, False], ids=["quarter", "full"])
def test_cylinder_with_a_spherical_end(quarter, tetrahedra):
    R, Rc, H = 10.0, 6.0, 5.0
    m = cylinder(Rc, H, end_radius=R, x0=1.0, y0=-2.0, z0=0.5, quarter=quarter,
                 h_contact=0.25, h=1.0, plateau=1.0, tetrahedra=tetrahedra)
    check_mesh(m, "cylinder")  # no inverted or folded element
    centre = np.array([[1.0], [-2.0], [0.5 + R]])
    end = np.unique(m.facets[:, m.boundaries["contact"]])
    assert np.abs(np.linalg.norm(m.p[:, end] - centre, axis=0) - R).max() < 1e-12
    side = np.unique(m.facets[:, m.boundaries["side"]])
    assert np.abs(np.hypot(m.p[0, side] - 1.0, m.p[1, side] + 2.0) - Rc).max() < 1e-12
    top = np.unique(m.facets[:, m.boundaries["top"]])
    assert np.abs(m.p[2, top] - (0.5 + H)).max() < 1e-12
    names = {"contact", "top", "side"} | ({"left", "front"} if quarter else set())
    assert set(m.boundaries) == names
    if quarter:
        assert np.abs(m.p[0, np.unique(m.facets[:, m.boundaries["left"]])] - 1.0).max() < 1e-12
        assert np.abs(m.p[1, np.unique(m.facets[:, m.boundaries["front"]])] + 2.0).max() < 1e-12
    # the volume: the cylinder less the cap under the sphere, to the faceting error
    exact = (math.pi * Rc ** 2 * H - math.pi * R * Rc ** 2
             + 2 * math.pi / 3 * (R ** 3 - (R ** 2 - Rc ** 2) ** 1.5))
    assert volume(m) * (4 if quarter else 1) == pytest.approx(exact, rel=4e-3)  # 2.3e-3 measured
    # the contact zone is a regular grid: spacing h_contact within the plateau of the axis
    near = end[np.hypot(m.p[0, end] - 1.0, m.p[1, end] + 2.0) < 0.9]
    xs = np.unique(np.round(m.p[0, near], 12))
    assert np.allclose(np.diff(xs), np.diff(xs)[0], rtol=1e-9)
    assert np.diff(xs)[0] <= 0.25


def test_flat_ended_cylinder_and_refusals():
    m = cylinder(1.0, 2.0, h=0.25, quarter=False)
    check_mesh(m, "punch")
    assert volume(m) == pytest.approx(math.pi * 2.0, rel=1e-2)
    assert np.abs(m.p[2, np.unique(m.facets[:, m.boundaries["contact"]])]).max() == 0.0
    with pytest.raises(ValueError, match="end_radius > radius"):
        cylinder(6.0, 5.0, end_radius=5.0, h=1.0)
    with pytest.raises(ValueError, match="height above 2"):
        cylinder(6.0, 1.5, end_radius=10.0, h=1.0)
    with pytest.raises(ValueError, match="give the element size h"):
        cylinder(1.0, 1.0)


@pytest.mark.parametrize("element,tetrahedra", [(ElementHex1, False), (ElementTetP1, True),
                                                (ElementTetP2, True),
                                                pytest.param(ElementHex2, False,
                                                             marks=pytest.mark.slow)],
                         ids=["hex1", "tet1", "tet2", "hex2"])
def test_3d_stiffness_equals_scikit_fem_assembly(element, tetrahedra):
    mesh = cylinder(6.0, 5.0, end_radius=10.0, h=3.0 if element is ElementHex2 else 1.5,
                    tetrahedra=tetrahedra)  # (curved, distorted hexahedra near the rim)
    plain = Basis(mesh, ElementVector(element()))
    remembering = Basis(mesh, ElementVector(element()), mapping=cell_mapping(mesh))
    assert all(np.array_equal(a[0].grad, b[0].grad) for a, b in
               zip(plain.basis, remembering.basis))  # the same numbers, computed once
    assert np.array_equal(plain.dx, remembering.dx)
    # the chunks' scalar gradients are the vector basis's, bit for bit, however it is cut
    # (a body keeps no basis: vfem.bodies.assembly.cell_gradients)
    for chunk in (None, 7):
        seen = 0
        for e, grads, dx in cell_gradients(mesh, element(), chunk=chunk):
            assert np.array_equal(dx, plain.dx[e])
            assert all(np.array_equal(grads[a], plain.basis[3 * a][0].grad[0][:, e])
                       for a in range(grads.shape[0]))
            seen += e.stop - e.start
        assert seen == mesh.nelements
    reference = asm(linear_elasticity(1.3, 0.7), plain).tocsr()
    K = elasticity_stiffness(mesh, element(), 1.3, 0.7)
    assert abs(K - reference).max() < 2e-15 * abs(reference).max()


def test_box_plateau_keeps_the_fine_spacing():
    m = box(0.0, 0.0, 0.0, 4.0, 4.0, 1.0, h=1.0, h_fine=0.1, fine_x=(0.0,), plateau=0.5)
    xs = np.unique(m.p[0])
    d = np.diff(xs[xs < 0.5 + 1e-9])
    assert np.allclose(d, d[0], rtol=1e-12) and 0.09 < d[0] <= 0.1


@pytest.mark.parametrize("tetrahedra", [False, True], ids=["hex", "tet"])
@pytest.mark.parametrize("quarter", [True, False], ids=["quarter", "full"])
def test_ring(quarter, tetrahedra):
    from vfem.mesh.solids import ring

    m = ring(1.0, 2.0, 0.5, x0=0.5, quarter=quarter, around=8, radial=3, layers=2,
             tetrahedra=tetrahedra)
    check_mesh(m, "ring")
    turns = 1 if quarter else 4
    assert volume(m) * 4 / turns == pytest.approx(math.pi * 3 * 0.5, rel=2e-2)
    for name, radius in (("inner", 1.0), ("outer", 2.0)):
        nodes = np.unique(m.facets[:, m.boundaries[name]])
        assert np.abs(np.hypot(m.p[0, nodes] - 0.5, m.p[1, nodes]) - radius).max() < 1e-12
        angles = np.unique(np.round(np.arctan2(m.p[1, nodes], m.p[0, nodes] - 0.5), 9))
        assert len(angles) == 8 * turns + (1 if quarter else 0)  # equally spaced, merged
    faces = 2 if tetrahedra else 1
    counts = {"inner": 8 * turns * 2 * faces, "outer": 8 * turns * 2 * faces,
              "bottom": 8 * turns * 3 * faces, "top": 8 * turns * 3 * faces}
    if quarter:
        counts.update(left=3 * 2 * faces, front=3 * 2 * faces)
    assert {k: len(v) for k, v in m.boundaries.items()} == counts
    assert len(m.boundary_facets()) == sum(counts.values())  # the whole ring closes up


def test_cylinder_rim_nodes_are_equally_spaced_in_angle():
    """With even spacing across, the rim's nodes lie at equal angles (2 n per quarter turn for
    n divisions across), so a ring of as many facets per turn has its nodes at the same
    angles (a shaft in a hub: similar polygons)."""
    m = cylinder(1.0, 0.5, h=1.0 / 12)
    side = np.unique(m.facets[:, m.boundaries["side"]])
    angles = np.unique(np.round(np.degrees(np.arctan2(m.p[1, side], m.p[0, side])), 9))
    assert np.allclose(angles, np.linspace(0.0, 90.0, 25), atol=1e-9)


def test_cylinder_with_a_grid_circle_under_a_punch_rim():
    """A block (a wide cylinder graded towards its top) with a grid circle at r = 1 whose nodes
    lie at the angles of the rim nodes of a punch of radius 1 with the same spacing."""
    blk = cylinder(8.0, 8.0, z0=-8.0, h_contact=0.125, h=2.0, growth=0.3, plateau=1.2,
                   circle_from=1 / 8, blend_from=0.5 / 8, graded_end="top", rings=(1.0,))
    check_mesh(blk, "block")
    top = np.unique(blk.facets[:, blk.boundaries["top"]])
    assert np.abs(blk.p[2, top]).max() == 0.0
    on = top[np.abs(np.hypot(*blk.p[:2, top]) - 1.0) < 1e-9]
    punch = cylinder(1.0, 1.0, h=0.125)
    end = np.unique(punch.facets[:, punch.boundaries["contact"]])
    rim = end[np.abs(np.hypot(*punch.p[:2, end]) - 1.0) < 1e-9]
    angles = [np.sort(np.arctan2(m.p[1, k], m.p[0, k])) for m, k in ((blk, on), (punch, rim))]
    assert len(angles[0]) == len(angles[1]) == 17
    assert np.allclose(*angles, atol=1e-12)
    z = np.unique(np.round(blk.p[2], 12))
    assert z[-1] - z[-2] < 0.13 and z[1] - z[0] > 0.25  # graded towards the top
    with pytest.raises(ValueError, match="blend_from must lie between 0 and 0.58 circle_from"):
        cylinder(8.0, 1.0, h=1.0, circle_from=0.125)


@pytest.mark.parametrize("kw", [
    dict(end_radius=10.0, h_contact=1.008 / 8, h=1.0, growth=0.3, plateau=1.2 * 1.008),
    dict(h_contact=0.2, h=1.0, graded_end="top", rings=(2.0,), grade_axis=False),
], ids=["spherical_end", "flat_end_rings"])
def test_cylinder_section_is_the_cylinders_plane_y0(kw):
    """Issue 42: the r-z section of the sphere example's cylinder (sphere_rz's sphere) is,
    node for node and element for element, the 3D quarter cylinder's face y = y0, r along x
    and the axis along y; its boundaries are the 3D ones cut by that plane."""
    x0, y0, z0 = 1.0, -2.0, 0.5
    m3 = cylinder(6.0, 5.0, x0=x0, y0=y0, z0=z0, **kw)
    m2 = cylinder_section(6.0, 5.0, x0=x0, y0=z0, **kw)
    check_mesh(m2, "cylinder_section")
    front = np.flatnonzero(np.abs(m3.p[1] - y0) < 1e-12)
    p3 = m3.p[np.ix_([0, 2], front)]
    assert p3.shape == m2.p.shape
    assert np.abs(p3[:, np.lexsort(p3)] - m2.p[:, np.lexsort(m2.p)]).max() < 1e-12
    # the 3D face's quadrilaterals are m2's elements: the same corners, by m2's numbering
    number = np.full(m3.p.shape[1], -1)
    number[front[np.lexsort(p3)]] = np.lexsort(m2.p)
    faces = number[m3.facets[:, m3.boundaries["front"]]]
    assert (faces >= 0).all()
    assert (set(map(tuple, np.sort(faces, axis=0).T))
            == set(map(tuple, np.sort(m2.t, axis=0).T)))
    assert set(m2.boundaries) == {"contact", "top", "side", "left"}
    for name in m2.boundaries:  # each named side: the 3D boundary's edges in the plane
        ends = m2.p[:, np.unique(m2.facets[:, m2.boundaries[name]])]
        cut = np.unique(m3.facets[:, m3.boundaries[name]])
        cut = m3.p[np.ix_([0, 2], cut[np.abs(m3.p[1, cut] - y0) < 1e-12])]
        assert np.abs(cut[:, np.lexsort(cut)] - ends[:, np.lexsort(ends)]).max() < 1e-12
    with pytest.raises(ValueError, match="end_radius > radius"):
        cylinder_section(6.0, 5.0, end_radius=5.0, h=1.0)
