"""Yield onset under Hertz's sphere (issue 41's acceptance: "sphere on a flat: p0 = 1.613 Y at
depth 0.481 a — the load at first yield within 2 % and the depth within one element").

The sphere example (``vfem_examples.sphere``: a quarter sphere-ended cylinder on a block, both
E = 200e3, nu = 0.3, meshes graded to the contact) with the flat of J2 material, elastic-
perfectly plastic, Y = p0 / (p0/Y at onset) at the full force, so that Hertz's onset is at load
factor 1; the force is the one whose Hertz radius is ``a_over_r`` R (Hertz's paraboloid and
half-space hold for a << R), the sphere's elements at the contact ``a / facets`` and the flat's
``flat_size_ratio`` times larger (the example's defaults: 6 and 1.3). The load
factors step by 1 % around the onset. Printed per run: the dofs, the last load factor with no
yielded point and the first with one (Hertz's onset: 1), the mean depth of the first yielded
points per a at that load against Huber's, the element size per a, the seconds.

The onset itself: :func:`vfem_examples.sphere_indentation.onset` (von Mises on the axis under
Hertz's pressure, Johnson, *Contact Mechanics*, 1985, eq. 3.45), its largest value and where.
The built-in example ``sphere_indentation`` is this model with a = 0.05 R at the onset on the
sphere example's default mesh, loaded past yield and lifted off.

    python3 benchmarks/sphere_onset.py                      # a = 0.1 R and 0.02 R, a/12
    python3 benchmarks/sphere_onset.py --elastic --a-over-r 0.05 --facets 6 8 --flat-size-ratio 1.3

``--elastic`` runs one elastic step at Hertz's onset force instead and prints the flat's
largest von Mises stress per Y at its Gauss points (where a Newton body keeps its state:
:func:`vfem.nonlinear.gauss_rule`) and at scikit-fem's default points (4 x 4 x 4 a hexahedron),
and the load factor at which each would first yield under Hertz's scaling (stress as the
force^(1/3)): the quadrature's part in the onset, without stepping.
    python3 benchmarks/sphere_onset.py --a-over-r 0.1 0.05 0.02 --facets 6 --flat-size-ratio 1.3
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from vfem.config import Steps
from vfem.materials import J2Plastic
from vfem.solver import Analysis
from vfem_examples import sphere
from vfem_examples.indentation import first_yielded
from vfem_examples.sphere_indentation import onset

#: the load factors (per Hertz's onset force)
LOAD_FACTORS = (0.5, 0.9, 0.94, 0.96, 0.97, 0.98, 0.99, 1.0, 1.01, 1.02, 1.03)


def _model(a_over_r: float, facets: int, flat_size_ratio: float, yield_stress=None,
           load_factors=LOAD_FACTORS):
    """The sphere example's model at a = ``a_over_r`` R with the flat of J2 material (Y at
    Hertz's onset unless ``yield_stress``), its parameters, theory and Y."""
    base = sphere.SphereParameters()
    E_star = sphere.theory(base)["e_star"]
    a = a_over_r * base.radius
    force = 4.0 * E_star * a ** 3 / (3.0 * base.radius)
    p = dataclasses.replace(base, force=force, facets_per_radius=facets,
                            flat_size_ratio=flat_size_ratio)
    th = sphere.theory(p)
    ratio, depth = onset(p.flat_poissons_ratio)
    Y = th["p0_theory"] / ratio
    cfg = sphere.config(p)
    bodies = tuple(dataclasses.replace(b, material=J2Plastic(
        p.flat_youngs_modulus, p.flat_poissons_ratio, yield_stress or Y))
        if b.name == "flat" else b for b in cfg.bodies)
    cfg = dataclasses.replace(cfg, bodies=bodies, steps=Steps(load_factors=load_factors))
    return cfg.build(), p, th, Y


def _von_mises(nl, basis, displacement) -> np.ndarray:
    """The von Mises stress of the flat's (elastic) law at ``basis``'s points."""
    g = basis.interpolate(np.ravel(displacement)).grad
    sigma = nl.material.response(0.5 * (g + np.swapaxes(g, 0, 1)),
                                 nl.material.initial_state(3, g.shape[2:])).stress
    dev = sigma - np.trace(sigma)[None, None] / 3.0 * np.eye(3)[:, :, None, None]
    return np.sqrt(1.5 * np.einsum("ij...,ij...->...", dev, dev))


