"""A hyperelastic body under large displacements: rigid rotation, Newton's quadratic convergence,
total vs updated Lagrangian, the small-load (linear) limit, tangent consistency."""

import logging

import numpy as np
import pytest
from skfem import MeshQuad1, MeshTri1, asm, condense, solve
from skfem.models.elasticity import linear_elasticity

from vfem.errors import AnalysisError, InputError
from vfem.kinematics import deformation_gradient, green_lagrange, push_forward_stress
from vfem.materials import LinearElastic
from vfem.materials.hyperelastic import NeoHookean, SaintVenantKirchhoff
from vfem.nonlinear import NonlinearBody

E_MOD = 1000.0


def rectangle(mesh_cls, length, height, nx, ny):
    return mesh_cls.init_tensor(np.linspace(0, length, nx + 1),
                                np.linspace(0, height, ny + 1)).with_defaults()


def cantilever(formulation, mesh_cls=MeshQuad1, order=1, load=6.0, material=None):
    """4 x 1 cantilever clamped on the left, a downward end load on the right: tip deflection
    about a third of the length at ``load=6`` (E = 1000)."""
    body = NonlinearBody(rectangle(mesh_cls, 4.0, 1.0, 16, 4), material or NeoHookean(E_MOD, 0.3),
                         order=order, formulation=formulation)
    body.prescribe(body.boundary_dofs("left"), 0.0)
    right = body.boundary_dofs("right", "y")
    body.add_nodal_forces(right, -load / len(right))
    return body


def compressed_block(formulation, mesh_cls=MeshQuad1, order=1, material=None):
    """Unit block clamped on both faces, the top pushed down 20 %: it barrels."""
    body = NonlinearBody(rectangle(mesh_cls, 1.0, 1.0, 8, 8), material or NeoHookean(E_MOD, 0.3),
                         order=order, formulation=formulation)
    body.prescribe(body.boundary_dofs("bottom"), 0.0)
    body.prescribe(body.boundary_dofs("top", "x"), 0.0)
    body.prescribe(body.boundary_dofs("top", "y"), -0.2)
    return body


def nodal(body, u):
    return np.vstack([u[0::2], u[1::2]])


# -- rigid rotation --------------------------------------------------------------------------------

@pytest.mark.parametrize("formulation", ["total", "updated"])
@pytest.mark.parametrize("mesh_cls, order, material", [
    (MeshQuad1, 1, NeoHookean(E_MOD, 0.3)),
    (MeshTri1, 2, SaintVenantKirchhoff(E_MOD, 0.3)),
])
def test_rigid_rotation_by_90_degrees(formulation, mesh_cls, order, material):
    """The left edge is turned by 90 deg in 6 steps, nothing else holds the body: it must follow
    as a rigid body, with zero strain, zero stress and zero reactions."""
    body = NonlinearBody(rectangle(mesh_cls, 2.0, 1.0, 8, 4), material, order=order,
                         formulation=formulation)
    left = body.boundary_dofs("left")
    X = body.basis0.doflocs[:, left]
    component = left % 2

    def rotation(load_factor):
        c, s = np.cos(load_factor * np.pi / 2), np.sin(load_factor * np.pi / 2)
        return np.where(component == 0, (c - 1) * X[0] - s * X[1], s * X[0] + (c - 1) * X[1])

    body.prescribe(left, rotation)
    steps = body.solve(6)
    assert all(s.converged and s.iterations < 10 for s in steps)

    P = body.mesh.doflocs
    exact = np.vstack([-P[1] - P[0], P[0] - P[1]])  # (R - I) X, R X = (-Y, X)
    assert np.abs(nodal(body, body.displacement) - exact).max() < 1e-10
    assert np.allclose(body.deformed_points(), np.vstack([-P[1], P[0]]), atol=1e-10)
    assert np.abs(body.green_lagrange_strain()).max() < 1e-10
    assert np.abs(body.second_piola_kirchhoff()).max() < 1e-10 * E_MOD
    assert np.abs(body.stress()).max() < 1e-10 * E_MOD
    assert np.abs(body.out_of_plane_stress()).max() < 1e-10 * E_MOD
    # the residual on all dofs, reactions included, vanishes
    assert np.abs(body.reactions()).max() < 1e-10 * E_MOD * body.length
    if formulation == "updated":
        assert np.abs(body.pseudo_strain).max() < 1e-10
        assert np.allclose(body.current_mesh.doflocs, body.deformed_points(), atol=1e-12)


