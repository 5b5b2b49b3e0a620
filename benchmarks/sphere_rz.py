"""Hertz's sphere as a body of revolution against the 3D sphere example (issue 42's
acceptance: the axisymmetric sphere's p0 and a against Hertz's, and against the 3D sphere on
equivalent meshes at a tenth or less of its time).

The 3D example (``vfem_examples.sphere``: R = 10, P = 15,000, a = 0.1 R, both bodies E = 200e3,
nu = 0.3; the quarter model) and, by default, its **section** in r-z (``plane =
"axisymmetric"``, the force P per full circle): the sphere's body the r-z section of the 3D
one, a cylinder 0.6 R wide and 0.5 R high whose end is the sphere of radius R, meshed node for
node as the 3D cylinder's plane y = 0 (the ``cylinder_section`` shape, the ``cylinder``
shape's grid: elements a / N within 1.2 a of the axis and of the end, growing by 0.3 per unit
distance up to 0.1 R), held radially on its top and pressed by a platen there, the axis a
roller; the flat the 3D box's section, R wide and R deep (the ``block`` shape: 1.3 a / N within
1.2 a of the axis and of the surface, growing by 0.3 up to 0.2 R), fixed on its bottom; the 3D
example's contact settings and two load steps. ``--hemisphere``: also the r-z model before it
(the ``axisymmetric_sphere`` example's: the Hertz example's quarter disk as a hemisphere of
R = 1 on a ``block`` flat R x R graded by 0.15 up to 0.1 R, one step), only alike to the 3D
one. ``--order``: the r-z elements (linear by default, as the 3D example's hexahedra).

Printed per N: each model's dofs, seconds, the sphere's peak nodal pressure against p0 =
3P / 2 pi a^2 and its contact radius against Hertz's a (r-z: midway between the outermost
sphere node in contact and the next one out along the surface; 3D: the example's own reading,
the mean radius of the midpoints of the surface edges from a node in contact to one that is
not), the differences 3D - r-z (in % of p0 and of a) and the time ratio. Both readings are
of single nodes: the peak is the highest node, wherever the mesh puts it, and the edge lies
within half a facet (a / 2N) of where the contact ends. ``--fit`` reads the whole zone
instead: p0 and a of Hertz's ellipse p^2 = p0^2 (1 - r^2/a^2) fitted to the sphere's nodal
pressures at 0 < r < 0.8 a.

    python3 benchmarks/sphere_rz.py --facets 6 8 12 16         # r-z only
    python3 benchmarks/sphere_rz.py --facets 6 8 12 --3d       # and the 3D example
    python3 benchmarks/sphere_rz.py --facets 6 8 12 --3d --hemisphere   # the older r-z model too
    python3 benchmarks/sphere_rz.py --facets 6 8 12 --3d --fit          # fitted p0 and a
    python3 benchmarks/sphere_rz.py --facets 6 8 12 --3d --nodes        # where the peaks are
    python3 benchmarks/sphere_rz.py --facets 6 8 --3d --disk-flat       # 3D on a round flat
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

import vfem
from vfem.bodies import Platen, Support
from vfem.config import BodyConfig, Curve, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.materials import LinearElastic
from vfem_examples import axisymmetric_sphere, hertz, sphere


def section(facets: int, order: int = 1) -> tuple[ModelConfig, float, float]:
    """The 3D sphere example's section in r-z, the sphere's elements a / ``facets`` at the
    contact: the model, Hertz's a and p0."""
    p = dataclasses.replace(sphere.SphereParameters(), facets_per_radius=facets)
    th = sphere.theory(p)
    R, a = p.radius, th["a_theory"]
    h, h_max = a / facets, 0.1 * R * p.max_element_size  # as sphere.config
    ball = BodyConfig(
        name="sphere",
        mesh=MeshSpec(shape="cylinder_section", curve=(
            Curve("contact", (0.0, R), R) if order == 2 else None),
            parameters=as_parameters(
                radius=sphere.CYLINDER_RADIUS * R, height=sphere.CYLINDER_HEIGHT * R,
                end_radius=R, h_contact=h, h=h_max, growth=p.growth,
                plateau=sphere.PLATEAU * a)),
        material=LinearElastic(p.sphere_youngs_modulus, p.sphere_poissons_ratio,
                               plane="axisymmetric"),
        supports=(Support("top", ("x",)), Support("left", ("x",))),
        platen=Platen("top", "y", -p.force),  # per full circle
        contact_boundaries=("contact",), order=order)
    L, D = sphere.FLAT_HALF_WIDTH * R, sphere.FLAT_DEPTH * R
    flat = BodyConfig(
        name="flat",
        mesh=MeshSpec(shape="block", parameters=as_parameters(
            x0=0.0, y0=-D, width=L, height=D, h=2.0 * h_max, h_fine=p.flat_size_ratio * h,
            growth=p.growth, fine_x=(0.0,), fine_y=(0.0,), plateau=sphere.PLATEAU * a,
            symmetry="left")),
        material=LinearElastic(p.flat_youngs_modulus, p.flat_poissons_ratio,
                               plane="axisymmetric"),
        supports=(Support("bottom", ("x", "y")), Support("symmetry", ("x",))),
        contact_boundaries=("top",), order=order)
    settings = ContactSettings(equilibrium_tolerance=p.equilibrium_tolerance)
    return (ModelConfig("sphere_rz", (ball, flat), settings, Steps(count=p.steps)), a,
            th["p0_theory"])


