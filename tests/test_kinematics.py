"""Strain increments (thesis eqs. 2.7.11–2.7.15, 2.7.36), change of reference (eq. 2.8.9) and the
hyperelastic laws, on random tensor fields and on fields interpolated on scikit-fem meshes."""

import numpy as np
import pytest
from skfem import Basis, ElementTriP2, ElementVector, MeshQuad1, MeshTri1

from vfem.errors import InputError
from vfem.kinematics import (
    almansi,
    change_reference,
    deformation_gradient,
    green_lagrange,
    inverse,
    push_forward_stress,
    strain_increment,
    updated_strain_increment,
)
from vfem.materials import LinearElastic
from vfem.materials.hyperelastic import NeoHookean, SaintVenantKirchhoff

SHAPE = (2, 2, 5, 7)  # like scikit-fem's (2, 2, nelems, nqp)


def mul(A, B):
    return np.einsum("ik...,kj...->ij...", A, B)


def tr(A):
    return np.swapaxes(A, 0, 1)


def eye():
    return np.broadcast_to(np.eye(2)[:, :, None, None], SHAPE)


def random_gradient(rng, scale=0.3):
    return scale * rng.standard_normal(SHAPE)


def close(a, b, tol=1e-13):
    return np.abs(a - b).max() <= tol * max(1.0, np.abs(b).max())


@pytest.fixture
def rng():
    return np.random.default_rng(20240607)


# -- decomposition of eq. 2.7.11 ------------------------------------------------------------------

def test_groups_sum_to_the_pseudo_strain_of_eq_2_7_10(rng):
    """E1+E2+E3+E4 = ((I+G0+g)^T (I+G0+g) - (I-W)^T (I-W)) / 2 for any C_A (eqs. 2.7.2, 2.7.11)."""
    G0, g, W = (random_gradient(rng) for _ in range(3))
    parts = strain_increment(G0, g, W)
    F_A2 = eye() + G0 + g  # dx_2/dx_A
    F_AU = eye() - W  # dx_U/dx_A (eq. 2.6.5)
    direct = 0.5 * (mul(tr(F_A2), F_A2) - mul(tr(F_AU), F_AU))
    assert close(parts.total, direct)
    # eq. 2.7.16: the pseudo-strain of C_1 is E1 + E4
    F_A1 = eye() + G0
    assert close(parts.E1 + parts.E4, 0.5 * (mul(tr(F_A1), F_A1) - mul(tr(F_AU), F_AU)))


def test_total_lagrangian_increment_of_green_lagrange_strain(rng):
    """C_A = C_U: E(G0 + g) = E1+E2+E3+E4 with E4 = 0, E1 = E(G0), E(G0+g) - E(G0) = E2 + E3."""
    for _ in range(5):
        G0, g = random_gradient(rng, 0.5), random_gradient(rng, 0.5)
        parts = strain_increment(G0, g)
        assert np.all(parts.E4 == 0.0)
        assert close(green_lagrange(G0 + g), parts.E1 + parts.E2 + parts.E3 + parts.E4)
        assert close(parts.E1, green_lagrange(G0))
        assert close(green_lagrange(G0 + g) - green_lagrange(G0), parts.E2 + parts.E3)
        assert close(parts.increment, parts.E2 + parts.E3)
        for E in (parts.E1, parts.E2, parts.E3, parts.E4):  # all symmetric
            assert close(E, tr(E))


@pytest.mark.parametrize("mesh_cls, element", [(MeshQuad1, None), (MeshTri1, ElementTriP2)])
def test_decomposition_on_a_mesh(rng, mesh_cls, element):
    """The same identities on gradients of displacement fields interpolated by scikit-fem."""
    mesh = mesh_cls.init_tensor(np.linspace(0, 2, 5), np.linspace(0, 1, 4))
    basis = Basis(mesh, ElementVector(element() if element else mesh.elem()))
    u0 = 0.1 * rng.standard_normal(basis.N)
    du = 0.1 * rng.standard_normal(basis.N)
    G0, g = basis.interpolate(u0).grad, basis.interpolate(du).grad
    assert G0.shape == (2, 2, mesh.nelements, basis.X.shape[-1])
    parts = strain_increment(G0, g)
    E_total = green_lagrange(basis.interpolate(u0 + du).grad)
    assert close(E_total, parts.total)
    assert close(E_total - green_lagrange(G0), parts.E2 + parts.E3)


