"""The O-ring example (issue 42, item 3: ``vfem_examples.oring``): a neo-Hookean body of revolution
squeezed at finite strain with friction, its verification, its walls, and its section."""

from __future__ import annotations

import dataclasses

import pytest

import vfem
from vfem.errors import InputError
from vfem_examples import oring

#: a coarser, shorter run than the default (its table is docs/examples.md's, a slow block)
QUICK = dataclasses.replace(oring.ORingParameters(), elements_across=20, steps=3)


def run(**change):
    p = dataclasses.replace(QUICK, **change)
    result = vfem.solve(oring.config(p))
    assert result.converged, result.message
    assert all(s.invariants["passed"] for s in result.steps)
    m = oring.evaluate(result, p)
    return p, m, oring.verification(m, result.model.contact)


def test_the_oring_verifies_itself_and_its_force_and_contact_grow():
    """At each step the lid's force, the contact width and the peak pressure grow with the
    compression; the walls (1.3 d apart) are not touched; both verification entries pass:
    the floor's force is the lid's to 1e-8 and no node's traction leaves Coulomb's cone."""
    _, m, checks = run()
    rows = m["steps"]
    assert len(rows) >= 3 and rows[-1]["compression"] == pytest.approx(0.3)
    for key in ("force_per_length", "contact_width", "peak_pressure"):
        values = [r[key] for r in rows]
        assert all(b > a > 0 for a, b in zip(values, values[1:])), key
    assert m["walls_touched_at"] is None
    assert all(c["passed"] for c in checks), checks
    assert m["cone"] == pytest.approx(1.0, abs=1e-8)  # the ring slides along the lid


def test_a_narrow_groove_is_touched_and_its_walls_take_their_share():
    """A groove 1.2 d wide: the ring, bulging to about 1.25 d at 30 %, touches both walls; the
    floor's force is then the lid's and the walls' friction along the axis (verified)."""
    _, m, checks = run(groove_width=2.4)
    assert m["walls_touched_at"] is not None and m["walls_touched_at"] <= 0.3
    assert m["steps"][-1]["wall_nodes"] > 0
    assert all(c["passed"] for c in checks), checks


def test_a_large_ring_is_the_straight_cord():
    """As D/d grows the ring's section tends to plane strain: at D = 100 d its force per unit
    circumference is the straight cord's per unit length (the plane-strain section, its
    quarter by symmetry) within 1 % (the hoop strain's share is of the order of d/D) at each
    step, and so are the contact width (within an element) and the peak pressure (1 %)."""
    ring = run(mean_diameter=200.0, groove_width=2.6)[1]["steps"]
    cord = run(mean_diameter=200.0, groove_width=2.6, section="plane strain")[1]["steps"]
    h = QUICK.cross_section / QUICK.elements_across
    for a, b in zip(ring, cord):
        assert a["force_per_length"] == pytest.approx(b["force_per_length"], rel=0.01)
        assert abs(a["contact_width"] - b["contact_width"]) <= 2 * h
        assert a["peak_pressure"] == pytest.approx(b["peak_pressure"], rel=0.01)


@pytest.mark.parametrize(("change", "words"), [
    ({"walls": "yes"}, "walls must be true or false"),
    ({"section": "plane stress"}, "section must be 'axisymmetric' or 'plane strain'"),
    ({"groove_width": 1.5}, "groove_width must exceed cross_section"),
    ({"compression": 0.7}, "compression must be below 0.6"),
    ({"elements_across": 2}, "elements_across must be a whole number from 4 to 400"),
])
def test_what_the_oring_refuses(change, words):
    with pytest.raises(InputError, match=words):
        oring.validate(dataclasses.replace(oring.ORingParameters(), **change))
