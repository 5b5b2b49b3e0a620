"""Isotropic hyperelastic materials for large deformations in plane strain or in 3D.

These laws are what :class:`vfem.nonlinear.NonlinearBody` evaluates at its quadrature points: given
the Green–Lagrange strain ``E`` relative to the unstrained configuration (thesis §2.6, eq. 2.6.18)
they return the second Piola–Kirchhoff stress ``S = dW/dE`` (the stress that is work-conjugate to
``E``, thesis Ch. 3) and the material tangent ``dS/dE`` that Newton's method needs.

Arrays follow scikit-fem's layout at quadrature points: a strain or stress is ``(2, 2, ...)``
(``(2, 2, nelems, nqp)`` inside a form), a tangent is ``(2, 2, 2, 2, ...)`` with
``D[i, j, k, l] = dS_ij / dE_kl`` taken on symmetric ``E`` (so ``D`` has the minor symmetries
``D_ijkl = D_jikl = D_ijlk`` and, being a second derivative of ``W``, the major one
``D_ijkl = D_klij``). Plane strain: the out-of-plane stretch is 1 (``E_33 = 0``, ``C_33 = 1``), so
only the in-plane components are carried; :meth:`out_of_plane_stress` gives ``S_33``. A 3D body
(issue 21, C16) passes ``(3, 3, ...)`` strains and gets ``(3, 3, ...)`` stresses and
``(3, 3, 3, 3, ...)`` tangents: the same formulas with the 3D trace and identity, no plane
assumption (:meth:`out_of_plane_stress` is then None). The 2D expressions are kept literally.

Both laws reduce to isotropic linear elasticity (:class:`LinearElastic`, plane strain) for small
strains: ``D(E = 0) = lambda I(x)I + 2 mu I_sym``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinematics import determinant as _det
from ..kinematics import inverse as _inv
from .constants import check_elastic_constants
from .protocol import Response, State


def _eye_like(E: np.ndarray) -> np.ndarray:
    """The identity broadcast to the shape of the tensor field ``E`` (2, 2, ...) or (3, 3, ...)."""
    eye = np.zeros_like(E)
    for i in range(E.shape[0]):
        eye[i, i] = 1.0
    return eye


def _trace(E: np.ndarray) -> np.ndarray:
    """``tr E`` of the field: ``E00 + E11`` in 2D (plane strain, ``E33 = 0``), plus ``E22`` in
    3D (added last, so the 2D sum is the same expression)."""
    tr = E[0, 0] + E[1, 1]
    return tr + E[2, 2] if E.shape[0] == 3 else tr


def _lame(E: float, nu: float) -> tuple[float, float]:
    """Plane-strain (= 3D) Lamé constants (lambda, mu)."""
    return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))


def _outer(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """(A (x) B)_ijkl = A_ij B_kl (by broadcasting: the same products as an einsum, faster on
    fields at quadrature points)."""
    return A[:, :, None, None] * B[None, None]


def _sym_outer(A: np.ndarray) -> np.ndarray:
    """(A (.) A)_ijkl = (A_ik A_jl + A_il A_jk)/2; for symmetric A, d(A^-1)/dA = -A^-1 (.) A^-1."""
    return 0.5 * (A[:, None, :, None] * A[None, :, None, :]
                  + A[:, None, None, :] * A[None, :, :, None])


@dataclass(frozen=True)
class _Isotropic:
    """The two constants of an isotropic hyperelastic law, as in :class:`LinearElastic`, and
    its answer to the :class:`~vfem.materials.protocol.Material` protocol (no state)."""

    youngs_modulus: float
    poissons_ratio: float

    def validate(self, where: str = "material") -> None:
        """Raise :class:`InputError` naming ``where`` if the constants are not admissible."""
        check_elastic_constants(self.youngs_modulus, self.poissons_ratio, where)

    def lame(self) -> tuple[float, float]:
        """(Small-strain) Lamé constants (lambda, mu), plane strain."""
        return _lame(self.youngs_modulus, self.poissons_ratio)

    # -- the Material protocol (vfem.materials.protocol): a hyperelastic law has no history ----

    def initial_state(self, dim: int, points: tuple[int, int]) -> State:
        """No state: the stress is a function of the strain alone."""
        return {}

    def response(self, E: np.ndarray, state: State) -> Response:
        """``S(E)``, ``dS/dE`` when asked, ``S_33`` in plane strain; ``state`` unchanged."""
        return Response(self.second_piola(E), lambda: self.tangent(E),
                        self.out_of_plane_stress(E), state)


@dataclass(frozen=True)
class SaintVenantKirchhoff(_Isotropic):
    """Saint Venant–Kirchhoff: linear elasticity written in the Green–Lagrange strain.

        W(E) = lambda/2 (tr E)^2 + mu E:E
        S    = lambda tr(E) I + 2 mu E
        D    = dS/dE = lambda I (x) I + 2 mu I_sym            (constant)

    Exact under rigid rotations of any size (``E`` is), but its stress ceases to grow under strong
    compression (stretch below ``sqrt(1/3)`` uniaxially): use :class:`NeoHookean` for large
    compressive strains.

    Attributes:
        youngs_modulus: E, > 0.
        poissons_ratio: nu, in (-1, 0.5).
    """

    def energy(self, E: np.ndarray) -> np.ndarray:
        """Strain energy per unit reference volume, ``W(E)`` (shape ``E.shape[2:]``)."""
        lam, mu = self.lame()
        tr = _trace(np.asarray(E))
        return 0.5 * lam * tr**2 + mu * np.einsum("ij...,ij...->...", E, E)

    def stress(self, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Second Piola–Kirchhoff stress ``S`` and tangent ``dS/dE`` for Green–Lagrange ``E``."""
        return self.second_piola(E), self.tangent(E)

    def second_piola(self, E: np.ndarray) -> np.ndarray:
        """``S`` alone (a state whose tangent may never be asked for)."""
        E = np.asarray(E, dtype=float)
        lam, mu = self.lame()
        return lam * _trace(E) * _eye_like(E) + 2.0 * mu * E

    def tangent(self, E: np.ndarray) -> np.ndarray:
        """``dS/dE`` alone."""
        eye = _eye_like(np.asarray(E, dtype=float))
        lam, mu = self.lame()
        return lam * _outer(eye, eye) + 2.0 * mu * _sym_outer(eye)

    def out_of_plane_stress(self, E: np.ndarray) -> np.ndarray | None:
        """``S_33 = lambda tr(E)`` (plane strain, ``E_33 = 0``); None for a 3D strain."""
        if np.asarray(E).shape[0] == 3:
            return None
        lam, _ = self.lame()
        return lam * (np.asarray(E)[0, 0] + np.asarray(E)[1, 1])


