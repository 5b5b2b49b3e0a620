"""An O-ring pressed by a lid, vfem against CalculiX on the same mesh (issue 42's acceptance:
"O-ring: ... against CalculiX (axisymmetric CAX4 or CAX8, ``*HYPERELASTIC, NEO HOOKE``, the
same mesh) within 3 %; time ratio beside it").

The model (default: the ``oring`` example, ``vfem_examples.oring``, without the groove's walls,
which it does not touch; ``--model`` an input file of a ring and a lid): the upper half of an
O-ring's cross-section (a half disk of radius 1 about r = 10, bilinear quadrilaterals, ``kinematics
= "total"``, ``law = "neo-hookean-isochoric"``: ccx's NEO HOOKE, the same law, E = 6, nu = 0.49,
``plane = "axisymmetric"``), its flat side on the plane of symmetry (held in y), pressed by a stiff
elastic lid (E = 2e5) moved down 0.3 (30 % compression of the section) in six steps, Coulomb
friction 0.2 between lid and ring. vfem solves it (``vfem.solve``); ccx solves the deck
:func:`vfem_tools.calculix.write_deck` makes of it (``steps="model"``: one ccx step per load
factor): the same nodes and elements as CAX4, the ring ``*HYPERELASTIC, NEO HOOKE``, NLGEOM,
surface-to-surface penalty contact (the ring the slave) with ccx's penalty friction.

Printed per load factor: the lid's displacement and the compression (over the ring's height),
the lid's force (its held top's total reaction, y, per full circle: vfem's
``reaction_total``; ccx's RF of the top, which ccx gives for its 2-degree wedge, times 180),
their difference; the contact width (the spread in deformed r of the ring's nodes in contact:
vfem's contact status, ccx's CPRESS > 0) and the peak contact pressure (Cauchy: vfem's normal
nodal contact force over the node's deformed tributary area, 2 pi r times half of each
adjoining facet; ccx's nodal CPRESS, extrapolated from its integration points), the largest over
the nodes in contact but the two outermost (where ccx's extrapolation overshoots: at 30 % it
reads 6.6 and 5.5 against 3.6 inside, and vfem's tributary half lies outside the contact).
Then ccx again at a tenth of the penalty (the largest force change, the acceptance that the
penalty does not matter: within 0.3 %), the two codes' seconds (one thread each:
``VFEM_THREADS=1``, ``OMP_NUM_THREADS=1`` and ccx's ``CCX_NPROC_*``; vfem's ``solve``, ccx's
process) and their ratio, and the two neo-Hookean laws at a material point.

The laws. vfem's :class:`vfem.materials.NeoHookean` is Ciarlet-Simo's, ``W = mu/2 (I1 - 3) -
mu ln J + lambda/2 (ln J)^2``; ccx's NEO HOOKE is ``W = C10 (I1bar - 3) + (J - 1)^2 / D1``
(``I1bar = J^(-2/3) I1``), written with the same small-strain constants (``C10 = mu / 2``,
``D1 = 2 / K``, ``K = lambda + 2 mu / 3``). They part at finite strain, ccx's the stiffer: the
nominal stress at a stretch of 0.7 (30 % compression) is 0.76 % higher in ccx's law under
uniaxial stress and 1.8 % higher under plane strain (the hoop stretch held: the section of a
ring of radius 10 is near it), 0.46 % and 1.0 % at 0.8 (:func:`laws`): about the difference at
full compression, which is then the law's, not the contact's. No form of ccx 2.20's
``*HYPERELASTIC`` (ARRUDA-BOYCE, MOONEY-RIVLIN, NEO HOOKE, OGDEN, POLYNOMIAL, REDUCED
POLYNOMIAL, YEOH) equals vfem's law: all split W into I1bar (or the deviatoric stretches) and a
function of J, while vfem's I1 term couples them (``I1 = J^(2/3) I1bar``). ``*HYPERFOAM`` with
N = 1, alpha = 2 has vfem's ``mu/2 (I1 - 3)`` but ``mu/(2 beta) (J^(-2 beta) - 1)`` for the
volumetric part, equal to vfem's to second order in ln J only (0.21 % uniaxially, 1.5 % in
plane strain at 0.7), and ccx 2.20 stops on this deck with it (exit status 255, no message).

Penalty and friction: the normal penalty 1e6 (pressure per unit overclosure: 4e-6 at the peak
pressure, 1e-4 of the smallest step's travel), the stick slope 1e4 (elastic slip at most mu p /
1e4 = 7e-5); with the stick slope at the penalty, ccx's default, ccx does not converge (too
many cutbacks in the first step) at penalties of 3e4, 1e5 and 1e6; a slope of 3e4 instead of
1e4 changes the force by under 0.01 %.

Measured on the example's defaults without its walls (ccx 2.20, 3,460 dofs, h = d/40, six
steps; 2 shared cores, 2026-12-03), the same law in both codes: the force differences (vfem -
ccx)/ccx at 5, 10, ..., 30 % compression +0.59, +0.23, +0.13, +0.02, +0.03 and +0.05 %; the
contact width alike to 0.001 but at 15 % and 30 % (one node more in ccx's contact); the peak
pressure -2.2 % at 5 % (three nodes in contact), then within 0.23 %; penalty 1e5 against 1e6
within 0.015 %; vfem 4.5 s, ccx 27.6 s (ratio 6.1). With vfem's Ciarlet-Simo law instead (the
example's ``law = "neo-hookean"``; ccx's NEO HOOKE is then not the same law): +0.48 ... -1.28 %,
growing with the compression as the laws part (below).

    python3 benchmarks/oring_calculix.py
    python3 benchmarks/oring_calculix.py --model ring_and_lid.toml --keep /tmp/ccx_oring

Needs ``ccx`` (Debian: calculix-ccx); prints a note without it.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def laws(E: float = 6.0, nu: float = 0.49, stretches=(0.9, 0.8, 0.7)) -> list[dict]:
    """The nominal stress of vfem's neo-Hookean law and of ccx's NEO HOOKE (same small-strain
    constants) at a material point compressed to each principal stretch, under uniaxial stress
    and under plane strain (the third stretch 1): ``{"stretch", "state", "vfem", "ccx",
    "difference"}`` (ccx's over vfem's, minus 1). vfem's stress is its law's own
    (:meth:`vfem.materials.NeoHookean.second_piola`); ccx's from its potential's principal
    Kirchhoff stresses, ``tau_i = 2 C10 J^(-2/3) (l_i^2 - I1/3) + 2/D1 J (J - 1)``."""
    from scipy.optimize import brentq

    from vfem.materials.hyperelastic import NeoHookean

    law = NeoHookean(E, nu)
    lam, mu = law.lame()
    bulk = lam + 2.0 * mu / 3.0

    def vfem(s: np.ndarray) -> np.ndarray:  # principal nominal stresses P_i = l_i S_i
        strain = np.diag(0.5 * (s**2 - 1.0))[:, :, None]
        return s * np.diag(law.second_piola(strain)[:, :, 0])

    def ccx(s: np.ndarray) -> np.ndarray:
        J = float(np.prod(s))
        i1 = float(np.sum(s**2))
        return (mu * J ** (-2.0 / 3.0) * (s**2 - i1 / 3.0) + bulk * J * (J - 1.0)) / s

    out = []
    for stretch in stretches:
        for state in ("uniaxial stress", "plane strain"):
            row = {"stretch": stretch, "state": state}
            for name, stress in (("vfem", vfem), ("ccx", ccx)):
                def stretches_at(s2, plane=state == "plane strain", s1=stretch):
                    return np.array([s1, s2, 1.0 if plane else s2])

                def lateral(s2, stress=stress, at=stretches_at):
                    return stress(at(s2))[1]
                s2 = brentq(lateral, 0.5, 2.0, xtol=1e-14)
                row[name] = float(stress(stretches_at(s2))[0])
            row["difference"] = row["ccx"] / row["vfem"] - 1.0
            out.append(row)
    return out


def _tributary(body, facets: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Each point's share of the ``facets`` at positions ``x`` (npoints, 2): half of each
    facet it ends, times 2 pi r at the facet's middle for a body of revolution."""
    ends = body.mesh.facets[:, facets]
    length = np.linalg.norm(x[ends[0]] - x[ends[1]], axis=1)
    if body.section.space == "axisymmetric":
        length = length * 2.0 * np.pi * 0.5 * (x[ends[0], 0] + x[ends[1], 0])
    out = np.zeros(len(x))
    np.add.at(out, ends[0], 0.5 * length)
    np.add.at(out, ends[1], 0.5 * length)
    return out


