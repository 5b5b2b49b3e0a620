"""A material law with history drops into the bodies through the ``Material`` protocol
(``vfem.materials.protocol``; issue 38, the seam issue 41's plastic laws need): its state is
carried at the quadrature points, committed only when a step converges, left untouched by a
discarded trial, saved and restored bit for bit, and a contact analysis runs it unchanged.

The laws here are test laws, not physical ones, chosen for closed forms:

* :class:`Damage`: Saint Venant-Kirchhoff scaled by ``1 - d``, ``d = min(D_MAX, RATE * kappa)``
  with ``kappa`` the largest norm of the Green-Lagrange strain reached so far (at converged
  states, and the iterate's own). Every dof of the block it is tried on is prescribed (a
  homogeneous stretch), so Newton needs no tangent and the numbers are exact: under prescribed
  displacements alone a uniformly scaled stress leaves the displacement as it is and scales the
  reactions by ``1 - d``; back at a smaller stretch the reactions remember the largest one.
* :class:`Recording`: Saint Venant-Kirchhoff whose state records ``kappa`` and nothing else, for
  a contact analysis: the answers are Saint Venant-Kirchhoff's (to the Newton tolerance), and
  the state after each step is the largest strain norm of the steps' converged fields.
"""

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from vfem.bodies import Body, PrescribedDisplacement, Support
from vfem.bodies.stresses import cauchy_stress, stress
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.materials import LAWS, LinearElastic, Material, Response, SaintVenantKirchhoff
from vfem.mesh.shapes import rectangle
from vfem.nonlinear import NonlinearBody
from vfem.solver import Analysis, Model

RATE, D_MAX = 20.0, 0.6
E_MOD, NU = 1000.0, 0.3


def strain_norm(E):
    return np.sqrt(np.einsum("ij...,ij...->...", E, E))


@dataclass(frozen=True)
class Recording(SaintVenantKirchhoff):
    """Saint Venant-Kirchhoff with a state that records the largest strain norm reached."""

    def initial_state(self, dim, points):
        return {"kappa": np.zeros(points)}

    def response(self, E, state):
        r = super().response(E, state)
        r.state = {"kappa": np.maximum(state["kappa"], strain_norm(E))}
        return r


@dataclass(frozen=True)
class Damage(Recording):
    """Saint Venant-Kirchhoff times ``1 - d(kappa)`` (see the module docstring); its tangent is
    the secant one (the tests prescribe every dof: Newton solves nothing)."""

    def damage(self, kappa):
        return np.minimum(D_MAX, RATE * kappa)

    def response(self, E, state):
        kappa = np.maximum(state["kappa"], strain_norm(E))
        scale = 1.0 - self.damage(kappa)
        S33 = self.out_of_plane_stress(E)
        return Response(scale * self.second_piola(E), lambda: scale * self.tangent(E),
                        None if S33 is None else scale * S33, {"kappa": kappa})


def stretched(law, formulation: str) -> NonlinearBody:
    """A unit square of 3 x 3 quadrilaterals, every node's displacement prescribed as a uniform
    stretch ``(0.01 x, -0.004 y)`` times the load factor: a homogeneous strain."""
    mesh = rectangle(nx=3, ny=3)
    body = NonlinearBody(mesh, law, formulation=formulation, name="block")
    x, y = body.mesh.doflocs
    nodes = np.arange(body.mesh.nvertices)
    body.prescribe(body.node_dofs(nodes, "x"), 0.01 * x)
    body.prescribe(body.node_dofs(nodes, "y"), -0.004 * y)
    return body


def test_both_hyperelastic_laws_keep_the_protocol_without_state():
    for law in LAWS.values():
        material = law(E_MOD, NU)
        assert isinstance(material, Material)
        assert material.initial_state(2, (4, 3)) == {}
        E = np.zeros((2, 2, 4, 3))
        E[0, 0] = 0.01
        r = material.response(E, {})
        assert np.array_equal(r.stress, material.second_piola(E))
        assert np.array_equal(r.moduli(), material.tangent(E))
        assert r.state == {}
    assert not isinstance(LinearElastic(E_MOD, NU), Material)  # no response: small strain only


