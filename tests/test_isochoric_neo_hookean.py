"""The neo-Hookean law with its shape and volume parts apart (``law = "neo-hookean-isochoric"``:
:class:`vfem.materials.hyperelastic.IsochoricNeoHookean`, CalculiX's and Abaqus's NEO HOOKE):
linear elasticity at rest, its stress the derivative of its energy and its tangent that of its
stress (central differences), its principal Kirchhoff stresses the closed form
``tau_i = mu J^(-2/3) (l_i^2 - I_1/3) + K J (J - 1)``, plane strain the 3D law with E_33 = 0."""

from __future__ import annotations

import numpy as np
import pytest

from vfem.materials.hyperelastic import LAWS, IsochoricNeoHookean, NeoHookean

LAW = IsochoricNeoHookean(1000.0, 0.3)


def strains(dim: int, scale: float, seed: int = 7) -> np.ndarray:
    e = np.random.default_rng(seed).standard_normal((dim, dim, 2, 3)) * scale
    return 0.5 * (e + e.transpose(1, 0, 2, 3))


@pytest.mark.parametrize("dim", [2, 3])
def test_at_rest_it_is_linear_elasticity(dim):
    """At E = 0 no stress and the tangent of linear elasticity (the Ciarlet–Simo law's, with the
    same constants) to round-off."""
    E = np.zeros((dim, dim, 1, 1))
    assert not np.any(LAW.second_piola(E))
    reference = NeoHookean(1000.0, 0.3).tangent(E)
    assert np.abs(LAW.tangent(E) - reference).max() <= 1e-14 * np.abs(reference).max()


@pytest.mark.parametrize("dim", [2, 3])
def test_stress_and_tangent_are_derivatives(dim):
    """At strains of 10 %: S = dW/dE and D = dS/dE by central differences (step 1e-6: error
    of order 1e-12 of the stress), D with the major symmetry."""
    E = strains(dim, 0.1)
    S, D = LAW.second_piola(E), LAW.tangent(E)
    h = 1e-6
    for k in range(dim):
        for m in range(dim):
            dE = np.zeros_like(E)
            dE[k, m] += 0.5 * h
            dE[m, k] += 0.5 * h
            dS = (LAW.second_piola(E + dE) - LAW.second_piola(E - dE)) / (2 * h)
            assert np.abs(dS - D[:, :, k, m]).max() <= 1e-8 * np.abs(D).max()
            dW = (LAW.energy(E + dE) - LAW.energy(E - dE)) / (2 * h)
            assert np.abs(dW - S[k, m]).max() <= 1e-8 * np.abs(S).max()
    assert np.abs(D - D.transpose(2, 3, 0, 1, 4, 5)).max() <= 1e-12 * np.abs(D).max()


@pytest.mark.parametrize("stretches", [(0.7, 1.1, 1.0), (1.8, 0.6, 0.9), (0.5, 0.5, 2.5)])
def test_principal_kirchhoff_stresses_are_the_closed_form(stretches):
    """Under principal stretches l_i: tau_i = l_i^2 S_i = mu J^(-2/3) (l_i^2 - I_1/3) + K J
    (J - 1), K = lambda + 2 mu / 3 (CalculiX's NEO HOOKE with C10 = mu/2, D1 = 2/K), to 1e-13 of
    the largest."""
    lam, mu = LAW.lame()
    K = lam + 2.0 * mu / 3.0
    s = np.asarray(stretches)
    E = np.diag(0.5 * (s ** 2 - 1.0))[:, :, None]
    tau = s ** 2 * np.diag(LAW.second_piola(E)[:, :, 0])
    J, i1 = float(np.prod(s)), float(np.sum(s ** 2))
    closed = mu * J ** (-2.0 / 3.0) * (s ** 2 - i1 / 3.0) + K * J * (J - 1.0)
    assert np.abs(tau - closed).max() <= 1e-13 * np.abs(closed).max()


def test_plane_strain_is_the_3d_law_with_no_strain_across():
    """A 2D strain is the 3D one with E_33 = 0: the in-plane S and D, and S_33 beside."""
    E2 = strains(2, 0.15)
    E3 = np.zeros((3, 3) + E2.shape[2:])
    E3[:2, :2] = E2
    assert np.array_equal(LAW.second_piola(E2), LAW.second_piola(E3)[:2, :2])
    assert np.array_equal(LAW.tangent(E2), LAW.tangent(E3)[:2, :2, :2, :2])
    assert np.array_equal(LAW.out_of_plane_stress(E2), LAW.second_piola(E3)[2, 2])
    assert LAW.out_of_plane_stress(E3) is None


def test_the_law_is_a_bodys_law_by_name():
    """``law = "neo-hookean-isochoric"`` names it."""
    assert LAWS["neo-hookean-isochoric"] is IsochoricNeoHookean
