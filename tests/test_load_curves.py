"""Load curves (issue 17, item 6): every traction, prescribed displacement and platen force may
follow an ``amplitude``, ``[[load_factor, multiplier], ...]``, in small and large kinematics.

Small kinematics superposes one solve per curve, which is exact because frictionless
small-strain contact is path independent: a step on a curve must give the proportional model's
answer at the curve's multiplier to round-off. Large kinematics follows the curve step by step;
there the answers agree to the solvers' tolerances.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import vfem
from vfem.bodies import Body, Platen, PrescribedDisplacement, Support, Traction, multiplier
from vfem.cli import main
from vfem.errors import InputError
from vfem.solver import Model

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "load_curve.toml"
#: load, hold, unload
CURVE = ((0.0, 0.0), (0.5, 1.0), (0.75, 1.0), (1.0, 0.0))


def _with_kinematics(config, kinematics: str):
    bodies = tuple(dataclasses.replace(b, kinematics=kinematics) for b in config.bodies)
    return dataclasses.replace(config, bodies=bodies)


def _forces(step, name: str) -> np.ndarray:
    return step.bodies[name].contact_force


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


# -- (a) load, hold, unload ---------------------------------------------------------------------


@pytest.fixture(scope="module", params=["small", "total"])
def pressed(request):
    """The example (a punch pressed into a block by a load curve), solved in both kinematics."""
    config = _with_kinematics(vfem.load(EXAMPLE), request.param)
    result = vfem.solve(config.build(EXAMPLE.parent))
    assert result.converged, result.message
    return request.param, config, result


def test_the_example_follows_its_curve(pressed):
    kinematics, config, result = pressed
    factors = [s.load_factor for s in result.steps]
    assert factors == list(config.steps.load_factors)
    assert config.bodies[1].prescribed[0].amplitude == CURVE
    full = next(s for s in result.steps if s.load_factor == 0.5)
    total = _forces(full, "block").sum(axis=0)
    assert total[1] < -10.0  # pressed: the punch pushes the block down
    for step in result.steps:
        m = multiplier(CURVE, step.load_factor)
        block, punch = _forces(step, "block"), _forces(step, "punch")
        # the contact forces of the two bodies balance
        assert np.abs(block.sum(axis=0) + punch.sum(axis=0)).max() <= 1e-9 * abs(total[1])
        assert step.invariants["passed"], step.invariants
        # the punch's top is where its curve puts it
        top = step.bodies["punch"].displacement[:, 1].min()
        assert top == pytest.approx(-0.01 * m, abs=1e-12) if m == 0 else top <= -0.01 * m
        if m == 1.0:  # the hold steps are the fully loaded state (large: Newton's round-off)
            same = 1e-12 if kinematics == "small" else 1e-9
            assert _relative(block, _forces(full, "block")) <= same
            assert _relative(step.bodies["punch"].displacement,
                             full.bodies["punch"].displacement) <= same
    last = result.steps[-1]
    assert multiplier(CURVE, last.load_factor) == 0.0
    # unloaded: no contact force left, the bodies back at rest
    assert np.abs(_forces(last, "block")).max() <= 1e-12 * abs(total[1])
    assert np.abs(last.bodies["punch"].displacement).max() <= 1e-12


def test_reactions_equal_the_contact_forces_at_every_step(pressed):
    """Issue 17's acceptance: loads, holds and unloads; at every step each body's support
    reaction equals minus its contact force (no other load acts) within 1e-8 of the largest
    contact force, and the two bodies' reactions balance."""
    kinematics, _, result = pressed
    largest = max(np.abs(_forces(s, "block").sum(axis=0)).max() for s in result.steps)
    for step in result.steps:
        for name in ("block", "punch"):
            r = step.bodies[name]
            assert np.abs(r.reaction_total + r.contact_force.sum(axis=0)).max() <= 1e-8 * largest
        total = step.bodies["block"].reaction_total + step.bodies["punch"].reaction_total
        assert np.abs(total).max() <= 1e-8 * largest
    unloaded = result.steps[-1].bodies["block"].reaction_total
    assert np.abs(unloaded).max() <= 1e-8 * largest


