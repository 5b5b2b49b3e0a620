"""Hill's thick cylinder under internal pressure (issue 41): an elastic-perfectly plastic tube,
plane strain, from first yield at the bore to the collapse of the whole wall.

A quarter of the tube, bore a, outer radius b, on rollers at its two symmetry planes, of J2
material (:class:`vfem.materials.J2Plastic`, no hardening), the bore's ``pressure`` raised
through Lamé's first-yield pressure towards Hill's limit. Quadratic quadrilaterals (order 2): the
plastic flow is incompressible and bilinear ones lock under it (they carried 1.03 times the
limit, ``docs/method.md`` §13); a plastic body that touches no other may take them.

* **First yield** (Lamé): the elastic stresses at the bore, sigma_rr = -p, sigma_tt = p (b^2 +
  a^2) / (b^2 - a^2), sigma_zz = nu (sigma_rr + sigma_tt), reach von Mises' Y at p_y. The first
  step (0.9 p_y) is elastic: its largest von Mises stress over the quadrature points, scaled to
  Y, gives the run's first-yield pressure.
* **The plastic zone** (Hill, *The Mathematical Theory of Plasticity*, 1950, ch. V; exact as
  nu -> 1/2): between p_y and the limit the wall is plastic out to c, with
  p = k (1 - c^2/b^2 + 2 ln(c/a)), k = Y / sqrt 3. The run's c at each pressure 1.1 to
  1.8 p_y is where the yielded quadrature points end (:func:`plastic_radius`: midway between
  the outermost yielded point and the next elastic one out).
* **The limit** 2 k ln(b/a): the wall carries 0.995 of it (the plastic zone then reaches nearly
  to b); beyond it there is no equilibrium (``tests/test_plasticity.py`` finds none at 1.01).

**Verification** (``summary.json``, the screen): the first-yield pressure against Lamé's (0.5 %,
the issue's bound), the pressure at each plastic radius against Hill's (1 %, the issue's), and
the pressure carried against the limit (1 %, the issue's). ``hill.png`` draws the pressure
against c beside Hill's curve; ``von_mises.png`` the wall when the plastic zone reaches about
halfway through it (the zone is where the von Mises stress stands at Y).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import Support, Traction
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.errors import InputError
from vfem.materials import J2Plastic
from vfem.solver import AnalysisResult, Model

#: the pressures of the steps per Lamé's first-yield pressure (the first elastic)
PER_FIRST_YIELD = (0.9, 1.1, 1.3, 1.5, 1.7, 1.8)
#: and the last, per Hill's limit pressure
OF_LIMIT = 0.995
#: the most elements the wall may have (around times radial), a few seconds of run
MAX_ELEMENTS = 20000


@dataclass(frozen=True)
class ThickCylinderParameters:
    """Parameters of the thick-cylinder example."""

    inner_radius: float = 1.0
    outer_radius: float = 2.0
    youngs_modulus: float = 1000.0
    poissons_ratio: float = 0.49  # Hill's solution is exact as nu -> 1/2
    yield_stress: float = 1.0
    around: int = 12  # elements per quarter turn
    radial: int = 24  # elements through the wall


Parameters = ThickCylinderParameters


def theory(p: ThickCylinderParameters) -> dict[str, float]:
    """Lamé's first-yield pressure (nu's axial stress included), Hill's k and limit pressure."""
    a, b, nu, Y = p.inner_radius, p.outer_radius, p.poissons_ratio, p.yield_stress
    s_rr, s_tt = -1.0, (b * b + a * a) / (b * b - a * a)
    s_zz = nu * (s_rr + s_tt)
    per_unit = math.sqrt(0.5 * ((s_rr - s_tt) ** 2 + (s_tt - s_zz) ** 2 + (s_zz - s_rr) ** 2))
    k = Y / math.sqrt(3.0)
    return {"first_yield_pressure": Y / per_unit, "k": k,
            "limit_pressure": 2.0 * k * math.log(b / a)}


