"""Thesis §5.3: a wide shallow wedge driven into a flat plate, five stiffness ratios.

Plane strain, right half of the model (the symmetry plane x = 0 has u_x = 0 on both bodies).
Plate: ``[0, 5] x [-1, 0]``, fixed on its lower face. Wedge: 1.3 thick at the centre and 1 at its
outer edge (x = 5); its lower face rises straight from the tip, which touches the plate at the
origin, to 0.3 at the edge; its top face is flat. The central portion of the wedge's top face,
0 <= x <= 1 (the middle fifth of the whole wedge: the thesis gives no width), moves down by 0.3.
Both bodies have nu = 0.3; the plate's modulus is 1 and the wedge's 1000, 2, 1, 1/2 and 1/1000
times that in the five cases (only the ratio matters: displacements are prescribed, so the
displacements do not depend on the moduli's common scale and the forces are proportional to it).

Ignoring contact, the wedge moves down rigidly by 0.3 (the linear prediction, thesis Fig. 5.5):
its tip overlaps the plate by 0.3 and the overlap falls linearly to 0 at the outer edge, so the
whole lower face of the wedge is a contact candidate (``search_distance`` is set to 1.1 times
the rise). The example reports how the 0.3 overlap at the tip is shared: the plate's share is
the plate tip's downward displacement over 0.3, the wedge's share how far its tip was pushed
back up from the prediction over 0.3; at convergence the two add up to 1.

Meshes (``mesh``):

* ``"graded"`` (default): the triangles of :func:`vfem.mesh.wedge` and
  :func:`vfem.mesh.wedge_plate`, of size ``h_contact`` (0.05) at the tip growing by ``growth``
  per unit distance to ``h_max`` (0.25); ``refinement`` halves both per level.
* ``"coarse"``: ``coarse_columns`` x ``coarse_rows`` (15 x 3) quadrilaterals per body, a mesh of
  the thesis's era whose surface elements are deeper than the 0.3 overlap.

Load steps. The thesis applies the whole motion in one step, but it also requires that no node
go deeper into the other body than its outer layer of elements (thesis §5.6, the *rind*; the
solver cuts a step that breaks it). The linear prediction puts the tip 0.3 deep, so one step
needs surface elements deeper than 0.3: the coarse mesh takes one step, the graded one (tip
elements about 0.025 deep) 15. ``steps = 0`` (default) chooses the fewest equal steps that keep
the predicted overlap increment within the rind, with a 10 % margin (:func:`planned_steps`).
The problem is linear (small strain, surfaces paired in the undeformed configuration), so the
final state does not depend on the number of steps, only the iteration counts do.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from skfem import MeshQuad, MeshTri

from vfem.bodies import Body, PrescribedDisplacement, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import CONVERGENCE_CRITERIA, VARIANTS, ContactSettings
from vfem.errors import InputError
from vfem.materials import LinearElastic
from vfem.solver import AnalysisResult, Model, StepResult

#: Wedge/plate modulus ratio of the thesis's five cases, in its numbering.
RATIOS = (1000.0, 2.0, 1.0, 0.5, 0.001)
#: Iterations the thesis reports for the five cases (one step each).
THESIS_ITERATIONS = (3, 6, 4, 4, 2)
#: The thesis's figure of each case's final configuration.
THESIS_FIGURES = {1: "5.6", 5: "5.7", 3: "5.8", 2: "5.9", 4: "5.10"}
#: The thesis's overlays of final configurations (cases, figure).
OVERLAYS = (((1, 3, 5), "5.11"), ((1, 2, 3), "5.12"), ((3, 4, 5), "5.13"))
MESHES = ("graded", "coarse")
#: Margin of the automatic step count on the rind rule (see :func:`planned_steps`).
RIND_MARGIN = 1.1
#: The reference of the verification (:func:`verification`): each case's plate share on the
#: graded mesh refined three times (``vfem run wedge --set refinement=3``, 23 100 dofs, about
#: 30 s; docs/examples.md, Wedge, *Refinement*), to the 5 decimals that leave its rounding far
#: below the tolerance.
REFINED_PLATE_SHARE = {1: 0.99942, 2: 0.57685, 3: 0.40462, 4: 0.25354, 5: 0.00068}
#: The reference model's refinement level (its element size at the tip: h_contact / 2^3)
REFINED_LEVEL = 3
#: How far a plate share may move per refinement level (a halving of the element sizes): an
#: empirical margin from the refinement study, not a convergence estimate. The study's largest
#: change from one level to the next is 6.2e-4 of the overlap up to level 3 (case 2, levels 1
#: to 2) and 9.9e-4 from level 3 to 4 (case 3, which runs at level 4 only with the
#: compatibility side switched; case 2 stops there): not yet falling, so no rate extrapolates
#: the error, and the reference (level 3) is not converged either. 2e-3 is twice the largest
#: change seen, allowed per level between a coarser mesh and the reference's; a mesh at or
#: beyond the reference's level is not checked against it (:func:`reference_levels`).
SHARE_PER_LEVEL = 2.0e-3
#: ``vfem verify --slow``: the graded mesh refined twice (6 222 dofs; about 5 s to solve, 40 s
#: with its files)
VERIFY_SLOW = ("refinement=2",)


@dataclass(frozen=True)
class WedgeParameters:
    """Parameters of the wedge example; the thesis's values (where it gives them) are defaults."""

    plate_youngs_modulus: float = 1.0  # the wedge's is ratio x this
    poissons_ratio: float = 0.3  # both bodies
    half_width: float = 5.0  # not in the thesis: "wide"; slope 0.06
    plate_thickness: float = 1.0
    edge_thickness: float = 1.0
    centre_thickness: float = 1.3
    loaded_width: float | None = None  # default half_width / 5: the middle fifth of the wedge
    motion: float = 0.3  # downward, on the loaded part of the wedge's top face
    case: int = 0  # 0: all five; 1 to 5: that case only
    mesh: str = "graded"  # or "coarse"
    h_contact: float = 0.05  # graded mesh: element size at the tip
    h_max: float = 0.25
    growth: float = 0.1
    refinement: int = 0  # graded mesh: halves h_contact and h_max per level
    coarse_columns: int = 15  # coarse mesh: quadrilaterals across each body
    coarse_rows: int = 3  # and through each body's thickness
    steps: int = 0  # 0: the fewest equal steps that respect the rind rule
    variant: str = "paired"
    convergence: str = "stationary"
    penetration_tolerance: float | None = None
    equilibrium_tolerance: float = 1e-3
    max_iterations: int = 100
    max_step_cuts: int = 6
    swap_bodies: bool = False  # list the plate first
    figures: bool = True