def test_small_kinematics_is_the_proportional_answer_at_the_multiplier(pressed):
    """Path independence: each step equals the proportional model at the curve's multiplier."""
    kinematics, config, result = pressed
    multipliers = sorted({multiplier(CURVE, s.load_factor) for s in result.steps} - {0.0})
    body = config.bodies[1]
    plain = dataclasses.replace(body, prescribed=tuple(
        dataclasses.replace(pd, amplitude=None) for pd in body.prescribed))
    proportional = dataclasses.replace(
        config, bodies=(config.bodies[0], plain),
        steps=dataclasses.replace(config.steps, load_factors=tuple(multipliers)))
    reference = vfem.solve(proportional.build(EXAMPLE.parent))
    assert reference.converged, reference.message
    at = {s.load_factor: s for s in reference.steps}
    tolerance = 1e-10 if kinematics == "small" else 1e-6
    for step in result.steps:
        m = multiplier(CURVE, step.load_factor)
        if m == 0.0:
            continue
        for name in ("block", "punch"):
            assert _relative(_forces(step, name), _forces(at[m], name)) <= tolerance
            assert _relative(step.bodies[name].displacement,
                             at[m].bodies[name].displacement) <= tolerance


def test_the_example_is_quick():
    """examples/load_curve.toml is one of tests/test_examples_invariants.py's cases (it runs
    every examples/**/*.toml); keep it well under 3 s."""
    import time

    t0 = time.perf_counter()
    result = vfem.solve(vfem.load(EXAMPLE).build(EXAMPLE.parent))
    assert result.converged
    assert time.perf_counter() - t0 < 3.0


# -- (b) tractions, (c) a platen force ----------------------------------------------------------


def _cantilever(kinematics: str, beam_load, block_load) -> list[Body]:
    """A cantilever (clamped on the left) over a block whose top it touches at rest; a traction
    presses the beam down onto the block, another pushes the block sideways."""
    beam = Body("beam", vfem.mesh.rectangle(0.0, 0.0, 2.0, 0.2, nx=20, ny=2),
                vfem.LinearElastic(1000.0, 0.3), supports=(Support("left"),),
                tractions=(beam_load,), contact_boundaries=("bottom",), kinematics=kinematics)
    block = Body("block", vfem.mesh.rectangle(1.0, -0.5, 1.2, 0.5, nx=12, ny=5),
                 vfem.LinearElastic(1000.0, 0.3), supports=(Support("bottom"),),
                 tractions=(block_load,), contact_boundaries=("top",), kinematics=kinematics)
    return [beam, block]


def _scaled(load, factor: float):
    """The same load without a curve, its value times ``factor``."""
    if isinstance(load, Traction):
        return Traction(load.boundary, tuple(factor * v for v in load.value))
    return Platen(load.boundary, load.component, factor * load.force)


@pytest.mark.parametrize("kinematics", ["small", pytest.param("total", marks=pytest.mark.slow)])
def test_a_traction_on_a_curve_is_the_proportional_traction_at_its_multiplier(kinematics):
    curve = ((0.0, 0.0), (0.5, 1.0), (1.0, 0.25))
    beam_load = Traction("top", (0.0, -0.006), amplitude=curve)
    block_load = Traction("right", (-0.5, 0.0))  # proportional
    factors = (0.25, 0.5, 0.75, 1.0)
    bodies = _cantilever(kinematics, beam_load, block_load)
    result = vfem.solve(Model("curved", bodies, load_factors=factors))
    assert result.converged, result.message
    tolerance = 1e-10 if kinematics == "small" else 1e-6
    for step in result.steps:
        lf, m = step.load_factor, multiplier(curve, step.load_factor)
        assert m == {0.25: 0.5, 0.5: 1.0, 0.75: 0.625, 1.0: 0.25}[lf]
        # the same model with each load's value at its multiplier, in one proportional step
        same = _cantilever(kinematics, _scaled(beam_load, m), _scaled(block_load, lf))
        reference = vfem.solve(Model("plain", same, load_factors=(1.0,))).steps[-1]
        contact = _forces(step, "beam")
        applied = -0.006 * 2.0 * m  # the beam's load along y at the curve's multiplier
        assert contact[:, 1].sum() > 0.1 * -applied, "the block must carry part of the beam"
        for name in ("beam", "block"):
            assert _relative(_forces(step, name), _forces(reference, name)) <= tolerance
            assert _relative(step.bodies[name].displacement,
                             reference.bodies[name].displacement) <= tolerance
        # contact forces balance, and the clamp holds the beam against the load at the curve's
        # multiplier and the contact force (the reaction reads the loads at the load factor)
        assert np.abs(contact.sum(axis=0) + _forces(step, "block").sum(axis=0)).max() \
            <= 1e-9 * np.abs(contact).sum()
        beam = bodies[0]
        u = step.bodies["beam"].displacement.ravel()
        clamp = beam.reaction(u, "left", "y", lf, contact.ravel())
        assert clamp == pytest.approx(-(applied + contact[:, 1].sum()), rel=1e-8)


