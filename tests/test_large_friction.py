"""Coulomb friction under large displacements (issue 20, item 3;
vfem.contact.formulations.large_friction): a block slid far over another carries mu times its normal
force, in any orientation and either body order; a block pushed less than its friction allows
sticks, as the small-kinematics friction says for a small push; what is not solved yet is refused
naming why."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from models import Raw, block_on_base, built, pressed, rectangle_mesh, slid
from resume_check import as_written_before_columns, assert_resumed_equals_whole
from vfem.contact.formulations.formulation import formulation_class
from vfem.contact.formulations.large_friction import FrictionalLargeContact
from vfem.contact.settings import ContactSettings, PairFriction
from vfem.errors import InputError
from vfem.io.input import loads
from vfem.io.results import frictional_work
from vfem.solver import Analysis, Model

SLIDE = block_on_base(
    "large slide", rectangle_mesh(-1.0, -0.5, 2.0, 0.5, 24, 6),
    rectangle_mesh(-0.8, 0.0, 0.5, 0.25, 7, 4),
    pressed(-0.005, end=2.0), slid(Raw("{shift}"), end=2.0), names=("base", "block"),
    friction=Raw("{mu}"), kinematics="{kinematics}", load_factors=Raw("{factors}"))

#: pressed in two steps, then slid in ten (the shift over load factors 0.5 to 2)
FACTORS = [0.25, 0.5, 0.55, 0.65, 0.8, 0.95, 1.1, 1.25, 1.4, 1.55, 1.7, 2.0]


def slide(mu: float = 0.3, shift: float = 1.0, kinematics: str = "total", swap: bool = False,
          factors=FACTORS) -> Model:
    """A block pressed on a wider base, then slid ``shift`` along it (12 of the base's facets
    for 1.0), both bodies under total Lagrangian kinematics (or ``kinematics``)."""
    return built(SLIDE.format(mu=mu, shift=shift, kinematics=kinematics, factors=factors), swap)


def run(model: Model):
    result = Analysis(model).run()
    assert result.converged, result.message
    return result


def resultant(result, name: str) -> np.ndarray:
    return np.array([s.bodies[name].contact_force.sum(axis=0) for s in result.steps])


def test_a_frictional_large_kinematics_model_picks_the_frictional_large_formulation():
    assert formulation_class(ContactSettings(friction=0.3), True) is FrictionalLargeContact
    caps = FrictionalLargeContact.capabilities
    assert "coefficients" in caps.friction and "large" in caps.kinematics


@pytest.mark.slow
def test_a_block_slid_far_carries_mu_times_its_normal_force():
    """Slid over 12 facets of the base, every node in contact slips: the tangential force is
    mu times the normal one (measured: 0.29928 to 0.30005 over the sliding steps from the
    second, the surfaces flat but for the indentation at the block's corners), the two
    bodies' forces balance to round-off, every invariant holds, and the friction
    dissipates."""
    result = run(slide())
    block, base = resultant(result, "block"), resultant(result, "base")
    np.testing.assert_allclose(block, -base, rtol=0, atol=1e-12 * np.abs(block).max())
    ratios = -block[:, 0] / block[:, 1]
    assert block[-1, 1] > 0 and block[-1, 0] < 0  # pushed up, held back
    np.testing.assert_allclose(ratios[3:], 0.3, rtol=3e-3)
    assert all(s.invariants.get("force_balance", 0.0) < 1e-12 for s in result.steps)
    work = np.asarray(frictional_work(result.steps))
    assert np.all(work[3:] > 0)
    # the last step slides 0.2 at mu times the normal force (measured: 0.07 % off)
    np.testing.assert_allclose(work[-1], -block[-1, 0] * 0.2, rtol=5e-3)
    status = result.steps[-1].bodies["block"].friction_status
    base_status = result.steps[-1].bodies["base"].friction_status
    slipping = np.concatenate([status[status >= 0], base_status[base_status >= 0]])
    assert np.all(slipping[slipping > 0] == 2)  # every node in contact slips


@pytest.mark.slow
def test_the_slide_does_not_depend_on_the_body_order():
    base = resultant(run(slide()), "block")
    swapped = resultant(run(slide(swap=True)), "block")
    np.testing.assert_allclose(swapped, base, rtol=0, atol=1e-8 * np.abs(base).max())


@pytest.mark.slow
def test_a_small_push_sticks_as_under_small_kinematics():
    """Pressed and then pushed sideways by 6 % of the press (far less than the slide the
    friction allows), the block sticks (but at its corners) and its tangential force grows with
    the push. Large and
    small kinematics differ by the geometric nonlinearity, in proportion to the strain: pressed
    by 0.005 (2 % strain) the forces differ by 1.2 % and the push's tangential force by 2.5 %;
    pressed ten times less, ten times less (0.12 % and 0.55 % measured)."""
    differences = []
    for press in (0.005, 0.0005):
        forces = {}
        for kinematics in ("total", "small"):
            text = SLIDE.format(mu=0.3, shift=0.06 * press * 1.5 / 0.5, kinematics=kinematics,
                                factors=[0.25, 0.5, 0.75, 1.0])
            model = loads(text.replace("value = -0.005", f"value = {-press}")).build()
            result = run(model)
            forces[kinematics] = resultant(result, "block")
            if kinematics == "total":
                status = result.steps[-1].bodies["block"].friction_status
                # all stick but the corner nodes, where the pressure is singular
                assert (status == 1).sum() >= 6 and (status == 2).sum() <= 2
        large, small = forces["total"], forces["small"]
        assert abs(large[-1, 0]) < 0.3 * large[-1, 1]  # inside the cone
        push = (large[-1, 0] - large[1, 0]) / (small[-1, 0] - small[1, 0]) - 1
        differences.append((np.abs(large - small).max() / np.abs(small).max(), abs(push)))
    (force0, push0), (force1, push1) = differences
    assert force0 < 0.015 and push0 < 0.03
    assert force1 < 0.15 * force0 and push1 < 0.3 * push0


def test_what_large_kinematics_friction_does_not_solve_yet_is_refused_by_validation():
    """Refused by the model's validation (``vfem check`` as well as ``vfem run``), naming the
    pair or the body and what to do: the elasto-plastic law under large kinematics or with the
    lagrange baseline, a force-controlled platen with friction under large kinematics."""
    from vfem.bodies import Platen

    model = slide()
    model.contact = dataclasses.replace(model.contact, pairs=(PairFriction(
        ("base", "block"), 0.3, "elastoplastic", slip_stiffness=1e4),))
    with pytest.raises(InputError, match=r"contact.pairs \['base', 'block'\]: the elastoplastic "
                                         "friction law .* not yet with large kinematics"):
        model.validate()
    small = slide(kinematics="small")
    small.contact = dataclasses.replace(model.contact, method="lagrange")
    with pytest.raises(InputError, match="not yet with contact.method = 'lagrange'"):
        small.validate()
    model = slide()
    block = model.bodies[1]
    block.platen = Platen("top", "y", -1.0)
    with pytest.raises(InputError, match="body 'block': a force-controlled platen with friction"):
        model.validate()


@pytest.mark.slow
def test_the_sliding_example_with_friction_slips_at_mu_in_the_contact_frame():
    """``vfem run sliding --set friction=0.3``, coarser: the punch slid 10 block facets over the
    block with mu = 0.3. Every node in contact slips; the tangential tractions' force is mu
    times the normal tractions' (to 1e-9); the punch's reactions are in the ratio
    tan(atan mu - tilt), the tilt being how far the normal tractions' resultant leans against
    the slide over the punch's curved face (a pressure not symmetric about its lowest point:
    measured 0.0071 rad on the example's mesh and 0.0066 on one twice as fine, a ratio of
    0.2922 and 0.2927); with materials alike, 0.0042 (0.2953)."""
    from vfem_examples import sliding

    p = sliding.Parameters(block_columns=60, block_rows=8, punch_columns=24, punch_rows=6,
                           slide=1.0, press_steps=3, slide_steps=5, start=-0.5, friction=0.3)
    result = run(sliding.build(p))
    assert all(s.invariants["passed"] for s in result.steps)
    f = sliding.evaluate(result, p)["friction"]
    assert f["slipping_nodes"] > 3 and f["sticking_nodes"] == 0
    assert f["friction_over_normal_part"] == pytest.approx(0.3, rel=1e-9)
    assert 0.0 < f["normal_part_tilt"] < 0.02
    rows = sliding.reactions(result)
    last = abs(rows["tangential"][-1]) / abs(rows["normal"][-1])
    assert last == pytest.approx(math.tan(math.atan(0.3) - f["normal_part_tilt"]), rel=1e-9)
    assert abs(last / 0.3 - 1) < 0.04


@pytest.mark.slow
def test_a_resumed_large_frictional_run_equals_an_uninterrupted_one(tmp_path):
    """Stopped after the third sliding step and resumed from its checkpoint, the slide ends
    with every number of the uninterrupted run: the anchors (material points of the other
    surface) and the accumulated slip come back with the bodies' states."""
    factors = [0.25, 0.5, 0.6, 0.7, 0.8, 0.9]
    config = loads(SLIDE.format(mu=0.3, shift=0.5, kinematics="total", factors=factors))
    assert_resumed_equals_whole(config, tmp_path, stop_after=4)
    # and from checkpoints written before the tangential arrays were columns in 2D (the
    # anchors, material points, were (n,) and stay so)
    assert_resumed_equals_whole(config, tmp_path, stop_after=4, folder="older",
                                before_resume=as_written_before_columns)