def test_degrees_in_the_increment(rng):
    """E1, E4 are independent of the increment, E2 is linear in it, E3 quadratic (thesis §2.7)."""
    G0, g, W = (random_gradient(rng) for _ in range(3))
    base = strain_increment(G0, g, W)
    for t in (-1.7, 0.5, 3.0):
        scaled = strain_increment(G0, t * g, W)
        assert close(scaled.E1, base.E1)
        assert close(scaled.E4, base.E4)
        assert close(scaled.E2, t * base.E2)
        assert close(scaled.E3, t**2 * base.E3)
    # the degree read numerically: log2 of |E_i(2g)| / |E_i(g)|
    doubled = strain_increment(G0, 2 * g, W)
    degrees = [np.log2(np.linalg.norm(getattr(doubled, k)) / np.linalg.norm(getattr(base, k)))
               for k in ("E1", "E2", "E3", "E4")]
    assert np.allclose(degrees, [0, 1, 2, 0], atol=1e-12)


def test_coupling_terms_of_e2(rng):
    """E2 = sym(g) + (G0^T g + g^T G0)/2: the coupling with the accumulated displacement."""
    G0, g = random_gradient(rng), random_gradient(rng)
    E2 = strain_increment(G0, g).E2
    E2_uncoupled = strain_increment(np.zeros(SHAPE), g).E2
    assert close(E2 - E2_uncoupled, 0.5 * (mul(tr(G0), g) + mul(tr(g), G0)))
    assert np.abs(E2 - E2_uncoupled).max() > 1e-3  # they are not small in general


def test_updated_form_eq_2_7_36(rng):
    """C_A = C_1: E1 = 0 and the coupling terms of E2 vanish; E2 = sym(h), E3 = h^T h / 2."""
    h = random_gradient(rng)
    W = random_gradient(rng)  # gradient in C_1 of the displacement from C_U to C_1
    general = strain_increment(np.zeros(SHAPE), h, W)  # the general groups with 11,1 u = 0
    updated = updated_strain_increment(h, almansi_from_current_gradient(W))
    assert np.all(updated.E1 == 0.0)
    assert np.all(general.E1 == 0.0)
    for k in ("E2", "E3", "E4"):
        assert close(getattr(updated, k), getattr(general, k))
    assert close(updated.E2, 0.5 * (h + tr(h)))
    assert close(updated.E3, 0.5 * mul(tr(h), h))
    # E2 + E3 is the Green–Lagrange strain relative to C_1
    assert close(updated.increment, green_lagrange(h))


def almansi_from_current_gradient(W):
    """Almansi strain (W + W^T - W^T W)/2, W: gradient in C_1 of the total displacement (2.7.34)."""
    return 0.5 * (W + tr(W) - mul(tr(W), W))


# -- change of reference, eq. 2.8.9 ----------------------------------------------------------------

def test_change_of_reference_eq_2_8_9(rng):
    """Moving the configuration of transformation from C_U to C_1 and on to C_2."""
    G1 = random_gradient(rng, 0.2)  # C_U -> C_1, gradient in C_U
    h = random_gradient(rng, 0.2)  # C_1 -> C_2, gradient in C_1
    F1, f = deformation_gradient(G1), deformation_gradient(h)
    G2 = mul(f, F1) - eye()  # C_U -> C_2, gradient in C_U (chain rule)
    E_U1, E_U2 = green_lagrange(G1), green_lagrange(G2)

    # eq. 2.8.10: the strain of C_1 transformed to C_1 is its Almansi strain, i.e. E4 of the
    # updated decomposition with W = I - F1^-1 (eq. 2.7.34)
    e1 = change_reference(E_U1, G1)
    assert close(e1, almansi(G1))
    assert close(e1, almansi_from_current_gradient(eye() - inverse(F1)))

    # linearity: the Green–Lagrange strain relative to the updated configuration C_1
    # is F1^-T (E(C_2) - E(C_1)) F1^-1
    assert close(change_reference(E_U2 - E_U1, G1), green_lagrange(h))

    # eq. 2.8.11: the pseudo-strain of C_2 in C_1 = 11_1E + E2 + E3 of the updated form
    assert close(change_reference(E_U2, G1), updated_strain_increment(h, e1).total)

    # eq. 2.8.13: one more change, C_1 -> C_2, gives the Almansi strain of C_2, the same as one
    # change from C_U to C_2
    e2 = change_reference(updated_strain_increment(h, e1).total, h)
    assert close(e2, almansi(G2))
    assert close(e2, change_reference(E_U2, G2))
    # and back: F^T e F recovers the Green–Lagrange strain
    F2 = deformation_gradient(G2)
    assert close(mul(tr(F2), mul(e2, F2)), E_U2)


