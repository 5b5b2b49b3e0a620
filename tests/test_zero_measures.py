"""Issue 37, item 5: convergence measures that never divide by a zero, and the thesis variant
outside its tolerance is not converged.

* A platen whose force is zero (a load curve at zero: a body held sideways by a platen while it
  is pressed, its sideways force exactly zero) was met only by an exactly zero reaction
  (``platen_tolerance`` times the force): the frictional press below, 2D and 3D, and two punches
  on one block with one held sideways so, stopped in their first step after 100 iterations with
  every error at 1e-17 (``SurfaceGroup.platen_allowance`` measures a zero force against the
  forces its reaction sums); and the frictional correction did not move a platen whose force
  is zero (``SmallFriction._correct_frictional``), so where friction makes a sideways
  reaction the iteration could not remove it.
* In 3D a node of a frictionless pair in a frictional model slips with no traction: its slip
  direction -s / |s| was 0 / 0 (NaN errors, warnings on the screen).
* The thesis variant stopped at its fixed point outside its tolerance and reported converged.

Each model here is checked against physics (balance, the platen's force) and a reference: the
zero force against the same model with a force of 1e-9 of the load instead of zero, which the
code before solved (its platen was bordered), so the answer is continuous at zero.
"""

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import vfem
from models import Raw, block_on_base, box_mesh, platen, prescribed, pressed, rectangle_mesh
from vfem.cli import main
from vfem.io.input import dumps, loads
from vfem_examples.hertz import config as hertz_config

EXAMPLES = Path(__file__).parent.parent / "examples"

#: a platen's load curve: its force times ZERO (filled in by :func:`solve`) during the press
AFTER_PRESS = [[0.0, Raw("ZERO")], [0.5, Raw("ZERO")], [1.0, 1.0]]

#: a block pressed on a wider base by moving its top down over load factors 0 to 0.5, held in x
#: only by a platen on its left face: its force zero during the press, then pushing it sideways
#: (load factors 0.5 to 1) below the friction's limit (mu = 0.3 of a normal force near 9.4)
PRESS_2D = block_on_base(
    "press_then_push", rectangle_mesh(-1.0, -1.0, 2.0, 1.0, 24, 12),
    rectangle_mesh(-0.5, 0.0, 1.0, 0.5, 14, 7), pressed(-0.01),
    platen("left", "x", 1.0, amplitude=AFTER_PRESS),
    names=("base", "block"), friction=0.3, load_factors=[0.25, 0.5, 0.75, 1.0])

#: the same in 3D: a box pressed on a wider one (z), held along y by its top and along x by a
#: platen on its left face, zero during the press, then pushing it (0.2 at the end)
PRESS_3D = block_on_base(
    "press_then_push_3d", box_mesh(-1.0, -1.0, -0.5, 2.0, 2.0, 0.5, 8, 8, 2),
    box_mesh(-0.68, -0.5, 0.0, 0.5, 0.5, 0.25, 4, 4, 2), pressed(-0.005, "z"),
    prescribed("top", "y", 0.0), platen("left", "x", 0.2, amplitude=AFTER_PRESS),
    names=("base", "block"), friction=0.3, load_factors=[0.25, 0.5, 0.75, 1.0])


def solve(text: str, zero: float = 0.0, *changes: str):
    """The model of ``text`` with its platen's press-time multiplier ``zero``, solved."""
    return vfem.solve(loads(text.replace("ZERO", repr(zero)), "<test>", changes).build())


def totals(step, body: str) -> np.ndarray:
    return step.bodies[body].contact_force.sum(axis=0)


