"""Speed-up of bodies over MPI ranks (issue 22, vfem.parallel) on a stack of plates of equal size.

The model is the ``stack`` example in 3D with ``--blocks`` plates of ``--divisions`` elements
across and ``--layers`` through (plates of alternating stiffness; the odd ones have one division
more, so the bodies are nearly equal). It is solved in one process (the default thread policy:
the sparse factorization on every core), in one process on one thread, and under
``mpiexec -n N`` for each N of ``--ranks`` (one thread a rank); the wall time of
``Analysis.run`` (set-up, steps, results in memory; nothing written) on rank 0, the answers
compared with the serial run's.

**The replicated fraction.** Every rank runs the analysis; the work spread over the ranks is
what runs inside :class:`vfem.parallel.Ranks`' ``own`` (a body's set-up, fields, reactions,
strain screen and part of the pair matrix W on its owner; a pair's search and geometry on one
rank), timed there (``Ranks.busy``). The rest of a run is done by every rank alike: the
replicated fraction is (T(1) - busy) / T(1) of the serial run on one thread. Of the replicated
time, the complementarity solves on W (dense over every pair's unknowns, m of them) are timed
apart: they grow as m^3, the rest as the bodies.

**The scaling model** (docs/scaling.md), from the serial run on one thread:

    T(P) = R + max_r sum_{b on r} w_b + (busy - sum_b w_b) / P

with R the replicated time, w_b body b's set-up (assembly, factorization, load cases) placed
as vfem.parallel places the bodies, the rest of the spread work shared evenly; beside the
measurement. ``--extrapolate``: a stack of P plates, one a rank (P - 1 pairs, m growing as
P - 1): each rank's own work, the replicated work per body times P, the complementarity times
((P - 1) / (B - 1))^3 while W is dense, to the power 1.5 once it is kept sparse
(:data:`SPARSE_GROWTH`), and each step's exchange.

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
    from vfem.contact.formulations import paired
    from vfem.solver import Analysis
    from vfem_examples import stack

    ranks = parallel.start()
    p = stack.Parameters(blocks=args.blocks, divisions=args.divisions, layers=args.layers,
                         thickness=args.thickness, flexibility=args.flexibility,
                         steps=args.steps)
    model = stack.build(p)
    # the complementarity solves timed (replicated on every rank: dense, growing as m^3)
    solve, spent = paired.linear_complementarity, [0.0]

    def timed(*a, **k):  # (less the spread work inside: matrix-free, W's products)
        t, busy = time.perf_counter(), ranks.busy
        try:
            return solve(*a, **k)
        finally:
            spent[0] += time.perf_counter() - t - (ranks.busy - busy)

    paired.linear_complementarity = timed
    if ranks.parallel:
        ranks.comm.Barrier()
    busy0 = ranks.busy
    t = time.perf_counter()
    analysis = Analysis(model)
    result = analysis.run()
    wall = time.perf_counter() - t
    busy = ranks.busy - busy0
    if ranks.parallel:
        per_rank = ranks.comm.gather(busy, root=0)
        ranks.comm.Barrier()
    else:
        per_rank = [busy]
    if not ranks.root:
        return
    answers = np.concatenate([np.concatenate([b.displacement.ravel(), b.contact_force.ravel()])
                              for b in result.steps[-1].bodies.values()])
    np.save(out + ".npy", answers)
    owner = ranks.owner or [0] * len(model.bodies)
    full = getattr(analysis.contact, "_full", None)
    record = {"ranks": ranks.size, "wall_s": wall, "converged": result.converged,
              "invariants": all(s.invariants["passed"] for s in result.steps),
              "dofs": int(sum(b.ndofs for b in model.bodies)),
              "contact_dofs": int(sum(s.dim * s.nc for s in result.surfaces)),
              "unknowns": int(full[3][-1]) if full is not None else 0,
              "flexibility": result.flexibility, "busy_s": per_rank,
              "complementarity_s": spent[0],
              "bodies": [{"name": b.name, "dofs": int(b.ndofs), "owner": int(owner[i]),
                          "own_s": float(b.timings.get("assemble_s", 0.0)
                                         + b.timings.get("factorize_s", 0.0)
                                         + b.timings.get("load_cases_s", 0.0))}
                         for i, b in enumerate(model.bodies)],
              "timings": {k: float(v) for k, v in result.timings.items()}}
    with open(out + ".json", "w") as f:
        json.dump(record, f)


def replicated(serial: dict) -> float:
    """The serial run's time that every rank would do alike: all but the spread work."""
    return serial["wall_s"] - serial["busy_s"][0]


def predicted(serial: dict, n: int, cores: int | None = None) -> float:
    """The scaling model's wall time on ``n`` ranks from a serial run's record: the bodies'
    set-up split as vfem.parallel places them (largest first, least loaded rank), the rest of
    the spread work evenly, the replicated time on every rank. On ``cores`` cores (default
    all of this machine's) fewer than the ranks (oversubscribed), the ranks share them: the
    replicated work of all n ranks and the spread work each take their share of the cores,
    the longest rank's own work no less than alone."""
    from vfem.parallel import Ranks

    cores = cores or os.cpu_count() or 1
    work = [b["own_s"] for b in serial["bodies"]]
    ranks = Ranks()
    ranks.size = n
    owner = ranks.place([b["dofs"] for b in serial["bodies"]])
    rest = serial["busy_s"][0] - sum(work)
    per_rank = [sum(w for w, o in zip(work, owner) if o == r) + rest / n for r in range(n)]
    share = max(1.0, n / cores)
    return replicated(serial) * share + max(max(per_rank), sum(per_rank) / cores)


