"""3D meshes (issue 21, C2): the mesh checks on tetrahedra and hexahedra, the facet topology of
3- and 4-node facets (the same arrays as scikit-fem's), and the box of vfem.mesh.solids."""

from dataclasses import replace

import numpy as np
import pytest
from skfem import (
    Basis,
    ElementHex1,
    ElementTetP1,
    MeshHex,
    MeshHex2,
    MeshTet,
    MeshTet2,
)

from vfem.errors import InputError
from vfem.mesh.checks import check_mesh
from vfem.mesh.solids import FACES, box
from vfem.mesh.topology import CACHED, facet_topology, with_topology


def _fresh(mesh):
    """The same mesh without its facet topology (scikit-fem builds its own)."""
    return type(mesh)(mesh.doflocs, mesh.t)


def _meshes():
    rng = np.random.default_rng(3)
    lines = [np.linspace(0, 1, 4), np.array([0.0, 0.3, 1.1, 1.5]), np.linspace(-1, 0, 3)]
    tet, hex_ = MeshTet.init_tensor(*lines), MeshHex.init_tensor(*lines)
    shuffled = []
    for m in (tet, hex_):  # elements in random order, each element's nodes rotated
        cols = rng.permutation(m.t.shape[1])
        shuffled.append(type(m)(m.p, m.t[:, cols]))
    # scikit-fem's own tetrahedra with nodes in any order (mixed orientation)
    t = tet.t.copy()
    for e in range(t.shape[1]):
        t[:, e] = t[rng.permutation(4), e]
    return {"tet": tet, "hex": hex_, "tet2": MeshTet2.from_mesh(tet),
            "hex2": MeshHex2.from_mesh(hex_), "tet-shuffled": shuffled[0],
            "hex-shuffled": shuffled[1], "tet-unsorted": MeshTet(tet.p, t),
            "tet-refined": tet.refined(1), "box-tet": box(nx=3, ny=2, nz=2, tetrahedra=True),
            "box-hex": box(nx=3, ny=2, nz=2)}


@pytest.mark.parametrize("name", list(_meshes()))
def test_facet_topology_of_3d_meshes_is_scikit_fems(name):
    """facets, t2f and f2t from facet_topology (and with_topology) equal scikit-fem's own,
    values, order and types: sorted triangles of tetrahedra, hexahedra's quadrilaterals in
    the cyclic order of their first element."""
    mesh = _meshes()[name]
    fresh = _fresh(mesh)
    theirs = (fresh.facets, fresh.t2f, fresh.f2t)
    sort = not isinstance(mesh, MeshHex)
    ours = facet_topology(mesh.t, mesh.elem.refdom.facets, sort)
    built = with_topology(_fresh(mesh))
    assert all(hasattr(built, name) for name in CACHED)
    for a, b, c in zip(ours, theirs, (built.facets, built.t2f, built.f2t)):
        assert a.dtype == b.dtype == c.dtype
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(c, b)
    if isinstance(mesh, MeshHex):  # and f2e (edges of the facets), built from them
        np.testing.assert_array_equal(built.f2e, fresh.f2e)


def _set_node(mesh, k, xyz):
    p = mesh.p.copy()
    p[:, k] = xyz
    return type(mesh)(p, mesh.t)


def _centre_node(mesh):
    return int(np.argmin(np.linalg.norm(mesh.p - np.array([[0.5], [0.5], [0.5]]), axis=0)))


@pytest.mark.parametrize("tetrahedra", [False, True])
def test_box_meshes_pass_the_checks(tetrahedra):
    check_mesh(box(nx=3, ny=2, nz=4, tetrahedra=tetrahedra), "body 'box'")
    check_mesh(box(h=0.3, h_fine=0.05, fine_z=[1.0], fine_x=[0.5], tetrahedra=tetrahedra),
               "body 'box'")
    check_mesh(MeshTet2.from_mesh(box(nx=2, ny=2, nz=2, tetrahedra=True)), "body 'box'")
    check_mesh(MeshHex2.from_mesh(box(nx=2, ny=2, nz=2)), "body 'box'")


