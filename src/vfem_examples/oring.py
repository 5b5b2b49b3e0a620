"""An O-ring squeezed in its groove (issue 42): a neo-Hookean body of revolution at finite
strain, with Coulomb friction against the groove and the lid.

An O-ring of cross-section diameter d and mean diameter D sits in a rectangular groove of
width ``groove_width`` (its floor at z = 0) and a flat lid is brought down on it until the
cross-section is compressed by ``compression`` (a fraction of d), in equal steps. Floor and lid
are alike and the groove is symmetric about the ring's mid-plane z = d/2(1 - c), so the model
is the upper half (the ``disk`` shape with ``half = true``: its flat side on the plane of
symmetry, held along the axis; the floor's part is played by that plane, whose reaction is the
floor's force): the ring (``kinematics = "total"``, ``law = "neo-hookean"``, E and nu of a
rubber, ``plane = "axisymmetric"``), the lid (steel) moved down by c d / 2, and the groove's
two walls (steel) from the mid-plane up, which the ring touches once it has bulged out to the
groove's width. Coulomb friction ``friction`` between the ring and the lid and walls. Forces
are per full circle (2 pi r); per unit of circumference they are divided by pi D.

Reported against compression: the lid's force per unit circumference beside **Lindley's
relation** F/L = E d (1.25 c^1.5 + 50 c^6) with E = 3G (P. B. Lindley, "Load-compression
relationships of rubber units", *J. Strain Anal.* 1 (1966) 190-195, as commonly quoted for a
circular cord compressed between flat plates: plane strain, incompressible, frictionless, up
to about 30 % compression; an empirical fit, not a bound), the contact width on the lid and its
peak pressure, and whether the ring touches the walls. The ring's linear quadrilaterals lock
as nu approaches 1/2 (the force falls as the mesh is refined: ``docs/examples.md``), and
CalculiX's CAX4 do the same; ``benchmarks/oring_calculix.py`` runs the same mesh in CalculiX.

**Verification** (``summary.json``, the screen): the floor's force (the reaction on the plane
of symmetry) against the lid's (the ring's equilibrium along the axis, with the walls' friction
along it), and Coulomb's cone at every node in contact at every step (the largest shear per
mu times the pressure, at most 1 to round-off).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import PrescribedDisplacement, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.materials import LinearElastic
from vfem.solver import AnalysisResult, Model

LINDLEY = ("Lindley (J. Strain Anal. 1, 1966), as commonly quoted: F/L = E d (1.25 c^1.5 + "
           "50 c^6), E = 3G")

#: the steel of the lid and the walls
STEEL = (200e3, 0.3)
#: the example's sections: the material's plane of each
SECTIONS = {"axisymmetric": "axisymmetric", "plane strain": "strain"}


@dataclass(frozen=True)
class ORingParameters:
    """Parameters of the O-ring example (lengths in mm and moduli in MPa, or any consistent
    units)."""

    cross_section: float = 2.0  # d
    mean_diameter: float = 20.0  # D
    youngs_modulus: float = 6.0  # a rubber of about 70 Shore A
    poissons_ratio: float = 0.49
    friction: float = 0.2
    groove_width: float = 2.6  # 1.3 d
    compression: float = 0.3  # the last step's, a fraction of d
    steps: int = 6
    elements_across: int = 40  # the ring's elements across d
    #: "axisymmetric" (the ring) or "plane strain" (a straight cord, Lindley's setting: forces
    #: per unit length)
    section: str = "axisymmetric"
    #: the groove's walls as bodies (false: the ring and the lid alone, between two flat
    #: plates: Lindley's setting, and the two-body model ``benchmarks/oring_calculix.py``
    #: writes for CalculiX)
    walls: bool = True
    #: the ring's hyperelastic law: CalculiX's and Abaqus's NEO HOOKE by default (the same law
    #: as benchmarks/oring_calculix.py's deck), or "neo-hookean" (Ciarlet–Simo)
    law: str = "neo-hookean-isochoric"


Parameters = ORingParameters

#: ``vfem verify --slow``: twice the elements
VERIFY_SLOW = ("elements_across=80",)


def validate(p: ORingParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    for name in ("cross_section", "mean_diameter", "youngs_modulus", "groove_width",
                 "compression"):
        value = getattr(p, name)
        if isinstance(value, bool) or not (isinstance(value, (int, float))
                                           and 0 < value < math.inf):
            raise InputError(f"oring: {name} must be a finite number > 0, got {value!r}")
    if not 0.0 <= p.poissons_ratio < 0.5:
        raise InputError(f"oring: poissons_ratio must be in [0, 0.5), got {p.poissons_ratio!r}")
    if not (isinstance(p.friction, (int, float)) and 0.0 <= p.friction < math.inf):
        raise InputError(f"oring: friction must be a number >= 0, got {p.friction!r}")
    if p.mean_diameter <= p.groove_width + p.cross_section:
        raise InputError(f"oring: mean_diameter must exceed groove_width + cross_section (the "
                         f"groove's inner wall off the axis), got {p.mean_diameter!r}")
    if p.groove_width <= p.cross_section:
        raise InputError(f"oring: groove_width must exceed cross_section ({p.cross_section!r}) "
                         f"for the ring to go in, got {p.groove_width!r}")
    if not isinstance(p.walls, bool):
        raise InputError(f"oring: walls must be true or false, got {p.walls!r}")
    if p.section not in SECTIONS:
        raise InputError(f"oring: section must be {' or '.join(map(repr, SECTIONS))}, got "
                         f"{p.section!r}")
    if p.compression >= 0.6:
        raise InputError(f"oring: compression must be below 0.6 of the cross-section, got "
                         f"{p.compression!r}")
    for name, low, high in (("steps", 1, 1000), ("elements_across", 4, 400)):
        value = getattr(p, name)
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise InputError(f"oring: {name} must be a whole number from {low} to {high}, got "
                             f"{value!r}")
    build(p).validate()


def _steel(name: str, x0: float, y0: float, width: float, height: float, h: float,
           boundary: str, supports: tuple, plane: str, **extra) -> BodyConfig:
    return BodyConfig(
        name=name,
        mesh=MeshSpec(shape="block", parameters=as_parameters(
            x0=x0, y0=y0, width=width, height=height, h=h)),
        material=LinearElastic(*STEEL, plane=plane),
        supports=supports, contact_boundaries=(boundary,), **extra)


def config(p: ORingParameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/oring.toml`` holds for the defaults)."""
    p = p or ORingParameters()
    d, rc, w = p.cross_section, 0.5 * p.mean_diameter, p.groove_width
    try:
        h = d / p.elements_across
        squeeze = 0.5 * p.compression * d  # the lid's travel on the half model
    except (TypeError, ZeroDivisionError):
        h, squeeze = d / 10, 0.1 * d  # validate() names what is wrong
    plane = SECTIONS.get(p.section, "axisymmetric")
    # a straight cord is symmetric about its vertical diameter too: its quarter, held along x
    # there (a ring of revolution is not: its inner and outer sides differ)
    cord = plane != "axisymmetric"
    ring = BodyConfig(
        name="ring",
        mesh=MeshSpec(shape="disk", translate=(rc, 0.0), parameters=as_parameters(
            radius=0.5 * d, h=h, quarter=cord, half=not cord)),
        material=LinearElastic(p.youngs_modulus, p.poissons_ratio, plane=plane),
        # the plane of symmetry (and the cord's vertical one)
        supports=(Support("bottom", ("y",)), *((Support("left", ("x",)),) if cord else ())),
        contact_boundaries=("rim",), kinematics="total", law=p.law)
    # the lid spans the groove and a little more; the walls stop short of the lid's lowest
    # position (a twentieth of d below it), so that steel never meets steel
    lid = _steel("lid", rc - (0.0 if cord else 0.75 * w), 0.5 * d, (0.75 if cord else 1.5) * w,
                 0.25 * d, h, "bottom", (Support("top", ("x",)),), plane,
                 prescribed=(PrescribedDisplacement("top", "y", -squeeze),))
    wall_height = 0.5 * d - squeeze - 0.05 * d
    inner = _steel("inner wall", rc - 0.5 * w - 0.25 * d, 0.0, 0.25 * d, wall_height, h,
                   "right", (Support("left", ("x", "y")),), plane)
    outer = _steel("outer wall", rc + 0.5 * w, 0.0, 0.25 * d, wall_height, h, "left",
                   (Support("right", ("x", "y")),), plane)
    bodies = (ring, lid) + (() if not p.walls else (outer,) if cord else (inner, outer))
    # the ring may touch each of the others; steel never meets steel
    pairs = tuple(("ring", b.name) for b in bodies[1:])
    steps = p.steps if isinstance(p.steps, int) and p.steps >= 1 else 1
    return ModelConfig("oring", bodies, ContactSettings(friction=p.friction), Steps(count=steps),
                       contact_pairs=pairs)


