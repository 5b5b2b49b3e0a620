"""Cattaneo-Mindlin partial slip, measured (issue 20; docs/method.md §11 quotes this table).

    python benchmarks/cattaneo.py                 # 12 and 17 contact facets across a
    python benchmarks/cattaneo.py 24 34 48 68     # and finer pairs (upper, lower)
    python benchmarks/cattaneo.py --cost 12 17    # with friction against without
    python benchmarks/cattaneo.py --baseline 16 23 40 57   # against the Lagrange baseline
    python benchmarks/cattaneo.py --cycle 12 17 24 34 48 68  # Mindlin-Deresiewicz's c'

Two elastically similar cylinders (``vfem_examples.cattaneo``) pressed by P, then sheared with
P held. Per step of the shear: Q/(mu P); the stick zone's half-width c of the theory
(a sqrt(1 - Q/(mu P))) and the outermost sticking node, in contact facets; the shear traction
values against Cattaneo-Mindlin's, largest error over |x| < 0.8 a and RMS over |x| < a, in % of
mu p0. Then the Hertz peak of the normal traction and the full slide's Q/(mu P).
"""

from __future__ import annotations

import time

import numpy as np

from vfem_examples import cattaneo


def main(pairs: list[tuple[int, int]]) -> None:
    for upper, lower in pairs:
        p = cattaneo.Parameters(facets_upper=upper, facets_lower=lower)
        t0 = time.perf_counter()
        result, readings = cattaneo.solve(p)
        seconds = time.perf_counter() - t0
        th = cattaneo.theory(p)
        a, p0 = th["a"], th["p0"]
        x = readings[-1].x
        h = np.diff(np.sort(x[np.abs(x) < a])).max()
        dofs = sum(b.ndofs for b in result.model.bodies)
        print(f"\n{upper} / {lower} contact facets across a: {dofs} dofs, {seconds:.1f} s, "
              f"converged {result.converged}, "
              f"{sum(s.iterations for s in result.steps)} iterations in {len(result.steps)} steps")
        print(f"{'Q/(mu P)':>9} {'c theory/a':>10} {'stick node/a':>12} {'(c - it)/h':>10} "
              f"{'shear max %':>11} {'shear RMS %':>11}")
        for r in cattaneo.evaluate(result, p)["steps"]:  # the example's own evaluation
            c, last = r["c_over_a"], r["last_sticking_over_a"]
            print(f"{r['Q_over_muP']:9.4f} {c:10.4f} {last:12.4f} {(c - last) * a / h:10.2f} "
                  f"{100 * r['shear_max_error']:11.2f} {100 * r['shear_rms_error']:11.2f}")
        pressed = next(r for r in readings if r.load_factor == 0.5)
        print(f"Hertz: p_max/p0 - 1 = {100 * (pressed.q.max() / p0 - 1):+.3f} %; "
              f"full slide Q/(mu P) - 1 = "
              f"{abs(readings[-1].tangential) / (p.friction * readings[-1].normal) - 1:+.1e}")


def cost(pairs: list[tuple[int, int]]) -> None:
    """The same model with friction and without (contact.friction = 0: the shear then slides
    freely), alternately, twice, the faster of each: wall time and contact iterations."""
    import dataclasses

    from vfem.solver import Analysis

    print(f"\n{'facets':>8} {'dofs':>7} {'frictional s':>12} {'iterations':>10} "
          f"{'frictionless s':>14} {'iterations':>10} {'ratio':>6}")
    for upper, lower in pairs:
        p = cattaneo.Parameters(facets_upper=upper, facets_lower=lower)
        best = {}
        for _ in range(2):
            for mu in (p.friction, 0.0):
                model = cattaneo.build(p)
                model.contact = dataclasses.replace(model.contact, friction=mu)
                t0 = time.perf_counter()
                result = Analysis(model).run()
                seconds = time.perf_counter() - t0
                its = sum(s.iterations for s in result.steps)
                if mu not in best or seconds < best[mu][0]:
                    best[mu] = (seconds, its, sum(b.ndofs for b in model.bodies))
        (tf, itf, dofs), (t0_, it0, _) = best[p.friction], best[0.0]
        print(f"{upper:>3}/{lower:<4} {dofs:>7} {tf:>12.2f} {itf:>10} {t0_:>14.2f} {it0:>10} "
              f"{tf / t0_:>6.2f}")


