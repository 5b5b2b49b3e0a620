"""The cylinder pressed into a plastic block, vfem against CalculiX on the same mesh (issue 41's
acceptance: "the cylinder indentation loaded past yield and unloaded, against CalculiX
(*PLASTIC, the same mesh): the force-indentation curve and the residual dent within 2 %; time
ratio beside it").

The ``block_indentation`` example (``vfem_examples.block_indentation``: a stiff elastic cylinder
on an elastic-perfectly plastic J2 block graded in width and depth, a force-controlled platen
loaded to ``overload`` times the yield onset's force and back to a hundredth of it) written as a
CalculiX deck by :func:`vfem_tools.calculix.write_deck` (the same nodes and elements, CPE4; the
block's ``*PLASTIC``, perfectly plastic; frictionless surface-to-surface penalty contact, the
block the slave; ``steps="curves"``: one ccx step up and one down, increments at the model's
load factors). At every load factor both codes carry the same platen force, so the
force-indentation curves are compared by the platen's travel there: printed per load factor,
vfem's, ccx's and their difference as a share of the peak travel; then the dent (the block's
top on the axis at the last load factor), and the two codes' seconds (vfem's solve, ccx's
process, one thread each).

    python3 benchmarks/indentation_calculix.py                 # the example's defaults
    python3 benchmarks/indentation_calculix.py --set facets_per_half_width=16
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from vfem.solver import Analysis
from vfem_examples import block_indentation as bi
from vfem_tools import calculix


def parse(assignments: list[str]) -> bi.BlockIndentationParameters:
    p = bi.BlockIndentationParameters()
    for item in assignments:
        key, _, value = item.partition("=")
        kind = type(getattr(p, key))
        p = dataclasses.replace(p, **{key: kind(value)})
    return p


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a parameter of the block_indentation example")
    ap.add_argument("--penalty", type=float, default=1e11, help="ccx's contact stiffness")
    ap.add_argument("--keep", help="a folder for ccx's files")
    args = ap.parse_args(argv)
    os.environ.setdefault("VFEM_THREADS", "1")
    p = parse(args.set)
    model = bi.build(p)
    t0 = time.perf_counter()
    result = Analysis(model).run()
    vfem_s = time.perf_counter() - t0
    if not result.converged:
        raise SystemExit(f"vfem: {result.message}")
    block = next(b for b in model.bodies if b.name == "block")
    X = block.mesh.p
    axis = int(np.argmin(np.hypot(X[0], X[1])))
    travel = {round(s.load_factor, 9): -s.platen_displacement for s in result.steps}
    dent = -result.steps[-1].bodies["block"].displacement[axis, 1]

    with tempfile.TemporaryDirectory() as tmp:
        deck = calculix.write_deck(bi.build(p), Path(tmp) / "indentation.inp", slave="block",
                                   penalty=args.penalty, steps="curves")
        ccx = calculix.run(deck, keep=args.keep)
    rows = [r for r in ccx["history"] if "platen_displacement" in r]
    peak = max(travel.values())
    print(f"block_indentation: {sum(b.ndofs for b in model.bodies)} dofs, overload "
          f"{p.overload:g}, {p.facets_per_half_width} elements over the peak's half-width")
    print(f"{'load factor':>11} {'force/onset':>11} {'vfem travel':>12} {'ccx travel':>12} "
          f"{'difference/peak':>15}")
    worst = 0.0
    for r in rows:
        lf = round(r["load_factor"], 9)
        if lf not in travel:
            continue
        force = p.overload * (lf if lf <= 1 else 2 - lf)
        ccx_travel = -r["platen_displacement"]
        diff = (ccx_travel - travel[lf]) / peak
        worst = max(worst, abs(diff))
        print(f"{lf:>11.4f} {force:>11.3f} {travel[lf]:>12.5e} {ccx_travel:>12.5e} "
              f"{diff:>+15.2e}")
    last = rows[-1]
    ccx_dent = -last["u"][axis, 1] if "u" in last else float("nan")
    print(f"largest travel difference: {100 * worst:.2f} % of the peak travel {peak:.5e}")
    print(f"dent on the axis: vfem {dent:.5e}, ccx {ccx_dent:.5e} "
          f"({100 * (dent / ccx_dent - 1):+.2f} %)")
    print(f"seconds: vfem {vfem_s:.1f}, ccx {ccx['wall_s']:.1f} (ccx / vfem "
          f"{ccx['wall_s'] / vfem_s:.2f}); ccx {ccx['increments']} increments, "
          f"{ccx['iterations']} iterations, {ccx['cutbacks']} cutbacks")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
