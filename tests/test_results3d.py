"""Results of 3D bodies (issue 21, C3): VTU/PVD with tetra/hexahedron cells (and tetra10,
hexahedron27), three displacement components, the six stresses, contact.csv and
reactions.csv with their z columns, summary.json's forces with three components.

A 3D model without contact runs through the solver's :class:`~vfem.solver.Analysis` and the
results writer (:func:`vfem.io.results.run_writing`): one box on rollers under a uniform
sigma_zz (the closed-form uniform state), beside a box clamped at its bottom under an oblique
traction, the two in one model whose ``contact_pairs`` leave them apart. The files are read
back through meshio and the CSV reader; 2D files keep their columns (the 2D gate:
``benchmarks/answers.py`` and a run's files compared byte for byte)."""

import csv
import json

import meshio
import numpy as np
import pytest

from models import box_mesh, input_file, rollers, support, toml_body, traction
from vfem.bodies import Body, Support, Traction
from vfem.contact.invariants.polygon import symmetry_facets
from vfem.errors import InputError
from vfem.io.input import dumps, loads
from vfem.io.replot import Folder, read_contact_csv
from vfem.io.results import (
    CONTACT_COLUMNS,
    FRICTION_COLUMNS,
    REACTION_COLUMNS,
    contact_columns,
    reaction_columns,
    run_writing,
)
from vfem.materials import LinearElastic
from vfem.mesh.shapes import rectangle
from vfem.mesh.solids import box
from vfem.solver import Model

E, NU, SIGMA = 200.0, 0.3, -2.0  # SIGMA: sigma_zz, negative: the top pressed down
SHEAR = (0.3, -0.2)  # the clamped box's tangential traction (tx, ty) on its top
SIZE = (1.0, 2.0, 1.5)  # width (x), depth (y), height (z)
AREA = SIZE[0] * SIZE[1]  # the top's
FACTORS = (0.5, 1.0)
ROLLERS = (Support("left", ("x",)), Support("front", ("y",)), Support("bottom", ("z",)))
CASES = {("tet", 1): "tetra", ("tet", 2): "tetra10", ("hex", 1): "hexahedron",
         ("hex", 2): "hexahedron27"}
STRESSES = {"stress_xx", "stress_yy", "stress_zz", "stress_yz", "stress_xz", "stress_xy",
            "von_mises"}


def boxes(cells: str, order: int) -> Model:
    """``rollers``: the box on rollers under sigma_zz; ``clamped``: a box beside it (x + 2),
    held at its bottom, under the traction (SHEAR, SIGMA) on its top. No pair may touch."""
    tet = cells == "tet"
    rollers = Body("rollers", box(0.0, 0.0, 0.0, *SIZE, nx=2, ny=3, nz=2, tetrahedra=tet),
                   LinearElastic(E, NU), supports=ROLLERS,
                   tractions=(Traction("top", (0.0, 0.0, SIGMA)),), order=order)
    clamped = Body("clamped", box(2.0, 0.0, 0.0, *SIZE, nx=2, ny=2, nz=2, tetrahedra=tet),
                   LinearElastic(E, NU), supports=(Support("bottom"),),
                   tractions=(Traction("top", (*SHEAR, SIGMA)),), order=order)
    return Model("boxes", [rollers, clamped], load_factors=FACTORS, contact_pairs=())


@pytest.fixture(scope="module", params=sorted(CASES), ids=lambda c: f"{c[0]}{c[1]}")
def run(request, tmp_path_factory):
    cells, order = request.param
    out = tmp_path_factory.mktemp(f"{cells}{order}")
    model = boxes(cells, order)
    analysis, result = run_writing(model, out)
    assert result.converged, result.message
    return CASES[request.param], model, result, out


