"""Newton bodies of revolution (issue 42, item 1): hyperelastic and plastic bodies in r-z, under
small and large kinematics (:class:`vfem.nonlinear.NonlinearBody` with ``axisymmetric=True``: 3x3
tensors with the hoop stretch 1 + u_r / r, the measure 2 pi r). Checked against the linear
axisymmetric stiffness at rest, the central differences of the internal force, closed forms of
homogeneous states (uniaxial stress: the neo-Hookean law's own, and J2 plasticity's at small and
finite strain), Hill's thick-walled tube, and a neo-Hookean stack in contact at finite strain."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from skfem import MeshQuad1, MeshTri1, asm

import vfem
from test_axisymmetric import STACK
from test_finite_plasticity import FINITE, LARGE_PATH
from test_plasticity import PATH, STEEL, Y, uniaxial_stress
from vfem.bodies import Support, Traction
from vfem.bodies.section import _axisymmetric_elasticity
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.io.input import loads
from vfem.materials import J2Plastic
from vfem.materials.hyperelastic import NeoHookean, SaintVenantKirchhoff
from vfem.nonlinear import NonlinearBody, _ElementArrays

E, NU = 1000.0, 0.3
RUBBER = NeoHookean(E, NU)


def cylinder(mesh_cls=MeshQuad1, radius=1.0, height=1.0, n=(4, 6)):
    """A solid cylinder's r-z section, graded towards the axis, its sides named."""
    mesh = mesh_cls.init_tensor(radius * np.linspace(0.0, 1.0, n[0] + 1) ** 1.3,
                                np.linspace(0.0, height, n[1] + 1))
    return mesh.with_boundaries({"axis": lambda x: x[0] == 0.0, "bottom": lambda x: x[1] == 0.0,
                                 "top": lambda x: x[1] == height,
                                 "side": lambda x: x[0] == radius})


@pytest.mark.parametrize("mesh_cls", [MeshQuad1, MeshTri1])
@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("formulation", ["total", "updated", "small"])
def test_the_tangent_at_rest_is_the_linear_axisymmetric_stiffness(mesh_cls, order, formulation):
    """At rest every law's tangent is isotropic linear elasticity with its small-strain
    constants: the Newton body of revolution's tangent is the linear section's stiffness
    (:class:`vfem.bodies.section.Axisymmetric`, a scikit-fem form) to round-off."""
    body = NonlinearBody(cylinder(mesh_cls), RUBBER, order=order, formulation=formulation,
                         axisymmetric=True)
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    K = body.tangent_stiffness()
    K_linear = asm(_axisymmetric_elasticity(lam, mu), body.basis0).tocsr()
    assert abs(K - K_linear).max() <= 1e-13 * abs(K_linear).max()


@pytest.mark.parametrize("formulation", ["total", "updated"])
@pytest.mark.parametrize("material", [RUBBER, SaintVenantKirchhoff(E, NU)],
                         ids=["neo-Hookean", "SVK"])
def test_the_tangent_is_the_derivative_of_the_internal_force_about_an_axis(formulation,
                                                                           material):
    """Away from rest (a bulged cylinder, 10 % strains), the tangent is the central difference
    of the internal force (the hoop slot's v_r / r and the 2 pi r weight included) to 1e-6,
    and symmetric."""
    body = NonlinearBody(cylinder(MeshTri1), material, formulation=formulation,
                         axisymmetric=True)
    body.prescribe(body.boundary_dofs("bottom"), 0.0)
    body.prescribe(body.boundary_dofs("top", "y"), -0.1)
    body.prescribe(body.boundary_dofs("axis", "x"), 0.0)
    body.solve([0.5, 1.0])
    rng = np.random.default_rng(42)
    direction = 1e-2 * rng.standard_normal(body.ndofs)
    direction[body.boundary_dofs("axis", "x")] = 0.0
    K = body.tangent_stiffness()
    h = 1e-6
    fd = (body._internal(body._state(h * direction))
          - body._internal(body._state(-h * direction))) / (2 * h)
    assert np.linalg.norm(fd - K @ direction) <= 1e-6 * np.linalg.norm(K @ direction)
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()


