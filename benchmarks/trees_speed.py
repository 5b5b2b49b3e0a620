"""The Hertz example and the 3D sphere timed on two source trees in one run (issue 38: "a
benchmark run before/after on Hertz 100k and the sphere 100k: no slowdown over 3 %").

    git worktree add /tmp/before <commit>
    python benchmarks/trees_speed.py /tmp/before/src src [--dofs 100k] [--repeat 5]
        [--cases hertz sphere]
    python benchmarks/trees_speed.py /tmp/before/src src --cases --repeat 3 \
        --runs "cattaneo3d --no-figures" "examples/sphere.toml --no-figures"

``--runs``: whole ``vfem run`` commands instead (issue 40's before/after phase tables), each
in a fresh process with its tree first on the path, run from the repository root of the
second tree (input files' paths are relative to it), timed end to end; per command the two
trees' median wall seconds and each phase's median from ``summary.json`` (the phases
``vfem -v run`` prints).

Each run is one case on one tree in a fresh subprocess (that tree first on the path), the trees
taking turns ``--repeat`` times per case; the clock covers the analysis alone
(``Analysis(model).run()``: search, assembly, factorization and condensation, every step with its
invariants), the model being built before it starts. The sizes are those of ``vfem bench
--dofs`` (the Hertz example with its contact facets and largest element scaled together; the
sphere with more facets across the contact radius). Printed: each run's seconds, then per case
the two trees' medians, their ratio (second over first) and whether the two trees' answers (the
sum of every body's nodal contact forces, a checksum) are the same to 1e-10; then each phase's
median on each tree (search, assembly, factorization, flexibility, contact iterations, fields,
invariants, steps: the timings every run records), which says where a difference lies when the
machine's noise on the whole run is larger than it. A tree from before
the examples moved beside the library (``vfem.examples`` rather than ``vfem_examples``) is run
as it is.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

CASE = """
import importlib, json, os, sys, time
import numpy as np
import vfem
from vfem.solver import Analysis
# the tree's own examples and tools: beside the library since issue 38, inside it before (an
# import that merely succeeds may come from an editable install's tree, later on the path)
tree = os.path.dirname(os.path.dirname(vfem.__file__))
beside = os.path.isdir(os.path.join(tree, "vfem_examples"))
bench = importlib.import_module("vfem_tools.bench" if beside else "vfem.tools.bench")
examples = importlib.import_module("vfem_examples" if beside else "vfem.examples")
case, dofs = sys.argv[1], int(sys.argv[2])
PHASES = ("search_s", "assemble_s", "factorize_s", "flexibility_s", "contact_s", "fields_s",
          "invariants_s", "steps_s")
parameters = bench.hertz_parameters(dofs) if case == "hertz" else bench.sphere_parameters(dofs)
model = importlib.import_module(examples.__name__ + "." + case).build(parameters)
t0 = time.perf_counter()
result = Analysis(model).run()
seconds = time.perf_counter() - t0
assert result.converged, result.message
checksum = float(sum(np.abs(np.asarray(b.contact_force)).sum()
                     for b in result.steps[-1].bodies.values()))
print(json.dumps({"seconds": seconds, "checksum": checksum,
                  "dofs": sum(b.ndofs for b in model.bodies),
                  "phases": {k: v for k, v in result.timings.items() if k in PHASES}}))