def hill(p: ThickCylinderParameters, c: float) -> float:
    """Hill's pressure with the wall plastic out to ``c``."""
    a, b = p.inner_radius, p.outer_radius
    return theory(p)["k"] * (1.0 - c * c / (b * b) + 2.0 * math.log(c / a))


def pressures(p: ThickCylinderParameters) -> tuple[float, ...]:
    """The bore's pressure at each step (the load factors: the traction is 1 per unit)."""
    th = theory(p)
    return tuple(s * th["first_yield_pressure"] for s in PER_FIRST_YIELD) + (
        OF_LIMIT * th["limit_pressure"],)


def validate(p: ThickCylinderParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    for name in ("inner_radius", "outer_radius", "youngs_modulus", "yield_stress"):
        value = getattr(p, name)
        if isinstance(value, bool) or not (isinstance(value, (int, float))
                                           and 0 < value < math.inf):
            raise InputError(f"{name} must be a finite number > 0, got {value!r}")
    if p.outer_radius <= p.inner_radius:
        raise InputError(f"outer_radius must exceed inner_radius ({p.inner_radius!r}), got "
                         f"{p.outer_radius!r}")
    nu = p.poissons_ratio
    if isinstance(nu, bool) or not (isinstance(nu, (int, float)) and 0.0 <= nu < 0.5):
        raise InputError(f"poissons_ratio must be in [0, 0.5), got {nu!r}")
    for name in ("around", "radial"):
        value = getattr(p, name)
        if isinstance(value, bool) or not isinstance(value, int) or value < 2:
            raise InputError(f"{name} must be a whole number >= 2, got {value!r}")
    if p.around * p.radial > MAX_ELEMENTS:
        raise InputError(f"around x radial must be at most {MAX_ELEMENTS} elements, got "
                         f"{p.around * p.radial}")
    th = theory(p)
    if pressures(p)[-2] >= th["limit_pressure"]:
        raise InputError(f"the wall is too thin for the steps: 1.8 times Lamé's first-yield "
                         f"pressure {th['first_yield_pressure']:.4g} reaches Hill's limit "
                         f"{th['limit_pressure']:.4g} (make outer_radius / inner_radius about "
                         f"1.95 or more, got {p.outer_radius / p.inner_radius:.4g})")
    build(p).validate()


def config(p: ThickCylinderParameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/thick_cylinder.toml`` holds for the defaults)."""
    p = p or ThickCylinderParameters()
    try:
        factors = pressures(p)
    except (ValueError, ArithmeticError, TypeError):
        factors = (1.0,)  # validate() names what is wrong
    body = BodyConfig(
        name="cylinder",
        mesh=MeshSpec(shape="annulus", parameters=as_parameters(
            inner_radius=p.inner_radius, outer_radius=p.outer_radius, around=p.around,
            radial=p.radial)),
        material=J2Plastic(p.youngs_modulus, p.poissons_ratio, p.yield_stress),
        supports=(Support("bottom", ("y",)), Support("left", ("x",))),
        tractions=(Traction("inner", pressure=1.0),),
        order=2)
    return ModelConfig("thick_cylinder", (body,), steps=Steps(load_factors=factors))


def build(p: ThickCylinderParameters | None = None) -> Model:
    return config(p).build()


def plastic_radius(radius: np.ndarray, yielded: np.ndarray) -> float | None:
    """Where the plastic zone ends, read from the quadrature points' radii and which yielded
    (None: none did): midway between the outermost yielded point and the nearest elastic one
    beyond it (b when none is), the zone's edge lying between the two. (The outermost yielded
    point alone reads c short by up to the points' spacing, half an element's width with the
    3 x 3 Gauss rule of a quadratic quadrilateral, and p(c) rises about as fast as c.)"""
    if not yielded.any():
        return None
    inner = float(radius[yielded].max())
    beyond = radius[~yielded]
    beyond = beyond[beyond > inner]
    outer = float(beyond.min()) if beyond.size else float(radius.max())
    return 0.5 * (inner + outer)


def _plastic_radii(result: AnalysisResult) -> list[float | None]:
    """The plastic zone's radius (:func:`plastic_radius`) at each step (None: none yielded),
    by the return map along the steps' converged displacements from the virgin state: the
    states the solver committed (the same law, strains and order)."""
    body = result.model.bodies[0]
    nl = body.mechanics.nonlinear
    x = nl.basis0.mapping.F(nl.basis0.X)
    radius = np.hypot(x[0], x[1])
    state = nl.material.initial_state(2, radius.shape)
    out = []
    for step in result.steps:
        g = nl.basis0.interpolate(np.ravel(step.bodies[body.name].displacement)).grad
        state = nl.material.response(0.5 * (g + np.swapaxes(g, 0, 1)), state).state
        yielded = state["equivalent_plastic_strain"] > 0
        out.append(plastic_radius(radius, yielded))
    return out


def peak_von_mises(nl, displacement: np.ndarray) -> float:
    """The largest von Mises stress (with sigma_zz) of a plane-strain Newton body ``nl``'s law
    answering ``displacement`` from the virgin state, read at its Gauss points and at its
    boundary's (the elastic solution's peak may be on the boundary, as on the bore, which the
    nearest Gauss points, a ninth of an element inside, read about 2 h / 9a low: 0.8 % with
    h = a/24)."""
    from skfem import ElementVector, FacetBasis

    u = np.ravel(displacement)
    peak = 0.0
    for basis in (nl.basis0, FacetBasis(nl.mesh, ElementVector(nl.mesh.elem()))):
        g = basis.interpolate(u).grad
        r = nl.material.response(0.5 * (g + np.swapaxes(g, 0, 1)),
                                 nl.material.initial_state(2, g.shape[2:]))
        s, szz = r.stress, r.out_of_plane
        vm = np.sqrt(0.5 * ((s[0, 0] - s[1, 1]) ** 2 + (s[1, 1] - szz) ** 2
                            + (szz - s[0, 0]) ** 2) + 3.0 * s[0, 1] ** 2)
        peak = max(peak, float(vm.max()))
    return peak


def _first_yield(result: AnalysisResult) -> float:
    """The first-yield pressure from the first (elastic) step: its pressure times Y over the
    elastic solution's largest von Mises stress (:func:`peak_von_mises`)."""
    body = result.model.bodies[0]
    nl = body.mechanics.nonlinear
    step = result.steps[0]
    return step.load_factor * nl.material.yield_stress / peak_von_mises(
        nl, step.bodies[body.name].displacement)


