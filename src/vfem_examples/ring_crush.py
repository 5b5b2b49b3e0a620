"""A ring crushed between two plates until its bore closes on itself (issue 42): self-contact at
finite strain, in plane strain.

A ring of bore a and outside radius b (a long tube's section: plane strain), neo-Hookean at
finite strain, is crushed by a stiff plate brought down by ``crush`` times its outside diameter
in equal steps. The ring is symmetric about its vertical diameter: the model is its right half
(the ``annulus`` shape with ``half = true``), its two cuts held along x; the lower plate is a
point support under the ring (its outer facet at the bottom held along y: the ``foot``), on
which the ring rests. As it is crushed the ring flattens and its bore closes: the bore's upper
and lower parts (more than ``split`` degrees from the horizontal: ``inner_upper`` and
``inner_lower``) are the two sides of a **self-contact pair** (``contact_pairs =
[["ring:inner_upper", "ring:inner_lower"]]``), which touch once the bore has closed; then the
ring stiffens sharply. Forces are per unit length of the tube, of the whole ring (twice the
half model's).

Reported per step: the plate's travel, its force, the bore's opening (its top and bottom on the
plane of symmetry), the self-contact force (the normal force the bore's upper part carries)
and the compatibility side's nodes in self-contact. ``benchmarks/ring_crush_calculix.py``
runs the same mesh in CalculiX.

**Verification** (``summary.json``, the screen): the plate's force against the foot's reaction
(the ring's equilibrium, to 1e-8), the self-contact forces equal and opposite (the bore's
contact forces sum to zero, to 1e-8 of the self-contact force), and the invariants of every
converged step passed — no node inside its own body's other side, nor inside the plate, beyond
the penetration tolerance and faceting allowance (``docs/method.md`` §15).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import PrescribedDisplacement, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.errors import InputError
from vfem.materials import LinearElastic
from vfem.solver import AnalysisResult, Model


@dataclass(frozen=True)
class RingCrushParameters:
    """Parameters of the ring crush example."""

    inner_radius: float = 0.7  # a
    outer_radius: float = 1.0  # b
    youngs_modulus: float = 1000.0
    poissons_ratio: float = 0.3
    crush: float = 0.8  # the plate's last travel, a fraction of the outside diameter 2b
    steps: int = 32
    around: int = 30  # elements per quarter turn
    radial: int = 6  # elements through the wall
    split: float = 60.0  # degrees: the bore's sides in self-contact lie beyond it
    plate_stiffness_ratio: float = 1000.0  # the plate's E over the ring's
    #: the ring's hyperelastic law: CalculiX's and Abaqus's NEO HOOKE by default (the same law
    #: as benchmarks/ring_crush_calculix.py's deck), or "neo-hookean" (Ciarlet–Simo)
    law: str = "neo-hookean-isochoric"


Parameters = RingCrushParameters


def validate(p: RingCrushParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    for name in ("inner_radius", "outer_radius", "youngs_modulus", "crush",
                 "plate_stiffness_ratio"):
        value = getattr(p, name)
        if isinstance(value, bool) or not (isinstance(value, (int, float))
                                           and 0 < value < math.inf):
            raise InputError(f"ring_crush: {name} must be a finite number > 0, got {value!r}")
    if p.outer_radius <= p.inner_radius:
        raise InputError(f"ring_crush: outer_radius must exceed inner_radius "
                         f"({p.inner_radius!r}), got {p.outer_radius!r}")
    if not 0.0 <= p.poissons_ratio < 0.5:
        raise InputError(f"ring_crush: poissons_ratio must be in [0, 0.5), got "
                         f"{p.poissons_ratio!r}")
    if p.crush >= 1.0:
        raise InputError(f"ring_crush: crush must be below 1 (a share of the outside "
                         f"diameter), got {p.crush!r}")
    if not (isinstance(p.split, (int, float)) and 0.0 < p.split < 90.0):
        raise InputError(f"ring_crush: split must lie between 0 and 90 degrees, got "
                         f"{p.split!r}")
    for name, low, high in (("steps", 1, 1000), ("around", 4, 200), ("radial", 1, 40)):
        value = getattr(p, name)
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise InputError(f"ring_crush: {name} must be a whole number from {low} to "
                             f"{high}, got {value!r}")
    build(p).validate()


def travel(p: RingCrushParameters) -> float:
    """The plate's last travel: ``crush`` times the outside diameter."""
    return 2.0 * p.crush * p.outer_radius


