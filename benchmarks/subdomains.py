"""One body split into subdomains (issue 43): BDDC's interface iterations against the number of
subdomains and the mesh size, with the times, against the direct solve.

The body is a unit square (2D, bilinear quadrilaterals, plane strain) or cube (3D, trilinear
hexahedra), held at its bottom, loaded by a traction on its top (vfem's own body, supports and
assembly: ``vfem.bodies.Body``). For each mesh (``n`` elements along a side) it is factorized
whole (vfem's default backend) and solved, then split into K subdomains
(:func:`vfem.bodies.subdomains.split_solve`) and solved by BDDC-preconditioned CG to its
relative residual 1e-12:

    python3 benchmarks/subdomains.py                        # 2D 32 64 128, 3D 8 12 16; K 2-16
    python3 benchmarks/subdomains.py --dim 3 --n 8 12 --k 2 4 8
    python3 benchmarks/subdomains.py --json out.json

Columns: dofs (free), K, the interface dofs and the coarse (primal) dofs, PCG iterations of
the load's solve, the set-up seconds (the subdomain matrices' assembly, then their
factorizations and the coarse problem), the solve's seconds, the direct factorization's and
solve's seconds together, and the largest difference from the direct displacement over the
largest displacement. Serial: the subdomains are factorized and solved one after the other
in one process, so the times say what the split costs on one core, not what ranks would gain.
"""

from __future__ import annotations

import argparse
import json
import logging
import time

from vfem.bodies import Body, condensation
from vfem.bodies.loads import Support, Traction
from vfem.bodies.subdomains import split_solve
from vfem.linalg import factorize
from vfem.materials import LinearElastic
from vfem.mesh.shapes import rectangle
from vfem.mesh.solids import box


def body(dim: int, n: int, k: int) -> Body:
    """The square or cube of ``n`` elements a side, assembled, to be split into ``k``."""
    if dim == 2:
        mesh, value = rectangle(nx=n, ny=n), (1.0, -0.5)
    else:
        mesh, value = box(nx=n, ny=n, nz=n), (1.0, -0.5, 0.3)
    b = Body("box", mesh, LinearElastic(1000.0, 0.3), supports=(Support("bottom"),),
             tractions=(Traction("top", value=value),), subdomains=k)
    condensation.assemble(b)
    return b


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dim", type=int, nargs="+", default=[2, 3])
    parser.add_argument("--n", type=int, nargs="+", help="elements a side (default: 2D 32 64 "
                        "128, 3D 8 12 16)")
    parser.add_argument("--k", type=int, nargs="+", default=[2, 4, 8, 16])
    parser.add_argument("--json", help="write the rows here")
    args = parser.parse_args()
    logging.basicConfig(level=logging.WARNING)
    rows = []
    print(f"{'dim':>3} {'n':>4} {'dofs':>7} {'K':>3} {'iface':>6} {'primal':>6} {'its':>4} "
          f"{'setup s':>8} {'solve s':>8} {'direct s':>8} {'error':>8}")
    for dim in args.dim:
        sizes = args.n or ([32, 64, 128] if dim == 2 else [8, 12, 16])
        for n in sizes:
            b = body(dim, n, 1)
            K_ff, f = b.K_ff, b.f_load[b.free_dofs]
            t0 = time.perf_counter()
            direct = factorize(K_ff).solve(f)
            t_direct = time.perf_counter() - t0
            for k in args.k:
                b.subdomains = k
                t0 = time.perf_counter()
                split = split_solve(b)
                t1 = time.perf_counter()
                x = split.solve(f)
                t2 = time.perf_counter()
                row = {"dim": dim, "n": n, "dofs": len(f), "K": k,
                       "interface": len(split.interface), "primal": split.n_primal,
                       "iterations": split.iterations[-1], "setup_s": t1 - t0,
                       "solve_s": t2 - t1, "direct_s": t_direct,
                       "error": float(abs(x - direct).max() / abs(direct).max())}
                rows.append(row)
                print(f"{dim:>3} {n:>4} {row['dofs']:>7} {k:>3} {row['interface']:>6} "
                      f"{row['primal']:>6} {row['iterations']:>4} {row['setup_s']:>8.2f} "
                      f"{row['solve_s']:>8.2f} {t_direct:>8.2f} {row['error']:>8.1e}",
                      flush=True)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
