"""Hertz's sphere on a flat (issue 21): the 3D counterpart of the thesis's §5.2 cylinder.

An elastic sphere of radius R is pressed onto an elastic flat by a force P. Hertz's theory
(both bodies half-spaces near the contact, frictionless):

    1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2,   a = (3 P R / (4 E*))^(1/3),
    p(r) = p0 sqrt(1 - r^2/a^2),              p0 = 3 P / (2 pi a^2).

The model: the sphere's contact region, a cylinder of radius 0.6 R and height 0.5 R whose lower
end is the sphere (:func:`vfem.mesh.solids.cylinder`), pushed down by a rigid force-controlled
platen on its top face (held there against sliding sideways); the flat a block 2 R wide and
R deep, fixed on its lower face. Both meshes are graded towards the first point of contact:
elements of size a/n (n = ``facets_per_radius``, doubled per ``refinement`` level) within
1.2 a of it, the flat's ``flat_size_ratio`` times larger (the surface meshes do not match).
``quarter`` (the default) models the quarter x >= 0, y >= 0 with two symmetry planes (rollers);
``quarter = false`` the whole. The defaults: steel-like, R = 10, P = 15,000, so a = 1.008 and
a/R = 0.1 (small strain: the analysis is linear).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import Platen, Support
from vfem.config import BodyConfig, Curve, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.io.runner import run_headline
from vfem.materials import LinearElastic
from vfem.solver import AnalysisResult, Model

from .hertz import check_resolution

#: The contact region's proportions, over the sphere's radius.
CYLINDER_RADIUS, CYLINDER_HEIGHT = 0.6, 0.5
FLAT_HALF_WIDTH, FLAT_DEPTH = 1.0, 1.0
#: The evenly fine zone's radius, over Hertz's contact radius.
PLATEAU = 1.2


@dataclass(frozen=True)
class SphereParameters:
    """Parameters of the sphere example."""

    radius: float = 10.0
    sphere_youngs_modulus: float = 200e3
    sphere_poissons_ratio: float = 0.3
    flat_youngs_modulus: float = 200e3
    flat_poissons_ratio: float = 0.3
    force: float = 15000.0  # on the whole sphere (a quarter of it on the quarter model)
    quarter: bool = True
    steps: int = 2
    refinement: int = 0
    facets_per_radius: int = 6  # over Hertz's contact radius a
    flat_size_ratio: float = 1.3
    max_element_size: float = 1.0  # over the sphere's radius, times 10 (the bulk's elements)
    growth: float = 0.3
    sphere_cells: str = "hex"  # or "tet"
    flat_cells: str = "hex"
    order: int = 1  # 2: quadratic tetrahedra (both cells "tet"), the sphere's midpoints on it
    swap_bodies: bool = False
    equilibrium_tolerance: float = 1e-3


Parameters = SphereParameters

#: ``vfem verify --slow``: the mesh refined once (12 facets across a, 92 172 dofs)
VERIFY_SLOW = ("refinement=1",)


def theory(p: SphereParameters) -> dict[str, float]:
    """Hertz's contact radius and peak pressure for the force on the whole sphere."""
    e1 = LinearElastic(p.sphere_youngs_modulus, p.sphere_poissons_ratio)
    e2 = LinearElastic(p.flat_youngs_modulus, p.flat_poissons_ratio)
    e_star = 1.0 / (1.0 / e1.plane_strain_modulus() + 1.0 / e2.plane_strain_modulus())
    if not (p.force > 0 and p.radius > 0 and e_star > 0):  # (a complex cube root otherwise)
        raise ValueError("Hertz's theory needs a positive force, radius and E*")
    a = (3.0 * p.force * p.radius / (4.0 * e_star)) ** (1.0 / 3.0)
    return {"a_theory": a, "p0_theory": 3.0 * p.force / (2.0 * math.pi * a * a), "e_star": e_star}