def elastic(a_over_r: float, facets: int, flat_size_ratio: float) -> dict:
    """One elastic step (Y out of reach) at Hertz's onset force: the flat's largest von Mises
    stress per Y at its Gauss points and at scikit-fem's default points, where, and the
    load factor of first yield each gives under Hertz's scaling."""
    from skfem import Basis, ElementVector

    model, p, th, Y = _model(a_over_r, facets, flat_size_ratio, yield_stress=1e30,
                             load_factors=(1.0,))
    t0 = time.perf_counter()
    result = Analysis(model).run()
    flat = next(b for b in model.bodies if b.name == "flat")
    nl = flat.mechanics.nonlinear
    u = result.steps[-1].bodies["flat"].displacement
    out = {"a_over_r": a_over_r, "facets": facets, "dofs": sum(b.ndofs for b in model.bodies),
           "element_over_a": flat_size_ratio / facets}
    for name, basis in (("gauss", nl.basis0),
                        ("default", Basis(nl.mesh, ElementVector(nl.mesh.elem())))):
        vm = _von_mises(nl, basis, u)
        k = np.unravel_index(vm.argmax(), vm.shape)
        out[name] = {"points": int(vm.shape[1]), "vm_over_Y": float(vm.max() / Y),
                     "onset": float((Y / vm.max()) ** 3),
                     "depth": float(-basis.mapping.F(basis.X)[2][k] / th["a_theory"])}
    out["seconds"] = time.perf_counter() - t0
    return out


def run(a_over_r: float, facets: int, flat_size_ratio: float) -> dict:
    model, p, th, Y = _model(a_over_r, facets, flat_size_ratio)
    ratio, depth = onset(p.flat_poissons_ratio)
    t0 = time.perf_counter()
    result = Analysis(model).run()
    seconds = time.perf_counter() - t0
    out = {"a_over_r": a_over_r, "facets": facets, "dofs": sum(b.ndofs for b in model.bodies),
           "seconds": seconds, "converged": result.converged, "onset_ratio": ratio,
           "onset_depth": depth, "element_over_a": flat_size_ratio / facets}
    if not result.converged:
        out["message"] = result.message
        return out
    steps = result.steps
    first = next((s for s in steps if s.yielded.get("flat", 0) > 0), None)
    if first is None:
        return out
    k = steps.index(first)
    out["first_yield"] = first.load_factor
    out["last_elastic"] = steps[k - 1].load_factor if k else 0.0
    flat = next(b for b in model.bodies if b.name == "flat")
    x, yielded = first_yielded(flat.mechanics.nonlinear, first.bodies["flat"].displacement)
    a_now = th["a_theory"] * first.load_factor ** (1.0 / 3.0)
    out["depth"] = float(-x[2][yielded].mean() / a_now)
    out["points"] = int(yielded.sum())
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--a-over-r", type=float, nargs="+", default=[0.1, 0.02])
    ap.add_argument("--facets", type=int, nargs="+", default=[12],
                    help="the sphere's elements over a (12)")
    ap.add_argument("--flat-size-ratio", type=float, default=1.0,
                    help="the flat's elements at the contact per the sphere's (1.0)")
    ap.add_argument("--elastic", action="store_true",
                    help="one elastic step at the onset force: the largest von Mises per Y")
    args = ap.parse_args(argv)
    ratio, depth = onset(0.3)
    print(f"Hertz's onset (nu = 0.3): p0 = {ratio:.4f} Y at {depth:.4f} a")
    if args.elastic:
        print(f"{'a/R':>6} {'a/h':>4} {'dofs':>7} {'points':>6} {'vm/Y':>7} {'onset':>6} "
              f"{'depth/a':>7} {'s':>5}")
        for a_over_r in args.a_over_r:
            for facets in args.facets:
                r = elastic(a_over_r, facets, args.flat_size_ratio)
                for name in ("gauss", "default"):
                    q = r[name]
                    print(f"{a_over_r:>6g} {facets:>4} {r['dofs']:>7} {q['points']:>6} "
                          f"{q['vm_over_Y']:>7.4f} {q['onset']:>6.3f} {q['depth']:>7.3f} "
                          f"{r['seconds']:>5.0f}", flush=True)
        return 0
    print(f"{'a/R':>6} {'dofs':>7} {'no yield at':>11} {'yield at':>9} {'depth/a':>8} "
          f"{'Huber':>6} {'element/a':>9} {'points':>6} {'s':>6}")
    for a_over_r, facets in ((a, f) for a in args.a_over_r for f in args.facets):
        # the sphere's elements a/facets, the flat's flat_size_ratio times larger
        r = run(a_over_r, facets, args.flat_size_ratio)
        if "first_yield" not in r:
            print(f"{a_over_r:>6g} {r['dofs']:>7} no yield: {r.get('message', '')}")
            continue
        print(f"{a_over_r:>6g} {r['dofs']:>7} {r['last_elastic']:>11.2f} {r['first_yield']:>9.2f} "
              f"{r['depth']:>8.3f} {r['onset_depth']:>6.3f} {r['element_over_a']:>9.3f} "
              f"{r['points']:>6} {r['seconds']:>6.0f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
