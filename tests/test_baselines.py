"""The classical baselines (contact.method penalty, lagrange, augmented): their physics on Hertz
and the patch test, their parameters, and that they answer like vfem does (same results)."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import vfem
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.solver import Analysis
from vfem_examples import hertz, patch

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


@pytest.mark.slow
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
    """A puck pulled away from a block by its platen: no candidates, so nothing holds it
    (singular). Pushed towards the block from the same gap, it finds it (the candidates are
    looked for where the platen brings it, vfem.contact.geometry.placement.platen_approach)."""
    from test_no_contact import puck

    away = puck(+1e6)
    away.contact = dataclasses.replace(away.contact, method="penalty")
    result = Analysis(away).run()
    assert not result.converged
    assert "body 'puck' is held along y only by its platen and by contact" in result.message
    assert "within contact.search_distance of each other" in result.message
    result = Analysis(hertz.build(hertz.HertzParameters(method="penalty",
                                                        initial_gap=0.2))).run()
    assert result.converged
    force = result.steps[-1].bodies["flat"].contact_force.sum(axis=0)
    assert force[1] == pytest.approx(-1530.0, rel=1e-6)  # the platen tolerance


# -- several bodies: two punches on one block (issue 16) ------------------------------------------

PUNCHES = Path(__file__).parent.parent / "examples" / "punch" / "two_punches.toml"
PAIRED_PER_PUNCH = 9.02912e6  # vfem's default (paired) method on examples/punch/two_punches.toml


def two_punches(method, faces_only=False, nx=None, x0=(-1.2, 0.2)):
    """examples/punch/two_punches.toml with a baseline; ``faces_only``: the punches' contact
    candidates are their bottom faces alone; ``nx``: punch meshes with that many elements
    across (10: coarser than the block, which then is the slave of both pairs); ``x0``: where
    the punches start."""
    m = vfem.load(PUNCHES).build()
    m.contact = dataclasses.replace(m.contact, method=method)
    for k, x in zip((1, 2), x0):
        punch = m.bodies[k]
        if nx is not None or tuple(x0) != (-1.2, 0.2):
            punch = dataclasses.replace(punch, mesh=vfem.mesh.rectangle(
                x0=x, width=1.0, height=0.5, nx=nx or 27, ny=8))
        if faces_only:
            punch = dataclasses.replace(punch, contact_boundaries=("bottom",))
        m.bodies[k] = punch
    return m


def check_two_punches(result, rel):
    """Converged; the punches' forces equal (mirror-symmetric model) to ``rel``, the block's
    minus their sum to round-off, no sideways force. Returns the force per punch."""
    assert result.converged, result.message
    t = {k: v.contact_force.sum(axis=0) for k, v in result.steps[-1].bodies.items()}
    load = abs(t["block"][1])
    assert np.abs(t["block"] + t["left"] + t["right"]).max() <= 1e-8 * load
    assert abs(t["block"][0]) <= 1e-8 * load
    assert t["left"][1] == pytest.approx(t["right"][1], rel=rel)
    return 0.5 * load


@pytest.mark.parametrize("method", METHODS)
def test_two_punches_on_one_block(method):
    """Three bodies: symmetric, balanced, and within 0.03 % of vfem (measured -0.022 % for all
    three: 9.027131e6, 9.027129e6 and 9.027131e6 per punch against 9.029120e6)."""
    per_punch = check_two_punches(vfem.solve(two_punches(method)),
                                  rel=1e-8)
    assert per_punch == pytest.approx(PAIRED_PER_PUNCH, rel=3e-4)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("case", ["faces only",
                                  *(pytest.param(c, marks=pytest.mark.slow)
                                    for c in ("coarse punches", "coarse, faces only"))])
def test_two_punches_whose_faces_line_up(method, case):
    """The punches' faces lie on one line with the block's top. With their faces alone as
    candidates, every slave node projected beyond the end of the other punch's face, on that
    line extended (gap 0): a punch's nodes were held level with the other punch, and, with
    the block the slave of both pairs, its nodes under one punch also held level with the
    other's corner; two such nodes against the same two corners are dependent constraints and
    the Lagrange saddle point was singular ("Factor is exactly singular"), the penalty and
    augmented methods cycled or answered 10 % apart for the two punches. Now a node beyond the
    end of a master surface is no contact of it and each slave node takes its closest master
    only: symmetric, balanced, within 0.03 % of vfem."""
    m = two_punches(method, faces_only="faces" in case, nx=10 if "coarse" in case else None)
    per_punch = check_two_punches(vfem.solve(m, solver="superlu"), rel=1e-8)  # the one that
    # said "Factor is exactly singular" (other backends failed otherwise)
    assert per_punch == pytest.approx(PAIRED_PER_PUNCH, rel=3e-4)


def test_one_row_per_slave_node_and_none_beyond_the_end():
    """The block, slave of both punches (coarse punches): one row per node, on the punch it
    lies under or nearer to (the node midway between them: one on each, mirrored); no
    punch node of the punch-punch pair is constrained against the other's face line."""
    from vfem.contact.formulations.baselines import GlobalContact

    g = GlobalContact(two_punches("lagrange", faces_only=True, nx=10))
    c, names = g.c, [b.name for b in g.model.bodies]
    assert {names[i] for i in c.slave} == {"block"}
    nodes, counts = np.unique(c.node, return_counts=True)
    x = g.surfaces[0].X[nodes, 0]
    assert np.all(counts[np.abs(x) > 1e-12] == 1) and np.all(counts[np.abs(x) <= 1e-12] == 2)
    x_row = g.surfaces[0].X[c.node, 0]
    master = np.array(names)[c.master]
    assert np.all((master == "left") | (x_row >= 0)) and np.all((master == "right") | (x_row <= 0))


@pytest.mark.parametrize("method", ["penalty", "augmented"])
def test_punches_touching_at_a_corner(method):
    """Two punches side by side, touching along x = 0, faces only as candidates: their corner
    nodes coincide and move together, gaps of +-1e-18 that made the penalty and augmented
    active sets cycle; nodes now enter past round-off (as Lagrange's do)."""
    m = two_punches(method, faces_only=True, nx=20, x0=(-1.0, 0.0))
    check_two_punches(vfem.solve(m), rel=1e-8)
