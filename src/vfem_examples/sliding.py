"""Large sliding: a rounded punch pressed into a long block, then slid along it (ironing).

The method's claim (thesis abstract and §4.5) is that virtual nodes allow "any amount of sliding of
the touching surfaces without requiring rediscretization". This example slides a punch 40 of the
block's facet lengths along it at constant indentation, with both bodies under large
displacements (:mod:`vfem.contact.formulations.large`), and records the reactions.

Plane strain, our dimensions (the thesis has no such example):

* **block**: 6 x 1 (x from -3 to 3), 120 x 16 quadrilaterals (facets 0.05 long on its top),
  neo-Hookean with E = 1000, nu = 0.3, its base fixed;
* **punch**: a circular face of radius 1 (lowest point at x = -1 on the block's top), 1.2 wide
  and 0.6 high, 48 x 8 quadrilaterals, neo-Hookean ten times stiffer than the block; its top is
  moved down by ``depth`` (0.05) over the first ``press_steps`` steps (load factor 0 to 1), then
  along x by ``slide`` (2.0, 40 block facets) over ``slide_steps`` steps (load factor 1 to 2) with
  the depth held: non-proportional loading through the prescribed displacements' ``amplitude``.

Frictionless sliding over an elastic block stores no energy in the motion, so once the punch is
away from the block's ends the normal reaction is constant and the tangential one nearly zero:
any jump when a node of one surface passes a vertex of the other is a defect of the
discretisation. With ``friction = mu`` (:mod:`vfem.contact.formulations.large_friction`) every node
in contact slips in steady sliding and the tangential tractions are mu times the normal ones; the
reactions' ratio is mu less the tilt of the normal tractions' resultant over the curved face
(:func:`_friction_reading`).

The checks (``evaluate``): every step converged, the normal reaction's largest deviation from its
mean over the steady part of the slide, the tangential reaction, and the
penetration of every candidate node of either body into the other, measured on the deformed
surfaces.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import PrescribedDisplacement, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.io.runner import friction_line, run_headline
from vfem.materials import LinearElastic
from vfem.result_types import largest_penetrations
from vfem.solver import AnalysisResult, Model


@dataclass(frozen=True)
class Parameters:
    """Parameters of the sliding example (our dimensions; see the module docstring)."""

    block_length: float = 6.0
    block_height: float = 1.0
    block_columns: int = 120
    block_rows: int = 16
    block_youngs_modulus: float = 1000.0
    punch_radius: float = 1.0
    punch_width: float = 1.2
    punch_height: float = 0.6
    punch_columns: int = 48
    punch_rows: int = 8
    stiffness_ratio: float = 10.0  # punch modulus / block modulus
    poissons_ratio: float = 0.3
    law: str = "neo-hookean"
    kinematics: str = "total"
    start: float = -1.0  # x of the punch's lowest point before sliding
    depth: float = 0.05
    slide: float = 2.0
    press_steps: int = 4
    slide_steps: int = 20
    steady_after: float = 0.1  # the first part of the slide (fraction) is not steady
    friction: float = 0.0  # Coulomb's mu between punch and block (0: frictionless)


#: ``vfem verify --slow``: every mesh twice as fine (240 x 32 block, 96 x 16 punch)
VERIFY_SLOW = ("block_columns=240", "block_rows=32", "punch_columns=96", "punch_rows=16")

#: the block's ends: the normal reaction varies smoothly over the steady slide by 0.028 % on the
#: 6-long block frictionless and by 0.12 % with mu = 0.3 (the friction pushes the block's top
#: towards its far end), by 2e-6 and 6e-6 on a block 12 long (``--set block_length=12 --set
#: block_columns=240``; docs/examples.md, Sliding): a long block's constant reaction is the
#: reference, and :func:`ends` is how far the default's ends move it, linear in mu between those
ENDS = 3e-4
ENDS_PER_MU = 3e-3


def ends(p: Parameters) -> float:
    """How far the block's ends move the normal reaction over the steady slide (a fraction of
    it): :data:`ENDS` plus :data:`ENDS_PER_MU` times mu."""
    return ENDS + ENDS_PER_MU * p.friction


def load_factors(p: Parameters) -> tuple[float, ...]:
    """0 to 1: pressing in; 1 to 2: sliding."""
    press = tuple((k + 1) / p.press_steps for k in range(p.press_steps))
    return press + tuple(1.0 + (k + 1) / p.slide_steps for k in range(p.slide_steps))


def config(p: Parameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/sliding.toml`` holds for the defaults)."""
    p = p or Parameters()
    block = BodyConfig(
        "block",
        MeshSpec(shape="rectangle", parameters=as_parameters(
            x0=-0.5 * p.block_length, y0=0.0, width=p.block_length, height=p.block_height,
            nx=p.block_columns, ny=p.block_rows)),
        LinearElastic(p.block_youngs_modulus, p.poissons_ratio),
        supports=(Support("bottom", ("x", "y")),), contact_boundaries=("top",),
        kinematics=p.kinematics, law=p.law)
    punch = BodyConfig(
        "punch",
        MeshSpec(shape="rounded_punch", parameters=as_parameters(
            x0=p.start, y0=p.block_height, width=p.punch_width, height=p.punch_height,
            radius=p.punch_radius, nx=p.punch_columns, ny=p.punch_rows)),
        LinearElastic(p.block_youngs_modulus * p.stiffness_ratio, p.poissons_ratio),
        prescribed=(PrescribedDisplacement("top", "y", -p.depth, ((0.0, 0.0), (1.0, 1.0))),
                    PrescribedDisplacement("top", "x", p.slide, ((1.0, 0.0), (2.0, 1.0)))),
        contact_boundaries=("face",), kinematics=p.kinematics, law=p.law)
    return ModelConfig("sliding", (block, punch), ContactSettings(friction=p.friction),
                       Steps(load_factors=load_factors(p)))


