"""What the O-ring example's force depends on: the section (the ring, or a straight cord in
plane strain, Lindley's setting), Poisson's ratio (the linear quadrilaterals' volumetric
locking as nu -> 1/2) and the mesh, against Lindley's relation (``vfem_examples.oring``).

For each combination the ``oring`` example's model is solved (the same groove, lid, friction and
steps) and the lid's force per unit circumference (per unit length in plane strain) is printed
at each compression beside Lindley's, with their ratio; then the contact width and the peak
pressure at the last step, and the run's seconds.

    python3 benchmarks/oring_study.py                      # the default sweep
    python3 benchmarks/oring_study.py --nu 0.49 --elements 20 40 80 --section axisymmetric
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import vfem
from vfem_examples import oring


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--section", nargs="+", default=["axisymmetric", "plane strain"],
                    choices=list(oring.SECTIONS))
    ap.add_argument("--nu", nargs="+", type=float, default=[0.45, 0.49])
    ap.add_argument("--elements", nargs="+", type=int, default=[20, 40],
                    help="the ring's elements across its cross-section")
    ap.add_argument("--friction", type=float, default=oring.ORingParameters.friction)
    args = ap.parse_args(argv)
    print("section        nu     n  | F/L over Lindley's at each compression | "
          "width/d  p_max/E at the last |   s")
    for section in args.section:
        for nu in args.nu:
            for n in args.elements:
                p = dataclasses.replace(oring.ORingParameters(), section=section,
                                        poissons_ratio=nu, elements_across=n,
                                        friction=args.friction)
                t0 = time.perf_counter()
                result = vfem.solve(oring.config(p))
                seconds = time.perf_counter() - t0
                if not result.converged:
                    print(f"{section:13s} {nu:5.3f} {n:4d}  | did not converge: "
                          f"{result.message}")
                    continue
                m = oring.evaluate(result, p)
                ratios = "  ".join(f"{100 * r['compression']:.0f}%: "
                                   f"{r['force_per_length'] / r['lindley']:.3f}"
                                   for r in m["steps"])
                last = m["steps"][-1]
                print(f"{section:13s} {nu:5.3f} {n:4d}  | {ratios} | "
                      f"{last['contact_width'] / p.cross_section:.3f}  "
                      f"{last['peak_pressure'] / p.youngs_modulus:.3f} | {seconds:5.1f}",
                      flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
