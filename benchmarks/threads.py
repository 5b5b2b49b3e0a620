"""The thread policy measured (vfem.threads, issue 19): Hertz at a few sizes under each setting,
every run in a fresh process, the settings taking turns.

    python benchmarks/threads.py [--refinements 3 4] [--repeat 3] [--solver auto]

Settings: ``off`` (the pools as the libraries set them: a thread per core each), ``1`` (every
pool on one thread, ``OMP_NUM_THREADS=1``) and the policy (dense BLAS on one thread, the sparse
factorization on the cores). Prints each run's analysis time and the medians.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

CASE = """
import json, sys, time
import vfem.linalg, vfem.threads
from vfem_examples import hertz
from vfem.solver import Analysis
if sys.argv[1] != "auto":
    vfem.linalg.use(sys.argv[1])
model = hertz.config(hertz.HertzParameters(refinement=int(sys.argv[2]))).build()
t0 = time.perf_counter()
Analysis(model).run()
print(json.dumps({"seconds": time.perf_counter() - t0, "dofs": sum(b.ndofs for b in model.bodies),
                  "pools": vfem.threads.info()}))
"""

SETTINGS = {
    "off (library defaults)": {"VFEM_THREADS": "off"},
    "all on one thread": {"VFEM_THREADS": "off", "OMP_NUM_THREADS": "1"},
    "policy (BLAS 1, factorization: cores)": {},
}


def once(env: dict, solver: str, refinement: int) -> dict:
    full = {k: v for k, v in os.environ.items() if k not in ("VFEM_THREADS", "OMP_NUM_THREADS")}
    full.update(env)
    out = subprocess.run([sys.executable, "-c", CASE, solver, str(refinement)], env=full,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--refinements", type=int, nargs="+", default=[3, 4])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--solver", default="auto")
    args = parser.parse_args(argv)
    for refinement in args.refinements:
        times: dict[str, list[float]] = {name: [] for name in SETTINGS}
        dofs = 0
        for _ in range(args.repeat):
            for name, env in SETTINGS.items():
                r = once(env, args.solver, refinement)
                times[name].append(r["seconds"])
                dofs = r["dofs"]
        base = statistics.median(times["off (library defaults)"])
        print(f"Hertz, refinement {refinement} ({dofs} dofs), {args.solver}, "
              f"{args.repeat} runs each (medians):")
        for name, t in times.items():
            m = statistics.median(t)
            print(f"  {name:40s} {m:7.3f} s  ({m / base:.2f} of the library defaults)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