def hemisphere(facets: int, order: int = 1, ratio: float = 1.3
               ) -> tuple[ModelConfig, float, float]:
    """The earlier r-z model (a unit hemisphere, the Hertz example's quarter disk, on a flat
    disk R wide and deep), the sphere's elements a / ``facets``: the model, a and p0."""
    s3 = sphere.SphereParameters()
    th3 = sphere.theory(s3)
    R, a, e_star = 1.0, th3["a_theory"] / s3.radius, th3["e_star"]
    p = hertz.HertzParameters(
        radius=R, cylinder_youngs_modulus=s3.sphere_youngs_modulus,
        cylinder_poissons_ratio=s3.sphere_poissons_ratio,
        flat_youngs_modulus=s3.flat_youngs_modulus, flat_poissons_ratio=s3.flat_poissons_ratio,
        force=a * a * math.pi * e_star / (8 * R),  # grades the disk's mesh to a
        facets_per_half_width=facets, steps=1, order=order)
    P = 4.0 * e_star * a ** 3 / (3.0 * R)
    base = hertz.config(p)
    ball = next(b for b in base.bodies if b.name == "cylinder")
    ball = dataclasses.replace(
        ball, name="sphere", material=dataclasses.replace(ball.material, plane="axisymmetric"),
        platen=dataclasses.replace(ball.platen, force=-P))
    flat = BodyConfig(
        name="flat", mesh=MeshSpec(shape="block", parameters=as_parameters(
            x0=0.0, y0=-R, width=R, height=R, h=0.1 * R, h_fine=ratio * a / facets,
            growth=0.15, fine_x=(0.0,), fine_y=(0.0,), plateau=1.5 * a, symmetry="left")),
        material=LinearElastic(s3.flat_youngs_modulus, s3.flat_poissons_ratio,
                               plane="axisymmetric"),
        supports=(Support("bottom", ("x", "y")), Support("symmetry", ("x",))),
        contact_boundaries=("top",), order=order)
    return dataclasses.replace(base, bodies=(ball, flat)), a, 3.0 * P / (2.0 * math.pi * a * a)


def edge(result, name: str = "sphere", boundary: str = "contact") -> float:
    """The r-z contact's edge on body ``name``: midway between its outermost node of
    ``boundary`` in contact and the next node of it farther out (the facets' end nodes)."""
    body = next(b for b in result.model.bodies if b.name == name)
    mesh = body.mesh
    nodes = np.unique(mesh.facets[:, mesh.boundaries[boundary]])
    on = result.steps[-1].bodies[name].contact_status[: mesh.p.shape[1]] > 0
    r = mesh.p[0]
    inside = r[nodes[on[nodes]]].max(initial=0.0)
    beyond = r[nodes][r[nodes] > inside]
    return float(0.5 * (inside + beyond.min())) if beyond.size else float(inside)


