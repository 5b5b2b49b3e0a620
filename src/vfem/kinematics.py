"""Large-deformation kinematics of thesis Chapter 2: strain, its increments, change of reference.

Every function works on fields of 2x2 tensors shaped ``(2, 2, ...)`` (``(2, 2, nelems, nqp)`` at
scikit-fem quadrature points; a single ``(2, 2)`` matrix works too), or of 3x3 tensors
``(3, 3, ...)`` for 3D bodies (issue 21, C16: the same formulas; only :func:`determinant` and
:func:`inverse` branch, on ``A.shape[0]``, to their 3x3 closed forms, the 2x2 ones unchanged).

Index convention. scikit-fem's ``grad(u)[i, j] = du_i/dX_j``; the deformation gradient is
``F = I + grad(u)`` and the Green–Lagrange strain ``E = (F^T F - I)/2``. The thesis writes the
gradient the other way round (``d x = d X . (dx/dX)``, so its ``u,X`` is our ``grad(u)^T``) and its
products ``u,X . u,X^T`` appear here as ``grad(u)^T grad(u)``. The formulas below are the thesis's
with that transpose applied; the equation numbers are the thesis's.

Configurations (thesis §2.6–2.8): ``C_U`` unstrained, ``C_1`` last converged, ``C_2`` next; ``C_A``
is the configuration of transformation, in which strains are expressed and gradients are taken.
Total Lagrangian: ``C_A = C_U``. Updated Lagrangian: ``C_A = C_1``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _eye_like(A: np.ndarray) -> np.ndarray:
    eye = np.zeros_like(A, dtype=float)
    for i in range(A.shape[0]):
        eye[i, i] = 1.0
    return eye


def _t(A: np.ndarray) -> np.ndarray:
    """Transpose of each 2x2 (3x3) tensor of the field."""
    return np.swapaxes(A, 0, 1)


def _mul(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Product of each pair of 2x2 (3x3) tensors, (A B)_ij = A_ik B_kj."""
    return np.einsum("ik...,kj...->ij...", A, B)


def determinant(A: np.ndarray) -> np.ndarray:
    """det of each 2x2 or 3x3 tensor of the field (shape ``A.shape[2:]``)."""
    if A.shape[0] == 3:
        return (A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
                - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
                + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]))
    return A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]


def inverse(A: np.ndarray) -> np.ndarray:
    """Inverse of each 2x2 or 3x3 tensor of the field (closed form: the adjugate over the
    determinant)."""
    d = determinant(A)
    if A.shape[0] == 3:
        out = np.empty_like(A, dtype=float)
        for i in range(3):
            for j in range(3):
                # (A^-1)_ij = cofactor_ji / det: rows/columns other than j and i, cyclically
                j1, j2, i1, i2 = (j + 1) % 3, (j + 2) % 3, (i + 1) % 3, (i + 2) % 3
                out[i, j] = (A[j1, i1] * A[j2, i2] - A[j1, i2] * A[j2, i1]) / d
        return out
    out = np.empty_like(A, dtype=float)
    out[0, 0] = A[1, 1] / d
    out[1, 1] = A[0, 0] / d
    out[0, 1] = -A[0, 1] / d
    out[1, 0] = -A[1, 0] / d
    return out


def deformation_gradient(grad_u: np.ndarray) -> np.ndarray:
    """``F = I + grad(u)`` (thesis eq. 2.6.9, 2.8.15)."""
    return _eye_like(grad_u) + grad_u


def green_lagrange(grad_u: np.ndarray) -> np.ndarray:
    """Green–Lagrange strain ``E = (grad u + grad u^T + grad u^T grad u)/2`` (eqs. 2.6.17–18)."""
    return 0.5 * (grad_u + _t(grad_u) + _mul(_t(grad_u), grad_u))


def almansi(grad_u: np.ndarray) -> np.ndarray:
    """Euler–Almansi strain ``e = (I - F^-T F^-1)/2`` of the configuration reached by ``u``.

    ``grad_u`` is taken with respect to the *initial* position. This is the thesis's pseudo-strain
    of a configuration transformed to itself (eqs. 2.6.19–21, 2.7.34): what an updated Lagrangian
    calculation carries as its strain state.
    """
    Fi = inverse(deformation_gradient(grad_u))
    return 0.5 * (_eye_like(grad_u) - _mul(_t(Fi), Fi))


