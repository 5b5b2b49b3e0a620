"""Hertz under large kinematics against the linear analysis, by load.

    python benchmarks/large_hertz.py [FRACTION ...]   # of the thesis's force; default 1 .. 1e-4

For each fraction of the thesis's force (1530 on the half model) it solves the Hertz example with
small kinematics and with the total and updated Lagrangian formulations, and prints p_max, the
large/linear difference, total vs updated and the contact iterations. The difference is
geometric nonlinearity: it falls with the contact strain (p0 / E*, about 3 % at the thesis's force).
"""

import dataclasses
import sys
import time

from vfem.solver import Analysis
from vfem_examples import hertz


def run(fraction: float, kinematics: str) -> tuple[float, int, float]:
    config = hertz.config(hertz.HertzParameters(force=1530.0 * fraction))
    config = dataclasses.replace(config, bodies=tuple(
        dataclasses.replace(b, kinematics=kinematics) for b in config.bodies))
    analysis = Analysis(config.build())
    t0 = time.perf_counter()
    result = analysis.run()
    seconds = time.perf_counter() - t0
    if not result.converged:
        raise SystemExit(f"{kinematics} at {fraction:g}: {result.message}")
    p_max = max(float(b.contact_pressure.max()) for b in result.steps[-1].bodies.values())
    return p_max, sum(s.iterations for s in result.steps), seconds


if __name__ == "__main__":
    fractions = [float(a) for a in sys.argv[1:]] or [1.0, 0.1, 0.01, 1e-3, 1e-4]
    print(f"{'force':>8} {'p_max linear':>13} {'total':>13} {'total/linear-1':>15} "
          f"{'updated/total-1':>16} {'iterations (lin, TL, UL)':>25} "
          f"{'s (lin, TL)':>12}")
    for f in fractions:
        lin, it_l, s_l = run(f, "small")
        tl, it_t, s_t = run(f, "total")
        ul, it_u, _ = run(f, "updated")
        print(f"{f:8.0e} {lin:13.6g} {tl:13.6g} {tl / lin - 1:15.3e} {ul / tl - 1:16.1e} "
              f"{f'{it_l}, {it_t}, {it_u}':>25} {f'{s_l:.1f}, {s_t:.1f}':>12}")
