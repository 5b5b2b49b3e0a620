"""Thesis §5.2, Hertz: the acceptance numbers of issue 2 on the default mesh, and refinement."""

import dataclasses

import numpy as np
import pytest

from vfem.solver import Analysis
from vfem_examples.hertz import HertzParameters, build, evaluate, theory


def test_theory_matches_the_method_notes():
    th = theory(HertzParameters())
    assert th["a_theory"] == pytest.approx(0.061168, abs=2e-6)
    assert th["p0_theory"] == pytest.approx(31848, abs=1)


def test_mesh_has_ten_or_more_facets_across_the_half_width(hertz_level0):
    p, result, h = hertz_level0
    assert h["a_theory"] / h["contact_facet_length"] >= 10


def test_every_step_converges(hertz_level0):
    _, result, _ = hertz_level0
    assert result.converged
    assert [s.load_factor for s in result.steps] == pytest.approx([0.2, 0.4, 0.6, 0.8, 1.0])
    assert all(s.converged and s.iterations >= 1 for s in result.steps)


def test_peak_pressure_half_width_and_profile(hertz_level0):
    _, _, h = hertz_level0
    # measured +0.099 % (the model's own limit, quadratic elements refined: +0.074 %)
    assert abs(h["p_max_error"]) < 1e-3
    assert abs(h["a_estimate"] - 0.06117) <= h["contact_facet_length"]
    assert h["rms_error_over_p0"] < 0.012  # measured 1.11 %


def test_contact_forces_balance_the_applied_load(hertz_level0):
    """Conservation: the platen's force reaches the flat through the contact."""
    _, _, h = hertz_level0
    # the platen's force, to the platen tolerance (measured 4e-14 relative)
    assert h["total_contact_force"] == pytest.approx(1530, rel=1e-9)
    # the flat receives the same total through the virtual elements (exact transfer)
    assert h["total_contact_force_flat"] == pytest.approx(h["total_contact_force"], rel=1e-12)


def test_no_node_penetrates_at_convergence(hertz_level0):
    """Measured independently of the formulation (vfem.contact.invariants.check: every node of
    either body against the other's deformed facets), not the formulation's own gaps (the flat's are
    zero by construction: it carries equilibrium)."""
    _, result, _ = hertz_level0
    for step in result.steps:
        inv = step.invariants
        assert inv["passed"] and not inv["failed"], inv
        assert inv["max_penetration_any_body"] <= 1e-12  # measured 1e-16: round-off
        assert inv["penetration"] <= inv["allowed"]


def test_swapping_the_bodies_changes_nothing(hertz_level0):
    p, result, h = hertz_level0
    swapped = dataclasses.replace(p, swap_bodies=True)
    r2 = Analysis(build(swapped)).run()
    h2 = evaluate(r2, swapped)
    assert h2["p_max"] == pytest.approx(h["p_max"], rel=1e-8)
    assert [s.iterations for s in r2.steps] == [s.iterations for s in result.steps]


@pytest.mark.slow
def test_refinement_keeps_p_max_within_a_fraction_of_a_percent():
    errors = []
    for level in (1, 2):
        p = HertzParameters(refinement=level)
        r = Analysis(build(p)).run()
        assert r.converged
        errors.append(evaluate(r, p)["p_max_error"])
    assert max(abs(e) for e in errors) < 0.005


def test_a_cylinder_starting_clear_of_the_flat_ends_in_the_same_state(hertz_level0):
    """The platen first closes the gap, then the contact builds up as before."""
    p, _, h = hertz_level0
    gapped = dataclasses.replace(p, initial_gap=1e-3)
    r = Analysis(build(gapped)).run()
    assert r.converged
    h2 = evaluate(r, gapped)
    assert h2["p_max"] == pytest.approx(h["p_max"], rel=1e-3)
    assert h2["total_contact_force"] == pytest.approx(1530, rel=1e-4)
    assert r.steps[-1].platen_displacement == pytest.approx(
        -1e-3 + Analysis(build(p)).run().steps[-1].platen_displacement, rel=1e-3)


def test_both_bodies_read_the_same_pressure(hertz_level0):
    """Paired in the undeformed configuration, as the linear kinematics of a small-strain model
    asks, the flat's nominal pressure is the cylinder's."""
    _, _, h = hertz_level0
    assert h["p_max_flat"] == pytest.approx(h["p_max"], rel=3e-3)
    assert h["total_contact_force_flat"] == pytest.approx(h["total_contact_force"], rel=1e-3)


def test_thesis_variant_meets_the_core_acceptance_too(hertz_level0):
    p, result, h = hertz_level0
    tp = dataclasses.replace(p, variant="thesis")
    r = Analysis(build(tp)).run()
    # every step stops at its fixed point outside its tolerance: run to the end, not converged
    # (issue 37), and its answer still meets the core acceptance
    assert r.complete and not r.converged and all(s.fixed_point for s in r.steps)
    assert "contact.variant = \"paired\"" in r.message
    ht = evaluate(r, tp)
    assert ht["p_max"] == pytest.approx(31848, rel=0.03)
    assert abs(ht["a_estimate"] - 0.06117) <= ht["contact_facet_length"]
    assert ht["rms_error_over_p0"] < 0.05
    assert ht["total_contact_force"] == pytest.approx(1530, rel=0.005)
    # the paired variant needs no more iterations than the plain reading, step by step
    assert [s.load_factor for s in r.steps] == [s.load_factor for s in result.steps]
    assert all(a.iterations <= b.iterations for a, b in zip(result.steps, r.steps))
    r2 = Analysis(build(dataclasses.replace(tp, swap_bodies=True))).run()
    assert evaluate(r2, tp)["p_max"] == pytest.approx(ht["p_max"], rel=1e-8)