def test_push_forward_is_conjugate_to_change_of_reference(rng):
    """S : dE per unit volume of C_U = (J^-1 F S F^T) : (F^-T dE F^-1) per unit volume of C_1."""
    G1 = random_gradient(rng, 0.2)
    F1 = deformation_gradient(G1)
    J1 = F1[0, 0] * F1[1, 1] - F1[0, 1] * F1[1, 0]
    S = random_gradient(rng)
    S = S + tr(S)
    dE = random_gradient(rng)
    dE = dE + tr(dE)
    lhs = np.einsum("ij...,ij...->...", S, dE)
    rhs = J1 * np.einsum("ij...,ij...->...", push_forward_stress(S, F1), change_reference(dE, G1))
    assert np.allclose(lhs, rhs, rtol=1e-13, atol=1e-13)


# -- hyperelastic materials -----------------------------------------------------------------------

MATERIALS = [SaintVenantKirchhoff(210e3, 0.3), NeoHookean(210e3, 0.3), NeoHookean(1.0, -0.4),
             SaintVenantKirchhoff(5.0, 0.45)]


def random_strain(rng, scale):
    E = scale * rng.standard_normal(SHAPE)
    return 0.5 * (E + tr(E))


@pytest.mark.parametrize("material", MATERIALS, ids=lambda m: f"{type(m).__name__}")
def test_zero_strain_and_small_strain_limit(material):
    S, D = material.stress(np.zeros(SHAPE))
    assert np.all(np.abs(S) <= 1e-12 * material.youngs_modulus)
    assert D.shape == (2, 2, 2, 2) + SHAPE[2:]
    lam, mu = LinearElastic(material.youngs_modulus, material.poissons_ratio, "strain").lame()
    assert np.allclose((lam, mu), material.lame(), rtol=1e-15)
    d = np.eye(2)
    C = (lam * np.einsum("ij,kl->ijkl", d, d)
         + mu * (np.einsum("ik,jl->ijkl", d, d) + np.einsum("il,jk->ijkl", d, d)))
    assert np.allclose(D, C[..., None, None], rtol=1e-14, atol=1e-14 * material.youngs_modulus)


@pytest.mark.parametrize("material", MATERIALS, ids=lambda m: f"{type(m).__name__}")
def test_stress_and_tangent_against_finite_differences(rng, material):
    E = random_strain(rng, 0.1)
    S, D = material.stress(E)
    scale = material.youngs_modulus
    h = 1e-6
    for k in range(2):
        for m in range(2):
            dE = np.zeros(SHAPE)
            dE[k, m] += 0.5
            dE[m, k] += 0.5  # symmetric direction
            # S = dW/dE
            dW = (material.energy(E + h * dE) - material.energy(E - h * dE)) / (2 * h)
            assert np.allclose(dW, np.einsum("ij...,ij...->...", S, dE), rtol=1e-6,
                               atol=1e-9 * scale)
            # D = dS/dE
            dS = (material.stress(E + h * dE)[0] - material.stress(E - h * dE)[0]) / (2 * h)
            DdE = np.einsum("ijkl...,kl...->ij...", D, dE)
            assert np.abs(dS - DdE).max() <= 1e-6 * np.abs(DdE).max() + 1e-9 * scale
    # major and minor symmetries
    assert np.allclose(D, np.transpose(D, (2, 3, 0, 1, 4, 5)), rtol=1e-12, atol=1e-12 * scale)
    assert np.allclose(D, np.transpose(D, (1, 0, 2, 3, 4, 5)), rtol=1e-12, atol=1e-12 * scale)


def test_neo_hookean_and_svk_agree_to_first_order(rng):
    E0 = random_strain(rng, 1.0)
    svk, nh = SaintVenantKirchhoff(100.0, 0.25), NeoHookean(100.0, 0.25)
    diffs = []
    for t in (1e-2, 1e-3, 1e-4):
        E = t * E0
        diffs.append(np.abs(svk.stress(E)[0] - nh.stress(E)[0]).max() / (100.0 * t))
    # relative difference O(t): falls tenfold with t
    assert diffs[0] < 1.0
    assert 7 < diffs[0] / diffs[1] < 13 and 7 < diffs[1] / diffs[2] < 13
    # out-of-plane stresses agree to first order too
    E = 1e-4 * E0
    s33_svk, s33_nh = svk.out_of_plane_stress(E), nh.out_of_plane_stress(E)
    assert np.abs(s33_svk - s33_nh).max() < 1e-2 * np.abs(s33_svk).max()


def test_material_validation():
    for bad in (SaintVenantKirchhoff(0.0, 0.3), NeoHookean(1.0, 0.5), NeoHookean(float("nan"), 0.3),
                SaintVenantKirchhoff(1.0, -1.0)):
        with pytest.raises(InputError, match="body A"):
            bad.validate("body A")
    SaintVenantKirchhoff(1.0, 0.0).validate()
