"""Random 3D models of ``benchmarks/random_models.py`` (seed 0) that vfem answered wrongly or
refused before the edges of both surfaces were held where they meet the other surface
(issue 37), each solved again and judged by the study's own checks, which do not use vfem's
contact code: each body's K u against its contact forces and reactions, the balance between
the bodies, no tension, and no node and no point of a sharp edge inside the other body on the
deformed geometry beyond 2 % of the push.

Measured before (2026-11-30, at 59efe15), the deepest point inside the other body, of the push:

- 3d-14: a soft block's rim 0.47 below a stiff sphere-ended punch's cap, read by its closest
  point at rest, under a facet near the cap's lowest point: 0.90 (now the rim is read where
  the ray along the loads' motion meets the cap, ``held.held_edges``);
- 3d-47: a soft block's rim under an overhanging stiff tilted box, its crossing of the box's
  edge 0.13 of a block facet from a rim node beyond the box, left to that node: 0.028;
- 3d-59: a stiff flat cylinder's rim across a soft block's twisted hexahedron faces, between
  two held crossings of one face: 0.051 (now held at the midpoint too, ``held._twisted``);
- 3d-17: a stiff tilted box's corner over a soft block's corner, the box's corner node over
  the block's top but its facets carrying none of the traction there: not held, 0.45 once
  the box's edge was no longer held against the block's side 0.42 below its top (an
  accident of the closest point at rest, now refused: ``over_facet``).

The first three are quick enough for every run; the slow set holds the others of the kind.

Not tuned for (seed 2): 3d-5, a stiff block's edge under a soft flat cylinder's face, crossed
two of the cylinder's facet edges 0.19 of a facet apart, between two of ``held_edges``'
samples; one bisection found one of them, and the edge lay 2.08 % of the push inside the
cylinder at the other (now both, ``held._crossings``: 0.30 %).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import vfem
from vfem.contact.geometry.held import _crossings

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import random_models  # noqa: E402


def solve_and_check(k: int, folder: Path, seed: int = 0) -> dict:
    p = random_models.draw(seed, 3, k)
    assert p["id"] == f"3d-{k}"
    config, info = random_models.build(p, folder)
    result = vfem.solve(config.build(folder))
    assert result.converged, result.message
    return random_models.check(result, p, info)


@pytest.mark.parametrize("k", [pytest.param(k, marks=pytest.mark.slow) for k in (14, 47, 59, 17)])
def test_an_edge_met_off_its_nodes_stays_outside(k, tmp_path):
    checks = solve_and_check(k, tmp_path)
    assert not checks["failed"], checks["deepest"]


@pytest.mark.slow
@pytest.mark.parametrize("k", [6, 30, 39, 41, 44, 53])
def test_the_other_rims_of_the_study_stay_outside(k, tmp_path):
    """3d-6, 3d-41 (a soft block's rim under an overhanging stiffer box), 3d-30 (a rim's
    crossing of a sphere's facet 0.06 of a facet from a held rim node), 3d-39, 3d-44, 3d-53 (a
    stiff block's rim under a soft sphere-ended punch's cap, 0.5 below it at rest)."""
    checks = solve_and_check(k, tmp_path)
    assert not checks["failed"], checks


@pytest.mark.slow
def test_two_crossings_between_two_samples_hold_the_edge(tmp_path):
    """3d-5 of seed 2 (module docstring)."""
    checks = solve_and_check(5, tmp_path, seed=2)
    assert not checks["failed"], checks["deepest"]


def test_two_crossings_between_two_samples_are_both_found():
    """``held_edges``' bisection: where the facet under an edge changes twice between two
    samples (the edge passing near a vertex of the other surface), both changes are found, and
    a third: each to round-off, with the facets on either side."""
    walls = np.array([0.30, 0.31, 0.32])

    def label(e, t, u):
        return np.searchsorted(walls, t)  # facets 0 | 1 | 2 | 3 along the edge

    e, lo, hi, u, s_lo, s_hi = _crossings(
        label, np.array([0]), np.array([0.25]), np.array([0.5]), np.full((1, 3), np.nan),
        np.array([0]), np.array([3]))
    order = np.argsort(lo)
    np.testing.assert_allclose(lo[order], walls, atol=1e-12)
    np.testing.assert_allclose(hi[order], walls, atol=1e-12)
    assert list(s_lo[order]) == [0, 1, 2] and list(s_hi[order]) == [1, 2, 3]