def build(p: ORingParameters | None = None) -> Model:
    return config(p).build()


def lindley(p: ORingParameters, c: float) -> float:
    """Lindley's force per unit length of cord at the compression ``c`` (E = 3G: the
    relation is for incompressible rubber, E = 2G(1 + nu) -> 3G)."""
    shear = p.youngs_modulus / (2.0 * (1.0 + p.poissons_ratio))
    return 3.0 * shear * p.cross_section * (1.25 * c ** 1.5 + 50.0 * c ** 6)


def _contact_nodes(result: AnalysisResult, step, body_name: str):
    body = next(b for b in result.model.bodies if b.name == body_name)
    r = step.bodies[body_name]
    x = body.points.T + np.asarray(r.displacement).reshape(-1, 2)
    return x, r


def evaluate(result: AnalysisResult, p: ORingParameters) -> dict:
    """Per step: the compression, the lid's force per full circle and per unit circumference,
    Lindley's, the contact width and peak pressure on the lid, the walls' contact; Coulomb's
    cone's largest share; the floor's force."""
    d = p.cross_section
    # per unit of circumference (a straight cord's forces are per unit length already, of
    # its quarter model: half the cord's); a quarter's contact width is half the cord's
    cord = p.section != "axisymmetric"
    circumference = 0.5 if cord else math.pi * p.mean_diameter
    rows = []
    cone = 0.0
    for step in result.steps:
        c = p.compression * step.load_factor
        lid_x, lid = _contact_nodes(result, step, "lid")
        ring_x, ring = _contact_nodes(result, step, "ring")
        # the ring's push on the lid (up), the floor's on the ring (the reaction on the plane
        # of symmetry, up) and the ring's on the walls along the axis (its friction): the
        # ring balances along the axis when floor = lid + walls
        lid_force = float(np.asarray(lid.contact_force)[:, 1].sum())
        floor = float(ring.reaction_total[1])
        walls = {}
        for name in ("inner wall", "outer wall"):
            if name in step.bodies:  # (a straight cord's quarter has the outer alone)
                _, wr = _contact_nodes(result, step, name)
                walls[name] = float(np.asarray(wr.contact_force)[:, 1].sum())
        # the ring's nodes against the lid: at the lid's height (the lid barely moves but
        # by its travel); the contact width between the outermost two
        top = 0.5 * d * (1.0 - c)
        on = (ring.contact_status > 0) & (ring_x[:, 1] > top - 0.25 * d / p.elements_across)
        width = (2.0 if cord else 1.0) * float(np.ptp(ring_x[on, 0])) if on.sum() > 1 else 0.0
        p_max = float(np.asarray(ring.contact_pressure)[on].max()) if on.any() else 0.0
        side = (ring.contact_status > 0) & ~on
        rows.append({
            "load_factor": float(step.load_factor), "compression": c,
            "lid_force": lid_force, "force_per_length": lid_force / circumference,
            "lindley": lindley(p, c), "contact_width": width, "peak_pressure": p_max,
            "floor_force": floor, "wall_axial_force": sum(walls.values()),
            "wall_nodes": int(side.sum()),
        })
        # Coulomb's cone on the pair's traction field (at the nodes that carry it: friction
        # status 1 stick or 2 slip), the normal traction the formulation's, not the nodal
        # reading of contact_pressure (a force over a tributary: not the same average)
        if p.friction > 0 and ring.contact_shear is not None:
            held = np.asarray(ring.friction_status) >= 1
            q = np.asarray(ring.contact_traction)[held]
            shear = np.linalg.norm(np.asarray(ring.contact_shear)[held], axis=1)
            if held.any():
                cone = max(cone, float((shear / (p.friction * q)).max()))
    return {"steps": rows, "cone": cone, "circumference": circumference,
            "walls_touched_at": next((r["compression"] for r in rows if r["wall_nodes"]),
                                     None)}