def _width_and_peak(x: np.ndarray, pressure: np.ndarray) -> tuple[float, float]:
    """The spread in r of the points in contact (``x``: their deformed positions) and the
    largest of their ``pressure`` but at the two outermost (all of them if fewer than 3)."""
    if not len(x):
        return 0.0, 0.0
    order = np.argsort(x[:, 0])
    inner = pressure[order][1:-1] if len(x) >= 3 else pressure
    return float(np.ptp(x[:, 0])), float(inner.max())


def vfem_rows(result, ring: str, lid: str, facets: np.ndarray) -> dict[float, dict]:
    """Per load factor of vfem's result: the lid's force (y of its ``reaction_total``), the
    contact width and the peak Cauchy pressure on the ring (its candidate ``facets``)."""
    body = next(b for b in result.model.bodies if b.name == ring)
    nodes = np.unique(body.mesh.facets[:, facets])
    out = {}
    for step in result.steps:
        r = step.bodies[ring]
        x = body.mesh.p.T + r.displacement
        on = nodes[r.contact_status[nodes] > 0]
        trib = _tributary(body, facets, x)
        pressure = np.linalg.norm(r.contact_force[on], axis=1) / trib[on]
        width, peak = _width_and_peak(x[on], pressure)
        out[round(step.load_factor, 9)] = {
            "force": float(step.bodies[lid].reaction_total[1]), "width": width, "peak": peak}
    return out


