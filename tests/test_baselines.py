"""The classical baselines (contact.method penalty, lagrange, augmented): their physics on Hertz
and the patch test, their parameters, and that they answer like vfem does (same results)."""

import dataclasses
import json

import numpy as np
import pytest

from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.examples import hertz, patch
from vfem.solver import Analysis

METHODS = ("penalty", "lagrange", "augmented")


def solve_hertz(**kw):
    p = hertz.HertzParameters(**kw)
    result = Analysis(hertz.build(p)).run()
    assert result.converged, result.message
    return p, result


@pytest.fixture(scope="module")
def hertz_runs():
    """Each method on the level-0 Hertz model, the bodies in both orders."""
    return {(m, swap): solve_hertz(method=m, swap_bodies=swap)
            for m in METHODS for swap in (False, True)}


def shortest_cylinder_facet(result):
    return float(next(s for s in result.surfaces if s.body.name == "cylinder").lengths.min())


@pytest.mark.parametrize("method", METHODS)
def test_hertz_peak_pressure(hertz_runs, method):
    p, result = hertz_runs[method, False]
    e = hertz.evaluate(result, p)
    # node-to-segment, non-matching meshes, 12 facets across a: +0.010 % for all three
    assert abs(e["p_max_error"]) < 2e-3
    assert e["contact_nodes_cylinder"] == 13
    assert e["rms_error_over_p0"] < 0.012


@pytest.mark.parametrize("method", METHODS)
def test_forces_balance_between_the_bodies_and_with_the_load(hertz_runs, method):
    p, result = hertz_runs[method, False]
    e = hertz.evaluate(result, p)
    last = result.steps[-1].bodies
    total_cyl = last["cylinder"].contact_force.sum(axis=0)
    total_flat = last["flat"].contact_force.sum(axis=0)
    np.testing.assert_allclose(total_cyl, -total_flat, rtol=1e-12, atol=1e-9)
    # the penalty's huge stiffness (1e3 x the flat's E' / h) costs a few digits of round-off
    assert e["total_contact_force"] == pytest.approx(p.force, rel=1e-7)
    # the master's nodal forces are the slave's spread on it: the flat reads a pressure too
    assert last["flat"].contact_pressure.max() > 0.5 * e["p0_theory"]


@pytest.mark.parametrize("method", METHODS)
def test_the_order_of_the_bodies_changes_nothing(hertz_runs, method):
    a = hertz_runs[method, False][1].steps[-1].bodies
    b = hertz_runs[method, True][1].steps[-1].bodies
    for name in ("cylinder", "flat"):
        np.testing.assert_allclose(a[name].contact_pressure, b[name].contact_pressure,
                                   rtol=1e-7, atol=1e-7 * 3e4)  # round-off x penalty
        np.testing.assert_array_equal(a[name].contact_status, b[name].contact_status)


def test_lagrange_closes_the_gaps_exactly(hertz_runs):
    _, result = hertz_runs["lagrange", False]
    h = shortest_cylinder_facet(result)
    for step in result.steps:
        cyl = step.bodies["cylinder"]
        on = cyl.contact_status > 0
        assert on.sum() >= 3
        assert np.abs(cyl.penetration[on]).max() < 1e-14 * h  # round-off
        assert step.history[-1].max_penetration < 1e-14 * h
        assert (cyl.contact_pressure >= 0).all()


def test_penalty_pressure_is_penalty_times_penetration(hertz_runs):
    p, result = hertz_runs["penalty", False]
    h = shortest_cylinder_facet(result)
    e_flat = hertz.LinearElastic(p.flat_youngs_modulus, p.flat_poissons_ratio)
    penalty = 1e3 * e_flat.plane_strain_modulus() / h  # the documented default
    cyl = result.steps[-1].bodies["cylinder"]
    on = cyl.contact_status > 0
    np.testing.assert_allclose(cyl.contact_pressure[on], penalty * cyl.penetration[on],
                               rtol=1e-5)
    assert (cyl.penetration[on] > 0).all()


def test_penalty_answer_depends_on_the_penalty(hertz_runs):
    p, lagrange = hertz_runs["lagrange", False]
    p_exact = hertz.evaluate(lagrange, p)["p_max"]
    soft_p, soft = solve_hertz(method="penalty", penalty_factor=0.01)
    e = hertz.evaluate(soft, soft_p)
    pen = soft.steps[-1].history[-1].max_penetration
    assert pen > 1e3 * hertz_runs["penalty", False][1].steps[-1].history[-1].max_penetration
    assert abs(e["p_max"] / p_exact - 1) > 1e-4  # 0.1 % lower with 1e-5 of the default
    assert e["p_max"] < p_exact
    # an explicit penalty wins over the factor
    e_flat = hertz.LinearElastic(p.flat_youngs_modulus, p.flat_poissons_ratio)
    penalty = 0.01 * e_flat.plane_strain_modulus() / shortest_cylinder_facet(soft)
    same_p, same = solve_hertz(method="penalty", penalty=penalty, penalty_factor=123.0)
    assert hertz.evaluate(same, same_p)["p_max"] == pytest.approx(e["p_max"], rel=1e-10)


