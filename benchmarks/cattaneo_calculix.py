"""Cattaneo-Mindlin partial slip in vfem and in CalculiX, on the same meshes (issue 20).

    python benchmarks/cattaneo_calculix.py [UPPER LOWER ...] [--stick-slope S ...] [--penalty K]
                                           [--threads N] [--ccx PATH] [--timeout S] [--keep DIR]

The example ``vfem_examples.cattaneo`` (two alike half disks pressed by P, then sheared with P
held; mu = 0.3) for each pair of contact-facet counts (default 17 24 and 43 61: about 20k and
100k dofs), solved by vfem (``cattaneo.solve``) and by ccx on the same nodes and elements
(``vfem_tools.calculix.write_deck(steps="curves", friction=mu)``: the platen's approach, the
press and the shear as three ccx steps, the shear's increments at vfem's load factors; penalty
contact, the lower body, vfem's finer compatibility side, the slave).

One table per mesh: per shear increment, for each code, Q/(mu P) (Q: the sideways reaction of
the moved flat side in ccx, the lower body's contact force in vfem), the stick zone's
half-width c/a of the theory at that Q (sqrt(1 - Q/(mu P))), the outermost sticking node x/a
(vfem: its friction status; ccx writes none: a slave node in contact sticks where its nodal
|CSHEAR| < mu CPRESS (1 - 1e-4), :func:`vfem_tools.calculix.sticking`), the peak shear traction
over mu p0 and Cattaneo-Mindlin's (the largest over x of the closed form at that Q), and the
shear's RMS error against the closed form over |x| < a, % of mu p0 (vfem: its nodal tractions,
``cattaneo.evaluate``; ccx: its nodal CSHEAR). Then the totals: wall time (vfem:
``cattaneo.solve``; ccx: the subprocess), iterations (vfem: contact iterations; ccx: Newton
iterations of its .sta file, per step: approach, press, shear) and their ratios in this run, and
ccx's normal contact force at the end of the press against P. With several ``--stick-slope``
values the first fills the table and a second one gives, per slope, ccx's Q/(mu P), outermost
sticking node and peak shear per increment, its iterations and seconds.

Needs ``ccx`` (Debian: calculix-ccx); prints a note without it. Run with ``OMP_NUM_THREADS=1``
in the environment for one thread on both sides (``--threads`` sets ccx's).
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

import numpy as np

from vfem.errors import VfemError
from vfem_examples import cattaneo
from vfem_tools.calculix import run, sticking, write_deck


def peak_theory(p: cattaneo.Parameters, tangential: float) -> float:
    """The largest Cattaneo-Mindlin shear traction under Q, over mu p0."""
    th = cattaneo.theory(p)
    x = np.linspace(-th["a"], th["a"], 20001)
    return float(cattaneo.shear_theory(p, x, tangential).max() / (p.friction * th["p0"]))


def vfem_rows(result, p: cattaneo.Parameters) -> dict[float, dict]:
    """Per shear step of vfem (load factor -> row): the example's own evaluation and the peak
    of its shear profile."""
    mu_p0 = p.friction * cattaneo.theory(p)["p0"]
    steps = {round(s.load_factor, 9): s for s in result.steps}
    out = {}
    for r in cattaneo.evaluate(result, p)["steps"]:
        step = steps[round(r["load_factor"], 9)]
        shear = np.abs(np.asarray(cattaneo.profile(result, step)["shear"]))
        q = r["Q_over_muP"] * p.friction * p.force
        out[round(r["load_factor"], 9)] = {
            "Q": r["Q_over_muP"], "c_theory": r["c_over_a"], "stick": r["last_sticking_over_a"],
            "peak": float(shear.max(initial=0.0)) / mu_p0, "peak_theory": peak_theory(p, q),
            "rms": r["shear_rms_error"]}
    return out


def ccx_rows(history: list[dict], p: cattaneo.Parameters, moved: str, support: str
             ) -> dict[float, dict]:
    """Per increment ccx wrote (load factor -> row), the same quantities from its contact
    stresses (nodal, .frd) and the reactions (.dat)."""
    th = cattaneo.theory(p)
    a, mu_p0 = th["a"], p.friction * th["p0"]
    out = {}
    for h in history:
        normal = h["reactions"][support][1]
        q = abs(h["reactions"][moved][0])
        x = h["x"][:, 0]
        shear = np.linalg.norm(h["cshear"], axis=1)
        stick = sticking(h, p.friction)
        on = (h["cpress"] > 0) & (np.abs(x) < a)
        err = (shear[on] - cattaneo.shear_theory(p, x[on], q)) / mu_p0
        out[round(h["load_factor"], 9)] = {
            "Q": q / (p.friction * normal),
            "c_theory": cattaneo.stick_half_width(p, q) / a,
            "stick": float(np.abs(x[stick]).max() / a) if stick.any() else 0.0,
            "peak": float(shear[h["cpress"] > 0].max(initial=0.0)) / mu_p0,
            "peak_theory": peak_theory(p, q),
            "rms": float(np.sqrt(np.mean(err**2))) if on.any() else float("nan"),
            "normal": float(h.get("contact_normal_force", np.nan))}
    return out


def run_ccx(p: cattaneo.Parameters, slave: str, slope: float, args) -> dict:
    model = cattaneo.build(p)
    keep = (Path(args.keep) / f"{p.facets_upper}_{p.facets_lower}_slope{slope:g}"
            if args.keep else None)
    folder = keep or Path(args.scratch)
    folder.mkdir(parents=True, exist_ok=True)
    deck = write_deck(model, folder / "cattaneo.inp", slave=slave, penalty=args.penalty,
                      steps="curves", friction=p.friction, stick_slope=slope)
    r = run(deck, ccx=args.ccx, threads=args.threads, timeout=args.timeout, keep=keep)
    body = {b.name: b for b in model.bodies}
    moved = next(f"B_{b.name.upper()}_{pd.boundary.upper()}" for b in body.values()
                 for pd in b.prescribed)
    support = next(f"B_{b.name.upper()}_{s.boundary.upper()}" for b in body.values()
                   for s in b.supports)
    rows = ccx_rows(r["history"], p, moved, support)
    return {"result": r, "rows": rows}


def fmt(row: dict | None) -> str:
    if row is None:
        return f"{'(no increment)':>47}"
    return (f"{row['Q']:7.4f} {row['c_theory']:6.3f} {row['stick']:6.3f} {row['peak']:6.3f} "
            f"{row['peak_theory']:7.3f} {100 * row['rms']:6.2f}")


def table(p: cattaneo.Parameters, dofs: int, vfem: dict, ccx: dict[float, dict], args) -> None:
    th = cattaneo.theory(p)
    main = next(s for s in args.stick_slope if "rows" in ccx[s])  # the first that ran
    r, rows = ccx[main]["result"], ccx[main]["rows"]
    shear = sorted(f for f in vfem["rows"])
    print(f"\n{p.facets_upper}/{p.facets_lower} contact facets across a: {dofs} dofs; "
          f"a = {th['a']:.5f}, mu p0 = {p.friction * th['p0']:.1f}; ccx: penalty "
          f"{args.penalty:g}, stick slope {main:g}, slave {vfem['slave']}")
    head = (f"{'Q/muP':>7} {'c/a th':>6} {'stick':>6} {'peak':>6} {'peak th':>7} "
            f"{'rms %':>6}")
    print(f"{'load':>6} | {'vfem':^47} | {'ccx':^47}")
    print(f"{'factor':>6} | {head} | {head}")
    for f in shear:
        print(f"{f:6.3f} | {fmt(vfem['rows'][f])} | {fmt(rows.get(f))}")
    its = r["step_iterations"]
    names = {1: "approach", 2: "press", 3: "shear"}
    ccx_its = sum(its.values())
    print(f"vfem: {vfem['seconds']:.2f} s, {vfem['iterations']} contact iterations (press "
          f"{vfem['press_iterations']}, shear {vfem['iterations'] - vfem['press_iterations']})")
    print(f"ccx:  {r['wall_s']:.2f} s (its own total {r['ccx_total_s']:.2f} s), {ccx_its} "
          f"iterations ({', '.join(f'{names.get(k, k)} {v}' for k, v in its.items())}), "
          f"{r['cutbacks']} cutbacks, {r['solver']} solver, {r['threads']} thread(s)")
    print(f"ccx / vfem: time {r['wall_s'] / vfem['seconds']:.1f}x, iterations "
          f"{ccx_its / max(vfem['iterations'], 1):.1f}x; ccx's normal contact force at the end of "
          f"the press / P - 1 = {100 * (press_normal(rows) / p.force - 1):+.3f} %")
    if len(args.stick_slope) > 1:
        slopes = args.stick_slope
        print("ccx against its stick slope (per slope: Q/(mu P), outermost sticking node x/a, "
              "peak / mu p0)")
        print(f"{'load':>6} {'c/a th':>6} {'vfem':>6} | "
              + " | ".join(f"{f'slope {s:g}':^20}" for s in slopes))
        for f in shear:
            cells = []
            for s in slopes:
                row = ccx[s]["rows"].get(f) if "rows" in ccx[s] else None
                cells.append(f"{row['Q']:6.4f} {row['stick']:6.3f} {row['peak']:6.3f}"
                             if row else f"{'-':^20}")
            print(f"{f:6.3f} {vfem['rows'][f]['c_theory']:6.3f} {vfem['rows'][f]['stick']:6.3f}"
                  " | " + " | ".join(cells))
        cells = [(f"{sum(ccx[s]['result']['step_iterations'].values()):6d} its "
                  f"{ccx[s]['result']['wall_s']:7.1f} s") if "result" in ccx[s] else
                 f"{'failed':^20}" for s in slopes]
        print(f"{'totals':>20} | " + " | ".join(cells))


def press_normal(rows: dict[float, dict]) -> float:
    """ccx's normal contact force at the end of the press (load factor 0.5)."""
    return rows.get(0.5, {}).get("normal", float("nan"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("facets", type=int, nargs="*", default=[17, 24, 43, 61],
                    help="pairs of contact facets across a, upper and lower (default 17 24 43 61)")
    ap.add_argument("--stick-slope", type=float, nargs="+", default=[1e11],
                    help="ccx's stick slope(s); the first fills the table (default 1e11)")
    ap.add_argument("--penalty", type=float, default=1e11,
                    help="ccx's contact stiffness per unit overclosure (default 1e11)")
    ap.add_argument("--threads", type=int, default=1, help="ccx's threads (default 1)")
    ap.add_argument("--ccx", default="ccx", help="the CalculiX executable")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per ccx run")
    ap.add_argument("--keep", help="a folder for ccx's files, one subfolder per mesh and slope")
    args = ap.parse_args()
    if len(args.facets) % 2:
        ap.error("facet counts come in pairs: UPPER LOWER ...")
    if shutil.which(args.ccx) is None:
        print(f"skipped: {args.ccx!r} not found (install CalculiX: apt install calculix-ccx)")
        return
    import tempfile

    for upper, lower in zip(args.facets[::2], args.facets[1::2]):
        p = cattaneo.Parameters(facets_upper=upper, facets_lower=lower)
        t0 = time.perf_counter()
        result, readings = cattaneo.solve(p)
        seconds = time.perf_counter() - t0
        if not result.converged:
            print(f"skipped {upper}/{lower}: vfem did not converge")
            continue
        press = [s for s in result.steps if s.load_factor <= 0.5 + 1e-12]
        vfem = {"rows": vfem_rows(result, p), "seconds": seconds, "slave": readings[-1].fine,
                "iterations": sum(s.iterations for s in result.steps),
                "press_iterations": sum(s.iterations for s in press)}
        dofs = sum(2 * b.npoints for b in result.model.bodies)
        ccx = {}
        with tempfile.TemporaryDirectory(prefix="vfem-cattaneo-") as scratch:
            args.scratch = scratch
            for slope in args.stick_slope:
                try:
                    ccx[slope] = run_ccx(p, vfem["slave"], slope, args)
                except VfemError as exc:
                    lines = str(exc).splitlines()
                    why = next((x.strip() for x in lines if "*ERROR" in x), lines[0])
                    print(f"skipped ccx on {upper}/{lower}, stick slope {slope:g}: {why}")
                    ccx[slope] = {}
        if not any("rows" in c for c in ccx.values()):
            continue
        table(p, dofs, vfem, ccx, args)


if __name__ == "__main__":
    main()