#: the broadcast bandwidth assumed for the extrapolation (bytes/s: a cluster's interconnect,
#: or shared memory between a machine's ranks), and each message's latency (s)
BANDWIDTH, LATENCY = 5e9, 5e-6


#: the complementarity's growth with the pairs where W is kept sparse (block tridiagonal: a
#: stack's pairs couple only through the plates they share; vfem.contact.solvers.
#: pair_flexibility.SPARSE_DENSITY): t ~ m^1.5, measured on stacks of 10 x 10 x 2 plates on one
#: thread, 8 plates (1,961 unknowns, W dense) 0.10 s and 32 plates (8,793, sparse) 0.94 s
SPARSE_GROWTH = 1.5


def extrapolate(serial: dict, sizes=(2, 4, 16, 64, 256, 1024)) -> list[dict]:
    """The scaling model for P ranks with one body each (a stack of P plates like the serial
    run's, P - 1 pairs): each rank's own work (the mean body's share of the spread work), the
    replicated work other than the complementarity per body done for all P bodies on every
    rank, the complementarity solves on W (m the pairs' unknowns, growing as P - 1): dense
    while the pairs' coupled blocks cover more than vfem's ``SPARSE_DENSITY`` of W (time as
    m^3, 8 m^2 bytes on every rank), sparse beyond (time as m^:data:`SPARSE_GROWTH`, its
    blocks' bytes); and each step's exchange of every body's fields (P n 8 bytes, log2 P
    stages, :data:`BANDWIDTH`, :data:`LATENCY`)."""
    from vfem.contact.solvers.pair_flexibility import SPARSE_DENSITY, SPARSE_MIN

    bodies = serial["bodies"]
    b = len(bodies)
    own = serial["busy_s"][0] / b
    lcp = serial["complementarity_s"]
    rest = (replicated(serial) - lcp) / b
    n = sum(x["dofs"] for x in bodies) / b
    m = serial["unknowns"]
    out = []
    for p in sizes:
        grow = (p - 1) / max(b - 1, 1)
        pairs = p - 1
        # a chain of pairs: each couples with itself and its two neighbours
        coverage = min(1.0, (3 * pairs - 2) / pairs**2) if pairs > 1 else 1.0
        sparse = coverage <= SPARSE_DENSITY and m * grow >= SPARSE_MIN
        solves = lcp * grow ** (SPARSE_GROWTH if sparse else 3)
        stages = max(1.0, float(np.log2(p)))
        comm = p * (n * 8 / BANDWIDTH + LATENCY) * stages
        t = own + p * rest + solves + comm
        out.append({"ranks": p, "bodies": p, "time_s": t, "efficiency": own / t,
                    "own_s": own, "replicated_s": p * rest, "complementarity_s": solves,
                    "sparse": sparse, "broadcast_s": comm, "unknowns": m * grow,
                    "W_gib": 8 * (m * grow) ** 2 * (coverage if sparse else 1.0) / 2**30})
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
              f"{serial['contact_dofs']:,} contact dofs, {serial['unknowns']:,} pair unknowns, "
              f"{serial['flexibility']}")
        rep = replicated(one_thread)
        print(f"replicated on every rank (serial run on one thread): {rep:.2f} s of "
              f"{one_thread['wall_s']:.2f} s = {100 * rep / one_thread['wall_s']:.1f} % "
              f"(the complementarity solves {one_thread['complementarity_s']:.2f} s)")
        print(f"{'run':>18} {'wall s':>8} {'speed-up':>9} {'predicted s':>12} "
              f"{'busy s per rank':>18} {'difference':>10}")
        reference = serial["answers"]
        for row in rows:
            diff = float(np.abs(row["answers"] - reference).max() / np.abs(reference).max())
            n = row["ranks"]
            pred = predicted(one_thread, n) if n > 1 else float("nan")
            ok = "" if row["converged"] and row["invariants"] else "  (not converged!)"
            busy = " ".join(f"{x:.1f}" for x in row["busy_s"])
            print(f"{row['label']:>18} {row['wall_s']:>8.2f} "
                  f"{serial['wall_s'] / row['wall_s']:>9.2f} {pred:>12.2f} {busy:>18} "
                  f"{diff:>10.1e}{ok}")
            row["difference"], row["predicted_s"] = diff, pred
            del row["answers"]
    if args.extrapolate:
        size = serial["dofs"] // len(serial["bodies"])
        print(f"\nscaling model, one body a rank (bodies of {size:,} dofs; from the serial run "
              "on one thread):")
        print(f"{'ranks':>6} {'own s':>7} {'replicated s':>13} {'complementarity s':>18} "
              f"{'W':>7} {'W GiB':>8} {'broadcast s':>12} {'T s':>9} {'efficiency':>11}")
        for e in extrapolate(one_thread):
            print(f"{e['ranks']:>6} {e['own_s']:>7.2f} {e['replicated_s']:>13.2f} "
                  f"{e['complementarity_s']:>18.2f} {'sparse' if e['sparse'] else 'dense':>7} "
                  f"{e['W_gib']:>8.2f} {e['broadcast_s']:>12.4f} {e['time_s']:>9.2f} "
                  f"{e['efficiency']:>11.3f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
