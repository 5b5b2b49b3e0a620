"""Cattaneo-Mindlin partial slip: two elastically similar cylinders pressed together by P, then
sheared by a growing sideways motion with P held (issue 20; the model and its measurement, not
yet a built-in example of ``vfem run``).

Two half disks of radius R = 1 (E = 1e6, nu = 0.2), flat sides out: the upper one's flat side
carries a force-controlled platen (P, then held) and a prescribed sideways motion (0, then
growing); the lower one's flat side is fixed. Their meshes are the Hertz example's graded
cylinder, mirrored into a half disk, with different numbers of contact facets across the
half-width (12 and 17 by default: non-matching). The bodies are alike and symmetric about the
contact plane, so the normal and tangential problems uncouple exactly: the normal contact is
Hertz's for R_eff = R/2, ``a = sqrt(4 P R_eff / (pi E*))``, E* = E / (2 (1 - nu^2)), and under a
tangential force Q < mu P the contact sticks over ``|x| < c = a sqrt(1 - Q / (mu P))`` and slips
outside, with the shear traction ``mu p0 (sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2))`` inside c
and ``mu p(x)`` outside (Cattaneo 1938, Mindlin 1949).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from skfem import MeshTri

from ..bodies import Body, Platen, PrescribedDisplacement, Support
from ..contact.friction import tangents
from ..contact.settings import ContactSettings
from ..solver import Analysis, Model


@dataclass(frozen=True)
class Parameters:
    """The two cylinders, the loads and the schedule."""

    force: float = 300.0  # P, per unit thickness
    friction: float = 0.3  # mu
    shift: float = 1e-3  # the upper flat side's sideways motion at the end
    facets_upper: int = 12  # contact facets across the half-width a
    facets_lower: int = 17
    youngs_modulus: float = 1.0e6
    poissons_ratio: float = 0.2
    press_steps: int = 5  # load factors 0 to 0.5: P applied
    shear_steps: int = 10  # load factors 0.5 to 1: the shift applied, P held
    # then (cycle) the shift back to -shift over load factors 1 to 1.5 and forward to +shift
    # over 1.5 to 2, shear_steps each: Mindlin and Deresiewicz's unloading and the loop
    cycle: bool = False


def theory(p: Parameters) -> dict[str, float]:
    """Hertz's half-width and peak pressure of the two cylinders (R_eff = 1/2)."""
    e_star = p.youngs_modulus / (2 * (1 - p.poissons_ratio**2))
    a = math.sqrt(4 * p.force * 0.5 / (math.pi * e_star))
    return {"a": a, "p0": 2 * p.force / (math.pi * a)}


def stick_half_width(p: Parameters, tangential: float) -> float:
    """Cattaneo-Mindlin's c for the tangential force ``tangential`` (0 at full slip)."""
    return theory(p)["a"] * math.sqrt(max(0.0, 1 - abs(tangential) / (p.friction * p.force)))


def reverse_stick_half_width(p: Parameters, peak: float, tangential: float) -> float:
    """Mindlin and Deresiewicz's c' of the stick zone while the tangential force falls from
    ``peak`` (Q*) to ``tangential``: the contact slips back over c' < |x| < a."""
    drop = abs(peak - tangential)
    return theory(p)["a"] * math.sqrt(max(0.0, 1 - drop / (2 * p.friction * p.force)))


def half_disk(p: Parameters, facets: int, flip: bool) -> MeshTri:
    """The Hertz example's graded cylinder, sized for this contact, mirrored into a half disk
    (flat side up; ``flip``: flat side down)."""
    from .hertz import HertzParameters, build

    hertz = HertzParameters(cylinder_youngs_modulus=p.youngs_modulus,
                            cylinder_poissons_ratio=p.poissons_ratio,
                            flat_youngs_modulus=p.youngs_modulus,
                            flat_poissons_ratio=p.poissons_ratio, force=p.force / 2,
                            facets_per_half_width=facets)
    quarter = next(b for b in build(hertz).bodies if b.name == "cylinder").mesh
    mirror = quarter.p * [[-1.0], [1.0]]
    pts = np.hstack([quarter.p, mirror])
    _, first, inverse = np.unique(np.round(pts.T / 1e-12).astype(np.int64), axis=0,
                                  return_index=True, return_inverse=True)
    t = quarter.t
    cells = inverse.ravel()[np.hstack([t, t[[0, 2, 1]] + mirror.shape[1]])]
    pts = pts[:, first]
    if flip:
        pts, cells = pts * [[1.0], [-1.0]], cells[[0, 2, 1]]
    return MeshTri(pts, cells)


def build(p: Parameters) -> Model:
    from ..materials import LinearElastic

    material = LinearElastic(p.youngs_modulus, p.poissons_ratio)
    up, down = half_disk(p, p.facets_upper, False), half_disk(p, p.facets_lower, True)
    top, bottom = up.p[1].max(), down.p[1].min()
    press = ((0.0, 0.0), (0.5, 1.0), (2.0, 1.0))
    shear = ((0.0, 0.0), (0.5, 0.0), (1.0, 1.0)) + (((1.5, -1.0), (2.0, 1.0)) if p.cycle else ())
    upper = Body("upper", up.with_boundaries({"top": lambda x: x[1] > top - 1e-9}), material,
                 prescribed=(PrescribedDisplacement("top", "x", p.shift, amplitude=shear),),
                 platen=Platen("top", "y", -p.force, amplitude=press))
    lower = Body("lower", down.with_boundaries({"bottom": lambda x: x[1] < bottom + 1e-9}),
                 material, supports=(Support("bottom", ("x", "y")),))
    branches = 3 if p.cycle else 1
    factors = ([0.5 * (k + 1) / p.press_steps for k in range(p.press_steps)]
               + [0.5 + 0.5 * (k + 1) / p.shear_steps for k in range(branches * p.shear_steps)])
    return Model("cattaneo", [upper, lower], ContactSettings(friction=p.friction), factors)


@dataclass
class Reading:
    """One converged step, read from the contact state: the lower body's resultant contact
    force (normal P_n, tangential Q), and per compatibility-side node its x, normal and
    tangential traction values, the latter also as its x component on the lower body."""

    load_factor: float
    normal: float
    tangential: float
    x: np.ndarray
    q: np.ndarray
    s: np.ndarray
    s_x: np.ndarray
    fine: str

    def last_sticking(self, mu: float) -> float:
        """|x| of the outermost sticking node (0 when none sticks)."""
        stick = (self.q > 0) & (np.abs(self.s) < (1 - 1e-6) * mu * self.q)
        return float(np.abs(self.x[stick]).max()) if stick.any() else 0.0


def run(p: Parameters) -> tuple[object, list[Reading]]:
    """Solve the model; the analysis result and a :class:`Reading` per converged step."""
    analysis = Analysis(build(p))
    readings: list[Reading] = []

    def on_step(step) -> None:
        c, state = analysis.contact, analysis.state
        pair = c.contact_pairs[0]
        force = step.bodies["lower"].contact_force.sum(axis=0)
        s = c.shear(state, 0).copy()
        readings.append(Reading(step.load_factor, -float(force[1]), float(force[0]),
                                c.surfaces[pair.fine].X[pair.nodes, 0].copy(),
                                c.tractions(state, 0).copy(), s,
                                s * tangents(pair.normal)[0][:, 0],
                                c.surfaces[pair.fine].body.name))

    return analysis.run(on_step), readings