Parameters = WedgeParameters


# -- the model ----------------------------------------------------------------------------------

def cases(p: WedgeParameters) -> list[int]:
    """The case numbers (1 to 5) a run covers."""
    return [p.case] if p.case else [1, 2, 3, 4, 5]


def loaded_width(p: WedgeParameters) -> float:
    """Width of the moving part of the wedge's top face, from the symmetry plane."""
    return p.half_width / 5.0 if p.loaded_width is None else float(p.loaded_width)


def rise(p: WedgeParameters) -> float:
    """Height of the wedge's lower face at its outer edge above the tip."""
    return p.centre_thickness - p.edge_thickness


def mesh_specs(p: WedgeParameters) -> tuple[MeshSpec, MeshSpec]:
    """(plate, wedge) meshes as data: graded triangles, or the thesis's coarse quadrilaterals."""
    if p.mesh == "coarse":
        # structured quadrilaterals, ``coarse_columns`` across and ``coarse_rows`` through each
        # body: the plate's surface elements are plate_thickness / coarse_rows deep (1/3 by
        # default, more than the 0.3 overlap of the linear prediction, so the thesis's single
        # step respects the rind rule)
        grid = dict(columns=p.coarse_columns, rows=p.coarse_rows, loaded_width=loaded_width(p))
        return (MeshSpec(shape="wedge_plate_grid", parameters=as_parameters(
                    half_width=p.half_width, thickness=p.plate_thickness, **grid)),
                MeshSpec(shape="wedge_grid", parameters=as_parameters(
                    half_width=p.half_width, edge_thickness=p.edge_thickness,
                    centre_thickness=p.centre_thickness, **grid)))
    scale = 0.5**p.refinement
    kw = dict(h_contact=p.h_contact * scale, h_max=p.h_max * scale, growth=p.growth)
    return (MeshSpec(shape="wedge_plate", parameters=as_parameters(
                half_width=p.half_width, thickness=p.plate_thickness, **kw)),
            MeshSpec(shape="wedge", parameters=as_parameters(
                half_width=p.half_width, edge_thickness=p.edge_thickness,
                centre_thickness=p.centre_thickness, loaded_width=loaded_width(p), **kw)))


