"""Running a model described by an input file: solve, write results, summarise.

The built-in examples have their own post-processing (Hertz's theory, the wedge's shares); a
model from an input file gets the generic one here: per step the iterations and the physical
errors, per body the contact force and support reactions, the largest contact pressure and
displacement, and the figures of :mod:`vfem.io.replot` drawn from the files written (so
``vfem plot`` redraws them identically).
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np

from ..config import ModelConfig
from ..solver import AnalysisResult, Model
from .files import forget_vtus
from .input import to_data
from .replot import contact_settings, friction_laws_text
from .results import (
    finish_summary,
    force_record,
    friction_summary,
    mpi_ranks,
    run_writing,
    step_record,
    subdomain_summary,
    total,
    write_summary,
)

log = logging.getLogger(__name__)


def body_summary(result: AnalysisResult) -> dict:
    """Per body at the last converged step: contact force (sum of nodal forces), support
    reactions (``reactions``: the body's total, ``reactions_by_boundary``, ``applied_load``:
    :func:`vfem.io.results.force_record`), largest nominal contact pressure, nodes in contact,
    largest displacement."""
    out = {}
    if not result.steps:
        return out
    last = result.steps[-1]
    forces = force_record(last)
    for s in result.surfaces:
        r = last.bodies[s.body.name]
        name = s.body.name
        reactions = forces["reactions"].get(name)
        out[name] = {
            "nodes": int(s.body.npoints),
            "dofs": int(s.body.ndofs),
            "contact_candidate_nodes": int(s.nc),
            "contact_force": total(r.contact_force),
            **({"reactions": reactions["total"],
                "reactions_by_boundary": reactions["boundaries"],
                "applied_load": forces["applied_load"][name]} if reactions else {}),
            "max_contact_pressure": float(r.contact_pressure.max()),
            "contact_nodes": int((r.contact_status > 0).sum()),
            "max_displacement": float(np.linalg.norm(r.displacement, axis=1).max()),
        }
    return out


def summarize(result: AnalysisResult, config: ModelConfig, source: str | None = None) -> dict:
    """The ``summary.json`` of a model run from an input file."""
    steps = []
    for s in result.steps:
        steps.append({**step_record(s), "platen_displacement": s.platen_displacement})
    friction = friction_summary(result, steps)  # the work the friction dissipated
    return {
        "model": config.name,
        "input": source,
        "converged": result.converged,
        "message": result.message,
        "steps": steps,
        "bodies": body_summary(result),
        "dofs": int(sum(s.body.ndofs for s in result.surfaces)),
        "contact_dofs": int(sum(s.dim * s.nc for s in result.surfaces)),
        "penetration_tolerance": result.penetration_tolerance,
        "pressure_measure": "nominal: nodal contact force / undeformed tributary length",
        "config": to_data(config),
        "contact_settings": contact_settings(result.model),
        "timings": result.timings,
        "linear_solver": result.backend,
        "contact_flexibility": result.flexibility,
        **mpi_ranks(),
        **subdomain_summary(result.model),
        **friction,
    }


def run(config: ModelConfig, out: Path, base: Path | None = None, on_step=None,
        source: str | None = None, figures: bool | None = None, model: Model | None = None,
        resume: bool = False) -> dict:
    """Solve ``config`` (mesh files relative to ``base``; or its ``model`` already built),
    writing VTU/PVD, contact.csv and reactions.csv per converged step, then ``summary.json``
    and the figures into ``out``."""
    out = Path(out)
    draw = config.output.figures if figures is None else figures
    model = model or config.build(base)
    _, result = run_writing(model, out, on_step, resume)
    summary = summarize(result, config, source)
    write_summary(out, summary)
    if draw and result.steps:
        from .replot import draw_run

        t0 = time.perf_counter()
        draw_run(out, summary, "input", model)
        summary["timings"]["figures_s"] = time.perf_counter() - t0
    forget_vtus()  # (kept for the figures: vfem.io.files.remember_vtu)
    finish_summary(out, summary)
    return summary


def invariants_line(steps: list[dict]) -> str:
    """One line on the invariants of the steps (summary.json's ``steps[*].invariants``): the
    worst of each over the steps, e.g. ``invariants: forces balance to 3e-16, no node beyond
    its allowance (deepest 1.2e-09 inside, allowed 3.7e-07), no tension``; "" when no step was
    checked. Each node has its own allowance (the tolerance, and more where the faceting of a
    corner or a curve allows it), so a deeper node than the allowance shown may pass: the line
    then says the deepest is within its own, and which node came nearest its allowance."""
    checked = [x["invariants"] for x in steps if x.get("invariants")]
    if not checked:
        return ""
    balance = max(c["force_balance"] for c in checked)
    over = [c for c in checked if c["where"] and c["penetration"] > c["allowed"]]
    tension = max(checked, key=lambda c: c["tension"])
    text = f"invariants: forces balance to {balance:.1e}, "
    if over:
        c = max(over, key=lambda c: c["penetration"] - c["allowed"])
        w = c["where"]
        text += (f"node {w['node']} of {w['body']!r} {c['penetration']:.1e} inside "
                 f"{w['into']!r} (allowed {c['allowed']:.1e}), ")
    elif any(c["where"] for c in checked):
        # every node within its own allowance (vfem.contact.invariants.check: the tolerance
        # plus, at a corner or a curve, the faceting's), so the deepest node may be deeper than
        # the allowance of the node nearest its own, which is the one the check compares
        deepest = max(c["max_penetration_any_body"] for c in checked)
        c = max((c for c in checked if c["where"]), key=lambda c: c["penetration"] - c["allowed"])
        near, allowed = c["penetration"], c["allowed"]
        if deepest <= allowed or near >= deepest:
            text += (f"no node beyond its allowance (deepest {deepest:.1e} inside, allowed "
                     f"{allowed:.1e}), ")
        else:
            text += (f"no node beyond its allowance (deepest {deepest:.1e} inside, within its "
                     "own" + (f"; nearest its allowance {near:.1e} inside, allowed "
                              f"{allowed:.1e}" if near > 0 else "") + "), ")
    else:
        text += "no node inside another body, "
    beyond = [c["second_order"] for c in checked if c.get("second_order")]
    if beyond:  # small kinematics: recorded, not enforced (vfem.contact.invariants.check)
        w = max(beyond, key=lambda w: w["beyond"])
        text += (f"on the deformed geometry node {w['node']} of {w['body']!r} "
                 f"{w['deformed_depth']:.1e} inside {w['into']!r} (allowed {w['allowed']:.1e}; "
                 "within as linear theory reads it), ")
    if tension["tension"] > tension["tension_tolerance"]:
        w = tension["tension_where"]
        text += f"tension {tension['tension']:.1e} at node {w['node']} of {w['body']!r}"
    elif tension["tension"] > 0:
        text += (f"no tension (largest tensile nodal force {tension['tension']:.1e}, within "
                 f"{tension['tension_tolerance']:.0e})")
    else:
        text += "no tension"
    failed = sorted({name for c in checked for name in c.get("failed", [])})
    if failed:
        text += f" — VIOLATED: {', '.join(failed)}"
    return text


def _xy(v) -> str:
    """A vector's components, "(x, y)" or in 3D "(x, y, z)"."""
    return "(" + ", ".join(f"{c:.6g}" for c in v) + ")"


def balance_line(steps: list[dict]) -> str:
    """One line on how the forces on each body balance over the steps (summary.json's
    ``steps[*]``: ``contact_force``, ``reactions`` and ``applied_load`` per body): the largest
    ``|contact + reactions + applied loads|`` over the steps, relative to the largest of those
    forces the body carries at any step (a step with no contact left, after unloading, is not
    divided by its round-off), its body and step; "" when no step has reactions."""
    scale: dict[str, float] = {}
    rows = []
    for x in steps:
        for name, r in (x.get("reactions") or {}).items():
            t = np.asarray(r["total"], dtype=float)
            none = (0.0,) * len(t)  # (x, y), or (x, y, z) in 3D
            c = np.asarray((x.get("contact_force") or {}).get(name, none), dtype=float)
            a = np.asarray((x.get("applied_load") or {}).get(name, none), dtype=float)
            scale[name] = max(scale.get(name, 0.0), *(float(np.linalg.norm(v)) for v in (c, t, a)))
            only = (x.get("resultant_components") or {}).get(name)
            if only is not None:  # a body of revolution: its axial force alone balances
                c, t, a = (v[only] for v in (c, t, a))
            rows.append((float(np.linalg.norm(c + t + a)), name, x["step"]))
    if not rows:
        return ""
    v, name, step = max(rows, key=lambda r: r[0] / scale[r[1]] if scale[r[1]] > 0 else 0.0)
    ratio = v / scale[name] if scale[name] > 0 else 0.0
    return (f"forces on each body (contact + reactions + applied loads) balance to {ratio:.1e} "
            f"of the largest force it carries (worst: {name!r}, step {step})")


def _applied(step: dict, name: str) -> str:
    """", applied loads (x, y)" where the body carries tractions, else "" (the third term of
    the balance the closing screen shows)."""
    a = (step.get("applied_load") or {}).get(name)
    return f", applied loads {_xy(a)}" if a is not None and any(a) else ""


def reaction_lines(steps: list[dict]) -> list[str]:
    """A built-in example's closing lines on forces: per body at the last step its contact
    force and support reactions, then :func:`balance_line`; [] when no step has reactions."""
    if not steps or not steps[-1].get("reactions"):
        return []
    last = steps[-1]
    lines = [f"{name}: contact force {_xy(last['contact_force'][name])}, reactions "
             f"{_xy(r['total'])}" + _applied(last, name) for name, r in last["reactions"].items()]
    return [*lines, balance_line(steps)]


def run_status(s: dict) -> str:
    """"converged" or "NOT converged"; where the thesis variant ended steps at its fixed point
    with residuals above its tolerance (docs/method.md §5), which is not converged either
    (issue 37), what it did."""
    outside = [x for x in s["steps"] if x.get("stopped_at_fixed_point")]
    if outside:
        return (f"NOT converged (stopped at the thesis variant's fixed point OUTSIDE its "
                f"tolerance in {len(outside)} step{'' if len(outside) == 1 else 's'})")
    if not s["converged"]:
        return "NOT converged"
    return "converged"


def run_headline(s: dict, unit: str = "steps", contact_dofs: bool = False) -> str:
    """An example report's first line: "vfem: <status> in N <unit>, M contact iterations, D
    dofs[ (C contact dofs)], T s" from its ``summary.json`` dictionary ``s``."""
    steps = s["steps"]
    dofs = f"{s['dofs']} dofs" + (f" ({s['contact_dofs']} contact dofs)" if contact_dofs else "")
    return (f"vfem: {run_status(s)} in {len(steps)} {unit}, "
            f"{sum(x['iterations'] for x in steps)} contact iterations, {dofs}, "
            f"{s['timings']['total_s']:.1f} s" + solver_words(s))


def solver_words(s: dict) -> str:
    """", linear solver <name>" for a summary that records its backend (``linear_solver``),
    with the way to a faster one where it is SciPy's SuperLU and a faster one is not installed
    (:data:`vfem.linalg.PREFERENCE`)."""
    name = s.get("linear_solver")
    if not name:
        return ""
    words = f", linear solver {name}"
    if name == "superlu":
        import platform

        words += (" (the slowest: pip install pypardiso gives PARDISO)"
                  if platform.machine() in ("x86_64", "AMD64") else
                  " (the slowest: docs/benchmarks.md lists the faster backends)")
    return words


def report(s: dict, out: Path) -> list[str]:
    """The one-screen summary the CLI prints at the end of a run."""
    n_iter = sum(x["iterations"] for x in s["steps"])
    lines = [f"vfem: {s['model']}: {run_status(s)} — "
             f"{len(s['steps'])} step{'' if len(s['steps']) == 1 else 's'}, {n_iter} contact "
             f"iteration{'' if n_iter == 1 else 's'}, {s['dofs']} dofs, "
             f"{s['timings'].get('total_s', 0.0):.1f} s{solver_words(s)}"]
    for name, b in s["bodies"].items():
        reactions = f", reactions {_xy(b['reactions'])}" if "reactions" in b else ""
        if any(b.get("applied_load") or ()):
            reactions += f", applied loads {_xy(b['applied_load'])}"
        lines.append(f"  {name:>12}: contact force {_xy(b['contact_force'])}{reactions}, p_max "
                     f"{b['max_contact_pressure']:.6g}, {b['contact_nodes']} nodes in contact, "
                     f"largest displacement {b['max_displacement']:.4g}")
    if s["steps"]:
        worst = max(s["steps"], key=lambda x: x["max_penetration"])
        lines.append(f"  largest residual penetration {worst['max_penetration']:.2e} "
                     f"(tolerance {s['penetration_tolerance']:.2e}), equilibrium error "
                     f"{max(x['max_equilibrium_error'] for x in s['steps']):.2e}")
    for line in (balance_line(s["steps"]), invariants_line(s["steps"])):
        if line:
            lines.append("  " + line)
    line = friction_line(s, "shear, slip and stick or slip per node in contact.csv and the VTU "
                            "files")
    if line:
        lines.append("  " + line)
    lines.extend("  " + line for line in subdomain_lines(s))
    return lines


def subdomain_lines(s: dict) -> list[str]:
    """A line per body split into subdomains (``summary.json``'s ``subdomains``, issue 43):
    how it was split and what its BDDC solves took, so a user sees the split was used and
    what it cost (the partition itself is the VTU cell field ``subdomain``)."""
    out = []
    for name, d in (s.get("subdomains") or {}).items():
        dofs = d.get("dofs") or []
        sizes = f" ({min(dofs)} to {max(dofs)} dofs each)" if dofs else ""
        its = d.get("pcg_iterations_max")
        solves = d.get("pcg_solves")
        cost = (f", {solves} solve{'' if solves == 1 else 's'} of at most {its} BDDC iterations"
                if its is not None and solves else "")
        out.append(f"{name!r} split into {d['count']} subdomains{sizes}, interface "
                   f"{d['interface_dofs']} dofs, coarse {d['primal_dofs']}{cost}; the partition "
                   "is the VTU cell field 'subdomain'")
    return out


#: A frictional work within this fraction of the external work is round-off: shown as 0.
#: The frictional work is a sum over the nodes of both sides of each pair of tangential nodal
#: forces times displacements in the step; where the friction dissipates nothing (every node
#: sticking) the two sides' terms cancel, and what is left is the round-off of the converged
#: solution, relative to the work the forces do: the machine epsilon (2.2e-16) times the
#: conditioning of the solves (examples/friction/patch_stick.toml, every node sticking:
#: -2.8e-17 of an external work of 0.0105, 2.7e-15). 1e-9 leaves six orders of magnitude
#: above that for worse-conditioned models (large stiffness ratios, fine meshes: condition
#: numbers to 1e6 and beyond), while a real dissipation that small, a billionth of the work
#: put in, is far below what a reading to four digits or the discretisation resolves.
ROUND_OFF = 1e-9


def dissipated(s: dict) -> float | None:
    """The run's frictional work (``frictional_work_total``) as the closing screens give it:
    0.0 where it is within :data:`ROUND_OFF` of the external work (the sum over the steps of
    each step's ``external_work`` in size, :func:`vfem.io.results.external_work`), so a run
    that only sticks never shows a negative dissipation like -2.8e-17; None without friction."""
    if "frictional_work_total" not in s:
        return None
    work = float(s["frictional_work_total"])
    scale = sum(abs(float(x.get("external_work", 0.0))) for x in s.get("steps") or ())
    scale = max(scale, abs(float(s.get("external_work_total", 0.0))))
    return 0.0 if abs(work) <= ROUND_OFF * scale else work


def friction_line(s: dict, note: str = "") -> str:
    """One line on a run with friction (a summary with ``frictional_work_total``), "" without:
    its laws (``contact_settings``, :func:`vfem.io.replot.friction_laws_text`) and the work
    the friction dissipated over the run (:func:`dissipated`: 0 "to round-off" where it is
    that), then ``note`` (where the per-node readings are)."""
    work = dissipated(s)
    if work is None:
        return ""
    laws = friction_laws_text(s.get("contact_settings"))
    return (f"friction{f' ({laws})' if laws else ''}: work dissipated {work:.4g} over the run"
            f"{', to round-off' if work == 0 else ''} ("
            + "; ".join(["each step's in summary.json", *([note] if note else [])]) + ")")

