"""An elasto-plastic cylinder pressed onto a stiff flat past first yield and lifted off (issue 41):
where and when yield starts under a Hertz contact, the force-approach loop and the flat it keeps.

The Hertz example's geometry (:mod:`vfem_examples.hertz`: a quarter disk of radius R on a layer,
half models by the symmetry plane x = 0), the cylinder of J2 material
(:class:`vfem.materials.J2Plastic`, elastic-perfectly plastic unless ``hardening_modulus`` is
set), the flat elastic and much stiffer. (Why not a stiff cylinder into a plastic block: the
Hertz example's layer has two rows of elements through its depth, graded along its surface
only, which is right for a stiff flat and far too stiff for a compliant one: with the flat as
compliant as the cylinder, elastic, ``vfem run hertz`` reads p_max 20 % high, and its own
verification says so. Under Hertz's pressure the two bodies' stresses are alike, so where and
when the first point yields is the same question.) Under Hertz's pressure the von Mises stress
peaks on the axis at
0.704 a with 0.557 p0 for nu = 0.3 (McEwen's stresses in plane strain, :func:`onset`): the first
point yields when p0 = 1.794 Y. The yield stress is set so that this happens at the force whose
Hertz half-width is ``onset_half_width`` R (small: the half-space's stresses hold to about
a / 2R, and the cylinder's own stress from the load, P / pi R, is 0.4 % of p0), the *onset
force*. The platen's force rises to it in steps of 1 % of it near it, on to ``overload`` times
it, and falls back to a hundredth of it (a force-controlled cylinder with no force left has no
position). The mesh: 24 facets over the peak force's half-width (15.2 over the onset's). With
the peak at 1.5 times the onset force and 12, 18 and 24 facets over its half-width (9.8, 14.7,
19.6 over the onset's) the first point yielded at 0.98, 0.99 and 0.99 of the onset force, 0.683,
0.692 and 0.698 a deep.

**Verification** (``summary.json``, the screen): the first step with a yielded point against
Hertz's onset (within 2 %, issue 41's bound; the steps 1 % apart bracket it); the mean depth of
the points that yield first against 0.704 a (within one element); the platen's force met at the
peak. Reported with no reference: the loop (the contact force against the platen's travel,
``loop.png``), the residual approach (the cylinder's permanent shortening at a hundredth of
the onset force: the dent's counterpart), how many points yielded.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import Platen
from vfem.config import ModelConfig, Steps
from vfem.errors import InputError
from vfem.materials import J2Plastic
from vfem.solver import AnalysisResult, Model

from . import hertz

#: the platen's force at each loading step, per onset force: 1 % apart around the onset (then
#: every half of it up to the peak)
LOADING = (0.5, 0.9, 0.96, 0.97, 0.98, 0.99, 1.0, 1.01, 1.02, 1.03, 1.1, 1.25)
#: the largest peak force per onset force (:func:`validate`)
MAX_OVERLOAD = 20.0
#: and at each unloading step (the last: what is left, a hundredth)
UNLOADING = (1.0, 0.5, 0.2, 0.01)


@dataclass(frozen=True)
class IndentationParameters:
    """Parameters of the indentation example."""

    radius: float = 1.0
    cylinder_youngs_modulus: float = 1.0e6
    cylinder_poissons_ratio: float = 0.3
    flat_youngs_modulus: float = 3.0e9
    flat_poissons_ratio: float = 0.2
    hardening_modulus: float = 0.0  # linear isotropic hardening (0: perfectly plastic)
    onset_half_width: float = 0.004  # Hertz's half-width at first yield, per radius
    overload: float = 2.5  # the peak force, per onset force (> 1.03)
    facets_per_half_width: int = 24  # at the peak force
    refinement: int = 0


Parameters = IndentationParameters


def onset(nu: float) -> tuple[float, float]:
    """Hertz's yield onset in plane strain (McEwen's stresses on the axis under p0, the axial
    stress nu times the in-plane sum): (p0 / Y at first yield, its depth per a)."""
    z = np.linspace(1e-3, 3.0, 300001)
    sx = -((1 + 2 * z * z) / np.sqrt(1 + z * z) - 2 * z)
    sz = -1 / np.sqrt(1 + z * z)
    sy = nu * (sx + sz)
    vm = np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2))
    k = int(vm.argmax())
    return 1.0 / float(vm[k]), float(z[k])


def _hertz(p: IndentationParameters, force: float) -> hertz.HertzParameters:
    return hertz.HertzParameters(
        radius=p.radius, cylinder_youngs_modulus=p.cylinder_youngs_modulus,
        cylinder_poissons_ratio=p.cylinder_poissons_ratio,
        flat_youngs_modulus=p.flat_youngs_modulus, flat_poissons_ratio=p.flat_poissons_ratio,
        force=force, facets_per_half_width=p.facets_per_half_width, refinement=p.refinement)


def theory(p: IndentationParameters) -> dict[str, float]:
    """The onset force (half model), its half-width and p0, the yield stress, and the onset's
    ratio p0 / Y and depth per a (:func:`onset`)."""
    e_star = hertz.theory(_hertz(p, 1.0))["e_star"]
    a = p.onset_half_width * p.radius
    force = math.pi * a * a * e_star / (8.0 * p.radius)  # half of P = pi a^2 E* / 4R
    ratio, depth = onset(p.cylinder_poissons_ratio)
    p0 = hertz.theory(_hertz(p, force))["p0_theory"]
    return {"onset_force": force, "a_onset": a, "p0_onset": p0, "yield_stress": p0 / ratio,
            "p0_over_Y": ratio, "depth_over_a": depth, "e_star": e_star}


def check_loading(p, positive: tuple[str, ...] = ("onset_half_width", "overload", "radius")
                  ) -> None:
    """Raise :class:`~vfem.errors.InputError` unless the parameters ``positive`` are finite and
    positive and the onset and the overload make a schedule (:func:`load_factors`): the checks
    this example and :mod:`.block_indentation` share."""
    for name in positive:
        value = getattr(p, name)
        if isinstance(value, bool) or not (isinstance(value, (int, float))
                                           and 0 < value < math.inf):
            raise InputError(f"{name} must be a finite number > 0, got {value!r}")
    if p.overload <= LOADING[-3]:
        raise InputError(f"overload must exceed {LOADING[-3]} (the steps around the onset "
                         f"reach {LOADING[-3]} of its force), got {p.overload!r}")
    if p.overload > MAX_OVERLOAD:
        raise InputError(f"overload must be at most {MAX_OVERLOAD:g} (the loading steps are half "
                         f"the onset force apart up to it), got {p.overload!r}")
    if getattr(p, "onset_half_width", 0.0) > 0.05:  # (the plane examples')
        raise InputError("onset_half_width must be at most 0.05 (Hertz's half-space holds to "
                         f"about a / 2R), got {p.onset_half_width!r}")
    if isinstance(p.hardening_modulus, bool) or not (
            isinstance(p.hardening_modulus, (int, float)) and 0 <= p.hardening_modulus < math.inf):
        raise InputError(f"hardening_modulus must be a finite number >= 0, got "
                         f"{p.hardening_modulus!r}")


def load_factors(overload: float) -> tuple[float, ...]:
    """The steps' load factors for a peak of ``overload`` onset forces over load factors 0 to
    1 and back over 1 to 2 (:data:`LOADING`, :data:`UNLOADING`)."""
    loading = [s for s in LOADING if s < overload] + [
        float(s) for s in np.arange(1.5, overload - 1e-9, 0.5)]
    return tuple(s / overload for s in loading) + (1.0,) + tuple(
        2.0 - s / overload for s in UNLOADING)


def force_at(step, overload: float) -> float:
    """The platen's force per onset force at a step's load factor (up to the peak over 0 to
    1, down over 1 to 2)."""
    lf = step.load_factor
    return overload * (lf if lf <= 1.0 else 2.0 - lf)


def first_yielded(nl, displacement: np.ndarray, finite: bool = False
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The quadrature points' positions (dim, ne, nq) of a Newton body ``nl``
    (:class:`vfem.nonlinear.NonlinearBody`) and which of them the ``displacement`` (its
    points', (n, dim)) takes past yield from the virgin state: the return map of its strain
    as the body's law reads it (the small strain, or with ``finite`` the Green-Lagrange
    one)."""
    x = nl.basis0.mapping.F(nl.basis0.X)
    g = nl.basis0.interpolate(np.ravel(displacement)).grad
    strain = 0.5 * (g + np.swapaxes(g, 0, 1))
    if finite:
        strain = strain + 0.5 * np.einsum("ki...,kj...->ij...", g, g)
    state = nl.material.response(strain, nl.material.initial_state(x.shape[0],
                                                                    x.shape[1:])).state
    return x, state["equivalent_plastic_strain"] > 0


