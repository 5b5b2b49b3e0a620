"""The ring crush example (issue 42, item 3: ``vfem_examples.ring_crush``): a neo-Hookean ring
crushed until its bore closes on itself, self-contact at finite strain in plane strain."""

from __future__ import annotations

import dataclasses

import pytest

import vfem
from vfem.errors import InputError
from vfem_examples import ring_crush

#: a coarser ring crushed a little past the bore's closing (the default is docs/examples.md's)
QUICK = dataclasses.replace(ring_crush.RingCrushParameters(), around=16, radial=4, crush=0.78,
                            steps=13)


def test_the_ring_closes_on_itself_and_stiffens():
    """The bore closes on itself (its opening on the plane of symmetry falls to zero, then the
    self-contact pair carries force), never through itself (the opening not below the
    penetration tolerance, and every step's invariants passed: no node inside the bore's other
    side); once closed the ring is more than three times as stiff; the example's
    verification passes."""
    result = vfem.solve(ring_crush.config(QUICK))
    assert result.converged, result.message
    m = ring_crush.evaluate(result, QUICK)
    rows = m["steps"]
    assert m["closed_at_travel"] is not None
    closed = [r for r in rows if r["self_contact_force"] > 0]
    open_ = [r for r in rows if r["self_contact_force"] == 0]
    assert len(closed) >= 2 and len(open_) >= 5
    # the default penetration tolerance: 1e-5 of the shortest candidate facet (the bore's)
    facet = 0.5 * 3.141592653589793 * QUICK.inner_radius / QUICK.around
    assert min(r["bore_opening"] for r in rows) >= -1e-5 * facet
    assert all(r["invariants"] for r in rows)
    before = (open_[-1]["force"] - open_[-2]["force"]) / (open_[-1]["travel"]
                                                          - open_[-2]["travel"])
    after = (closed[-1]["force"] - closed[-2]["force"]) / (closed[-1]["travel"]
                                                           - closed[-2]["travel"])
    assert after > 3.0 * before > 0
    assert all(c["passed"] for c in ring_crush.verification(m)), ring_crush.verification(m)


@pytest.mark.parametrize(("change", "words"), [
    ({"outer_radius": 0.5}, "outer_radius must exceed inner_radius"),
    ({"crush": 1.0}, "crush must be below 1"),
    ({"split": 95.0}, "split must lie between 0 and 90 degrees"),
    ({"around": 2}, "around must be a whole number from 4 to 200"),
])
def test_what_the_ring_crush_refuses(change, words):
    with pytest.raises(InputError, match=words):
        ring_crush.validate(dataclasses.replace(ring_crush.RingCrushParameters(), **change))