# -- Newton ----------------------------------------------------------------------------------------

def check_quadratic(step):
    """Converged in < 10 iterations, quadratically: the last correction gains at least 3 orders
    (to round-off) and r_k+1 / r_k^2 (relative residuals) stays bounded over the last iterations
    (those whose r_k^2 is above round-off, where the ratio still means something)."""
    assert step.converged
    assert step.iterations < 10
    r = step.relative_residuals
    assert r[-1] < 1e-10
    assert r[-1] <= 1e-3 * r[-2], r
    ratios = [q for q, a in zip(step.quadratic_ratios, r[:-1]) if a > 1e-8]
    assert max(ratios[-2:]) < 1e3, (r, ratios)
    # the order gain grows: the last correction gains more digits than the one before
    assert np.log10(r[-2] / r[-1]) > np.log10(r[-3] / r[-2]), r


@pytest.mark.parametrize("formulation", ["total", "updated"])
@pytest.mark.parametrize("mesh_cls, order", [(MeshQuad1, 1), (MeshTri1, 2)])
def test_newton_converges_quadratically_on_a_cantilever(formulation, mesh_cls, order, caplog):
    body = cantilever(formulation, mesh_cls, order)
    with caplog.at_level(logging.INFO, logger="vfem.nonlinear"):
        steps = body.solve([0.5, 1.0])
    tip = body.boundary_dofs("right", "y")
    deflection = -body.displacement[tip].mean()
    assert 1.1 < deflection < 1.5  # a third of the length: geometrically nonlinear
    for step in steps:
        check_quadratic(step)
    assert body.history == [s.residuals for s in steps]
    assert "r_k+1/r_k^2" in caplog.text


@pytest.mark.parametrize("formulation", ["total", "updated"])
def test_newton_converges_quadratically_on_a_compressed_block(formulation):
    body = compressed_block(formulation, MeshQuad1, 2)
    steps = body.solve(2)
    for step in steps:
        check_quadratic(step)
    # barrelling: the mid-height of the free sides bulges out
    P = body.deformed_points()
    mid = np.isclose(body.mesh.doflocs[1], 0.5)
    assert P[0, mid].max() > 1.05 and P[0, mid].min() < -0.05
    # the platen pushes the body down
    top_y = body.boundary_dofs("top", "y")
    assert body.reactions()[top_y].sum() < 0


@pytest.mark.parametrize("formulation", ["total", "updated"])
@pytest.mark.parametrize("material", [NeoHookean(E_MOD, 0.3), SaintVenantKirchhoff(E_MOD, 0.3)],
                         ids=["neo-Hookean", "SVK"])
def test_tangent_is_the_derivative_of_the_internal_force(formulation, material):
    body = compressed_block(formulation, MeshTri1, 1, material)
    body.solve([0.5])
    rng = np.random.default_rng(3)
    direction = 1e-2 * rng.standard_normal(body.ndofs)
    K = body.tangent_stiffness()
    h = 1e-6

    def f_int(delta):
        return body._internal(body._state(delta))

    fd = (f_int(h * direction) - f_int(-h * direction)) / (2 * h)
    Kd = K @ direction
    assert np.linalg.norm(fd - Kd) <= 1e-6 * np.linalg.norm(Kd)
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()


# -- total vs updated Lagrangian -------------------------------------------------------------------