def summarize(result: AnalysisResult, p: ORingParameters) -> dict:
    """The ``summary.json`` dictionary of a run."""
    from vfem.io.results import example_summary

    summary = example_summary("oring", result, p)
    if result.converged and result.steps:
        summary["oring"] = m = evaluate(result, p)
        summary["verification"] = verification(m, result.model.contact)
    return summary


def verification(m: dict, settings) -> list[dict]:
    """The floor's force against the lid's and the walls' along the axis; Coulomb's cone."""
    from vfem.io.verification import check

    last = m["steps"][-1]
    return [
        check("floor's force (the plane of symmetry's reaction, per full circle)",
              last["floor_force"], last["lid_force"] + last["wall_axial_force"],
              "the ring's equilibrium along the axis: the lid's force and the walls' "
              "friction along it", 1e-8,
              "the contact iteration's equilibrium (every body balances to round-off "
              "of its largest force)"),
        check("largest shear per mu times the pressure, over the nodes in contact and the "
              "steps, above 1", max(m["cone"] - 1.0, 0.0), 0.0, "Coulomb's law (|q_t| <= mu "
              "q_n)", 1e-8, "round-off of the friction solve's traction", measure="absolute"),
    ]


def run(p: ORingParameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD, ``summary.json`` and the figures to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), figures, on_step, resume)