@pytest.mark.parametrize("formulation", ["total", "updated"])
def test_the_state_is_committed_by_a_converged_step_only(formulation):
    law = Damage(E_MOD, NU)
    body = stretched(law, formulation)
    ref = stretched(SaintVenantKirchhoff(E_MOD, NU), formulation)
    eps = np.finfo(float).eps
    for lf in (1.0, 2.0):
        body.solve([lf])
        ref.solve([lf])
        # the displacement is prescribed everywhere: the same field for both laws
        assert np.array_equal(body.displacement, ref.displacement)
        norm = strain_norm(body.green_lagrange_strain())
        # committed: the strain norm of the converged field (it only grows here)
        assert np.allclose(body.material_state["kappa"], norm, rtol=1e-12, atol=0.0)
        # the reactions scaled by the damage at that strain (uniform)
        d = float(law.damage(norm).mean())
        r, r0 = body.reactions(), ref.reactions()
        assert np.abs(r - (1.0 - d) * r0).max() <= 1e3 * eps * np.abs(r0).max()

    saved = body.saved_state()
    assert np.array_equal(saved["material_kappa"], body.material_state["kappa"])
    before = body.material_state["kappa"].copy()
    body.equilibrate(3.0)  # a trial beyond the step, then dropped (a cut step)
    body.discard()
    assert np.array_equal(body.material_state["kappa"], before)
    body.equilibrate(3.0)
    body.accept()
    assert (body.material_state["kappa"] > before).all()
    # restored from the saved arrays, the next step is the same bit for bit
    first = body.displacement.copy(), body.reactions().copy(), body.material_state["kappa"]
    body.restore_state(saved)
    assert np.array_equal(body.material_state["kappa"], before)
    body.equilibrate(3.0)
    body.accept()
    assert np.array_equal(body.displacement, first[0])
    assert np.array_equal(body.reactions(), first[1])
    assert np.array_equal(body.material_state["kappa"], first[2])


def test_unloading_remembers_the_largest_strain():
    """Path dependence, which no hyperelastic law has: back at load factor 1 after 2, the
    reactions are those of the Saint Venant-Kirchhoff block at 1 scaled by ``1 - d`` of the
    strain at 2, not of the strain at 1 as on the way up."""
    law = Damage(E_MOD, NU)
    body = stretched(law, "total")
    ref = stretched(SaintVenantKirchhoff(E_MOD, NU), "total")
    ref.solve([1.0])
    body.solve([1.0])
    d1 = float(law.damage(strain_norm(body.green_lagrange_strain())).mean())
    body.solve([2.0])
    d2 = float(law.damage(strain_norm(body.green_lagrange_strain())).mean())
    body.solve([1.0])
    assert d2 > d1 + 0.1
    eps = np.finfo(float).eps
    r0 = ref.reactions()
    assert np.abs(body.reactions() - (1.0 - d2) * r0).max() <= 1e3 * eps * np.abs(r0).max()


def pressed_block(material, law: str, load_factors: list[float]):
    """A block of ``material`` under large kinematics (hyperelastic ``law``), held at its
    bottom and pressed by a stiffer punch 0.02 down per unit load factor: the converged run
    and the block."""
    block = Body("block", rectangle(-1.0, -1.0, 2.0, 1.0, nx=10, ny=5), material,
                 supports=(Support("bottom"),), contact_boundaries=("top",),
                 kinematics="total", law=law)
    punch = Body("punch", rectangle(-0.35, 0.0, 0.7, 0.3, nx=5, ny=2),
                 LinearElastic(20 * E_MOD, NU),
                 prescribed=(PrescribedDisplacement("top", "y", -0.02),),
                 supports=(Support("top", ("x",)),), contact_boundaries=("bottom",))
    model = Model("pressed", [block, punch], load_factors=load_factors)
    model.contact = ContactSettings()
    result = Analysis(model).run()
    assert result.converged, result.message
    return result, block


@pytest.mark.slow
def test_a_contact_analysis_carries_the_law_unchanged(monkeypatch):
    """A block of a law with state under large kinematics, pressed by a stiffer punch in
    three steps (down, further, back up): contact sees only the body's mechanics, so the
    answers are Saint Venant-Kirchhoff's (to the Newton tolerance), and after the run the
    body's saved state holds the largest strain norm of the steps' converged fields, computed
    here from the steps' displacements."""
    monkeypatch.setitem(LAWS, "recording", Recording)
    recorded, block = pressed_block(LinearElastic(E_MOD, NU), "recording", [1.0, 2.0, 1.0])
    plain, _ = pressed_block(LinearElastic(E_MOD, NU), "saint-venant-kirchhoff",
                             [1.0, 2.0, 1.0])
    # the same arithmetic in both runs; a threaded factorization may round differently from
    # run to run, and each converged state is exact only to the bodies' Newton tolerance (1e-8
    # of the reference force, large.BODY_TOLERANCE): the answers agree within it
    assert len(recorded.steps) == len(plain.steps)
    for a, b in zip(recorded.steps, plain.steps):
        for name, field in (("block", "displacement"), ("punch", "contact_force")):
            x, y = (np.asarray(getattr(r.bodies[name], field)) for r in (a, b))
            assert np.abs(x - y).max() <= 1e-8 * np.abs(y).max()
    nl = block.nonlinear
    kappa = np.zeros_like(nl.material_state["kappa"])
    for step in recorded.steps:
        grad = nl.basis0.interpolate(np.ravel(step.bodies["block"].displacement)).grad
        E = 0.5 * (grad + np.einsum("ij...->ji...", grad)
                   + np.einsum("ki...,kj...->ij...", grad, grad))
        kappa = np.maximum(kappa, strain_norm(E))
    assert kappa.max() > 0.01
    assert np.allclose(block.saved_state()["material_kappa"], kappa, rtol=1e-9,
                       atol=1e-12 * kappa.max())


