"""Cattaneo-Mindlin in 3D (issue 21, C14): a sphere on a flat of the same material, pressed by a
force P, then sheared by a growing sideways motion along x with P held; Coulomb friction.

Theory (Mindlin 1949, Johnson's *Contact Mechanics* §7.2). The bodies are alike, so the normal
and the tangential problems uncouple: the contact is Hertz's (the ``sphere`` example's a and
p0), and under a tangential force Q < mu P along x it sticks over the circle r < c,

    c / a = (1 - Q / (mu P))^(1/3),

and slips outside, with the shear traction along x

    q(r) = mu p0 sqrt(1 - r^2/a^2)                                  for c < r < a,
    q(r) = mu p0 (sqrt(1 - r^2/a^2) - (c/a) sqrt(1 - r^2/c^2))      for r < c.

The model: the ``sphere`` example's bodies (the sphere's contact region, a cylinder of radius
0.6 R and height 0.5 R whose lower end is the sphere, :func:`vfem.mesh.solids.cylinder`; the
flat a block 2 R wide and R deep, fixed below), but the half y >= 0 (the shear along x breaks
the symmetry about x = 0; rollers in y on the plane y = 0 of both bodies). The sphere's top
face carries a force-controlled platen along z (P/2 on the half: applied over load factors 0 to
0.5, then held), a prescribed motion along x (0 until 0.5, then growing linearly to ``shift`` at
1) and is held in y. Defaults: steel-like, R = 10, P = 15,000 (a = 1.008, a/R = 0.1), mu = 0.3,
``shift`` a little beyond the motion at which the whole contact slips (Mindlin's
3 mu P (2 - nu) / (8 G a) = 0.037, plus the bodies' own compliance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import Platen, PrescribedDisplacement, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.io.runner import friction_line, run_headline
from vfem.materials import LinearElastic
from vfem.solver import AnalysisResult, Model

from .sphere import CYLINDER_HEIGHT, CYLINDER_RADIUS, FLAT_DEPTH, FLAT_HALF_WIDTH, PLATEAU, contour

#: The load factors nearest which the figures draw the stick zone and the shear profile.
PICKS = (0.3, 0.6, 0.9)

#: ``vfem verify --slow``: facets a/8 (84 531 dofs), the study's finest mesh
VERIFY_SLOW = ("facets_per_radius=8",)


@dataclass(frozen=True)
class Parameters:
    """Parameters of the 3D Cattaneo-Mindlin example (see the module docstring)."""

    radius: float = 10.0  # R, the sphere's
    youngs_modulus: float = 200e3  # both bodies'
    poissons_ratio: float = 0.3
    force: float = 15000.0  # P, on the whole sphere (half of it on the half model)
    friction: float = 0.3  # mu
    shift: float = 0.045  # the top face's motion along x at load factor 1
    press_steps: int = 1  # load factors 0 to 0.5: P applied
    shear_steps: int = 10  # load factors 0.5 to 1: the motion applied, P held
    refinement: int = 0
    facets_per_radius: int = 6  # over Hertz's contact radius a (the sphere's facets)
    flat_size_ratio: float = 1.3  # the flat's contact facets over the sphere's
    max_element_size: float = 1.0  # over the sphere's radius, times 10 (the bulk's elements)
    growth: float = 0.3
    sphere_cells: str = "hex"  # or "tet"
    flat_cells: str = "hex"
    swap_bodies: bool = False
    equilibrium_tolerance: float = 1e-3


def theory(p: Parameters) -> dict[str, float]:
    """Hertz's contact radius a and peak pressure p0 of the two similar bodies, and mu p0."""
    e_star = p.youngs_modulus / (2.0 * (1.0 - p.poissons_ratio ** 2))
    if not (p.force > 0 and p.radius > 0 and e_star > 0):  # (a complex cube root otherwise)
        raise ValueError("Hertz's theory needs a positive force, radius and E*")
    a = (3.0 * p.force * p.radius / (4.0 * e_star)) ** (1.0 / 3.0)
    p0 = 3.0 * p.force / (2.0 * math.pi * a * a)
    return {"a": a, "p0": p0, "mu_p0": p.friction * p0, "e_star": e_star}