def _uniaxial_neo_hookean(axial: float) -> tuple[float, float]:
    """The lateral stretch and the nominal axial stress P_zz of the neo-Hookean law in uniaxial
    stress at the axial stretch ``axial``, from the law's own stress (S_rr = S_tt = 0)."""
    def S(lateral):
        E_gl = np.zeros((3, 3, 1, 1))
        E_gl[0, 0] = E_gl[2, 2] = 0.5 * (lateral ** 2 - 1.0)
        E_gl[1, 1] = 0.5 * (axial ** 2 - 1.0)
        return RUBBER.response(E_gl, {}).stress[:, :, 0, 0]

    lateral = brentq(lambda s: S(s)[0, 0], 0.3, 3.0, xtol=1e-16, rtol=1e-15)
    return lateral, axial * S(lateral)[1, 1]


@pytest.mark.parametrize("formulation", ["total", "updated"])
@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("axial", [1.4, 0.7])
def test_a_neo_hookean_cylinder_in_uniaxial_stress_is_the_closed_form(formulation, order,
                                                                     axial):
    """A rubber cylinder (radius 1, height 2) stretched to 140 % or squeezed to 70 % along its
    axis, its ends free to slide: the state is homogeneous, u_r = (lateral - 1) r with the
    lateral stretch from the law's own S_rr = 0, to 1e-12 of the radius; the end's force per
    full circle is P_zz pi R^2 to 1e-10; the hoop Cauchy stress vanishes (to 1e-9 of the
    axial one)."""
    body = NonlinearBody(cylinder(height=2.0), RUBBER, order=order, formulation=formulation,
                         axisymmetric=True)
    body.prescribe(body.boundary_dofs("axis", "x"), 0.0)
    body.prescribe(body.boundary_dofs("bottom", "y"), 0.0)
    top = body.boundary_dofs("top", "y")
    body.prescribe(top, (axial - 1.0) * 2.0)
    records = body.solve(4, tol=1e-13)  # the residual to round-off of the forces
    assert all(r.converged for r in records)
    lateral, P_zz = _uniaxial_neo_hookean(axial)
    x = body.mesh.doflocs
    assert np.abs(body.displacement[0::2] - (lateral - 1.0) * x[0]).max() <= 1e-12
    assert np.abs(body.displacement[1::2] - (axial - 1.0) * x[1]).max() <= 1e-12
    assert body.reactions()[top].sum() == pytest.approx(P_zz * math.pi, rel=1e-10)
    s = body.stress()
    assert s.shape[1:] == (3, 3)
    assert np.abs(s[:, 2, 2]).max() <= 1e-9 * abs(s[:, 1, 1]).max()
    assert np.abs(s[:, 0, 0]).max() <= 1e-9 * abs(s[:, 1, 1]).max()


@pytest.mark.parametrize(("kinematics", "path"), [("small", PATH), ("total", LARGE_PATH),
                                                 ("updated", LARGE_PATH)])
def test_a_plastic_cylinder_in_uniaxial_stress_follows_the_closed_form(kinematics, path):
    """A J2 cylinder (radius 1, height 1) compressed, pulled back, stretched and compressed
    along its axis, its ends free to slide: the force per full circle is pi R^2 times the
    uniaxial closed form (the small-strain one; at finite strain the same in the log of the
    stretch, the Kirchhoff stress over the stretch: ``tests/test_finite_plasticity.py``'s
    block) to 1e-10 Y pi at every step — the 3D law on the body of revolution's 3x3 strain."""
    law = STEEL if kinematics == "small" else FINITE
    body = NonlinearBody(cylinder(n=(3, 2)), law, formulation=kinematics, axisymmetric=True)
    body.prescribe(body.boundary_dofs("axis", "x"), 0.0)
    body.prescribe(body.boundary_dofs("bottom", "y"), 0.0)
    top = body.boundary_dofs("top", "y")
    at = np.r_[0.0, path]
    body.prescribe(top, lambda lf: np.full(len(top), np.interp(lf, np.arange(len(at)), at)))
    if kinematics == "small":
        expected = uniaxial_stress(path)
    else:
        expected = [t / (1 + u) for t, u in
                    zip(uniaxial_stress([math.log1p(u) for u in path]), path)]
    for k, sigma in enumerate(expected, start=1):
        body.equilibrate(float(k), tol=1e-13)
        body.accept()
        assert abs(body.reactions()[top].sum() - math.pi * sigma) <= 1e-10 * Y * math.pi
    assert body.material_state["equivalent_plastic_strain"].min() > 0.0