@dataclass(frozen=True)
class StrainIncrement:
    """The four groups of thesis eq. 2.7.11, ``2A_E = E1 + E2 + E3 + E4``.

    ``2A_E`` is the (pseudo-)strain of the next configuration ``C_2`` relative to the unstrained
    one, transformed to the configuration of transformation ``C_A`` (eq. 2.7.10). Each field is
    ``(2, 2, ...)``:

    * ``E1`` (eq. 2.7.12) — the part due to the displacement already accumulated from ``C_A`` to
      ``C_1``; independent of the increment (degree 0 in it).
    * ``E2`` (eq. 2.7.13) — the *linear* part of the increment; it holds the terms that *couple* the
      increment with the accumulated displacement (they vanish in the updated form, eq. 2.7.36).
    * ``E3`` (eq. 2.7.14) — the *nonlinear (quadratic)* part of the increment.
    * ``E4`` (eq. 2.7.15) — the strain already present in ``C_A`` itself (zero when ``C_A`` is
      unstrained, i.e. total Lagrangian; the Almansi strain of ``C_1`` in the updated form).

    ``E1 + E4`` is the pseudo-strain of ``C_1`` (eq. 2.7.16), so the increment of strain over the
    step is ``E2 + E3``.
    """

    E1: np.ndarray
    E2: np.ndarray
    E3: np.ndarray
    E4: np.ndarray

    @property
    def total(self) -> np.ndarray:
        """``E1 + E2 + E3 + E4`` (eq. 2.7.11): the pseudo-strain of ``C_2`` in ``C_A``."""
        return self.E1 + self.E2 + self.E3 + self.E4

    @property
    def increment(self) -> np.ndarray:
        """``E2 + E3``: the change of the pseudo-strain from ``C_1`` to ``C_2``."""
        return self.E2 + self.E3


def strain_increment(grad_u_accumulated: np.ndarray, grad_u_increment: np.ndarray,
                     grad_u_transformation: np.ndarray | None = None) -> StrainIncrement:
    """Split the strain of ``C_2`` into the groups of thesis eqs. 2.7.11–2.7.15.

    All gradients are taken with respect to position in ``C_A`` (the thesis's ``,A``).

    Args:
        grad_u_accumulated: ``G0``, gradient of the displacement from ``C_A`` to ``C_1``
            (thesis ``1A,A u``); in the total Lagrangian form the accumulated displacement.
        grad_u_increment: ``g``, gradient of the incremental displacement from ``C_1`` to
            ``C_2`` (thesis ``21,A u``).
        grad_u_transformation: ``W``, gradient of the displacement from the unstrained ``C_U`` to
            ``C_A`` (thesis ``AU,A u``); ``None`` (zero) when ``C_A = C_U``.

    The groups, thesis form (gradients transposed, see the module docstring) → this code:

        E1 = 1/2 {1A,A u + 1A,A u^T + 1A,A u . 1A,A u^T}        = (G0 + G0^T + G0^T G0)/2
        E2 = 1/2 {21,A u + 21,A u^T + 1A,A u . 21,A u^T
                  + 21,A u . 1A,A u^T}                         = (g + g^T + G0^T g + g^T G0)/2
        E3 = 1/2 {21,A u . 21,A u^T}                           = g^T g / 2
        E4 = 1/2 {AU,A u^T + AU,A u - AU,A u . AU,A u^T}       = (W + W^T - W^T W)/2

    (``E4`` follows from ``dx_U/dx_A = I - W``, eq. 2.6.5, in eq. 2.7.2.) With ``W = 0`` the sum is
    the Green–Lagrange strain ``E(G0 + g)`` and ``E1 = E(G0)``, so ``E(G0 + g) - E(G0) = E2 + E3``.
    """
    G0, g = grad_u_accumulated, grad_u_increment
    G0t, gt = _t(G0), _t(g)
    E1 = 0.5 * (G0 + G0t + _mul(G0t, G0))
    E2 = 0.5 * (g + gt + _mul(G0t, g) + _mul(gt, G0))
    E3 = 0.5 * _mul(gt, g)
    if grad_u_transformation is None:
        E4 = np.zeros_like(E1)
    else:
        W = grad_u_transformation
        E4 = 0.5 * (W + _t(W) - _mul(_t(W), W))
    return StrainIncrement(E1, E2, E3, E4)