def check_press_then_push(result, platen_force: float, normal: int):
    """Converged in every step with errors at round-off; the block's contact force balances
    its platen: zero sideways while it is pressed, then the platen's force, sticking (within mu
    of the normal force); the two bodies' forces equal and opposite."""
    assert result.converged, result.message
    assert [s.cuts for s in result.steps] == [0, 0, 0, 0]
    model = result.model
    platen = next(b.platen for b in model.bodies if b.platen is not None)
    for step in result.steps:
        assert step.history[-1].max_penetration <= 1e-12  # (tolerance 7e-7, 1.25e-6)
        block, base = totals(step, "block"), totals(step, "base")
        load = abs(block[normal])
        assert load > 0
        np.testing.assert_allclose(block + base, 0.0, atol=1e-12 * load)
        # along x only the platen holds the block: the contact holds what the platen pushes,
        # to the platen's tolerance (3D: the block's top holds it along y)
        target = -platen.force_at(step.load_factor)
        assert block[0] == pytest.approx(target, abs=1e-5 * max(abs(target), load))
        sideways = np.delete(block, normal)
        assert np.linalg.norm(sideways) < 0.3 * load  # below the friction's limit: it sticks
    assert platen.force_at(0.5) == 0.0 and platen.force_at(1.0) == platen_force


def check_continuous_at_zero(result, reference, nodal: int | None = None,
                             component: int = 0):
    """Every nodal contact force of the first ``nodal`` steps (all by default) as with a force
    of 1e-9 instead of zero, to the platen's own tolerance: a zero force is met within 1e-5 of
    the forces its reaction sums (``SurfaceGroup.platen_allowance``), so the two answers differ
    by up to that (1.8e-7 of the largest with SuperLU, where 1e-6 was fitted to PARDISO's). In
    the steps after those, where the discrete problem does not determine the nodal forces (the
    3D test), each body's resultant along the platen (``component``), to the same tolerance of
    its largest resultant."""
    for i, (step, ref) in enumerate(zip(result.steps, reference.steps, strict=True)):
        for name, r in ref.bodies.items():
            if nodal is None or i < nodal:
                scale = np.abs(r.contact_force).max()
                np.testing.assert_allclose(step.bodies[name].contact_force, r.contact_force,
                                           rtol=0, atol=1e-5 * scale)
            else:
                total = r.contact_force.sum(axis=0)
                assert totals(step, name)[component] == pytest.approx(
                    total[component], abs=1e-5 * np.abs(total).max())


def check_coulomb(result, body: str, mu: float):
    """Coulomb's law at every compatibility-side node of ``body`` in every step, from the
    output fields: within the cone ``|s| <= mu q`` (to ``CONE_TOLERANCE``), a sticking node
    with no slip within the step (to the penetration tolerance), a slipping node on the cone
    (3D writes the slip increment's length only: its direction, opposite s, is the solve's
    check)."""
    tol = result.penetration_tolerance
    for step in result.steps:
        b = step.bodies[body]
        on = b.friction_status > 0
        assert on.any()
        shear = np.linalg.norm(b.contact_shear[on], axis=1)
        cone = mu * b.contact_traction[on]
        status, slip = b.friction_status[on], b.slip_increment[on]
        assert np.all(cone > 0)
        assert np.all(shear <= cone + 1e-9 * cone.max())
        assert np.all(np.abs(slip[status == 1]) <= tol)
        np.testing.assert_allclose(shear[status == 2], cone[status == 2], rtol=0,
                                   atol=1e-9 * cone.max())


def test_a_frictional_press_with_a_zero_sideways_force_2d():
    """Before: step 1 stopped after 100 iterations, 6 cuts ("penetration 1.36e-20, tangential
    slip error 3.17e-17"); the platen's reaction was 0.22 off its zero force and the
    correction never moved it."""
    result = solve(PRESS_2D)
    check_press_then_push(result, 1.0, normal=1)
    assert all(s.iterations <= 2 for s in result.steps)
    check_continuous_at_zero(result, solve(PRESS_2D, 1e-9))


