"""A held node that its guard excused, found inside by invariant (b), is held (issue 37).

A stiff punch (550 times the block's modulus, its facets 2.8 times the block's) with filleted
corners lands, under a platen force, on its fillet. The block's top carries compatibility and
the punch's nodes are held where they would penetrate, but one whose guard (the block nodes of
the facet under it) all touch is left to the block's faceting. At load factor 0.52 a fillet
node lay 3.5e-7 inside where invariant (b) allowed less, and the step was cut six times and
the analysis stopped (random model 2d-132 of ``benchmarks/random_models.py``). The solver now
has the formulation hold that node and solves the step again
(``vfem.solver.Analysis._enforce``, ``vfem.contact.formulations.paired.PairedContact.enforce``).
Since a stiffer surface's own features are held whatever their guard (``held.held_nodes``), the
fillet's vertices are held from the start; the mechanism is tested with the guard as before.

The depth is read from the full-mesh results alone: every boundary node of the punch at
X + u against the polyline of the block's deformed top.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import vfem
import vfem.solver

MODEL = Path(__file__).parent / "data" / "models" / "fillet_landing.toml"


def deepest_punch_node(result, m: vfem.Model) -> float:
    last = result.steps[-1]
    bodies = {b.name: b for b in m.bodies}
    X = bodies["block"].mesh.p.T
    top = np.flatnonzero(np.isclose(X[:, 1], 0.0))
    top = top[np.argsort(X[top, 0])]
    xb = X[top] + last.bodies["block"].displacement[top]
    punch = bodies["upper"]
    nodes = np.unique(punch.mesh.facets[:, punch.mesh.boundary_facets()])
    xs = punch.mesh.p.T[nodes] + last.bodies["upper"].displacement[nodes]
    y_block = np.interp(xs[:, 0], xb[:, 0], xb[:, 1], left=-np.inf, right=-np.inf)
    return float((y_block - xs[:, 1]).max())


def test_a_fillet_node_inside_beyond_faceting_is_held_and_the_step_solved():
    m = vfem.load(MODEL).build()
    result = vfem.solve(m)
    assert result.converged, result.message
    assert all(not s.invariants["failed"] for s in result.steps)
    # the punch's nodes held exactly (the tolerance is the solver's own reading)
    assert deepest_punch_node(result, m) <= result.penetration_tolerance


def guard_as_before(monkeypatch):
    """Held nodes paired at their closest points and excused by their guard whatever their own
    surface does, as when this mechanism came (a stiff surface's own features, the punch's
    fillet vertices, are held now whatever their guard, and paired where the loads' approach
    meets the other surface: ``held.held_nodes``)."""
    import vfem.contact.formulations.pairmaking as pairmaking  # (where the pairs are made)
    made_by = pairmaking.held_nodes

    def as_before(*args, **kwargs):
        return made_by(*args, **{**kwargs, "features": False, "approach": None})

    monkeypatch.setattr(pairmaking, "held_nodes", as_before)


def test_alone_it_holds_the_node_and_solves_the_step(monkeypatch):
    guard_as_before(monkeypatch)
    m = vfem.load(MODEL).build()
    result = vfem.solve(m)
    assert result.converged, result.message
    assert deepest_punch_node(result, m) <= result.penetration_tolerance


def test_without_it_the_step_stops_at_invariant_b(monkeypatch):
    """The same model with no node held after a check, and the rules' compatibility side
    kept: the mechanism is what solves it (the solver's switch of the side solves it too,
    ``tests/test_side_switch.py``, and is left out here)."""
    guard_as_before(monkeypatch)
    monkeypatch.setattr(vfem.solver, "ENFORCED_NODES", 0)
    monkeypatch.setattr(vfem.solver.Analysis, "_switch_side", lambda self, *a: None)
    result = vfem.solve(vfem.load(MODEL).build())
    assert not result.converged
    assert "invariant (b)" in result.message