def validate(p: SphereParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    for name in ("force", "radius"):
        value = getattr(p, name)
        if not (isinstance(value, (int, float)) and 0 < value < math.inf):
            raise InputError(f"{name} must be a finite number > 0 (the sphere is pressed onto "
                             f"the flat), got {value!r}")
    check_resolution("facets_per_radius", p.facets_per_radius, "radius", p.refinement)
    for name in ("sphere_cells", "flat_cells"):
        if getattr(p, name) not in ("hex", "tet"):
            raise InputError(f"{name} must be 'hex' or 'tet', got {getattr(p, name)!r}")
    if p.order not in (1, 2):
        raise InputError(f"order must be 1 or 2, got {p.order!r}")
    if p.order == 2 and (p.sphere_cells, p.flat_cells) != ("tet", "tet"):
        raise InputError("order = 2 (quadratic elements) needs sphere_cells = 'tet' and "
                         "flat_cells = 'tet': 3D contact of quadratic hexahedra is not "
                         "implemented")
    build(p).validate()


def config(p: SphereParameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/sphere.toml`` holds for the defaults)."""
    p = p or SphereParameters()
    try:
        th = theory(p) if p.sphere_youngs_modulus > 0 and p.flat_youngs_modulus > 0 else None
    except (ValueError, ArithmeticError):
        th = None
    R = p.radius
    a = th["a_theory"] if th and th["a_theory"] > 0 else 0.1 * R
    n = p.facets_per_radius * 2 ** p.refinement
    h = a / n
    h_max = 0.1 * R * p.max_element_size / 2 ** p.refinement
    quarter = bool(p.quarter)
    rollers = (Support("left", ("x",)), Support("front", ("y",))) if quarter else ()
    # quadratic: the midpoints of the spherical end's edges on the sphere (straight-sided
    # quadratic tetrahedra make it a polyhedron, whose creases the quadratic traction
    # resolves: corners 2.3 p0 at a/4; mesh.quadratic.curved)
    curve = Curve("contact", (0.0, 0.0, R), R) if p.order == 2 else None
    sphere = BodyConfig(
        name="sphere",
        mesh=MeshSpec(shape="cylinder", curve=curve, parameters=as_parameters(
            radius=CYLINDER_RADIUS * R, height=CYLINDER_HEIGHT * R, end_radius=R,
            quarter=quarter, h_contact=h, h=h_max, growth=p.growth, plateau=PLATEAU * a,
            tetrahedra=p.sphere_cells == "tet")),
        order=p.order,
        material=LinearElastic(p.sphere_youngs_modulus, p.sphere_poissons_ratio),
        supports=(Support("top", ("x", "y")), *rollers),
        platen=Platen("top", "z", -p.force / (4.0 if quarter else 1.0)),
        contact_boundaries=("contact",),
    )
    L, D = FLAT_HALF_WIDTH * R, FLAT_DEPTH * R
    flat = BodyConfig(
        name="flat",
        mesh=MeshSpec(shape="box", parameters=as_parameters(
            x0=0.0 if quarter else -L, y0=0.0 if quarter else -L, z0=-D,
            width=L if quarter else 2 * L, depth=L if quarter else 2 * L, height=D,
            h=2.0 * h_max, h_fine=p.flat_size_ratio * h, growth=p.growth, fine_x=(0.0,),
            fine_y=(0.0,), fine_z=(0.0,), plateau=PLATEAU * a,
            tetrahedra=p.flat_cells == "tet")),
        material=LinearElastic(p.flat_youngs_modulus, p.flat_poissons_ratio),
        supports=(Support("bottom"), *rollers),
        contact_boundaries=("top",),
        order=p.order,
    )
    bodies = (flat, sphere) if p.swap_bodies else (sphere, flat)
    settings = ContactSettings(equilibrium_tolerance=p.equilibrium_tolerance)
    return ModelConfig("sphere", bodies, settings, Steps(count=p.steps))


def build(p: SphereParameters | None = None) -> Model:
    return config(p).build()


def cut_edges(mesh, boundary: str, touching: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ends (two node arrays) of the facet edges on ``boundary`` that join a node in
    contact (``touching``, per mesh node) to one that is not."""
    facets = mesh.facets[:, mesh.boundaries[boundary]]
    # a facet's edges: consecutive nodes (quadrilaterals in cyclic order; a triangle's three)
    a = facets.ravel()
    b = np.roll(facets, -1, axis=0).ravel()
    cut = touching[a] != touching[b]
    return a[cut], b[cut]


def contour(mesh, boundary: str, touching: np.ndarray) -> np.ndarray:
    """The contact zone's edge on ``boundary``: the midpoints (x, y) of the boundary facets'
    edges that join a node in contact (``touching``, per mesh node) to one that is not."""
    a, b = cut_edges(mesh, boundary, touching)
    return 0.5 * (mesh.p[:2, a] + mesh.p[:2, b]).T


def contour_edge(mesh, boundary: str, touching: np.ndarray) -> float:
    """The longest of the facet edges whose midpoints :func:`contour` reads as the contact
    zone's edge (0 when none): each midpoint lies within half of it of where the zone ends, so
    it bounds how far a round zone's edge, read there, can seem from a circle."""
    a, b = cut_edges(mesh, boundary, touching)
    return float(np.linalg.norm(mesh.p[:, a] - mesh.p[:, b], axis=0).max(initial=0.0))


def evaluate(result: AnalysisResult, p: SphereParameters) -> dict:
    """Compare the last step with Hertz: peak pressure, contact radius and its roundness, RMS
    error, total force. Pressures are nominal (the sphere's nodal contact force over its
    undeformed tributary area)."""
    th = theory(p)
    a, p0 = th["a_theory"], th["p0_theory"]
    last = result.steps[-1]
    share = 4.0 if p.quarter else 1.0
    out = {"p0_theory": p0, "a_theory": a, "applied_force": p.force}
    for name in ("sphere", "flat"):
        body = next(b for b in result.model.bodies if b.name == name)
        r = last.bodies[name]
        boundary = "contact" if name == "sphere" else "top"
        on = r.contact_status > 0
        x = body.mesh.p
        rr = np.hypot(x[0], x[1])
        surface = np.unique(body.mesh.facets[:, body.mesh.boundaries[boundary]])
        edge = np.hypot(*contour(body.mesh, boundary, on).T)
        inside = surface[rr[surface] < a]
        p_theory = p0 * np.sqrt(np.clip(1 - (rr[inside] / a) ** 2, 0, None))
        rms = float(np.sqrt(np.mean((r.contact_pressure[inside] - p_theory) ** 2)) / p0)
        up = 1.0 if name == "sphere" else -1.0
        out[name] = {
            "p_max": float(r.contact_pressure.max()),
            "p_max_error": float(r.contact_pressure.max() / p0 - 1),
            "a_estimate": float(edge.mean()) if len(edge) else 0.0,
            "contour_spread": float(edge.max() - edge.min()) if len(edge) else 0.0,
            "contour_edge": contour_edge(body.mesh, boundary, on),
            "rms_error_over_p0": rms,
            "total_contact_force": float(up * share * r.contact_force[:, 2].sum()),
            "contact_nodes": int(on.sum()),
        }
    # invariant (a)'s scale for the whole's forces: the larger body's total contact force on the
    # modelled part (all three components), times the share
    out["largest_body_contact_force"] = share * max(
        float(np.linalg.norm(last.bodies[name].contact_force.sum(axis=0)))
        for name in ("sphere", "flat"))
    n = p.facets_per_radius * 2 ** p.refinement
    out["facet_size"] = a / n
    out["flat_facet_size"] = p.flat_size_ratio * a / n
    return out


def summarize(result: AnalysisResult, p: SphereParameters) -> dict:
    """The ``summary.json`` dictionary of a sphere run: :func:`~vfem.io.results.example_summary`
    with the platen's motion per step, the bodies' sizes and, at full load, ``hertz``."""
    from vfem.io.results import solid_summary

    summary = solid_summary("sphere", result, p, "hertz", evaluate)
    for record, step in zip(summary["steps"], result.steps):
        record["platen_displacement"] = step.platen_displacement
    if result.converged and "hertz" in summary:  # converged at full load
        summary["verification"] = verification(summary["hertz"], p, result.model.contact)
    return summary


#: Hertz's closed form for a sphere on a flat (the source of a and p0)
HERTZ = "Hertz (sphere on a flat)"


def verification(h: dict, p: SphereParameters, settings: ContactSettings) -> list[dict]:
    """The sphere run's checks (``summary.json``'s ``verification``;
    :mod:`vfem.io.verification`) against Hertz's sphere on a flat (Johnson, *Contact
    Mechanics*, §4.2), its own load and Newton's third law. The tolerances: the peak pressure's
    discretisation error falls about as (h/a)^2 (docs/examples.md's refinement study: -2.21,
    -1.33, -0.50 % at a/6, a/8, a/12, i.e. 0.80, 0.85 and 0.72 (h/a)^2); it is allowed (h/a)^2,
    h the sphere's contact facet: 1.18 to 1.39 times the study's coefficients, an empirical
    margin over them, not a bound; the contact radius is read at the midpoints of the facet
    edges between touching and free nodes, within a facet of the zone's end; Hertz's zone is a
    circle, and each of those midpoints lies within half its edge of the zone's end, so the
    edge's radius varies around it by at most the longest such edge; the platen's force is met
    to the model's ``contact.platen_tolerance`` (``settings``), and the flat's contact forces
    are the sphere's, equal and opposite (invariant (a), :func:`vfem.io.verification.balance`).
    """
    from vfem.io.verification import balance, check, platen

    sph = h["sphere"]
    a, facet = h["a_theory"], h["facet_size"]
    whole = "whole sphere: 4 x the quarter model's" if p.quarter else "whole sphere"
    return [
        check("peak pressure p_max (the sphere's)", sph["p_max"], h["p0_theory"], HERTZ,
              (facet / a) ** 2,
              "discretisation: falls about as (h/a)^2, 0.80, 0.85 and 0.72 (h/a)^2 at a/6, a/8, "
              "a/12 (docs/examples.md's refinement study); allowed (h/a)^2, h the sphere's "
              "facet: 1.18-1.39 times the study's coefficients, an empirical margin"),
        check("contact radius (the edge's mean radius)", sph["a_estimate"], a, HERTZ, facet,
              "the edge is read between the last node in contact and the next: one facet (h)",
              measure="absolute"),
        check("contact edge's roundness (radius max - min)", sph["contour_spread"], 0.0,
              "Hertz (a round contact zone)", sph["contour_edge"],
              "each point of the edge is read within half a facet edge of the zone's end: "
              "the longest edge it crosses", measure="absolute"),
        platen(f"contact force on the sphere ({whole})", sph["total_contact_force"],
               h["applied_force"], settings),
        balance(f"contact force on the flat ({whole})", h["flat"]["total_contact_force"],
                sph["total_contact_force"], "the sphere's, equal and opposite",
                scale=h["largest_body_contact_force"]),
    ]


def run(p: SphereParameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD per step, ``summary.json`` and the figures to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), figures, on_step, resume)


