"""The matrix-free contact correction (issue 22): the dense route's answers, without dense blocks.

``contact.flexibility = "matrix_free"`` applies each body's flexibility through its
factorization (one back-substitution per body per GMRES iteration) where ``"dense"`` forms it
(PARDISO's Schur complement on the contact dofs) and the pair matrix W from it. Both solve the
same linear complementarity problem, so every displacement and contact force must agree to the
GMRES tolerance: measured 2026-11-28 within 5e-10 of the largest (2D Hertz with its platen,
the 3D sphere and its platen, 3D patch tests, stacks of plates 2D and 3D, the gasket's releases
and re-contacts, relaxed corrections); 1e-8 is the acceptance of the issue.
"""

import dataclasses

import numpy as np
import pytest

from test_patch3d import stacked
from vfem.contact.formulations import pairmaking
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.solver import Analysis
from vfem_examples import load, stack

RTOL = 1e-8


def with_route(config, route: str, **settings):
    return dataclasses.replace(config, contact=dataclasses.replace(
        config.contact, flexibility=route, **settings))


def run_both(config, **settings):
    out = {}
    for route in ("dense", "matrix_free"):
        result = Analysis(with_route(config, route, **settings).build()).run()
        assert result.converged, result.message
        assert result.flexibility == route
        assert all(s.invariants["passed"] for s in result.steps)
        out[route] = result
    return out["dense"], out["matrix_free"]


def assert_same(a, b, rtol=RTOL):
    assert len(a.steps) == len(b.steps)
    assert [s.iterations for s in a.steps] == [s.iterations for s in b.steps]
    for sa, sb in zip(a.steps, b.steps):
        for name, ra in sa.bodies.items():
            rb = sb.bodies[name]
            for field in ("displacement", "contact_force"):
                x, y = getattr(ra, field), getattr(rb, field)
                scale = max(np.abs(x).max(), 1e-300)
                assert np.abs(x - y).max() <= rtol * scale, (name, field)
            assert np.array_equal(ra.contact_status, rb.contact_status), name


def example_config(name, **parameters):
    module = load(name)
    return module.config(module.Parameters(**parameters))


@pytest.mark.parametrize("name", ["hertz", "block", "punch",
                                  pytest.param("gasket", marks=pytest.mark.slow)])
def test_2d_examples_agree_with_the_dense_route(name):
    assert_same(*run_both(example_config(name)))


@pytest.mark.slow
def test_the_sphere_and_its_platen_agree_with_the_dense_route():
    assert_same(*run_both(example_config("sphere")))


@pytest.mark.parametrize("lower,upper", [(("hex", 4), ("tet", 7)), (("tet", 5), ("hex", 2))])
def test_3d_patch_test_is_met_to_round_off_matrix_free(lower, upper):
    model = stacked(lower, upper, flexibility="matrix_free")
    result = Analysis(model).run()
    assert result.converged and result.flexibility == "matrix_free"
    assert [s.iterations for s in result.steps] == [1]
    for body in model.bodies:
        r = result.steps[-1].bodies[body.name]
        on = r.contact_status > 0
        assert np.abs(r.contact_pressure[on] / 1.0 - 1).max() < 1e-8  # E D / 2 = 1


@pytest.mark.parametrize("dim,parameters", [
    (2, {"blocks": 5, "divisions": 12}),
    pytest.param(3, {"blocks": 2, "divisions": 24, "thickness": 0.1, "shrink": 0.2},
                 marks=pytest.mark.slow),
    pytest.param(3, {"blocks": 3, "divisions": 6, "tetrahedra": True}, marks=pytest.mark.slow),
])
def test_stacks_agree_with_the_dense_route(dim, parameters, monkeypatch):
    if parameters.get("divisions", 0) == 24:
        # more nodes on each face than the side choice reads: both routes sample alike
        monkeypatch.setattr(pairmaking, "SIDE_SAMPLE", 200)
    config = stack.config(stack.Parameters(dim=dim, **parameters))
    dense, free = run_both(config)
    assert_same(dense, free)
    if parameters.get("divisions", 0) == 24:
        assert max(s.nc for s in free.surfaces) > pairmaking.SIDE_SAMPLE