@pytest.mark.slow
def test_the_sliding_reactions_tend_to_mu_as_the_indentation_shrinks():
    """The reactions' ratio differs from mu by the tilt of the normal tractions' resultant,
    which shrinks with the indentation (the pressure's asymmetry over the punch's curved face
    is a property of the model, not of the discretisation): on the example's meshes, slid 0.5
    with mu = 0.3, measured tilts 0.0071 / 0.0032 / 0.0009 rad and ratios 0.2922 / 0.2965 /
    0.2990 at depths 0.05 / 0.025 / 0.0125 (2026-11-27). At a quarter of the example's depth
    the ratio is within 1 % of mu, as the issue asks of steady sliding."""
    from vfem_examples import sliding

    tilts = {}
    for depth in (0.05, 0.0125):
        p = sliding.Parameters(slide=0.5, slide_steps=4, friction=0.3, depth=depth)
        result = run(sliding.build(p))
        assert all(s.invariants["passed"] for s in result.steps)
        f = sliding.evaluate(result, p)["friction"]
        assert f["sticking_nodes"] == 0
        tilts[depth] = f["normal_part_tilt"]
        rows = sliding.reactions(result)
        ratio = abs(rows["tangential"][-1]) / abs(rows["normal"][-1])
        assert ratio == pytest.approx(math.tan(math.atan(0.3) - tilts[depth]), rel=1e-6)
    assert 0 < tilts[0.0125] < tilts[0.05] / 4
    assert abs(ratio / 0.3 - 1) < 0.01


