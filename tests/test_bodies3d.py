"""3D bodies (issue 21, C1): tetrahedra and hexahedra, linear and quadratic, linear elasticity
under small kinematics; supports, tractions, reactions, stresses and VTK cells in 3D, and clear
errors for what 3D does not take."""

import meshio
import numpy as np
import pytest
from skfem import Basis, ElementHex1, ElementVector, MeshHex, MeshHex2, MeshTet2

from vfem.bodies import Body, PrescribedDisplacement, Support, Traction
from vfem.bodies.stresses import _largest_eigenvalue, _with_von_mises, max_strain, stress
from vfem.errors import InputError
from vfem.materials import LinearElastic
from vfem.mesh.shapes import rectangle
from vfem.mesh.solids import box
from vfem.mesh.topology import share_topology

E, NU, SIGMA = 200.0, 0.3, -2.0  # SIGMA: sigma_zz, negative: the top pressed down
SIZE = (1.0, 2.0, 1.5)  # width (x), depth (y), height (z)
ROLLERS = (Support("left", ("x",)), Support("front", ("y",)), Support("bottom", ("z",)))
CASES = [("tet", 1), ("tet", 2), ("hex", 1), ("hex", 2)]


def distorted(mesh, amount=0.15, seed=0):
    """``mesh`` with its interior nodes moved at random (up to ``amount`` of a cell): the
    elements are no longer affine, the fields of a uniform state are still linear."""
    rng = np.random.default_rng(seed)
    p = mesh.p.copy()
    lo, hi = p.min(axis=1, keepdims=True), p.max(axis=1, keepdims=True)
    inside = np.all((p > lo + 1e-9) & (p < hi - 1e-9), axis=0)
    p[:, inside] += amount * 0.5 * rng.uniform(-1, 1, (3, int(inside.sum())))
    moved = type(mesh)(p, mesh.t, _boundaries=dict(mesh.boundaries))
    return share_topology(mesh, moved)


def uniform_box(cells, order, distort=False, **kw):
    mesh = box(0.0, 0.0, 0.0, *SIZE, nx=2, ny=3, nz=2, tetrahedra=cells == "tet")
    if distort:
        mesh = distorted(mesh)
    body = Body("box", mesh, LinearElastic(E, NU), supports=kw.pop("supports", ROLLERS),
                tractions=(Traction("top", (0.0, 0.0, SIGMA)),), order=order, **kw)
    body.setup()
    return body