def test_hills_thick_walled_tube_in_r_z():
    """Hill's tube (a = 1, b = 2, nu = 0.49, the thick-cylinder example's steps) as a strip of
    revolution held at both ends along the axis (every section in plane strain): no point
    yields at 0.9 of Lamé's first-yield pressure, some at 1.1; the plastic radius c read at
    the Gauss points (:func:`vfem_examples.thick_cylinder.plastic_radius`) gives Hill's
    pressure within 1 % at every plastic step (the plane-strain example's acceptance); 0.995
    of the limit pressure is carried."""
    from vfem_examples.thick_cylinder import (
        ThickCylinderParameters,
        hill,
        plastic_radius,
        pressures,
        theory,
    )

    p = ThickCylinderParameters()
    h = 1.0 / 24
    body = BodyConfig(
        name="tube",
        mesh=MeshSpec(shape="block", parameters=as_parameters(
            x0=p.inner_radius, y0=0.0, width=p.outer_radius - p.inner_radius, height=2 * h,
            h=h)),
        material=J2Plastic(p.youngs_modulus, p.poissons_ratio, p.yield_stress,
                           plane="axisymmetric"),
        supports=(Support("bottom", ("y",)), Support("top", ("y",))),
        tractions=(Traction("left", pressure=1.0),), order=2)
    result = vfem.solve(ModelConfig("tube", (body,), steps=Steps(load_factors=pressures(p))))
    assert result.converged, result.message
    nl = result.model.bodies[0].mechanics.nonlinear
    radius = nl.basis0.mapping.F(nl.basis0.X)[0]
    arrays = _ElementArrays.of(nl.basis0, axisymmetric=True)
    state = nl.material.initial_state(3, radius.shape)
    radii = []
    for step in result.steps:
        g = arrays.gradient(np.ravel(step.bodies["tube"].displacement))
        state = nl.material.response(0.5 * (g + np.swapaxes(g, 0, 1)), state).state
        radii.append(plastic_radius(radius, state["equivalent_plastic_strain"] > 0))
    assert radii[0] is None and radii[1] is not None
    for step, c in zip(result.steps[1:], radii[1:]):
        assert step.load_factor == pytest.approx(hill(p, c), rel=0.01)
    assert result.steps[-1].load_factor == pytest.approx(0.995 * theory(p)["limit_pressure"])


@pytest.mark.parametrize("kinematics", ["total", "updated"])
def test_neo_hookean_discs_pressed_together_at_finite_strain(kinematics):
    """Two neo-Hookean discs of revolution (radius 1, non-matching meshes) stacked and pressed
    by a platen with 100 pi per full circle (9 % axial strain): the state is homogeneous
    uniaxial stress across the contact, so every node moves as the law's closed form says to
    1e-12 and the contact pressure (nominal: per undeformed area) is 100 to 1e-9 at every
    contact node, at each of four steps' last, with the invariants passed."""
    text = STACK
    for name in ("lower", "upper"):
        text = text.replace(f'name = "{name}"\n', f'name = "{name}"\nkinematics = '
                                                  f'"{kinematics}"\nlaw = "neo-hookean"\n')
    text = (text.replace("force = -3.141592653589793", f"force = {-100.0 * math.pi!r}")
            .replace("load_factors = [1.0]", "load_factors = [0.25, 0.5, 0.75, 1.0]"))
    result = vfem.solve(loads(text, "model.toml"))
    assert result.converged, result.message
    assert all(s.invariants["passed"] for s in result.steps)
    axial = brentq(lambda s: _uniaxial_neo_hookean(s)[1] + 100.0, 0.5, 1.0, xtol=1e-16,
                   rtol=1e-15)
    lateral = _uniaxial_neo_hookean(axial)[0]
    for body in result.model.bodies:
        r = result.steps[-1].bodies[body.name]
        u = np.asarray(r.displacement).reshape(-1, 2)
        x = body.points.T
        below = 0.0 if body.name == "lower" else (axial - 1.0) * 0.5
        assert np.abs(u[:, 0] - (lateral - 1.0) * x[:, 0]).max() <= 1e-12
        assert np.abs(u[:, 1] - below - (axial - 1.0) * (x[:, 1] - x[:, 1].min())).max() \
            <= 1e-12
        on = r.contact_status > 0
        assert on.sum() >= 11
        assert np.abs(r.contact_pressure[on] - 100.0).max() <= 1e-9 * 100.0
