"""Finite-strain plasticity in the logarithmic strain space (issue 41, item 1: J2 plasticity
under the total and updated Lagrangian bodies).

**The model** (Miehe, Apel & Lambrecht, *Comput. Methods Appl. Mech. Engrg.* 191, 2002,
5383-5425: plasticity additive in the logarithmic strain space): the Lagrangian logarithmic
(Hencky) strain

    E_log = 1/2 ln C,        C = F^T F = I + 2 E,

takes the place of the small strain in the small-strain law, *unchanged*: the additive split
``E_log = E_e + E_p``, the elastic stress ``T = K tr E_log I + 2 mu (dev E_log - E_p)``, the
von Mises yield function in ``T`` less the back stress, the radial return and its consistent
tangent (:mod:`vfem.materials.plastic`). ``T`` is the stress conjugate to ``E_log`` per unit
reference volume; the second Piola-Kirchhoff stress the body needs is its pull-back,

    S = T : P,      P = dE_log / dE,

and the tangent ``dS/dE = P^T : C_alg : P + T : d^2 E_log / dE^2``.

**Why this model** (the issue asks for the multiplicative split with logarithmic elastic
strains, or an equivalent formulation justified): for isotropic elasticity and J2 flow with
fixed principal axes it *is* the multiplicative model ``F = F_e F_p`` with a Hencky elastic
energy and the exponential map (Simo 1992): ``T`` is then the Kirchhoff stress in the principal
frame and ``E_p`` the plastic log stretch, so the homogeneous tests read its closed form — the
small-strain one with ``ln(stretch)`` for the strain and the Kirchhoff stress for the stress.
Where the principal axes turn under plastic flow the two models are not the
same (the plastic strain here is a Lagrangian log strain, not the logarithm of a plastic
metric), and the homogeneous tests, whose axes stay fixed, do not tell them apart. What it
gives: the small-strain return, its hardening, its curve and its state serve finite strain
without a line changed; the state is Lagrangian, so a rigid rotation leaves it and the stress
``S`` untouched (objective by construction); and the law answers ``S(E)``, the contract every
body here uses (:mod:`vfem.materials.protocol`), under the total and the updated Lagrangian
forms alike.

**The derivatives of the matrix logarithm** (Daleckii and Krein; Bhatia, *Matrix Analysis*,
1997, §V.3): with ``C = Q diag(lambda) Q^T`` and the hatted tensors in that eigenbasis,

    d(ln C)[H]^ = g1 o H^,                 g1_ab = ln[lambda_a, lambda_b],
    d2(ln C)[H, K]^_ab = sum_k g2_akb (H^_ak K^_kb + K^_ak H^_kb),
                                             g2_akb = ln[lambda_a, lambda_k, lambda_b],

the first and second divided differences of ``ln`` over the eigenvalues (derivatives where
they coincide). They hold for any orthonormal eigenbasis, so repeated eigenvalues (no strain,
uniaxial and plane strain states) need no special case; the divided differences are taken in a
form that keeps full precision as eigenvalues approach each other (:func:`first_divided`,
:func:`second_divided`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .protocol import Response, State

#: three eigenvalues within this share of their mean take the second divided difference from
#: its Taylor series about the mean; further apart, from two first differences, whose
#: cancellation then costs at most a factor 1/0.05 of round-off
_SERIES_SPREAD = 0.05
#: terms of that series: the next is below 0.05^15 ~ 3e-20 of the first
_SERIES_TERMS = 15


def first_divided(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``ln[a, b] = (ln a - ln b) / (a - b)``, ``1 / a`` where ``a == b``; within a factor
    1.5 of each other as ``log1p(x) / x / b`` with ``x = (a - b) / b``, which keeps full
    precision as ``a -> b`` (the function of ``x`` is smooth, and ``log1p`` exact to
    round-off)."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    x = (a - b) / b
    near = np.abs(x) < 0.5  # a - b exact (Sterbenz), x to round-off
    ratio = np.ones_like(x)
    np.divide(np.log1p(x), x, out=ratio, where=near & (x != 0.0))
    far = np.zeros_like(x)  # apart, the logs' difference has no cancellation to fear
    np.divide(np.log(a / b), a - b, out=far, where=~near)
    return np.where(near, ratio / b, far)


def second_divided(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """``ln[a, b, c]``, the second divided difference of ``ln`` (symmetric in its arguments;
    ``-1 / (2 a^2)`` where all three are equal).

    Within :data:`_SERIES_SPREAD` of their mean ``m``: ``sum_k (-1)^(k+1) h_k(d) / (k+2) / m^2``
    with ``d = (a, b, c)/m - 1`` and ``h_k`` the complete homogeneous symmetric polynomials (a
    divided difference of ``(x - m)^j`` over the points is ``h_(j-2)`` of their offsets; Newton's
    identities give ``h_k`` from the power sums). Further apart: ``(ln[hi, mid] - ln[mid, lo])
    / (hi - lo)``, the extreme pair in the denominator.
    """
    a, b, c = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (a, b, c)))
    m = (a + b + c) / 3.0
    d = np.stack([a / m - 1.0, b / m - 1.0, c / m - 1.0])
    near = np.abs(d).max(axis=0) < _SERIES_SPREAD
    powers = [None] + [(d ** i).sum(axis=0) for i in range(1, _SERIES_TERMS)]
    h = [np.ones_like(m)]
    series = -0.5 * h[0]
    for k in range(1, _SERIES_TERMS):
        h.append(sum(powers[i] * h[k - i] for i in range(1, k + 1)) / k)
        series = series + (-1.0) ** (k + 1) * h[k] / (k + 2)
    series = series / m ** 2
    lo, mid, hi = np.sort(np.stack([a, b, c]), axis=0)
    spread = hi - lo
    direct = np.zeros_like(m)
    np.divide(first_divided(hi, mid) - first_divided(mid, lo), spread, out=direct,
              where=spread > 0.0)
    return np.where(near, series, direct)


def _last(A: np.ndarray, k: int) -> np.ndarray:
    """A field's ``k`` tensor indices moved from the front to the back."""
    return np.moveaxis(A, tuple(range(k)), tuple(range(-k, 0)))