def test_a_frictional_press_with_a_zero_sideways_force_3d():
    """Before: step 1 stopped after 100 iterations, 6 cuts ("penetration 1.02e-20").

    The nodal forces are compared with the 1e-9 model's during the press only (the first two
    steps, where the platen's force is zero or 1e-9: 4e-7 of the largest apart, SuperLU and
    PARDISO alike). Once the platen pushes (load factors 0.75 and 1) the discrete problem has
    more than one solution, so only the resultant along the platen and Coulomb's law are
    checked there. The pair matrix G over the block's 25 q and 2 x 25 s has two null
    directions: x-tractions on the leading row (the nodes on the platen's face, whose x motion
    is the platen's rigid one), self-equilibrated into the platen (singular values 4e-18 of
    its largest; the platen's reaction unchanged). At load factor 0.75 PARDISO (MKL 2026.2.1)
    and SuperLU met the same equations on different sets: node 0's s_x -4.78 on its cone
    against -1.96 (0.77 of it), both with no slip; node 7 slipping 1.05e-5 on its cone
    against sticking at 0.94 of it. Each state, put into the other's equations (exact under
    small kinematics), meets them to 1.6e-9 (tolerance 1.25e-6). Their nodal forces are
    2.8e-2 of the largest apart, displacements 3.8e-3, the normal resultant 1e-5 of itself;
    the resultant along the platen and the balance agree to round-off. The solve picks one
    through a correction whose system is singular (smallest singular value 3e-22 of the
    largest), so which one depends on the linear solver's round-off."""
    result = solve(PRESS_3D)
    check_press_then_push(result, 0.2, normal=2)
    reference = solve(PRESS_3D, 1e-9)
    check_continuous_at_zero(result, reference, nodal=2)
    check_coulomb(result, "block", 0.3)
    check_coulomb(reference, "block", 0.3)


def test_two_punches_one_held_sideways_by_a_zero_force_platen(tmp_path):
    """The left punch of ``examples/punch/two_punches.toml`` held sideways by a platen with no
    force instead of a support. Frictionless and flat, nothing pushes it sideways: the answer
    is the supported example's. Before: step 1 stopped after 100 iterations, 6 cuts
    ("penetration 3.39e-20")."""
    text = (EXAMPLES / "punch" / "two_punches.toml").read_text()
    held = """[[bodies.supports]]
boundary = "top"
components = ["x"]

[[bodies.prescribed]]
boundary = "top"
component = "y"
value = -0.01

[[bodies]]
name = "right\""""
    assert held in text
    platen = held.replace('[[bodies.supports]]\nboundary = "top"\ncomponents = ["x"]',
                          '[bodies.platen]\nboundary = "top"\ncomponent = "x"\nforce = 0.0')
    result = vfem.solve(loads(text.replace(held, platen), "<test>").build())
    reference = vfem.solve(loads(text, "<test>").build())
    assert result.converged, result.message
    assert all(s.history[-1].max_penetration <= 1e-12 for s in result.steps)
    for step, ref in zip(result.steps, reference.steps, strict=True):
        left = totals(step, "left")
        assert abs(left[0]) <= 1e-5 * left[1]  # the platen's zero force, to its tolerance
        for name in ("block", "left", "right"):
            np.testing.assert_allclose(totals(step, name), totals(ref, name), rtol=1e-9,
                                       atol=1e-9 * abs(totals(ref, "block")[1]))


@pytest.mark.slow
def test_a_frictionless_pair_in_a_frictional_3d_model_has_no_nan():
    """Three plates of ``examples/stack.toml``, the lower pair with friction, the upper one
    frictionless: the upper pair's nodes slip with no traction, whose direction -s/|s| was
    0/0 (NaN in the friction's errors, warnings on the screen). Now no warning; the
    frictionless pair carries no tangential force, and every force balances."""
    text = (EXAMPLES / "stack.toml").read_text()
    pairs = """[[contact.pairs]]
bodies = ["plate0", "plate1"]
friction = 0.3

[[contact.pairs]]
bodies = ["plate1", "plate2"]
friction = 0.0

"""
    at = text.index("[[bodies]]")
    model = loads(text[:at] + pairs + text[at:], "<test>").build()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        result = vfem.solve(model)
    assert result.converged, result.message
    last = result.steps[-1]
    top = totals(last, "plate2")  # what the frictionless pair carries
    assert top[2] > 0
    assert np.abs(top[:2]).max() <= 1e-9 * abs(top[2])
    assert np.abs(sum(totals(last, b.name) for b in model.bodies)).max() <= 1e-9 * abs(top[2])


