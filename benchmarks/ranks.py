"""Speed-up of bodies over MPI ranks (issue 22, vfem.parallel) on a stack of plates of equal size.

The model is the ``stack`` example in 3D with ``--blocks`` plates of ``--divisions`` elements
across and ``--layers`` through (plates of alternating stiffness; the odd ones have one division
more, so the bodies are nearly equal). It is solved in one process (the default thread policy:
the sparse factorization on every core), in one process on one thread, and under
``mpiexec -n N`` for each N of ``--ranks`` (one thread a rank); the wall time of
``Analysis.run`` (set-up, steps, results in memory; nothing written) on rank 0, the answers
compared with the serial run's, and beside each the prediction of the scaling model of
docs/scaling.md from the serial run's own timings:

    T(P) = T(1) - sum_b w_b + max_r sum_{b on r} w_b - S + S / min(P, pairs) - C + C s_max

with w_b body b's work that its owner alone does (its factorization and its load cases'
back-substitutions, ``Body.timings``), S the pairs' set-up (their geometry, spread over the
ranks) and, matrix-free, C the contact iterations (the products of W: a back-substitution per
body, all owners at once; s_max the largest rank's share of the dofs), all from the serial run
on one thread.

    python3 benchmarks/ranks.py                                  # 4 plates, 2 ranks
    python3 benchmarks/ranks.py --blocks 4 --divisions 30 --layers 8 --ranks 2 4
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np


def one(args, out: str) -> None:
    """Solve the model in this process (one rank of an MPI run or the serial run)."""
    from vfem import parallel
    from vfem.solver import Analysis
    from vfem_examples import stack

    ranks = parallel.start()
    p = stack.Parameters(blocks=args.blocks, divisions=args.divisions, layers=args.layers,
                         thickness=args.thickness, flexibility=args.flexibility,
                         steps=args.steps)
    model = stack.build(p)
    if ranks.parallel:
        ranks.comm.Barrier()
    t = time.perf_counter()
    analysis = Analysis(model)
    result = analysis.run()
    if ranks.parallel:
        ranks.comm.Barrier()
    wall = time.perf_counter() - t
    if not ranks.root:
        return
    answers = np.concatenate([np.concatenate([b.displacement.ravel(), b.contact_force.ravel()])
                              for b in result.steps[-1].bodies.values()])
    np.save(out + ".npy", answers)
    owner = ranks.owner or [0] * len(model.bodies)
    record = {"ranks": ranks.size, "wall_s": wall, "converged": result.converged,
              "invariants": all(s.invariants["passed"] for s in result.steps),
              "dofs": int(sum(b.ndofs for b in model.bodies)),
              "contact_dofs": int(sum(s.dim * s.nc for s in result.surfaces)),
              "flexibility": result.flexibility,
              "bodies": [{"name": b.name, "dofs": int(b.ndofs), "owner": int(owner[i]),
                          "own_s": float(b.timings.get("factorize_s", 0.0)
                                         + b.timings.get("load_cases_s", 0.0))}
                         for i, b in enumerate(model.bodies)],
              "timings": {k: float(v) for k, v in result.timings.items()}}
    with open(out + ".json", "w") as f:
        json.dump(record, f)


def predicted(serial: dict, n: int) -> float:
    """The scaling model's wall time on ``n`` ranks from a serial run's record: the owners'
    work split as vfem.parallel places the bodies (largest first, least loaded rank), and the
    pairs' set-up (their geometry and the compliance densities: ``flexibility_s``) spread
    over as many ranks as there are pairs, at most ``n``; the rest as in serial."""
    from vfem.parallel import Ranks

    work = [b["own_s"] for b in serial["bodies"]]
    ranks = Ranks()
    ranks.size = n
    owner = ranks.place([b["dofs"] for b in serial["bodies"]])
    per_rank = [sum(w for w, o in zip(work, owner) if o == r) for r in range(n)]
    pairs = serial["timings"].get("flexibility_s", 0.0)
    spread = min(n, max(1, len(serial["bodies"]) - 1))
    # matrix-free: the contact iteration is the products of W, one back-substitution per body,
    # all owners at once: its share of the largest rank (by dofs)
    contact = serial["timings"].get("contact_s", 0.0) if serial["flexibility"] == \
        "matrix_free" else 0.0
    dofs = [b["dofs"] for b in serial["bodies"]]
    share = max(sum(d for d, o in zip(dofs, owner) if o == r) for r in range(n)) / sum(dofs)
    return (serial["wall_s"] - sum(work) + max(per_rank) - pairs + pairs / spread
            - contact + contact * share)


#: the broadcast bandwidth assumed for the extrapolation (bytes/s: a cluster's interconnect,
#: or shared memory between a machine's ranks), and each message's latency (s)
BANDWIDTH, LATENCY = 5e9, 5e-6


def extrapolate(serial: dict, sizes=(2, 4, 16, 64, 256, 1024)) -> list[dict]:
    """The scaling model for P ranks with one body each (a stack of P plates like the serial
    run's, P - 1 pairs): each rank's own work w (the mean of the serial run's bodies), the
    replicated work r per body (T(1) - sum w - S, over the bodies) done for all P bodies on
    every rank, one pair's set-up s on each rank, and each step's broadcast of every body's
    displacement (P n 8 bytes, log2 P stages, :data:`BANDWIDTH`, :data:`LATENCY`)."""
    bodies = serial["bodies"]
    w = sum(b["own_s"] for b in bodies) / len(bodies)
    pairs = serial["timings"].get("flexibility_s", 0.0)
    s = pairs / max(1, len(bodies) - 1)
    r = (serial["wall_s"] - sum(b["own_s"] for b in bodies) - pairs) / len(bodies)
    n = sum(b["dofs"] for b in bodies) / len(bodies)
    ideal = w + r + s
    out = []
    for p in sizes:
        stages = max(1.0, float(np.log2(p)))
        comm = p * (n * 8 / BANDWIDTH + LATENCY) * stages
        t = w + p * r + s + comm
        out.append({"ranks": p, "bodies": p, "time_s": t, "efficiency": ideal / t,
                    "own_s": w, "replicated_s": p * r, "broadcast_s": comm})
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blocks", type=int, default=4)
    ap.add_argument("--divisions", type=int, default=24)
    ap.add_argument("--layers", type=int, default=8)
    ap.add_argument("--thickness", type=float, default=0.25)
    ap.add_argument("--steps", type=int, default=1)
    ap.add_argument("--flexibility", default="dense", choices=["dense", "matrix_free"])
    ap.add_argument("--ranks", type=int, nargs="+", default=[2])
    ap.add_argument("--json", help="write the rows to this file")
    ap.add_argument("--extrapolate", action="store_true",
                    help="also the scaling model for 2 to 1,024 ranks, one body each")
    ap.add_argument("--one", help=argparse.SUPPRESS)  # the output stem: run in this process
    args = ap.parse_args(argv)
    if args.one:
        one(args, args.one)
        return 0
    from vfem import parallel

    mpiexec = parallel.launcher()
    if mpiexec is None:
        print("needs mpi4py and an mpiexec: pip install -e \".[mpi]\"")
        return 2
    model_args = [f"--blocks={args.blocks}", f"--divisions={args.divisions}",
                  f"--layers={args.layers}", f"--thickness={args.thickness}",
                  f"--steps={args.steps}", f"--flexibility={args.flexibility}"]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        def launch(label: str, n: int, threads: str | None) -> dict:
            out = os.path.join(tmp, label)
            command = [sys.executable, __file__, *model_args, f"--one={out}"]
            env = dict(os.environ)
            if n > 1:
                command, env = parallel.launch_command(mpiexec, n, command)
            env.pop("VFEM_THREADS", None)
            if threads is not None:
                env["VFEM_THREADS"] = threads
            done = subprocess.run(command, env=env, capture_output=True, text=True)
            if done.returncode != 0:
                raise SystemExit(f"{label}: exit {done.returncode}\n{done.stderr[-2000:]}")
            with open(out + ".json") as f:
                row = json.load(f)
            row["label"], row["answers"] = label, np.load(out + ".npy")
            return row

        serial = launch("serial", 1, None)
        one_thread = launch("serial, 1 thread", 1, "1")
        rows = [serial, one_thread] + [launch(f"{n} ranks", n, None) for n in args.ranks]
        print(f"{len(serial['bodies'])} bodies, {serial['dofs']:,} dofs "
              f"({', '.join(str(b['dofs']) for b in serial['bodies'])}), "
              f"{serial['contact_dofs']:,} contact dofs, {serial['flexibility']}")
        print(f"{'run':>18} {'wall s':>8} {'speed-up':>9} {'predicted s':>12} "
              f"{'difference':>10}")
        reference = serial["answers"]
        for row in rows:
            diff = float(np.abs(row["answers"] - reference).max() / np.abs(reference).max())
            n = row["ranks"]
            pred = predicted(one_thread, n) if n > 1 else float("nan")
            ok = "" if row["converged"] and row["invariants"] else "  (not converged!)"
            print(f"{row['label']:>18} {row['wall_s']:>8.2f} "
                  f"{serial['wall_s'] / row['wall_s']:>9.2f} {pred:>12.2f} {diff:>10.1e}{ok}")
            row["difference"], row["predicted_s"] = diff, pred
            del row["answers"]
    if args.extrapolate:
        size = serial["dofs"] // len(serial["bodies"])
        print(f"\nscaling model, one body a rank (bodies of {size:,} dofs; from the serial run "
              "on one thread):")
        print(f"{'ranks':>6} {'own s':>7} {'replicated s':>13} {'broadcast s':>12} {'T s':>8} "
              f"{'efficiency':>11}")
        for e in extrapolate(one_thread):
            print(f"{e['ranks']:>6} {e['own_s']:>7.2f} {e['replicated_s']:>13.2f} "
                  f"{e['broadcast_s']:>12.4f} {e['time_s']:>8.2f} {e['efficiency']:>11.2f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