def meshes(p: WedgeParameters) -> tuple[MeshTri | MeshQuad, MeshTri | MeshQuad]:
    """(plate, wedge) meshes with the named boundaries of :mod:`vfem.mesh.shapes`."""
    plate, body = mesh_specs(p)
    return plate.make(), body.make()


def surface_depth(mesh: MeshTri | MeshQuad, boundary: str) -> tuple[np.ndarray, np.ndarray]:
    """(x at the facet's end nearer the tip, depth) of each facet of ``boundary``: the depth is
    the area of the element behind the facet over the facet's length, as the solver's rind rule
    measures it (``ContactSurface.rind_depth``)."""
    f = mesh.boundaries[boundary]
    elem = mesh.f2t[0, f]
    x, y = mesh.p[:, mesh.t[:, elem]]
    area = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0))
    ends = mesh.p[:, mesh.facets[:, f]]  # (2, 2, nf)
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=0)
    return ends[0].min(axis=0), area / length


def planned_steps(p: WedgeParameters, plate: MeshTri | MeshQuad,
                  body: MeshTri | MeshQuad) -> int:
    """Equal steps of the motion: ``p.steps``, or (0) the fewest that respect the rind rule.

    In a step the wedge moves down rigidly by motion / steps on top of the converged state, so
    a facet at x is overlapped by at most (motion - rise x / half_width) / steps. That must stay
    within the depth of the surface elements of both bodies (the side whose nodes are checked
    depends on the stiffnesses), with a margin of ``RIND_MARGIN``.
    """
    if p.steps > 0:
        return int(p.steps)
    worst = 0.0
    for mesh in (plate, body):
        x, depth = surface_depth(mesh, "contact")
        overlap = np.clip(p.motion - rise(p) * x / p.half_width, 0.0, None)
        worst = max(worst, float(np.max(overlap / depth)))
    return max(1, math.ceil(RIND_MARGIN * worst))


def settings(p: WedgeParameters) -> ContactSettings:
    return ContactSettings(variant=p.variant, convergence=p.convergence,
                           penetration_tolerance=p.penetration_tolerance,
                           equilibrium_tolerance=p.equilibrium_tolerance,
                           max_iterations=p.max_iterations, max_step_cuts=p.max_step_cuts,
                           search_distance=1.1 * rise(p))


def config(p: WedgeParameters | None = None, case: int = 3) -> ModelConfig:
    """One case (1 to 5) as data (``examples/wedge/case<N>.toml`` hold the defaults)."""
    p = p or WedgeParameters()
    plate_spec, wedge_spec = mesh_specs(p)
    ratio = RATIOS[case - 1]
    plate = BodyConfig(
        name="plate", mesh=plate_spec,
        material=LinearElastic(p.plate_youngs_modulus, p.poissons_ratio),
        supports=(Support("bottom", ("x", "y")), Support("symmetry", ("x",))),
        contact_boundaries=("contact",),
    )
    upper = BodyConfig(
        name="wedge", mesh=wedge_spec,
        material=LinearElastic(ratio * p.plate_youngs_modulus, p.poissons_ratio),
        supports=(Support("symmetry", ("x",)),),
        prescribed=(PrescribedDisplacement("top_loaded", "y", -p.motion),),
        contact_boundaries=("contact",),
    )
    bodies = (plate, upper) if p.swap_bodies else (upper, plate)
    n = planned_steps(p, *meshes(p))
    return ModelConfig(f"wedge case {case} (E_wedge / E_plate = {ratio:g})", bodies,
                       settings(p), Steps(count=n))


def configs(p: WedgeParameters | None = None) -> dict[str, ModelConfig]:
    """Every case the parameters select, by file-name-friendly key (``case1``)."""
    p = p or WedgeParameters()
    return {f"case{c}": config(p, c) for c in cases(p)}


def build(p: WedgeParameters | None = None, case: int = 3) -> Model:
    """The model of one case (1 to 5)."""
    return config(p, case).build()


