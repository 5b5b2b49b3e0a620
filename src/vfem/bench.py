"""Benchmarks: what a contact solve costs against one plain linear solve of the same bodies.

``vfem bench hertz`` (and ``benchmarks/hertz.py``) runs the Hertz example at several refinements
and prints, per level: dofs, contact candidate dofs, vfem's analysis time (assembly,
factorization with the flexibility, all contact steps; mesh generation and file output
excluded), the time of one plain linear solve of the same bodies with the same backend (factor +
solve, assembly excluded), their ratio, the same ratio with the assembly left out of vfem's time
too, the parts of vfem's time, the contact iterations and the p_max error. Both are measured in
the same process, one after the other.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from .examples.hertz import HertzParameters, build, evaluate
from .linalg import factorize
from .solver import Analysis

HEADER = (f"{'level':>5} {'dofs':>8} {'contact':>8} {'vfem s':>8} {'plain s':>8} {'ratio':>6} "
          f"{'w/o asm':>7} {'asm s':>7} {'factor s':>8} {'steps s':>8} {'iters':>6} "
          f"{'p_max err':>10}")


def plain_solve_time(model) -> float:
    """Factor and solve each body of ``model`` once (its supports, its loads); seconds."""
    total = 0.0
    for body in model.bodies:
        K = body.K_ff
        rhs = np.ones(K.shape[0])
        t0 = time.perf_counter()
        factorize(K).solve(rhs)
        total += time.perf_counter() - t0
    return total


def hertz_benchmark(levels: list[int], print_row: Callable[[str], None] | None = None,
                    variant: str = "paired", order: int = 1) -> list[dict]:
    rows = []
    if print_row:
        print_row(HEADER)
    for level in levels:
        p = HertzParameters(refinement=level, variant=variant, order=order)
        model = build(p)
        t0 = time.perf_counter()
        analysis = Analysis(model)
        result = analysis.run()
        vfem_s = time.perf_counter() - t0
        plain_s = plain_solve_time(model)
        h = evaluate(result, p) if result.converged else {}
        row = {
            "level": level,
            "variant": variant,
            "order": order,
            "dofs": int(sum(b.ndofs for b in model.bodies)),
            "facets_across_a": p.facets_per_half_width * 2**level,
            "contact_dofs": int(sum(2 * s.nc for s in result.surfaces)),
            "vfem_s": vfem_s,
            "plain_solve_s": plain_s,
            "ratio": vfem_s / plain_s,
            "ratio_without_assembly": (vfem_s - result.timings["assemble_s"]) / plain_s,
            "assemble_s": result.timings["assemble_s"],
            "factorize_s": result.timings["factorize_s"],
            "steps_s": result.timings["steps_s"],
            "iterations": int(sum(s.iterations for s in result.steps)),
            "converged": result.converged,
            "p_max_error": h.get("p_max_error", float("nan")),
            "rms_error_over_p0": h.get("rms_error_over_p0", float("nan")),
            "rms_error_averaged": h.get("rms_error_averaged", float("nan")),
            "p_max_flat_error": (h["p_max_flat"] / h["p0_theory"] - 1) if h else float("nan"),
        }
        rows.append(row)
        if print_row:
            print_row(f"{level:>5} {row['dofs']:>8} {row['contact_dofs']:>8} "
                      f"{vfem_s:>8.2f} {plain_s:>8.2f} {row['ratio']:>6.1f} "
                      f"{row['ratio_without_assembly']:>7.1f} {row['assemble_s']:>7.2f} "
                      f"{row['factorize_s']:>8.2f} {row['steps_s']:>8.2f} {row['iterations']:>6} "
                      f"{row['p_max_error']:>+10.4%}")
    return rows