def cycle(pairs: list[tuple[int, int]]) -> None:
    """Mindlin and Deresiewicz's unloading (``vfem run cattaneo --set cycle=true --set
    shift=5e-4``, 10 steps per branch): per unloading step, the outermost sticking node's
    distance inside c' = a sqrt(1 - (Q* - Q)/(2 mu P)), in contact facets (negative:
    outside), and how many steps have it within one facet."""
    for upper, lower in pairs:
        p = cattaneo.Parameters(cycle=True, shift=5e-4, facets_upper=upper, facets_lower=lower)
        result, readings = cattaneo.solve(p)
        if not result.converged:
            print(f"{upper}/{lower}: stopped: {result.message}")
            continue
        a = cattaneo.theory(p)["a"]
        x = readings[-1].x
        h = float(np.diff(np.sort(x[np.abs(x) < a])).max())
        peak = next(r.tangential for r in readings if abs(r.load_factor - 1.0) < 1e-9)
        gaps = []
        for r in readings:
            if 1.0 < r.load_factor <= 1.5:
                c = cattaneo.reverse_stick_half_width(p, peak, r.tangential)
                if c > 0:
                    gaps.append((c - r.last_sticking(p.friction)) / h)
        within = sum(abs(g) <= 1.0 for g in gaps)
        print(f"{upper:>3}/{lower:<4} Q*/(mu P) = {peak / (p.friction * p.force):.3f}; c' - "
              f"stick, facets: {' '.join(f'{g:.2f}' for g in gaps)}; within one facet: "
              f"{within} of {len(gaps)}")


def baseline(pairs: list[tuple[int, int]]) -> None:
    """vfem against the classical Lagrange-multiplier baseline with Coulomb friction
    (``contact.method = "lagrange"``: node-to-segment, one global saddle point refactorized
    whenever the contact or stick/slip set changes) on the same model and meshes: per shear
    step the stick zone (the theory's c and each method's outermost sticking node, in facets
    from c) and the shear's largest error over |x| < 0.8 a (% of mu p0); then each method's
    iterations (linear solves), factorizations and wall time (the faster of two runs)."""
    import dataclasses

    from vfem.solver import Analysis

    for upper, lower in pairs:
        p = cattaneo.Parameters(facets_upper=upper, facets_lower=lower)
        th = cattaneo.theory(p)
        runs = {}
        for method in ("vfem", "lagrange"):
            for _ in range(2):
                model = cattaneo.build(p)
                model.contact = dataclasses.replace(model.contact, method=method)
                analysis = Analysis(model)
                t0 = time.perf_counter()
                result = analysis.run()
                seconds = time.perf_counter() - t0
                if method not in runs or seconds < runs[method][1]:
                    runs[method] = (result, seconds, analysis)
        dofs = sum(b.ndofs for b in runs["vfem"][0].model.bodies)
        x = cattaneo.profile(runs["vfem"][0], runs["vfem"][0].steps[-1])["x"]
        h = float(np.diff(np.sort(np.asarray(x)[np.abs(x) < th["a"]])).max())
        print(f"\n{upper} / {lower} contact facets across a, {dofs} dofs")
        print(f"{'Q/(mu P)':>9} {'c/a':>7} {'(c - stick)/h vfem':>19} {'lagrange':>9} "
              f"{'shear max % vfem':>17} {'lagrange':>9}")
        # (the steps each converged: a run that stopped is compared up to where it stopped)
        rows = {m: cattaneo.evaluate(r[0], p)["steps"] for m, r in runs.items()}
        for rv, rl in zip(rows["vfem"], rows["lagrange"]):
            if rv["c_over_a"] <= 0:
                continue
            gap = [(r["c_over_a"] - r["last_sticking_over_a"]) * th["a"] / h for r in (rv, rl)]
            print(f"{rv['Q_over_muP']:9.3f} {rv['c_over_a']:7.4f} {gap[0]:19.2f} {gap[1]:9.2f} "
                  f"{100 * rv['shear_max_error']:17.2f} {100 * rl['shear_max_error']:9.2f}")
        for method, (result, seconds, analysis) in runs.items():
            if not result.converged:
                print(f"  {method} stopped after {len(result.steps)} of "
                      f"{len(result.model.load_factors)} steps: {result.message}")
            its = sum(st.iterations for st in result.steps)
            factorizations = (analysis.contact.factorizations if method == "lagrange"
                              else len(result.model.bodies))
            print(f"  {method:>8}: {its} iterations, {factorizations} factorizations, "
                  f"{seconds:.2f} s")
        print(f"  lagrange / vfem time: {runs['lagrange'][1] / runs['vfem'][1]:.1f}")


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n", 1)[1])
    ap.add_argument("facets", type=int, nargs="*", default=[12, 17],
                    help="pairs of contact facets across a, upper and lower (default 12 17)")
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--cost", action="store_true", help="with friction against without")
    mode.add_argument("--baseline", action="store_true", help="against the Lagrange baseline")
    mode.add_argument("--cycle", action="store_true",
                      help="Mindlin-Deresiewicz's c' over the unloading branch")
    args = ap.parse_args()
    if len(args.facets) % 2:
        ap.error("facet counts come in pairs: UPPER LOWER ...")
    pairs = list(zip(args.facets[::2], args.facets[1::2]))
    (cost if args.cost else baseline if args.baseline else cycle if args.cycle else main)(pairs)
