"""Thesis §5.4: a larger block forced against a smaller fixed block — sharp corners in the contact.

The thesis gives no dimensions ("the model used is very crude"); these are ours. Plane strain,
half model about x = 0 (symmetry: u_x = 0), both blocks of the same material (E = 1000,
nu = 0.3):

* the **small block** 0 <= x <= 0.5, -0.5 <= y <= 0, fixed on its base; its top corner (0.5, 0)
  is the sharp corner that presses into the large block. Quadrilaterals graded towards that
  corner (0.02 there, up to 0.1);
* the **large block** 0 <= x <= 1, 0 <= y <= 1, its top face moved down by ``displacement``
  (0.05: 5 % of its height, enough to see in true-scale figures). Columns of equal width 1/27,
  so no node of its face sits on the corner (the corner lies inside one of its facets), rows
  graded towards the contact face. Its face is the coarser of the two, so the small block,
  sharp corner and all, carries compatibility (docs/method.md §6). With 27 columns (finer than
  the small block's face) the roles swap and the corner indents the large block's face by
  8.4e-4 (1.7 % of the press's motion), which the both-ways penetration check reports.

The blocks touch along y = 0 before loading. The linear prediction (contact ignored) moves the
large block down rigidly by ``displacement``, so it overlaps the small block's whole top face.
The exact answer is not known in closed form (the corner is a stress singularity); the checks are
the ones any contact solution must meet: no penetration beyond the tolerance at convergence, the
contact force equal to the fixed block's support reaction and to the force the press applies,
and the same answer with the bodies listed in the other order.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import PrescribedDisplacement, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.io.runner import run_headline
from vfem.materials import LinearElastic
from vfem.result_types import largest_penetrations
from vfem.solver import AnalysisResult, Model

#: ``vfem verify --slow``: every element size halved (33 columns in the large block, odd so no
#: node of its face sits on the corner), 2 840 dofs, about 2 s
VERIFY_SLOW = ("h=0.05", "h_corner=0.01", "large_columns=33")
#: What a block's equilibrium (its support's or the press's reaction against the contact force)
#: is allowed, relative to the force: the round-off of the linear solves, machine epsilon
#: (2.2e-16) times the condition of the block's stiffness (free dofs), 1.1e3 (small) and 1.9e3
#: (large) at the default mesh, 4e-13, and growing as 1/h^2 (four times per halving of the
#: elements). 1e-9 holds for conditions up to 4.5e6, five halvings finer than the default
#: (``vfem verify --slow`` is one). Measured at the default: 3.3e-15 and 3.7e-14.
EQUILIBRIUM_ROUND_OFF = 1e-9


@dataclass(frozen=True)
class Parameters:
    """Parameters of the block example (our dimensions; see the module docstring)."""

    youngs_modulus: float = 1000.0
    poissons_ratio: float = 0.3
    small_half_width: float = 0.5
    small_height: float = 0.5
    large_half_width: float = 1.0
    large_height: float = 1.0
    displacement: float = 0.05  # of the large block's top face, downwards
    h: float = 0.1  # largest element size
    h_corner: float = 0.02  # element size at the small block's corner
    large_columns: int = 17  # equal columns of the large block (odd: no node on the corner)
    steps: int = 1
    variant: str = "paired"
    swap_bodies: bool = False


def config(p: Parameters) -> ModelConfig:
    """The model as data (what ``examples/block.toml`` holds for the defaults)."""
    mat = LinearElastic(p.youngs_modulus, p.poissons_ratio)
    w, c = p.small_half_width, p.h_corner
    small_mesh = MeshSpec(shape="block", parameters=as_parameters(
        x0=0.0, y0=-p.small_height, width=w, height=p.small_height, h=p.h, h_fine=c,
        growth=0.3, fine_x=(w,), fine_y=(0.0,), symmetry="left"))
    large_mesh = MeshSpec(shape="block", parameters=as_parameters(
        x0=0.0, y0=0.0, width=p.large_half_width, height=p.large_height,
        h=p.large_half_width / p.large_columns, h_fine=c, growth=0.3, fine_y=(0.0,),
        symmetry="left"))
    small = BodyConfig("small", small_mesh, mat,
                       supports=(Support("bottom", ("x", "y")), Support("symmetry", ("x",))))
    large = BodyConfig("large", large_mesh, mat, supports=(Support("symmetry", ("x",)),),
                       prescribed=(PrescribedDisplacement("top", "y", -p.displacement),))
    bodies = (large, small) if p.swap_bodies else (small, large)
    return ModelConfig("block", bodies, ContactSettings(variant=p.variant),
                       Steps(count=p.steps))


def build(p: Parameters) -> Model:
    return config(p).build()


def validate(p: Parameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    from vfem.errors import InputError

    if p.small_half_width >= p.large_half_width:
        raise InputError("block: small_half_width must be less than large_half_width (the "
                         "small block's corner must lie under the large block)")
    if p.steps < 1:
        raise InputError(f"block: steps must be at least 1, got {p.steps}")
    if p.large_columns < 1:
        raise InputError(f"block: large_columns must be at least 1, got {p.large_columns}")
    build(p).validate()


def evaluate(result: AnalysisResult, p: Parameters) -> dict:
    """Force balance and residual penetration of the last step."""
    last = result.steps[-1]
    bodies = {b.name: b for b in result.model.bodies}
    out = {}
    for name, boundary in (("small", "bottom"), ("large", "top")):
        b, r = bodies[name], last.bodies[name]
        out[f"{name}_reaction_y"] = b.reaction_of(r, boundary, "y")
        out[f"{name}_contact_force_y"] = float(r.contact_force[:, 1].sum())
    # invariant (a)'s scale: the larger block's total contact force (x and y)
    out["largest_body_contact_force"] = max(
        float(np.linalg.norm(last.bodies[n].contact_force.sum(axis=0))) for n in ("small", "large"))
    # the contact pushes the small block down and the large block up
    force = out["large_contact_force_y"]
    out["contact_force"] = force
    out["balance_error_small"] = abs(out["small_reaction_y"] - force) / abs(force)
    out["balance_error_large"] = abs(-out["large_reaction_y"] - force) / abs(force)
    out["equal_and_opposite_error"] = (abs(out["small_contact_force_y"] + force) / abs(force))
    h = last.history[-1]
    out["max_penetration"] = h.max_penetration
    out["penetration_tolerance"] = result.penetration_tolerance
    both = largest_penetrations(result, last)
    out["largest_penetration_any_node"] = max(v["penetration"] for v in both.values())
    out["penetration_by_body"] = both
    small = last.bodies["small"]
    pts = bodies["small"].points
    top = np.flatnonzero((np.abs(pts[1]) < 1e-12) & (small.contact_status > 0))
    out["contact_nodes_small"] = int(len(top))
    out["corner_pressure"] = float(small.contact_pressure[
        int(np.argmin(np.hypot(pts[0] - p.small_half_width, pts[1])))])
    return out


def summarize(result: AnalysisResult, p: Parameters) -> dict:
    from vfem.io.results import example_summary

    summary = example_summary("block", result, p)
    if result.complete:  # (also the thesis variant's run, not converged: issue 37)
        summary["block"] = evaluate(result, p)
        if result.converged:
            summary["verification"] = verification(summary["block"], p, result)
    return summary


def verification(b: dict, p: Parameters, result: AnalysisResult) -> list[dict]:
    """The block's checks (``summary.json``'s ``verification``; :mod:`vfem.io.verification`).
    Its exact answer is not known in closed form (the corner is a stress singularity, thesis
    §5.4), so it is checked against what any contact solution must meet exactly: each block in
    equilibrium (the fixed block's support reaction and the press's reaction equal the contact
    force: round-off of the linear solves, :data:`EQUILIBRIUM_ROUND_OFF`); where the
    formulation enforces invariant (a) (the paired variant, whose forces on both blocks follow
    from one traction, docs/method.md §6), the forces on the two blocks equal and opposite
    (:func:`vfem.io.verification.balance`; the thesis variant's are recorded, not held to it:
    no record); and no node of either block inside the other (checked both ways,
    independently of the solver: within the contact iteration's penetration tolerance)."""
    from vfem.io.verification import balance, check, enforces_balance

    force = b["contact_force"]
    solve = ("round-off of the linear solves: machine epsilon times the blocks' stiffness "
             "condition, 4e-13 at the default mesh, growing 4 times per halving; allowed "
             "to conditions of 4.5e6 (block.EQUILIBRIUM_ROUND_OFF)")
    records = [
        check("fixed block's support reaction", b["small_reaction_y"], force,
              "the contact force, by the block's equilibrium", EQUILIBRIUM_ROUND_OFF, solve),
        check("press's reaction", -b["large_reaction_y"], force,
              "the contact force, by the block's equilibrium", EQUILIBRIUM_ROUND_OFF, solve),
    ]
    if enforces_balance(result.model.contact):
        records.append(balance("contact force on the fixed block", -b["small_contact_force_y"],
                               force, "the large block's, equal and opposite",
                               scale=b["largest_body_contact_force"]))
    records.append(check(
        "penetration, any node, both ways", b["largest_penetration_any_node"], 0.0,
        "none: the bodies do not overlap", b["penetration_tolerance"],
        "the contact iteration's penetration tolerance (contact.penetration_tolerance: "
        "1e-5 of the shortest contact facet)", measure="absolute"))
    return records


def run(p: Parameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example: VTU/PVD per step, ``summary.json`` and the figures in ``out``."""
    from vfem.io.results import run_example

    def draw(model, result, summary):
        """What the figures need beyond the results files: the linear prediction (contact
        ignored, as extra VTU files) and the windows (``summary.json``'s ``figure_data``)."""
        from vfem.io.replot import write_frames

        if not result.steps:
            return
        lf = result.steps[-1].load_factor
        w = p.small_half_width
        summary["figure_data"] = {
            "frames": {"prediction": write_frames(
                Path(out), "prediction", model,
                {b.name: (lf * b.u_load).reshape(-1, 2) for b in model.bodies})},
            "window": [0.0, p.large_half_width, -p.small_height, p.large_height],
            "corner_window": [w - 0.15, w + 0.15, -0.15, 0.1]}

    return run_example(build(p), out, lambda r: summarize(r, p), draw if figures else None,
                       on_step, resume)


def figures(folder) -> list[Path]:
    """The figures of a block results folder (:class:`vfem.io.replot.Folder`), which the run
    draws and ``vfem plot`` redraws: thesis Figs. 5.14-5.16 (``initial.png``,
    ``prediction.png``, ``final.png``), ``corner.png``, ``pressure.png`` (the small block's
    top, the last step's VTU) and ``von_mises.png``."""
    from vfem.io import plots, replot

    s = folder.summary
    if not folder.has_steps or "figure_data" not in s:
        return []
    data = s["figure_data"]
    method = replot.contact_label(s)
    last = folder.steps[-1]

    def frame(bodies, zero=False):
        return [(b.name, b.points, b.polygons, 0.0 * b.displacement if zero else b.displacement)
                for b in bodies]

    out = folder.directory
    window, zoom = tuple(data["window"]), tuple(data["corner_window"])
    names = ["initial.png", "prediction.png", "final.png", "corner.png"]
    plots.configurations(out / names[0], [("initial", frame(last.bodies, zero=True))],
                         "Block: initial configuration (thesis Fig. 5.14)", window)
    plots.configurations(out / names[1], [("linear prediction",
                                           frame(folder.frames("prediction")))],
                         "Block: linear prediction, contact ignored (Fig. 5.15)", window,
                         magnification=1.0)
    final = frame(last.bodies)
    plots.configurations(out / names[2], [("final", final)],
                         f"Block: final configuration (Fig. 5.16)\n{method}", window,
                         magnification=1.0)
    plots.configurations(out / names[3], [("final", final)],
                         f"Block: the small block's corner, final configuration\n{method}",
                         zoom, magnification=1.0)
    small = next(b for b in last.bodies if b.name == "small")
    x, y = small.points.T
    top = np.flatnonzero(np.abs(y) < 1e-12)
    order = top[np.argsort(x[top], kind="stable")]
    pressure = np.asarray(small.point_data["contact_pressure"], dtype=float).ravel()
    plots.history(out / "pressure.png", x[order], {"small block (top face)": pressure[order]},
                  f"x, undeformed ({plots.LENGTH})",
                  f"nominal contact pressure ({plots.LENGTH})",
                  f"Block: contact pressure on the small block\n{method}")
    vm = replot.von_mises(folder, last, "von_mises.png",
                          f"Block: von Mises stress, final configuration\n{method}", window)
    return [out / n for n in names] + [out / "pressure.png", vm]


def report(s: dict) -> list[str]:
    lines = [run_headline(s, "step(s)")]
    if "block" in s:
        b = s["block"]
        lines.append(f"  contact force {b['contact_force']:.4g}; fixed block's reaction "
                     f"{b['small_reaction_y']:.4g} ({b['balance_error_small']:.1e} off); "
                     f"press {-b['large_reaction_y']:.4g} ({b['balance_error_large']:.1e} off)")
        lines.append(f"  largest residual penetration {b['max_penetration']:.2e} (tolerance "
                     f"{b['penetration_tolerance']:.1e}); any node of either block, checked "
                     f"both ways: {b['largest_penetration_any_node']:.2e}")
    return lines
