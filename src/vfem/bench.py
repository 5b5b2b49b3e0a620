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

import shutil
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .examples.hertz import HertzParameters, build, evaluate, theory
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


CALCULIX_HEADER = (f"{'level':>5} {'dofs':>8} {'ccx s':>8} {'incs':>5} {'iters':>7} "
                   f"{'raw err':>9} {'nodal err':>10} {'vfem s':>8} {'vfem err':>9} "
                   f"{'ccx/vfem':>9}")


def calculix_rows(levels: list[int], print_row: Callable[[str], None] | None = None,
                  ccx: str = "ccx", threads: int = 1, penalty: float = 1e11,
                  timeout: float = 600.0, keep: str | Path | None = None) -> list[dict]:
    """vfem and CalculiX on the same Hertz meshes; ``[]`` when ``ccx`` is not installed.

    Per level: vfem's analysis time (as :func:`hertz_benchmark` measures it) and p_max error;
    the wall time of the ccx process (deck writing and result reading excluded), its
    increments (load steps) and iterations (``ccx_iterations_total`` counts the contact-making
    first step's too, as the printed table does), and its p_max error read two ways: ccx's own
    contact pressure on the slave nodes ("raw", CPRESS) and the cylinder's nodal contact forces
    ``K u`` per undeformed tributary length (vfem's reading). ``keep``: a folder for ccx's
    files, one sub-folder per level.
    """
    if shutil.which(ccx) is None:
        return []
    from .io.calculix import run, write_deck

    rows = []
    if print_row:
        print_row(CALCULIX_HEADER)
    for level in levels:
        p = HertzParameters(refinement=level)
        model = build(p)
        t0 = time.perf_counter()
        result = Analysis(model).run()
        vfem_s = time.perf_counter() - t0
        h = evaluate(result, p) if result.converged else {}
        with tempfile.TemporaryDirectory(prefix="vfem-bench-ccx-") as tmp:
            deck = write_deck(model, Path(tmp) / f"hertz{level}.inp", penalty=penalty)
            c = run(deck, ccx=ccx, threads=threads, timeout=timeout,
                    p0=theory(p)["p0_theory"],
                    keep=None if keep is None else Path(keep) / f"level{level}")
        row = {
            "level": level,
            "dofs": c["dofs"],
            "ccx_s": c["wall_s"],
            "ccx_threads": c["threads"],
            "ccx_solver": c["solver"],
            "ccx_equations": c["equations"],
            "ccx_increments": c["increments"],
            "ccx_iterations": c["iterations"],
            "ccx_cutbacks": c["cutbacks"],
            "ccx_contact_step_iterations": c["contact_step_iterations"],
            "ccx_iterations_total": c["iterations"] + c["contact_step_iterations"],
            "ccx_penalty": penalty,
            "ccx_p_max_error_raw": c["p_max_error_raw"],
            "ccx_p_max_error_nodal": c["p_max_error_nodal"],
            "ccx_flat_p_max_error_nodal": c["p_max_master_error_nodal"],
            "ccx_total_contact_force": c["contact_normal_force"],
            "ccx_nodal_residual": c["nodal_residual"],
            "vfem_s": vfem_s,
            "vfem_iterations": int(sum(s.iterations for s in result.steps)),
            "vfem_converged": result.converged,
            "vfem_p_max_error": h.get("p_max_error", float("nan")),
            "ratio": c["wall_s"] / vfem_s,
        }
        rows.append(row)
        if print_row:
            print_row(f"{level:>5} {row['dofs']:>8} {row['ccx_s']:>8.2f} "
                      f"{row['ccx_increments']:>5} {row['ccx_iterations_total']:>7} "
                      f"{row['ccx_p_max_error_raw']:>+9.3%} {row['ccx_p_max_error_nodal']:>+10.4%} "
                      f"{vfem_s:>8.2f} {row['vfem_p_max_error']:>+9.4%} {row['ratio']:>9.1f}")
    return rows
