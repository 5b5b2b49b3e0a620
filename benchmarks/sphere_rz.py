"""Hertz's sphere as a body of revolution against the 3D sphere example (issue 42's
acceptance: the axisymmetric sphere's p0 and a against Hertz's, and against the 3D sphere on
equivalent meshes at a tenth or less of its time).

The 3D example (``vfem_examples.sphere``: a = 0.1 R, both bodies E = 200e3, nu = 0.3, the
sphere's facets a / N at the contact, the flat's 1.3 times larger) and, in r-z on a unit
sphere (Hertz is scale-free), the Hertz example's quarter disk read as a hemisphere
(``plane = "axisymmetric"``) pressed by the sphere's force P = 4 E* a^3 / 3R (per full circle)
onto a flat disk R wide and deep graded in width *and* depth (the ``block`` shape of the
``block_indentation`` example: the Hertz example's own flat, two element rows through a thin
layer, is far too stiff for a compliant flat), elements a / N at the sphere's contact and 1.3
a / N on the flat. Printed per N: each model's dofs, seconds, the sphere's peak nodal
pressure against p0 = 3P / 2 pi a^2, and the time ratio.

    python3 benchmarks/sphere_rz.py --facets 6 8 12            # r-z only
    python3 benchmarks/sphere_rz.py --facets 6 8 12 --3d       # and the 3D example
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import vfem
from vfem.bodies import Support
from vfem.config import BodyConfig, MeshSpec, as_parameters
from vfem.materials import LinearElastic
from vfem_examples import hertz, sphere


def axisymmetric(facets: int, order: int = 1, ratio: float = 1.3) -> dict:
    """The r-z sphere with the sphere's elements a / ``facets`` at the contact."""
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
        ball, material=dataclasses.replace(ball.material, plane="axisymmetric"),
        platen=dataclasses.replace(ball.platen, force=-P))
    flat = BodyConfig(
        name="flat", mesh=MeshSpec(shape="block", parameters=as_parameters(
            x0=0.0, y0=-R, width=R, height=R, h=0.1 * R, h_fine=ratio * a / facets,
            growth=0.15, fine_x=(0.0,), fine_y=(0.0,), plateau=1.5 * a, symmetry="left")),
        material=LinearElastic(s3.flat_youngs_modulus, s3.flat_poissons_ratio,
                               plane="axisymmetric"),
        supports=(Support("bottom", ("x", "y")), Support("symmetry", ("x",))),
        contact_boundaries=("top",), order=order)
    t0 = time.perf_counter()
    result = vfem.solve(dataclasses.replace(base, bodies=(ball, flat)))
    seconds = time.perf_counter() - t0
    r = result.steps[-1].bodies["cylinder"]
    p0 = 3.0 * P / (2.0 * math.pi * a * a)
    return {"dofs": sum(b.ndofs for b in result.model.bodies), "seconds": seconds,
            "converged": result.converged, "p_max_error": float(r.contact_pressure.max() / p0 - 1)}


def solid(facets: int) -> dict:
    """The 3D sphere example with the sphere's facets a / ``facets``."""
    p = dataclasses.replace(sphere.SphereParameters(), facets_per_radius=facets)
    t0 = time.perf_counter()
    result = vfem.solve(sphere.config(p))
    seconds = time.perf_counter() - t0
    r = result.steps[-1].bodies["sphere"]
    return {"dofs": sum(b.ndofs for b in result.model.bodies), "seconds": seconds,
            "converged": result.converged,
            "p_max_error": float(r.contact_pressure.max() / sphere.theory(p)["p0_theory"] - 1)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--facets", type=int, nargs="+", default=[6, 8, 12])
    ap.add_argument("--order", type=int, default=1, help="the r-z model's elements (1 or 2)")
    ap.add_argument("--3d", dest="solid", action="store_true", help="run the 3D example too")
    args = ap.parse_args(argv)
    print(f"{'a/h':>4} {'r-z dofs':>8} {'s':>6} {'p_max':>8}"
          + (f" {'3D dofs':>8} {'s':>7} {'p_max':>8} {'3D-r-z':>7} {'time ratio':>10}"
             if args.solid else ""))
    for n in args.facets:
        rz = axisymmetric(n, args.order)
        line = (f"{n:>4} {rz['dofs']:>8} {rz['seconds']:>6.2f} {100 * rz['p_max_error']:>+7.2f}%")
        if args.solid:
            s = solid(n)
            line += (f" {s['dofs']:>8} {s['seconds']:>7.1f} {100 * s['p_max_error']:>+7.2f}%"
                     f" {100 * (s['p_max_error'] - rz['p_max_error']):>+6.2f}%"
                     f" {s['seconds'] / rz['seconds']:>10.0f}")
        print(line, flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