def build(p: Parameters | None = None) -> Model:
    return config(p).build()


def validate(p: Parameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    if p.press_steps < 1 or p.slide_steps < 1:
        raise InputError("sliding: press_steps and slide_steps must be at least 1")
    half = 0.5 * p.block_length
    if not -half + p.punch_width < p.start < p.start + p.slide < half - p.punch_width:
        raise InputError("sliding: the punch must stay over the block, a punch width from "
                         "its ends (start, slide, block_length, punch_width)")
    if p.kinematics == "small":
        raise InputError("sliding: needs large kinematics ('total' or 'updated')")
    if not p.friction >= 0:
        raise InputError(f"sliding: friction (mu) must be >= 0, got {p.friction!r}")
    build(p).validate()


def reactions(result: AnalysisResult) -> dict[str, list[float]]:
    """Per converged step: the slide so far and the force the punch's top support applies to
    it (the punch's reaction), along x (tangential) and y (normal, negative: pressing down)."""
    punch = next(b for b in result.model.bodies if b.name == "punch")
    rows: dict[str, list[float]] = {"load_factor": [], "slide": [], "normal": [],
                                    "tangential": []}
    top = punch.boundary_points("top")
    for step in result.steps:
        r = step.bodies["punch"]
        rows["load_factor"].append(step.load_factor)
        rows["slide"].append(float(np.mean(r.displacement[top, 0])))
        rows["normal"].append(punch.reaction_of(r, "top", "y"))
        rows["tangential"].append(punch.reaction_of(r, "top", "x"))
    return rows


def evaluate(result: AnalysisResult, p: Parameters) -> dict:
    """The acceptance numbers of a run (see the module docstring)."""
    rows = reactions(result)
    lf = np.asarray(rows["load_factor"])
    normal = -np.asarray(rows["normal"])  # the force pressing the punch down, > 0
    tangential = np.asarray(rows["tangential"])
    steady = lf >= 1.0 + p.steady_after - 1e-12
    out: dict = {"slide": float(rows["slide"][-1]) if rows["slide"] else 0.0,
                 "block_facet_length": p.block_length / p.block_columns}
    out["slide_in_facets"] = out["slide"] / out["block_facet_length"]
    if steady.any():
        mean = float(normal[steady].mean())
        out["steady_steps"] = int(steady.sum())
        out["normal_reaction_mean"] = mean
        out["normal_reaction_max_deviation"] = float(np.abs(normal[steady] / mean - 1).max())
        out["tangential_reaction_max"] = float(np.abs(tangential[steady]).max())
        if p.friction > 0:
            out["friction"] = _friction_reading(result, p, steady, normal, tangential)
    if result.steps:
        last = result.steps[-1].bodies
        out["contact_force_block"] = last["block"].contact_force.sum(axis=0).tolist()
        out["contact_force_punch"] = last["punch"].contact_force.sum(axis=0).tolist()
    worst = 0.0
    for step in result.steps:
        both = largest_penetrations(result, step)
        worst = max(worst, max(v["penetration"] for v in both.values()))
    out["largest_penetration_any_node"] = worst
    out["largest_residual_penetration"] = max(s.history[-1].max_penetration
                                              for s in result.steps) if result.steps else 0.0
    out["penetration_tolerance"] = result.penetration_tolerance
    out["reactions"] = rows
    return out


def _friction_reading(result: AnalysisResult, p: Parameters, steady: np.ndarray,
                      normal: np.ndarray, tangential: np.ndarray) -> dict:
    """Steady sliding with friction: the punch's tangential over normal reaction, and the
    block's contact force split into the tangential tractions' part (``friction_force``) and
    the normal tractions' part.

    Where every node in contact slips, the first is mu times the second in magnitude, whatever
    the pressure (one traction field, s = mu q at each node). The reactions' ratio is mu only
    if the normal part is normal to the slide: over the punch's curved face a pressure that is
    not symmetric about its lowest point tilts it, by ``normal_part_tilt`` (radians, positive
    when it leans against the slide), and the reactions' ratio is then tan(atan mu - tilt).
    """
    ratio = np.abs(tangential[steady]) / normal[steady]
    last = result.steps[-1].bodies["block"]
    total = last.contact_force.sum(axis=0)
    friction = last.friction_force.sum(axis=0)
    normal_part = total - friction
    status = last.friction_status
    return {"mu": p.friction,
            "reaction_ratio_mean": float(ratio.mean()),
            "reaction_ratio_min": float(ratio.min()),
            "reaction_ratio_max": float(ratio.max()),
            "friction_over_normal_part": float(np.linalg.norm(friction)
                                               / np.linalg.norm(normal_part)),
            "normal_part_tilt": float(np.arctan2(-normal_part[0], -normal_part[1])
                                      * np.sign(p.slide)),
            "slipping_nodes": int((status == 2).sum()),
            "sticking_nodes": int((status == 1).sum())}


def summarize(result: AnalysisResult, p: Parameters) -> dict:
    from vfem.io.results import example_summary

    summary = example_summary("sliding", result, p)
    if result.steps:
        summary["sliding"] = evaluate(result, p)
        if result.converged and result.steps[-1].load_factor == 2.0 \
                and "normal_reaction_mean" in summary["sliding"]:
            summary["verification"] = verification(summary["sliding"], p)
    return summary


def verification(e: dict, p: Parameters) -> list[dict]:
    """The sliding run's checks (``summary.json``'s ``verification``;
    :mod:`vfem.io.verification`).

    * The normal reaction over the steady slide against its mean: constant on a long block
      (frictionless sliding over an elastic body stores no energy in the motion). As the block's
      nodes pass the punch's vertices the depth they see changes by up to the punch facets'
      chord sag h_p^2 / (8 R), and the force with it by at most 3/2 times that over the depth
      (a force growing as depth^(3/2) at most, a Winkler layer's; measured 1.27 from the press
      steps); the block's ends add :func:`ends`, twice.
    * The contact forces on the two bodies, equal and opposite: the length of their sum
      against 0, scaled by the larger (invariant (a), :func:`vfem.io.verification.balance`).
    * The largest penetration of any node of either body into the other's deformed facets:
      the punch's vertices (they carry equilibrium, not compatibility) lie below the block's
      straight facets by up to the arc's sag over one block facet, h_b^2 / (8 R) (docs/method.md
      §10), with 50 % for the bodies' deformation.
    * With friction, every node in contact slipping: the tangential tractions' force over the
      normal tractions' is Coulomb's mu, exactly (the tangent at each node is its normal
      turned by 90 degrees, so the two resultants have the magnitudes' ratio of the tractions).
    """
    from vfem.io.verification import balance, check

    h_punch = p.punch_width / p.punch_columns  # the columns are equally spaced in x
    h_block = p.block_length / p.block_columns
    jump = 1.5 * h_punch**2 / (8 * p.punch_radius) / p.depth
    sag = h_block**2 / (8 * p.punch_radius)
    block, punch = np.asarray(e["contact_force_block"]), np.asarray(e["contact_force_punch"])
    records = [
        check("normal reaction, largest deviation from its mean",
              e["normal_reaction_max_deviation"], 0.0, "constant on a long block",
              jump + 2 * ends(p),
              f"discretisation: the punch's faceting moves the depth by its chord sag "
              f"h_p^2/8R, the force by 3/2 of that over the depth ({jump:.2%}), plus twice the "
              f"block's ends' {ends(p):.2%} (docs/examples.md, Sliding)", measure="absolute"),
        balance("contact forces' sum, |punch + block|", float(np.linalg.norm(block + punch)),
                0.0, "equal and opposite",
                scale=max(float(np.linalg.norm(block)), float(np.linalg.norm(punch)))),
        check("penetration of any node, deformed surfaces", e["largest_penetration_any_node"],
              0.0, "no interpenetration but the faceting's", 1.5 * sag,
              f"faceting: the arc's sag over one block facet, h_b^2/8R = {sag:.2e}, with 50 % "
              "for the deformation (docs/method.md §10)", measure="absolute"),
    ]
    f = e.get("friction")
    if f:
        records.append(check(
            "tangential / normal tractions' force, slid", f["friction_over_normal_part"], f["mu"],
            "the Coulomb ratio mu when sliding", 1e-9,
            "round-off: each slipping node's tangential traction is mu times its normal one, "
            "along its normal turned 90 degrees, a tie each linear solve meets exactly (1e-9: "
            "the round-off of the Newton steps, with margin)"))
    return records


def run(p: Parameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example: VTU/PVD per step, ``summary.json`` and the figures in ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p),
                       (lambda model, result, summary: _figure_data(model, result, summary, p))
                       if figures else None, on_step, resume)