def config(p: RingCrushParameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/ring_crush.toml`` holds for the defaults)."""
    p = p or RingCrushParameters()
    a, b = p.inner_radius, p.outer_radius
    try:
        h = 0.5 * math.pi * b / p.around  # the outer facets' length
        depth = travel(p)
    except (TypeError, ZeroDivisionError):
        h, depth = 0.1 * b, 0.5 * b  # validate() names what is wrong
    ring = BodyConfig(
        name="ring",
        mesh=MeshSpec(shape="annulus", parameters=as_parameters(
            inner_radius=a, outer_radius=b, around=p.around, radial=p.radial, half=True,
            split=p.split)),
        material=LinearElastic(p.youngs_modulus, p.poissons_ratio),
        supports=(Support("top", ("x",)), Support("bottom", ("x",)), Support("foot", ("y",))),
        contact_boundaries=("inner_upper", "inner_lower", "outer"),
        kinematics="total", law=p.law)
    plate = BodyConfig(
        name="plate",
        mesh=MeshSpec(shape="block", parameters=as_parameters(
            x0=0.0, y0=b, width=1.5 * b, height=0.2 * b, h=h)),
        material=LinearElastic(p.plate_stiffness_ratio * p.youngs_modulus, 0.3),
        supports=(Support("left", ("x",)),),  # on the plane of symmetry
        prescribed=(PrescribedDisplacement("top", "y", -depth),),
        contact_boundaries=("bottom",))
    steps = p.steps if isinstance(p.steps, int) and p.steps >= 1 else 1
    return ModelConfig("ring_crush", (ring, plate), steps=Steps(count=steps),
                       contact_pairs=(("ring:outer", "plate"),
                                      ("ring:inner_upper", "ring:inner_lower")))


def build(p: RingCrushParameters | None = None) -> Model:
    return config(p).build()


def evaluate(result: AnalysisResult, p: RingCrushParameters) -> dict:
    """Per step: the plate's travel and force (the whole ring's, per unit length), the bore's
    opening, the self-contact force and nodes; the equilibrium and the self-contact's balance."""
    ring = next(b for b in result.model.bodies if b.name == "ring")
    mesh = ring.mesh
    x0, y0 = mesh.p
    top = int(np.argmin(np.hypot(x0, y0 - p.inner_radius)))
    bottom = int(np.argmin(np.hypot(x0, y0 + p.inner_radius)))
    bore = np.unique(mesh.facets[:, mesh.boundaries["inner"]])
    upper = np.unique(mesh.facets[:, mesh.boundaries["inner_upper"]])
    rows = []
    equilibrium = balance = 0.0
    for step in result.steps:
        r = step.bodies["ring"]
        plate = step.bodies["plate"]
        u = np.asarray(r.displacement)
        f = np.asarray(r.contact_force)
        force = float(np.asarray(plate.contact_force)[:, 1].sum())  # the ring pushes it up
        foot = float(r.reactions.get("foot", (0.0, 0.0))[1])
        self_force = float(f[upper, 1].sum())  # the lower part pushes the upper one up
        opening = float((y0[top] + u[top, 1]) - (y0[bottom] + u[bottom, 1]))
        rows.append({"load_factor": float(step.load_factor),
                     "travel": float(step.load_factor) * travel(p),
                     "force": 2.0 * force, "foot_reaction": 2.0 * foot,
                     "bore_opening": opening, "self_contact_force": 2.0 * self_force,
                     "self_contact_nodes": int((r.contact_status[bore] > 0).sum()),
                     "invariants": bool(step.invariants["passed"])})
        equilibrium = max(equilibrium, abs(foot - force) / max(abs(force), 1e-300))
        scale = max(float(np.abs(f[bore]).sum()), 1e-300)
        balance = max(balance, float(np.linalg.norm(f[bore].sum(axis=0))) / scale
                      if np.any(f[bore]) else 0.0)
    closed = next((row for row in rows if row["self_contact_force"] > 0), None)
    return {"steps": rows, "equilibrium": equilibrium, "self_balance": balance,
            "closed_at_travel": None if closed is None else closed["travel"],
            "steps_passed": sum(row["invariants"] for row in rows),
            "thin_ring_stiffness": thin_ring_stiffness(p)}