def evaluate(result: AnalysisResult, p: ThickCylinderParameters) -> dict:
    """First yield, the plastic radius at each pressure and the limit from a run."""
    out = dict(theory(p))
    out["pressure"] = [float(s.load_factor) for s in result.steps]
    out["plastic_radius"] = _plastic_radii(result)
    out["hill_pressure"] = [hill(p, c) if c is not None else None
                            for c in out["plastic_radius"]]
    out["run_first_yield_pressure"] = _first_yield(result)
    out["yielded_points"] = [int(s.yielded.get("cylinder", 0)) for s in result.steps]
    return out


def summarize(result: AnalysisResult, p: ThickCylinderParameters) -> dict:
    """The ``summary.json`` dictionary of a run."""
    from vfem.io.results import step_record

    summary = {
        "example": "thick_cylinder",
        "converged": result.converged,
        "message": result.message,
        "steps": [step_record(s) for s in result.steps],
        "dofs": int(sum(b.ndofs for b in result.model.bodies)),
        "parameters": dataclasses.asdict(p),
        "timings": result.timings,
        "linear_solver": result.backend,
    }
    if result.converged:
        summary["thick_cylinder"] = m = evaluate(result, p)
        summary["verification"] = verification(m)
    return summary


def verification(m: dict) -> list[dict]:
    """The first-yield pressure against Lamé's, the pressure at each plastic radius against
    Hill's, the pressure carried against the limit."""
    from vfem.io.verification import check

    records = [check("first-yield pressure", m["run_first_yield_pressure"],
                     m["first_yield_pressure"], "Lamé's elastic stresses at the bore, von Mises",
                     0.005, "issue 41's bound (the elastic solution's peak, read at the Gauss "
                     "points and on the bore)")]
    hill_source = "Hill (1950, ch. V): p = k (1 - c^2/b^2 + 2 ln(c/a)), exact as nu -> 1/2"
    for p, c, ref in zip(m["pressure"][1:-1], m["plastic_radius"][1:-1],
                         m["hill_pressure"][1:-1]):
        if c is None:
            continue
        records.append(check(f"pressure with the wall plastic to c = {c:.3f}", p, ref,
                             hill_source, 0.01,
                             "issue 41's bound (c: midway between the outermost yielded Gauss "
                             "point and the next elastic one)"))
    records.append(check("pressure carried / Hill's limit 2k ln(b/a)",
                         m["pressure"][-1] / m["limit_pressure"], 1.0,
                         "Hill's limit pressure (1950, ch. V)", 0.01,
                         f"issue 41's bound: {OF_LIMIT} of it carried (beyond it, no "
                         "equilibrium)"))
    return records