@pytest.mark.slow
def test_a_frictionless_pair_in_a_frictional_model_slides_freely():
    """Two blocks pressed on one base and pushed along it, under large kinematics: the left
    pair with Coulomb's mu = 0.3, the right one frictionless (``[[contact.pairs]]`` friction
    0). The frictionless pair's nodes are free, as under small kinematics (counted as sticking,
    their slip along the base was an error no traction could correct, and the step stopped
    short of convergence): every step converges, the right block's contact forces have no
    tangential part (its friction forces, the nodal forces of the tangential traction, are
    zero), and the left block's have one."""
    from vfem.bodies import Body, PrescribedDisplacement, Support
    from vfem.materials import LinearElastic
    from vfem.mesh.shapes import rectangle

    press, shove = ((0.0, 0.0), (0.5, 1.0), (2.0, 1.0)), ((0.0, 0.0), (0.5, 0.0), (2.0, 1.0))
    material = LinearElastic(1000.0, 0.3)
    base = Body("base", rectangle(-1.0, -0.5, 2.0, 0.5, 16, 4), material,
                supports=(Support("bottom"),), contact_boundaries=("top",), kinematics="total")

    def block(name, x0):
        moved = (PrescribedDisplacement("top", "y", -0.01, amplitude=press),
                 PrescribedDisplacement("top", "x", 0.1, amplitude=shove))
        return Body(name, rectangle(x0, 0.0, 0.4, 0.25, 5, 3), material, prescribed=moved,
                    contact_boundaries=("bottom",), kinematics="total")

    pairs = (PairFriction(("base", "left"), 0.3), PairFriction(("base", "right"), 0.0))
    model = Model("two blocks", [base, block("left", -0.8), block("right", 0.2)],
                  ContactSettings(friction=0.0, pairs=pairs), [0.25, 0.5, 0.8, 1.2],
                  contact_pairs=(("base", "left"), ("base", "right")))
    result = run(model)
    for step in result.steps:
        right = step.bodies["right"]
        assert np.abs(right.contact_force).max() > 0  # pressed
        assert not np.any(right.friction_force)
    assert np.abs(result.steps[-1].bodies["left"].friction_force).max() > 0
