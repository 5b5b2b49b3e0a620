"""J2 (von Mises) elasto-plasticity in small strain: radial return and its consistent tangent
(issue 41, item 1; the first material nonlinearity the thesis names, Ch. 1). Read in the
logarithmic strain, the same law serves finite strain (:mod:`.logstrain`).

The strain splits additively, ``eps = eps_e + eps_p``; the stress is the elastic one of the
elastic part, ``sigma = K tr(eps) I + 2 mu (dev(eps) - eps_p)`` (the plastic strain is
deviatoric). The yield function is von Mises' in the stress relative to the back stress
``beta`` (linear kinematic hardening, Prager), the radius growing with the equivalent plastic
strain ``alpha`` (linear isotropic hardening):

    f = |xi| - sqrt(2/3) (Y + H_iso alpha),      xi = dev(sigma) - beta,
    d(eps_p) = dgamma n,  d(alpha) = sqrt(2/3) dgamma,  d(beta) = 2/3 H_kin dgamma n,
    n = xi / |xi|.

A uniaxial test reads ``sigma = Y + (H_iso + H_kin) eps_p`` while loading: ``H = H_iso + H_kin``
is the slope of the stress against the plastic strain, and the elasto-plastic tangent
``E H / (E + H)``. In place of ``Y + H_iso alpha`` the yield stress may be a piecewise-linear
curve of the equivalent plastic strain, ``sigma_y(alpha)`` (``hardening_curve``: pairs
(alpha, sigma_y) from (0, Y), held at its last value beyond its last point, as Abaqus's
``*PLASTIC`` table), with ``H_iso`` its slope where ``alpha`` lies.

**Radial return** (Simo & Hughes, *Computational Inelasticity*, 1998, box 3.1): the trial
state freezes the plastic variables; where ``f_trial > 0`` the closest point projection onto
the yield surface is along ``n_trial`` and, with linear hardening, closed form:
``dgamma = f_trial / (2 mu + 2/3 (H_iso + H_kin))``; on a curve the return is the same on the
segment where the new ``alpha`` lies (the consistency condition is piecewise linear in
``dgamma``: each segment's root, the next segment's where it falls beyond, exact).
**Consistent tangent** (their box 3.2, ``H_iso`` the slope at the new ``alpha``):

    C = K I (x) I + 2 mu theta (I_sym - I (x) I / 3) - 2 mu theta_bar n (x) n,
    theta = 1 - 2 mu dgamma / |xi_trial|,
    theta_bar = 1 / (1 + (H_iso + H_kin) / (3 mu)) - (1 - theta),

the exact derivative of the returned stress with respect to the total strain, which keeps
Newton's convergence quadratic past yield.

The tensors are carried in 3D (a plane-strain body's ``eps_zz = 0`` and its plastic strain's
zz component is not: ``tr eps_p = 0``); a 2D body gets the in-plane stress and tangent and
``sigma_zz`` beside them. In plane stress ``eps_zz`` is the unknown that makes the returned
``sigma_zz`` vanish at each point (a scalar Newton iteration on the 3D return), and the
in-plane tangent the 3D one condensed by ``sigma_zz = 0``.

The state (:mod:`.protocol`): ``plastic_strain`` and ``back_stress`` (3, 3, ne, nq),
``equivalent_plastic_strain`` (ne, nq), committed only when a step converges.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import InputError
from .constants import check_elastic_constants
from .hyperelastic import _lame
from .logstrain import LogarithmicStrain
from .protocol import Response, State

#: a trial state whose yield function is at most this share of the yield radius is elastic:
#: the stress returned at the last step lies on the surface to round-off, and a step that
#: holds the strain must not flow by it
YIELD_TOLERANCE = 1e-12

#: Newton iterations of the plane-stress return's sigma_zz = 0 at most (it takes 2 to 6)
_PLANE_STRESS_ITERATIONS = 60

#: the names of the J2 model in an input file's ``model`` key
MODELS = ("von_mises",)


@dataclass(frozen=True)
class J2Plastic:
    """Elasto-plastic material: isotropic elasticity and J2 (von Mises) plasticity with linear
    isotropic and kinematic hardening; a table with a ``yield_stress`` is this one. Its bodies
    are solved by Newton's method (plane strain or 3D): in small strain under small
    kinematics (linear elements where it touches another body, quadratic too where it touches
    none), at finite strain under ``total`` or ``updated`` kinematics (the same law in the
    logarithmic strain, :mod:`vfem.materials.logstrain`; linear elements).

    (The law: :mod:`vfem.materials.plastic`'s docstring.)

    Attributes:
        youngs_modulus: E, > 0.
        poissons_ratio: nu, in (-1, 0.5).
        yield_stress: Y, > 0: the initial yield stress in uniaxial tension.
        hardening_modulus: H_iso >= 0: isotropic hardening, the yield stress's growth per unit
            equivalent plastic strain (0: no isotropic hardening).
        kinematic_modulus: H_kin >= 0: linear kinematic hardening (Prager), the back stress's
            growth per unit plastic strain, uniaxially (0: none).
        hardening_curve: the yield stress as a piecewise-linear function of the equivalent
            plastic strain, ``[[0, Y], [alpha_1, sigma_1], ...]``: alpha increasing from 0,
            sigma_y from ``yield_stress`` never falling, held beyond the last pair; in place of
            ``hardening_modulus`` (default: none).
        model: ``"von_mises"``: the yield criterion.
        plane: ``"strain"`` or ``"stress"``: the section of a 2D body (plane stress under
            small kinematics).
    """

    youngs_modulus: float
    poissons_ratio: float
    yield_stress: float
    hardening_modulus: float = 0.0
    kinematic_modulus: float = 0.0
    hardening_curve: tuple[tuple[float, float], ...] = ()
    model: str = "von_mises"
    plane: str = "strain"

    #: a body of this material carries a state from step to step, and so answers its contact
    #: forces by Newton's method under small kinematics too (:attr:`vfem.bodies.Body.iterates`)
    carries_state: ClassVar[bool] = True

    def validate(self, where: str = "material") -> None:
        """Raise :class:`InputError` naming ``where`` if a parameter is not admissible."""
        check_elastic_constants(self.youngs_modulus, self.poissons_ratio, where)
        if self.model not in MODELS:
            raise InputError(f"{where}: model must be {' or '.join(map(repr, MODELS))}, "
                             f"got {self.model!r}")
        for key in ("yield_stress", "hardening_modulus", "kinematic_modulus"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value):
                raise InputError(f"{where}: {key} must be a finite number, got {value!r}")
        if self.yield_stress <= 0:
            raise InputError(f"{where}: yield_stress must be > 0, got {self.yield_stress!r}")
        for key in ("hardening_modulus", "kinematic_modulus"):
            if getattr(self, key) < 0:
                raise InputError(f"{where}: {key} must be >= 0 (softening is not taken), "
                                 f"got {getattr(self, key)!r}")
        self._check_curve(where)

    def _check_curve(self, where: str) -> None:
        curve = self.hardening_curve
        if not curve:
            return
        if self.hardening_modulus != 0.0:
            raise InputError(f"{where}: give hardening_curve or hardening_modulus, not both")
        if any(len(pair) != 2 or not all(isinstance(v, (int, float)) and math.isfinite(v)
                                         for v in pair) for pair in curve):
            raise InputError(f"{where}: hardening_curve must be pairs of finite numbers "
                             f"[equivalent plastic strain, yield stress], got {curve!r}")
        alpha = [float(a) for a, _ in curve]
        stress = [float(v) for _, v in curve]
        if alpha[0] != 0.0 or stress[0] != float(self.yield_stress):
            raise InputError(f"{where}: hardening_curve must start at [0, yield_stress] "
                             f"([0, {self.yield_stress!r}]), got {list(curve[0])!r}")
        if any(b <= a for a, b in zip(alpha, alpha[1:])):
            raise InputError(f"{where}: hardening_curve's plastic strains must increase, "
                             f"got {alpha!r}")
        if any(b < a for a, b in zip(stress, stress[1:])):
            raise InputError(f"{where}: hardening_curve's yield stresses must not fall "
                             f"(softening is not taken), got {stress!r}")

    def _segments(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The yield stress's segments: their first equivalent plastic strains, yield stresses
        there and slopes (the last one unbounded: ``H_iso``, or 0 beyond a curve's end)."""
        if not self.hardening_curve:
            return (np.zeros(1), np.array([float(self.yield_stress)]),
                    np.array([float(self.hardening_modulus)]))
        alpha = np.array([float(a) for a, _ in self.hardening_curve])
        stress = np.array([float(v) for _, v in self.hardening_curve])
        return alpha, stress, np.r_[np.diff(stress) / np.diff(alpha), 0.0]

    def lame(self) -> tuple[float, float]:
        """Lamé constants (lambda, mu) of the elastic part as a body's section reads them
        (lambda modified in plane stress, as :meth:`LinearElastic.lame
        <vfem.materials.LinearElastic.lame>`): the stiffness at rest."""
        lam, mu = self._lame3d()
        if self.plane == "stress":
            lam = 2.0 * lam * mu / (lam + 2.0 * mu)
        return lam, mu

    def _lame3d(self) -> tuple[float, float]:
        """The 3D Lamé constants (lambda, mu), which the return map reads."""
        return _lame(self.youngs_modulus, self.poissons_ratio)

    def plane_strain_modulus(self) -> float:
        """E/(1-nu^2) of the elastic part (E in plane stress): the modulus in Hertz's E*."""
        if self.plane == "stress":
            return self.youngs_modulus
        return self.youngs_modulus / (1.0 - self.poissons_ratio ** 2)

    def law(self, name: str, kinematics: str = "small") -> J2Plastic | LogarithmicStrain:
        """The law a body of this material evaluates (``name``, the hyperelastic law of a
        large body, does not apply): this one under small kinematics; under ``total`` or
        ``updated`` kinematics this one read in the logarithmic strain
        (:class:`~vfem.materials.logstrain.LogarithmicStrain`: finite-strain plasticity)."""
        return self if kinematics == "small" else LogarithmicStrain(self)

    # -- the Material protocol (vfem.materials.protocol) ----------------------------------------

    def initial_state(self, dim: int, points: tuple[int, int]) -> State:
        """No plastic strain, no back stress, no equivalent plastic strain."""
        return {"plastic_strain": np.zeros((3, 3) + tuple(points)),
                "back_stress": np.zeros((3, 3) + tuple(points)),
                "equivalent_plastic_strain": np.zeros(tuple(points))}

    def response(self, E: np.ndarray, state: State) -> Response:
        """The stress that answers the small strain ``E`` (dim, dim, ne, nq) from the
        converged ``state``, by radial return; the consistent tangent when asked; the state
        to commit. A plane-strain body's ``eps_zz`` is 0 and its ``sigma_zz`` comes beside the
        in-plane stress; a plane-stress body's ``eps_zz`` is the one that makes ``sigma_zz``
        vanish (:meth:`_plane_stress`)."""
        E = np.asarray(E, dtype=float)
        dim = E.shape[0]
        if dim == 3:
            sigma, moduli, new = self._return(E, state)
            return Response(sigma, moduli, None, new)
        eps = np.zeros((3, 3) + E.shape[2:])
        eps[:2, :2] = E
        if self.plane == "stress":
            return self._plane_stress(eps, state)
        sigma, moduli, new = self._return(eps, state, dim=2)
        return Response(sigma[:2, :2].copy(), moduli, sigma[2, 2].copy(), new)

    def _plane_stress(self, eps: np.ndarray, state: State) -> Response:
        """Plane stress: ``eps_zz`` at each point such that the returned ``sigma_zz`` is 0,
        by Newton's method on that one equation with the 3D return and its tangent
        ``C_zzzz`` (at least the bulk modulus: ``sigma_zz`` rises monotonically with
        ``eps_zz``), kept inside the bracket its signs have shown (bisection where a step
        leaves it); then the in-plane tangent condensed, ``C_abcd - C_abzz C_zzcd / C_zzzz``,
        the exact derivative of the plane-stress return (its ``eps_zz`` follows the in-plane
        strain through ``sigma_zz = 0``). Converged where ``|sigma_zz|`` is within 1e-14 of
        the stress's scale, or the step within round-off of ``eps_zz``."""
        lam, mu = self._lame3d()
        ep = state["plastic_strain"]
        # the elastic guess: sigma_zz = lam tr(eps) + 2 mu (eps_zz - ep_zz) = 0
        eps[2, 2] = (2.0 * mu * ep[2, 2] - lam * (eps[0, 0] + eps[1, 1])) / (lam + 2.0 * mu)
        lo = np.full(eps.shape[2:], -np.inf)
        hi = np.full(eps.shape[2:], np.inf)
        for _ in range(_PLANE_STRESS_ITERATIONS):
            sigma, moduli, new = self._return(eps, state)
            s33 = sigma[2, 2]
            scale = self.yield_stress + np.abs(sigma[:2, :2]).max(axis=(0, 1))
            if np.all(np.abs(s33) <= 1e-14 * scale):
                break
            C = moduli()
            hi = np.where(s33 > 0.0, np.minimum(hi, eps[2, 2]), hi)
            lo = np.where(s33 < 0.0, np.maximum(lo, eps[2, 2]), lo)
            step = -s33 / C[2, 2, 2, 2]
            trial = eps[2, 2] + step
            outside = (trial <= lo) | (trial >= hi)
            bisect = outside & np.isfinite(lo) & np.isfinite(hi)
            middle = 0.5 * (np.where(bisect, lo, 0.0) + np.where(bisect, hi, 0.0))
            trial = np.where(bisect, middle, trial)
            if np.all(np.abs(trial - eps[2, 2]) <= 4.0 * np.finfo(float).eps
                      * np.maximum(np.abs(eps[2, 2]), np.abs(eps[:2, :2]).max(axis=(0, 1)))):
                eps[2, 2] = trial
                sigma, moduli, new = self._return(eps, state)
                break
            eps[2, 2] = trial
        else:
            raise ArithmeticError(f"plane-stress return: sigma_zz not zero after "
                                  f"{_PLANE_STRESS_ITERATIONS} iterations")

        def condensed() -> np.ndarray:
            C = moduli()
            return (C[:2, :2, :2, :2]
                    - C[:2, :2, 2, 2][:, :, None, None] * C[2, 2, :2, :2][None, None]
                    / C[2, 2, 2, 2])

        return Response(sigma[:2, :2].copy(), condensed, np.zeros_like(sigma[2, 2]), new)

    def _return(self, eps: np.ndarray, state: State, dim: int = 3):
        """The radial return at the 3D small strain ``eps`` (3, 3, ...): the stress (3, 3,
        ...), its consistent tangent as a function (its first ``dim`` components in each
        index: (dim, dim, dim, dim, ...)) and the state to commit."""
        lam, mu = self._lame3d()
        bulk = lam + 2.0 * mu / 3.0
        tr = eps[0, 0] + eps[1, 1] + eps[2, 2]
        dev = eps.copy()
        for i in range(3):
            dev[i, i] -= tr / 3.0
        ep, beta = state["plastic_strain"], state["back_stress"]
        alpha = state["equivalent_plastic_strain"]
        s_trial = 2.0 * mu * (dev - ep)
        xi = s_trial - beta
        norm = np.sqrt(np.einsum("ij...,ij...->...", xi, xi))
        start, level, slope = self._segments()
        root = math.sqrt(2.0 / 3.0)
        j = np.searchsorted(start, alpha, side="right") - 1  # the segment of each point
        radius = root * (level[j] + slope[j] * (alpha - start[j]))
        f = norm - radius
        flows = f > YIELD_TOLERANCE * radius
        # the consistency condition, linear on a segment: its root, or the next segment's
        # where the new alpha falls beyond it (at most a pass per segment)
        dgamma = np.zeros_like(norm)
        hardening = slope[j]  # H_iso where the new alpha lies
        todo = flows.copy()
        for _ in range(len(start)):
            if not todo.any():
                break
            jt = j[todo]
            dg = ((norm[todo] - root * (level[jt] + slope[jt] * (alpha[todo] - start[jt])))
                  / (2.0 * mu + 2.0 / 3.0 * (self.kinematic_modulus + slope[jt])))
            beyond = (jt + 1 < len(start)) & (
                alpha[todo] + root * dg > start[np.minimum(jt + 1, len(start) - 1)])
            dgamma[todo] = dg
            hardening[todo] = slope[jt]
            j[todo] = jt + beyond
            todo[todo] = beyond
        n = np.divide(xi, norm, out=np.zeros_like(xi), where=flows)
        step = dgamma * n
        sigma = s_trial - 2.0 * mu * step
        for i in range(3):
            sigma[i, i] += bulk * tr
        new = {"plastic_strain": ep + step,
               "back_stress": beta + 2.0 / 3.0 * self.kinematic_modulus * step,
               "equivalent_plastic_strain": alpha + root * dgamma}

        def moduli() -> np.ndarray:
            theta = 1.0 - 2.0 * mu * np.divide(dgamma, norm, out=np.zeros_like(norm),
                                               where=flows)
            H = hardening + self.kinematic_modulus
            theta_bar = np.where(flows, 1.0 / (1.0 + H / (3.0 * mu)) - (1.0 - theta), 0.0)
            eye = np.eye(dim)
            shape = (dim, dim, dim, dim) + eps.shape[2:]
            ii = np.einsum("ij,kl->ijkl", eye, eye)
            sym = 0.5 * (np.einsum("ik,jl->ijkl", eye, eye) + np.einsum("il,jk->ijkl", eye, eye))
            C = np.broadcast_to((bulk * ii)[..., None, None], shape).copy()
            C += 2.0 * mu * theta * (sym - ii / 3.0)[..., None, None]
            nd = n[:dim, :dim]
            C -= 2.0 * mu * theta_bar * nd[:, :, None, None] * nd[None, None]
            return C

        return sigma, moduli, new

    def fields(self, state: State) -> dict[str, np.ndarray]:
        """What a body writes of the state (element averages, :mod:`.protocol`): the
        equivalent plastic strain, a yielded flag (1 where any plastic strain) and the
        plastic strain tensor's components."""
        alpha = state["equivalent_plastic_strain"]
        ep = state["plastic_strain"]
        out = {"equivalent_plastic_strain": alpha, "yielded": (alpha > 0.0).astype(float)}
        for name, (i, j) in (("xx", (0, 0)), ("yy", (1, 1)), ("zz", (2, 2)), ("xy", (0, 1)),
                             ("yz", (1, 2)), ("xz", (0, 2))):
            out[f"plastic_strain_{name}"] = ep[i, j]
        return out


__all__ = ["J2Plastic", "MODELS", "YIELD_TOLERANCE"]
