"""Thesis §4.2.1: the 1D example with two nonlinear springs (acceptance numbers of issue 2)."""

import pytest

from vfem_examples.springs import run


@pytest.fixture(scope="module")
def summary():
    return run()


def test_converges_every_step(summary):
    assert summary["converged"]
    assert [s["iterations"] for s in summary["steps"]][:4] == [0, 0, 0, 0]  # no contact yet


def test_step5_and_step6_match_the_exact_solution(summary):
    assert summary["contact_point"][4] == pytest.approx(12.196, abs=0.002)
    assert summary["contact_force"][4] == pytest.approx(395.8, abs=1.0)
    assert summary["contact_point"][5] == pytest.approx(12.431, abs=0.002)
    assert summary["contact_force"][5] == pytest.approx(893.4, abs=1.0)
    assert summary["stiffness_a"] == pytest.approx(1569, abs=1)
    assert summary["stiffness_b"] == pytest.approx(2074, abs=1)


def test_trace_of_step5_begins_like_the_thesis(summary):
    first, second = summary["trace"][4][:2]
    assert first["compatibility_force"] == pytest.approx(333, abs=2)
    assert second["equilibrium_error"] == pytest.approx(109, abs=2)
    assert second["equilibrium_force_a"] == pytest.approx(-43, abs=2)  # 43 lb to the right
    assert second["equilibrium_force_b"] == pytest.approx(66, abs=2)


def test_trace_of_step6_errors_shrink_like_the_thesis(summary):
    errors = [abs(it["equilibrium_error"]) for it in summary["trace"][5][1:5]]
    assert errors == pytest.approx([165, 33, 7, 1], abs=2)
