"""Invariants of every converged step, checked independently of the contact formulation
(issue 16, item 2): force balance, no interpenetration, no tension (vfem.contact.invariants.check).

Hand-made states that satisfy or break each one; the solver cutting and then stopping when a
converged state breaks one; summary.json and checkpoints carrying the measures per step.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import logging
from types import SimpleNamespace

import numpy as np
import pytest
from skfem import MeshQuad, MeshTri

import models
from vfem.bodies import Body, PrescribedDisplacement, Support
from vfem.cli import main
from vfem.contact.invariants.check import InvariantCheck, step_invariants
from vfem.contact.invariants.plane import PLANE
from vfem.contact.invariants.polygon import _Boundary, _Polygon
from vfem.contact.settings import ContactSettings
from vfem.errors import InvariantViolation
from vfem.io import checkpoint
from vfem.io.results import run_writing
from vfem.materials import LinearElastic
from vfem.solver import Analysis, Model

MAT = LinearElastic(1000.0, 0.3)
TOL = 1e-8  # the penetration tolerance of the hand-made states


#: the tensor meshes here have their left side marked too
rect = functools.partial(models.rect, boundaries=("bottom", "top", "left"))


def blocks(order=1):
    """A block (0.2 <= x <= 0.8, 0 <= y <= 0.5, triangles) resting on a wider one (0 <= x <= 1,
    -0.5 <= y <= 0, quadrilaterals); the meshes do not match."""
    lower = Body("lower", rect(MeshQuad, 0, 1, -0.5, 0, 8, 4), MAT, supports=(Support("bottom"),),
                 order=order)
    upper = Body("upper", rect(MeshTri, 0.2, 0.8, 0, 0.5, 5, 5), MAT,
                 prescribed=(PrescribedDisplacement("top", "y", -0.001),), order=order)
    return [lower, upper]


def state(bodies, shift=0.0, pressure=10.0):
    """Fields of the blocks: ``upper`` moved down by ``shift``, a uniform ``pressure`` between
    them as consistent nodal forces (upper: its bottom facets; lower: spread equally over its
    top nodes under the upper block, so the totals balance)."""
    lower, upper = bodies
    out = {}
    for b in bodies:
        out[b.name] = SimpleNamespace(displacement=np.zeros((b.npoints, 2)),
                                      contact_force=np.zeros((b.npoints, 2)))
    out["upper"].displacement[:, 1] = -shift
    fp = upper.facet_points(upper.mesh.boundaries["bottom"])
    X = upper.points
    for facet in fp:
        L = abs(X[0, facet[1]] - X[0, facet[0]])
        share = [L / 6, L / 6, 2 * L / 3] if len(facet) == 3 else [L / 2, L / 2]
        for k, s in zip(facet, share):
            out["upper"].contact_force[k, 1] += pressure * s  # pushed up: into the block
    balance(lower, out)
    return out


def balance(lower, fields):
    """Spread minus the upper block's total force equally over the lower block's top nodes
    under it."""
    top = lower.boundary_points("top")
    x = lower.points[0, top]
    under = top[(x > 0.2 + 1e-9) & (x < 0.8 - 1e-9)]
    total = fields["upper"].contact_force.sum(axis=0)
    fields["lower"].contact_force[under] = -total / len(under)


# -- the three measures on hand-made states ---------------------------------------------------


@pytest.mark.parametrize("order", [1, 2])
def test_a_balanced_compressive_touching_state_passes(order):
    bodies = blocks(order)
    inv = step_invariants(bodies, None, state(bodies), TOL)
    assert inv.ok, inv.message()
    assert inv.force_balance < 1e-14
    assert inv.max_penetration <= 1e-14  # the bottom nodes of the upper block touch the lower
    assert inv.tension == 0.0
    assert inv.message() == ""
    record = inv.record()
    assert record["passed"] and record["failed"] == []
    json.dumps(record)  # plain JSON values


def test_forces_that_do_not_sum_to_zero_break_the_force_balance():
    bodies = blocks()
    fields = state(bodies)
    fields["lower"].contact_force *= 1.01
    inv = step_invariants(bodies, None, fields, TOL)
    assert not inv.ok and inv.failed() == ["force balance"]
    assert inv.force_balance == pytest.approx(0.01 / 1.01, rel=1e-9)
    assert "invariant (a) force balance" in inv.message() and "'lower'" in inv.message()


def test_a_body_pushed_into_another_breaks_no_interpenetration():
    bodies = blocks()
    inv = step_invariants(bodies, None, state(bodies, shift=0.01), TOL)
    assert not inv.ok and inv.failed() == ["interpenetration"]
    assert inv.penetration == pytest.approx(0.01, rel=1e-9)
    assert inv.max_penetration == pytest.approx(0.01, rel=1e-9)
    assert inv.allowed == pytest.approx(TOL)  # straight faces: no faceting allowance
    w = inv.where
    assert {w["body"], w["into"]} == {"lower", "upper"}
    assert w["deformed_depth"] == pytest.approx(0.01) and w["linearised_depth"] == pytest.approx(
        0.01)
    msg = inv.message()
    assert "invariant (b) no interpenetration" in msg and f"node {w['node']} of body" in msg


def test_an_overlap_within_the_tolerance_passes_and_pairs_are_respected():
    bodies = blocks()
    assert step_invariants(bodies, None, state(bodies, shift=0.5 * TOL), TOL).ok
    # bodies that may not touch are not checked against each other
    assert step_invariants(bodies, [], state(bodies, shift=0.01), TOL).separated
    assert not step_invariants(bodies, [("upper", "lower")], state(bodies, shift=0.01),
                               TOL).separated


def test_a_tensile_force_breaks_no_tension():
    bodies = blocks()
    fields = state(bodies)
    upper = fields["upper"].contact_force
    k = int(np.flatnonzero(upper[:, 1] > 0)[2])
    pull = upper[k, 1]
    upper[k, 1] = -pull  # pulled down, out of the block: tension
    lower = fields["lower"].contact_force
    under = np.flatnonzero(lower[:, 1])
    lower[under, 1] += 2 * pull / len(under)  # the totals still balance, lower still pressed
    assert lower[under, 1].max() < 0
    inv = step_invariants(bodies, None, fields, TOL)
    assert inv.failed() == ["tension"]
    assert inv.tension_where == {"body": "upper", "node": k, "value": pytest.approx(pull)}
    assert "invariant (c) no tension" in inv.message() and f"node {k} of body 'upper'" in (
        inv.message())


def test_a_force_along_a_face_is_not_tension_and_quadratic_vertices_read_with_midpoints():
    bodies = blocks()
    fields = state(bodies)
    # a side node of the upper block pushed down, along its face: no normal component
    side = int(np.flatnonzero((bodies[1].points[0] < 0.2 + 1e-9)
                              & (bodies[1].points[1] > 0.05))[0])
    fields["upper"].contact_force[side] = (0.0, -1.0)
    lower = fields["lower"].contact_force
    under = np.flatnonzero(lower[:, 1])
    lower[under, 1] += 1.0 / len(under)
    assert step_invariants(bodies, None, fields, TOL).ok
    # quadratic: a traction that is 1 at one vertex and 0 at every other node gives the
    # vertices two facets away -L/30 (consistent forces: a column of the facet mass matrix);
    # read with their facets' midpoints they are compressive
    quad = blocks(order=2)
    fields = state(quad, pressure=0.0)
    upper = quad[1]
    fp = upper.facet_points(upper.mesh.boundaries["bottom"])
    centre = fp[np.argsort(upper.points[0, fp[:, 0]])[2], 0]
    mass = np.array([[4.0, -1.0, 2.0], [-1.0, 4.0, 2.0], [2.0, 2.0, 16.0]]) / 30
    f = fields["upper"].contact_force
    for facet in fp[(fp[:, :2] == centre).any(axis=1)]:
        L = float(np.ptp(upper.points[0, facet[:2]]))
        f[facet, 1] += 100.0 * L * mass[:, list(facet).index(centre)]
    balance(quad[0], fields)
    assert (f[:, 1] < 0).sum() == 2  # the two far vertices, pulled by the nodal test's reading
    inv = step_invariants(quad, None, fields, TOL)
    assert inv.ok and inv.tension == 0.0
    assert inv.tension_tolerance == pytest.approx(5e-2)


def test_turning_angles_faceting_allowance_and_symmetry_planes():
    square = Body("square", rect(MeshQuad, 0, 1, 0, 1, 4, 4), MAT)
    g = _Polygon(_Boundary.of(square), square.points[:, _Boundary.of(square).nodes].T)
    corners = np.isclose(g.x, 0).sum(axis=1) + np.isclose(g.x, 1).sum(axis=1) == 2
    assert np.allclose(g.turning[corners], np.pi / 2) and np.allclose(g.turning[~corners], 0)
    # held along x on its left side: a symmetry plane; its corners there are no corners
    half = Body("half", rect(MeshQuad, 0, 1, 0, 1, 4, 4), MAT,
                supports=(Support("left", ("x",)),))
    b = _Boundary.of(half)
    g = _Polygon(b, half.points[:, b.nodes].T)
    left = np.isclose(g.x[:, 0], 0)
    assert np.allclose(g.turning[left & corners], 0)
    assert np.allclose(g.turning[~left & corners], np.pi / 2)
    assert b.mirror.sum() == 4

    # a diamond whose lower corner (90 degrees) presses into the middle of a facet of length
    # 0.125: it may protrude (L/2) tan(45 deg) = 0.0625 there, not more
    diamond = MeshTri.init_tensor(np.linspace(-1, 1, 5), np.linspace(-1, 1, 5))
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    p = 0.05 / np.sqrt(2) * np.array([[c, -s], [s, c]]) @ diamond.p
    p += np.array([[0.5625], [0.05]])
    diamond = MeshTri(p, diamond.t)
    bodies = [blocks()[0], Body("diamond", diamond, MAT)]
    under = np.flatnonzero(np.isclose(bodies[0].points[1], 0)
                           & np.isin(np.round(bodies[0].points[0], 9), (0.5, 0.625)))
    tip = int(np.argmin(diamond.p[1]))
    for shift, touching, ok in ((0.01, True, True), (0.08, True, False), (0.01, False, False)):
        fields = {b.name: SimpleNamespace(displacement=np.zeros((b.npoints, 2)),
                                          contact_force=np.zeros((b.npoints, 2)))
                  for b in bodies}
        fields["diamond"].displacement[:, 1] = -shift
        if touching:  # the facet's nodes carry the corner's force
            fields[bodies[0].name].contact_force[under, 1] = -1.0
            fields["diamond"].contact_force[tip, 1] = 2.0
        inv = step_invariants(bodies, None, fields, TOL)
        assert inv.separated == ok
        assert inv.where["body"] == "diamond" and inv.penetration == pytest.approx(shift)
        # where nothing touches the facet, a corner inside it is contact missed, not faceting
        assert inv.allowed == pytest.approx(TOL + (0.0625 if touching else 0.0))


def test_a_corner_slid_along_a_tilted_face_is_read_along_that_face():
    """A block's corner (turning 90 degrees) under the middle of a facet of a square turned 30
    degrees, the square moved straight down until the corner lies 1e-3 inside it: linear
    theory reads the depth along the facet's normal (exact for a translation). The corner's
    nodal normal is only the bisector of its two sides, and the square's slide along the
    facet read along it is a false gap of 3.7e-3 (random model 2d-52 of seed 3 passed so)."""
    lower = blocks()[0]
    gap, inside = 0.03, 1e-3
    m = np.array([0.5, -np.sqrt(0.75)])  # the facet's outward normal: towards the corner
    centre = -gap * m - 0.25 * m  # the facet's middle right above the corner, gap away
    local = MeshTri.init_tensor(np.linspace(-0.25, 0.25, 4), np.linspace(-0.25, 0.25, 4))
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    square = Body("square", MeshTri(np.array([[c, -s], [s, c]]) @ local.p + centre[:, None],
                                    local.t), MAT)
    fields = {b.name: SimpleNamespace(displacement=np.zeros((b.npoints, 2)),
                                      contact_force=np.zeros((b.npoints, 2)))
              for b in (lower, square)}
    fields["square"].displacement[:, 1] = -(gap + inside) / c
    inv = step_invariants([lower, square], None, fields, TOL)
    assert not inv.separated
    w = inv.where
    assert (w["body"], w["into"]) == ("lower", "square")
    assert (w["x"], w["y"]) == (0.0, 0.0)
    assert w["deformed_depth"] == pytest.approx(inside, rel=1e-9)
    assert w["linearised_depth"] == pytest.approx(inside, rel=1e-9)
    assert inv.allowed == pytest.approx(TOL)  # nothing touches the facet: no faceting


def test_a_node_inside_only_on_the_deformed_geometry_is_recorded_not_failed(monkeypatch):
    """Small kinematics: a node that linear theory reads outside but that lies inside on the
    deformed geometry beyond its allowance passes (b) (the smaller reading is judged) and is
    recorded as ``second_order`` (the solver warns about it). Linear theory's reading is made
    here to say 1e-3 outside while the upper block lies 1e-3 inside the lower one."""
    bodies = blocks()
    shift = 1e-3
    real = PLANE.linearised_depth

    def outside(reference, i, j, node, cur):
        depth, second = real(reference, i, j, node, cur)
        return depth - 2 * shift, second

    fields = state(bodies, shift=shift, pressure=0.0)
    assert step_invariants(bodies, None, fields, TOL).second_order is None  # read alike
    monkeypatch.setattr(InvariantCheck, "kind", property(
        lambda self: dataclasses.replace(PLANE, linearised_depth=outside)))
    inv = step_invariants(bodies, None, fields, TOL)
    assert inv.separated and inv.ok
    w = inv.second_order
    assert w is not None and {w["body"], w["into"]} == {"upper", "lower"}
    # round-off of O(1) coordinates on a depth of 1e-3
    assert w["deformed_depth"] == pytest.approx(shift, rel=1e-9)
    assert w["linearised_depth"] < 0  # (made 2e-3 less than its own reading)
    assert w["allowed"] == pytest.approx(TOL)  # no force: no faceting allowance
    assert w["beyond"] == pytest.approx(shift - TOL, rel=1e-9)
    assert inv.record()["second_order"] == w


@pytest.mark.parametrize("settings, order, remedy", [
    ({}, 1, 'reads it 0.002 outside: the answer holds as linear theory reads '
     'it, its deformed geometry is off by about that depth; kinematics = "total" reads'),
    ({}, 2, 'kinematics = "total" (with linear elements) reads'),
    ({"variant": "thesis"}, 1, 'the paired variant (the default contact method) with '
     'kinematics = "total" reads'),
    ({"method": "penalty"}, 1, 'the paired variant (the default contact method) with '
     'kinematics = "total" reads')])
def test_the_second_order_warning_names_the_step_node_and_a_remedy_the_model_can_take(
        caplog, settings, order, remedy):
    """Once per run, at the step furthest beyond (not the first): large kinematics for the
    paired variant, linear elements where a body is quadratic, and for a formulation with
    small kinematics only (the thesis variant, the baselines) the paired variant."""
    def step(k, beyond):
        return SimpleNamespace(step=k, load_factor=k / 4, invariants={"second_order": {
            "body": "upper", "node": 10 + k, "into": "lower", "deformed_depth": 1e-3 + beyond,
            "linearised_depth": -2e-3, "allowed": 1e-3, "beyond": beyond}})

    analysis = SimpleNamespace(
        model=SimpleNamespace(bodies=[SimpleNamespace(name="upper", order=order),
                                      SimpleNamespace(name="lower", order=1)],
                              contact=ContactSettings(**settings)))
    steps = [step(1, 1e-4), step(2, 3e-4), SimpleNamespace(step=3, invariants={}),
             step(4, 2e-4)]
    with caplog.at_level(logging.WARNING, logger="vfem"):
        Analysis.warn_second_order(analysis, steps)
    messages = [r.getMessage() for r in caplog.records]
    assert len(messages) == 1
    assert messages[0].startswith("step 2 (load factor 0.5): node 12 of body 'upper' lies "
                                  "0.0013 inside body 'lower'")
    assert remedy in messages[0]
    caplog.clear()
    Analysis.warn_second_order(analysis, steps[2:3])  # nothing recorded: nothing said
    assert not caplog.records


# -- the solver ---------------------------------------------------------------------------------


def punch_model(max_step_cuts=2):
    lower = Body("flat", rect(MeshQuad, 0, 1.5, -0.5, 0, 15, 5), MAT,
                 supports=(Support("bottom"),))
    punch = Body("punch", rect(MeshTri, 0.5, 1.0, 0, 0.5, 6, 6), MAT,
                 prescribed=(PrescribedDisplacement("top", "y", -0.002),
                             PrescribedDisplacement("top", "x", 0.0)),
                 contact_boundaries=("bottom",))
    return Model("punch", [lower, punch], ContactSettings(max_step_cuts=max_step_cuts),
                 load_factors=(1.0,))


def unbalanced(monkeypatch, attempts):
    """Make the first ``attempts`` converged states carry 10 % more force on the punch."""
    real = Analysis._fields
    calls = []

    def fields(self, state, result):
        out = real(self, state, result)
        calls.append(state.load_factor)
        if len(calls) <= attempts:
            out["punch"].contact_force *= 1.1
        return out

    monkeypatch.setattr(Analysis, "_fields", fields)
    return calls


def test_a_state_that_breaks_an_invariant_is_cut_then_stops_the_analysis(monkeypatch, caplog):
    calls = unbalanced(monkeypatch, attempts=100)
    with caplog.at_level(logging.INFO, logger="vfem.solver"):
        result = Analysis(punch_model(max_step_cuts=2)).run()
    assert not result.converged and result.steps == []
    assert calls == [1.0, 0.5, 0.25]  # the step, then cut twice
    assert sum("cutting the increment" in r.message for r in caplog.records) == 2
    msg = result.message
    assert msg.startswith("step 1 (load factor 0 -> 0.25) failed with the increment cut 2 times")
    assert "invariant (a) force balance violated" in msg and "body 'punch'" in msg
    assert "a contact formulation error" in msg  # the remedy of diagnosis()


def test_a_cut_step_that_then_satisfies_the_invariants_goes_on(monkeypatch):
    calls = unbalanced(monkeypatch, attempts=1)
    result = Analysis(punch_model()).run()
    assert result.converged
    assert calls[:2] == [1.0, 0.5]
    assert [s.load_factor for s in result.steps] == [0.5, 1.0]
    assert result.steps[0].cuts == 1
    for s in result.steps:
        assert s.invariants["passed"] and s.invariants["force_balance"] < 1e-12
        assert s.invariants["tension"] == 0.0
    assert result.timings["invariants_s"] > 0


def test_an_invariant_not_enforced_is_recorded_and_logged(monkeypatch, caplog):
    """Interpenetration injected (the punch's displacement pushed 1e-3 into the flat): a stop
    if the solver enforces it (``vfem.solver.ENFORCED``), else recorded in the step."""
    from vfem import solver

    real = Analysis._fields

    def fields(self, state, result):
        out = real(self, state, result)
        out["punch"].displacement[:, 1] -= 1e-3
        return out

    monkeypatch.setattr(Analysis, "_fields", fields)
    with caplog.at_level(logging.WARNING, logger="vfem.solver"):
        result = Analysis(punch_model()).run()
    if "interpenetration" in solver.ENFORCED:
        assert not result.converged and "invariant (b) no interpenetration" in result.message
        return
    assert result.converged
    inv = result.steps[-1].invariants
    assert inv["failed"] == ["interpenetration"] and inv["passed"]
    assert inv["penetration"] > 9e-4 and inv["where"]["body"] in ("punch", "flat")
    assert any("recorded, not enforced: interpenetration" in r.message for r in caplog.records)


def test_invariant_violation_is_an_analysis_error():
    assert issubclass(InvariantViolation, Exception)
    from vfem.errors import AnalysisError

    assert issubclass(InvariantViolation, AnalysisError)


def test_checkpoints_keep_the_invariants(tmp_path):
    model = punch_model()
    _, result = run_writing(model, tmp_path)
    back = checkpoint.read(tmp_path, model)
    assert [s.invariants for s in back.steps] == [s.invariants for s in result.steps]
    assert back.steps[-1].invariants["passed"]


@pytest.mark.slow
def test_summary_json_and_closing_screen_show_the_invariants(tmp_path, capsys):
    out = tmp_path / "patch"
    assert main(["run", "examples/patch/4x7_nu0.3.toml", "--out", str(out)]) == 0
    steps = json.loads((out / "summary.json").read_text())["steps"]
    assert steps
    for s in steps:
        inv = s["invariants"]
        for key in ("force_balance", "max_penetration_any_body", "allowed", "where", "tension",
                    "passed"):
            assert key in inv
        assert inv["passed"] and inv["force_balance"] < 1e-12
    text = capsys.readouterr().out
    assert "invariants: forces balance to" in text and "no tension" in text


def test_invariant_check_takes_a_model_and_its_pairs():
    model = punch_model()
    check = InvariantCheck(model, None, TOL)
    assert check.pairs == [(0, 1), (1, 0)]
    assert InvariantCheck(model.bodies, [], TOL).pairs == []
