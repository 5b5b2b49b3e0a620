"""A pair whose compatibility side cannot hold the contact at any step size is switched to the
other side (issue 37, ``vfem.solver.Analysis._switch_side``).

Two models of ``benchmarks/random_models.py`` (seed 0) stopped with the side the rules chose,
whatever the cuts, and solved with the other side forced (``--remedies``, 2026-11-30):

- 2d-75: a soft rotated rectangle of quadratic elements (366 times softer than the block) on a
  platen; its corner slides 0.0127 along the block's top, which the load turns by 2.5e-4 rad,
  and a block node under the corner reads 4.1e-6 inside against 3.0e-6 allowed by invariant
  (b) from load factor 0.23;
- 2d-215: a stiff round face (121 times stiffer, facets a third of the block's) pushed by a
  prescribed motion, a node past the block's outer layer of elements at load factor 0.91.

Frictionless contact under small kinematics has an answer for each load factor whatever the
path, so the switched run must end where the run forced to the other side from the start ends:
the same complementarity problem solved twice. The study's own checks (each body's K u against
its forces, the balance, no tension, no node inside the other on the deformed geometry) judge
every converged step.
"""
from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

import vfem

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import random_models  # noqa: E402

#: the two runs solve one linear complementarity problem at the last load factor with the same
#: contact set, by different paths: they differ by round-off times the condition of the pair
#: matrix (below 1e7 on these models), relative to the largest nodal force
SAME = 1e-9


def build(k: int, folder: Path, side: str | None = None):
    p = random_models.draw(0, 2, k)
    folder.mkdir(parents=True, exist_ok=True)
    config, info = random_models.build(p, folder)
    # (mesh files by their whole path: the runs below read them from any folder)
    config = dataclasses.replace(config, bodies=tuple(
        dataclasses.replace(b, mesh=dataclasses.replace(b.mesh, file=str(folder / b.mesh.file)))
        if b.mesh.file else b for b in config.bodies))
    if side is not None:
        config = dataclasses.replace(config, contact=dataclasses.replace(
            config.contact, compatibility_side=side))
    return p, config, info


@pytest.mark.parametrize(("k", "other"), [(75, "block"), (215, "upper")])
@pytest.mark.slow
def test_the_switched_side_solves_and_ends_where_that_side_forced_ends(k, other, tmp_path):
    p, config, info = build(k, tmp_path / "a")
    result = vfem.solve(config.build(tmp_path / "a"))
    assert result.converged, result.message
    checks = random_models.check(result, p, info)
    assert not checks["failed"], checks["deepest"]
    switched = [s.step for s in result.steps if s.compatibility_switched]
    assert switched, "the rules' side solved it: this test no longer tests the switch"
    assert switched == list(range(switched[0], len(result.steps) + 1))
    assert all(s.compatibility_switched == {"upper/block": other}
               for s in result.steps[switched[0] - 1:])

    _, forced_config, _ = build(k, tmp_path / "b", side=other)
    forced = vfem.solve(forced_config.build(tmp_path / "b"))
    assert forced.converged, forced.message
    assert not any(s.compatibility_switched for s in forced.steps)
    a, b = result.steps[-1], forced.steps[-1]
    assert a.load_factor == b.load_factor == 1.0
    for name, fa in a.bodies.items():
        fa, fb = fa.contact_force, b.bodies[name].contact_force
        assert np.abs(fa - fb).max() <= SAME * np.abs(fa).max()


def test_a_forced_side_is_not_switched(tmp_path):
    """``contact.compatibility_side`` set: the user's choice stands, and the stop says what
    to try."""
    _, config, _ = build(75, tmp_path, side="upper")
    result = vfem.solve(config.build(tmp_path))
    assert not result.converged
    assert not any(s.compatibility_switched for s in result.steps)
    assert "compatibility_side" in result.message


def test_a_side_that_cannot_reach_the_steps_before_is_not_kept(tmp_path, monkeypatch):
    """Where the other side does not reach the load factors already converged, the rules'
    side is kept (the state, the formulation and the checkpoint all of it) and the stop says
    what was tried instead of proposing it."""
    import vfem.solver

    monkeypatch.setattr(vfem.solver.Analysis, "_replay", lambda self, steps: None)
    _, config, _ = build(75, tmp_path)
    analysis = vfem.solver.Analysis(config.build(tmp_path))
    result = analysis.run()
    assert not result.converged
    assert "the solver tried the other body of the two on the compatibility side and kept " \
        "the rules'" in result.message
    assert "contact.compatibility_side = " not in result.message
    assert not analysis.sides and analysis.checkpoint().sides == []
    assert not any(s.compatibility_switched for s in result.steps)
    names = [b.name for b in analysis.model.bodies]
    (pair, (carrier, _)), = analysis.contact.carriers.items()
    assert names[carrier] == "upper"  # the rules' side: the soft rectangle
    analysis.contact.penetrations(analysis.state)  # the state is that formulation's


