"""Total-Lagrangian Hertz timed on two source trees in one run (issue 18: "time before and
after, measured in one run of both").

    git worktree add /tmp/before <commit>
    python benchmarks/tl_hertz_speed.py /tmp/before/src src [--repeat 3] [--solver superlu]

Each tree's ``vfem`` runs the Hertz example with ``kinematics = "total"`` on both bodies (the
large-Hertz benchmark's case at the thesis's force) in a subprocess of its own, the trees taking
turns ``--repeat`` times; it prints each run's analysis time (set-up and steps, not Python's
start-up) and its steps' alone, p_max and the contact iterations, then the median times and their
ratio, and the two trees' p_max. These agree to within what large kinematics leaves to
round-off: the Newton iteration stops at a residual of 1e-8 of the reference force, so the
converged state moves within it with the order of floating-point sums (PARDISO's threads alone
move p_max by 1e-10 between runs of one tree; SuperLU against PARDISO, 2e-10 at refinement 0 and
4e-8 at refinement 2).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

CASE = """
import dataclasses, importlib, json, os, sys, time
import vfem, vfem.linalg
# the tree's own examples: beside the library since issue 38, inside it before (an import
# that merely succeeds may come from an editable install's tree, later on the path)
tree = os.path.dirname(os.path.dirname(vfem.__file__))
beside = os.path.isdir(os.path.join(tree, "vfem_examples"))
hertz = importlib.import_module("vfem_examples.hertz" if beside else "vfem.examples.hertz")
from vfem.solver import Analysis
if sys.argv[1] != "auto":
    vfem.linalg.use(sys.argv[1])
config = hertz.config(hertz.HertzParameters(refinement=int(sys.argv[2])))
config = dataclasses.replace(config, bodies=tuple(
    dataclasses.replace(b, kinematics="total") for b in config.bodies))
t0 = time.perf_counter()
result = Analysis(config.build()).run()
seconds = time.perf_counter() - t0
p_max = max(float(b.contact_pressure.max()) for b in result.steps[-1].bodies.values())
print(json.dumps({"seconds": seconds, "steps_s": result.timings["steps_s"], "p_max": p_max,
                  "converged": result.converged,
                  "iterations": sum(s.iterations for s in result.steps)}))
"""


def once(src: str, solver: str, refinement: int) -> dict:
    env = dict(os.environ, PYTHONPATH=os.path.abspath(src))
    out = subprocess.run([sys.executable, "-c", CASE, solver, str(refinement)], env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before", help="the src folder of the tree before the change")
    parser.add_argument("after", help="the src folder of the tree after it")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--solver", default="auto", help="linear solver (default: auto)")
    parser.add_argument("--refinement", type=int, default=0,
                        help="the Hertz example's refinement (default 0: the large-Hertz "
                             "benchmark's mesh)")
    args = parser.parse_args(argv)
    times: dict[str, list[float]] = {"before": [], "after": []}
    steps: dict[str, list[float]] = {"before": [], "after": []}
    answers = {}
    for k in range(args.repeat):
        for label, src in (("before", args.before), ("after", args.after)):
            r = once(src, args.solver, args.refinement)
            times[label].append(r["seconds"])
            steps[label].append(r["steps_s"])
            answers[label] = r
            print(f"run {k + 1} {label:6s}: {r['seconds']:.3f} s (steps {r['steps_s']:.3f} s)  "
                  f"p_max {r['p_max']:.10g}  "
                  f"{r['iterations']} contact iterations  converged {r['converged']}")
    tb, ta = statistics.median(times["before"]), statistics.median(times["after"])
    sb, sa = statistics.median(steps["before"]), statistics.median(steps["after"])
    print(f"median: before {tb:.3f} s, after {ta:.3f} s, after/before {ta / tb:.3f}; the steps "
          f"alone (set-up left out) {sb:.3f} s and {sa:.3f} s, {sa / sb:.3f} "
          f"({args.solver}, refinement {args.refinement})")
    pb, pa = answers["before"]["p_max"], answers["after"]["p_max"]
    print(f"p_max before {pb:.12g}, after {pa:.12g}, relative difference "
          f"{abs(pa - pb) / abs(pb):.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