@pytest.mark.parametrize("distort", [False, True])
@pytest.mark.parametrize(("cells", "order"), CASES)
def test_uniform_pressure_gives_the_exact_uniform_state(cells, order, distort):
    """A box on rollers (x on the left, y on the front, z on the bottom face) under a uniform
    sigma_zz on its top: u_z = sigma z / E, u_x = -nu sigma x / E, u_y = -nu sigma y / E,
    sigma_zz = sigma and every other stress zero, to round-off, whatever the elements' shape."""
    body = uniform_box(cells, order, distort)
    assert body.dim == 3 and body.components == ("x", "y", "z")
    u = body.u_load.reshape(-1, 3)
    x, y, z = body.points
    scale = abs(SIGMA) / E * max(SIZE)
    np.testing.assert_allclose(u[:, 2], SIGMA * z / E, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(u[:, 0], -NU * SIGMA * x / E, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(u[:, 1], -NU * SIGMA * y / E, rtol=0, atol=1e-10 * scale)
    s = stress(body, body.u_load)
    assert set(s) == {"sxx", "syy", "szz", "syz", "sxz", "sxy", "von_mises"}
    np.testing.assert_allclose(s["szz"], SIGMA, rtol=1e-10)
    for k in ("sxx", "syy", "syz", "sxz", "sxy"):
        np.testing.assert_allclose(s[k], 0.0, atol=1e-10 * abs(SIGMA))
    np.testing.assert_allclose(s["von_mises"], abs(SIGMA), rtol=1e-10)
    strain, _ = max_strain(body, body.u_load)
    assert strain == pytest.approx(abs(SIGMA) / E, rel=1e-10)
    # the supports carry the load: the bottom's z reaction is the top's force, reversed
    r = body.nodal_reaction(body.u_load)
    area = SIZE[0] * SIZE[1]
    reactions = body.boundary_reactions(r)
    assert len(reactions["bottom"]) == 3
    assert reactions["bottom"][2] == pytest.approx(-SIGMA * area, rel=1e-10)
    assert abs(reactions["left"][0]) < 1e-10 * abs(SIGMA) * area
    np.testing.assert_allclose(body.applied_load(1.0).reshape(-1, 3).sum(axis=0),
                               [0.0, 0.0, SIGMA * area], atol=1e-12)


@pytest.mark.parametrize(("cells", "order"), CASES)
def test_points_are_scikit_fems_dof_locations(cells, order):
    """Point k is where scikit-fem puts the dofs 3k, 3k + 1, 3k + 2: vertices, edge middles,
    (hexahedra) facet and element centres, in its dof order; also on curved (quadratic)
    meshes, whose own nodes are the points."""
    body = uniform_box(cells, order)
    np.testing.assert_allclose(body.basis.doflocs[:, 0::3], body.points, rtol=0, atol=1e-15)
    np.testing.assert_allclose(body.basis.doflocs[:, 2::3], body.points, rtol=0, atol=1e-15)
    if order == 2:
        curved_mesh = (MeshTet2 if cells == "tet" else MeshHex2).from_mesh(body.mesh)
        curved = Body("curved", curved_mesh, LinearElastic(E, NU), order=2)
        basis = Basis(curved_mesh, ElementVector(curved.element()))
        np.testing.assert_allclose(basis.doflocs[:, 0::3], curved.points, atol=1e-15)


@pytest.mark.parametrize(("cells", "order"), CASES)
def test_facet_points_are_the_facets_nodes(cells, order):
    """facet_points: the facet's vertices, then (order 2) the middles of its edges 0-1, 1-2,
    then 0-2 (triangle) or 2-3, 0-3 (quadrilateral), then a quadrilateral's centre; together
    the dofs scikit-fem puts on those facets."""
    body = uniform_box(cells, order)
    facets = body.mesh.boundaries["top"]
    fp = body.facet_points(facets)
    X = body.points[:, fp]  # (3, nf, k)
    nv = 3 if cells == "tet" else 4
    assert fp.shape == (len(facets), {("tet", 1): 3, ("tet", 2): 6, ("hex", 1): 4,
                                      ("hex", 2): 9}[(cells, order)])
    np.testing.assert_array_equal(fp[:, :nv], body.mesh.facets[:, facets].T)
    if order == 2:
        edges = [(0, 1), (1, 2), (0, 2)] if nv == 3 else [(0, 1), (1, 2), (2, 3), (0, 3)]
        for k, (a, b) in enumerate(edges):
            np.testing.assert_allclose(X[:, :, nv + k], 0.5 * (X[:, :, a] + X[:, :, b]),
                                       atol=1e-15)
        if nv == 4:
            np.testing.assert_allclose(X[:, :, -1], X[:, :, :4].mean(axis=2), atol=1e-15)
    dofs = body.basis.get_dofs(facets).all("u^3")
    np.testing.assert_array_equal(np.unique(fp), np.sort(dofs) // 3)
    np.testing.assert_array_equal(body.boundary_points("top"), np.unique(fp))


#: VTK's reference coordinates of a hexahedron's (and hexahedron27's) nodes
_VTK_HEX = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                     [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
_VTK_HEX_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
                  (0, 4), (1, 5), (2, 6), (3, 7)]
_VTK_HEX_FACES = [(0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 2, 6, 7), (0, 3, 2, 1),
                  (4, 5, 6, 7)]
_VTK_TET_EDGES = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]


def _vtk_volumes(kind, x):
    """Volumes of VTK cells (x: (ncells, nodes, 3)) in VTK's node order: a tetrahedron's
    (x1 - x0) x (x2 - x0) . (x3 - x0) / 6; a hexahedron's trilinear map on its 8 corners,
    integrated by 2 x 2 x 2 Gauss points."""
    if kind.startswith("tetra"):
        a, b, c = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
        return np.einsum("ei,ei->e", np.cross(a, b), c) / 6
    g = 0.5 + np.array([-1, 1]) / (2 * np.sqrt(3))
    vol = 0.0
    for xi in g:
        for eta in g:
            for zeta in g:
                r = np.array([xi, eta, zeta])
                # d/d(r_j) of the trilinear shape functions at r
                dN = np.empty((8, 3))
                for k, v in enumerate(_VTK_HEX):
                    f = np.where(v == 1, r, 1 - r)
                    for j in range(3):
                        d = 1.0 if v[j] == 1 else -1.0
                        dN[k, j] = d * np.prod(np.delete(f, j))
                J = np.einsum("eki,kj->eij", x[:, :8], dN)
                vol = vol + np.linalg.det(J) / 8
    return vol


def _mirrored(mesh):
    """``mesh`` with every other element's nodes listed as its mirror image (a tetrahedron's
    nodes 1 and 2 swapped; a hexahedron's by scikit-fem's reference x -> 1 - x): the same
    geometry, the element orientation reversed."""
    t = mesh.t.copy()
    mirror = [0, 2, 1, 3] if t.shape[0] == 4 else [3, 5, 6, 0, 7, 1, 2, 4]
    t[:, ::2] = t[mirror][:, ::2]
    return type(mesh)(mesh.p, t, _boundaries=None)


@pytest.mark.parametrize("mirror", [False, True])
@pytest.mark.parametrize(("cells", "order"), CASES)
def test_cells_are_vtk_cells_with_positive_volumes(cells, order, mirror, tmp_path):
    """Body.cells(): VTK's cell type and node order (a quadratic cell's edge, face and centre
    nodes where VTK puts them), every cell's volume positive as VTK computes it, also where
    the elements are mirrored (scikit-fem's own hexahedra are; tetrahedra come both ways);
    written and read back by meshio unchanged, the volumes summing to the box's."""
    mesh = box(0.0, 0.0, 0.0, *SIZE, nx=2, ny=2, nz=2, tetrahedra=cells == "tet")
    if mirror:
        mesh = _mirrored(mesh if cells == "tet" else
                         MeshHex.init_tensor(*[np.linspace(0, s, 3) for s in SIZE]))
    body = Body("box", mesh, LinearElastic(E, NU), supports=(), order=order)
    body.basis = Basis(mesh, ElementVector(body.element()))
    kind, conn = body.cells()
    assert kind == {("tet", 1): "tetra", ("tet", 2): "tetra10", ("hex", 1): "hexahedron",
                    ("hex", 2): "hexahedron27"}[(cells, order)]
    path = tmp_path / "cells.vtu"
    meshio.write(path, meshio.Mesh(body.points.T, [(kind, conn)]))
    back = meshio.read(path)
    np.testing.assert_array_equal(back.cells_dict[kind], conn)
    x = back.points[back.cells_dict[kind]]  # (ncells, nodes, 3)
    volumes = _vtk_volumes(kind, x)
    assert volumes.min() > 0
    assert volumes.sum() == pytest.approx(np.prod(SIZE), rel=1e-12)
    if kind == "tetra10":
        for k, (a, b) in enumerate(_VTK_TET_EDGES):
            np.testing.assert_allclose(x[:, 4 + k], 0.5 * (x[:, a] + x[:, b]), atol=1e-14)
    if kind == "hexahedron27":
        for k, (a, b) in enumerate(_VTK_HEX_EDGES):
            np.testing.assert_allclose(x[:, 8 + k], 0.5 * (x[:, a] + x[:, b]), atol=1e-14)
        for k, face in enumerate(_VTK_HEX_FACES):
            np.testing.assert_allclose(x[:, 20 + k], x[:, list(face)].mean(axis=1),
                                       atol=1e-14)
        np.testing.assert_allclose(x[:, 26], x[:, :8].mean(axis=1), atol=1e-14)


def test_mirrored_hexahedra_give_the_same_answer():
    """Element orientation does not matter to the analysis (scikit-fem integrates |det J|)."""
    mesh = box(0.0, 0.0, 0.0, *SIZE, nx=2, ny=2, nz=2)
    flipped = _mirrored(mesh)
    flipped = type(flipped)(flipped.p, flipped.t, _boundaries=dict(mesh.boundaries))
    answers = []
    for m in (mesh, flipped):
        body = Body("box", m, LinearElastic(E, NU), supports=ROLLERS,
                    tractions=(Traction("top", (0.0, 0.0, SIGMA)),))
        body.setup()
        answers.append(body.u_load)
    np.testing.assert_allclose(answers[0], answers[1], atol=1e-14)


@pytest.mark.parametrize(("supports", "free"), [
    ((), "translation in x; translation in y; translation in z; rotation about x; "
         "rotation about y; rotation about z"),
    ((Support("bottom", ("z",)),), "translation in x; translation in y; rotation about z"),
    ((Support("bottom", ("z",)), Support("left", ("x",))), "translation in y"),
    ((Support("left", ("x",)), Support("front", ("y",))), r"translation in z\)"),
])
def test_unsupported_3d_body_names_its_free_motions(supports, free):
    body = Body("cube", box(nx=2, ny=2, nz=2), LinearElastic(E, NU), supports=supports)
    with pytest.raises(InputError, match=r"body 'cube' is not supported: it can move freely "
                                         r"as a rigid body \(" + free):
        body.setup()
    with pytest.raises(InputError, match="body 'cube' is not supported"):
        body.check_supports()


def test_rollers_on_three_faces_hold_a_3d_body():
    """Three single-component rollers fix all six rigid motions; so does the default support
    (every component of the body: x, y and z in 3D)."""
    Body("cube", box(nx=2, ny=2, nz=2), LinearElastic(E, NU), supports=ROLLERS).check_supports()
    body = Body("cube", box(nx=2, ny=2, nz=2), LinearElastic(E, NU),
                supports=(Support("bottom"),), tractions=(Traction("top", (1.0, 0.0, 0.0)),))
    body.setup()
    assert body.support_components(body.supports[0]) == ("x", "y", "z")
    bottom = body.basis.get_dofs(body.mesh.boundaries["bottom"]).all()
    assert set(bottom.tolist()) <= set(body.fixed_dofs.tolist())
    assert len(body.fixed_dofs) == 3 * len(body.boundary_points("bottom"))
    np.testing.assert_array_equal(body.u_load[bottom], 0.0)
    # the shear load's x reaction on the clamped bottom
    assert body.boundary_reactions(body.nodal_reaction(body.u_load))["bottom"][0] == \
        pytest.approx(-1.0, rel=1e-10)


def test_the_2d_default_support_is_unchanged():
    s = Support("left")
    assert s.components == ("x", "y") and list(s.components) == ["x", "y"]
    body = Body("plate", rectangle(nx=2, ny=2), LinearElastic(E, NU), supports=(s,))
    assert body.dim == 2 and body.support_components(s) == ("x", "y")


def test_prescribed_z_displacement_on_a_3d_body():
    body = Body("cube", box(nx=2, ny=2, nz=2), LinearElastic(E, NU),
                supports=ROLLERS, prescribed=(PrescribedDisplacement("top", "z", -0.01),))
    body.setup()
    u = body.u_load.reshape(-1, 3)
    np.testing.assert_allclose(u[:, 2], -0.01 * body.points[2], atol=1e-14)
    s = stress(body, body.u_load)
    np.testing.assert_allclose(s["szz"], E * -0.01, rtol=1e-10)


@pytest.mark.parametrize(("make", "kw", "match"), [
    ("2d", {"supports": (Support("left", ("z",)),)},
     r"body 'b': support on 'left': component must be 'x' or 'y' \(the body's mesh is 2D\), "
     r"got 'z'"),
    ("2d", {"prescribed": (PrescribedDisplacement("top", "z", 1.0),)},
     r"body 'b': prescribed displacement on 'top': component must be 'x' or 'y' \(the "
     r"body's mesh is 2D\), got 'z'"),
    ("2d", {"supports": (Support("left", ("w",)),)},
     r"body 'b': support on 'left': component must be 'x' or 'y', got 'w'"),
    ("3d", {"supports": (Support("left", ("w",)),)},
     r"body 'b': support on 'left': component must be 'x', 'y' or 'z', got 'w'"),
    ("2d", {"tractions": (Traction("top", (0.0, 0.0, 1.0)),)},
     r"body 'b': traction on 'top': value must have 2 components \(tx, ty\) on a 2D body, "
     r"got \[0.0, 0.0, 1.0\]"),
    ("3d", {"tractions": (Traction("top", (0.0, 1.0)),)},
     r"body 'b': traction on 'top': value must have 3 components \(tx, ty, tz\) on a 3D "
     r"body, got \[0.0, 1.0\]"),
    ("3d-stress", {}, r"body 'b': plane = 'stress' is an assumption of 2D bodies"),
    ("3d", {"kinematics": "total", "order": 2},
     r"body 'b': large kinematics \('total'\) needs linear elements \(order 1\)$"),
])
def test_what_a_body_cannot_take_is_named(make, kw, match):
    mesh = rectangle(nx=2, ny=2) if make == "2d" else box(nx=2, ny=2, nz=2)
    material = LinearElastic(E, NU, "stress" if make == "3d-stress" else "strain")
    kw.setdefault("supports", (Support("bottom"),))
    body = Body("b", mesh, material, **kw)
    with pytest.raises(InputError, match=match):
        body.validate()


def test_3d_tractions_sum_over_the_face_area():
    """A traction (tx, ty, tz) per unit area gives nodal forces summing to it times the
    face's area, on linear and quadratic, tetrahedral and hexahedral faces."""
    for cells, order in CASES:
        body = Body("box", box(0.0, 0.0, 0.0, *SIZE, nx=2, ny=3, nz=2,
                               tetrahedra=cells == "tet"),
                    LinearElastic(E, NU), supports=(Support("bottom"),),
                    tractions=(Traction("back", (1.0, -2.0, 3.0)),), order=order)
        body.assemble()
        total = body.f_load.reshape(-1, 3).sum(axis=0)
        np.testing.assert_allclose(total, np.array([1.0, -2.0, 3.0]) * SIZE[0] * SIZE[2],
                                   rtol=1e-13)


def test_largest_eigenvalue_and_von_mises_in_3d():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(200, 3, 3))
    A = A + A.transpose(0, 2, 1)
    A[0] = np.diag([2.0, 2.0, 2.0])  # a repeated eigenvalue (p = 0)
    A[1] = np.diag([-3.0, 1.0, 1.0])
    comps = [A[:, 0, 0], A[:, 1, 1], A[:, 2, 2], A[:, 1, 2], A[:, 0, 2], A[:, 0, 1]]
    expected = np.abs(np.linalg.eigvalsh(A)).max(axis=1)
    np.testing.assert_allclose(_largest_eigenvalue(*comps), expected, rtol=1e-12, atol=1e-12)
    zero = np.zeros(1)
    shear = _with_von_mises({"sxx": zero, "syy": zero, "szz": zero, "syz": zero + 2.0,
                             "sxz": zero, "sxy": zero})
    np.testing.assert_allclose(shear["von_mises"], 2.0 * np.sqrt(3.0))


def test_hexahedral_stiffness_is_scikit_fems_linear_elasticity():
    """The body's stiffness is scikit-fem's linear elasticity with the material's Lame
    constants (the 3D ones: lame() is plane strain's, which are), to round-off: the body
    assembles it over all local dof pairs at once (vfem.bodies.assembly)."""
    body = uniform_box("hex", 1)
    lam, mu = body.material.lame()
    assert lam == pytest.approx(E * NU / ((1 + NU) * (1 - 2 * NU)))
    assert mu == pytest.approx(E / (2 * (1 + NU)))
    basis = Basis(body.mesh, ElementVector(ElementHex1()))
    from skfem import asm
    from skfem.models.elasticity import linear_elasticity
    K = asm(linear_elasticity(lam, mu), basis)
    assert abs(K - body.K).max() < 1e-15 * abs(K).max()


@pytest.mark.parametrize(("cells", "order"), CASES)
def test_a_platen_on_a_3d_body(cells, order):
    """A force-controlled platen along z on the top of a roller-supported box: a unit platen
    motion is a uniform strain, so the platen's stiffness is E times the area over the
    height."""
    from vfem.bodies import Platen

    mesh = box(0.0, 0.0, 0.0, *SIZE, nx=2, ny=2, nz=2, tetrahedra=cells == "tet")
    body = Body("box", mesh, LinearElastic(E, NU), supports=ROLLERS,
                platen=Platen("top", "z", -5.0), order=order)
    body.setup()
    assert body.platen_stiffness == pytest.approx(E * SIZE[0] * SIZE[1] / SIZE[2], rel=1e-10)
    np.testing.assert_allclose(body.u_platen.reshape(-1, 3)[:, 2], body.points[2] / SIZE[2],
                               atol=1e-12)


def test_a_3d_body_checks_its_mesh():
    """Body.validate runs the mesh checks in 3D (vfem.mesh.checks): an inverted hexahedron is
    named with the body."""
    mesh = box(nx=2, ny=2, nz=2)
    p = mesh.p.copy()
    centre = int(np.argmin(np.linalg.norm(p - 0.5, axis=0)))
    p[:, centre] = [0.5, 0.5, 1.4]
    body = Body("cube", MeshHex(p, mesh.t, _boundaries=dict(mesh.boundaries)),
                LinearElastic(E, NU), supports=(Support("bottom"),))
    with pytest.raises(InputError, match=r"body 'cube': \d+ element\(s\) are inverted"):
        body.validate()