def ccx_rows(ccx: dict, deck, lid: str) -> dict[float, dict]:
    """Per model load factor ccx reached (its increments that end on one): the lid's force (the
    total reaction of its prescribed boundary, y, per full circle), the contact width and the
    peak CPRESS on the slave (the ring)."""
    model = deck.model
    body = next(b for b in model.bodies if b.name == deck.slave)
    lid_body = next(b for b in model.bodies if b.name == lid)
    held = f"B_{lid.upper()}_{lid_body.prescribed[0].boundary.upper()}"
    factors = np.array([round(f, 9) for f in model.load_factors])
    out = {}
    for row in ccx["history"]:
        # (the .frd file's times have 6 digits: 1/3 reads 0.333333)
        k = int(np.argmin(np.abs(factors - row["load_factor"])))
        lf = float(factors[k])
        if (abs(lf - row["load_factor"]) > 1e-5 or held not in row["reactions"]
                or "u" not in row):
            continue
        on = row["cpress"] > 0
        nodes = row["nodes"][on]
        x = body.mesh.p[:, nodes].T + row["u"][nodes]
        width, peak = _width_and_peak(x, row["cpress"][on])
        out[lf] = {"force": float(row["reactions"][held][1]), "width": width, "peak": peak}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", type=Path, default=None,
                    help="a vfem input file of a ring and a lid (default: the oring example "
                         "without its walls)")
    ap.add_argument("--lid", default="lid", help="the body whose prescribed boundary moves")
    ap.add_argument("--penalty", type=float, default=1e6, help="ccx's contact stiffness")
    ap.add_argument("--stick-slope", type=float, default=1e4, help="ccx's *FRICTION slope")
    ap.add_argument("--no-penalty-check", action="store_true",
                    help="skip ccx's second run at a tenth of the penalty")
    ap.add_argument("--ccx", default="ccx", help="the CalculiX executable")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per ccx run")
    ap.add_argument("--keep", help="a folder for ccx's files")
    args = ap.parse_args(argv)
    os.environ.setdefault("VFEM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")

    import vfem
    from vfem.io.input import load
    from vfem_tools import calculix

    if args.model is not None:
        path, config = args.model, load(args.model)
    else:  # the oring example without its walls (which it does not touch): two bodies
        import dataclasses

        from vfem_examples import oring

        path = "the oring example (walls = false)"
        config = oring.config(dataclasses.replace(oring.ORingParameters(), walls=False))
    model = config.build()
    friction = model.contact.friction or None
    names = [b.name for b in model.bodies]
    if args.lid not in names:
        raise SystemExit(f"no body {args.lid!r} in {path} (it has {', '.join(names)})")

    t0 = time.perf_counter()
    result = vfem.solve(config)
    vfem_s = time.perf_counter() - t0
    if not result.converged:
        print(f"vfem did not converge: {result.message}")

    if shutil.which(args.ccx) is None:
        print(f"CalculiX ({args.ccx!r}) is not installed: vfem alone took {vfem_s:.1f} s")
        return 0

    with tempfile.TemporaryDirectory() as tmp:
        deck, ccx, other = calculix.run_with_penalty_check(
            config, Path(tmp) / "oring.inp", args.penalty, check=not args.no_penalty_check,
            keep=args.keep, ccx=args.ccx, timeout=args.timeout, friction=friction,
            stick_slope=args.stick_slope)
    ring = deck.slave
    ours = vfem_rows(result, ring, args.lid, deck.body(ring).contact_facets)
    theirs = ccx_rows(ccx, deck, args.lid)

    lid_body = next(b for b in model.bodies if b.name == args.lid)
    ring_body = next(b for b in model.bodies if b.name == ring)
    height = float(np.ptp(ring_body.mesh.p[1]))
    move = lid_body.prescribed[0]
    print(f"{path}: {model.name!r}, {sum(2 * b.npoints for b in model.bodies)} dofs, "
          f"friction {friction or 0:g}; ccx penalty {args.penalty:g}, stick slope "
          f"{args.stick_slope:g}; forces per full circle")
    print(f"{'lf':>5} {'lid u':>8} {'compr.':>6} {'F vfem':>10} {'F ccx':>10} {'diff':>7}  "
          f"{'width vfem':>10} {'ccx':>6}  {'p_max vfem':>10} {'ccx':>6} {'diff':>7}")
    worst = 0.0
    for lf in sorted(ours):
        v = ours[lf]
        u = move.at(lf)
        c = theirs.get(lf)
        if c is None:
            print(f"{lf:>5.2f} {u:>8.4f} {100 * abs(u) / height:>5.1f}% {v['force']:>10.4f} "
                  f"{'(none)':>10}")
            continue
        diff = v["force"] / c["force"] - 1.0
        worst = max(worst, abs(diff))
        print(f"{lf:>5.2f} {u:>8.4f} {100 * abs(u) / height:>5.1f}% {v['force']:>10.4f} "
              f"{c['force']:>10.4f} {100 * diff:>+6.2f}%  {v['width']:>10.4f} "
              f"{c['width']:>6.3f}  {v['peak']:>10.4f} {c['peak']:>6.3f} "
              f"{100 * (v['peak'] / c['peak'] - 1.0):>+6.2f}%")
    print(f"largest force difference: {100 * worst:.2f} % (the acceptance: 3 %)")
    if other is not None:
        low = ccx_rows(other, deck, args.lid)
        common = sorted(set(low) & set(theirs))
        change = max(abs(low[f]["force"] / theirs[f]["force"] - 1.0) for f in common)
        print(f"ccx at a penalty of {args.penalty / 10:g}: the force within "
              f"{100 * change:.3f} % of {args.penalty:g}'s at {len(common)} load factors")
    print(f"seconds (one thread each): vfem {vfem_s:.1f}, ccx {ccx['wall_s']:.1f} "
          f"(ccx / vfem {ccx['wall_s'] / vfem_s:.1f}); ccx {ccx['increments']} increments, "
          f"{ccx['iterations']} iterations, {ccx['cutbacks']} cutbacks")
    E, nu = ring_body.material.youngs_modulus, ring_body.material.poissons_ratio
    print(f"the laws at a material point (E {E:g}, nu {nu:g}): ccx's NEO HOOKE over vfem's "
          "neo-Hookean, nominal stress")
    for row in laws(E, nu):
        print(f"  stretch {row['stretch']:.2f}, {row['state']:<15}: vfem {row['vfem']:+.5f}, "
              f"ccx {row['ccx']:+.5f} ({100 * row['difference']:+.2f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
