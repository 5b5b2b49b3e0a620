"""Support reactions in the outputs (issue 17, item 4): per converged step, body and constrained
boundary, the force the supports, prescribed displacements and platen apply to the body.

The model: a base held at its bottom (x and y) and its left side (x; the bottom-left corner's
x is constrained by both), pushed sideways by a traction on its right side; a punch held in x
and pushed down by a platen on its top, with a traction on its left side. Each body then
balances its contact force, its applied loads and its reactions, under small and under large
kinematics.
"""

from __future__ import annotations

import csv
import dataclasses
import json

import meshio
import numpy as np
import pytest

from vfem import load
from vfem.cli import main
from vfem.io import runner
from vfem.io.results import run_writing

MODEL = """
name = "reactions"

[[bodies]]
name = "base"
mesh = {shape = "rectangle", x0 = 0.0, y0 = -0.5, width = 2.0, height = 0.5, nx = 16, ny = 4}
material = {youngs_modulus = 1000.0, poissons_ratio = 0.3}
supports = [{boundary = "bottom"}, {boundary = "left", components = ["x"]}]
tractions = [{boundary = "right", value = [-3.0, 0.0]}]

[[bodies]]
name = "punch"
material = {youngs_modulus = 1000.0, poissons_ratio = 0.3}
supports = [{boundary = "top", components = ["x"]}]
tractions = [{boundary = "left", value = [1.5, 0.5]}]
platen = {boundary = "top", component = "y", force = -20.0}
contact_boundaries = ["bottom"]

[bodies.mesh]
shape = "rectangle"
x0 = 0.5
y0 = 0.0
width = 1.0
height = 0.5
nx = 8
ny = 4
triangles = true

[steps]
load_factors = [0.5, 1.0]
"""
PLATEN_FORCE = -20.0
KINEMATICS = ("small", "total")


def _config(tmp_path, kinematics="small"):
    path = tmp_path / "reactions.toml"
    path.write_text(MODEL)
    config = load(path)
    bodies = tuple(dataclasses.replace(b, kinematics=kinematics) for b in config.bodies)
    return dataclasses.replace(config, bodies=bodies), path


@pytest.fixture(scope="module", params=KINEMATICS)
def solved(request, tmp_path_factory):
    """The model solved and written (runner.run: summary.json as ``vfem run`` writes it)."""
    tmp = tmp_path_factory.mktemp(request.param)
    config, _ = _config(tmp, request.param)
    model = config.build()
    analysis, result = run_writing(model, tmp / "out")
    summary = runner.summarize(result, config)
    assert result.converged, result.message
    return model, result, summary, tmp / "out"


def test_each_body_balances_at_every_step(solved):
    """reactions + contact force + applied loads = 0 per body and step, to 1e-8 of the contact
    force; the applied loads are the tractions' resultants (length x traction x load factor)."""
    model, result, _, _ = solved
    tractions = {"base": np.array([-3.0, 0.0]) * 0.5, "punch": np.array([1.5, 0.5]) * 0.5}
    for step in result.steps:
        for body in model.bodies:
            r = step.bodies[body.name]
            contact = r.contact_force.sum(axis=0)
            np.testing.assert_allclose(r.applied_load, step.load_factor * tractions[body.name],
                                       rtol=1e-12)
            scale = np.linalg.norm(contact)
            assert scale > 1.0  # the punch presses on the base at every step
            residual = np.linalg.norm(r.reaction_total + contact + r.applied_load)
            assert residual <= 1e-8 * scale, (step.step, body.name, residual / scale)


def test_the_platen_boundary_carries_the_platen_force(solved):
    """Sign convention: a reaction is the force on the body, so the platen's boundary reaction
    along its component is the platen force times the load factor (-20 pushes the punch down),
    and the punch's top carries nothing else in y."""
    _, result, _, _ = solved
    for step in result.steps:
        r = step.bodies["punch"]
        assert r.reactions["top"][1] == pytest.approx(PLATEN_FORCE * step.load_factor, rel=1e-8)
        assert r.reaction_total[1] == pytest.approx(r.reactions["top"][1], rel=1e-12)


def test_reactions_live_on_the_constrained_dofs_and_shared_corners_count_once(solved):
    model, result, _, _ = solved
    base = next(b for b in model.bodies if b.name == "base")
    r = result.steps[-1].bodies["base"]
    free = np.setdiff1d(np.arange(base.ndofs), base.fixed_dofs)
    assert np.all(r.reaction.ravel()[free] == 0.0)
    # the bottom-left corner's x dof is constrained by both boundaries: in each of their totals,
    # once in the body's
    corner = int(np.argmin(np.hypot(*(base.points - np.array([[0.0], [-0.5]])))))
    rx_corner = r.reaction[corner, 0]
    assert abs(rx_corner) > 1e-6
    assert r.reactions["bottom"][0] + r.reactions["left"][0] - rx_corner == pytest.approx(
        r.reaction_total[0], rel=1e-10)
    assert r.reactions["left"][1] == 0.0  # the left side holds x only
    assert r.reactions["bottom"][1] == pytest.approx(r.reaction_total[1], rel=1e-12)