def _first(A: np.ndarray, k: int) -> np.ndarray:
    """A field's ``k`` tensor indices moved from the back to the front (contiguous)."""
    return np.ascontiguousarray(np.moveaxis(A, tuple(range(-k, 0)), tuple(range(k))))


@dataclass(frozen=True)
class LogarithmicStrain:
    """A small-strain law with history (:class:`~vfem.materials.plastic.J2Plastic`) read in the
    Lagrangian logarithmic strain: the finite-strain law a plastic body under ``total`` or
    ``updated`` kinematics evaluates (see the module docstring).

    Attributes:
        small: the small-strain law: its stress becomes ``T``, conjugate to ``E_log``.
    """

    small: object

    #: a body of this law carries a state from step to step (its small law's)
    carries_state: ClassVar[bool] = True

    @property
    def youngs_modulus(self) -> float:
        """The small law's E: the body's scale of force (:class:`~vfem.materials.Material`)."""
        return self.small.youngs_modulus

    def validate(self, where: str = "material") -> None:
        """The small law's checks."""
        self.small.validate(where)

    def initial_state(self, dim: int, points: tuple[int, int]) -> State:
        """The small law's state at rest (its plastic strain is the plastic log strain)."""
        return self.small.initial_state(dim, points)

    def fields(self, state: State) -> dict[str, np.ndarray]:
        """The small law's fields: the plastic strain shown is the plastic log strain."""
        return self.small.fields(state)

    def response(self, E: np.ndarray, state: State) -> Response:
        """``S`` for the Green-Lagrange strain ``E`` (dim, dim, ne, nq) from the converged
        ``state``: the small law at ``E_log = ln(I + 2E) / 2``, its stress pulled back by
        ``dE_log/dE``; its tangent when asked; the small law's state to commit. A plane-strain
        body's ``C_33 = 1``: ``E_log`` is the log of the in-plane block, its zz component 0, and
        ``S_33 = T_33``."""
        E = np.asarray(E, dtype=float)
        dim = E.shape[0]
        C = _last(2.0 * E, 2) + np.eye(dim)
        # (..., d), (..., d, d): C = Q diag(lam) Q^T, lam > 0 (the body refuses det F <= 0)
        lam, Q = np.linalg.eigh(C)
        E_log = np.einsum("...ia,...a,...ja->...ij", Q, 0.5 * np.log(lam), Q)
        r = self.small.response(_first(E_log, 2), state)
        T_hat = np.einsum("...ia,...ij,...jb->...ab", Q, _last(r.stress, 2), Q)
        g1 = first_divided(lam[..., :, None], lam[..., None, :])
        S = np.einsum("...ia,...ab,...jb->...ij", Q, g1 * T_hat, Q)

        def moduli() -> np.ndarray:
            C_alg = _last(r.moduli(), 4)
            C_hat = np.einsum("...ia,...jb,...ijkl,...kc,...ld->...abcd", Q, Q, C_alg, Q, Q,
                              optimize=True)
            M = g1[..., :, :, None, None] * C_hat * g1[..., None, None, :, :]
            # T : d2 E_log/dE2 (dC = 2 dE): G_abc T_ac d_bd + G_abd T_ad d_bc
            #                                + G_abc T_cb d_ad + G_abd T_db d_ac
            G = second_divided(lam[..., :, None, None], lam[..., None, :, None],
                               lam[..., None, None, :])
            eye = np.eye(dim)
            M += np.einsum("...abc,...ac,bd->...abcd", G, T_hat, eye)
            M += np.einsum("...abd,...ad,bc->...abcd", G, T_hat, eye)
            M += np.einsum("...abc,...cb,ad->...abcd", G, T_hat, eye)
            M += np.einsum("...abd,...db,ac->...abcd", G, T_hat, eye)
            return _first(np.einsum("...ia,...jb,...abcd,...kc,...ld->...ijkl", Q, Q, M, Q, Q,
                                    optimize=True), 4)

        return Response(_first(S, 2), moduli, r.out_of_plane, r.state)


__all__ = ["LogarithmicStrain", "first_divided", "second_divided"]