def run(p: ThickCylinderParameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD per step, ``summary.json`` and the figures to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), figures, on_step, resume)


def figures(folder) -> list[Path]:
    """``hill.png``: the pressure against the plastic zone's radius, the run's and Hill's at
    the same radii; ``von_mises.png`` when the zone reaches about halfway through the wall."""
    from vfem.io import plots, replot

    s = folder.summary
    m = s.get("thick_cylinder")
    if not folder.has_steps or m is None:
        return []
    out = folder.directory
    rows = [(c, p, h) for c, p, h in zip(m["plastic_radius"], m["pressure"], m["hill_pressure"])
            if c is not None]
    c = np.array([r[0] for r in rows])
    plots.history(out / "hill.png", c, {"vfem": np.array([r[1] for r in rows]),
                                        "Hill (1950)": np.array([r[2] for r in rows])},
                  "radius of the plastic zone c", "bore pressure",
                  f"thick cylinder: bore pressure against the plastic radius (Hill's limit "
                  f"{m['limit_pressure']:.4g})")
    # the step whose plastic zone reaches nearest the middle of the wall: the zone (von Mises
    # at Y) and the elastic rest beside it
    middle = 0.5 * (s["parameters"]["inner_radius"] + s["parameters"]["outer_radius"])
    k = min((i for i, c in enumerate(m["plastic_radius"]) if c is not None),
            key=lambda i: abs(m["plastic_radius"][i] - middle))
    step = folder.steps[min(k, len(folder.steps) - 1)]
    vm = replot.von_mises(folder, step, "von_mises.png",
                          f"thick cylinder: von Mises stress at p = {m['pressure'][k]:.4g}, "
                          f"plastic to c = {m['plastic_radius'][k]:.3f}")
    return [out / "hill.png", vm]


def report(s: dict) -> list[str]:
    """What the CLI prints after the run."""
    m = s.get("thick_cylinder")
    if m is None:
        return []
    lines = [f"  first yield at p = {m['run_first_yield_pressure']:.5g} (Lamé: "
             f"{m['first_yield_pressure']:.5g}); Hill's limit 2k ln(b/a) = "
             f"{m['limit_pressure']:.5g}"]
    for p, c, h in zip(m["pressure"], m["plastic_radius"], m["hill_pressure"]):
        if c is not None:
            lines.append(f"  p = {p:.5g}: plastic to c = {c:.4f}, Hill's p there {h:.5g} "
                         f"({100 * (p / h - 1):+.2f} %)")
    return lines
