"""3D contact surfaces (issue 21, C6 of the 3D plan): ``ContactSurface.build`` on a 3D body's
boundary with the ``Triangle`` and ``Quad`` facet kinds (contact/geometry/facets.py on
contact/geometry/facets3d.py): orientation and normals, sizes and tributary areas, the rind, closest
points, patch boundaries, and the flexibility on the candidate dofs from the factorization's
trailing inverse."""

import numpy as np
import pytest

from vfem import linalg
from vfem.bodies import Body, Support
from vfem.contact.geometry import closest3d, facets3d
from vfem.contact.geometry.facets import Quad, Segment, Triangle, kind_of
from vfem.contact.geometry.surface import ContactSurface, element_volumes, simplices
from vfem.materials import LinearElastic
from vfem.mesh.solids import FACES, box

SIZE = (1.0, 2.0, 1.5)  # width (x), depth (y), height (z)
CASES = [("tet", 1), ("tet", 2), ("hex", 1), ("hex", 2)]
OUTWARD = {name: (axis, 1.0 if end else -1.0) for name, (axis, end) in FACES.items()}
AREA = {"left": SIZE[1] * SIZE[2], "right": SIZE[1] * SIZE[2], "front": SIZE[0] * SIZE[2],
        "back": SIZE[0] * SIZE[2], "bottom": SIZE[0] * SIZE[1], "top": SIZE[0] * SIZE[1]}


def _body(cells, order, faces=tuple(FACES), n=(2, 3, 2)):
    mesh = box(0.0, 0.0, 0.0, *SIZE, nx=n[0], ny=n[1], nz=n[2], tetrahedra=cells == "tet")
    return Body("box", mesh, LinearElastic(200.0, 0.3), supports=(Support("bottom"),),
                order=order, contact_boundaries=tuple(faces))


def _surface(body, faces):
    ids = np.unique(np.concatenate([body.mesh.boundaries[f] for f in faces]))
    return ContactSurface.build(body, ids)


def _unit(axis, sign):
    e = np.zeros(3)
    e[axis] = sign
    return e


@pytest.mark.parametrize(("cells", "order"), CASES)
def test_kinds_and_node_order(cells, order):
    """The kind follows the elements; a quadratic facet's midside nodes are its edges' middles
    (the order of ``geometry.edges``) and a Q9's ninth node the centre."""
    s = _surface(_body(cells, order), FACES)
    kind = s.kind
    assert kind == (Triangle if cells == "tet" else Quad)(order)
    assert kind == kind_of(3, s.facets) and kind.dim == 3
    assert s.facets.shape[1] == kind.nodes == {1: 3, 2: 6}[order] + (cells == "hex") * (
        {1: 1, 2: 3}[order])
    X = s.X[s.facets]
    if order == 2:
        for a, b, m in kind.geometry.edges:
            np.testing.assert_allclose(X[:, m], 0.5 * (X[:, a] + X[:, b]), atol=1e-15)
        if cells == "hex":
            np.testing.assert_allclose(X[:, 8], X[:, :4].mean(axis=1), atol=1e-15)
    assert kind.readings.shape == (1 + kind.corners, 2)
    facets3d.check_facets(s.X, s.facets)  # no folded (bow-tie) quadrilateral


@pytest.mark.parametrize(("cells", "order"), CASES)
@pytest.mark.parametrize("face", list(FACES))
def test_every_face_outward_unit_normals_and_areas(cells, order, face):
    """On each face of a box alone: facet normals (chords and at the readings, through
    facets3d), node normals and the surface map's normal are unit and outward; the areas and the
    tributary areas sum to the face's area; T6 vertices carry no share of a pressure."""
    s = _surface(_body(cells, order, (face,)), (face,))
    e = _unit(*OUTWARD[face])
    nf = len(s.facets)
    np.testing.assert_allclose(s.facet_normals(), np.tile(e, (nf, 1)), atol=1e-14)
    np.testing.assert_allclose(s.node_normals(), np.tile(e, (s.nc, 1)), atol=1e-14)
    xi = np.tile(s.kind.readings, (nf, 1))
    seg = np.repeat(np.arange(nf), len(s.kind.readings))
    n = facets3d.facet_normals(s.X, s.facets, seg, xi)
    np.testing.assert_allclose(n, np.tile(e, (len(seg), 1)), atol=1e-14)
    _, jn = s.surface_map(seg, xi)
    np.testing.assert_allclose(jn / np.linalg.norm(jn, axis=1)[:, None],
                               np.tile(e, (len(seg), 1)), atol=1e-14)
    assert s.areas.sum() == pytest.approx(AREA[face], rel=1e-13)
    np.testing.assert_allclose(s.sizes, np.sqrt(s.areas), rtol=1e-15)
    assert s.tributary.sum() == pytest.approx(AREA[face], rel=1e-13)
    vertices = np.unique(s.facets[:, : s.kind.corners])
    if cells == "tet" and order == 2:
        np.testing.assert_allclose(s.tributary[vertices], 0.0, atol=1e-14)
    else:
        assert s.tributary[vertices].min() > 0
    # the rind: simplices of the elements behind the face, the depth the element's thickness
    assert s.rind.shape[1] == 4 and s.rind.min() >= 0 and s.rind.max() < len(s.nodes)
    h = np.array(SIZE) / np.array((2, 3, 2))
    axis = OUTWARD[face][0]
    depth = h[axis] / (3.0 if cells == "tet" else 1.0)  # a Kuhn tet's volume / its face
    np.testing.assert_allclose(s.rind_depth, depth, rtol=1e-13)


