"""The ``cattaneo3d`` example (issue 21, C14): Cattaneo-Mindlin partial slip of a sphere on a
flat of the same material, the half model y >= 0.

Fast: a coarser mesh (facets a/5) with three steps of the shear (Q/(mu P) 0.35, 0.64, 0.88) —
converged with every invariant at every step, the tangential contact forces of the two bodies
balanced to round-off, the outermost sticking node within one facet of Mindlin's stick radius c
at each step (measured 0.04, 0.08, 0.34 facets inside it), and the same answer with the bodies
listed the other way round.
Slow: the acceptance, the default run (ten steps of the shear) and a finer mesh, at the steps
nearest Q/(mu P) = 0.3, 0.6 and 0.9.
"""

import math

import numpy as np
import pytest

from vfem.errors import InputError
from vfem.mesh import solids
from vfem.solver import Analysis
from vfem_examples import cattaneo3d

FAST = cattaneo3d.Parameters(facets_per_radius=5, shear_steps=3, shift=0.03)


def solve(p):
    result = Analysis(cattaneo3d.build(p)).run()
    assert result.converged, result.message
    return result


@pytest.fixture(scope="module")
def fast():
    return solve(FAST)


@pytest.fixture(scope="module")
def swapped():
    return solve(cattaneo3d.Parameters(facets_per_radius=5, shear_steps=3, shift=0.03,
                                      swap_bodies=True))


def test_theory():
    p = cattaneo3d.Parameters()
    th = cattaneo3d.theory(p)
    e_star = 200e3 / (2 * (1 - 0.3 ** 2))
    assert th["a"] == pytest.approx((3 * 15000 * 10 / (4 * e_star)) ** (1 / 3), rel=1e-14)
    mu_p = p.friction * p.force
    assert cattaneo3d.stick_radius(p, 0.0) == pytest.approx(th["a"])
    assert cattaneo3d.stick_radius(p, 0.875 * mu_p) == pytest.approx(0.5 * th["a"])
    assert cattaneo3d.stick_radius(p, mu_p) == 0.0
    # full slip: the shear is mu times Hertz's pressure; no shear: none
    r = np.linspace(0, 1.2, 13) * th["a"]
    hertz = th["mu_p0"] * np.sqrt(np.clip(1 - (r / th["a"]) ** 2, 0, None))
    assert np.allclose(cattaneo3d.shear_theory(p, r, mu_p), hertz)
    assert np.allclose(cattaneo3d.shear_theory(p, r, 0.0), 0.0, atol=1e-12 * th["mu_p0"])
    # the traction's resultant over the circle is Q (Mindlin)
    rr = np.linspace(0, th["a"], 200001)
    q = 0.6 * mu_p
    total = np.trapezoid(cattaneo3d.shear_theory(p, rr, q) * 2 * math.pi * rr, rr)
    assert total == pytest.approx(q, rel=1e-4)


def test_half_cylinder_is_half_the_whole():
    kw = dict(end_radius=10.0, h_contact=0.25, h=1.0, growth=0.3, plateau=1.2)
    half = solids.cylinder(6.0, 5.0, quarter=False, half=True, **kw)
    whole = solids.cylinder(6.0, 5.0, quarter=False, **kw)
    assert half.p[1].min() == 0.0
    assert set(half.boundaries) == {"contact", "top", "side", "front"}
    whole_nodes = {tuple(x) for x in np.round(whole.p.T, 12)}
    assert all(tuple(x) in whole_nodes for x in np.round(half.p.T, 12))
    assert 2 * half.nelements == whole.nelements
    with pytest.raises(ValueError, match="quarter = False"):
        solids.cylinder(6.0, 5.0, half=True, **kw)


@pytest.mark.slow
def test_fast_invariants_balance_and_stick_radius(fast):
    p = FAST
    for step in fast.steps:
        assert step.invariants["passed"], step.invariants
    ev = cattaneo3d.evaluate(fast, p)
    assert ev["compatibility_body"] == "sphere"
    assert len(ev["steps"]) == 3
    for row in ev["steps"]:
        assert row["normal"] == pytest.approx(p.force, rel=1e-10)
        assert row["tangential_balance"] < 1e-12
        assert 0.2 < row["Q_over_muP"] < 0.95
        # the outermost sticking node within one facet of Mindlin's c (measured: 0.04, 0.08, 0.34)
        assert abs(row["last_sticking_off_c_facets"]) < 1.0, row
        assert abs(row["edge_off_c_facets"]) < 1.0, row
        assert row["iterations"] <= 3
    ratios = [r["Q_over_muP"] for r in ev["steps"]]
    assert ratios == sorted(ratios)


@pytest.mark.slow
def test_body_order_does_not_matter(fast, swapped):
    p = FAST
    mu_p0 = cattaneo3d.theory(p)["mu_p0"]
    for a, b in zip(fast.steps, swapped.steps, strict=True):
        sa, sb = cattaneo3d.stick_slip(fast, a), cattaneo3d.stick_slip(swapped, b)
        assert sa["body"] == sb["body"] == "sphere"
        assert np.array_equal(sa["status"], sb["status"])
        for key in ("shear_x", "shear_y", "normal"):
            assert np.abs(sa[key] - sb[key]).max() < 1e-8 * mu_p0
        assert np.allclose(cattaneo3d.resultants(a), cattaneo3d.resultants(b),
                           rtol=0, atol=1e-8 * p.force)


def test_refused():
    with pytest.raises(InputError, match="friction"):
        cattaneo3d.validate(cattaneo3d.Parameters(friction=0.0))
    with pytest.raises(InputError, match="force"):
        cattaneo3d.validate(cattaneo3d.Parameters(force=float("nan")))
    with pytest.raises(InputError, match="not small"):
        cattaneo3d.validate(cattaneo3d.Parameters(force=1e9))


def _acceptance(p):
    result = solve(p)
    for step in result.steps:
        assert step.invariants["passed"], step.invariants
    ev = cattaneo3d.evaluate(result, p)
    rows = [ev["steps"][i] for i in cattaneo3d.picks(ev["steps"])]
    assert len(rows) == 3
    for row, target in zip(rows, cattaneo3d.PICKS, strict=True):
        assert abs(row["Q_over_muP"] - target) < 0.1
        assert abs(row["last_sticking_off_c_facets"]) < 1.0, row
        assert row["tangential_balance"] < 1e-12
    return rows


@pytest.mark.slow
def test_acceptance_default():
    _acceptance(cattaneo3d.Parameters())


@pytest.mark.slow
def test_acceptance_finer():
    _acceptance(cattaneo3d.Parameters(facets_per_radius=8))


@pytest.mark.slow
def test_acceptance_coarsest():
    """Facets a/4: a strict expected failure until the edges of both surfaces were held where
    they land (issue 37, 2026-11-30): the press failed invariant (b) at a flat node on the
    symmetry plane y = 0 at 0.92 a (3.7e-4 inside the sphere against 3.2e-4 allowed), the
    increment cut 6 times. Measured now: every step converges with every invariant, the
    outermost sticking node 0.45, 0.05 and 0.45 facets inside Mindlin's c at Q/(mu P) 0.31,
    0.59 and 0.90."""
    _acceptance(cattaneo3d.Parameters(facets_per_radius=4))
