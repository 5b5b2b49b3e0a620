"""Measure what vfem.memory models: a backend's fill and the peak memory of Analysis.setup.

    python benchmarks/memory_model.py                    # the fitted cases, SuperLU
    python benchmarks/memory_model.py quad 1 80          # one case: element, order, refinement
    python benchmarks/memory_model.py --solver pardiso   # the same with another backend
    python benchmarks/memory_model.py --solver pardiso sphere 1 22   # 3D: the sphere example
                                                         # with 22 facets across a (316k dofs)

Each case runs in its own process (peak resident memory is per process): two rectangular bodies
in contact (the lower 2n x n elements, the upper n x n/2 on part of its top), or, with ``strip``,
two long thin strips whose whole faces are contact candidates (the dense flexibility on the
tracked dofs dominates); ``sphere`` (3D, the refinement read as the facets across the
contact radius): the sphere example of ``vfem bench sphere`` (hexahedra, 26k dofs at 6 facets,
928k at 36), whose fill fits ``vfem.memory.PARDISO_3D``. Printed per case: the dofs, the
tracked dofs, nnz(L + U) against the fill model, and the measured peak against the estimate.
"""

import json
import resource
import subprocess
import sys

CASES = [("quad", 1, n) for n in (20, 40, 80, 160)] + [
    ("tri", 1, 40), ("tri", 1, 80), ("tri", 1, 160), ("tri", 2, 20), ("tri", 2, 40),
    ("tri", 2, 80), ("quad", 2, 20), ("quad", 2, 40), ("quad", 2, 80), ("strip", 1, 500),
    ("strip", 1, 1000)]


def model(kind: str, order: int, n: int):
    from vfem import Body, LinearElastic, Model, PrescribedDisplacement, Support
    from vfem.mesh import rectangle

    if kind == "sphere":
        from vfem_examples.sphere import SphereParameters, build

        return build(SphereParameters(facets_per_radius=n, steps=1))

    mat = LinearElastic(1000.0, 0.3)
    if kind == "strip":
        lower, upper = rectangle(0, -0.01, 2, 0.01, nx=n, ny=2), rectangle(0, 0, 2, 0.01, nx=n,
                                                                            ny=2)
    else:
        tri = kind == "tri"
        lower = rectangle(0, -1, 2, 1, nx=2 * n, ny=n, triangles=tri)
        upper = rectangle(0.5, 0, 1, 0.5, nx=n, ny=max(1, n // 2), triangles=tri)
    return Model("m", [
        Body("lower", lower, mat, supports=(Support("bottom"),), contact_boundaries=("top",),
             order=order),
        Body("upper", upper, mat, supports=(Support("left", ("x",)),),
             prescribed=(PrescribedDisplacement("top", "y", -1e-3),),
             contact_boundaries=("bottom",), order=order)])


def measure(kind: str, order: int, n: int, backend: str) -> dict:
    import vfem.solver
    from vfem.contact.geometry import ContactPairs
    from vfem.memory import estimate, factor_entries
    from vfem.solver import Analysis

    # measured, not refused: the estimate being fitted must not stop the case it is fitted to
    vfem.solver.check_memory = estimate
    m = model(kind, order, n)
    m.validate()
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    analysis = Analysis(m, backend)
    analysis.setup()
    peak = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) * 1024
    rows = []
    for s in analysis.surfaces:
        factor = s.body.factor
        entries = (factor._lu.L.nnz + factor._lu.U.nnz if hasattr(factor, "_lu")
                   else getattr(factor, "factor_entries", 0))
        condensed = len(s.condensed_dofs)
        rows.append({"dofs": s.body.ndofs, "tracked": condensed, "nnz_LU": entries,
                     "model": round(factor_entries(s.body.ndofs, condensed, backend,
                                                   s.body.dim))})
    total = estimate(analysis.surfaces, ContactPairs.every(2), backend)["total"]
    return {"case": f"{kind} P{order} n={n}", "bodies": rows, "peak_MiB": peak / 2**20,
            "estimate_MiB": total / 2**20}


if __name__ == "__main__":
    args = sys.argv[1:]
    backend = "superlu"
    if "--solver" in args:
        i = args.index("--solver")
        backend = args[i + 1]
        del args[i:i + 2]
    if len(args) == 4 and args[0] == "--one":
        print(json.dumps(measure(args[1], int(args[2]), int(args[3]), backend)))
        sys.exit(0)
    cases = [(args[0], int(args[1]), int(args[2]))] if len(args) == 3 else CASES
    for kind, order, n in cases:
        out = subprocess.run([sys.executable, __file__, "--one", kind, str(order), str(n),
                              "--solver", backend],
                             capture_output=True, text=True, check=True).stdout
        r = json.loads(out)
        fill = ", ".join(f"{b['dofs']} dofs ({b['tracked']} condensed): factor {b['nnz_LU']} "
                         f"model x{b['model'] / b['nnz_LU']:.2f}" for b in r["bodies"])
        print(f"{r['case']:>16}: peak {r['peak_MiB']:7.0f} MiB, estimate "
              f"{r['estimate_MiB']:7.0f} MiB (x{r['estimate_MiB'] / r['peak_MiB']:.2f}); {fill}",
              flush=True)
