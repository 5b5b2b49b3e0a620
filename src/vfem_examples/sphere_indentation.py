"""A sphere pressed into an elasto-plastic flat past first yield and lifted off (issue 41): where
and when the flat yields under Hertz's sphere, the force-indentation loop and the dent it keeps
(the 3D counterpart of the block_indentation example).

The sphere example's model (:mod:`vfem_examples.sphere`: a quarter of a sphere-ended cylinder of
radius R on a block R wide and deep, symmetry planes x = 0 and y = 0, both meshes graded to the
contact: elements a/``facets_per_radius`` over 1.2 a, the flat's ``flat_size_ratio`` times
larger), the sphere elastic and the flat of J2 material (:class:`vfem.materials.J2Plastic`,
elastic-perfectly plastic unless ``hardening_modulus`` is set), both steel-like.

Under Hertz's pressure the von Mises stress peaks on the axis at 0.481 a with 0.620 p0 for
nu = 0.3 (Huber's stresses, Johnson, *Contact Mechanics*, 1985, eq. 3.45: :func:`onset`): the
first point yields when p0 = 1.613 Y. The yield stress is set so that this happens at the force
whose Hertz radius is ``onset_contact_radius`` R (the *onset force*; the mesh's a is that
force's); the platen's force rises to it in steps of 1 % of it near it, on to ``overload`` times
it (whose contact radius the fine zone still covers: overload^(1/3) < 1.2), and falls back to
a hundredth of it. Why a = 0.05 R: Hertz's half-space holds for a << R; the sphere's onset
measured on this mesh (``benchmarks/sphere_onset.py``, the flat's elements 0.217 a, its state
at their Gauss points: :func:`vfem.nonlinear.gauss_rule`) came at 0.99-1.00 of Hertz's with
a = 0.1 R and 1.00-1.01 with 0.05 R.

**Verification** (``summary.json``, the screen): the first step with a yielded point against
Hertz's onset (within 2 %, issue 41's bound; the steps 1 % apart bracket it); the mean depth of
the points that yield first against 0.481 a (within one of the flat's elements); the platen's
force met at the peak. Reported with no reference: the loop (the contact force against the
platen's travel, ``loop.png``), the dent (the flat's top on the axis, lifted off to a hundredth
of the onset force, whose elastic depression is left in it), how many points yielded, and the
von Mises stress in the plane y = 0 at the peak (``von_mises.png``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import Platen
from vfem.config import ModelConfig, Steps
from vfem.errors import InputError
from vfem.materials import J2Plastic
from vfem.solver import AnalysisResult, Model

from . import sphere
from .hertz import check_resolution
from .indentation import (
    check_loading,
    first_yielded,
    load_factors,
    loop_and_onset,
    loop_figure,
    report_lines,
    summary_of,
)


@dataclass(frozen=True)
class SphereIndentationParameters:
    """Parameters of the sphere-indentation example."""

    radius: float = 10.0
    sphere_youngs_modulus: float = 200e3
    sphere_poissons_ratio: float = 0.3
    flat_youngs_modulus: float = 200e3
    flat_poissons_ratio: float = 0.3
    hardening_modulus: float = 0.0  # linear isotropic hardening (0: perfectly plastic)
    onset_contact_radius: float = 0.05  # Hertz's contact radius at first yield, per radius
    overload: float = 1.5  # the peak force, per onset force (> 1.03, at most 1.7)
    facets_per_radius: int = 6  # the sphere's elements over the onset's contact radius
    flat_size_ratio: float = 1.3  # the flat's elements at the contact, per the sphere's


Parameters = SphereIndentationParameters

#: the largest overload whose contact radius (overload^(1/3) a) the meshes' fine zone covers
MAX_OVERLOAD = 1.7


def onset(nu: float) -> tuple[float, float]:
    """(p0 / Y at first yield, its depth per a) under Hertz's sphere: von Mises on the axis
    (Johnson 1985, eq. 3.45: sigma_r = sigma_theta = p0 (-(1 + nu)(1 - (z/a) arctan(a/z)) +
    (1/2)(1 + z^2/a^2)^-1), sigma_z = -p0 (1 + z^2/a^2)^-1), its largest value and where
    (sampled every 1e-5 a: the depth to that, the ratio to round-off of its flat peak)."""
    z = np.linspace(1e-4, 3.0, 300001)
    sr = -(1 + nu) * (1 - z * np.arctan(1 / z)) + 0.5 / (1 + z * z)
    sz = -1 / (1 + z * z)
    vm = np.abs(sz - sr)
    k = int(vm.argmax())
    return 1.0 / float(vm[k]), float(z[k])


def _sphere(p: SphereIndentationParameters, force: float) -> sphere.SphereParameters:
    """The sphere example's parameters for a whole-sphere ``force`` (the mesh's a is its)."""
    return sphere.SphereParameters(
        radius=p.radius, sphere_youngs_modulus=p.sphere_youngs_modulus,
        sphere_poissons_ratio=p.sphere_poissons_ratio,
        flat_youngs_modulus=p.flat_youngs_modulus, flat_poissons_ratio=p.flat_poissons_ratio,
        force=force, facets_per_radius=p.facets_per_radius, flat_size_ratio=p.flat_size_ratio)


def theory(p: SphereIndentationParameters) -> dict[str, float]:
    """The onset force (on the quarter model: a quarter of the sphere's P = 4 E* a^3 / 3R),
    its contact radius and p0, the yield stress, and the onset's ratio p0 / Y and depth per a
    (:func:`onset`, the flat's nu)."""
    e_star = sphere.theory(_sphere(p, 1.0))["e_star"]
    a = p.onset_contact_radius * p.radius
    whole = 4.0 * e_star * a ** 3 / (3.0 * p.radius)
    ratio, depth = onset(p.flat_poissons_ratio)
    p0 = sphere.theory(_sphere(p, whole))["p0_theory"]
    return {"onset_force": whole / 4.0, "a_onset": a, "p0_onset": p0,
            "yield_stress": p0 / ratio, "p0_over_Y": ratio, "depth_over_a": depth,
            "e_star": e_star, "a_peak": a * p.overload ** (1.0 / 3.0)}


def validate(p: SphereIndentationParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    check_loading(p, ("onset_contact_radius", "overload", "radius", "flat_size_ratio"))
    if p.overload > MAX_OVERLOAD:
        raise InputError(f"overload must be at most {MAX_OVERLOAD:g} (the peak's contact radius, "
                         f"overload^(1/3) a, within the meshes' fine zone of 1.2 a), got "
                         f"{p.overload!r}")
    if p.onset_contact_radius > 0.1:
        raise InputError("onset_contact_radius must be at most 0.1 (Hertz's half-space holds "
                         f"for a << R), got {p.onset_contact_radius!r}")
    check_resolution("facets_per_radius", p.facets_per_radius, "radius", 0)
    build(p).validate()


def config(p: SphereIndentationParameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/sphere_indentation.toml`` holds for the defaults)."""
    p = p or SphereIndentationParameters()
    try:
        th = theory(p)
    except (ValueError, ArithmeticError, ZeroDivisionError, TypeError):
        th = {"onset_force": 1.0, "yield_stress": 1.0}  # validate() names what is wrong
    base = sphere.config(_sphere(p, 4.0 * th["onset_force"]))
    peak = p.overload * th["onset_force"]
    # the platen's force on the quarter: up to the peak over load factors 0 to 1, down over 1 to 2
    curve = ((0.0, 0.0), (1.0, 1.0), (2.0, 0.0))
    bodies = []
    for b in base.bodies:
        if b.name == "sphere":
            b = dataclasses.replace(b, platen=Platen("top", "z", -peak, curve))
        else:
            b = dataclasses.replace(b, material=J2Plastic(
                p.flat_youngs_modulus, p.flat_poissons_ratio, th["yield_stress"],
                hardening_modulus=p.hardening_modulus))
        bodies.append(b)
    return ModelConfig("sphere_indentation", tuple(bodies), base.contact,
                       Steps(load_factors=load_factors(p.overload)))


def build(p: SphereIndentationParameters | None = None) -> Model:
    return config(p).build()


def evaluate(result: AnalysisResult, p: SphereIndentationParameters) -> dict:
    """The onset, the loop and the dent from a run."""
    th = theory(p)
    out, first = loop_and_onset(result, p.overload, th, "flat", indenter="sphere", axis=2)
    steps = result.steps
    flat = next(b for b in result.model.bodies if b.name == "flat")
    X = flat.mesh.p
    axis = int(np.argmin(np.hypot(X[0], X[1]) + np.abs(X[2])))  # the top's point on the axis
    out["dent"] = float(-steps[-1].bodies["flat"].displacement[axis, 2])
    out["depression_at_peak"] = float(max(-s.bodies["flat"].displacement[axis, 2]
                                          for s in steps))
    if first is None:
        return out
    # the points that yield first: those the step's displacement takes past yield from the
    # virgin state (the return map of the step's strain, as the flat's law reads it)
    x, yielded = first_yielded(flat.mechanics.nonlinear, first.bodies["flat"].displacement)
    a_now = th["a_onset"] * out["first_yield_force"] ** (1.0 / 3.0)
    out["first_yield_depth_over_a"] = float(
        (-x[2][yielded]).mean() / a_now) if yielded.any() else float("nan")
    out["element_over_a"] = p.flat_size_ratio * th["a_onset"] / p.facets_per_radius / a_now
    return out


def summarize(result: AnalysisResult, p: SphereIndentationParameters) -> dict:
    """The ``summary.json`` dictionary of a run."""
    return summary_of("sphere_indentation", result, p, evaluate, "Huber's stresses on the axis")


def run(p: SphereIndentationParameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD per step, ``summary.json`` and the figures to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), figures, on_step, resume)


def figures(folder) -> list[Path]:
    """``loop.png``: the contact force against the platen's travel, loading and unloading;
    ``von_mises.png``: the symmetry plane y = 0 at the peak, the flat's plastic zone under the
    contact."""
    from vfem.io import plots
    from vfem.io.replot import plane_section

    drawn = loop_figure(folder, "sphere_indentation", "sphere indentation")
    if drawn is None:
        return []
    step, a = drawn
    bodies = []
    for b in step.bodies:
        x, faces, u, vm = plane_section(b, 1, 0.0, "von_mises")
        bodies.append((b.name, x, faces, u, vm))
    out = folder.directory
    plots.von_mises(out / "von_mises.png", bodies,
                    "sphere indentation: von Mises in the plane y = 0 at the peak",
                    window=(0.0, 3.0 * a, -3.0 * a, 0.5 * a))
    return [out / "loop.png", out / "von_mises.png"]


def report(s: dict) -> list[str]:
    """What the CLI prints after the run."""
    m = s.get("sphere_indentation")
    return [] if m is None else report_lines(
        m, "sphere indentation: onset force on the quarter", "Huber")