@dataclass(frozen=True)
class Shown(Recording):
    """:class:`Recording` whose results show its state."""

    def fields(self, state):
        return {"kappa": state["kappa"]}


@dataclass(frozen=True)
class RecordingTable(LinearElastic):
    """A material table (``[bodies.material]``, :data:`vfem.materials.MATERIALS`) whose bodies
    carry :class:`Shown`'s state, as a plastic material's will: they iterate whatever their
    kinematics, and evaluate its law, not the body's hyperelastic ``law``."""

    carries_state: ClassVar[bool] = True

    def law(self, name, kinematics):
        return Shown(self.youngs_modulus, self.poissons_ratio)


def test_the_fields_a_law_shows_of_its_state_are_element_averages_beside_the_stresses():
    """Under the homogeneous stretch the state is uniform: its element averages are its value,
    to round-off."""
    body = stretched(Shown(E_MOD, NU), "total")
    body.solve([1.0])
    *_, fields = body.cauchy_stress_at(body.displacement)
    kappa = strain_norm(body.green_lagrange_strain())
    assert np.allclose(fields["kappa"], kappa.mean(), rtol=1e-12, atol=0.0)
    assert np.ptp(kappa) <= 1e-12 * kappa.mean()
    *_, none = stretched(SaintVenantKirchhoff(E_MOD, NU), "total").cauchy_stress_at(
        np.zeros(2 * 16))
    assert none == {}


def test_a_material_table_that_carries_state_makes_its_body_iterate_with_its_own_law():
    """What a body reads of its material: ``carries_state`` (Newton's method, whatever the
    kinematics) and ``law`` (what it evaluates); a contact analysis then shows the state beside
    the stresses, each element's value between its quadrature points' committed ones."""
    mesh = rectangle(-1.0, -1.0, 2.0, 1.0, nx=10, ny=5)
    small = Body("block", mesh, RecordingTable(E_MOD, NU), supports=(Support("bottom"),))
    assert small.iterates and not small.large
    assert not Body("block", mesh, LinearElastic(E_MOD, NU)).iterates
    result, block = pressed_block(RecordingTable(E_MOD, NU), "saint-venant-kirchhoff", [1.0])
    assert isinstance(block.nonlinear.material, Shown)
    shown = stress(block, np.ravel(result.steps[-1].bodies["block"].displacement))["kappa"]
    kappa = block.saved_state()["material_kappa"]
    assert shown.max() > 0.005
    assert (shown >= kappa.min(axis=1) * (1 - 1e-12)).all()
    assert (shown <= kappa.max(axis=1) * (1 + 1e-12)).all()


def test_a_body_of_a_material_with_state_is_refused_where_newtons_method_cannot_take_it():
    """Linear elements only (the Newton mechanics' element), not by the classical contact
    methods (one linear solve): each with a message that says so. Under small kinematics the
    body takes the small-strain mode (issue 41)."""
    from vfem.contact.formulations import check_capabilities

    mesh = rectangle(-1.0, -1.0, 2.0, 1.0, nx=4, ny=2)
    quadratic = Body("block", mesh, RecordingTable(E_MOD, NU), supports=(Support("bottom"),),
                     order=2)
    quadratic.validate()  # alone, any element (a plastic thick cylinder)
    small = Body("block", mesh, RecordingTable(E_MOD, NU), supports=(Support("bottom"),))
    small.setup()
    assert small.nonlinear.formulation == "small"
    punch = Body("punch", rectangle(-0.35, 0.0, 0.7, 0.3, nx=2, ny=1), LinearElastic(E_MOD, NU),
                 supports=(Support("top"),))
    # in contact, linear elements: the Newton contact formulation pairs linear facets
    with pytest.raises(InputError, match=r"body 'block': contact with a body of a material "
                                         r"that carries state \(Newton's method\) needs linear "
                                         r"elements \(order 1\)"):
        check_capabilities(Model("quadratic", [quadratic, punch]))
    model = Model("recorded", [small, punch])
    model.contact = ContactSettings(method="penalty")
    with pytest.raises(InputError, match="small kinematics with a material that carries no "
                                         "state; use contact.method = 'vfem'"):
        check_capabilities(model)
    model.contact = ContactSettings(variant="thesis")
    with pytest.raises(InputError, match="a material that carries state \\(Newton's method\\) "
                                         "needs the paired contact variant"):
        check_capabilities(model)


def test_a_law_whose_fields_would_replace_a_stress_is_refused():
    @dataclass(frozen=True)
    class Clashing(Recording):
        def fields(self, state):
            return {"sxx": state["kappa"]}

    body = stretched(Clashing(E_MOD, NU), "total")
    body.solve([1.0])
    with pytest.raises(ValueError, match=r"fields \['sxx'\] have the names of stresses"):
        cauchy_stress(body, body.displacement)