def _figure_data(model: Model, result: AnalysisResult, summary: dict, p: Parameters) -> None:
    """What the figures need beyond the results files (``summary.json``'s ``figure_data``):
    the three moments drawn (pressed in, half way, slid: their VTU step) and a window that
    follows the punch."""
    if not result.steps:
        return
    picks = {"pressed in": next((s for s in result.steps if s.load_factor >= 1.0), None),
             "half way": next((s for s in result.steps if s.load_factor >= 1.5), None),
             "slid": result.steps[-1]}
    half = 0.5 * p.punch_width
    top = next(b for b in model.bodies if b.name == "punch").boundary_points("top")
    shown = []
    for (label, step), name in zip(picks.items(), ("pressed.png", "halfway.png", "slid.png")):
        if step is None:
            continue
        x = p.start + float(np.mean(step.bodies["punch"].displacement[top, 0]))
        shown.append({"label": label, "file": name, "step": step.step,
                      "window": [x - 2.5 * half, x + 2.5 * half, p.block_height - 0.6,
                                 p.block_height + 0.4]})
    summary["figure_data"] = {"moments": shown}


def figures(folder) -> list[Path]:
    """The figures of a sliding results folder (:class:`vfem.io.replot.Folder`), which the run
    draws and ``vfem plot`` redraws: ``reactions.png``, the punch's reactions against the
    slide (``summary.json``'s ``sliding.reactions``); the deformed bodies at three moments
    (``pressed.png``, ``halfway.png``, ``slid.png``); ``von_mises.png``, slid."""
    from vfem.io import plots, replot

    s = folder.summary
    if not folder.has_steps or "sliding" not in s or "figure_data" not in s:
        return []
    method = replot.contact_label(s)
    out = folder.directory
    rows = s["sliding"]["reactions"]
    slide = np.asarray(rows["slide"], dtype=float)
    sliding = np.asarray(rows["load_factor"]) >= 1.0
    panels = [(f"normal reaction, pressing down ({plots.LENGTH})",
               {"punch": (slide[sliding], -np.asarray(rows["normal"])[sliding])}, False),
              (f"tangential reaction ({plots.LENGTH})",
               {"punch": (slide[sliding], np.asarray(rows["tangential"])[sliding])}, False)]
    plots.history_panels(out / "reactions.png", panels,
                         f"slide: punch top displacement along x ({plots.LENGTH})",
                         f"Sliding: the punch's reactions at constant depth\n{method}")
    written = [out / "reactions.png"]
    moments = s["figure_data"]["moments"]
    for m in moments:
        step = folder.step(m["step"])
        frame = [(b.name, b.points, b.polygons, b.displacement) for b in step.bodies]
        plots.configurations(out / m["file"], [(m["label"], frame)],
                             f"Sliding: {m['label']} (load factor {step.load_factor:g})\n"
                             f"{method}", tuple(m["window"]), magnification=1.0)
        written.append(out / m["file"])
    if moments:
        last = moments[-1]
        step = folder.step(last["step"])
        written.append(replot.von_mises(
            folder, step, "von_mises.png", f"Sliding: von Mises stress, {last['label']} (load "
            f"factor {step.load_factor:g})\n{method}", tuple(last["window"])))
    return written