@pytest.mark.slow
def test_a_run_resumed_after_the_switch_ends_as_the_whole_run(tmp_path):
    """The switch is part of the checkpoint: resumed after it, the run goes on with the
    switched side (every step's contact forces as the whole run's, contact.csv the same)."""
    from resume_check import assert_resumed_equals_whole

    _, config, _ = build(75, tmp_path / "mesh")
    resumed = assert_resumed_equals_whole(config, tmp_path, stop_after=4)
    assert [bool(s.get("compatibility_switched")) for s in resumed["steps"]] == \
        [False, False, False, True, True, True]


@pytest.mark.slow
def test_the_docs_large_gasket_runs_through_on_the_other_side():
    """The large-kinematics gasket of docs/examples.md (``vfem run gasket --set
    kinematics=total --set order=1 --set n_through=3 --set back_motion=0.5``) stopped at step
    11: a stiff vertex between two soft nodes that carry no force, 4.79e-6 inside where
    2.62e-7 is allowed. The stiff gasket switched onto the compatibility side, the bodies go
    through the steps so far again from unloaded and the run ends; every step after the switch
    is where the run with the stiff gasket forced from the start is at that load factor, to a
    few of the contact iteration's penetration tolerances (the two runs stop their contact
    iterations at different states within it; hyperelastic bodies and frictionless contact
    leave nothing else to the path)."""
    from vfem_examples import gasket

    cfg = gasket.config(gasket.GasketParameters(kinematics="total", order=1, n_through=3,
                                                back_motion=0.5))
    result = vfem.solve(cfg.build())
    assert result.converged, result.message
    switched = [s for s in result.steps if s.compatibility_switched]
    assert switched and all(s.compatibility_switched == {"soft/stiff": "stiff"}
                            for s in switched)
    forced = vfem.solve(dataclasses.replace(cfg, contact=dataclasses.replace(
        cfg.contact, compatibility_side="stiff")).build())
    assert forced.converged, forced.message
    at = {round(s.load_factor, 12): s for s in forced.steps}
    tol = 10 * result.penetration_tolerance
    compared = 0
    for s in switched:
        other = at.get(round(s.load_factor, 12))
        if other is None:
            continue
        compared += 1
        for name, fields in s.bodies.items():
            assert np.abs(fields.displacement - other.bodies[name].displacement).max() <= tol
    assert compared >= 10


def test_a_frictional_pair_is_not_switched():
    """With friction the answer at a load factor owes its slip history to the path, and so to
    the side that carried compatibility on the way: no switch. A soft block pressed on a base
    and pushed along it, both on a symmetry plane through the contact (3D, small kinematics,
    mu = 0.3), breaks invariant (b) at load factor 1.77 whatever the cuts: frictionless, the
    switch would have tried the base's side (it did, wrongly, while the frictional formulation
    was the frictionless one holding a friction part); with friction the run stops there, the
    rules' side kept, and the stop message offers the other side to the user instead of saying
    it was tried."""
    from vfem.bodies import Body, PrescribedDisplacement, Support
    from vfem.contact.settings import ContactSettings
    from vfem.materials import LinearElastic
    from vfem.mesh.solids import box
    from vfem.solver import Analysis, Model

    press, shove = ((0.0, 0.0), (0.5, 1.0), (2.0, 1.0)), ((0.0, 0.0), (0.5, 0.0), (2.0, 1.0))
    material = LinearElastic(1000.0, 0.3)
    base = Body("base", box(0.0, -1.0, -0.5, 1.0, 2.0, 0.5, 4, 8, 2), material,
                supports=(Support("bottom"), Support("left", ("x",))),
                contact_boundaries=("top",))
    moved = (PrescribedDisplacement("top", "z", -0.005, amplitude=press),
             PrescribedDisplacement("top", "y", 0.3, amplitude=shove))
    block = Body("block", box(0.0, -0.25, 0.0, 0.25, 0.5, 0.25, 2, 4, 2), material,
                 supports=(Support("left", ("x",)),), prescribed=moved,
                 contact_boundaries=("bottom",))
    model = Model("half 3d", [base, block], ContactSettings(friction=0.3),
                  [0.25, 0.5, 0.8, 1.2, 1.6, 2.0])
    result = Analysis(model).run()
    assert result.steps and not result.converged, "it solves: this test no longer tests it"
    assert not any(s.compatibility_switched for s in result.steps)
    assert "switched the pair's compatibility side" not in result.message
    assert "try the other body of the two on the compatibility side" in result.message