def validate(p: IndentationParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    check_loading(p)
    hertz.check_resolution("facets_per_half_width", p.facets_per_half_width, "half-width",
                           p.refinement)
    build(p).validate()


def config(p: IndentationParameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/indentation.toml`` holds for the defaults)."""
    p = p or IndentationParameters()
    try:
        th = theory(p)
    except (ValueError, ArithmeticError, ZeroDivisionError):
        th = {"onset_force": 1.0, "yield_stress": 1.0}  # validate() names what is wrong
    peak = p.overload * th["onset_force"]
    base = hertz.config(_hertz(p, peak))
    cylinder = next(b for b in base.bodies if b.name == "cylinder")
    flat = next(b for b in base.bodies if b.name == "flat")
    # the platen's force: up to the peak over load factors 0 to 1, down over 1 to 2
    curve = ((0.0, 0.0), (1.0, 1.0), (2.0, 0.0))
    cylinder = dataclasses.replace(cylinder, platen=Platen("top", "y", -peak, curve),
                                   material=J2Plastic(p.cylinder_youngs_modulus,
                                                      p.cylinder_poissons_ratio,
                                                      th["yield_stress"],
                                                      hardening_modulus=p.hardening_modulus))
    return ModelConfig("indentation", (cylinder, flat), base.contact,
                       Steps(load_factors=load_factors(p.overload)))


def build(p: IndentationParameters | None = None) -> Model:
    return config(p).build()


def loop_and_onset(result: AnalysisResult, overload: float, th: dict, plastic: str,
                   indenter: str = "cylinder", axis: int = 1) -> tuple[dict, object]:
    """What this example, :mod:`.block_indentation` and :mod:`.sphere_indentation` read alike
    from a run: the theory ``th``, the platen's force per onset force, the contact force on
    the ``indenter`` (its component ``axis``, the platen's) and the platen's travel at each
    step, the points of body ``plastic`` yielded, the peak forces, the first step with a
    yielded point and the forces either side of the onset; and that first step (None where
    none yielded)."""
    steps = result.steps
    first = next((s for s in steps if s.yielded.get(plastic, 0) > 0), None)
    out = dict(th)
    out["force_over_onset"] = [force_at(s, overload) for s in steps]
    out["contact_force"] = [float(s.bodies[indenter].contact_force[:, axis].sum())
                            for s in steps]
    out["travel"] = [float(-s.platen_displacement) for s in steps]
    out["yielded_points"] = [int(s.yielded.get(plastic, 0)) for s in steps]
    out["peak_contact_force"] = max(out["contact_force"])
    out["peak_applied_force"] = overload * th["onset_force"]
    if first is not None:
        k = steps.index(first)
        out["first_yield_step"] = first.step
        out["first_yield_force"] = force_at(first, overload)
        out["last_elastic_force"] = force_at(steps[k - 1], overload) if k else 0.0
    return out, first


def evaluate(result: AnalysisResult, p: IndentationParameters) -> dict:
    """The onset, the loop and the dent from a run."""
    th = theory(p)
    out, first = loop_and_onset(result, p.overload, th, "cylinder")
    steps = result.steps
    cylinder = next(b for b in result.model.bodies if b.name == "cylinder")
    X = cylinder.mesh.p
    tip = int(np.argmin(np.hypot(X[0], X[1] - X[1].min())))  # the lowest point, on the axis
    # the residual approach: the platen's travel less the lowest point's, lifted off (the
    # elastic approach of a hundredth of the onset force is left in it: the first step's
    # travel is about half of it)
    out["residual_approach"] = float(steps[-1].bodies["cylinder"].displacement[tip, 1]
                                     - steps[-1].platen_displacement)
    if first is None:
        return out
    # the points that yield first: those the step's displacement takes past yield from the
    # virgin state (the return map of the step's strain, as the cylinder's law reads it)
    x, yielded = first_yielded(cylinder.mechanics.nonlinear,
                               first.bodies["cylinder"].displacement)
    a_now = th["a_onset"] * math.sqrt(out["first_yield_force"])
    out["first_yield_depth_over_a"] = float(
        (x[1][yielded] - X[1].min()).mean() / a_now) if yielded.any() else float("nan")
    out["element_over_a"] = (th["a_onset"] * math.sqrt(p.overload) / (
        p.facets_per_half_width * 2**p.refinement) / a_now)
    return out


def summarize(result: AnalysisResult, p: IndentationParameters) -> dict:
    """The ``summary.json`` dictionary of a run."""
    return summary_of("indentation", result, p, evaluate)


def summary_of(example: str, result: AnalysisResult, p, evaluate,
               stresses: str = "McEwen's stresses in plane strain") -> dict:
    """The ``summary.json`` dictionary of a run of ``example`` (this one,
    :mod:`.block_indentation` or :mod:`.sphere_indentation`): the steps with the platen's
    displacement, and where the run converged ``evaluate(result, p)`` under the example's name
    and its verification (:func:`verification` with ``stresses``)."""
    from vfem.io.results import step_record

    summary = {
        "example": example,
        "converged": result.converged,
        "message": result.message,
        "steps": [{**step_record(s), "platen_displacement": s.platen_displacement}
                  for s in result.steps],
        "dofs": int(sum(s.body.ndofs for s in result.surfaces)),
        "parameters": dataclasses.asdict(p),
        "timings": result.timings,
        "linear_solver": result.backend,
    }
    if result.converged:
        summary[example] = m = evaluate(result, p)
        summary["verification"] = verification(m, result.model.contact, stresses)
    return summary


def verification(m: dict, settings, stresses: str = "McEwen's stresses in plane strain"
                 ) -> list[dict]:
    """The indentation's checks (``summary.json``'s ``verification``): the load at first yield
    against Hertz's onset, the depth of the first yielded points against the onset's depth
    under Hertz's pressure (``stresses``: whose), the platen's force at the peak."""
    from vfem.io.verification import check, platen

    source = (f"Hertz, {stresses}: p0 = {m['p0_over_Y']:.3f} Y at "
              f"{m['depth_over_a']:.3f} a")
    records = []
    if "first_yield_force" in m:
        records.append(check(
            "force at first yield / Hertz's onset", m["first_yield_force"], 1.0, source, 0.02,
            "issue 41's bound (the steps bracket it: no yield at "
            f"{m['last_elastic_force']:.2f}, yield at {m['first_yield_force']:.2f})"))
        records.append(check(
            "depth of the first yielded points / a", m["first_yield_depth_over_a"],
            m["depth_over_a"], source, m["element_over_a"],
            "one element under the contact (the points' mean depth)", measure="absolute"))
    records.append(platen("contact force at the peak", m["peak_contact_force"],
                          m["peak_applied_force"], settings))
    return records


def run(p: IndentationParameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD per step, ``summary.json`` and the figures to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), figures, on_step, resume)


def figures(folder) -> list[Path]:
    """``loop.png``: the contact force against the platen's travel, loading and unloading (from
    ``summary.json``'s ``indentation``); ``von_mises.png`` at the peak, with the plastic zone."""
    from vfem.io import plots, replot

    s = folder.summary
    m = s.get("indentation")
    if not folder.has_steps or m is None:
        return []
    out = folder.directory
    travel = np.array(m["travel"])
    force = np.array(m["contact_force"]) / m["onset_force"]
    plots.history(out / "loop.png", travel, {"contact force / onset force": force},
                  "platen travel (approach)", "force / onset force",
                  f"indentation: loaded to {s['parameters']['overload']:g} times the onset force "
                  f"and lifted off; residual approach {m['residual_approach']:.3g}")
    peak = int(np.argmax(force))
    a = m["a_onset"] * math.sqrt(s["parameters"]["overload"])
    step = folder.steps[min(peak, len(folder.steps) - 1)]
    cyl = next(b for b in step.bodies if b.name == "cylinder")
    tip = int(np.argmin(np.hypot(*cyl.points.T)))  # the first point of contact
    y0 = float(cyl.points[tip, 1] + cyl.displacement[tip, 1])
    vm = replot.von_mises(folder, step, "von_mises.png",
                          "indentation: von Mises stress at the peak force",
                          window=(0.0, 3.0 * a, y0 - 0.5 * a, y0 + 2.5 * a))
    return [out / "loop.png", vm]


def report(s: dict) -> list[str]:
    """What the CLI prints after the run."""
    m = s.get("indentation")
    if m is None:
        return []
    return report_lines(m, "indentation: onset force", closing=(
        f"  peak force {m['peak_contact_force']:.4g}, {max(m['yielded_points'])} points "
        f"yielded; lifted off to a hundredth of the onset force: residual approach "
        f"{m['residual_approach']:.4g}"))


def loop_figure(folder, example: str, label: str):
    """``loop.png`` of a plastic indentation's results folder (this example's,
    :mod:`.block_indentation`'s, :mod:`.sphere_indentation`'s): the contact force per onset
    force against the platen's travel, loading and unloading. Returns the peak step's frames
    and the peak's contact radius, or None where the run left no steps or no summary of it."""
    from vfem.io import plots

    s = folder.summary
    m = s.get(example)
    if not folder.has_steps or m is None:
        return None
    travel = np.array(m["travel"])
    force = np.array(m["contact_force"]) / m["onset_force"]
    plots.history(folder.directory / "loop.png", travel, {"contact force / onset force": force},
                  "platen travel (approach)", "force / onset force",
                  f"{label}: loaded to {s['parameters']['overload']:g} times the "
                  f"onset force and lifted off; dent {m['dent']:.3g}")
    return folder.steps[min(int(np.argmax(force)), len(folder.steps) - 1)], m["a_peak"]


def report_lines(m: dict, label: str, reference: str = "Hertz", closing: str | None = None
                 ) -> list[str]:
    """What the CLI prints after a plastic indentation (``label`` its first words,
    ``reference`` whose onset depth; ``closing`` the last line, by default the peak and the
    dent into a block or a flat)."""
    lines = [f"  {label} {m['onset_force']:.4g} (Hertz: a = {m['a_onset']:.4g}, "
             f"p0 = {m['p0_onset']:.4g}, Y = {m['yield_stress']:.4g})"]
    if "first_yield_force" in m:
        lines.append(f"  first yield at {m['first_yield_force']:.2f} of it (none at "
                     f"{m['last_elastic_force']:.2f}), {m['first_yield_depth_over_a']:.3f} a deep "
                     f"({reference}: {m['depth_over_a']:.3f} a)")
    lines.append(closing or (
        f"  peak force {m['peak_contact_force']:.4g}, {max(m['yielded_points'])} points "
        f"yielded; depression on the axis {m['depression_at_peak']:.4g} at the peak, "
        f"dent {m['dent']:.4g} lifted off to a hundredth of the onset force"))
    return lines
