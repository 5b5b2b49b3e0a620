"""The dense route at its worst: two flat strips whose whole faces are in contact, timed.

    python benchmarks/strip.py [CONTACT_DOFS ...]        # default 2000 4000 8000
    PYTHONPATH=/tmp/before/src python benchmarks/strip.py 2000   # another tree, same model

Two thin strips (2 x 0.01 each, two elements through the thickness, non-matching: the upper has
1.37 times the lower's facets) pressed together by a prescribed motion of the upper's top, one
step, paired formulation. Every node of both faces is a contact candidate, so the flexibility on
the contact dofs is as large as the surfaces: this is where the dense route's n^3 time and n^2
memory show (issue 19, item 4). ``CONTACT_DOFS`` is the candidate dofs of both faces together
(2 per node).

Each size runs in its own process (peak resident memory is per process). Printed per size: the
candidate and tracked dofs, the set-up's wall time (assembly, factorization and flexibility), the
contact solve's, the whole run's, the peak resident memory, the contact iterations and the total
contact force (to compare trees: the answer must not change), and why a run that did not
converge stopped.
"""

import json
import resource
import subprocess
import sys
import time


def model(contact_dofs: int):
    from vfem import Body, LinearElastic, Model, PrescribedDisplacement, Support
    from vfem.mesh import rectangle

    # candidate nodes: (n + 1) + (1.37 n + 1), two dofs each
    n = max(4, round((contact_dofs / 2 - 2) / 2.37))
    mat = LinearElastic(1000.0, 0.3)
    lower = rectangle(0, -0.01, 2, 0.01, nx=n, ny=2)
    upper = rectangle(0, 0, 2, 0.01, nx=round(1.37 * n), ny=2)
    return Model("strip", [
        Body("lower", lower, mat, supports=(Support("bottom"),), contact_boundaries=("top",)),
        Body("upper", upper, mat, supports=(Support("left", ("x",)),),
             prescribed=(PrescribedDisplacement("top", "y", -1e-4),),
             contact_boundaries=("bottom",))])


def measure(contact_dofs: int) -> dict:
    from vfem.solver import Analysis

    m = model(contact_dofs)
    t0 = time.perf_counter()
    analysis = Analysis(m)
    analysis.setup()
    t1 = time.perf_counter()
    result = analysis.run()
    t2 = time.perf_counter()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    force = (float(result.steps[-1].bodies["upper"].contact_force[:, 1].sum())
             if result.steps else float("nan"))
    return {"candidate_dofs": sum(2 * s.nc for s in analysis.surfaces),
            "tracked_dofs": sum(len(s.tracked_dofs) for s in analysis.surfaces),
            "setup_s": t1 - t0, "solve_s": t2 - t1, "total_s": t2 - t0,
            "peak_MiB": peak / 2**20, "converged": bool(result.converged),
            "iterations": [len(s.history) for s in result.steps], "force": force,
            "message": "" if result.converged else result.message[:160]}


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--one":
        print(json.dumps(measure(int(sys.argv[2]))))
        sys.exit(0)
    sizes = [int(a) for a in sys.argv[1:]] or [2000, 4000, 8000]
    print(f"{'candidate':>9} {'tracked':>8} {'setup s':>8} {'solve s':>8} {'total s':>8} "
          f"{'peak MiB':>9} {'iterations':>10}  contact force")
    for size in sizes:
        out = subprocess.run([sys.executable, __file__, "--one", str(size)],
                             capture_output=True, text=True)
        if out.returncode != 0:
            tail = (out.stderr or out.stdout).strip().splitlines() or [f"exit {out.returncode}"]
            print(f"{size:>9}: failed: {tail[-1]}")
            continue
        r = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"{r['candidate_dofs']:>9} {r['tracked_dofs']:>8} {r['setup_s']:>8.2f} "
              f"{r['solve_s']:>8.2f} {r['total_s']:>8.2f} {r['peak_MiB']:>9.0f} "
              f"{str(r['iterations']):>10}  {r['force']:.12g}", flush=True)
        if not r["converged"]:
            print(f"{'':>9} not converged: {r['message']}")