def thin_ring_stiffness(p: RingCrushParameters) -> float:
    """A thin ring's stiffness under two opposite line loads, P / delta = E' I / ((pi/4 - 2/pi)
    R^3) per unit length (Castigliano on the curved beam of radius R = (a + b)/2, I = t^3/12,
    E' = E / (1 - nu^2) in plane strain; e.g. Roark's *Formulas for Stress and Strain*, the
    ring under diametral load): the first step's comparison, off by the wall's thickness
    (t / R = 0.35 here: a curved beam's and the contacts' own flexibilities)."""
    t, R = p.outer_radius - p.inner_radius, 0.5 * (p.outer_radius + p.inner_radius)
    E = p.youngs_modulus / (1.0 - p.poissons_ratio ** 2)
    return E * t ** 3 / 12.0 / ((0.25 * math.pi - 2.0 / math.pi) * R ** 3)


def summarize(result: AnalysisResult, p: RingCrushParameters) -> dict:
    """The ``summary.json`` dictionary of a run."""
    from vfem.io.results import example_summary

    summary = example_summary("ring_crush", result, p)
    if result.converged and result.steps:
        summary["ring_crush"] = m = evaluate(result, p)
        summary["verification"] = verification(m)
    return summary


def verification(m: dict) -> list[dict]:
    """The plate's force against the foot's reaction, the self-contact's balance, every
    step's invariants."""
    from vfem.io.verification import check

    last = m["steps"][-1]
    return [
        check("plate's force against the foot's reaction (per unit length)",
              last["foot_reaction"], last["force"], "the ring's equilibrium along y", 1e-8,
              "the contact iteration's equilibrium (every body balances to round-off of its "
              "largest force)"),
        check("the bore's contact forces' sum over their magnitudes", m["self_balance"], 0.0,
              "Newton's third law within one body (self-contact)", 1e-8,
              "round-off of the transfer", measure="absolute"),
        check("steps whose invariants failed", len(m["steps"]) - m["steps_passed"], 0.0,
              "every converged step checked independently of the formulation (no node inside "
              "its own body's other side or the plate: docs/method.md §15)", 0.5,
              "a count: none may fail", measure="absolute"),
    ]


def run(p: RingCrushParameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD, ``summary.json`` and the figures to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), figures, on_step, resume)


def figures(folder) -> list[Path]:
    """``crush.png``: the plate's force and the self-contact force against its travel, the
    bore's opening beside; the generic figures (deformed, contact pressure, von Mises)."""
    from vfem.io import replot
    from vfem.io.plots import require_matplotlib, save

    s = folder.summary
    m = s.get("ring_crush")
    drawn = replot.generic(folder) if folder.has_steps else []
    if m is None:
        return drawn
    rows = m["steps"]
    d = [0.0] + [r["travel"] for r in rows]
    plt = require_matplotlib()
    fig, (left, right) = plt.subplots(1, 2, figsize=(10.0, 4.0))
    left.plot(d, [0.0] + [r["force"] for r in rows], "o-", ms=3, label="plate's force")
    left.plot(d, [0.0] + [r["self_contact_force"] for r in rows], "s--", ms=3,
              label="the bore's self-contact force")
    if m["closed_at_travel"] is not None:
        left.axvline(m["closed_at_travel"], color="0.6", lw=0.8)
    left.set_xlabel("plate travel")
    left.set_ylabel("force per unit length (whole ring)")
    left.legend(fontsize=8)
    left.grid(alpha=0.3)
    right.plot(d, [2.0 * s["parameters"]["inner_radius"]] + [r["bore_opening"] for r in rows],
               "o-", ms=3)
    right.set_xlabel("plate travel")
    right.set_ylabel("the bore's opening on the plane of symmetry")
    right.grid(alpha=0.3)
    fig.suptitle(f"ring crush (a = {s['parameters']['inner_radius']:g}, b = "
                 f"{s['parameters']['outer_radius']:g}, neo-Hookean, plane strain), "
                 f"{s['dofs']} dofs", fontsize=10)
    path = folder.directory / "crush.png"
    save(plt, fig, path)
    return [path, *drawn]


def report(s: dict) -> list[str]:
    """What the CLI prints after the run."""
    m = s.get("ring_crush")
    if m is None:
        return []
    lines = ["  travel    force   bore opening   self-contact force  nodes"]
    for r in m["steps"]:
        lines.append(f"  {r['travel']:6.3f}  {r['force']:8.4g}  {r['bore_opening']:12.4g}  "
                     f"{r['self_contact_force']:18.4g}  {r['self_contact_nodes']:5d}")
    closed = m["closed_at_travel"]
    lines.append("  the bore closes on itself at a travel of "
                 f"{closed:.4g}" if closed is not None else "  the bore stays open")
    first = m["steps"][0]
    lines.append(f"  first step's stiffness {first['force'] / first['travel']:.4g} per unit "
                 f"length (a thin ring's: {m['thin_ring_stiffness']:.4g})")
    return lines