def test_augmented_lagrangian_updates_without_refactorizing(hertz_runs):
    p, result = solve_hertz(method="augmented", penalty_factor=0.01)
    _, lagrange = hertz_runs["lagrange", False]
    tol = 1e-9 * shortest_cylinder_facet(result)
    assert result.penetration_tolerance == pytest.approx(tol)
    for step in result.steps:
        assert step.history[-1].max_penetration <= tol
    # Uzawa's updates: more solves than the penalty method with the same penalty
    _, penalty = solve_hertz(method="penalty", penalty_factor=0.01)
    assert sum(s.iterations for s in result.steps) > sum(s.iterations for s in penalty.steps)
    e = hertz.evaluate(result, p)
    assert e["p_max"] == pytest.approx(hertz.evaluate(lagrange, p)["p_max"], rel=1e-7)


def test_a_failed_step_stops_the_analysis_with_the_reason():
    p = hertz.HertzParameters(method="lagrange")
    model = hertz.build(p)
    model.contact = dataclasses.replace(model.contact, max_iterations=2)
    result = Analysis(model).run()
    assert not result.converged and not result.steps
    assert "active set did not settle in 2 linear solves" in result.message
    assert result.message.startswith("step 1 (load factor 0 -> 0.2) failed")


def test_patch_test_errors():
    """Single-pass node-to-segment passes the patch test when the meshes nest (2/10, 1/5) and
    fails it otherwise (4/7: 4.4 %, the known defect of a single pass); the penalty's
    compliance 1 / penalty costs it h / (2000 H) on top."""
    out = {}
    for method in METHODS:
        p = patch.Parameters(method=method)
        for lower, upper, nu in ((4, 7, 0.0), (2, 10, 0.3), (5, 1, 0.0)):
            case = patch.run_case(p, lower, upper, nu)
            assert case["converged"]
            out[method, lower, upper] = case["pressure_deviation"], case["stress_deviation"]
    assert max(out["lagrange", 2, 10]) < 1e-12
    assert max(out["lagrange", 5, 1]) < 1e-12
    assert 0.03 < out["lagrange", 4, 7][0] < 0.05
    assert 0.02 < out["lagrange", 4, 7][1] < 0.03
    for lower, upper, h in ((2, 10, 0.1), (5, 1, 0.2)):  # h: the finer (slave) block's facet
        for method in ("penalty", "augmented"):
            # the augmented method closes the gaps to 1e-9 of a facet: the pressure to ~1e-8
            expected = h / 2000 / (1 + h / 2000)
            dev = out[method, lower, upper][0]
            if method == "penalty":
                assert dev == pytest.approx(expected, rel=1e-6)
            else:
                assert dev < 3e-8
    assert 0.03 < out["penalty", 4, 7][0] < 0.05


def test_settings_are_checked():
    assert ContactSettings().method == "vfem"
    with pytest.raises(InputError, match=r"contact.method must be one of \('vfem', 'penalty', "
                                         r"'lagrange', 'augmented'\), got 'mortar'"):
        ContactSettings(method="mortar").validate()
    for key in ("penalty", "penalty_factor", "augmented_tolerance"):
        with pytest.raises(InputError, match=f"contact.{key} must be > 0"):
            ContactSettings(**{key: -1.0}).validate()
    with pytest.raises(InputError, match="the classical contact methods"):
        hertz.build(hertz.HertzParameters(method="lagrange", order=2))


def test_cli_runs_hertz_with_a_baseline(tmp_path, capsys):
    from vfem.cli import main

    out = tmp_path / "hertz"
    assert main(["run", "hertz", "--set", "contact.method=lagrange", "--set", "steps=2",
                 "--out", str(out)]) == 0
    assert "contact method 'lagrange'" in capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert summary["parameters"]["method"] == "lagrange"
    assert abs(summary["hertz"]["p_max_error"]) < 2e-3
    assert (out / "cylinder_step0002.vtu").stat().st_size > 0
    assert (out / "contact.csv").stat().st_size > 0


def test_a_body_only_contact_could_hold_but_none_can_touch_is_refused():
    """The cylinder 0.2 above the flat: no candidates, so nothing holds it (singular)."""
    result = Analysis(hertz.build(hertz.HertzParameters(method="penalty",
                                                        initial_gap=0.2))).run()
    assert not result.converged
    assert "body 'cylinder' is held along y only by its platen and by contact" in result.message
    assert "within contact.search_distance of each other" in result.message
