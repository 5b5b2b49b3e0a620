"""The thick-cylinder example (issue 41, ``vfem_examples.thick_cylinder``): its theory, its
parameters and its run's own verification (first yield against Lamé, the plastic zone against
Hill, the limit carried). ``tests/test_plasticity.py`` checks the same model through its input
file with code of its own."""

from __future__ import annotations

import dataclasses
import math

import pytest

from vfem.errors import InputError
from vfem_examples import thick_cylinder as tc


def test_lame_and_hill_meet_at_first_yield_as_nu_goes_to_a_half():
    """Hill's pressure with the plastic zone at the bore, k (1 - a^2/b^2), is Lamé's first
    yield of an incompressible tube (von Mises: sigma_zz the mean of the in-plane stresses);
    the example's nu = 0.49 puts it 0.02 % away; the limit is 2k ln(b/a)."""
    p = tc.ThickCylinderParameters()
    incompressible = dataclasses.replace(p, poissons_ratio=0.5 - 1e-12)
    a, b = p.inner_radius, p.outer_radius
    assert tc.theory(incompressible)["first_yield_pressure"] == pytest.approx(
        tc.hill(p, a), rel=1e-9)
    assert tc.theory(p)["first_yield_pressure"] == pytest.approx(tc.hill(p, a), rel=1e-3)
    assert tc.theory(p)["limit_pressure"] == pytest.approx(
        2 / math.sqrt(3) * math.log(b / a), rel=1e-15)
    assert tc.hill(p, b) == pytest.approx(tc.theory(p)["limit_pressure"], rel=1e-15)
    assert tc.config(p).steps.load_factors == tc.pressures(p)


@pytest.mark.parametrize(("change", "words"), [
    ({"inner_radius": 0.0}, "inner_radius must be a finite number > 0"),
    ({"outer_radius": 0.5}, "outer_radius must exceed inner_radius"),
    ({"outer_radius": 1.5}, "the wall is too thin for the steps"),
    ({"poissons_ratio": 0.5}, r"poissons_ratio must be in \[0, 0.5\)"),
    ({"around": 1}, "around must be a whole number >= 2"),
    ({"radial": 2000}, "around x radial must be at most"),
    ({"yield_stress": math.inf}, "yield_stress must be a finite number > 0"),
])
def test_bad_parameters_are_named(change, words):
    p = dataclasses.replace(tc.ThickCylinderParameters(), **change)
    with pytest.raises(InputError, match=words):
        tc.validate(p)


def test_the_example_verifies_itself(tmp_path):
    """``vfem run thick_cylinder`` (defaults, 2,450 dofs, seconds): every verification record
    passes (first yield within 0.5 % of Lamé, the pressure at each plastic radius within 1 % of
    Hill, 0.995 of the limit carried), no point yielded at 0.9 of the first-yield pressure
    and the plastic zone growing outwards step by step."""
    summary = tc.run(tc.ThickCylinderParameters(), tmp_path, figures=False)
    assert summary["converged"]
    records = summary["verification"]
    assert len(records) == 7 and all(r["passed"] for r in records)
    radii = summary["thick_cylinder"]["plastic_radius"]
    assert radii[0] is None and all(b > a for a, b in zip(radii[1:], radii[2:]))
