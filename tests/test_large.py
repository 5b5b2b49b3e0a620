"""Contact under large displacements (vfem.contact.formulations.large): the bodies equilibrated by
Newton's method inside every contact iteration, paired on their deformed surfaces."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vfem.bodies import PrescribedDisplacement
from vfem.result_types import largest_penetrations
from vfem.solver import Analysis
from vfem_examples import hertz, sliding


def _with_kinematics(config, kinematics):
    return dataclasses.replace(config, bodies=tuple(
        dataclasses.replace(b, kinematics=kinematics) for b in config.bodies))


def _p_max(result):
    return max(float(b.contact_pressure.max()) for b in result.steps[-1].bodies.values())


@pytest.fixture(scope="module")
def small_load_hertz():
    """The Hertz example at 1 % of the thesis's force (contact strains about 0.3 %): linear,
    total and updated Lagrangian."""
    config = hertz.config(hertz.HertzParameters(force=15.3))
    out = {}
    for kinematics in ("small", "total", "updated"):
        analysis = Analysis(_with_kinematics(config, kinematics).build())
        out[kinematics] = (analysis, analysis.run())
    return out


@pytest.mark.slow
def test_small_loads_reproduce_the_linear_hertz_peak_pressure(small_load_hertz):
    linear = _p_max(small_load_hertz["small"][1])
    for kinematics in ("total", "updated"):
        result = small_load_hertz[kinematics][1]
        assert result.converged
        assert _p_max(result) == pytest.approx(linear, rel=5e-3)  # measured: -0.18 %


def test_total_and_updated_lagrangian_give_the_same_contact(small_load_hertz):
    total, updated = small_load_hertz["total"][1], small_load_hertz["updated"][1]
    for a, b in zip(total.steps, updated.steps):
        for name in a.bodies:
            ua, ub = a.bodies[name].displacement, b.bodies[name].displacement
            assert np.abs(ua - ub).max() <= 1e-6 * np.abs(ua).max()
    assert _p_max(total) == pytest.approx(_p_max(updated), rel=1e-6)


def test_the_platen_carries_its_scheduled_force_under_large_kinematics(small_load_hertz):
    """The contact force on the flat equals the platen's force (15.3 on the half model)."""
    result = small_load_hertz["total"][1]
    flat = result.steps[-1].bodies["flat"].contact_force
    assert -flat[:, 1].sum() == pytest.approx(15.3, rel=1e-6)


@pytest.fixture(scope="module")
def slide():
    """A coarse version of ``vfem run sliding``: 10 block facets of slide in 5 steps."""
    p = sliding.Parameters(block_columns=60, block_rows=8, punch_columns=24, punch_rows=6,
                           slide=1.0, press_steps=3, slide_steps=5, start=-0.5)
    analysis = Analysis(sliding.build(p))
    result = analysis.run()
    return p, analysis, result


@pytest.mark.slow
def test_sliding_ten_facets_keeps_the_normal_reaction_steady(slide):
    p, _, result = slide
    assert result.converged and len(result.steps) == p.press_steps + p.slide_steps
    e = sliding.evaluate(result, p)
    assert e["slide_in_facets"] == pytest.approx(10.0, rel=1e-9)
    assert e["normal_reaction_max_deviation"] < 0.02
    # frictionless: the tangential reaction is a small fraction of the normal one
    assert e["tangential_reaction_max"] < 1e-3 * e["normal_reaction_mean"]
    # the compatibility side (the softer block): none of its nodes inside the punch's deformed
    # facets at the end, measured by the independent check (not the iteration's own stopping
    # rule, which a converged run meets by definition; measured -5e-14), and every step passes
    # the three invariants
    block = largest_penetrations(result)["block"]["penetration"]
    assert block <= result.penetration_tolerance
    assert all(s.invariants["passed"] for s in result.steps)


@pytest.mark.slow
def test_sliding_contact_forces_balance_the_support_reaction(slide):
    """Newton's third law across the interface, and the block's equilibrium on its deformed
    shape: its base reaction equals the contact force it carries."""
    _, analysis, result = slide
    last = result.steps[-1]
    block = next(b for b in result.model.bodies if b.name == "block")
    s = next(s for s in result.surfaces if s.body is block)
    f_block = last.bodies["block"].contact_force
    f_punch = last.bodies["punch"].contact_force
    total = f_block.sum(axis=0)
    assert np.abs(total + f_punch.sum(axis=0)).max() <= 1e-9 * np.abs(total).max()
    f = np.zeros(block.ndofs)
    f[s.candidate_dofs] = f_block[s.nodes[: s.nc]].ravel()
    u = last.bodies["block"].displacement.ravel()
    for k, c in enumerate("xy"):
        reaction = block.reaction(u, "bottom", c, last.load_factor, f)
        assert reaction == pytest.approx(-total[k], abs=1e-8 * np.abs(total).max())


@pytest.mark.slow
def test_sliding_nodes_of_the_other_side_indent_only_by_the_chord_sag(slide):
    """The punch's vertices are not constrained (its surface carries equilibrium); they can lie
    below the block's straight facets by the sag of the arc over one block facet, h^2 / (8 R)."""
    p, _, result = slide
    h = p.block_length / p.block_columns
    worst = max(v["penetration"] for v in largest_penetrations(result).values())
    assert worst < 1.5 * h**2 / (8 * p.punch_radius)


def test_an_amplitude_scales_a_prescribed_displacement():
    pd = PrescribedDisplacement("top", "x", 2.0, ((1.0, 0.0), (2.0, 1.0)))
    assert [pd.at(lf) for lf in (0.5, 1.0, 1.5, 2.0, 3.0)] == [0.0, 0.0, 1.0, 2.0, 2.0]
    assert PrescribedDisplacement("top", "x", 2.0).at(0.25) == 0.5