def stick_radius(p: Parameters, tangential: float) -> float:
    """Mindlin's stick radius c for the tangential force ``tangential`` (0 at full slip)."""
    ratio = abs(tangential) / (p.friction * p.force)
    return theory(p)["a"] * max(0.0, 1.0 - ratio) ** (1.0 / 3.0)


def shear_theory(p: Parameters, r: np.ndarray, tangential: float) -> np.ndarray:
    """Mindlin's shear traction magnitude at the radii ``r`` under the tangential force."""
    th = theory(p)
    a, mu_p0 = th["a"], th["mu_p0"]
    c = stick_radius(p, tangential)
    r = np.abs(np.asarray(r, dtype=float))
    out = mu_p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None))
    if c > 0:
        out -= np.where(r < c, mu_p0 * (c / a) * np.sqrt(np.clip(1 - (r / c) ** 2, 0, None)),
                        0.0)
    return out


def shear_curve() -> tuple[tuple[float, float], ...]:
    """The load curve of the sideways motion: 0 until 0.5, 1 at 1."""
    return ((0.0, 0.0), (0.5, 0.0), (1.0, 1.0))


def load_factors(p: Parameters) -> tuple[float, ...]:
    return (tuple(0.5 * (k + 1) / p.press_steps for k in range(p.press_steps))
            + tuple(0.5 + 0.5 * (k + 1) / p.shear_steps for k in range(p.shear_steps)))


def facet_size(p: Parameters) -> float:
    """The sphere's contact facets' size, a / n."""
    return theory(p)["a"] / (p.facets_per_radius * 2 ** p.refinement)


