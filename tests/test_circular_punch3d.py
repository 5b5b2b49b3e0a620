"""A stiff flat circular punch on an elastic block (issue 21's ``circular_punch``): the built-in
example, and the meshes that do not reach Boussinesq.

Boussinesq's rigid punch on a half-space: p(r) = P / (2 pi a sqrt(a^2 - r^2)). The example
(``vfem run circular_punch``): both meshes graded towards the rim (facets 0.02 a there, growing
0.2 per unit distance), the block's grid with a circle under the rim at the punch's rim nodes'
angles and circles from 0.6 a out. Measured 2026-11-28: one iteration, every invariant, the
force exact, no block node beyond the rim loaded; the block's nodal pressure within 2.25 % of
Boussinesq's over r < 0.8 a (at r = 0.768 a; RMS 1.66 %, centre +0.04 %) at 91k dofs; 4.19 %,
3.25 %, 2.25 % and 1.86 % at rim facets 0.04, 0.03, 0.02 and 0.015 a (50k, 70k, 91k, 118k
dofs); growing 0.15 instead, 2.08 % at 173k dofs; growing 0.3, 2.53 % at 43k.

Meshes that do not get there (kept, as what a user meeting the singular rim should know):

* the block a box graded to the axis planes (facets 1.3 a/8 within 1.2 a; the rim crosses its
  grid anywhere): converged in one iteration with every invariant and the force exact, the
  centre pressure 2.1 % above Boussinesq's, but 2-4 % high inside 0.7 a and 6-19 % high at
  0.77-0.83 a at a/8 and a/12, the interior offset not falling with the facets. At a/16 the
  first step failed invariant (b) after six cuts (a punch node at r = 0.90 a, 2.63e-7 inside
  the block against 2.16e-7 allowed) until the edges of both surfaces were held where they
  land (issue 37, 2026-11-30): now one step, one iteration, every invariant, the force exact
  (to 3e-15), its pressure 7.5 % low at the centre and up to 15.8 % off inside 0.8 a (the held
  rim's share, as at a/8). The pressures are strict expected failures.
* evenly fine facets with the grid aligned to the rim (before the example's grading): the
  error falls only as h (9.5 % at a/12, 171k dofs).
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from vfem.bodies import Platen, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.materials import LinearElastic
from vfem.solver import Analysis
from vfem_examples import circular_punch

A, P, E = 1.0, 10.0, 1000.0
ROOT = Path(__file__).resolve().parents[1]


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


@pytest.mark.slow
def test_punch_converges_with_every_invariant_and_exact_force(eighth):
    m, result = eighth
    assert result.converged, result.message
    assert [s.iterations for s in result.steps] == [1]
    assert all(s.invariants["passed"] for s in result.steps)
    for name, sign in (("punch", 1.0), ("block", -1.0)):
        total = 4 * sign * result.steps[-1].bodies[name].contact_force[:, 2].sum()
        assert total == pytest.approx(P, rel=1e-12)


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=(
    "open (issue 37): the punch's rim nodes, held where they would penetrate the block, take "
    "58 % of the quarter load as point forces beside the block's nodes in contact next to them, "
    "and the block reads its centre pressure 14.8 % low (2.06 % high before)"))
@pytest.mark.slow
def test_the_centre_pressure_is_boussinesqs(eighth):
    m, result = eighth
    r, p = block_pressure(m, result)
    centre = p[np.argmin(r)] / boussinesq(0.0) - 1
    assert 0.0 < centre < 0.03  # measured 2.06 % before the rim was held


@pytest.mark.xfail(strict=True, reason="open: 8.8 % at 0.8 a (a/8); see the module docstring")
@pytest.mark.slow
def test_pressure_within_3_percent_of_boussinesq_inside_0_8_a(eighth):
    m, result = eighth
    r, p = block_pressure(m, result)
    inner = r < 0.8 * A
    assert np.abs(p[inner] / boussinesq(r[inner]) - 1).max() < 0.03


@pytest.mark.slow
def test_finer_punch_converges():
    """A strict expected failure until the edges of both surfaces were held (module docstring)."""
    result = Analysis(model(16)).run()
    assert result.converged, result.message
    assert all(s.invariants["passed"] for s in result.steps)
    for name, sign in (("punch", 1.0), ("block", -1.0)):
        total = 4 * sign * result.steps[-1].bodies[name].contact_force[:, 2].sum()
        assert total == pytest.approx(P, rel=1e-12)


# -- the built-in example ------------------------------------------------------------------


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    p = circular_punch.Parameters()
    out = tmp_path_factory.mktemp("circular_punch")
    return p, circular_punch.run(p, out), out


@pytest.mark.slow
def test_example_within_3_percent_of_boussinesq_inside_0_8_a(example):
    p, s, out = example
    assert s["converged"], s["message"]
    assert [x["iterations"] for x in s["steps"]] == [1]
    assert all(x["invariants"]["passed"] for x in s["steps"])
    b = s["boussinesq"]
    for name in ("block", "punch"):
        assert b[name]["largest_error"] < 0.03  # measured 2.25 %
        assert b[name]["rms_error"] < 0.02  # 1.66 %
        assert abs(b[name]["centre_error"]) < 0.01  # +0.04 %
        assert b[name]["total_contact_force"] == pytest.approx(p.force, rel=1e-12)
    assert b["block"]["nodes_beyond_rim_loaded"] == 0
    assert b["block"]["nodes_inside"] == 49  # the nodes the 3 % is read at
    assert json.loads((out / "summary.json").read_text())["boussinesq"] == b
    for name in ("pressure.png", "pressure_map.png"):
        assert (out / name).stat().st_size > 10_000
    assert "of Boussinesq's" in "\n".join(circular_punch.report(s))


def test_example_is_its_input_file():
    from vfem import load

    assert circular_punch.config() == load(ROOT / "examples" / "circular_punch.toml")


@pytest.mark.slow
def test_body_order_does_not_matter():
    results = []
    for swap in (False, True):
        p = circular_punch.Parameters(rim_size=0.04, swap_bodies=swap)
        m = circular_punch.build(p)
        r = Analysis(m).run()
        assert r.converged and all(s.invariants["passed"] for s in r.steps)
        results.append(r.steps[-1].bodies["block"].contact_pressure)
    assert np.abs(results[0] - results[1]).max() < 1e-8 * P / (math.pi * A * A)


@pytest.mark.slow
def test_example_error_falls_with_the_rim_facets():
    """Measured: 4.19 %, 3.25 %, 2.25 % at rim facets 0.04, 0.03, 0.02 a; and with growth 0.3
    (the punch capped at a smaller size than the block before both took one, the grids then
    apart on r < a) invariant (b) failed at a block ring node: it converges now."""
    errors = []
    for size in (0.04, 0.03, 0.02):
        p = circular_punch.Parameters(rim_size=size)
        r = Analysis(circular_punch.build(p)).run()
        assert r.converged and all(s.invariants["passed"] for s in r.steps)
        errors.append(circular_punch.evaluate(r, p)["block"]["largest_error"])
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.03


def test_bad_parameters_are_refused():
    with pytest.raises(InputError, match="rim_size must lie between"):
        circular_punch.validate(circular_punch.Parameters(rim_size=1e-6))
    with pytest.raises(InputError, match="block_size must lie between"):
        circular_punch.validate(circular_punch.Parameters(block_size=1.0))