@pytest.mark.parametrize("problem, mesh_cls, order, material", [
    (cantilever, MeshQuad1, 2, NeoHookean(E_MOD, 0.3)),
    (cantilever, MeshTri1, 1, SaintVenantKirchhoff(E_MOD, 0.3)),
    (compressed_block, MeshTri1, 1, NeoHookean(E_MOD, 0.45)),
])
def test_total_and_updated_lagrangian_agree(problem, mesh_cls, order, material):
    bodies = [problem(f, mesh_cls, order, material=material) for f in ("total", "updated")]
    for body in bodies:
        body.solve([0.25, 0.5, 0.75, 1.0])
    total, updated = bodies
    scale = np.abs(total.displacement).max()
    assert np.abs(total.displacement - updated.displacement).max() < 1e-8 * scale
    sig_t, sig_u = total.stress(), updated.stress()
    assert np.abs(sig_t - sig_u).max() < 1e-8 * np.abs(sig_t).max()
    assert np.allclose(total.out_of_plane_stress(), updated.out_of_plane_stress(),
                       atol=1e-8 * np.abs(sig_t).max())
    assert np.allclose(total.reactions(), updated.reactions(), atol=1e-8 * np.abs(sig_t).max())
    # the same nodal forces, so the same tangent (d f_int / d u) at the converged state
    K_t, K_u = total.tangent_stiffness(), updated.tangent_stiffness()
    assert abs(K_t - K_u).max() < 1e-8 * abs(K_t).max()
    # the carried pseudo-strain is the Almansi strain of the current configuration (eq. 2.8.13)
    F = deformation_gradient(total.basis0.interpolate(total.displacement).grad)
    Fi = np.linalg.inv(np.moveaxis(F, (0, 1), (-2, -1)))
    almansi = 0.5 * (np.eye(2) - np.einsum("...ki,...kj->...ij", Fi, Fi))
    assert np.allclose(np.moveaxis(updated.pseudo_strain, (0, 1), (-2, -1)), almansi, atol=1e-10)
    assert np.allclose(updated.current_mesh.doflocs, total.deformed_points(), atol=1e-10)


# -- small-load limit and homogeneous states -------------------------------------------------------

def test_small_load_limit_is_linear_elasticity():
    """The nonlinear solution tends to scikit-fem's linear elastic one; difference O(load)."""
    differences = []
    for load in (1e-2, 1e-3):
        body = cantilever("total", MeshQuad1, 1, load=load)
        body.solve(1)
        lam, mu = LinearElastic(E_MOD, 0.3).lame()
        K = asm(linear_elasticity(lam, mu), body.basis0)
        D = body.boundary_dofs("left")
        u_lin = solve(*condense(K, body.nodal_forces, D=D))
        differences.append(np.abs(body.displacement - u_lin).max() / np.abs(u_lin).max())
    assert differences[0] < 1e-2
    assert 8 < differences[0] / differences[1] < 12


@pytest.mark.parametrize("formulation", ["total", "updated"])
def test_homogeneous_deformation_gives_the_analytic_cauchy_stress(formulation):
    """u = (F - I) X on the boundary: a uniform state, sigma = J^-1 F S(E) F^T everywhere."""
    material = NeoHookean(E_MOD, 0.3)
    body = NonlinearBody(rectangle(MeshTri1, 1.0, 2.0, 3, 5), material, formulation=formulation)
    F = np.array([[1.3, 0.4], [-0.2, 0.8]])
    dofs = np.unique(np.concatenate([body.boundary_dofs(b) for b in
                                     ("left", "right", "top", "bottom")]))
    X = body.basis0.doflocs[:, dofs]
    u = (F - np.eye(2)) @ X
    values = np.where(dofs % 2 == 0, u[0], u[1])
    body.prescribe(dofs, values)
    body.solve(3)
    G = (F - np.eye(2))[:, :, None]
    S, _ = material.stress(green_lagrange(G))
    sigma = push_forward_stress(S, F[:, :, None])[:, :, 0]
    assert np.allclose(body.stress(), sigma[None], rtol=1e-10, atol=1e-10 * E_MOD)
    J = np.linalg.det(F)
    lam, _ = material.lame()
    assert np.allclose(body.out_of_plane_stress(), lam * np.log(J) / J, rtol=1e-10)
    assert np.allclose(nodal(body, body.displacement), (F - np.eye(2)) @ body.mesh.doflocs,
                       atol=1e-12)


# -- errors ----------------------------------------------------------------------------------------

def test_input_errors():
    mesh = rectangle(MeshQuad1, 1.0, 1.0, 2, 2)
    with pytest.raises(InputError, match="formulation"):
        NonlinearBody(mesh, NeoHookean(1.0, 0.3), formulation="eulerian")
    with pytest.raises(InputError, match="material"):
        NonlinearBody(mesh, LinearElastic(1.0, 0.3))
    with pytest.raises(InputError, match="poissons_ratio"):
        NonlinearBody(mesh, NeoHookean(1.0, 0.5))
    with pytest.raises(InputError, match="order"):
        NonlinearBody(mesh, NeoHookean(1.0, 0.3), order=3)
    body = NonlinearBody(mesh, NeoHookean(1.0, 0.3))
    with pytest.raises(InputError, match="no boundary"):
        body.boundary_dofs("nowhere")