def hertz_unloaded(end: float):
    """The Hertz example with its platen's force loaded and unloaded back to ``end`` times its
    peak along a load curve."""
    text = dumps(hertz_config())
    assert "force = -1530.0\n" in text and "[steps]\ncount = 5" in text
    text = text.replace("force = -1530.0\n", "force = -1530.0\namplitude = [[0.0, 0.0], "
                        f"[0.5, 1.0], [1.0, {end!r}]]\n")
    text = text.replace("[steps]\ncount = 5", "[steps]\nload_factors = [0.25, 0.5, 0.75, 1.0]")
    return loads(text, "<test>", ("contact.max_step_cuts=0",)).build()


def test_a_platen_unloaded_to_zero_converges_or_names_the_platen_and_the_remedy():
    """The Hertz cylinder, which only its platen and the contact hold, unloaded to a zero force:
    nothing then holds it (it is free to lift off). The step converges with no contact force,
    or it stops, and the message names the platen, how far off its force, and what to change;
    the remedy it names (end the curve at a small force) measured to work."""
    result = vfem.solve(hertz_unloaded(0.0))
    if result.converged:
        assert np.abs(totals(result.steps[-1], "cylinder")).max() <= 1e-9 * 1530
    else:
        assert len(result.steps) == 3  # loaded, then unloaded half-way
        assert "the platen on body 'cylinder' is" in result.message
        assert "off its force 0 (allowed" in result.message
        assert "end the platen's load curve at a small force instead of zero" in result.message
    remedy = vfem.solve(hertz_unloaded(1e-3))
    assert remedy.converged, remedy.message
    last = totals(remedy.steps[-1], "cylinder")
    assert last[1] == pytest.approx(1.53, rel=1e-5)  # the platen's force, 1e-3 of 1530
    np.testing.assert_allclose(last + totals(remedy.steps[-1], "flat"), 0.0, atol=1e-12)


def run_cli(tmp_path: Path, name: str, *changes: str) -> tuple[int, dict]:
    out = tmp_path / name
    status = main(["-q", "run", str(EXAMPLES / "punch" / "flat_punch.toml"), "--no-figures",
                   "--out", str(out), *[a for c in changes for a in ("--set", c)]])
    return status, json.loads((out / "summary.json").read_text())


@pytest.mark.slow
def test_the_thesis_variant_outside_its_tolerance_is_not_converged(tmp_path, capsys):
    """The stiff flat punch (200 times the block's modulus): the thesis variant stops every
    step at its fixed point, penetrations of 1e-3 where its tolerance is 3.7e-7, the block and
    the punch carrying forces 2 % apart. Before: exit status 0 and "converged": true. Now the
    run writes every step but is not converged (exit status 1, as any analysis that does not
    converge), and says what to change: the paired variant, measured here to solve it."""
    status, s = run_cli(tmp_path, "thesis", "contact.variant=thesis")
    assert status == 1 and not s["converged"]
    tol = s["penetration_tolerance"]
    assert all(x["stopped_at_fixed_point"] and not x["converged"] for x in s["steps"])
    assert len(s["steps"]) == 4 and max(x["max_penetration"] for x in s["steps"]) > 1e3 * tol
    assert "stopped at the thesis variant's fixed point OUTSIDE its tolerance" in s["message"]
    assert 'contact.variant = "paired"' in s["message"]
    assert len(list((tmp_path / "thesis").glob("*.vtu"))) == 8  # every step's results kept
    err = capsys.readouterr().err
    assert "vfem: the analysis did not converge: 4 of 4 steps stopped" in err
    block = -s["bodies"]["block"]["contact_force"][1]
    punch_force = s["bodies"]["punch"]["contact_force"][1]
    assert abs(block / punch_force - 1) > 0.01  # its forces do not balance

    status, p = run_cli(tmp_path, "paired")  # the remedy it names
    assert status == 0 and p["converged"]
    assert not any(x["stopped_at_fixed_point"] for x in p["steps"])
    block = -p["bodies"]["block"]["contact_force"][1]
    assert block == pytest.approx(p["bodies"]["punch"]["contact_force"][1], rel=1e-10)
    # the block alone under a rigid punch (vfem_examples.punch.reference_force): -0.26 %
    assert block == pytest.approx(1.06696e7, rel=0.01)
