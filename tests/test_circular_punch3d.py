"""A stiff flat circular punch on an elastic block (issue 21's ``circular_punch``, not yet an
example): what holds and what does not yet, measured 2026-11-27.

The model: a flat-ended cylinder of radius a = 1 (``solids.cylinder``, a/8 facets, 1000 times
the block's Young's modulus) pushed by a force-controlled platen with P = 10 on a block 8 a
wide and deep (``solids.box`` graded to the axis planes, facets 1.3 a/8 within 1.2 a), quarter
model. Boussinesq's rigid punch on a half-space: p(r) = P / (2 pi a sqrt(a^2 - r^2)).

Holds: converged in one iteration with every invariant, the contact force equal to the applied
one, the centre pressure 2.1 % above Boussinesq's. Does not hold yet (strict expected
failures): the acceptance's 3 % over r < 0.8 a (the block's nodal pressure is 2-4 % high
inside 0.7 a and 6-19 % high at 0.77-0.83 a at a/8 and a/12, with the interior offset not
falling: 2.1 % at a/8, 3.1 % at a/12 — a smooth excess with a more uniform shape than
Boussinesq's, moving with the bulk's grading, 2.8/2.1/6.6 % for blocks 4/8/16 a wide); and at
a/16 the first step fails invariant (b) after six cuts (a punch node at r = 0.90 a, 2.63e-7
inside the block against 2.16e-7 allowed).

With the block's grid aligned to the rim (the block a wide cylinder with a grid circle under the
punch's rim at the rim nodes' angles, ``solids.cylinder(circle_from=, rings=, graded_end=)``;
slow test below) the rim nodes take the singular traction and the error falls with the facets,
about as h: the centre -5.7 % and -3.8 %, the largest over r < 0.8 a 14.8 % and 9.5 % (RMS
9.1 % and 5.7 %), at a/8 and a/12 (68k and 171k dofs): 3 % would need some a/40.
"""

import math

import numpy as np
import pytest

from vfem.bodies import Platen, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.materials import LinearElastic
from vfem.solver import Analysis

A, P, E = 1.0, 10.0, 1000.0


ROLLERS = (Support("left", ("x",)), Support("front", ("y",)))


def punch_on(block_mesh: MeshSpec, fixed: str, h: float):
    """The quarter punch (facets h across) on a block of ``block_mesh`` fixed on ``fixed``."""
    punch = BodyConfig(
        name="punch",
        mesh=MeshSpec(shape="cylinder", parameters=as_parameters(radius=A, height=A, h=h)),
        material=LinearElastic(1000 * E, 0.3), supports=(Support("top", ("x", "y")), *ROLLERS),
        platen=Platen("top", "z", -P / 4), contact_boundaries=("contact",))
    block = BodyConfig(name="block", mesh=block_mesh, material=LinearElastic(E, 0.3),
                       supports=(Support(fixed), *ROLLERS), contact_boundaries=("top",))
    return ModelConfig("circular_punch", (punch, block), ContactSettings(), Steps(count=1)
                       ).build()


def model(n: int):
    """The block a graded box 8 a wide and deep."""
    h = A / n
    return punch_on(MeshSpec(shape="box", parameters=as_parameters(
        z0=-8 * A, width=8 * A, depth=8 * A, height=8 * A, h=2 * A, h_fine=1.3 * h,
        growth=0.3, fine_x=(0.0,), fine_y=(0.0,), fine_z=(0.0,), plateau=1.2 * A)), "bottom", h)


def block_pressure(m, result):
    block = next(b for b in m.bodies if b.name == "block")
    nodes = np.unique(block.mesh.facets[:, block.mesh.boundaries["top"]])
    r = np.hypot(*block.mesh.p[:2, nodes])
    return r, result.steps[-1].bodies["block"].contact_pressure[nodes]


def boussinesq(r):
    return P / (2 * math.pi * A * np.sqrt(A * A - r * r))


@pytest.fixture(scope="module")
def eighth():
    m = model(8)
    return m, Analysis(m).run()


def test_punch_converges_with_every_invariant_and_exact_force(eighth):
    m, result = eighth
    assert result.converged, result.message
    assert [s.iterations for s in result.steps] == [1]
    assert all(s.invariants["passed"] for s in result.steps)
    for name, sign in (("punch", 1.0), ("block", -1.0)):
        total = 4 * sign * result.steps[-1].bodies[name].contact_force[:, 2].sum()
        assert total == pytest.approx(P, rel=1e-12)
    r, p = block_pressure(m, result)
    centre = p[np.argmin(r)] / boussinesq(0.0) - 1
    assert 0.0 < centre < 0.03  # measured 2.06 %


@pytest.mark.xfail(strict=True, reason="open: 8.8 % at 0.8 a (a/8); see the module docstring")
def test_pressure_within_3_percent_of_boussinesq_inside_0_8_a(eighth):
    m, result = eighth
    r, p = block_pressure(m, result)
    inner = r < 0.8 * A
    assert np.abs(p[inner] / boussinesq(r[inner]) - 1).max() < 0.03


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="open: a/16 fails invariant (b) at step 1 after six cuts")
def test_finer_punch_converges():
    result = Analysis(model(16)).run()
    assert result.converged, result.message


def aligned_model(n: int):
    """The block a cylinder 8 a wide and deep with a grid circle under the punch's rim."""
    h = A / n
    return punch_on(MeshSpec(shape="cylinder", parameters=as_parameters(
        radius=8 * A, height=8 * A, z0=-8 * A, h_contact=h, h=2 * A, growth=0.3,
        plateau=1.2 * A, circle_from=1 / 8, blend_from=0.5 / 8, graded_end="top",
        rings=(A,))), "contact", h)


@pytest.mark.slow
def test_aligned_rim_converges_towards_boussinesq():
    errors = []
    for n in (8, 12):
        m = aligned_model(n)
        result = Analysis(m).run()
        assert result.converged and all(s.invariants["passed"] for s in result.steps)
        total = -4 * result.steps[-1].bodies["block"].contact_force[:, 2].sum()
        assert total == pytest.approx(P, rel=1e-12)
        r, p = block_pressure(m, result)
        inner = r < 0.8 * A
        rel = p[inner] / boussinesq(r[inner]) - 1
        errors.append((abs(rel[np.argmin(r[inner])]), np.abs(rel).max()))
    assert errors[1][0] < errors[0][0] < 0.06 and errors[1][1] < errors[0][1] < 0.15