def config(p: Parameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/cattaneo3d.toml`` holds for the defaults)."""
    p = p or Parameters()
    try:
        a = theory(p)["a"]
    except (ValueError, ArithmeticError, ZeroDivisionError, TypeError):
        a = None  # parameters that make no theory are refused by validate()
    R = p.radius
    a = a if a is not None and a > 0 else 0.1 * R
    n = p.facets_per_radius * 2 ** p.refinement
    h = a / n
    h_max = 0.1 * R * p.max_element_size / 2 ** p.refinement
    material = LinearElastic(p.youngs_modulus, p.poissons_ratio)
    press = ((0.0, 0.0), (0.5, 1.0), (1.0, 1.0))
    roller = Support("front", ("y",))
    sphere = BodyConfig(
        name="sphere",
        mesh=MeshSpec(shape="cylinder", parameters=as_parameters(
            radius=CYLINDER_RADIUS * R, height=CYLINDER_HEIGHT * R, end_radius=R,
            quarter=False, half=True, h_contact=h, h=h_max, growth=p.growth,
            plateau=PLATEAU * a, tetrahedra=p.sphere_cells == "tet")),
        material=material,
        supports=(Support("top", ("y",)), roller),
        prescribed=(PrescribedDisplacement("top", "x", p.shift, shear_curve()),),
        platen=Platen("top", "z", -p.force / 2.0, press),
        contact_boundaries=("contact",),
    )
    L, D = FLAT_HALF_WIDTH * R, FLAT_DEPTH * R
    flat = BodyConfig(
        name="flat",
        mesh=MeshSpec(shape="box", parameters=as_parameters(
            x0=-L, y0=0.0, z0=-D, width=2 * L, depth=L, height=D,
            h=2.0 * h_max, h_fine=p.flat_size_ratio * h, growth=p.growth, fine_x=(0.0,),
            fine_y=(0.0,), fine_z=(0.0,), plateau=PLATEAU * a,
            tetrahedra=p.flat_cells == "tet")),
        material=material,
        supports=(Support("bottom"), roller),
        contact_boundaries=("top",),
    )
    bodies = (flat, sphere) if p.swap_bodies else (sphere, flat)
    settings = ContactSettings(friction=p.friction, equilibrium_tolerance=p.equilibrium_tolerance)
    return ModelConfig("cattaneo3d", bodies, settings, Steps(load_factors=load_factors(p)))


def build(p: Parameters | None = None) -> Model:
    return config(p).build()


def validate(p: Parameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    for name in ("radius", "youngs_modulus", "poissons_ratio", "force", "friction", "shift",
                 "flat_size_ratio", "max_element_size", "growth", "equilibrium_tolerance"):
        value = getattr(p, name)
        if isinstance(value, bool) or not (isinstance(value, (int, float))
                                           and math.isfinite(value)):
            raise InputError(f"cattaneo3d: {name} must be a finite number, got {value!r}")
    for name in ("radius", "youngs_modulus", "force", "flat_size_ratio", "max_element_size",
                 "growth", "equilibrium_tolerance"):
        if not getattr(p, name) > 0:
            raise InputError(f"cattaneo3d: {name} must be > 0, got {getattr(p, name)!r}")
    if not 0 <= p.poissons_ratio < 0.5:
        raise InputError(f"cattaneo3d: poissons_ratio must lie in [0, 0.5), got "
                         f"{p.poissons_ratio!r}")
    if not p.friction > 0:
        raise InputError(f"cattaneo3d: friction (mu) must be > 0, got {p.friction!r} (the "
                         "example is about stick and slip; frictionless contact is vfem run "
                         "sphere)")
    for name, least in (("press_steps", 1), ("shear_steps", 1), ("facets_per_radius", 1),
                        ("refinement", 0)):
        value = getattr(p, name)
        if isinstance(value, bool) or not isinstance(value, int) or value < least:
            raise InputError(f"cattaneo3d: {name} must be a whole number >= {least}, got "
                             f"{value!r}")
    for name in ("sphere_cells", "flat_cells"):
        if getattr(p, name) not in ("hex", "tet"):
            raise InputError(f"cattaneo3d: {name} must be 'hex' or 'tet', got "
                             f"{getattr(p, name)!r}")
    if theory(p)["a"] > 0.3 * p.radius:
        raise InputError(f"cattaneo3d: the contact radius a = {theory(p)['a']:.3g} is not small "
                         f"against the sphere's radius {p.radius:g} (Hertz's theory needs "
                         "a << R, and the model's cylinder is 0.6 R wide): lower the force")
    build(p).validate()


# -- reading a step -----------------------------------------------------------------------------

def stick_slip(result: AnalysisResult, step) -> dict:
    """At a converged step, the compatibility side's contact candidate nodes (the body whose
    nodes carry the friction status): undeformed x, y, the friction status (0 free, 1 stick,
    2 slip), the normal traction, the shear traction's x component on the flat and its y
    component; and the edge between sticking and other nodes (midpoints of the facet edges,
    as :func:`vfem_examples.sphere.contour`)."""
    fine = next(n for n, r in step.bodies.items() if (r.friction_status >= 0).any())
    body = next(b for b in result.model.bodies if b.name == fine)
    boundary = "contact" if fine == "sphere" else "top"
    r = step.bodies[fine]
    nodes = np.unique(body.mesh.facets[:, body.mesh.boundaries[boundary]])
    sign = 1.0 if fine == "flat" else -1.0  # the traction on the flat
    edge = contour(body.mesh, boundary, r.friction_status == 1)
    return {"body": fine, "x": body.mesh.p[0, nodes], "y": body.mesh.p[1, nodes],
            "status": r.friction_status[nodes], "normal": r.contact_traction[nodes],
            "shear_x": sign * r.contact_shear[nodes, 0],
            "shear_y": sign * r.contact_shear[nodes, 1], "edge": edge}


def resultants(step) -> tuple[float, float, float]:
    """The whole sphere's contact force on the flat: normal P, tangential Q (x) and its y part
    (0 by symmetry on the whole; the half model's own y force is the roller's)."""
    force = 2.0 * step.bodies["flat"].contact_force.sum(axis=0)
    return -float(force[2]), float(force[0]), float(force[1])


def evaluate(result: AnalysisResult, p: Parameters) -> dict:
    """Per step of the shear: Q/(mu P), Mindlin's c, the outermost sticking node's radius and
    the stick/slip edge's mean radius (over a and in facets off c), the shear traction's
    largest (r < 0.8 a) and RMS (r < a) errors along x against Mindlin's (over mu p0), and the
    tangential forces' balance (the two bodies' contact forces along x and y, over mu P)."""
    th = theory(p)
    a, mu_p0 = th["a"], th["mu_p0"]
    h = facet_size(p)
    rows = []
    for step in result.steps:
        if step.load_factor <= 0.5 + 1e-12:
            continue
        normal, tangential, _ = resultants(step)
        st = stick_slip(result, step)
        rr = np.hypot(st["x"], st["y"])
        stick = st["status"] == 1
        c = stick_radius(p, tangential)
        last = float(rr[stick].max()) if stick.any() else 0.0
        edge = np.hypot(*st["edge"].T) if len(st["edge"]) else np.zeros(0)
        err = (st["shear_x"] - shear_theory(p, rr, tangential)) / mu_p0
        totals = [step.bodies[name].contact_force.sum(axis=0) for name in ("flat", "sphere")]
        balance = (totals[0] + totals[1])[:2]
        rows.append({
            "step": step.step, "load_factor": step.load_factor, "iterations": step.iterations,
            "normal": normal, "tangential": tangential,
            "Q_over_muP": tangential / (p.friction * p.force), "c_over_a": c / a,
            "last_sticking_over_a": last / a, "last_sticking_off_c_facets": (last - c) / h,
            "edge_over_a": float(edge.mean() / a) if len(edge) else 0.0,
            "edge_off_c_facets": float((edge.mean() - c) / h) if len(edge) else -c / h,
            "sticking_nodes": int(stick.sum()), "slipping_nodes": int((st["status"] == 2).sum()),
            "shear_max_error": float(np.abs(err[rr < 0.8 * a]).max(initial=0.0)),
            "shear_rms_error": float(np.sqrt(np.mean(err[rr < a] ** 2))),
            "tangential_balance": float(np.abs(balance).max() / (p.friction * p.force)),
            # invariant (a)'s reading (the half model's): |the sum of the two bodies' totals|
            # and the larger body's |total|
            "contact_force_sum": float(np.linalg.norm(totals[0] + totals[1])),
            "largest_body_contact_force": float(max(np.linalg.norm(t) for t in totals)),
        })
    return {"a": a, "p0": th["p0"], "mu_p0": mu_p0, "facet_size": h,
            "compatibility_body": stick_slip(result, result.steps[-1])["body"]
            if result.steps else None, "steps": rows}


def picks(rows: list[dict]) -> list[int]:
    """The rows of the shear nearest Q/(mu P) = 0.3, 0.6 and 0.9 (each once)."""
    if not rows:
        return []
    ratio = np.array([r["Q_over_muP"] for r in rows])
    return sorted({int(np.argmin(np.abs(ratio - f))) for f in PICKS})


def summarize(result: AnalysisResult, p: Parameters) -> dict:
    from vfem.io.results import example_summary

    summary = example_summary("cattaneo3d", result, p)
    if result.steps:
        ev = evaluate(result, p)
        summary["cattaneo3d"] = ev
        shear = [s for s in result.steps if s.load_factor > 0.5 + 1e-12]
        maps = []
        for i in picks(ev["steps"]):
            st = stick_slip(result, shear[i])
            keep = np.hypot(st["x"], st["y"]) < 1.3 * ev["a"]
            line = keep & (np.abs(st["y"]) < 1e-9 * p.radius)
            maps.append({"step": shear[i].step, "tangential": ev["steps"][i]["tangential"],
                         "x": st["x"][keep].tolist(), "y": st["y"][keep].tolist(),
                         "status": st["status"][keep].tolist(),
                         "line_x": st["x"][line].tolist(),
                         "line_shear": st["shear_x"][line].tolist()})
        summary["figure_data"] = {"stick": maps}
        if result.converged and result.steps[-1].load_factor == 1.0 and ev["steps"]:
            summary["verification"] = verification(ev, p)
    return summary


#: Mindlin's partial slip (Johnson, *Contact Mechanics*, §7.2), with Hertz's a
MINDLIN = "Mindlin"


def verification(ev: dict, p: Parameters) -> list[dict]:
    """The run's checks (``summary.json``'s ``verification``; :mod:`vfem.io.verification`)
    against Mindlin's partial slip, Coulomb's law at full slip and Newton's third law, each at
    the worst step of the shear. The tolerances: the stick zone is read at the nodes, so its
    end lies between the outermost sticking node and its slipping neighbours, one facet h
    out, and so does its edge (the midpoints of the facet edges that leave it): one facet; the
    shear traction's error is largest at the nodes within a facet of Mindlin's kink at c and of
    the contact's edge, a fraction about h/a of the nodes in r < a, so its RMS falls as about
    sqrt(h/a) (15.3, 13.5, 12.6 % of mu p0 at the worst step at a/5, a/6, a/8, docs/examples.md's
    study), allowed 0.5 sqrt(h/a); at full slip (recorded only when every node slips at the last
    step) Coulomb's cone holds at each node about its surface's normal, the sphere's tilted by
    up to a/R from the flat's, where Mindlin's Q = mu P takes both surfaces flat: with cones
    about the sphere's normals (tilt theta = r/R) and Hertz's pressure, Q/(mu P) - 1 is to
    leading order the pressure-weighted mean of theta^2 / 4, (a/R)^2 / 10 (the mean of
    (r/a)^2 is 2/5), and 0 with the flat's; allowed (a/R)^2 / 2, an estimate of that order with
    margin (the faceted nodes' normals and pressure add to it), not a bound; the two bodies'
    forces equal and opposite at the worst step (invariant (a),
    :func:`vfem.io.verification.balance`)."""
    from vfem.io.verification import balance, check

    rows = ev["steps"]
    a, h = ev["a"], ev["facet_size"]
    stick = max(rows, key=lambda r: abs(r["last_sticking_off_c_facets"]))
    edge = max(rows, key=lambda r: abs(r["edge_off_c_facets"]))
    shear = max(rows, key=lambda r: r["shear_rms_error"])
    forces = max(rows, key=lambda r: r["contact_force_sum"] / r["largest_body_contact_force"])
    at = "worst, Q/(mu P) {:.3f}".format
    records = [
        check(f"outermost sticking node / a ({at(stick['Q_over_muP'])})",
              stick["last_sticking_over_a"], stick["c_over_a"], MINDLIN, h / a,
              "one facet: the stick zone is read at the nodes, its end lying between the "
              "outermost sticking node and its slipping neighbours, a facet h out (h/a)",
              measure="absolute"),
        check(f"stick/slip edge's radius / a ({at(edge['Q_over_muP'])})",
              edge["edge_over_a"], edge["c_over_a"], MINDLIN, h / a,
              "one facet: read at the midpoints of the facet edges that leave the stick zone, "
              "between a sticking node and a slipping one, a facet h apart (h/a)",
              measure="absolute"),
        check(f"shear traction's RMS error / (mu p0) ({at(shear['Q_over_muP'])})",
              shear["shear_rms_error"], 0.0, MINDLIN,
              0.5 * math.sqrt(h / a),
              "discretisation: the nodes within a facet of c and of a, about h/a of them, read "
              "off by much of mu p0, so the RMS falls as sqrt(h/a) (12.6-15.3 % at a/8-a/5, "
              "docs/examples.md's study); allowed 0.5 sqrt(h/a)", measure="absolute"),
    ]
    last = rows[-1]
    if last["sticking_nodes"] == 0:  # the whole contact slips: Q = mu P
        records.append(check(
            "Q / (mu P) at full slip (last step)", last["Q_over_muP"], 1.0,
            "Coulomb (every node slipping)", 0.5 * (a / p.radius) ** 2,
            "an estimate: Mindlin takes both surfaces flat, each node's cone is about its "
            "surface's normal (the sphere's tilted by r/R); to leading order (a/R)^2/10 with "
            "the sphere's normals and Hertz's pressure, 0 with the flat's; allowed (a/R)^2/2, "
            "that order with margin, not a bound", measure="absolute"))
    records.append(balance(
        f"contact forces' sum, |sphere + flat| (worst step, load factor "
        f"{forces['load_factor']:.3g}; the half model's)", forces["contact_force_sum"], 0.0,
        "Newton's third law (equal and opposite)", scale=forces["largest_body_contact_force"]))
    return records


def run(p: Parameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example: VTU/PVD per step, ``summary.json`` and the figures in ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), figures, on_step, resume)


def figures(folder) -> list[Path]:
    """The figures of a 3D Cattaneo results folder (:class:`vfem.io.replot.Folder`), which the
    run draws and ``vfem plot`` redraws, at the steps of the shear nearest Q/(mu P) = 0.3, 0.6
    and 0.9: ``stick_map.png``, the compatibility side's nodes seen from below, sticking or
    slipping, with Mindlin's circle r = c and Hertz's r = a; ``shear.png``, the shear traction
    along x over mu p0 against x/a along y = 0, with Mindlin's."""
    from vfem.io import plots, replot

    s = folder.summary
    data = s.get("figure_data")
    if "cattaneo3d" not in s or not data or not data.get("stick"):
        return []
    p = Parameters(**{k: v for k, v in s["parameters"].items()
                      if k in Parameters.__dataclass_fields__})
    a, mu_p0 = s["cattaneo3d"]["a"], s["cattaneo3d"]["mu_p0"]
    method = replot.contact_label(s)
    out = folder.directory
    panels, curves = [], []
    for d in data["stick"]:
        q = d["tangential"]
        label = f"Q/(mu P) = {q / (p.friction * p.force):.2f}"
        panels.append((label, np.asarray(d["x"]) / a, np.asarray(d["y"]) / a,
                       np.asarray(d["status"], dtype=int), stick_radius(p, q) / a))
        x = np.asarray(d["line_x"])
        order = np.argsort(x)
        xs = np.linspace(-a, a, 401)
        curves.append((label, x[order] / a, np.asarray(d["line_shear"])[order] / mu_p0,
                       xs / a, shear_theory(p, xs, q) / mu_p0))
    plots.stick_map(out / "stick_map.png", panels,
                    f"Cattaneo-Mindlin 3D: stick (filled) and slip (open) seen from below, mu = "
                    f"{p.friction:g}; dashed: Mindlin's r = c, dotted: Hertz's r = a\n{method}")
    plots.profiles(out / "shear.png", curves, "x / a (along y = 0)",
                   "shear traction along x / (mu p0)",
                   f"Cattaneo-Mindlin 3D: sphere on a flat, mu = {p.friction:g} "
                   f"(lines: Mindlin)\n{method}")
    return [out / "stick_map.png", out / "shear.png"]


def report(s: dict) -> list[str]:
    lines = [run_headline(s, "step(s)")]
    ev = s.get("cattaneo3d")
    if ev and ev["steps"]:
        lines.append(f"  a = {ev['a']:.4f} (Hertz), mu p0 = {ev['mu_p0']:.5g}, facets "
                     f"{ev['facet_size']:.3g} (a/{ev['a'] / ev['facet_size']:.0f})")
        for r in ev["steps"]:
            lines.append(f"  load factor {r['load_factor']:.3f}: Q/(mu P) {r['Q_over_muP']:.3f}"
                         f", c/a {r['c_over_a']:.3f} (Mindlin), outermost sticking node "
                         f"{r['last_sticking_over_a']:.3f} ({r['last_sticking_off_c_facets']:+.2f}"
                         f" facets), shear error {100 * r['shear_max_error']:.1f} % max, "
                         f"{100 * r['shear_rms_error']:.1f} % RMS of mu p0, "
                         f"{r['iterations']} iterations")
    if friction_line(s):
        lines.append("  " + friction_line(s, "the shear per node in contact.csv and the VTU "
                                             "files"))
    return lines