@pytest.mark.parametrize("cells", ["tet", "hex"])
def test_rind_simplices_fill_the_elements(cells):
    """The rind's tetrahedra (a hexahedron's six) fill its elements: volumes sum to theirs."""
    mesh = _body(cells, 1).mesh
    tets = simplices(mesh, mesh.t)
    P = mesh.p.T[tets]
    vol = np.abs(np.einsum("ij,ij->i", np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]),
                           P[:, 3] - P[:, 0])) / 6
    assert vol.min() > 0
    assert vol.sum() == pytest.approx(np.prod(SIZE), rel=1e-13)
    assert element_volumes(mesh, np.arange(mesh.t.shape[1])).sum() == pytest.approx(
        np.prod(SIZE), rel=1e-13)


@pytest.mark.parametrize(("cells", "order"), CASES)
def test_closest_points_are_facets3ds(cells, order):
    """Points through the whole box surface (inside, outside, beyond edges and corners): the
    surface's closest points equal facets3d's on the same facets, on all facets and on a
    subset; the facet numbers are the surface's."""
    s = _surface(_body(cells, order), FACES)
    rng = np.random.default_rng(3)
    points = rng.uniform(-0.4, 1.0, (300, 3)) * (np.array(SIZE) + 0.8)[None, :] * 0.9
    normals = rng.normal(size=(300, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    seg, xi, dist, n, xi_free = s.closest(points, point_normals=normals)
    ref = closest3d.closest_on_facets(points, s.X, s.facets, normals)
    np.testing.assert_array_equal(seg, ref.facet)
    np.testing.assert_array_equal(xi, ref.xi)
    np.testing.assert_array_equal(dist, ref.distance)
    np.testing.assert_array_equal(n, ref.normal)
    np.testing.assert_array_equal(xi_free, ref.xi_free)
    pos, _ = s.curve(seg, xi)
    np.testing.assert_allclose(np.linalg.norm(points - pos, axis=1), dist, atol=1e-14)
    # a subset: the top face's facets, numbered as the surface numbers them
    top = np.flatnonzero(np.isin(s.facet_ids, s.body.mesh.boundaries["top"]))
    seg, xi, dist, _, _ = s.closest(points, facets=top)
    ref = closest3d.closest_on_facets(points, s.X, s.facets[top])
    np.testing.assert_array_equal(seg, top[ref.facet])
    np.testing.assert_array_equal(xi, ref.xi)
    np.testing.assert_array_equal(dist, ref.distance)
    over = np.all((points[:, :2] > 0) & (points[:, :2] < np.array(SIZE[:2])), axis=1)
    np.testing.assert_allclose(dist[over], np.abs(points[over, 2] - SIZE[2]), atol=1e-14)


@pytest.mark.parametrize(("cells", "order"), CASES)
def test_patch_boundary_beyond_and_on_boundary(cells, order):
    """The top face as a patch of the whole surface: its boundary edges are the face's rim
    (the corners on them the rim's vertices); points over the face are not beyond it, points
    past its rim are, points over the rim are on its boundary."""
    s = _surface(_body(cells, order), FACES)
    top = np.flatnonzero(np.isin(s.facet_ids, s.body.mesh.boundaries["top"]))
    boundary = s.patch_boundary(top)
    assert boundary.shape == (len(s.facets), len(s.kind.geometry.edges))
    assert not boundary[np.setdiff1d(np.arange(len(s.facets)), top)].any()
    edges = s.kind.edge_nodes(s.facets)[boundary]  # (nb, 2) corner nodes
    Xe = s.X[edges]
    rim = lambda x: (np.isclose(x[..., 0], 0) | np.isclose(x[..., 0], SIZE[0])  # noqa: E731
                     | np.isclose(x[..., 1], 0) | np.isclose(x[..., 1], SIZE[1]))
    assert np.all(rim(Xe))
    # every rim edge of the top face once: their lengths sum to its perimeter
    assert np.linalg.norm(Xe[:, 1] - Xe[:, 0], axis=1).sum() == pytest.approx(
        2 * (SIZE[0] + SIZE[1]), rel=1e-13)
    nodes = s.boundary_nodes(boundary)
    corners = np.unique(s.facets[top][:, : s.kind.corners])
    on_rim = corners[rim(s.X[corners]) & np.isclose(s.X[corners, 2], SIZE[2])]
    np.testing.assert_array_equal(np.flatnonzero(nodes), np.sort(on_rim))
    inside = np.array([[0.3, 0.7, 1.8], [0.9, 1.9, 1.6], [0.5, 1.0, 1.2]])
    past = np.array([[1.2, 0.7, 1.7], [0.3, -0.2, 1.6], [-0.1, 2.3, 1.9]])
    over_rim = np.array([[1.0, 0.7, 1.7], [0.3, 0.0, 1.9]])
    for pts, beyond, on in ((inside, False, False), (past, True, True),
                            (over_rim, False, True)):
        seg, _, _, _, tf = s.closest(pts, facets=top)
        assert np.all(s.beyond(seg, tf, boundary) == beyond)
        assert np.all(s.on_boundary(seg, tf, boundary) == on)
    # strictly inside: the plane projection off every edge of its facet
    kind = s.kind
    c = np.asarray(kind.geometry.centre)
    assert kind.strictly_inside(c[None, :])[0]
    assert not kind.strictly_inside(np.array([[0.0, 0.3], [c[0], -0.1], [0.5, 1e-12]])).any()


def test_orientation_turns_inward_facets_over():
    """Facets given inward are turned over with their midside nodes (T6, Q9) kept on their
    edges: after ``orient`` the normal of the surface map is outward everywhere."""
    for cells, kind in (("tet", Triangle(2)), ("hex", Quad(2))):
        body = _body(cells, 2)
        mesh = body.mesh
        ids = mesh.boundaries["top"]
        fn = body.facet_points(ids)
        inward = fn[:, list(kind._REVERSED[kind.nodes])].copy()  # every facet turned inward
        centroid = mesh.p[:, mesh.t[:, mesh.f2t[0, ids]]].mean(axis=1).T
        for given in (fn.copy(), inward):
            kind.orient(mesh.p, given, centroid)
            x = body.points.T
            xi = np.tile(kind.readings, (len(given), 1))
            _, jn = kind.surface_map(x, np.repeat(given, len(kind.readings), axis=0), xi)
            assert np.all(jn[:, 2] > 0) and np.allclose(jn[:, :2], 0, atol=1e-14)
            X = x[given]
            for a, b, m in kind.geometry.edges:
                np.testing.assert_allclose(X[:, m], 0.5 * (X[:, a] + X[:, b]), atol=1e-15)


def test_kind_of_and_refusals():
    assert kind_of(2, np.zeros((0, 2))) == Segment(1)
    assert kind_of(2, np.zeros((0, 3))) == Segment(2)
    assert kind_of(3, np.zeros((0, 3))) == Triangle(1)
    assert kind_of(3, np.zeros((0, 9))) == Quad(2)
    assert Triangle(1) != Quad(1) and hash(Triangle(2)) == hash(Triangle(2))
    with pytest.raises(ValueError, match="no facet kind of 5 nodes in 3D"):
        kind_of(3, np.zeros((0, 5)))
    with pytest.raises(ValueError, match="facets are of order 1 or 2"):
        Quad(3)


BACKENDS = ["superlu"] + [b for b in ("pardiso",) if b in linalg.available()]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize(("cells", "order"), CASES)
def test_flexibility_is_the_inverse_stiffness_block(cells, order, backend):
    """A box held on its bottom, its top face the contact surface: the flexibility from the
    factorization's trailing inverse (``condensed_dofs`` = the top face's dofs) equals the
    columns of K^-1 by back-substitution to 1e-10; the surface takes it as ``C``, and the
    Castigliano normal stiffness 1/(n^T C n) is positive and finite."""
    body = _body(cells, order, ("top",), n=(2, 2, 2))
    s = _surface(body, ("top",))
    s.rind_rows = False
    dofs = s.condensed_dofs
    assert len(dofs) == 3 * s.nc
    body.setup(backend, condensed_dofs=dofs)
    G = body.condensed_flexibility
    ref = body.flexibility_columns(dofs)[dofs]
    scale = np.abs(ref).max()
    np.testing.assert_allclose(G, ref, rtol=0, atol=1e-10 * scale)
    s.compute_flexibility()
    assert s.exactly_symmetric and s.C.shape == (3 * s.nc, 3 * s.nc)
    np.testing.assert_allclose(s.C, ref, rtol=0, atol=1e-10 * scale)
    nodes = np.arange(s.nc)
    normals = s.node_normals()
    k = s.normal_stiffness(nodes, normals)
    assert np.all(np.isfinite(k)) and np.all(k > 0)
    direct = np.array([1.0 / (nv @ ref[3 * j:3 * j + 3, 3 * j:3 * j + 3] @ nv)
                       for j, nv in zip(nodes, normals)])
    np.testing.assert_allclose(k, direct, rtol=1e-12)
    # the normal flexibility among the nodes: symmetric, its diagonal 1/k
    F = s.normal_flexibility(nodes, normals)
    np.testing.assert_allclose(np.diag(F), 1.0 / k, rtol=1e-12)
    np.testing.assert_allclose(F, F.T, rtol=0, atol=1e-12 * np.abs(F).max())


@pytest.mark.parametrize("cells", ["tet", "hex"])
def test_normals_at_do_not_average_across_the_bodys_edges(cells):
    """``normals_at`` (the virtual node's normal, issue 37): at every point of a top facet,
    the top's normal, also at the nodes on the box's edges, where the nodal normals (the mean
    of all the facets around a node) lean 45 degrees towards the side; on the side's facets
    their own normal. A cylinder's face over a block's edge read its gaps along the leaning
    one and lay 50 % of the push inside the block (random model 3d-54)."""
    body = _body(cells, 1, ("top", "right", "front"))
    s = _surface(body, ("top", "right", "front"))
    centres = s.X[s.facets[:, :s.kind.corners]].mean(axis=1)
    for face in ("top", "right", "front"):
        axis, sign = OUTWARD[face]
        e = _unit(axis, sign)
        on = np.flatnonzero(np.isclose(centres[:, axis], SIZE[axis] if sign > 0 else 0.0))
        for xi in s.kind.readings:  # (the corners among them for linear facets)
            seg = on
            t = np.tile(xi, (len(seg), 1))
            np.testing.assert_allclose(s.normals_at(seg, t), np.tile(e, (len(seg), 1)),
                                       atol=1e-14)
        corners = np.unique(s.facets[on, :s.kind.corners])
        edge = corners[np.isclose(s.X[corners, 0], SIZE[0])
                       & np.isclose(s.X[corners, 2], SIZE[2])]
        assert len(edge) and np.all(np.abs(s.node_normals()[edge] @ e) < 0.99)


@pytest.mark.parametrize(("cells", "order"), CASES)
def test_feature_nodes_are_the_boxs_edges(cells, order):
    """``feature_nodes`` (issue 37): the nodes on the box's edges where two of the given faces
    meet (at 90 degrees), and no other: not the faces' inner nodes, not a quadratic facet's
    midside or centre nodes off the edges; with one face alone, none."""
    body = _body(cells, order, ("top", "right", "front"))
    s = _surface(body, ("top", "right", "front"))
    x = s.X[: s.nc]
    on_top, on_right, on_front = (np.isclose(x[:, 2], SIZE[2]), np.isclose(x[:, 0], SIZE[0]),
                                  np.isclose(x[:, 1], 0.0))
    edges = (on_top & on_right) | (on_top & on_front) | (on_right & on_front)
    np.testing.assert_array_equal(s.feature_nodes(), edges)
    top = np.flatnonzero(np.isin(s.facet_ids, body.mesh.boundaries["top"]))
    assert not s.feature_nodes(top).any()


@pytest.mark.parametrize("order", [1, 2])
def test_feature_nodes_in_2d_are_the_corners(order):
    """The same in 2D: a block's top and side meet at its corner; a faceted arc's nodes turn
    by less than 60 degrees and are no feature."""
    from skfem import MeshTri

    mesh = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 4)).with_boundaries(
        {"top": lambda p: p[1] > 1 - 1e-9, "left": lambda p: p[0] < 1e-9})
    body = Body("block", mesh, LinearElastic(200.0, 0.3), supports=(Support("top"),),
                order=order)
    ids = np.concatenate([mesh.boundaries["top"], mesh.boundaries["left"]])
    s = ContactSurface.build(body, ids)
    corner = np.isclose(s.X[: s.nc, 0], 0.0) & np.isclose(s.X[: s.nc, 1], 1.0)
    assert corner.sum() == 1
    np.testing.assert_array_equal(s.feature_nodes(), corner)
