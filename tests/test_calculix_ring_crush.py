"""The ring crush in CalculiX (issue 42's acceptance: "Ring crush: the force-deflection curve up to
and past self-contact against CalculiX (the same mesh, ``*CONTACT PAIR`` of the surface with
itself ...) within 2 %; no node inside its own body at any converged step";
``benchmarks/ring_crush_calculix.py``).

The deck (always checked): the ring's self-contact pair, two named boundaries of one body, is
written as two element-face surfaces of the bore's parts and a ``*CONTACT PAIR`` between them
(the upper part the slave, the lower the master), beside the ring's outside against the plate.

Where ccx is installed (slow): the example's ring is CalculiX's own law
(``law = "neo-hookean-isochoric"``, ``*HYPERELASTIC, NEO HOOKE``): the plate's force within 2 %
of ccx's at every step, before and after the bore closes (measured: +0.72 % at the first step,
whose contact with the plate is a facet or two wide, then within 0.42 %); with Saint
Venant-Kirchhoff in both (ccx's ``*ELASTIC`` under NLGEOM; up to a travel of 0.9, past which it
buckles in both) within 0.2 % but at the first step. vfem's Ciarlet-Simo neo-Hookean
(``law = "neo-hookean"``) is not ccx's law: against ccx's NEO HOOKE it reads +2.2 % at 0.9,
+6.4 % at 1.40 and 8 to 20 % after the bore closes (``benchmarks/ring_crush_calculix.py --law
neo-hookean``): the law's difference, not the contact's.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

from vfem_examples import ring_crush
from vfem_tools.calculix import run, write_deck

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import ring_crush_calculix as bench  # noqa: E402

from test_calculix import blocks as cards  # noqa: E402
from test_calculix import needs_ccx  # noqa: E402

PENALTY = 1e8  # the benchmark's: a tenth changes the force by 0.34 % at most


def test_the_self_contact_pair_is_two_element_surfaces_of_the_ring(tmp_path):
    """Two ``*CONTACT PAIR``: the ring's outside (slave) with the plate, the bore's upper part
    (slave) with its lower part (master); each named side an element-face surface whose faces
    are its boundary's facets; both pairs' forces printed at every step; NLGEOM, NEO HOOKE."""
    model = ring_crush.build()
    deck = write_deck(model, tmp_path / "ring.inp", steps="model", penalty=PENALTY)
    assert deck.pairs == [("S_RING_OUTER", "S_PLATE"),
                          ("S_RING_INNER_UPPER", "S_RING_INNER_LOWER")]
    assert (deck.slave, deck.master) == ("ring", "plate")
    c = cards(deck.path.read_text())
    keys = [k for k, _ in c]
    pairs = [data for k, data in c if k.startswith("*CONTACT PAIR")]
    assert pairs == [["S_RING_OUTER, S_PLATE"], ["S_RING_INNER_UPPER, S_RING_INNER_LOWER"]]
    assert "*SURFACE, NAME=S_RING, TYPE=ELEMENT" not in keys  # only the sides the pairs name
    elements = {int(row.split(",")[0]): [int(v) for v in row.split(",")[1:]]
                for k, data in c if k.startswith("*ELEMENT") for row in data}
    ring = model.bodies[0]
    for name, boundary in (("S_RING_OUTER", "outer"), ("S_RING_INNER_UPPER", "inner_upper"),
                           ("S_RING_INNER_LOWER", "inner_lower")):
        (faces,) = [data for k, data in c if k == f"*SURFACE, NAME={name}, TYPE=ELEMENT"]
        got = set()
        for row in faces:
            e, label = (v.strip() for v in row.split(","))
            conn = elements[int(e)]
            k = int(label[1:]) - 1
            got.add(frozenset((conn[k] - 1, conn[(k + 1) % 4] - 1)))
        want = {frozenset(f) for f in ring.mesh.facets[:, ring.mesh.boundaries[boundary]].T
                .tolist()}
        assert got == want, name
    steps = [k for k in keys if k.startswith("*STEP")]
    assert len(steps) == 32 and all("NLGEOM" in k for k in steps)
    assert keys.count("*CONTACT PRINT, SLAVE=S_RING_INNER_UPPER, MASTER=S_RING_INNER_LOWER") == 32
    assert "*HYPERELASTIC, NEO HOOKE" in keys


@needs_ccx
@pytest.mark.slow
def test_ccx_crushes_the_ring_as_vfem_does_under_one_law(tmp_path):
    """Saint Venant-Kirchhoff in both codes (the same law), 18 steps to a travel of 0.9 (about
    15 s): the plate's force within 1 % at every step (measured: +0.69 % at the first, whose
    contact with the plate is a facet or two wide, then within 0.2 %) and the bore's opening
    within 1e-3 (measured 4e-4)."""
    import vfem

    p = dataclasses.replace(ring_crush.RingCrushParameters(), crush=0.45, steps=18)
    config = bench.with_law(ring_crush.config(p), "saint-venant-kirchhoff")
    result = vfem.solve(config)
    assert result.converged, result.message
    ours = {round(r["load_factor"], 9): r for r in ring_crush.evaluate(result, p)["steps"]}
    deck = write_deck(config.build(), tmp_path / "ring.inp", steps="model", penalty=PENALTY)
    theirs = bench.ccx_rows(run(deck), deck, p)
    assert sorted(theirs) == sorted(ours)
    for lf, v in ours.items():
        assert v["force"] == pytest.approx(theirs[lf]["force"], rel=0.01), v["travel"]
        assert v["bore_opening"] == pytest.approx(theirs[lf]["bore_opening"], abs=1e-3)


@pytest.fixture(scope="module")
def crushed(tmp_path_factory):
    """The example's defaults in both codes (about 35 s): vfem's rows, ccx's rows, the
    parameters and vfem's deepest node of the bore's upper part inside the lower part."""
    import vfem

    p = ring_crush.RingCrushParameters()
    result = vfem.solve(ring_crush.config(p))
    assert result.converged, result.message
    evaluated = ring_crush.evaluate(result, p)
    ring = result.model.bodies[0]
    inside = max(bench.self_penetration(ring.mesh, np.asarray(st.bodies["ring"].displacement))
                 for st in result.steps)
    deck = write_deck(ring_crush.build(p), tmp_path_factory.mktemp("ccx") / "ring.inp",
                      steps="model", penalty=PENALTY)
    theirs = bench.ccx_rows(run(deck), deck, p)
    return evaluated, theirs, p, inside


@needs_ccx
@pytest.mark.slow
def test_ccx_closes_the_bore_on_itself(crushed):
    """Both codes reach every step; the bore closes in both (vfem's self-contact force from a
    travel of 1.45, ccx's from 1.50: its surface-to-surface contact sees no overlap at its
    integration points at 1.45, where the bore's top node is 1.4e-4 inside), and carries most
    of the load at the end; ccx's plate balances its foot; vfem's invariants passed at every
    step: no node inside the ring's other side beyond the penetration tolerance and the
    faceting allowance (the benchmark's own reading, without the allowance: 1.2e-5 at the
    last step, 7e-4 of a bore facet, where the flattened bore's other side turns between its
    nodes; ccx's nodes up to 1.4e-4 inside); the forces within 2 % up to a travel of 0.8."""
    evaluated, theirs, p, inside = crushed
    ours = {round(r["load_factor"], 9): r for r in evaluated["steps"]}
    assert sorted(theirs) == sorted(ours)
    assert evaluated["steps_passed"] == len(ours)
    assert inside < 0.5 * np.pi * p.inner_radius / p.around  # within a bore facet
    last = max(ours)
    for rows in (ours, theirs):
        assert 0.6 < rows[last]["self_contact_force"] / rows[last]["force"] < 1.0
        assert rows[0.9375]["self_contact_force"] > 0  # a travel of 1.50
    assert ours[0.90625]["self_contact_force"] > 0  # 1.45
    for c in theirs.values():
        assert c["foot"] == pytest.approx(c["force"], rel=1e-4)
    for lf, v in ours.items():
        if v["travel"] <= 0.8 + 1e-9:
            assert v["force"] == pytest.approx(theirs[lf]["force"], rel=0.02), v["travel"]


@needs_ccx
@pytest.mark.slow
def test_the_force_curve_is_within_2_percent_of_ccx(crushed):
    """The acceptance: the plate's force within 2 % of ccx's at every step, up to and past
    the bore's closing, the same law in both (the example's)."""
    evaluated, theirs, _, _ = crushed
    for v in evaluated["steps"]:
        lf = round(v["load_factor"], 9)
        assert v["force"] == pytest.approx(theirs[lf]["force"], rel=0.02), v["travel"]