def _platen_model(kinematics: str, platen: Platen) -> list[Body]:
    block = Body("block", vfem.mesh.rectangle(-1.0, -1.0, 2.0, 1.0, nx=16, ny=8),
                 vfem.LinearElastic(1000.0, 0.3), supports=(Support("bottom"),),
                 contact_boundaries=("top",), kinematics=kinematics)
    punch = Body("punch", vfem.mesh.rectangle(-0.5, 0.0, 1.0, 0.5, nx=12, ny=6),
                 vfem.LinearElastic(10000.0, 0.3), supports=(Support("top", ("x",)),),
                 platen=platen, contact_boundaries=("bottom",), kinematics=kinematics)
    return [block, punch]


@pytest.mark.parametrize("kinematics", ["small", pytest.param("total", marks=pytest.mark.slow)])
def test_a_platen_force_on_a_curve(kinematics):
    curve = ((0.0, 0.0), (0.5, 1.0), (1.0, 0.5))
    platen = Platen("top", "y", -10.0, amplitude=curve)
    assert platen.force_at(0.75) == pytest.approx(-7.5)
    result = vfem.solve(Model("platen", _platen_model(kinematics, platen),
                              load_factors=(0.25, 0.5, 0.75, 1.0)))
    assert result.converged, result.message
    tolerance = 1e-8 if kinematics == "small" else 1e-6
    for step in result.steps:
        m = multiplier(curve, step.load_factor)
        block, punch = _forces(step, "block"), _forces(step, "punch")
        # the contact carries the platen's force at the curve's multiplier, in balance
        assert punch[:, 1].sum() == pytest.approx(10.0 * m, rel=1e-6)
        assert block[:, 1].sum() == pytest.approx(-10.0 * m, rel=1e-6)
        reference = vfem.solve(Model("plain", _platen_model(kinematics, _scaled(platen, m)),
                                     load_factors=(1.0,))).steps[-1]
        assert step.platen_displacement == pytest.approx(reference.platen_displacement,
                                                         rel=tolerance)
        assert _relative(punch, _forces(reference, "punch")) <= 1e-6


def test_a_baseline_follows_the_curves_too():
    """The classical methods (one global system) scale each curve's loads by its multiplier."""
    config = dataclasses.replace(vfem.load(EXAMPLE), contact=vfem.ContactSettings(
        method="lagrange"))
    result = vfem.solve(config.build(EXAMPLE.parent))
    assert result.converged, result.message
    full = next(s for s in result.steps if s.load_factor == 0.5)
    for step in result.steps:
        m = multiplier(CURVE, step.load_factor)
        expected = m * full.bodies["block"].contact_force
        assert np.abs(step.bodies["block"].contact_force - expected).max() <= 1e-9 * np.abs(
            expected).max(initial=1.0)


# -- (d) validation -----------------------------------------------------------------------------


BAD_CURVES = [
    ([[0.0, 0.0], [1.0]], "must be [load factor, multiplier] pairs"),
    ([[0.0, 0.0, 1.0]], "must be [load factor, multiplier] pairs"),
    ([], "must be [load factor, multiplier] pairs"),
    ("ramp", "must be [load factor, multiplier] pairs"),
    ([[0.0, 0.0], [1.0, math.nan]], "must hold finite numbers"),
    ([[0.0, 0.0], [math.inf, 1.0]], "must hold finite numbers"),
    ([[0.0, 0.0], [0.5, 1.0], [0.5, 0.0]],
     "strictly increasing load factors; 0.5 is followed by 0.5"),
    ([[1.0, 0.0], [0.5, 1.0]], "strictly increasing load factors; 1 is followed by 0.5"),
]


@pytest.mark.parametrize("kinematics", ["small", "total"])
@pytest.mark.parametrize(("curve", "message"), BAD_CURVES)
@pytest.mark.parametrize("load", ["traction", "prescribed displacement", "platen"])
def test_a_bad_curve_is_one_message_naming_body_load_and_boundary(load, curve, message,
                                                                   kinematics):
    mesh = vfem.mesh.rectangle(nx=2, ny=2)
    loads = {"traction": {"tractions": (Traction("top", (0.0, -1.0), amplitude=curve),)},
             "prescribed displacement": {
                 "prescribed": (PrescribedDisplacement("top", "y", -0.1, amplitude=curve),)},
             "platen": {"platen": Platen("top", "y", -1.0, amplitude=curve)}}[load]
    body = Body("pad", mesh, vfem.LinearElastic(1000.0, 0.3), supports=(Support("bottom"),),
                kinematics=kinematics, **loads)
    with pytest.raises(InputError) as info:
        body.validate()
    assert str(info.value).startswith(f"body 'pad': {load} on 'top': the amplitude")
    assert message in str(info.value)