def figures(folder) -> list[Path]:
    """``oring.png``: the lid's force per unit circumference against compression beside
    Lindley's, and the contact width and peak pressure on the lid; the generic figures
    (deformed, contact pressure, friction, history, von Mises)."""
    from vfem.io import replot
    from vfem.io.plots import require_matplotlib, save

    s = folder.summary
    m = s.get("oring")
    drawn = replot.generic(folder) if folder.has_steps else []
    if m is None:
        return drawn
    rows = m["steps"]
    c = np.array([r["compression"] for r in rows]) * 100
    d = s["parameters"]["cross_section"]
    E = s["parameters"]["youngs_modulus"]
    plt = require_matplotlib()
    fig, (left, right) = plt.subplots(1, 2, figsize=(10.0, 4.0))
    left.plot([0.0, *c], [0.0, *(r["force_per_length"] for r in rows)], "o-", ms=4,
              label="vfem")
    cc = np.linspace(0.0, c.max(), 100)
    run_p = ORingParameters(**s["parameters"])
    left.plot(cc, [lindley(run_p, x / 100) for x in cc], "-", label="Lindley (1966)")
    left.set_xlabel("compression (% of d)")
    left.set_ylabel("lid force per unit circumference")
    left.legend(fontsize=8)
    left.grid(alpha=0.3)
    right.plot([0.0, *c], [0.0, *(r["contact_width"] / d for r in rows)], "o-", ms=4,
               label="contact width / d")
    right.plot([0.0, *c], [0.0, *(r["peak_pressure"] / E for r in rows)], "s--", ms=4,
               label="peak pressure / E")
    right.set_xlabel("compression (% of d)")
    right.legend(fontsize=8)
    right.grid(alpha=0.3)
    section = s["parameters"].get("section", "axisymmetric")
    shape = (f"O-ring (d = {d:g}, D = {s['parameters']['mean_diameter']:g}" if section ==
             "axisymmetric" else f"a straight cord (d = {d:g}, plane strain")
    fig.suptitle(f"{shape}, neo-Hookean, "
                 f"mu = {s['parameters']['friction']:g}), {s['dofs']} dofs", fontsize=10)
    path = folder.directory / "oring.png"
    save(plt, fig, path)
    return [path, *drawn]


def report(s: dict) -> list[str]:
    """What the CLI prints after the run."""
    m = s.get("oring")
    if m is None:
        return []
    lines = ["  compression  F per length  Lindley's  ratio  contact width  peak pressure"]
    for r in m["steps"]:
        lines.append(f"  {100 * r['compression']:10.1f} %  {r['force_per_length']:12.4g}  "
                     f"{r['lindley']:9.4g}  {r['force_per_length'] / r['lindley']:5.2f}  "
                     f"{r['contact_width']:13.4g}  {r['peak_pressure']:13.4g}")
    touched = m["walls_touched_at"]
    lines.append("  the ring touches the groove's walls from "
                 f"{100 * touched:.1f} % compression" if touched is not None
                 else "  the ring does not touch the groove's walls")
    return lines