@pytest.mark.slow
def test_relaxed_corrections_solve_their_sets_matrix_free():
    """Settings that relax the corrections take the pairs' active sets one correction at a
    time (PairedContact._solve_pairs), not by complementarity: the same answers."""
    assert_same(*run_both(example_config("hertz"), first_relaxation=0.5, relaxed_iterations=2))


def test_auto_goes_matrix_free_past_the_dense_limit_and_stays_dense_below():
    config = stack.config(stack.Parameters(dim=2, blocks=3, divisions=10))
    small = Analysis(with_route(config, "auto").build()).run()
    assert small.flexibility == "dense"  # a few kB of dense blocks, far below half the memory
    tight = Analysis(with_route(config, "auto", dense_limit_mib=1e-3).build()).run()
    assert tight.flexibility == "matrix_free"
    assert_same(small, tight)



def test_auto_predicts_the_route_measured_faster():
    """``"auto"`` goes matrix-free by predicted time too (issue 40,
    :func:`~vfem.contact.solvers.routes.predicted_seconds`), where the memory would allow the
    dense route: on a large flat zone (two plates of 40 divisions, 8,964 contact dofs:
    measured 6.3 s matrix-free against 11.4 s dense, ``benchmarks/matrix_free.py``) it goes
    matrix-free; where the contact set changes often on a small zone of large bodies (the
    sphere refined once, 120,849 dofs, 2,538 contact dofs: 43.5 s matrix-free, 617
    applications of W, against 11.0 s dense) and on a small model (the default stack) it
    stays dense. The surfaces only: nothing is factorized."""
    from vfem.contact.solvers import predicted_seconds
    from vfem_examples import sphere

    plates = stack.build(stack.Parameters(blocks=2, divisions=40, thickness=0.1, shrink=0.2,
                                          press=0.0005, layers=2))
    cases = ((plates, True), (sphere.build(sphere.SphereParameters(refinement=1)), False),
             (stack.build(stack.Parameters()), False))
    for model, faster in cases:
        _, surfaces = model.contact_surfaces()
        for s in surfaces:  # the paired variant condenses the candidates alone (Analysis.setup)
            s.rind_rows = False
        t = predicted_seconds(surfaces, len(model.load_factors), "pardiso")
        assert (t["matrix_free"] < t["dense"]) == faster, (model.name, t)


@pytest.mark.parametrize("settings,why", [
    ({"friction": 0.3}, "the model has friction"),
    ({"variant": "thesis"}, "the thesis variant reads the flexibility node by node"),
])
def test_matrix_free_refused_where_it_does_not_serve(settings, why):
    config = with_route(example_config("hertz"), "matrix_free", **settings)
    with pytest.raises(InputError, match=why):
        Analysis(config.build()).run()
    # "auto" keeps them dense, whatever the limit
    result = Analysis(with_route(example_config("hertz"), "auto", dense_limit_mib=1e-6,
                                 **settings).build()).run()
    assert result.flexibility == "dense"


def test_matrix_free_refused_under_large_kinematics():
    config = example_config("hertz")
    config = dataclasses.replace(config, bodies=tuple(
        dataclasses.replace(b, kinematics="total") for b in config.bodies))
    with pytest.raises(InputError, match="large kinematics"):
        Analysis(with_route(config, "matrix_free").build()).run()


def test_the_setting_is_checked():
    with pytest.raises(InputError, match="contact.flexibility must be one of"):
        ContactSettings(flexibility="sparse").validate()
    with pytest.raises(InputError, match="contact.dense_limit_mib must be > 0"):
        ContactSettings(dense_limit_mib=0.0).validate()


@pytest.mark.slow
def test_stack_balances_and_body_order_changes_nothing():
    p = stack.Parameters(dim=3, blocks=3, divisions=5)
    results = [Analysis(stack.build(dataclasses.replace(p, reverse_bodies=r))).run()
               for r in (False, True)]
    for result in results:
        m = stack.evaluate(result, p)
        assert m["balance_error"] < 1e-12
        assert all(i["equal_and_opposite_error"] < 1e-12 for i in m["interfaces"])
        assert all(i["force"] > 0 for i in m["interfaces"])
    a, b = (r.steps[-1].bodies for r in results)
    for name in a:
        np.testing.assert_allclose(a[name].contact_force, b[name].contact_force,
                                   rtol=1e-8, atol=1e-10 * np.abs(a[name].contact_force).max())
