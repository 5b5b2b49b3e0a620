"""The matrix-free contact correction against the dense one on growing contact zones (issue 22).

The model is the ``stack`` example as a flange-like pair of plates (two plates 0.1 thick,
the upper 20 % narrower, its whole face in contact; 3D, trilinear hexahedra, non-matching
meshes): ``divisions`` elements across the lower plate, so about ``3 ((n + 1)^2 + (n + 2)^2)``
contact dofs. Each route of each size runs in its own process (its peak resident memory is its
own), and the two routes' displacements and contact forces are compared (largest difference over
the largest value):

    python3 benchmarks/matrix_free.py                      # 18 40 70: about 2k, 10k, 30k
    python3 benchmarks/matrix_free.py --divisions 100 130 --routes matrix_free
    python3 benchmarks/matrix_free.py --json out.json

    python3 benchmarks/matrix_free.py --divisions 40 --routes matrix_free --preconditioner diagonal
    python3 benchmarks/matrix_free.py --divisions 30 --layers 10 --thickness 0.5   # thick plates

Columns: contact dofs, the pair unknowns m (the compatibility side's nodes and the other side's
held ones), set-up seconds (assembly, factorization and, dense, the Schur complement and its
inverse), contact seconds, total, peak MiB, W's columns applied (matrix-free: GMRES's
products and the columns of the small sets formed at once), the GMRES solves, their products
each (mean and largest: the iterations per solve, issue 40), and the relative difference
between the routes.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np


def one(divisions: int, route: str, out: str, preconditioner: str | None = None,
        layers: int = 2, thickness: float = 0.1) -> None:
    """Run one size on one route in this process; write its figures and answers to ``out``."""
    from vfem.contact.solvers import matrix_free
    from vfem.solver import Analysis
    from vfem_examples import stack

    if preconditioner is not None:
        matrix_free.PRECONDITIONER = preconditioner

    p = stack.Parameters(blocks=2, divisions=divisions, thickness=thickness, shrink=0.2,
                         press=0.0005, flexibility=route, layers=layers)
    t = time.perf_counter()
    analysis = Analysis(stack.build(p))
    result = analysis.run()
    total = time.perf_counter() - t
    full = analysis.contact._full
    W = None if full is None else full[0]
    history = list(getattr(W, "history", []))  # (unknowns, products, how) per solve
    iterative = [h[1] for h in history if h[2] != "direct"]
    answers = np.concatenate([np.concatenate([b.displacement.ravel(), b.contact_force.ravel()])
                              for b in result.steps[-1].bodies.values()])
    np.save(out + ".npy", answers)
    t = result.timings
    record = {
        "divisions": divisions, "route": result.flexibility, "converged": result.converged,
        "invariants": all(s.invariants["passed"] for s in result.steps),
        "dofs": int(sum(b.ndofs for b in result.model.bodies)),
        "contact_dofs": int(sum(s.dim * s.nc for s in result.surfaces)),
        "m": int(W.m if hasattr(W, "m") else len(W)) if W is not None else 0,
        "applied": int(getattr(W, "applications", 0)) if W is not None else 0,
        "solves": len(history), "gmres_solves": len(iterative),
        "per_solve": float(np.mean(iterative)) if iterative else 0.0,
        "per_solve_max": int(max(iterative)) if iterative else 0,
        "setup_s": t["assemble_factorize_s"] + t["flexibility_s"] + t["search_s"],
        "contact_s": t["contact_s"], "total_s": total,
        "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}
    with open(out + ".json", "w") as f:
        json.dump(record, f)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--divisions", type=int, nargs="+", default=[18, 40, 70])
    ap.add_argument("--routes", nargs="+", default=["dense", "matrix_free"],
                    choices=["dense", "matrix_free"])
    ap.add_argument("--preconditioner", choices=["lumped", "diagonal"],
                    help="matrix-free GMRES's preconditioner (default: the package's)")
    ap.add_argument("--layers", type=int, default=2, help="elements through each plate")
    ap.add_argument("--thickness", type=float, default=0.1, help="each plate's thickness")
    ap.add_argument("--json", help="write the rows to this file")
    ap.add_argument("--one", nargs=6, help=argparse.SUPPRESS)  # n route out prec layers thick
    args = ap.parse_args(argv)
    if args.one:
        one(int(args.one[0]), args.one[1], args.one[2],
            None if args.one[3] == "-" else args.one[3], int(args.one[4]), float(args.one[5]))
        return 0
    rows = []
    print(f"{'contact dofs':>12} {'m':>6} {'route':>12} {'set-up s':>9} {'contact s':>9} "
          f"{'total s':>8} {'peak MiB':>9} {'applied':>8} {'GMRES':>5} {'per solve':>9} "
          f"{'max':>4} {'difference':>10}")
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.divisions:
            answers = {}
            for route in args.routes:
                out = os.path.join(tmp, f"{n}_{route}")
                done = subprocess.run([sys.executable, __file__, "--one", str(n), route, out,
                                       args.preconditioner or "-", str(args.layers),
                                       str(args.thickness)])
                if done.returncode != 0:
                    print(f"{n} {route}: failed (exit {done.returncode})")
                    continue
                with open(out + ".json") as f:
                    row = json.load(f)
                answers[route] = np.load(out + ".npy")
                if len(answers) == 2:
                    a, b = answers.values()
                    row["difference"] = float(np.abs(a - b).max() / np.abs(a).max())
                rows.append(row)
                diff = f"{row['difference']:.1e}" if "difference" in row else ""
                print(f"{row['contact_dofs']:>12,} {row['m']:>6,} {row['route']:>12} "
                      f"{row['setup_s']:>9.2f} {row['contact_s']:>9.2f} {row['total_s']:>8.2f} "
                      f"{row['peak_mib']:>9,.0f} {row['applied']:>8} {row['gmres_solves']:>5} "
                      f"{row['per_solve']:>9.1f} {row['per_solve_max']:>4} {diff:>10}",
                      flush=True)
                if not (row["converged"] and row["invariants"]):
                    print(f"  {n} {route}: not converged or an invariant failed")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