def updated_strain_increment(grad_u_increment: np.ndarray,
                             pseudo_strain: np.ndarray | None = None) -> StrainIncrement:
    """The groups of eq. 2.7.11 when ``C_A`` has been updated to ``C_1`` (eqs. 2.7.31–2.7.36).

    ``grad_u_increment`` is ``h = 21,1 u``, the increment's gradient with respect to position in
    ``C_1``; ``pseudo_strain`` is ``11_1 E``, the strain state carried in ``C_1`` (the Almansi
    strain of ``C_1``, obtained with :func:`change_reference`, eq. 2.8.10). Because the accumulated
    displacement from ``C_A = C_1`` to ``C_1`` is zero (``11,1 u = 0``):

        E1 = 0                                                   (eq. 2.7.31)
        E2 = 1/2 {21,1 u + 21,1 u^T}   = (h + h^T)/2             (eqs. 2.7.32, 2.7.36: the two
                                                                  coupling terms vanish)
        E3 = 1/2 {21,1 u . 21,1 u^T}   = h^T h / 2               (eq. 2.7.33)
        E4 = 11_1 E                                              (eq. 2.7.34)

    so the pseudo-strain of ``C_2`` in ``C_1`` is ``11_1 E + E2 + E3`` (eq. 2.8.11) and ``E2 + E3``
    is the Green–Lagrange strain of ``C_2`` relative to ``C_1``. Identical to
    ``strain_increment(0, h, W)`` with ``W`` the gradient (in ``C_1``) of the total displacement.
    """
    h = grad_u_increment
    E2 = 0.5 * (h + _t(h))
    E3 = 0.5 * _mul(_t(h), h)
    E4 = np.zeros_like(E2) if pseudo_strain is None else np.asarray(pseudo_strain, dtype=float)
    return StrainIncrement(np.zeros_like(E2), E2, E3, E4)


def change_reference(pseudo_strain: np.ndarray, grad_u_step: np.ndarray) -> np.ndarray:
    """Transform a pseudo-strain from configuration ``C_P`` to ``C_Q`` (thesis eq. 2.8.9).

    ``grad_u_step`` is the gradient, with respect to position in ``C_P``, of the displacement that
    carries ``C_P`` to ``C_Q``, so ``F = dx_Q/dx_P = I + grad_u_step`` (eq. 2.8.15). The thesis
    writes ``AQ_E = (dQx/dPx)^-1 . AP_E . (dQx/dPx)^-T`` with its transposed gradient, i.e.

        E_Q = F^-T E_P F^-1.

    Applied to the Green–Lagrange strain of ``C_1`` (``C_P = C_U``) it gives the pseudo-strain the
    updated form carries (eq. 2.8.10); applied at the end of each converged step with the step's
    increment it moves that state to the new configuration (eq. 2.8.13). Being linear, it also maps
    a strain *difference*: ``F^-T (E(C_2) - E(C_1)) F^-1`` is the Green–Lagrange strain of ``C_2``
    relative to ``C_1``.
    """
    Fi = inverse(deformation_gradient(grad_u_step))
    return _mul(_t(Fi), _mul(pseudo_strain, Fi))


def push_forward_stress(S: np.ndarray, F: np.ndarray) -> np.ndarray:
    """``J^-1 F S F^T``: a second Piola–Kirchhoff stress moved to the configuration ``F`` reaches.

    The stress counterpart of :func:`change_reference`: if ``S`` is work-conjugate to a strain
    ``E_P`` per unit volume of ``C_P``, then ``J^-1 F S F^T`` is work-conjugate to
    ``F^-T E_P F^-1`` per unit volume of ``C_Q``. With ``C_P`` unstrained it is the Cauchy stress.
    """
    return _mul(F, _mul(S, _t(F))) / determinant(F)


__all__ = [
    "StrainIncrement",
    "almansi",
    "change_reference",
    "deformation_gradient",
    "determinant",
    "green_lagrange",
    "inverse",
    "push_forward_stress",
    "strain_increment",
    "updated_strain_increment",
]