def axisymmetric(facets: int, order: int = 1, model: str = "section") -> dict:
    """The r-z sphere (``model``: "section" or "hemisphere"), its elements a / ``facets``."""
    config, a, p0 = (section if model == "section" else hemisphere)(facets, order)
    t0 = time.perf_counter()
    result = vfem.solve(config)
    seconds = time.perf_counter() - t0
    r = result.steps[-1].bodies["sphere"]
    p0_fit, a_fit = axisymmetric_sphere.hertz_fit(result, a)
    mesh = next(b for b in result.model.bodies if b.name == "sphere").mesh
    nodes = np.unique(mesh.facets[:, mesh.boundaries["contact"]])
    nodes = nodes[np.argsort(mesh.p[0, nodes])]  # the axis node first, then r = h
    return {"dofs": sum(b.ndofs for b in result.model.bodies), "seconds": seconds,
            "converged": result.converged, "p_max_error": float(r.contact_pressure.max() / p0 - 1),
            "a_error": edge(result) / a - 1, "p0_fit_error": p0_fit / p0 - 1,
            "a_fit_error": a_fit / a - 1,
            "nodes": {"axis": r.contact_pressure[nodes[0]] / p0 - 1,
                      "r = h": r.contact_pressure[nodes[1]] / p0 - 1}}


def disk_flat(config: ModelConfig, p: sphere.SphereParameters) -> ModelConfig:
    """The 3D example with its flat's plan a quarter disk R in radius, not the box's square
    (the ``cylinder`` shape, flat-ended, graded towards its top: within half its radius the
    box's grid lines, node for node), R deep, fixed below: the r-z flat's solid of revolution."""
    R, a = p.radius, sphere.theory(p)["a_theory"]
    h, h_max = a / p.facets_per_radius, 0.1 * R * p.max_element_size
    flat = next(b for b in config.bodies if b.name == "flat")
    flat = dataclasses.replace(
        flat, mesh=MeshSpec(shape="cylinder", parameters=as_parameters(
            radius=sphere.FLAT_HALF_WIDTH * R, height=sphere.FLAT_DEPTH * R,
            z0=-sphere.FLAT_DEPTH * R, h_contact=p.flat_size_ratio * h, h=2.0 * h_max,
            growth=p.growth, plateau=sphere.PLATEAU * a, graded_end="top")),
        supports=(Support("contact"), Support("left", ("x",)), Support("front", ("y",))))
    return dataclasses.replace(config, bodies=tuple(flat if b.name == "flat" else b
                                                    for b in config.bodies))