"""

def run(tree: str, case: str, dofs: int) -> dict:
    """One case on ``tree`` in a subprocess of its own."""
    env = dict(os.environ, PYTHONPATH=tree)
    done = subprocess.run([sys.executable, "-c", CASE, case, str(dofs)], env=env,
                          capture_output=True, text=True, cwd=os.path.dirname(tree) or ".")
    if done.returncode:
        raise SystemExit(f"{tree}: {case} failed:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def run_command(tree: str, command: str, cwd: str) -> dict:
    """``vfem run COMMAND`` on ``tree`` in a process of its own: wall seconds and phases."""
    import shlex
    import tempfile
    import time

    env = dict(os.environ, PYTHONPATH=tree)
    with tempfile.TemporaryDirectory(prefix="vfem-trees-") as tmp:
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "vfem", "-q", "run", *shlex.split(command),
                               "--out", os.path.join(tmp, "out")], env=env,
                              capture_output=True, text=True, cwd=cwd)
        seconds = time.perf_counter() - t0
        if done.returncode:
            raise SystemExit(f"{tree}: vfem run {command} failed:\n{done.stderr[-2000:]}")
        with open(os.path.join(tmp, "out", "summary.json"), encoding="utf-8") as f:
            summary = json.load(f)
    return {"seconds": seconds, "phases": summary.get("phases", {}),
            "dofs": summary.get("dofs")}


def main_runs(trees: list[str], commands: list[str], repeat: int) -> int:
    """``--runs``: the whole runs, alternately on the two trees, medians per phase."""
    cwd = os.path.dirname(trees[1])
    rows = {(c, t): [] for c in commands for t in trees}
    for k in range(repeat):
        for command in commands:
            for tree in trees:
                row = run_command(tree, command, cwd)
                rows[command, tree].append(row)
                print(f"{k + 1} {command:40s} {row['seconds']:8.2f} s  {tree}", flush=True)
    for command in commands:
        a, b = (statistics.median(r["seconds"] for r in rows[command, t]) for t in trees)
        print(f"\nvfem run {command} ({rows[command, trees[1]][0]['dofs']} dofs): median "
              f"{a:.2f} s then {b:.2f} s, ratio {b / a:.3f}")
        print("| phase | before s | after s |\n|---|---:|---:|")
        keys = list(rows[command, trees[0]][0]["phases"])
        for key in keys:
            a, b = (statistics.median(r["phases"].get(key, 0.0) for r in rows[command, t])
                    for t in trees)
            print(f"| {key} | {a:.2f} | {b:.2f} |")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("first", help="the first tree's src folder (before)")
    parser.add_argument("second", help="the second tree's src folder (after)")
    parser.add_argument("--dofs", default="100k", help="about this many dofs (10k, 100k, 1M)")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--cases", nargs="*", default=["hertz", "sphere"],
                        choices=("hertz", "sphere"))
    parser.add_argument("--runs", nargs="+", metavar="COMMAND",
                        help="whole vfem run commands instead of the cases")
    args = parser.parse_args(argv)
    if args.runs:
        return main_runs([os.path.abspath(args.first), os.path.abspath(args.second)],
                         args.runs, args.repeat)
    from vfem_tools.bench import parse_size  # (vfem bench --dofs's sizes)

    dofs = parse_size(args.dofs)
    trees = [os.path.abspath(args.first), os.path.abspath(args.second)]
    times = {(c, t): [] for c in args.cases for t in trees}
    phases = {(c, t): [] for c in args.cases for t in trees}
    sums = {}
    for k in range(args.repeat):
        for case in args.cases:
            for tree in trees:
                row = run(tree, case, dofs)
                times[case, tree].append(row["seconds"])
                phases[case, tree].append(row["phases"])
                sums.setdefault((case, tree), row["checksum"])
                print(f"{k + 1} {case:6s} {row['dofs']:8d} dofs  {row['seconds']:8.3f} s  {tree}",
                      flush=True)
    for case in args.cases:
        a, b = (statistics.median(times[case, t]) for t in trees)
        same = abs(sums[case, trees[0]] - sums[case, trees[1]]) <= 1e-10 * abs(
            sums[case, trees[0]])
        print(f"{case}: median {a:.3f} s then {b:.3f} s, ratio {b / a:.3f} "
              f"(answers {'the same' if same else 'DIFFERENT'})")
        # each phase's median (the timings a run records): where a difference lies, apart
        # from the machine's noise on the whole
        for key in phases[case, trees[0]][0]:
            a, b = (statistics.median(p.get(key, 0.0) for p in phases[case, t]) for t in trees)
            print(f"  {key.removesuffix('_s'):12s} {a:8.3f} s then {b:8.3f} s  ({b - a:+.3f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
