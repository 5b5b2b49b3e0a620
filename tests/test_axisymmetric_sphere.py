"""The axisymmetric sphere example (issue 42, ``vfem_examples.axisymmetric_sphere``): Hertz's
sphere on a flat as bodies of revolution, verified by its own ``summary.json``."""

from __future__ import annotations

import dataclasses
import math

import pytest

from vfem.errors import InputError
from vfem_examples import axisymmetric_sphere as ax


def test_the_theory_is_hertzs_sphere():
    """P = 4 E* a^3 / 3R gives back a = (3PR / 4E*)^(1/3) (R = 1) and p0 = 3P / (2 pi a^2)
    = 2 E* a / (pi R) (Johnson 1985, §4.2)."""
    p = ax.AxisymmetricSphereParameters()
    th = ax.theory(p)
    assert (3 * th["force"] / (4 * th["e_star"])) ** (1 / 3) == pytest.approx(
        p.contact_radius, rel=1e-12)
    assert th["p0_theory"] == pytest.approx(2 * th["e_star"] * p.contact_radius / math.pi,
                                            rel=1e-12)


@pytest.mark.parametrize("facets", [12, 24])
def test_the_example_verifies_itself_and_converges(tmp_path, facets):
    """At the default mesh (quadratic, a/12) and refined (a/24): the sphere's peak pressure
    and the contact radius of Hertz's ellipse fitted to its nodal pressures within issue 42's
    0.5 % of p0 and a (measured -0.09 % and -0.03 %; -0.36 % and -0.16 %), the contact's edge
    within a facet of a, the platen's force met; every invariant at every step."""
    p = dataclasses.replace(ax.AxisymmetricSphereParameters(), facets_per_radius=facets)
    summary = ax.run(p, tmp_path, figures=False)
    assert summary["converged"]
    records = summary["verification"]
    assert len(records) == 4 and all(r["passed"] for r in records), records
    assert all(s["invariants"]["passed"] for s in summary["steps"])


def test_the_fitted_radius_converges():
    """The fitted contact radius approaches Hertz's a as the facets shrink (a/6, a/12, a/24):
    its error falls at every refinement, as the fitted p0's stays within 0.5 %."""
    from vfem.solver import Analysis

    errors = []
    for facets in (6, 12, 24):
        p = dataclasses.replace(ax.AxisymmetricSphereParameters(), facets_per_radius=facets)
        m = ax.evaluate(Analysis(ax.build(p)).run(), p)
        errors.append(abs(m["a_fit"] / m["a_theory"] - 1))
        assert abs(m["p0_fit"] / m["p0_theory"] - 1) <= 5e-3
    assert errors[2] < errors[1] < errors[0]


def test_finer_is_closer():
    """The peak pressure's error falls with the facets (a/6 to a/12, quadratic)."""
    from vfem.solver import Analysis

    errors = []
    for facets in (6, 12):
        p = dataclasses.replace(ax.AxisymmetricSphereParameters(), facets_per_radius=facets)
        result = Analysis(ax.build(p)).run()
        m = ax.evaluate(result, p)
        errors.append(abs(m["sphere_p_max"] / m["p0_theory"] - 1))
    assert errors[1] < errors[0] <= 5e-3


@pytest.mark.parametrize(("change", "words"), [
    ({"contact_radius": 0.5}, "contact_radius must be at most 0.2"),
    ({"contact_radius": -1.0}, "contact_radius must be a finite number > 0"),
    ({"facets_per_radius": 0}, "facets_per_radius must be a whole number"),
    ({"order": 3}, "order must be 1 or 2"),
])
def test_bad_parameters_are_refused(change, words):
    p = dataclasses.replace(ax.AxisymmetricSphereParameters(), **change)
    with pytest.raises(InputError, match=words):
        ax.validate(p)
