"""Bodies that start apart under force control, and bodies that can never touch (issue 17,
item 8: "the stop diagnosis names the real cause").

A body pushed by a platen (force control) towards another from a gap wider than the contact
search distance finds it (:func:`vfem.contact.geometry.placement.platen_approach`): Hertz with a gap
gives Hertz's answer. Bodies that no load brings together are named with their distance, and an
analysis that fails for lack of contact says so rather than "allow more iterations".
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import vfem
from models import Raw, input_file, platen, support, toml_body
from vfem.config import check
from vfem.contact.geometry.placement import platen_approach
from vfem.io.input import loads
from vfem_examples.hertz import HertzParameters, build

PUCK = input_file(
    "puck",
    toml_body("block", dict(shape="rectangle", width=2.0, height=1.0, nx=8, ny=4, x0=-1.0,
                            y0=-1.0), support("bottom"), E=Raw("1e9")),
    toml_body("puck", dict(shape="rectangle", width=0.5, height=0.5, nx=4, ny=4, x0=-0.25,
                           y0=0.2), support("top", ["x"]), platen("top", "y", Raw("FORCE")),
              E=Raw("1e9")))


def puck(force: float, y0: float = 0.2):
    text = PUCK.replace("FORCE", repr(force)).replace("y0 = 0.2", f"y0 = {y0!r}")
    return check(loads(text), None)


def cylinder_force(result) -> np.ndarray:
    return result.steps[-1].bodies["cylinder"].contact_force.sum(axis=0)


def test_hertz_from_a_gap_gives_the_touching_answer():
    touching = vfem.solve(build(HertzParameters()))
    apart = vfem.solve(build(HertzParameters(initial_gap=0.05)))  # 2.5 search distances
    assert apart.converged
    p0 = touching.steps[-1].bodies["cylinder"].contact_pressure.max()
    p1 = apart.steps[-1].bodies["cylinder"].contact_pressure.max()
    assert p1 == pytest.approx(p0, rel=1e-9)
    assert cylinder_force(apart)[1] == pytest.approx(1530.0, rel=1e-10)


def test_a_platen_towards_the_other_body_finds_it():
    result = vfem.solve(puck(-1e6))
    assert result.converged
    block = result.steps[-1].bodies["block"].contact_force.sum(axis=0)
    assert block[1] == pytest.approx(-1e6, rel=1e-10) and abs(block[0]) < 1e-6


def test_bodies_that_cannot_touch_are_named_with_their_distance(caplog):
    result = vfem.solve(puck(+1e6))  # pulled away: nothing can hold the puck
    assert not result.converged
    assert "no contact was found" in result.message
    assert "'block' and 'puck' are 0.2 apart" in result.message
    assert "allow more iterations" not in result.message
    assert any("cannot touch in this analysis" in r.message for r in caplog.records)


def test_platen_approach_is_the_ray_distance():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    moving = (square + [0, 2], np.roll(square, -1, axis=0) + [0, 2])
    fixed = (square * [3, 1] - [1, 0], np.roll(square * [3, 1] - [1, 0], -1, axis=0))
    assert platen_approach(moving, fixed, np.array([0.0, -1.0])) == pytest.approx(1.0)
    assert platen_approach(moving, fixed, np.array([0.0, 1.0])) == np.inf
    beside = (moving[0] + [5, 0], moving[1] + [5, 0])
    assert platen_approach(beside, fixed, np.array([0.0, -1.0])) == np.inf


def test_a_platen_pulling_a_touching_body_away_is_named():
    """The puck touches the block, its platen pulls it up: no equilibrium exists, and the
    message says why rather than "allow more iterations"."""
    result = vfem.solve(puck(+1e6, y0=0.0))
    assert not result.converged
    assert "the platen on body 'puck' must move it along +y" in result.message
    assert "moves it away from every body it may touch" in result.message
    assert "allow more iterations" not in result.message


@pytest.mark.slow
def test_a_platen_whose_bodies_meet_edge_or_corner_first_is_held_on_either_side(
        monkeypatch):
    """Random model 3d-17 (a tilted box over a block's corner, pushed by a platen): with the
    box on the compatibility side none of its nodes' facets carry traction over the block, and
    before the box's corner node was held as a point (``pairmaking.make_pair``: a compatibility
    node over the other patch whose facets carry none of its traction) and the edges of both
    bodies where they cross the other's facets (``held.held_edges``), nothing held the
    platen: the analysis stopped with "no node of either body lies over the other's surface"
    (``PlatenUnpaired``). Now either side, forced or by default, converges with every
    invariant, the platen's force carried."""
    path = Path(__file__).parent / "data" / "models" / "tilted_box_over_corner.toml"
    monkeypatch.chdir(path.parent)  # (its mesh file is named relative to it)
    for side in (None, "upper", "block"):
        m = vfem.load(path).build()
        m.contact = dataclasses.replace(m.contact, compatibility_side=side)
        solved = vfem.solve(m)
        assert solved.converged, solved.message
        assert all(not s.invariants["failed"] for s in solved.steps)
        force = solved.steps[-1].bodies["upper"].contact_force.sum(axis=0)
        assert force[2] == pytest.approx(-m.bodies[0].platen.force, rel=1e-8)