def figures(folder) -> list[Path]:
    """The figures of a sphere results folder (:class:`vfem.io.replot.Folder`), drawn by the
    run and by ``vfem plot``: ``pressure_map.png``, the sphere's contact pressure over the
    contact zone seen from below, with Hertz's circle r = a; ``pressure.png``, p/p0 against
    r/a at both bodies' contact candidate nodes with Hertz's ellipse; ``deformed.png``, the
    symmetry plane y = 0 near the contact, deformed, true scale."""
    from vfem.io import plots

    s = folder.summary
    if not folder.has_steps or "hertz" not in s:
        return []
    th = s["hertz"]
    a, p0 = th["a_theory"], th["p0_theory"]
    last = folder.steps[-1]
    ra, pp, maps = {}, {}, {}
    for b in last.bodies:
        c = folder.contact(last, b)
        r = np.hypot(c.x[:, 0], c.x[:, 1])
        keep = r < 1.4 * a
        ra[b.name] = r[keep] / a
        pp[b.name] = c.pressure[keep] / p0
        maps[b.name] = (c.x[keep, 0] / a, c.x[keep, 1] / a, c.pressure[keep] / p0)
    out = folder.directory
    model = "quarter model" if s["parameters"].get("quarter", True) else "whole sphere"
    sph = th["sphere"]
    plots.hertz_pressure(out / "pressure.png", ra, pp,
                         f"Hertz sphere ({model}), {s['dofs']} dofs: p_max "
                         f"{sph['p_max_error']:+.2%} vs p0, RMS {sph['rms_error_over_p0']:.2%}",
                         xlabel="r / a (undeformed radius over Hertz's contact radius; "
                                "dimensionless)", per="area")
    plots.pressure_map(out / "pressure_map.png", *maps["sphere"],
                       f"Sphere: contact pressure p / p0 seen from below ({model})\n"
                       f"dashed: Hertz's r = a; contact edge radius {sph['a_estimate'] / a:.3f} a"
                       f" (spread {sph['contour_spread'] / a:.3f} a)")
    # the contact region in the symmetry plane y = 0 (the whole model: its mid-plane nodes)
    from vfem.io.replot import plane_section

    sections = []
    for b in last.bodies:
        p2, faces, u2 = plane_section(b, 1, 0.0)
        if len(faces):
            sections.append((b.name, p2, faces, u2))
    if sections:
        sph_frame = next(b for b in last.bodies if b.name == "sphere")
        tip = int(np.argmin(np.linalg.norm(sph_frame.points, axis=1)))  # first touch
        z0 = float(sph_frame.displacement[tip, 2])
        plots.configurations(out / "deformed.png", [("deformed", sections)],
                             f"Sphere on a flat ({model}): the plane y = 0 near the contact, "
                             f"true scale (a = {a:.4f})",
                             window=(0.0 if s["parameters"].get("quarter", True) else -2.5 * a,
                                     2.5 * a, z0 - 1.5 * a, z0 + 1.0 * a), magnification=1.0,
                             axes="xz")
        return [out / "pressure.png", out / "pressure_map.png", out / "deformed.png"]
    return [out / "pressure.png", out / "pressure_map.png"]


def report(s: dict) -> list[str]:
    """The closing lines of a sphere run."""
    lines = [run_headline(s, contact_dofs=True)]
    if "hertz" in s:
        h = s["hertz"]
        sph = h["sphere"]
        lines.append(f"  p_max {sph['p_max']:.1f} (theory {h['p0_theory']:.1f}, "
                     f"{sph['p_max_error']:+.3%})   contact radius {sph['a_estimate']:.4f} "
                     f"(theory {h['a_theory']:.4f}; facets {h['facet_size']:.3g})")
        lines.append(f"  RMS error over r < a: {sph['rms_error_over_p0']:.3%} of p0; the edge's "
                     f"radius varies by {sph['contour_spread']:.3g} around the circle")
        lines.append(f"  contact force {sph['total_contact_force']:.2f} on the sphere, "
                     f"{h['flat']['total_contact_force']:.2f} on the flat "
                     f"(applied {h['applied_force']:g})")
    return lines