@dataclass(frozen=True)
class NeoHookean(_Isotropic):
    """Compressible neo-Hookean solid (Ciarlet–Simo form), plane strain or 3D.

    With ``C = I + 2E`` the right Cauchy–Green tensor (3D, ``C_33 = 1`` in plane strain),
    ``J = det F = sqrt(det C)`` and ``I_1 = tr C`` (3D trace, ``= C_11 + C_22 + 1`` in plane
    strain):

        W(E) = mu/2 (I_1 - 3) - mu ln J + lambda/2 (ln J)^2
        S    = mu (I - C^-1) + lambda ln(J) C^-1
        D    = lambda C^-1 (x) C^-1 + 2 (mu - lambda ln J) C^-1 (.) C^-1

    where ``(A (.) A)_ijkl = (A_ik A_jl + A_il A_jk)/2``. At ``E = 0``: ``S = 0`` and
    ``D = lambda I (x) I + 2 mu I_sym`` (linear elasticity). ``W -> infinity`` as ``J -> 0``: no
    element can be compressed to zero area.

    Attributes:
        youngs_modulus: E, > 0 (small-strain modulus).
        poissons_ratio: nu, in (-1, 0.5) (small-strain ratio).
    """

    @staticmethod
    def _right_cauchy_green(E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        C = 2.0 * np.asarray(E, dtype=float) + _eye_like(np.asarray(E, dtype=float))
        detC = _det(C)
        if np.any(detC <= 0.0):
            raise ValueError("neo-Hookean: det C <= 0, the strain is not that of a deformation")
        return C, 0.5 * np.log(detC)

    def energy(self, E: np.ndarray) -> np.ndarray:
        """Strain energy per unit reference volume, ``W(E)``."""
        lam, mu = self.lame()
        C, lnJ = self._right_cauchy_green(E)
        i1 = C[0, 0] + C[1, 1] - 2.0 if C.shape[0] == 2 else C[0, 0] + C[1, 1] + C[2, 2] - 3.0
        return 0.5 * mu * i1 - mu * lnJ + 0.5 * lam * lnJ**2

    def stress(self, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Second Piola–Kirchhoff stress ``S`` and tangent ``dS/dE`` for Green–Lagrange ``E``."""
        return self.second_piola(E), self.tangent(E)

    def second_piola(self, E: np.ndarray) -> np.ndarray:
        """``S`` alone (a state whose tangent may never be asked for)."""
        lam, mu = self.lame()
        C, lnJ = self._right_cauchy_green(E)
        Ci = _inv(C)
        return mu * (_eye_like(C) - Ci) + lam * lnJ * Ci

    def tangent(self, E: np.ndarray) -> np.ndarray:
        """``dS/dE`` alone: ``lambda Ci (x) Ci + 2 (mu - lambda ln J) Ci (.) Ci``, with the
        scalars applied to one factor of each product (three products of broadcast fields
        instead of eight passes: a third of a large body's tangent time)."""
        lam, mu = self.lame()
        C, lnJ = self._right_cauchy_green(E)
        Ci = _inv(C)
        c = (mu - lam * lnJ) * Ci  # the 2 and the 1/2 of the symmetric product cancel
        return (Ci[:, :, None, None] * (lam * Ci)[None, None]
                + c[:, None, :, None] * Ci[None, :, None, :]
                + c[:, None, None, :] * Ci[None, :, :, None])

    def out_of_plane_stress(self, E: np.ndarray) -> np.ndarray | None:
        """``S_33 = mu (1 - 1/C_33) + lambda ln J / C_33 = lambda ln J`` (``C_33 = 1``); None
        for a 3D strain."""
        if np.asarray(E).shape[0] == 3:
            return None
        lam, _ = self.lame()
        return lam * self._right_cauchy_green(E)[1]


@dataclass(frozen=True)
class IsochoricNeoHookean(_Isotropic):
    """Neo-Hookean solid with its shape and volume parts apart (the form of Abaqus's and
    CalculiX's ``*HYPERELASTIC, NEO HOOKE``), plane strain or 3D.

    With ``C = I + 2E`` (``C_33 = 1`` in plane strain), ``J = sqrt(det C)``, ``I_1 = tr C`` and
    the isochoric invariant ``I1bar = J^(-2/3) I_1``:

        W(E) = mu/2 (I1bar - 3) + K/2 (J - 1)^2          (C10 = mu/2, D1 = 2/K)
        S    = mu J^(-2/3) (I - I_1/3 C^-1) + K J (J - 1) C^-1
        D    = mu J^(-2/3) [2 I_1/3 C^-1 (.) C^-1 - 2/3 (I (x) C^-1 + C^-1 (x) I)
                            + 2 I_1/9 C^-1 (x) C^-1]
               + K [J (2J - 1) C^-1 (x) C^-1 - 2 J (J - 1) C^-1 (.) C^-1]

    (``D = 2 dS/dC``: d(J^(-2/3))/dC = -J^(-2/3) C^-1 / 3, dJ/dC = J C^-1 / 2, d(C^-1)/dC =
    -C^-1 (.) C^-1), with mu and K = lambda + 2 mu / 3 the small-strain shear and bulk moduli:
    at ``E = 0`` it is linear elasticity, as :class:`NeoHookean` is; they part at finite strain
    where the volume changes (the Ciarlet–Simo form's ``I_1`` is not isochoric), by 0.2 to
    1.8 % at stretches of 0.9 to 0.7 for nu = 0.49 and up to 16 % at 1.8 for nu = 0.3
    (``benchmarks/oring_calculix.py``, ``benchmarks/ring_crush_calculix.py``). This one lets a
    model be compared with CalculiX and Abaqus on the same law. A plane-strain strain is read
    as the 3D one with ``E_33 = 0``; the in-plane parts of ``S`` and ``D`` are returned, and
    ``S_33`` by :meth:`out_of_plane_stress`.
    """

    def _kinematics(self, E: np.ndarray):
        """The 3D ``C`` (``C_33 = 1`` for a 2D strain), its inverse, ``J`` and ``I_1``."""
        E = np.asarray(E, dtype=float)
        C = np.zeros((3, 3) + E.shape[2:])
        C[: E.shape[0], : E.shape[0]] = 2.0 * E
        for i in range(3):
            C[i, i] += 1.0
        detC = _det(C)
        if np.any(detC <= 0.0):
            raise ValueError("neo-Hookean: det C <= 0, the strain is not that of a deformation")
        return C, _inv(C), np.sqrt(detC), C[0, 0] + C[1, 1] + C[2, 2]

    def _constants(self) -> tuple[float, float]:
        lam, mu = self.lame()
        return mu, lam + 2.0 * mu / 3.0

    def energy(self, E: np.ndarray) -> np.ndarray:
        """Strain energy per unit reference volume, ``W(E)``."""
        mu, K = self._constants()
        _, _, J, i1 = self._kinematics(E)
        return 0.5 * mu * (J ** (-2.0 / 3.0) * i1 - 3.0) + 0.5 * K * (J - 1.0) ** 2

    def _stress3(self, E: np.ndarray) -> np.ndarray:
        mu, K = self._constants()
        C, Ci, J, i1 = self._kinematics(E)
        return mu * J ** (-2.0 / 3.0) * (_eye_like(C) - i1 / 3.0 * Ci) + K * J * (J - 1.0) * Ci

    def stress(self, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Second Piola–Kirchhoff stress ``S`` and tangent ``dS/dE`` for Green–Lagrange ``E``."""
        return self.second_piola(E), self.tangent(E)

    def second_piola(self, E: np.ndarray) -> np.ndarray:
        """``S`` alone (in-plane for a 2D strain)."""
        d = np.asarray(E).shape[0]
        return np.ascontiguousarray(self._stress3(E)[:d, :d])

    def tangent(self, E: np.ndarray) -> np.ndarray:
        """``dS/dE`` alone (in-plane for a 2D strain: ``E_33`` is held)."""
        d = np.asarray(E).shape[0]
        mu, K = self._constants()
        C, Ci, J, i1 = self._kinematics(E)
        a = mu * J ** (-2.0 / 3.0)
        eye = _eye_like(C)
        D = (2.0 * (a * i1 / 3.0 - K * J * (J - 1.0)) * _sym_outer(Ci)
             - (2.0 / 3.0) * a * (_outer(eye, Ci) + _outer(Ci, eye))
             + (2.0 * a * i1 / 9.0 + K * J * (2.0 * J - 1.0)) * _outer(Ci, Ci))
        return np.ascontiguousarray(D[:d, :d, :d, :d])

    def out_of_plane_stress(self, E: np.ndarray) -> np.ndarray | None:
        """``S_33`` of a plane-strain strain (``C_33 = 1``); None for a 3D strain."""
        if np.asarray(E).shape[0] == 3:
            return None
        return self._stress3(E)[2, 2].copy()


#: the hyperelastic laws by the name a body's ``law`` gives (``[bodies.law]`` in an input file)
LAWS: dict[str, type] = {"saint-venant-kirchhoff": SaintVenantKirchhoff,
                         "neo-hookean": NeoHookean,
                         "neo-hookean-isochoric": IsochoricNeoHookean}

__all__ = ["SaintVenantKirchhoff", "NeoHookean", "IsochoricNeoHookean", "LAWS"]
