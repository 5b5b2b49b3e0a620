"""Nightly cases (``python3 -m pytest -m slow``): finer meshes than CI can afford."""

import pytest

from vfem.solver import Analysis
from vfem_examples.hertz import HertzParameters, build, evaluate


@pytest.mark.slow
def test_hertz_level3_stays_within_a_fraction_of_a_percent():
    p = HertzParameters(refinement=3)
    r = Analysis(build(p)).run()
    assert r.converged
    h = evaluate(r, p)
    assert abs(h["p_max_error"]) < 0.003
    assert h["rms_error_over_p0"] < 0.01
    assert abs(h["a_estimate"] - h["a_theory"]) <= h["contact_facet_length"]
