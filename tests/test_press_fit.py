"""The ``press_fit`` example (issue 21): a shaft in a hub with a radial interference, against
Lame's thick cylinders in plane strain.

Measured (2026-11-28): the default (hexahedra, 24 facets per quarter turn, 8 through the wall,
5,574 dofs) in one iteration with every invariant, the hub's nodal pressure within 0.27 % of
Lame's everywhere (mean +0.18 %), the shaft's within 0.82 % (mean -0.81 %); 32 facets per
quarter turn 0.23 %; 48 and 16 through the wall (interference 0.005) 0.065 %. (Before the
symmetry planes' edges stopped counting as the patches' boundary, 2026-11-28, the pressure
read at the nodes on the symmetry planes was 1.59 % off.) With tetrahedra in the hub: one
iteration, every invariant, the mean within 0.7 % but the nodal pressure scattering by 9-13 %
(the tetrahedral bore's facets are not at the shaft's angles: the faceting sag differs from
node to node); with tetrahedra in both the start is refused (the interference is deeper than
the shaft's outer tetrahedra).
"""

import numpy as np
import pytest

from vfem.errors import InputError
from vfem.solver import Analysis
from vfem_examples import press_fit


def solve(**kw):
    p = press_fit.Parameters(**kw)
    model = press_fit.build(p)
    result = Analysis(model).run()
    assert result.converged, result.message
    return p, model, result


@pytest.fixture(scope="module")
def default():
    return solve()


def test_lame():
    p = press_fit.Parameters()
    E, nu, b, c, d = 200e3, 0.3, 1.0, 2.0, 0.01
    # the hub's bore and the shaft's surface move apart by the interference under Lame's p
    pl = press_fit.lame(p)
    u_hub = pl * b * (1 + nu) * ((1 - 2 * nu) * b * b + c * c) / (E * (c * c - b * b))
    u_shaft = -pl * b * (1 + nu) * (1 - 2 * nu) / E
    assert u_hub - u_shaft == pytest.approx(d, rel=1e-14)


@pytest.mark.slow
def test_pressure_within_2_percent_of_lame(default):
    p, model, result = default
    assert [s.iterations for s in result.steps] == [1]
    assert all(s.invariants["passed"] for s in result.steps)
    ev = press_fit.evaluate(result, p)
    for name in ("hub", "shaft"):
        assert ev[name]["nodes_in_contact"] == ev[name]["nodes"]  # the whole surface
        assert ev[name]["largest_error"] < 0.01  # measured 0.27 %, 0.82 %
        assert abs(ev[name]["mean_error"]) < 0.01
    # the resultant on the quarter: p b L along x and along y, equal and opposite
    f_shaft = result.steps[-1].bodies["shaft"].contact_force.sum(axis=0)
    f_hub = result.steps[-1].bodies["hub"].contact_force.sum(axis=0)
    assert np.abs(f_shaft + f_hub).max() < 1e-10 * np.abs(f_hub).max()
    assert f_hub[0] == pytest.approx(ev["lame_pressure"] * p.bore_radius * p.length, rel=0.005)


@pytest.mark.slow
def test_body_order_does_not_matter(default):
    p, _, a = default
    _, _, b = solve(swap_bodies=True)
    for name in ("hub", "shaft"):
        pa = a.steps[-1].bodies[name].contact_pressure
        pb = b.steps[-1].bodies[name].contact_pressure
        assert np.abs(pa - pb).max() < 1e-8 * press_fit.lame(p)


@pytest.mark.slow
def test_finer_facets_come_closer(default):
    p, _, result = solve(around=32)
    coarse = press_fit.evaluate(default[2], default[0])["hub"]["largest_error"]
    assert press_fit.evaluate(result, p)["hub"]["largest_error"] < coarse  # 0.23 % < 0.27 %


