"""Input files and configuration in 3D (issue 21, C18): ``mesh.translate`` with three values,
``mesh.curve`` 2D only, three traction components, support components by the body's dimension,
``vfem check`` of 3D files and the export round trip (``dumps`` -> ``vfem run`` of the file ->
the same numbers as the direct run).

The model is the 3D patch test of tests/test_patch3d.py (two stacked boxes pressed together,
a uniform pressure E D / 2), here as a configuration.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from vfem.bodies import PrescribedDisplacement, Support, Traction
from vfem.cli import main
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Output, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.io.input import dumps, load, loads
from vfem.materials import LinearElastic
from vfem.solver import Analysis

E, NU, D = 200.0, 0.3, 0.01
EXACT = E * D / 2.0
ROLLERS = (Support("left", ("x",)), Support("front", ("y",)))


def box(z0, n, tetrahedra=False, translate=(0.0, 0.0)) -> MeshSpec:
    return MeshSpec(shape="box", parameters=as_parameters(z0=z0, nx=n, ny=n, nz=2,
                                                          tetrahedra=tetrahedra),
                    translate=translate)


def patch(lower: MeshSpec, upper: MeshSpec, upper_supports=ROLLERS) -> ModelConfig:
    mat = LinearElastic(E, NU)
    return ModelConfig("patch3d", (
        BodyConfig("lower", lower, mat, supports=(Support("bottom", ("z",)), *ROLLERS),
                   contact_boundaries=("top",)),
        BodyConfig("upper", upper, mat, supports=upper_supports,
                   prescribed=(PrescribedDisplacement("top", "z", -D),),
                   contact_boundaries=("bottom",))),
        contact=ContactSettings(variant="paired"), output=Output(figures=False))


def pressures(config: ModelConfig, base=None) -> dict[str, np.ndarray]:
    result = Analysis(config.build(base)).run()
    assert result.converged, result.message
    return {name: r.contact_pressure for name, r in result.steps[-1].bodies.items()}


# -- translate -------------------------------------------------------------------------------------


def test_translate_with_three_values_moves_a_3d_mesh():
    """The upper box made 0.5 too low and 0.25 off in x and y, then moved back up by
    ``translate = [0.25, -0.25, 0.5]``: the nodes are the box's moved, and the patch test gives
    the uniform pressure on the (smaller) overlap of the faces."""
    moved = box(-0.5, 3, translate=(0.25, -0.25, 0.5)).make()
    plain = box(-0.5, 3).make()
    assert np.array_equal(moved.p, plain.p + np.array([[0.25], [-0.25], [0.5]]))
    text = dumps(patch(box(-1.0, 4), box(-0.5, 3, tetrahedra=True, translate=(0.0, 0.0, 0.5))))
    assert "translate = [0.0, 0.0, 0.5]" in text
    p = pressures(loads(text))
    for name in ("lower", "upper"):
        on = p[name] > 0
        assert on.sum() >= 9 and np.abs(p[name][on] / EXACT - 1).max() < 1e-8


def check_refuses(capsys, tmp_path, text, *words):
    path = tmp_path / "model.toml"
    path.write_text(text)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err
    return err


def with_keys(text: str, after: str, lines: str) -> str:
    """``text`` with ``lines`` inserted after the first line equal to ``after``."""
    head, tail = text.split(after + "\n", 1)
    return head + after + "\n" + lines + "\n" + tail


BOX_PATCH = dumps(patch(box(-1.0, 3), box(0.0, 2)))
RECT = dumps(ModelConfig("flat", (BodyConfig(
    "flat", MeshSpec(shape="rectangle", parameters=as_parameters(width=1.0, height=1.0, nx=2,
                                                                 ny=2)),
    LinearElastic(E, NU), supports=(Support("bottom"),),
    tractions=(Traction("top", (0.0, -1.0)),)),)))


@pytest.mark.parametrize("text, values, words", [
    (BOX_PATCH, "[0.0, 0.5]", ("body 'lower': mesh.translate: expected 3 values (dx, dy, dz) "
                               "for the 3D shape 'box', got 2",)),
    (BOX_PATCH, "[0.0, 0.5, 0.0, 1.0]", ("expected 3 values (dx, dy, dz)", "got 4")),
    (RECT, "[0.0, 0.5, 1.0]", ("body 'flat': mesh.translate: expected 2 values (dx, dy) for the "
                               "2D shape 'rectangle', got 3",)),
    (RECT, "[1.0]", ("body 'flat': mesh.translate: expected 2 values", "got 1")),
])
def test_translate_with_the_wrong_count_is_refused(capsys, tmp_path, text, values, words):
    text = with_keys(text, 'shape = "box"' if "box" in text else 'shape = "rectangle"',
                     f"translate = {values}")
    check_refuses(capsys, tmp_path, text, "model.toml", *words)


def test_a_2d_mesh_file_given_three_translation_values(capsys, tmp_path):
    (tmp_path / "square.inp").write_text(
        "*Node\n1, 0, 0\n2, 1, 0\n3, 1, 1\n4, 0, 1\n*Element, type=CPS4, elset=body\n"
        "1, 1, 2, 3, 4\n*Nset, nset=bottom\n1, 2\n")
    text = RECT.replace('shape = "rectangle"\nheight = 1.0\nnx = 2\nny = 2\nwidth = 1.0\n',
                        'file = "square.inp"\ncells = "body"\ntranslate = [0.0, 0.0, 1.0]\n')
    assert "square.inp" in text
    check_refuses(capsys, tmp_path, text, "body 'flat': mesh.translate: expected 2 values "
                                          "(dx, dy) for the 2D mesh of file 'square.inp', got 3")


def test_a_curve_on_a_hexahedral_mesh_or_with_a_2d_centre_is_refused(capsys, tmp_path):
    text = BOX_PATCH + ('\n[bodies.mesh.curve]\nboundary = "top"\ncentre = [0.0, 0.0]\n'
                        'radius = 1.0\n')
    check_refuses(capsys, tmp_path, text, "body 'upper': mesh.curve: curved facets in 3D are "
                                          "for tetrahedra (on a sphere); the 3D shape 'box' is "
                                          "of hexahedra")
    text = text.replace('tetrahedra = false', 'tetrahedra = true')
    check_refuses(capsys, tmp_path, text, "mesh.curve.centre: expected 3 values for the 3D "
                                          "shape 'box', got 2")


# -- loads and components by the body's dimension ----------------------------------------------


def test_tractions_have_as_many_components_as_the_body(capsys, tmp_path):
    three = RECT.replace("value = [0.0, -1.0]", "value = [0.0, -1.0, 0.0]")
    check_refuses(capsys, tmp_path, three, "body 'flat': traction on 'top': value must have 2 "
                                           "components (tx, ty) on a 2D body, got [0.0, -1.0, 0.0]")
    solid = BOX_PATCH + '\n[[bodies.tractions]]\nboundary = "right"\nvalue = [1.0, 0.0]\n'
    check_refuses(capsys, tmp_path, solid, "body 'upper': traction on 'right': value must have 3 "
                                           "components (tx, ty, tz) on a 3D body")
    ok = BOX_PATCH + '\n[[bodies.tractions]]\nboundary = "right"\nvalue = [0.0, 0.0, -1.0]\n'
    (tmp_path / "ok.toml").write_text(ok)
    assert main(["-q", "check", str(tmp_path / "ok.toml")]) == 0


def test_a_3d_traction_is_applied():
    """A uniform traction (0, 0, -p) on the top of a box on rollers, written and read back:
    uniaxial stress, the top moved down by p h / E."""
    config = ModelConfig("pressed", (BodyConfig(
        "box", box(-1.0, 2, tetrahedra=True), LinearElastic(E, NU),
        supports=(Support("bottom", ("z",)), *ROLLERS),
        tractions=(Traction("top", (0.0, 0.0, -EXACT)),)),))
    text = dumps(config)
    assert "value = [0.0, 0.0, -1.0]" in text
    model = loads(text).build()
    result = Analysis(model).run()
    u = result.steps[-1].bodies["box"].displacement.reshape(-1, 3)
    top = np.isclose(model.bodies[0].points[2], 0.0)
    assert top.sum() == 9 and np.abs(u[top, 2] + EXACT / E).max() < 1e-12


def test_support_components_by_the_body_dimension(capsys, tmp_path):
    z2d = RECT.replace('boundary = "bottom"', 'boundary = "bottom"\ncomponents = ["x", "z"]')
    check_refuses(capsys, tmp_path, z2d, "body 'flat': support on 'bottom': component must be "
                                         "'x' or 'y' (the body's mesh is 2D), got 'z'")
    w3d = BOX_PATCH.replace('components = ["z"]', 'components = ["w"]')
    check_refuses(capsys, tmp_path, w3d, "body 'lower': support on 'bottom': component must be "
                                         "'x', 'y' or 'z', got 'w'")


def test_vfem_check_of_a_3d_file(capsys, tmp_path):
    path = tmp_path / "patch3d.toml"
    path.write_text(BOX_PATCH)
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "model 'patch3d' is valid — 2 bodies (lower: 48 nodes, upper: 27 nodes), 1 step" in out


# -- export round trip ---------------------------------------------------------------------------


def test_export_round_trip_of_a_3d_model(tmp_path):
    """``dumps`` of a 3D model (a translated tetrahedral box; a support of two components, x
    and y, on the upper top, which holds with Poisson's ratio 0) read back is the same
    configuration, written the same, and ``vfem run`` of the file gives the direct run's
    pressures and summary digit for digit."""
    config = patch(box(-1.0, 4), box(-0.25, 3, tetrahedra=True, translate=(0.0, 0.0, 0.25)),
                   upper_supports=(*ROLLERS, Support("top", ("x", "y"))))
    config = ModelConfig(config.name, tuple(
        BodyConfig(b.name, b.mesh, LinearElastic(E, 0.0), supports=b.supports,
                   prescribed=b.prescribed, contact_boundaries=b.contact_boundaries)
        for b in config.bodies), config.contact, output=config.output)
    text = dumps(config)
    assert 'components = ["x", "y"]' in text  # else read back as x, y and z
    again = loads(text)
    assert again == config and dumps(again) == text
    assert again.bodies[1].supports[2].components == ("x", "y")
    assert len(again.build().bodies[1].support_components(again.bodies[1].supports[2])) == 2
    path = tmp_path / "patch3d.toml"
    path.write_text(text)
    assert main(["-q", "run", str(path), "--out", str(tmp_path / "file")]) == 0
    direct = pressures(config)
    summary = json.loads((tmp_path / "file" / "summary.json").read_text())
    for name in ("lower", "upper"):
        on = direct[name] > 0
        assert np.abs(direct[name][on] / EXACT - 1).max() < 1e-8
        assert summary["bodies"][name]["max_contact_pressure"] == direct[name].max()


def test_export_of_mesh_files_keeps_support_components(tmp_path):
    """A mesh file's dimension is not known when it is written: supports given with some
    components are written with them (for a 3D file, left out they would read back as x, y
    and z)."""
    spec = MeshSpec(file="blocks.msh", cells="upper", translate=(0.0, 0.0, 1.0))
    config = ModelConfig("files", (BodyConfig(
        "upper", spec, LinearElastic(E, NU),
        supports=(Support("left", ("x", "y")), Support("bottom"))),))
    text = dumps(config)
    assert text.count("components") == 1 and 'components = ["x", "y"]' in text
    assert "translate = [0.0, 0.0, 1.0]" in text
    again = loads(text)
    assert again == config and dumps(again) == text
    assert again.bodies[0].supports[0].components == ("x", "y")
    with pytest.raises(InputError, match="no such file"):
        again.build(tmp_path)


def test_an_input_file_with_a_3d_mesh_file_runs(tmp_path):
    """The file route end to end: a 3D mesh file named in a TOML file (relative to it),
    ``load`` and run; the pressure of the patch test."""
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        lo = gmsh.model.occ.addBox(0, 0, -1, 1, 1, 1)
        gmsh.model.occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [lo], name="lower")
        for name, axis, at in (("bottom", 2, -1.0), ("top", 2, 0.0), ("left", 0, 0.0),
                               ("front", 1, 0.0)):
            faces = [s for _, s in gmsh.model.getEntities(2)
                     if abs(gmsh.model.occ.getCenterOfMass(2, s)[axis] - at) < 1e-9]
            gmsh.model.addPhysicalGroup(2, faces, name=name)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.34)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(tmp_path / "lower.msh"))
    finally:
        gmsh.finalize()
    config = patch(MeshSpec(file="lower.msh", cells="lower"), box(0.0, 2))
    path = tmp_path / "model.toml"
    path.write_text(dumps(config))
    p = pressures(load(path), tmp_path)
    for name in ("lower", "upper"):
        on = p[name] > 0
        assert on.any() and np.abs(p[name][on] / EXACT - 1).max() < 1e-8


@pytest.mark.slow
def test_vfem_export_of_a_3d_example_runs_as_the_example(tmp_path):
    """``vfem export sphere`` (a coarse quarter, one step) read back is the example's own
    configuration, and ``vfem run`` of the file writes the example's contact and reaction
    tables byte for byte."""
    from vfem_examples import sphere

    sets = ["--set", "facets_per_radius=4", "--set", "steps=1"]
    path = tmp_path / "sphere.toml"
    assert main(["-q", "export", "sphere", *sets, "--out", str(path)]) == 0
    assert load(path) == sphere.config(sphere.Parameters(facets_per_radius=4, steps=1))
    assert main(["-q", "run", str(path), "--set", "output.figures=false",
                 "--out", str(tmp_path / "file")]) == 0
    assert main(["-q", "run", "sphere", *sets, "--out", str(tmp_path / "example")]) == 0
    for name in ("contact.csv", "reactions.csv"):
        assert (tmp_path / "file" / name).read_bytes() == (tmp_path / "example" / name).read_bytes()