def validate(p: WedgeParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    def need(ok: bool, message: str) -> None:
        if not ok:
            raise InputError(f"wedge: {message}")

    finite = all(isinstance(v, (int, float)) and math.isfinite(v) for v in
                 (p.half_width, p.plate_thickness, p.edge_thickness, p.centre_thickness,
                  p.motion, p.h_contact, p.h_max, p.growth))
    need(finite, "dimensions and mesh sizes must be finite numbers")
    need(p.half_width > 0 and p.plate_thickness > 0, "half_width and plate_thickness must be > 0")
    need(0 < p.edge_thickness < p.centre_thickness,
         f"need 0 < edge_thickness < centre_thickness, got {p.edge_thickness!r} and "
         f"{p.centre_thickness!r}")
    need(p.motion > 0, f"motion must be > 0, got {p.motion!r}")
    b = loaded_width(p)
    need(0 < b <= p.half_width, f"loaded_width must lie in (0, half_width], got {b!r}")
    need(p.case in (0, 1, 2, 3, 4, 5), f"case must be 0 (all) or 1 to 5, got {p.case!r}")
    need(p.mesh in MESHES, f"mesh must be one of {MESHES}, got {p.mesh!r}")
    need(p.variant in VARIANTS, f"variant must be one of {VARIANTS}, got {p.variant!r}")
    need(p.convergence in CONVERGENCE_CRITERIA,
         f"convergence must be one of {CONVERGENCE_CRITERIA}, got {p.convergence!r}")
    need(0 < p.h_contact <= p.h_max and p.growth >= 0,
         "need 0 < h_contact <= h_max and growth >= 0")
    need(p.refinement >= 0 and p.steps >= 0, "refinement and steps must be >= 0")
    need(p.coarse_columns >= 2 and p.coarse_rows >= 1,
         "need coarse_columns >= 2 and coarse_rows >= 1")
    need(p.max_step_cuts >= 0, "max_step_cuts must be >= 0")
    try:
        meshes(p)
    except ValueError as exc:
        raise InputError(f"wedge: {exc}") from None
    build(p, cases(p)[0]).validate()


# -- one case -----------------------------------------------------------------------------------

def tip(body: Body) -> int:
    """The body's point at the origin: the wedge's tip, the plate's point under it."""
    return int(np.argmin(np.hypot(*body.points)))


def solve_case(model: Model, out: Path | None = None, on_step=None, resume: bool = False
               ) -> tuple[AnalysisResult, str | None]:
    """Run one case's model, writing its VTU files into ``out`` if given: (result, the body
    whose surface carries compatibility in the paired variant, else None). A case that does not
    converge ends with the solver's message once its step cuts run out (``max_step_cuts``)."""
    from vfem.io.results import run_writing

    analysis, result = run_writing(model, out, on_step, resume)
    pairs = getattr(analysis.contact, "contact_pairs", None)
    compatibility = model.bodies[pairs[0].fine].name if pairs else None
    return result, compatibility


def evaluate(model: Model, steps: list[StepResult], p: WedgeParameters) -> dict:
    """Shares of the tip overlap, contact forces and their balance at load factor 1."""
    last = steps[-1]
    bodies = {b.name: b for b in model.bodies}
    plate, upper = bodies["plate"], bodies["wedge"]
    rp, rw = last.bodies["plate"], last.bodies["wedge"]
    tp, tw = tip(plate), tip(upper)
    predicted = float(upper.u_load[2 * tw + 1])  # the wedge tip, contact ignored
    plate_share = -float(rp.displacement[tp, 1]) / p.motion
    wedge_share = (float(rw.displacement[tw, 1]) - predicted) / p.motion
    f_wedge = rw.contact_force.sum(axis=0)  # on the wedge, from the plate
    f_plate = rp.contact_force.sum(axis=0)
    support = plate.reaction_of(rp, "bottom", "y")
    drive = upper.reaction_of(rw, "top_loaded", "y")
    force = float(f_wedge[1])
    scale = max(abs(force), 1e-300)
    x_contact = upper.points[0][rw.contact_status > 0]
    penetration = max(float(r.penetration.max()) for r in last.bodies.values())
    return {
        "plate_tip_displacement": -plate_share * p.motion,
        "wedge_tip_displacement": float(rw.displacement[tw, 1]),
        "wedge_tip_predicted": predicted,
        "plate_share": plate_share,
        "wedge_share": wedge_share,
        "share_sum": plate_share + wedge_share,
        "contact_force": force,
        "contact_force_x": float(f_wedge[0]),
        "contact_force_plate": -float(f_plate[1]),
        "plate_support_reaction": support,
        "wedge_drive_reaction": drive,
        "plate_balance_error": abs(support + float(f_plate[1])) / scale,
        "action_reaction_error": float(np.linalg.norm(f_wedge + f_plate)) / scale,
        "final_max_penetration": max(penetration, 0.0),
        "contact_nodes_wedge": int((rw.contact_status > 0).sum()),
        "contact_nodes_plate": int((rp.contact_status > 0).sum()),
        "contact_extent": float(x_contact.max()) if len(x_contact) else 0.0,
    }


def reference_levels(p: WedgeParameters) -> float | None:
    """How many halvings of the element size lie between this run's mesh and the reference's
    (:data:`REFINED_PLATE_SHARE`), or None where the reference is no reference for this run:
    another geometry, Poisson's ratio or motion, the coarse mesh, a graded mesh of another
    family (its size at the tip is the only size allowed to differ), or a mesh at or beyond the
    reference's level (the reference would be the model itself, or coarser than it: not a
    converged answer to compare with)."""
    d = WedgeParameters()
    same = ("poissons_ratio", "half_width", "plate_thickness", "edge_thickness",
            "centre_thickness", "motion", "mesh", "growth")
    if any(getattr(p, k) != getattr(d, k) for k in same) or loaded_width(p) != loaded_width(d):
        return None
    if p.h_max / p.h_contact != d.h_max / d.h_contact:
        return None
    tip = p.h_contact * 0.5**p.refinement
    levels = math.log2(tip / (d.h_contact * 0.5**REFINED_LEVEL))
    return levels if levels > 1e-9 else None


def verification(s: dict, p: WedgeParameters) -> list[dict]:
    """The wedge's checks (``summary.json``'s ``verification``; :mod:`vfem.io.verification`),
    one per case: how the overlap at the tip is shared, the plate's share against the same
    model on the graded mesh refined three times (:data:`REFINED_PLATE_SHARE`). The thesis gives
    the shares only as figures (Figs. 5.6-5.13: all the deflection in the plate in case 1, in the
    wedge in case 5, the contact a little above the middle of the overlap in case 3, §5.3).

    The tolerance is :data:`SHARE_PER_LEVEL` of the overlap per halving of the element sizes
    between this mesh and the reference's (at least one): an empirical margin, twice the
    refinement study's largest change per level, which is not yet falling. Where the reference
    is no reference for this run (:func:`reference_levels`: another model, or a mesh at or
    beyond the reference's level), each case is checked instead for what holds exactly at
    convergence: the plate's and the wedge's shares add up to 1, the tips meeting to within the
    contact iteration's penetration tolerance (over the motion)."""
    from vfem.io.verification import check

    levels = reference_levels(p)
    records = []
    for c in s["cases"]:
        case = c["case"]
        if levels is not None:
            records.append(check(
                f"case {case}: plate share", c["plate_share"], REFINED_PLATE_SHARE[case],
                f"the model refined {REFINED_LEVEL} times", SHARE_PER_LEVEL * max(1.0, levels),
                f"an empirical margin from the refinement study (docs/examples.md): "
                f"{SHARE_PER_LEVEL:g} of the overlap per halving of the elements, twice the "
                f"study's largest change per level (9.9e-4), which is not yet falling; "
                f"{max(1.0, levels):g} halvings between this mesh and the reference's",
                measure="absolute"))
        else:
            records.append(check(
                f"case {case}: plate share + wedge share", c["share_sum"], 1.0,
                "exact: the tips meet", c["penetration_tolerance"] / p.motion,
                "the contact iteration's penetration tolerance over the motion",
                measure="absolute"))
    return records


def summarize_case(p: WedgeParameters, case: int, model: Model, steps: list[StepResult],
                   converged: bool, message: str, seconds: float,
                   compatibility: str | None = None) -> dict:
    """The ``summary.json`` entry of one case."""
    iterations = [s.iterations for s in steps]
    out = {
        "case": case,
        "modulus_ratio": RATIOS[case - 1],
        "wedge_youngs_modulus": RATIOS[case - 1] * p.plate_youngs_modulus,
        "plate_youngs_modulus": p.plate_youngs_modulus,
        "thesis_iterations": THESIS_ITERATIONS[case - 1],
        "thesis_figure": THESIS_FIGURES[case],
        "planned_steps": len(model.load_factors),
        "converged": converged,
        "message": message,
        "compatibility_surface": compatibility,
        "iterations": iterations,
        "total_iterations": int(sum(iterations)),
        "load_factors": [s.load_factor for s in steps],
        "cuts": int(sum(s.cuts for s in steps)),
        "stopped_at_fixed_point": int(sum(s.fixed_point for s in steps)),
        "max_penetration": max((s.history[-1].max_penetration for s in steps), default=None),
        "max_equilibrium_error": max((s.history[-1].max_equilibrium_error for s in steps),
                                     default=None),
        "seconds": seconds,
    }
    if steps and steps[-1].load_factor == 1.0:
        out.update(evaluate(model, steps, p))
    return out


# -- the run ------------------------------------------------------------------------------------

def run(p: WedgeParameters, out=None, on_step=None, resume: bool = False) -> dict:
    """Run the cases, writing ``out/caseN/`` (VTU/PVD), the figures (unless ``p.figures`` is
    false, or the figures are deferred: ``vfem run --no-figures``, ``vfem verify``) and
    ``summary.json``."""
    from vfem.io.results import write_summary

    start = time.perf_counter()
    out = Path(out) if out is not None else None
    entries, finals, models = [], {}, {}
    for case in cases(p):
        t0 = time.perf_counter()
        model = build(p, case)
        start_case = getattr(on_step, "start_case", None)  # the CLI's progress: label the case
        if start_case is not None:
            start_case(f"case {case}")
        result, compatibility = solve_case(model, out / f"case{case}" if out else None,
                                           on_step, resume)
        steps, message = result.steps, result.message
        converged = result.converged
        entries.append(summarize_case(p, case, model, steps, converged, message,
                                      time.perf_counter() - t0, compatibility))
        entries[-1]["penetration_tolerance"] = result.penetration_tolerance
        models[case] = model
        if steps and steps[-1].load_factor == 1.0:
            finals[case] = steps[-1]
    first = models[cases(p)[0]]
    summary = {
        "example": "wedge",
        "converged": all(c["converged"] for c in entries),
        "message": "; ".join(f"case {c['case']}: {c['message']}" for c in entries
                             if not c["converged"]),
        "variant": p.variant,
        "mesh": p.mesh,
        "steps": [{"case": c["case"], "step": k + 1, "load_factor": lf, "iterations": it,
                   "converged": True}
                  for c in entries for k, (lf, it) in enumerate(zip(c["load_factors"],
                                                                      c["iterations"]))],
        "cases": entries,
        "bodies": {b.name: {"points": int(b.npoints), "dofs": int(b.ndofs),
                            "elements": int(b.mesh.t.shape[1])} for b in first.bodies},
        "dofs": int(sum(b.ndofs for b in first.bodies)),
        "loaded_width": loaded_width(p),
        "search_distance": settings(p).search_distance,
        "parameters": dataclasses.asdict(p),
        "timings": {},
    }
    summary["timings"] = {"total_s": time.perf_counter() - start,
                          "cases_s": float(sum(c["seconds"] for c in entries))}
    if summary["converged"] and all("plate_share" in c for c in entries):
        summary["verification"] = verification(summary, p)
    if out is not None:
        write_summary(out, summary)
        if p.figures:
            from vfem.io.replot import draw_run, write_frames

            summary["figure_data"] = {
                "first_case": cases(p)[0],
                "final_steps": {str(c): step.step for c, step in finals.items()},
                "frames": {"prediction": write_frames(
                    out, "prediction", first,
                    {b.name: b.u_load.reshape(-1, 2) for b in first.bodies})}}
            draw_run(out, summary, "wedge", first)
    return summary


def figures(folder) -> list[Path]:
    """The figures of a wedge results folder (:class:`vfem.io.replot.Folder`), which the run
    draws and ``vfem plot`` redraws: the thesis's figures 5.4 to 5.13 (those whose cases
    reached the full motion; each case's results in ``caseN/``) and ``von_mises_caseN.png``,
    each such case's final state filled by the von Mises stress."""
    from vfem.io import plots, replot

    s = folder.summary
    data = s.get("figure_data")
    if not data:
        return []
    method = replot.contact_label(s)
    mesh = s["parameters"]["mesh"]
    motion = s["parameters"]["motion"]
    out = folder.directory

    def frames(bodies, label: str = "", zero: bool = False) -> list:
        """One frame per body (wedge first), so each body gets its colour and legend entry."""
        order = sorted(bodies, key=lambda b: b.name != "wedge")
        return [(f"{label}{b.name}", [(b.points, b.polygons,
                                       0.0 * b.displacement if zero else b.displacement)])
                for b in order]

    def outline(bodies, label: str) -> tuple:
        """One frame for a whole configuration: both bodies in one colour."""
        order = sorted(bodies, key=lambda b: b.name != "wedge")
        return (label, [(b.name, b.points, b.polygons, b.displacement) for b in order])

    written = []
    first = folder.sub(f"case{data['first_case']}")
    if first.has_steps:
        plots.configurations(out / "mesh.png", frames(first.steps[0].bodies, zero=True),
                             f"Wedge (thesis Fig. 5.4): the meshes in the original "
                             f"configuration ({mesh})", mesh_lines=True)
        written.append(out / "mesh.png")
    plots.configurations(out / "prediction.png", frames(folder.frames("prediction")),
                         f"Wedge (Fig. 5.5): the linear prediction, contact ignored: the wedge "
                         f"moves down {motion:g}", mesh_lines=True, magnification=1.0)
    written.append(out / "prediction.png")
    final = {int(c): folder.sub(f"case{c}").step(n).bodies
             for c, n in data["final_steps"].items()}
    for case in sorted(final):
        plots.configurations(out / f"case{case}.png", frames(final[case]),
                             f"Wedge case {case} (Fig. {THESIS_FIGURES[case]}): E_wedge / "
                             f"E_plate = {RATIOS[case - 1]:g}, final configuration\n{method}",
                             mesh_lines=True, magnification=1.0)
        written.append(out / f"case{case}.png")
    for group, figure in OVERLAYS:
        if not all(c in final for c in group):
            continue
        name = "cases_" + "_".join(str(c) for c in group) + ".png"
        plots.configurations(out / name,
                             [outline(final[c], f"case {c}: E_wedge / E_plate = "
                                                f"{RATIOS[c - 1]:g}") for c in group],
                             f"Wedge (Fig. {figure}): final configurations of cases "
                             f"{', '.join(str(c) for c in group)}\n{method}",
                             mesh_lines=False, magnification=1.0)
        written.append(out / name)
    for case in sorted(final):
        step = folder.sub(f"case{case}").step(data["final_steps"][str(case)])
        written.append(replot.von_mises(
            folder, step, f"von_mises_case{case}.png",
            f"Wedge case {case}: von Mises stress, final configuration\n{method}"))
    return written


def report(s: dict) -> list[str]:
    """The closing lines of a wedge run: one row per case."""
    lines = [f"vfem: wedge (thesis §5.3), {s['variant']} variant, {s['mesh']} mesh, "
             f"{s['dofs']} dofs: {'converged' if s['converged'] else 'NOT converged'}, "
             f"{s['timings']['total_s']:.1f} s",
             f"  {'case':>4} {'E_w/E_p':>7} {'steps':>5} {'iterations':>10} {'thesis':>6} "
             f"{'plate share':>11} {'wedge share':>11} {'sum':>8} {'contact force':>13} "
             f"{'penetration':>11}"]
    for c in s["cases"]:
        head = (f"  {c['case']:>4} {c['modulus_ratio']:>7g} {len(c['iterations']):>5} "
                f"{c['total_iterations']:>10} {c['thesis_iterations']:>6}")
        if "plate_share" in c:
            lines.append(f"{head} {c['plate_share']:>11.2%} {c['wedge_share']:>11.2%} "
                         f"{c['share_sum']:>8.5f} {c['contact_force']:>13.5g} "
                         f"{c['max_penetration']:>11.1e}")
        else:
            lines.append(f"{head}  did not reach the full motion: {c['message']}")
    if any(len(c["iterations"]) > 1 for c in s["cases"]):
        lines.append("  iterations: the sum over the steps; the thesis took the whole motion in "
                     "one step (so does --set mesh=coarse, whose surface elements are deeper "
                     "than the overlap)")
    lines.append("  shares of the tip overlap: the plate's = its tip's downward displacement, "
                 "the wedge's = how far its tip was pushed back up; contact force: vertical, "
                 "on the half model")
    return lines