# measured +0.099, +0.097, +0.094, +0.083 %
@pytest.mark.parametrize(("ratio", "bound"), [(0.5, 1.2e-3), (3.0, 1.2e-3), (5.0, 1.2e-3),
                                              (10.0, 1.2e-3)])
def test_flat_facets_up_to_ten_times_the_cylinders(ratio, bound):
    """Thesis §5.6: a 3:1 ratio is easily tolerated; larger ones ask for care."""
    p = HertzParameters(flat_size_ratio=ratio)
    r = Analysis(build(p)).run()
    assert r.converged
    h = evaluate(r, p)
    assert abs(h["p_max_error"]) < bound
    assert h["total_contact_force_flat"] == pytest.approx(1530, rel=1e-9)  # exact transfer


def test_step_cutting_is_bounded_and_reported():
    """A step that cannot converge is cut at most max_step_cuts times below its scheduled
    increment, then the analysis stops with a message (it never creeps up on a load factor)."""
    model = build(HertzParameters())
    # relaxed corrections (one correction of the bodies at a time): the contact set by
    # complementarity would converge in one
    model.contact = dataclasses.replace(model.contact, max_iterations=3, max_step_cuts=3,
                                        relaxation=0.3, first_relaxation=0.3)
    result = Analysis(model).run()
    assert not result.converged
    assert "failed with the increment cut 3 times" in result.message
    assert all(s.cuts <= 3 for s in result.steps)
    # the smallest increment tried is the scheduled one (0.2) over 2**3; the message says
    # where the error is and what to change
    assert "(load factor 0 -> 0.025)" in result.message
    assert " of body 'cylinder'" in result.message
    assert "What to change: allow more iterations (contact.max_iterations = 3)" in result.message


def _pressure_reading():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parent.parent / "benchmarks" / "pressure_reading.py"
    spec = importlib.util.spec_from_file_location("pressure_reading", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
def test_pointwise_pressure_at_48_facets_and_no_dip_on_the_symmetry_plane():
    """Issue 16, item 5: at 48 facets across a the pressure is within 1 % of Hertz's at every
    node over |x| < 0.8 a, read either way (measured: nodal reading 0.10 %, traction q 0.10 %),
    and the node at x = 0 reads as its neighbours do (no dip: measured within 0.01 % of p0 at
    12 and 48 facets; the rings of the former mesh read 1.9 % low there at 12). A full model,
    the half mirrored about x = 0, reads the same there within 0.1 % of p0 (measured 0.04 %).
    ``benchmarks/pressure_reading.py`` prints the table docs/method.md §6 quotes."""
    import vfem

    bench = _pressure_reading()
    for n in (12, 48):
        p = HertzParameters(facets_per_half_width=n)
        th = theory(p)
        a, p0 = th["a_theory"], th["p0_theory"]
        result = vfem.solve(build(p))
        e = bench.errors(result, a, p0)
        for name, values in e.items():
            assert values[1] < (1.0 if name.startswith("traction") else 0.2), (n, name, values)
        s = next(s for s in result.surfaces if s.body.name == "cylinder")
        x = np.abs(s.X[: s.nc, 0])
        pressure = result.steps[-1].bodies["cylinder"].contact_pressure[s.nodes[: s.nc]]
        error = (pressure - p0 * np.sqrt(np.clip(1 - (x / a) ** 2, 0, None))) / p0
        order = np.argsort(x)
        assert abs(error[order[0]] - error[order[1:3]].mean()) < 2e-4  # no dip at x = 0
    p = HertzParameters()
    th = theory(p)
    half = bench.errors(vfem.solve(build(p)), th["a_theory"], th["p0_theory"])
    full = bench.errors(vfem.solve(bench.mirrored(p)), th["a_theory"], th["p0_theory"])
    for name in half:
        assert half[name][3] == pytest.approx(full[name][3], abs=0.1)  # % of p0


def test_the_contact_set_by_complementarity_takes_one_correction_per_step():
    """Issue 20, item 6: the paired variant finds the contact set on the pair matrix before
    the bodies see it, so each linear step takes one correction of the bodies; the iteration
    that releases and adds nodes one correction at a time (reached by releasing tension over
    two iterations, thesis §5.6) ends in the same state, to round-off, in more corrections."""
    fast = Analysis(build(HertzParameters())).run()
    model = build(HertzParameters())
    model.contact = dataclasses.replace(model.contact, tension_release_iterations=2)
    slow = Analysis(model).run()
    assert fast.converged and slow.converged
    assert [s.iterations for s in fast.steps] == [1] * 5
    assert sum(s.iterations for s in slow.steps) > 10
    for a, b in zip(fast.steps, slow.steps):
        for ra, rb in zip(a.bodies.values(), b.bodies.values()):
            scale = np.abs(rb.contact_force).max()
            assert np.abs(ra.contact_force - rb.contact_force).max() <= 1e-10 * scale
            assert np.abs(ra.displacement - rb.displacement).max() <= 1e-10 * np.abs(
                rb.displacement).max()