def _volumes(kind: str, x: np.ndarray) -> np.ndarray:
    """(ncells, 8) VTK cell volumes at the 2 x 2 x 2 Gauss points of the trilinear map on a
    hexahedron's corners (VTK order), each weighted 1/8 (each must be positive); a
    tetrahedron's (x1 - x0) x (x2 - x0) . (x3 - x0) / 6 (one column). ``x``: (ncells, nodes,
    3), VTK's node order."""
    if kind.startswith("tetra"):
        a, b, c = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
        return (np.einsum("ei,ei->e", np.cross(a, b), c) / 6)[:, None]
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                        [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
    g = 0.5 + np.array([-1.0, 1.0]) / (2 * np.sqrt(3))
    out = []
    for r in np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T:
        f = np.where(corners == 1, r, 1 - r)  # (8, 3) the 1D factors
        sign = np.where(corners == 1, 1.0, -1.0)
        dN = np.stack([sign[:, j] * np.prod(np.delete(f, j, axis=1), axis=1)
                       for j in range(3)], axis=1)  # (8, 3)
        J = np.einsum("eki,kj->eij", x[:, :8], dN)
        out.append(np.linalg.det(J) / 8)
    return np.column_stack(out)


def test_vtu_round_trip_cells_volumes_and_the_uniform_state(run):
    """Each step's VTU, read back by meshio: the body's cells as VTK's 3D cells, every volume
    positive (summing to the box's), the points' three coordinates, the displacement's three
    components equal to the closed form (u_z = sigma z / E, u_x = -nu sigma x / E,
    u_y = -nu sigma y / E, times the load factor) to 1e-10, and the six stresses named as the
    2D ones are (stress_zz = sigma, the others zero)."""
    kind, model, result, out = run
    body = model.bodies[0]
    for step, lf in zip(result.steps, FACTORS):
        m = meshio.read(out / f"rollers_step{step.step:04d}.vtu")
        assert [c.type for c in m.cells] == [kind]
        conn = m.cells_dict[kind]
        np.testing.assert_array_equal(conn, body.cells()[1])
        np.testing.assert_array_equal(m.points, body.points.T)
        volumes = _volumes(kind, m.points[conn])
        assert volumes.min() > 0
        assert volumes.sum() == pytest.approx(np.prod(SIZE), rel=1e-12)
        u = m.point_data["displacement"]
        assert u.shape == (body.npoints, 3)
        x, y, z = m.points.T
        scale = abs(SIGMA) / E * max(SIZE)
        s = lf * SIGMA
        np.testing.assert_allclose(u[:, 2], s * z / E, rtol=0, atol=1e-10 * scale)
        np.testing.assert_allclose(u[:, 0], -NU * s * x / E, rtol=0, atol=1e-10 * scale)
        np.testing.assert_allclose(u[:, 1], -NU * s * y / E, rtol=0, atol=1e-10 * scale)
        np.testing.assert_array_equal(u, result.steps[step.step - 1].bodies["rollers"]
                                      .displacement)
        for name in ("contact_force", "reaction"):
            assert m.point_data[name].shape == (body.npoints, 3)
        assert not np.any(m.point_data["contact_force"])
        assert not np.any(m.point_data["contact_status"])
        assert set(m.cell_data) == STRESSES
        np.testing.assert_allclose(m.cell_data["stress_zz"][0], s, rtol=1e-10)
        for name in ("stress_xx", "stress_yy", "stress_yz", "stress_xz", "stress_xy"):
            np.testing.assert_allclose(m.cell_data[name][0], 0.0, atol=1e-10 * abs(SIGMA))
        np.testing.assert_allclose(m.cell_data["von_mises"][0], abs(s), rtol=1e-10)
        # the reaction field: the bottom's nodes carry the load, in z
        np.testing.assert_allclose(m.point_data["reaction"].sum(axis=0)[2], -s * AREA,
                                   rtol=1e-10)


def test_pvd_lists_every_body_and_step(run):
    kind, model, result, out = run
    text = (out / "results.pvd").read_text()
    for step in result.steps:
        for k, body in enumerate(model.bodies):
            name = f"{body.name}_step{step.step:04d}.vtu"
            assert (out / name).is_file()
            assert f'part="{k}" name="{body.name}" file="{name}"' in text
    # read back as vfem plot reads it: 3D frames, every coordinate and component
    folder = Folder(out)
    frames = folder.steps[-1].bodies
    assert [f.name for f in frames] == ["rollers", "clamped"]
    for f, body in zip(frames, model.bodies):
        assert f.dim == 3 and f.cell_type == kind
        np.testing.assert_array_equal(f.points, body.points.T)
        np.testing.assert_array_equal(f.displacement, result.steps[-1].bodies[f.name]
                                      .displacement)


def _rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        return next(reader), list(reader)


def test_reactions_per_component_are_the_traction_times_the_area(run):
    """reactions.csv's Rx, Ry, Rz: the rollers' bottom carries -sigma A in z, its left and
    front nothing; the clamped box's bottom -(tx, ty, sigma) A, to 1e-10, at each load factor;
    the (total) rows as summary.json's totals, which balance the applied loads."""
    kind, model, result, out = run
    columns, rows = _rows(out / "reactions.csv")
    assert tuple(columns) == REACTION_COLUMNS + ("Rz",) == reaction_columns(3)
    table = {(int(r[0]), r[2], r[3]): np.array(r[4:], dtype=float) for r in rows}
    summary = json.loads((out / "summary.json").read_text())
    scale = abs(SIGMA) * AREA
    for step, lf in zip(result.steps, FACTORS):
        k = step.step
        np.testing.assert_allclose(table[k, "rollers", "bottom"], [0.0, 0.0, -lf * SIGMA * AREA],
                                   rtol=1e-10, atol=1e-10 * scale)
        for side in ("left", "front"):
            np.testing.assert_allclose(table[k, "rollers", side], 0.0, atol=1e-10 * scale)
        expected = -lf * np.array([*SHEAR, SIGMA]) * AREA
        for row in ("bottom", "(total)"):
            np.testing.assert_allclose(table[k, "clamped", row], expected, rtol=1e-10,
                                       atol=1e-10 * scale)
        record = summary["steps"][k - 1]
        for name in ("rollers", "clamped"):
            total = record["reactions"][name]["total"]
            assert len(total) == 3
            np.testing.assert_array_equal(total, table[k, name, "(total)"])  # same digits
            assert record["contact_force"][name] == [0.0, 0.0, 0.0]
            assert len(record["applied_load"][name]) == 3
            assert record["reaction_imbalance"][name] < 1e-12
        np.testing.assert_allclose(record["applied_load"]["clamped"], -expected, rtol=1e-12)
        assert record["invariants"]["passed"] and record["invariants"]["force_balance"] == 0.0


def test_contact_csv_has_the_z_columns(run):
    """A 3D model's contact.csv: z after y, uz after uy (no rows: no body may touch); the CSV
    reader takes it."""
    _, _, _, out = run
    columns, rows = _rows(out / "contact.csv")
    assert tuple(columns) == contact_columns(3)
    assert columns[4:10] == ["x", "y", "z", "ux", "uy", "uz"] and rows == []
    assert read_contact_csv(out / "contact.csv") == {}


def test_csv_columns_by_dimension():
    """2D columns are the constants, unchanged; 3D adds z, uz, shear_z and Rz."""
    assert contact_columns(2) == CONTACT_COLUMNS
    assert contact_columns(2, friction=True) == CONTACT_COLUMNS + FRICTION_COLUMNS
    assert contact_columns(3, friction=True) == (
        "step", "load_factor", "body", "node", "x", "y", "z", "ux", "uy", "uz", "pressure",
        "gap", "status", "shear_x", "shear_y", "shear_z", "slip_increment",
        "accumulated_slip", "friction")
    assert reaction_columns(2) == REACTION_COLUMNS
    assert reaction_columns(3)[-3:] == ("Rx", "Ry", "Rz")


def test_read_contact_csv_with_z(tmp_path):
    path = tmp_path / "contact.csv"
    path.write_text(",".join(contact_columns(3)) + "\n"
                    "1,1,b,7,0.5,1.5,2.5,1e-3,2e-3,-3e-3,10,0,contact\n"
                    "1,1,b,8,0.25,1,2,0,0,0,0,0.1,free\n", encoding="utf-8")
    c = read_contact_csv(path)[1, "b"]
    np.testing.assert_array_equal(c.node, [7, 8])
    np.testing.assert_array_equal(c.x, [[0.5, 1.5, 2.5], [0.25, 1, 2]])
    np.testing.assert_array_equal(c.u, [[1e-3, 2e-3, -3e-3], [0, 0, 0]])
    np.testing.assert_array_equal(c.contact, [True, False])


def test_resume_keeps_the_3d_files(run, tmp_path):
    """A 3D run resumed from its checkpoint (after its last step: nothing left to do) rebuilds
    the same reactions.csv, contact.csv and PVD from the steps read back."""
    cells, order = next(k for k, v in CASES.items() if v == run[0])
    again = tmp_path / "again"
    _, first = run_writing(boxes(cells, order), again)
    before = {n: (again / n).read_bytes() for n in ("reactions.csv", "contact.csv",
                                                     "results.pvd")}
    _, resumed = run_writing(boxes(cells, order), again, resume=True)
    assert resumed.converged and len(resumed.steps) == len(first.steps)
    for name, data in before.items():
        assert (again / name).read_bytes() == data, name


BOX_TOML = input_file("box3d", toml_body(
    "box", box_mesh(width=1.0, depth=2.0, height=1.5, nx=2, ny=2, nz=2, tetrahedra=True),
    rollers(), support("bottom", ["z"]), traction("top", [0.0, 0.0, -2.0]), E=200.0))


def test_a_3d_input_file_runs_and_writes_its_summary(tmp_path):
    """``shape = "box"`` in an input file: the model runs as ``vfem run`` runs it
    (:func:`vfem.io.runner.run`), its summary's forces with three components, no contact
    dofs; its figures are the 3D ones without a pressure map (no node in contact, which a note
    says) and the history."""
    from vfem.io.runner import run as run_input

    config = loads(BOX_TOML)
    summary = run_input(config, tmp_path, figures=False)
    assert summary["converged"] and summary["contact_dofs"] == 0
    body = summary["bodies"]["box"]
    assert body["contact_force"] == [0.0, 0.0, 0.0]
    np.testing.assert_allclose(body["reactions"], [0.0, 0.0, 2.0 * AREA], atol=1e-12)
    np.testing.assert_allclose(body["applied_load"], [0.0, 0.0, -2.0 * AREA], atol=1e-12)
    assert body["max_displacement"] == pytest.approx(
        np.sqrt((NU * 2.0 * 1.0 / E) ** 2 + (NU * 2.0 * 2.0 / E) ** 2 + (2.0 * 1.5 / E) ** 2),
        rel=1e-10)
    assert meshio.read(tmp_path / "box_step0001.vtu").cells[0].type == "tetra"
    pytest.importorskip("matplotlib")
    from vfem.io.replot import plot_results

    notes: list[str] = []
    assert sorted(p.name for p in plot_results(tmp_path, notes)) == [
        "deformed.png", "history.png", "von_mises.png"]
    assert any(n.startswith("pressure_box.png: no node of 'box' in contact") for n in notes)


def test_export_writes_a_3d_support_exactly():
    """Left out, a support's components are every one of the body's: x, y and z in 3D. A 3D
    support given as ["x", "y"] (equal to the 2D default) is written as given; the default is
    still left out."""
    text = BOX_TOML.replace('components = ["z"]', 'components = ["x", "y"]').replace(
        'boundary = "front"\ncomponents = ["y"]', 'boundary = "front"')
    config = loads(text)
    written = dumps(config)
    assert 'boundary = "bottom"\ncomponents = ["x", "y"]' in written
    assert 'boundary = "front"\n\n' in written  # the default: every component
    again = loads(written)
    assert again == config
    body = again.build().bodies[0]
    assert [body.support_components(s) for s in body.supports] == [
        ("x",), ("x", "y", "z"), ("x", "y")]


def test_symmetry_facets_of_a_z_roller():
    """A roller in z on the bottom face (z = 0) is a symmetry plane normal to z, read along z
    (not y): its facets are the bottom's; one in x on the left face, the left's; a roller in
    x on the bottom (not normal to x) is none."""
    mesh = box(0.0, 0.0, 0.0, *SIZE, nx=2, ny=3, nz=2)
    body = Body("box", mesh, LinearElastic(E, NU), supports=ROLLERS)
    found = np.sort(symmetry_facets(body))
    expected = np.sort(np.concatenate([mesh.boundaries[n] for n in ("left", "front",
                                                                    "bottom")]))
    np.testing.assert_array_equal(found, expected)
    only_z = Body("box", mesh, LinearElastic(E, NU), supports=(Support("bottom", ("z",)),))
    np.testing.assert_array_equal(np.sort(symmetry_facets(only_z)),
                                  np.sort(mesh.boundaries["bottom"]))
    across = Body("box", mesh, LinearElastic(E, NU), supports=(Support("bottom", ("x",)),
                                                               Support("top")))
    assert len(symmetry_facets(across)) == 0


def test_a_model_of_2d_and_3d_bodies_is_refused():
    flat = Body("flat", rectangle(0.0, -1.0, 1.0, 1.0, 2, 2), LinearElastic(E, NU),
                supports=(Support("bottom"),))
    solid = Body("solid", box(0.0, 0.0, 0.0, 1.0, 1.0, 1.0), LinearElastic(E, NU),
                 supports=(Support("bottom"),))
    with pytest.raises(InputError, match=r"its bodies must all be plane strain or all plane "
                                         r"stress or all axisymmetric or all 3D, got 'flat' "
                                         r"plane strain, 'solid' 3D"):
        Model("mixed", [flat, solid], contact_pairs=()).validate()


def test_3d_bodies_that_may_touch_are_refused_where_3d_contact_is_not_there():
    """3D contact (issue 21, C10) is the paired variant's, frictionless, of linear elements
    and quadratic tetrahedra: two quadratic hexahedral bodies that may touch (every pair, by
    default) are refused, each named; linear ones are accepted."""
    model = boxes("hex", 2)
    model.contact_pairs = None
    with pytest.raises(InputError, match=r"body 'rollers': 3D contact of quadratic "
                                         r"hexahedra \(9-node facets\) is not implemented"):
        model.validate()
    model.contact_pairs = (("rollers", "clamped"),)
    with pytest.raises(InputError, match="3D contact of quadratic hexahedra"):
        model.validate()
    boxes("hex", 1).validate()
    linear = boxes("hex", 1)
    linear.contact_pairs = None
    linear.validate()


def test_resume_tells_a_3d_default_support_from_x_and_y(tmp_path):
    """The default support of a 3D body fixes x, y and z; one given as ("x", "y") compares
    equal to it as a tuple, but it is another model: its checkpoint is not resumed, and the
    refusal names the components."""
    def model(bottom: Support) -> Model:
        body = Body("block", box(0.0, 0.0, 0.0, *SIZE, nx=1, ny=1, nz=1), LinearElastic(E, NU),
                    supports=(bottom, Support("left", ("z",)), Support("right", ("z",))),
                    tractions=(Traction("top", (*SHEAR, 0.0)),))
        return Model("block", [body])

    run_writing(model(Support("bottom")), tmp_path)
    with pytest.raises(InputError, match=r"supports\[0\]\.components.*'x', 'y', 'z'"):
        run_writing(model(Support("bottom", ("x", "y"))), tmp_path, resume=True)


def test_a_3d_run_keeps_no_scikit_fem_basis(run):
    """Assembly, strains, stresses and the written results of a 3D body work a chunk of
    elements at a time: no body keeps the whole ``CellBasis`` (147 KB per trilinear
    hexahedron; the million-dof sphere was killed building it), though ``body.basis`` still
    builds it for a caller that asks."""
    _, model, result, _ = run
    assert all("_basis" not in b.__dict__ for b in model.bodies)
    body = model.bodies[0]
    assert body.basis.N == body.ndofs and "_basis" in body.__dict__