def solid(facets: int, disk: bool = False) -> dict:
    """The 3D sphere example with the sphere's facets a / ``facets`` (``disk``: on a flat
    whose plan is a disk, :func:`disk_flat`)."""
    p = dataclasses.replace(sphere.SphereParameters(), facets_per_radius=facets)
    config = sphere.config(p)
    t0 = time.perf_counter()
    result = vfem.solve(disk_flat(config, p) if disk else config)
    seconds = time.perf_counter() - t0
    h = sphere.evaluate(result, p)
    a, p0 = h["a_theory"], h["p0_theory"]
    p0_fit, a_fit = axisymmetric_sphere.hertz_fit(result, a)
    # the nodes on the axis, at (h, 0) (in the plane y = 0: r-z's node at r = h) and at (h, h)
    mesh = next(b for b in result.model.bodies if b.name == "sphere").mesh
    nodes = np.unique(mesh.facets[:, mesh.boundaries["contact"]])
    x, y = mesh.p[0, nodes], mesh.p[1, nodes]
    step = x[(y == 0.0) & (x > 0.0)].min()
    pressure = result.steps[-1].bodies["sphere"].contact_pressure
    at = lambda u, v: pressure[nodes[np.argmin(np.hypot(x - u, y - v))]] / p0 - 1  # noqa: E731
    return {"dofs": sum(b.ndofs for b in result.model.bodies), "seconds": seconds,
            "converged": result.converged, "p_max_error": h["sphere"]["p_max_error"],
            "a_error": h["sphere"]["a_estimate"] / a - 1, "p0_fit_error": p0_fit / p0 - 1,
            "a_fit_error": a_fit / a - 1,
            "nodes": {"axis": at(0.0, 0.0), "(h, 0)": at(step, 0.0),
                      "(h, h)": at(step, step)}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--facets", type=int, nargs="+", default=[6, 8, 12])
    ap.add_argument("--order", type=int, default=1, help="the r-z model's elements (1 or 2)")
    ap.add_argument("--3d", dest="solid", action="store_true", help="run the 3D example too")
    ap.add_argument("--hemisphere", action="store_true",
                    help="the earlier r-z model too (a hemisphere on a flat disk), a row of its "
                         "own beside the section's, against the same 3D run")
    ap.add_argument("--disk-flat", action="store_true",
                    help="the 3D flat's plan a quarter disk R in radius (the cylinder shape), "
                         "not the box's square: the r-z flat's solid of revolution")
    ap.add_argument("--nodes", action="store_true",
                    help="also the sphere's nodal pressures at the axis and the next node out "
                         "(r-z: r = h; 3D: (h, 0) and (h, h)), in %% of p0")
    ap.add_argument("--fit", action="store_true",
                    help="p0 and a of Hertz's ellipse fitted to the nodal pressures (r < 0.8 a) "
                         "instead of the peak node and the contact's edge")
    args = ap.parse_args(argv)
    models = ("section", "hemisphere") if args.hemisphere else ("section",)
    p_key, a_key = ("p0_fit_error", "a_fit_error") if args.fit else ("p_max_error", "a_error")
    print(f"r-z order {args.order}; p: "
          + ("fitted p0" if args.fit else "peak nodal pressure p_max") + " / Hertz's p0 - 1, a: "
          + ("fitted a" if args.fit else "the contact's edge") + " / Hertz's a - 1")
    print(f"{'a/h':>4} {'r-z model':>10} {'dofs':>6} {'s':>6} {'p':>7} {'a':>7}"
          + (f" {'3D dofs':>8} {'s':>6} {'p':>7} {'a':>7} {'3D-rz p':>7} {'3D-rz a':>7}"
             f" {'time ratio':>10}" if args.solid else ""))
    for n in args.facets:
        rows = [(m, axisymmetric(n, args.order, m)) for m in models]
        s = solid(n, args.disk_flat) if args.solid else None
        for model, rz in rows:
            line = (f"{n:>4} {model:>10} {rz['dofs']:>6} {rz['seconds']:>6.2f}"
                    f" {100 * rz[p_key]:>+6.2f}% {100 * rz[a_key]:>+6.2f}%")
            if s is not None:
                line += (f" {s['dofs']:>8} {s['seconds']:>6.1f} {100 * s[p_key]:>+6.2f}%"
                         f" {100 * s[a_key]:>+6.2f}% {100 * (s[p_key] - rz[p_key]):>+6.2f}%"
                         f" {100 * (s[a_key] - rz[a_key]):>+6.2f}%"
                         f" {s['seconds'] / rz['seconds']:>10.0f}")
                if not s["converged"]:
                    line += " (3D not converged)"
            if not rz["converged"]:
                line += " (r-z not converged)"
            print(line, flush=True)
            if args.nodes:
                print(f"{'':>11} {model} nodes: " + ", ".join(
                    f"{k} {100 * v:+.2f}%" for k, v in rz["nodes"].items()))
        if args.nodes and s is not None:
            print(f"{'':>11} 3D nodes: " + ", ".join(
                f"{k} {100 * v:+.2f}%" for k, v in s["nodes"].items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