@pytest.mark.slow
def test_tetrahedral_hub():
    """A bore node at an end face and a symmetry plane was read as beyond the shaft's patch
    (invariant (b) failed there, 3.9e-4 inside) until symmetry-plane edges stopped being the
    patch's boundary."""
    p, _, result = solve(hub_cells="tet")
    assert [s.iterations for s in result.steps] == [1]
    assert all(s.invariants["passed"] for s in result.steps)
    ev = press_fit.evaluate(result, p)
    for name in ("hub", "shaft"):
        assert abs(ev[name]["mean_error"]) < 0.01  # measured +0.68 %, -0.36 %
        assert ev[name]["largest_error"] < 0.15  # 9.2 %, 13.4 %: facets at other angles


def test_too_deep_an_interference_is_refused():
    with pytest.raises(InputError, match="start deeply interpenetrated"):
        Analysis(press_fit.build(press_fit.Parameters(hub_cells="tet", shaft_cells="tet"))).run()


def test_bad_parameters_are_refused():
    with pytest.raises(InputError, match="around must be an even number"):
        press_fit.validate(press_fit.Parameters(around=7))
    with pytest.raises(InputError, match="hub_radius must exceed bore_radius"):
        press_fit.validate(press_fit.Parameters(hub_radius=0.5))


@pytest.mark.slow
def test_push_out_force_with_friction():
    """The shaft's end faces pushed along the axis after the fit (mu = 0.3): every contact node
    slips and the axial force is 2 pi b L mu p. The end faces' rim nodes are contact nodes whose
    axial motion both bodies' supports fix (prescribed on the shaft, held on the hub): they slip
    by that motion, known, with friction's traction against it. Measured 2026-11-28: one
    iteration per step, every invariant, +0.23 % of 2 pi b L mu p (the fit's pressure is 0.18 %
    above Lame's); the bodies listed the other way round the same. (Before: the end nodes'
    axial slip counted as a sticking node's error the solve could not correct, and the push
    never converged.)"""
    forces = []
    for swap in (False, True):
        p, _, result = solve(friction=0.3, push=0.02, swap_bodies=swap)
        assert [s.iterations for s in result.steps] == [1, 1, 1]
        assert all(s.invariants["passed"] for s in result.steps)
        ev = press_fit.evaluate(result, p)
        for step in ev["push"]:
            assert step["slipping_nodes"] == ev["shaft"]["nodes"]  # the whole fit slides
            assert step["axial_force"] == pytest.approx(press_fit.push_out_force(p), rel=0.005)
        forces.append(ev["push"][-1]["axial_force"])
    assert forces[1] == pytest.approx(forces[0], rel=1e-8)


@pytest.mark.slow
def test_a_longer_shaft_pushed_at_its_far_ends():
    """A model of our own: the shaft twice the hub's length, pushed at its far end faces (its
    contact nodes then carry no supports). The hub's pressure is no longer Lame's (end effects:
    mean +13 %), so the push-out force is checked against mu times the total normal force,
    which it must equal when every node slips along the axis. Measured 2026-11-28: the fit and
    the push converge (the frictional fit did not before), every invariant, every contact node
    slipping, the axial force 1.0007 mu N."""
    import dataclasses

    from vfem.config import MeshSpec, as_parameters

    p = press_fit.Parameters(friction=0.3, push=0.02)
    config = press_fit.config(p)
    bodies = []
    for body in config.bodies:
        if body.name == "shaft":
            shape = dict(body.mesh.parameters, height=2 * p.length, z0=-0.5 * p.length)
            body = dataclasses.replace(body, mesh=MeshSpec(shape="cylinder",
                                                           parameters=as_parameters(**shape)))
        bodies.append(body)
    model = dataclasses.replace(config, bodies=tuple(bodies)).build()
    result = Analysis(model).run()
    assert result.converged, result.message
    assert all(s.invariants["passed"] for s in result.steps)
    last = result.steps[-1].bodies["shaft"]
    shaft = next(b for b in model.bodies if b.name == "shaft")
    on = last.contact_status > 0
    assert (last.friction_status[on] == 2).all()
    x = shaft.mesh.p.T
    inward = -np.einsum("ij,ij->i", last.contact_force[:, :2],
                        x[:, :2] / np.maximum(np.hypot(x[:, 0], x[:, 1]), 1e-30)[:, None])
    assert -last.contact_force[:, 2].sum() == pytest.approx(0.3 * inward.sum(), rel=0.005)
