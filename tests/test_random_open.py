"""Random models of ``benchmarks/random_models.py`` that vfem still answers wrongly, kept as
strict expected failures so that the verification set holds the cases that do not work too
(issue 37; the study's own checks, which do not use vfem's contact code).

- 2d-50 of seed 4 (found 2026-11-30 on a seed not tuned for, after 2d-52 of seed 3 was
  mended; the same before that change): a soft graded quarter disk of quadratic elements
  (0.18 of the block's stiffness, facets 1.29 of the block's), 2.2 facets above the block and
  pushed by a platen into 3.6 % strain. As it flattens, its facet at the edge of contact turns
  by 0.087 rad while it slips 0.017 (a quarter facet) over the block: slip times rotation,
  linear theory's second-order term, is 1.5e-3, 7 % of the push. On the deformed geometry a
  block node lies 5.8e-4 (2.7 % of the push) inside that facet's curve, outside as linear
  theory reads it. Outside what small kinematics answers (docs/method.md, *The deformed
  geometry off by more than linear theory's second order*): large kinematics, open to linear
  elements only, reads the model with linear elements 0.004 % of the push inside; vfem warns
  that its deformed geometry is off (the second test).
"""
from __future__ import annotations

import logging
import sys
from pathlib import Path

import pytest

import vfem

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import random_models  # noqa: E402


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=(
    "small kinematics' second order (issue 37): a soft quadratic quarter disk flattened on a "
    "block, 2.7 % of the push inside on the deformed geometry"))
@pytest.mark.slow
def test_a_soft_quadratic_disk_flattened_on_a_block_stays_outside(tmp_path):
    p = random_models.draw(4, 2, 50)
    assert p["id"] == "2d-50" and p["order"] == 2
    config, info = random_models.build(p, tmp_path)
    result = vfem.solve(config.build(tmp_path))
    assert result.converged, result.message
    checks = random_models.check(result, p, info)
    assert not checks["failed"], checks["deepest"]


def test_vfem_warns_that_the_disk_s_deformed_geometry_is_off(tmp_path, caplog):
    """2d-50 is not a silent answer: the step's invariants record a node inside on the deformed
    geometry beyond the allowance for faceting and linear theory's second order, and the run
    warns about it once, naming the remedy (large kinematics, linear elements)."""
    p = random_models.draw(4, 2, 50)
    config, info = random_models.build(p, tmp_path)
    with caplog.at_level(logging.WARNING, logger="vfem"):
        result = vfem.solve(config.build(tmp_path))
    assert result.converged, result.message
    found = [s.invariants["second_order"] for s in result.steps
             if s.invariants["second_order"] is not None]
    assert found
    worst = max(found, key=lambda w: w["beyond"])
    assert worst["deformed_depth"] > worst["allowed"] >= worst["linearised_depth"]
    warned = [r.getMessage() for r in caplog.records if "on the deformed geometry" in
              r.getMessage()]
    assert len(warned) == 1
    assert 'kinematics = "total" (with linear elements)' in warned[0]
    assert f"node {worst['node']} of body {worst['body']!r}" in warned[0]
    # the study judges the same answer 2 % of the push or more inside (the first test)
    checks = random_models.check(result, p, info)
    assert checks["depth_over_push"] > random_models.PUSH_FRACTION