def test_a_hexahedron_twisted_inside_out_is_inverted():
    """The centre node of a 2 x 2 x 2 box moved up past the top face: the upper hexahedra's
    Jacobian changes sign inside them."""
    mesh = box(nx=2, ny=2, nz=2)
    bad = _set_node(mesh, _centre_node(mesh), [0.5, 0.5, 1.4])
    with pytest.raises(InputError, match=r"body 'cube': \d+ element\(s\) are inverted: the "
                                         r"Jacobian changes sign inside them \(the first: "
                                         r"element \d+, corners at \[\(.*, .*, .*\)"):
        check_mesh(bad, "body 'cube'")


def test_a_curved_hexahedron_bowed_inside_out_is_inverted():
    """A quadratic hexahedron's face centre pulled through the element: its Jacobian changes
    sign inside (only a finer lattice than the corners sees it)."""
    mesh = MeshHex2.from_mesh(MeshHex.init_tensor(*[np.linspace(0, 1, 2)] * 3))
    p = mesh.doflocs.copy()
    face = int(np.argmin(np.linalg.norm(p - np.array([[0.5], [0.5], [1.0]]), axis=0)))
    p[2, face] = -0.6
    with pytest.raises(InputError, match="are inverted"):
        check_mesh(MeshHex2(p, mesh.t), "body 'c'")


@pytest.mark.parametrize("tetrahedra", [False, True])
def test_an_element_folded_over_its_neighbour_is_refused(tetrahedra):
    """A node moved past its neighbours' opposite faces: a tetrahedron turns inside out as a
    whole (its own Jacobian keeps one sign), its neighbours then lie on the same side of the
    face they share."""
    mesh = box(nx=2, ny=2, nz=2, tetrahedra=tetrahedra)
    if tetrahedra:
        bad = _set_node(mesh, _centre_node(mesh), [0.5, 0.5, 1.4])
    else:  # the far x face of a 2 x 1 x 1 row moved back inside the first hexahedron
        mesh = box(width=2.0, nx=2, ny=1, nz=1)
        p = mesh.p.copy()
        p[0, p[0] > 1.5] = 0.5
        bad = type(mesh)(p, mesh.t)
    with pytest.raises(InputError, match=r"body 'b': \d+ pair\(s\) of neighbouring elements "
                                         r"overlap: an inverted \(folded\) element \(the "
                                         r"first: elements \d+ and \d+ lie on the same side "
                                         r"of their shared face with corners at \[\("):
        check_mesh(bad, "body 'b'")


def test_a_flat_tetrahedron_has_zero_volume():
    p = np.array([[0.0, 1.0, 0.0, 0.0, 0.5], [0.0, 0.0, 1.0, 0.0, 0.5],
                  [0.0, 0.0, 0.0, 1.0, 0.0]])
    mesh = MeshTet(p, np.array([[0, 1, 2, 3], [0, 1, 2, 4]]).T)  # the second one flat
    with pytest.raises(InputError, match=r"body 'b': 1 element\(s\) have zero volume \(the "
                                         r"first: element 1, corners at .*lie in a plane"):
        check_mesh(mesh, "body 'b'")


def test_duplicate_nodes_and_separate_pieces_in_3d():
    a = box(nx=1, ny=1, nz=1)
    b = box(x0=1.0, nx=1, ny=1, nz=1)  # touches a at x = 1 without sharing its nodes
    p = np.hstack([a.p, b.p])
    glued = MeshHex(p, np.hstack([a.t, b.t + a.p.shape[1]]))
    with pytest.raises(InputError, match=r"body 'b': 4 pair\(s\) of nodes at the same position "
                                         r"\(the first: nodes \d+ and \d+, at \(1, .*, .*\)\)"):
        check_mesh(glued, "body 'b'")
    far = box(x0=3.0, nx=1, ny=1, nz=1)
    apart = MeshHex(np.hstack([a.p, far.p]), np.hstack([a.t, far.t + a.p.shape[1]]))
    with pytest.raises(InputError, match="body 'b': the mesh is 2 separate pieces"):
        check_mesh(apart, "body 'b'")


def test_non_finite_3d_coordinates_are_named():
    mesh = box(nx=1, ny=1, nz=1)
    bad = _set_node(mesh, 3, [0.0, np.nan, 1.0])
    with pytest.raises(InputError, match=r"node 3 has coordinates that are not finite numbers "
                                         r"\(\(0, nan, 1\)\)"):
        check_mesh(bad, "body 'b'")