def test_a_step_that_does_not_converge_keeps_the_last_state():
    body = cantilever("updated")
    body.solve([0.5])
    u, mesh = body.displacement.copy(), body.current_mesh
    with pytest.raises(AnalysisError, match="did not converge"):
        body.solve([1.0], max_iter=2)
    assert np.array_equal(body.displacement, u)
    assert body.current_mesh is mesh
    assert body.load_factor == 0.5
    assert not body.steps[-1].converged


def test_a_large_step_is_damped_and_still_reaches_the_prescribed_values(caplog):
    """80 % compression in one step: the first full correction would turn elements inside out, so
    it is halved; the rest of the prescribed increment is applied by the next corrections."""
    bodies = []
    for formulation in ("total", "updated"):
        body = compressed_block(formulation)
        body.prescribe(body.boundary_dofs("top", "y"), -0.8)
        with caplog.at_level(logging.INFO, logger="vfem.nonlinear"):
            (step,) = body.solve(1)
        assert step.converged and step.iterations < 20
        assert np.allclose(body.displacement[body.boundary_dofs("top", "y")], -0.8, atol=1e-14)
        bodies.append(body)
    assert "correction halved" in caplog.text
    scale = np.abs(bodies[0].displacement).max()
    assert np.abs(bodies[0].displacement - bodies[1].displacement).max() < 1e-8 * scale


@pytest.mark.parametrize("element", ["quad1", "tri1", "tri2"])
def test_whole_array_assembly_gives_scikit_fems_forms(element):
    """The tangent, the internal force and the displacement gradient that the large-kinematics
    bodies take from ``_ElementArrays`` are scikit-fem's assembly of the weak forms
    ``_tangent_form`` and ``_internal_force_form`` and its interpolation, to round-off, on
    bilinear quadrilaterals and linear and quadratic triangles (random moduli, not symmetric)."""
    from skfem import (
        Basis,
        ElementQuad1,
        ElementTriP1,
        ElementTriP2,
        ElementVector,
        MeshQuad,
        MeshTri,
        asm,
    )

    from vfem.nonlinear import _ElementArrays, _internal_force_form, _tangent_form

    x, y = np.linspace(-1.0, 2.0, 9), np.linspace(0.0, 1.0, 4)
    mesh, elem = {"quad1": (MeshQuad.init_tensor(x, y), ElementQuad1()),
                  "tri1": (MeshTri.init_tensor(x, y), ElementTriP1()),
                  "tri2": (MeshTri.init_tensor(x, y), ElementTriP2())}[element]
    c, s_ = np.cos(0.3), np.sin(0.3)  # a rotated, sheared mesh: no gradient is axis-aligned
    mesh = type(mesh)(np.array([[c, -s_], [s_, c]]) @ (mesh.p
                                                       + 0.2 * mesh.p[[1, 0]]), mesh.t)
    basis = Basis(mesh, ElementVector(elem))
    rng = np.random.default_rng(5)
    ne, nq = basis.nelems, basis.X.shape[-1]
    A = rng.standard_normal((2, 2, 2, 2, ne, nq))
    P = rng.standard_normal((2, 2, ne, nq))
    u = rng.standard_normal(basis.N)
    fast = _ElementArrays.of(basis)
    assert _ElementArrays.of(basis) is fast  # made once per basis
    K0 = asm(_tangent_form, basis, A=A).tocsr()
    K1 = fast.assemble(A)
    assert abs(K1 - K0).max() <= 1e-14 * abs(K0).max()
    f0 = asm(_internal_force_form, basis, P=P)
    assert np.abs(fast.internal_force(P) - f0).max() <= 1e-14 * np.abs(f0).max()
    g0 = basis.interpolate(u).grad
    g1 = fast.gradient(u)
    assert g1.flags.c_contiguous and np.abs(g1 - g0).max() <= 1e-14 * np.abs(g0).max()