def test_body_reaction_reads_the_same_nodal_reaction(solved):
    """Body.reaction (one boundary, one component) is the nodal reaction summed, for each
    component the boundary's own conditions constrain (Body.reaction sums every constrained
    dof of the boundary's nodes: on the left side in y, the corner the bottom holds)."""
    model, result, _, _ = solved
    step = result.steps[-1]
    for body in model.bodies:
        r = step.bodies[body.name]
        for boundary, dofs in body.reaction_dofs().items():
            for k in np.unique(dofs % 2):
                c, value = "xy"[k], r.reactions[boundary][k]
                got = body.reaction(r.displacement.ravel(), boundary, c, step.load_factor,
                                    r.contact_force.ravel())
                assert got == pytest.approx(value, rel=1e-10, abs=1e-12)


def test_summary_csv_and_vtu_hold_the_same_numbers(solved):
    model, result, summary, out = solved
    on_disk = json.loads((out / "summary.json").read_text())  # the running summary
    with open(out / "reactions.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == ["step", "load_factor", "body", "boundary", "Rx", "Ry"]
    expected = {"base": ["bottom", "left"], "punch": ["top"]}
    assert len(rows) == len(result.steps) * (3 + 2)  # the boundaries, then each body's total
    for s, written, step in zip(summary["steps"], on_disk["steps"], result.steps):
        assert written["reactions"] == s["reactions"]
        for body in model.bodies:
            rec = s["reactions"][body.name]
            assert list(rec["boundaries"]) == expected[body.name]
            mine = [x for x in rows if int(x["step"]) == step.step and x["body"] == body.name]
            assert [x["boundary"] for x in mine] == [*expected[body.name], "(total)"]
            for x in mine:
                assert float(x["load_factor"]) == step.load_factor
                assert [float(x["Rx"]), float(x["Ry"])] == (
                    rec["total"] if x["boundary"] == "(total)"
                    else rec["boundaries"][x["boundary"]])
            vtu = meshio.read(out / f"{body.name}_step{step.step:04d}.vtu")
            reaction = vtu.point_data["reaction"]
            assert reaction.shape == (body.npoints, 3) and np.all(reaction[:, 2] == 0)
            np.testing.assert_array_equal(reaction[:, :2], step.bodies[body.name].reaction)
            np.testing.assert_allclose(reaction[:, :2].sum(axis=0), rec["total"], rtol=1e-12)
            assert s["reaction_imbalance"][body.name] <= 1e-8
            assert s["applied_load"][body.name] == list(step.bodies[body.name].applied_load)


def test_the_closing_screen_shows_reactions_and_the_balance(solved):
    from vfem.cli.run import results_line
    from vfem.io.folders import ResultsFolder, run_description

    _, _, summary, out = solved
    ResultsFolder(out, run_description("test", "test", [])).update()  # the run's own files
    lines = results_line(runner.report(summary, out), out)  # the screen vfem run prints
    punch = next(x for x in lines if x.strip().startswith("punch:"))
    assert "contact force (" in punch and ", reactions (" in punch
    fx, fy = summary["bodies"]["punch"]["reactions"]
    assert fy == pytest.approx(PLATEN_FORCE, rel=1e-8)
    balance = next(x for x in lines if "balance to" in x and "applied loads" in x)
    assert float(balance.split("balance to ")[1].split()[0]) <= 1e-8
    assert "reactions.csv" in lines[-1]


def test_resume_keeps_the_earlier_rows(tmp_path):
    """A run stopped after step 1 (the later checkpoint and VTU files removed) resumes to the
    same reactions.csv as a run never interrupted."""
    config, _ = _config(tmp_path)
    full, cut = tmp_path / "full", tmp_path / "cut"
    run_writing(config.build(), full)
    run_writing(config.build(), cut)
    (cut / "checkpoint" / "step0002.npz").unlink()
    for f in cut.glob("*_step0002.vtu"):
        f.unlink()
    (cut / "reactions.csv").write_text("step,load_factor,body,boundary,Rx,Ry\n")  # a stale file
    _, resumed = run_writing(config.build(), cut, resume=True)
    assert [s.step for s in resumed.steps] == [1, 2]
    assert resumed.steps[0].bodies["punch"].reactions["top"][1] == pytest.approx(-10.0)
    assert (cut / "reactions.csv").read_text() == (full / "reactions.csv").read_text()


@pytest.mark.slow
def test_the_command_line_prints_reactions(tmp_path, capsys):
    _, path = _config(tmp_path)
    assert main(["run", str(path), "--out", str(tmp_path / "cli")]) == 0
    out = capsys.readouterr().out
    assert ", reactions (" in out and "(contact + reactions + applied loads) balance to" in out
    assert (tmp_path / "cli" / "reactions.csv").is_file()
