"""The verification records (issue 39; :mod:`vfem.io.verification`) of the sliding, punch,
cattaneo and press_fit examples: each run as its own tests run it, every record passed, with a
source and a basis. Sliding's default run takes 15 s: it is slow, and a small slide (coarse
meshes, 8 block facets in two steps) checks the same records fast, its tolerances computed from
its own facets."""

from __future__ import annotations

import pytest

import vfem
from vfem.solver import Analysis
from vfem_examples import cattaneo, press_fit, punch, sliding


def verified(summary: dict, count: int) -> list[dict]:
    """The summary's records: ``count`` of them, every one passed, each with its source and
    the basis of its tolerance."""
    assert summary["converged"]
    records = summary["verification"]
    assert len(records) == count, [r["quantity"] for r in records]
    for r in records:
        assert r["passed"], r
        assert r["source"].strip() and r["basis"].strip(), r
        assert r["tolerance"] > 0
    return records


#: a small slide: the block 60 x 4 (facets 0.1), the punch 24 x 3, pressed in one step and slid
#: 0.4 (4 block facets) in two
SMALL_SLIDE = dict(block_columns=60, block_rows=4, punch_columns=24, punch_rows=3, slide=0.4,
                   press_steps=1, slide_steps=2, start=-0.2)


@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_a_small_slide_verifies(friction):
    p = sliding.Parameters(**SMALL_SLIDE, friction=friction)
    records = verified(sliding.summarize(Analysis(sliding.build(p)).run(), p),
                       4 if friction else 3)
    # the tolerances follow the facets: the punch's chord sag over the depth, the block's sag
    h_punch, h_block = 1.2 / 24, 6.0 / 60
    assert records[0]["tolerance"] == pytest.approx(
        1.5 * h_punch**2 / 8 / p.depth + 2 * sliding.ends(p), rel=1e-12)
    assert records[2]["tolerance"] == pytest.approx(1.5 * h_block**2 / 8, rel=1e-12)


@pytest.mark.slow
def test_the_sliding_example_verifies():
    p = sliding.Parameters()
    verified(sliding.summarize(Analysis(sliding.build(p)).run(), p), 3)


def test_the_punch_example_verifies():
    p = punch.Parameters()
    records = verified(punch.summarize(vfem.solve(punch.build(p)), p), 4)
    force = records[0]
    assert force["source"] == punch.RIGID and force["value"] < force["reference"]


def test_the_punch_reference_is_recorded_under_small_kinematics_only():
    """The rigid-punch reference is a small-strain solve: under kinematics = "total" it is no
    reference and there is no record; the corners' record is scaled by the largest nodal
    force (what contact.equilibrium_tolerance bounds)."""
    c = {"force": 1.0e7, "reference_force": 1.0e7, "punch_contact_force": [0.0, 1.0e7],
         "block_contact_force": [0.0, -1.0e7], "sideways_force": 0.0,
         "outside_punch_largest_force": 0.0, "largest_nodal_force": 1.0e6}
    settings = punch.ContactSettings()
    small = punch.verification(c, punch.Parameters(), settings)
    total = punch.verification(c, punch.Parameters(kinematics="total"), settings)
    assert small[0]["source"] == punch.RIGID and "no contact" in punch.RIGID
    assert [r["quantity"] for r in total] == [r["quantity"] for r in small[1:]]
    assert small[-1]["scale"] == 1.0e6
    thesis = punch.verification(c, punch.Parameters(), punch.ContactSettings(variant="thesis"))
    assert "contact force on the punch" not in [r["quantity"] for r in thesis]


def test_the_cattaneo_example_verifies():
    p = cattaneo.Parameters()
    result, _ = cattaneo.solve(p)
    records = verified(cattaneo.summarize(result, p), 4)
    # the stick zone's edge within one facet of the compatibility side (17 across a)
    assert records[0]["tolerance"] == pytest.approx(1 / 17, rel=0.05)


def test_the_press_fit_example_verifies():
    p = press_fit.Parameters()
    verified(press_fit.summarize(Analysis(press_fit.build(p)).run(), p), 4)


def test_the_press_fit_push_out_verifies():
    p = press_fit.Parameters(friction=0.3, push=0.02, push_steps=1)
    records = verified(press_fit.summarize(Analysis(press_fit.build(p)).run(), p), 5)
    assert records[-1]["reference"] == pytest.approx(press_fit.push_out_force(p), rel=1e-15)