def report(s: dict) -> list[str]:
    steps = s["steps"]
    lines = [run_headline(s, "step(s)")]
    if "sliding" in s:
        e = s["sliding"]
        lines.append(f"  slid {e['slide']:.4g} ({e['slide_in_facets']:.1f} block facets) at "
                     "constant depth, no remeshing")
        if "normal_reaction_mean" in e:
            lines.append(f"  normal reaction {e['normal_reaction_mean']:.6g}, largest deviation "
                         f"over {e['steady_steps']} steady steps "
                         f"{100 * e['normal_reaction_max_deviation']:.3f} %; tangential "
                         f"reaction at most {e['tangential_reaction_max']:.3g}")
        if "friction" in e:
            f = e["friction"]
            lines.append(f"  friction mu = {f['mu']:g}: tangential / normal reaction "
                         f"{f['reaction_ratio_min']:.5f} to {f['reaction_ratio_max']:.5f} over "
                         f"the steady steps; slid, the tangential tractions' force is "
                         f"{f['friction_over_normal_part']:.5f} times the normal tractions', "
                         f"which lean {f['normal_part_tilt']:.4f} rad against the slide "
                         f"({f['slipping_nodes']} nodes slipping, {f['sticking_nodes']} "
                         "sticking)")
        if friction_line(s):  # with friction, whether or not the slide reached steady steps
            lines.append("  " + friction_line(s))
        residual = max((x["max_penetration"] for x in steps), default=0.0)
        lines.append(f"  residual penetration {residual:.2e} (tolerance "
                     f"{e['penetration_tolerance']:.1e}); any node of either body into the "
                     f"other's deformed facets: {e['largest_penetration_any_node']:.2e}, punch "
                     "vertices below the block's straight facets that cut across the curved "
                     "contact (faceting, not an iteration error: docs/examples.md, Sliding)")
    return lines