def _facet_areas(mesh, facets):
    x = mesh.p[:, mesh.facets[:, facets]]  # (3, k, nf)
    if x.shape[1] == 3:
        n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], axis=0)
    else:
        n = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1], axis=0)
    return 0.5 * np.linalg.norm(n, axis=0)


@pytest.mark.parametrize("tetrahedra", [False, True])
@pytest.mark.parametrize("graded", [False, True])
def test_box_faces_and_facets(tetrahedra, graded):
    """box(): the named faces' facets lie on their planes and their areas sum to the face's
    area; they are exactly the boundary facets; every other facet has two elements; the
    element volumes sum to the box's; graded boxes have the fine spacing at their planes."""
    x0, y0, z0, W, D, H = -1.0, 0.5, 2.0, 2.0, 1.0, 1.5
    kw = (dict(h=0.4, h_fine=0.05, growth=0.5, fine_x=[0.0], fine_z=[z0 + H]) if graded
          else dict(nx=3, ny=2, nz=4))
    mesh = box(x0, y0, z0, W, D, H, tetrahedra=tetrahedra, **kw)
    assert isinstance(mesh, MeshTet if tetrahedra else MeshHex)
    assert set(mesh.boundaries) == set(FACES) == {"left", "right", "front", "back", "bottom",
                                                  "top"}
    lo, hi = np.array([x0, y0, z0]), np.array([x0 + W, y0 + D, z0 + H])
    for name, (axis, end) in FACES.items():
        facets = mesh.boundaries[name]
        mid = mesh.p[:, mesh.facets[:, facets]].mean(axis=1)
        np.testing.assert_allclose(mid[axis], (lo, hi)[end][axis], atol=1e-14)
        others = [a for a in range(3) if a != axis]
        area = np.prod((hi - lo)[others])
        assert _facet_areas(mesh, facets).sum() == pytest.approx(area, rel=1e-13)
    named = np.sort(np.concatenate(list(mesh.boundaries.values())))
    np.testing.assert_array_equal(named, mesh.boundary_facets())
    interior = np.setdiff1d(np.arange(mesh.facets.shape[1]), named)
    assert (mesh.f2t[1, interior] >= 0).all() and (mesh.f2t[1, named] == -1).all()
    # each facet is listed by exactly its elements: two for interior facets, one outside
    counts = np.bincount(mesh.t2f.ravel(), minlength=mesh.facets.shape[1])
    assert (counts[interior] == 2).all() and (counts[named] == 1).all()
    basis = Basis(mesh, ElementTetP1() if tetrahedra else ElementHex1())
    assert basis.dx.sum() == pytest.approx(W * D * H, rel=1e-14)
    if graded:
        x = np.unique(mesh.p[0])
        assert np.any(np.isclose(x, 0.0, atol=1e-14))  # the fine plane is a grid plane
        assert 0.05 - 1e-12 <= np.diff(x).min() <= 0.1  # h_fine there (the first interval
        # is the size function's average over it)
        assert np.diff(x).max() <= 0.4 + 1e-12
        z = np.unique(mesh.p[2])
        assert 0.05 - 1e-12 <= z[-1] - z[-2] <= 0.1
        assert np.diff(np.unique(mesh.p[1])).max() <= 0.4 + 1e-12  # y: uniform, <= h
    check_mesh(mesh, "body 'box'")


def test_box_parameters_are_checked():
    with pytest.raises(ValueError, match="width, depth and height must be positive"):
        box(width=0.0)
    with pytest.raises(ValueError, match="nx, ny and nz must be whole numbers"):
        box(nx=0)
    with pytest.raises(ValueError, match="more than the"):
        box(nx=1000, ny=1000, nz=1000)
    with pytest.raises(ValueError, match="more than the"):
        box(h=1e-9)


def test_box_keeps_its_topology_through_copies():
    """The topology is built once: a copy made by replace() with the boundaries shares it."""
    mesh = box(nx=2, ny=2, nz=2)
    assert all(hasattr(mesh, name) for name in CACHED)
    copy = replace(mesh)
    assert copy.facets.shape == mesh.facets.shape