def test_small_kinematics_takes_curves():
    """The refusal "needs large kinematics" is gone: every load of a small body may have one."""
    body = Body("pad", vfem.mesh.rectangle(nx=2, ny=2), vfem.LinearElastic(1000.0, 0.3),
                supports=(Support("bottom"),),
                prescribed=(PrescribedDisplacement("left", "x", 0.01, amplitude=CURVE),),
                tractions=(Traction("top", (0.0, -1.0), amplitude=CURVE),
                           Traction("right", (1.0, 0.0), amplitude=CURVE)))
    body.setup()
    # the proportional case (holding the supports) and one for the shared curve
    assert [c.amplitude for c in body.load_cases] == [None, CURVE]
    for lf in (0.25, 0.6, 1.0, 1.5):
        m = multiplier(CURVE, lf)
        assert np.allclose(body.applied_load(lf), m * body.f_load, rtol=0, atol=1e-15)
        assert np.allclose(body.load_displacement(lf), m * body.u_load, rtol=0, atol=1e-15)


def _file_with(tmp_path: Path, table: str) -> Path:
    text = EXAMPLE.read_text(encoding="utf-8").replace(
        "amplitude = [[0.0, 0.0], [0.5, 1.0], [0.75, 1.0], [1.0, 0.0]]", f"amplitude = {table}")
    assert f"amplitude = {table}" in text
    path = tmp_path / "bad_curve.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(("table", "message"), [
    ("[[0.0, 0.0], [0.5, 1.0], [0.25, 0.0]]",
     "body 'punch': prescribed displacement on 'top': the amplitude must have strictly "
     "increasing load factors; 0.5 is followed by 0.25"),
    ("[[0.0, 0.0, 1.0]]", "bodies[1] (punch).prescribed[0].amplitude[0]: expected 2 values, got 3"),
    ("[[0.0, 0.0], [1.0, nan]]",
     "bodies[1] (punch).prescribed[0].amplitude[1][1]: must be a finite number, got nan"),
    ("[0.0, 1.0]", "bodies[1] (punch).prescribed[0].amplitude[0]: expected [number, number]"),
])
def test_a_bad_curve_in_an_input_file_exits_2(table, message, tmp_path, capsys):
    path = _file_with(tmp_path, table)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert str(path) in err and err.count("\n") == 1 and "Traceback" not in err


def test_the_example_checks():
    assert main(["check", str(EXAMPLE)]) == 0


def test_the_documented_curve_is_the_example_file():
    """docs/input.md shows the key with the numbers of examples/load_curve.toml, which the
    tests above (and tests/test_examples_invariants.py) run."""
    docs = (ROOT / "docs" / "input.md").read_text(encoding="utf-8")
    example = EXAMPLE.read_text(encoding="utf-8")
    block = docs.split("loads, holds and unloads a punch under small kinematics:\n\n```toml\n")[1]
    for line in block.split("```")[0].strip().splitlines():
        assert line in example.splitlines(), line


def test_a_curve_that_never_loads_is_warned_about_and_an_empty_one_shown_as_written(caplog):
    import logging

    from vfem.errors import InputError
    from vfem.solver import Analysis

    config = vfem.load(EXAMPLE)
    punch = config.bodies[1]
    idle = dataclasses.replace(punch.prescribed[0], amplitude=((1.0, 0.0), (2.0, 1.0)))
    model = dataclasses.replace(config, bodies=(config.bodies[0], dataclasses.replace(
        punch, prescribed=(idle,)))).build(EXAMPLE.parent)
    with caplog.at_level(logging.WARNING, logger="vfem.solver"):
        Analysis(model).setup()
    assert any("is 0 at every load factor of the steps" in r.message and "'punch'" in r.message
               for r in caplog.records)
    empty = dataclasses.replace(punch.prescribed[0], amplitude=())
    with pytest.raises(InputError) as info:
        dataclasses.replace(config, bodies=(config.bodies[0], dataclasses.replace(
            punch, prescribed=(empty,)))).build(EXAMPLE.parent)
    assert "got []" in str(info.value)
