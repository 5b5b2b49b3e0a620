"""Benchmarks: what a contact solve costs against one plain linear solve of the same bodies.

``vfem bench hertz`` (and ``benchmarks/hertz.py``) solves the Hertz example at several sizes,
with each linear-algebra backend and each contact method asked for, and prints per case: dofs,
contact candidate dofs, vfem's analysis time (candidate search, assembly, factorization with the
flexibility, load cases, every contact step with its full-field back-substitution; mesh
generation and file output excluded), the time of one **plain linear solve** of the same bodies
with the same backend (assembly, supports, factorization, one solve: what a linear analysis
without contact costs), their ratio, the ratio with assembly left out of both, the contact
iterations, the p_max error against Hertz and the peak memory of the process.

Each case runs in a fresh Python process (:func:`run_isolated`), so that its peak memory is its
own and one case's garbage does not slow the next; vfem and the plain solve of a case run in the
same process one after the other, so their ratio is measured under the same conditions.
"""

from __future__ import annotations

import dataclasses
import gc
import json
import math
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from vfem.bodies.condensation import solve_with
from vfem.linalg import factorize, resolve
from vfem.solver import Analysis
from vfem_examples.hertz import HertzParameters, build, evaluate, theory

#: named sizes of ``vfem bench hertz --dofs``
SIZES = {"10k": 10_000, "30k": 30_000, "100k": 100_000, "300k": 300_000, "1M": 1_000_000}

#: level 3 of the Hertz example (96 facets across a, largest element 0.05 / 8): 118,648 dofs
#: (with the cylinder's layered contact zone; 76,964 before it)
_LEVEL3_DOFS = 118_648


def parse_size(text: str) -> int:
    """``"100k"``, ``"1M"`` or a number of dofs."""
    if text in SIZES:
        return SIZES[text]
    scale = {"k": 1_000, "m": 1_000_000}.get(text[-1:].lower(), 1)
    number = text[:-1] if scale > 1 else text
    try:
        value = int(float(number) * scale)
    except ValueError:
        from vfem.errors import InputError

        raise InputError(f"--dofs: expected a number of dofs such as 10k, 100k or 1M, got "
                         f"{text!r}") from None
    return value


def hertz_parameters(dofs: int | None = None, level: int | None = None,
                     variant: str = "paired", order: int = 1) -> HertzParameters:
    """The Hertz example at about ``dofs`` degrees of freedom (contact facets and largest
    element scaled together, as the refinement levels do), or at refinement ``level``."""
    if level is not None:
        return HertzParameters(refinement=level, variant=variant, order=order)
    s = 8.0 * math.sqrt(dofs / _LEVEL3_DOFS)
    return HertzParameters(facets_per_half_width=max(4, round(12 * s)),
                           max_element_size=0.05 / s, variant=variant, order=order)


def plain_solve(model, backend: str) -> dict[str, float]:
    """One plain linear analysis of each body of ``model``: assemble every body by vfem's own
    path (:meth:`Body.assemble`: stiffness, supports, load vector), then factorize each one's
    free block and solve once. Seconds, by part (``assemble_s``: scikit-fem's assembly alone,
    as in vfem's own timings)."""
    times = {"assemble_s": 0.0, "constraints_s": 0.0, "factorize_s": 0.0, "solve_s": 0.0}
    for body in model.bodies:  # the whole model assembled first, as vfem's set-up does
        body.assemble()
    for body in model.bodies:
        t0 = time.perf_counter()
        K_ff = body.K[body.free_dofs][:, body.free_dofs].tocsc()
        t1 = time.perf_counter()
        factor = factorize(K_ff, backend)
        t2 = time.perf_counter()
        factor.solve(np.ones(len(body.free_dofs)))
        t3 = time.perf_counter()
        del factor  # one body's factors at a time (3D: 8 GiB for a 575k-dof sphere)
        times["assemble_s"] += body.timings["assemble_s"]
        times["constraints_s"] += body.timings["constraints_s"] + t1 - t0
        times["factorize_s"] += t2 - t1
        times["solve_s"] += t3 - t2
    times["total_s"] = sum(times.values())
    return times


def plain_run(p: HertzParameters, out: Path, backend: str) -> dict[str, float]:
    """A plain linear analysis of the Hertz example's bodies, as a user without contact would
    run one: build the meshes, assemble each body by vfem's own path (:meth:`Body.assemble`),
    factorize, solve once under the body's loads and prescribed displacements (the platen
    held) plus a unit force at every free dof (so that its fields are not all zero), and
    write the same VTU series and PVD the vfem run writes: one file per body and
    step (displacement, reaction, stresses; the contact fields zero), a linear run's fields
    scaled by each step's load factor. Seconds, by part."""
    from vfem.io.results import ResultsWriter
    from vfem.result_types import BodyStepResult, StepResult

    t0 = time.perf_counter()
    model = build(p)
    t1 = time.perf_counter()
    times = {"mesh_s": t1 - t0, "assemble_s": 0.0, "factorize_s": 0.0, "solve_s": 0.0}
    bodies = {}
    for body in model.bodies:
        ta = time.perf_counter()
        body.assemble()
        K_ff = body.K[body.free_dofs][:, body.free_dofs].tocsc()
        tb = time.perf_counter()
        body.factor = factorize(K_ff, backend, what=f"body {body.name!r}")
        tc = time.perf_counter()
        # the body's loads and a unit force at every free dof: fields as dense as a contact
        # run's (under its own loads alone the Hertz bodies stay at rest, and all-zero
        # fields would compress for nothing)
        f = body.f_load.copy()
        f[body.free_dofs] += 1.0
        u = solve_with(body, f, body.u_prescribed)
        n = body.npoints
        zeros = np.zeros(n)
        bodies[body.name] = BodyStepResult(
            displacement=u.reshape(-1, 2), contact_force=np.zeros((n, 2)),
            contact_pressure=zeros, contact_status=np.zeros(n, dtype=int), penetration=zeros,
            contact_traction=zeros, reaction=(body.K @ u - body.f_load).reshape(-1, 2))
        times["assemble_s"] += tb - ta
        times["factorize_s"] += tc - tb
        times["solve_s"] += time.perf_counter() - tc
    t2 = time.perf_counter()
    writer = ResultsWriter(out, model)
    for k, factor in enumerate(model.load_factors, start=1):
        writer.write_step(StepResult(k, factor, 0, True, [], bodies={
            name: dataclasses.replace(r, displacement=factor * r.displacement,
                                      reaction=factor * r.reaction)
            for name, r in bodies.items()}))
    times["output_s"] = time.perf_counter() - t2
    times["total_s"] = time.perf_counter() - t0
    return times


def whole_run_case(p: HertzParameters, backend: str | None = None, repeat: int = 2) -> dict:
    """``vfem run hertz`` end to end (mesh, set-up, steps, VTU, summary, figures: what a user
    waits for) against :func:`plain_run` of the same bodies, alternately, ``repeat`` times, the
    fastest of each kept; the whole run's phases (``summary.json``'s ``phases``)."""
    from vfem.config import _shape_mesh
    from vfem_examples import hertz

    backend = resolve(backend)
    best, plain, summary = None, None, None
    for _ in range(repeat):
        with tempfile.TemporaryDirectory(prefix="vfem-bench-run-") as tmp:
            _shape_mesh.cache_clear()  # each run builds its meshes, as a fresh process does
            t0 = time.perf_counter()
            s = hertz.run(p, Path(tmp) / "run")
            seconds = time.perf_counter() - t0
            if best is None or seconds < best:
                best, summary = seconds, s
            _shape_mesh.cache_clear()
            again = plain_run(p, Path(tmp) / "plain", backend)
            if plain is None or again["total_s"] < plain["total_s"]:
                plain = again
    phases = summary.get("phases", {})
    total = sum(phases.values()) or 1.0
    return {"dofs": int(summary.get("dofs", 0)), "backend": backend, "run_s": best,
            "plain_run_s": plain["total_s"], "ratio": best / plain["total_s"],
            "plain": plain, "phases": phases,
            "phase_shares": {k: v / total for k, v in phases.items()},
            "p_max_error": summary.get("hertz", {}).get("p_max_error", float("nan")),
            "converged": summary.get("converged")}


WHOLE_RUN_HEADER = (f"{'dofs':>9} {'backend':>8} {'run s':>8} {'plain s':>8} {'ratio':>6} "
                    f"{'figures':>8} {'output':>7}  largest phases")


def format_whole_run(r: dict) -> str:
    shares = r["phase_shares"]

    def share(word: str) -> float:
        return sum(v for k, v in shares.items() if word in k.lower())

    top = sorted(shares.items(), key=lambda kv: -kv[1])[:3]
    return (f"{r['dofs']:>9} {r['backend']:>8} {r['run_s']:>8.2f} {r['plain_run_s']:>8.2f} "
            f"{r['ratio']:>6.2f} {share('figure'):>8.1%} {share('output'):>7.1%}  "
            + ", ".join(f"{k} {v:.0%}" for k, v in top))


def _peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def hertz_case(p: HertzParameters, backend: str | None = None, method: str = "vfem",
               repeat: int = 1) -> dict:
    """Solve the Hertz example ``p`` with ``backend`` and contact ``method``, then one plain
    linear solve of the same bodies with the same backend; one row of the benchmark.

    ``repeat``: solve both that many times, alternately, and keep the fastest of each (the
    first solve of a size pays for the memory the libraries then keep: an order effect)."""
    backend = resolve(backend)
    model = build(p)
    if method != "vfem":
        model.contact = dataclasses.replace(model.contact, method=method)
    vfem_s = plain = peak = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        analysis = Analysis(model, backend)
        run = analysis.run()
        seconds = time.perf_counter() - t0
        if vfem_s is None or seconds < vfem_s:
            vfem_s, result = seconds, run
            # the baselines refactorize their global matrix; vfem factorizes each body once
            factorizations = getattr(analysis.contact, "factorizations", len(model.bodies))
        peak = peak or _peak_mib()  # the first solve's: vfem's own peak, before the plain solve
        again = plain_solve(model, backend)
        if plain is None or again["total_s"] < plain["total_s"]:
            plain = again
    h = evaluate(result, p) if result.complete else {}  # (the thesis variant: issue 37)
    t = result.timings
    assemble = t.get("assemble_s", 0.0)
    return {
        "method": method, "variant": p.variant, "order": p.order, "backend": backend,
        "level": p.refinement, "facets_across_a": p.facets_per_half_width * 2**p.refinement,
        "dofs": int(sum(b.ndofs for b in model.bodies)),
        "contact_dofs": int(sum(s.dim * s.nc for s in result.surfaces)),
        "vfem_s": vfem_s, "plain_solve_s": plain["total_s"],
        "ratio": vfem_s / plain["total_s"],
        "ratio_without_assembly": (vfem_s - assemble)
        / (plain["total_s"] - plain["assemble_s"]),
        "plain_assemble_s": plain["assemble_s"], "plain_factorize_s": plain["factorize_s"],
        "plain_solve_only_s": plain["solve_s"],
        "search_s": t.get("search_s", 0.0), "assemble_s": assemble,
        "factorize_s": t.get("factorize_s", 0.0), "steps_s": t.get("steps_s", 0.0),
        "iterations": int(sum(s.iterations for s in result.steps)),
        "factorizations": int(factorizations),
        "converged": result.converged, "message": result.message,
        "peak_mib": peak,
        "p_max_error": h.get("p_max_error", float("nan")),
        "rms_error_over_p0": h.get("rms_error_over_p0", float("nan")),
        "rms_error_averaged": h.get("rms_error_averaged", float("nan")),
        "p_max_flat_error": (h["p_max_flat"] / h["p0_theory"] - 1) if h else float("nan"),
    }


#: the sphere example's dofs (both bodies) by facets_per_radius, measured (2026-11-27/28):
#: the fine zone, a cube of 1.2 a on each body, dominates, and its share grows with the
#: facets, so the dofs grow as a power of the facets that rises from 1.8 to 2.2; between
#: these points :func:`sphere_parameters` interpolates log-log
_SPHERE_DOFS = ((3, 7_623), (6, 26_160), (8, 43_377), (12, 92_172), (16, 161_088),
                (22, 315_825), (29, 568_008), (36, 928_191), (37, 980_694), (43, 1_415_670))


#: the sphere's CalculiX contact stiffness (pressure per unit overclosure): an overclosure of
#: 7e-6 at Hertz's p0, 7e-5 of the sphere's indentation; measured (docs/benchmarks.md, *Sphere
#: (3D)*): 1e8 is too soft (p_max 1 % lower at 7.6k dofs), 1e10 and 1e11 raise ccx's p_max
#: further from vfem's and Hertz's and take twice the iterations
SPHERE_PENALTY = 1e9


def sphere_parameters(dofs: int | None = None, level: int | None = None):
    """The sphere example (quarter model, one step) at about ``dofs`` degrees of freedom (more
    facets across the contact radius, the bulk's elements kept), or at refinement ``level``."""
    from vfem_examples.sphere import SphereParameters

    if level is not None:
        return SphereParameters(refinement=level, steps=1)
    facets, counts = np.log(np.array(_SPHERE_DOFS, dtype=float)).T
    slope = np.diff(facets) / np.diff(counts)  # extrapolated with the end pieces' powers
    k = int(np.clip(np.searchsorted(counts, math.log(dofs)) - 1, 0, len(slope) - 1))
    n = math.exp(facets[k] + slope[k] * (math.log(dofs) - counts[k]))
    return SphereParameters(facets_per_radius=max(3, round(n)), steps=1)


def sphere_case(p, backend: str | None = None, repeat: int = 1) -> dict:
    """:func:`hertz_case` for the sphere example: vfem's analysis time against one plain
    linear solve of the same bodies with the same backend, iterations, p_max error."""
    from vfem_examples.sphere import build as build_sphere
    from vfem_examples.sphere import evaluate as evaluate_sphere

    backend = resolve(backend)
    vfem_s = plain = peak = None
    # The first large allocations of a process are dearer than the same ones later: the
    # kernel faults in and zeroes (with NumPy's huge pages, compacts) memory no one has used
    # yet, while what is freed and asked for again is ready. Measured (2026-12-01, 104k dofs,
    # the two bodies' assembly three times in one process): 5.32 s, then 3.17 and 3.97 s,
    # the system time 2.5 s, then 0.6 and 1.4 s. Whichever of vfem and the plain solve ran
    # first paid it: this was issue 40's "assembly 3.4 s slower than the plain run's for no
    # known reason" at 278k. So one plain solve first, untimed, then the two alike.
    plain_solve(build_sphere(p), backend)
    gc.collect()
    for _ in range(repeat):
        model = build_sphere(p)
        t0 = time.perf_counter()
        run = Analysis(model, backend).run()
        seconds = time.perf_counter() - t0
        if vfem_s is None or seconds < vfem_s:
            vfem_s, result = seconds, run
            h = evaluate_sphere(result, p) if result.converged else {}
            dofs = int(sum(b.ndofs for b in model.bodies))
            contact_dofs = int(sum(s.dim * s.nc for s in result.surfaces))
        peak = peak or _peak_mib()
        # the plain solve on bodies of its own, vfem's factors let go first (both in memory
        # at once would double the peak: 13 GiB of factors each at 928k dofs)
        result = dataclasses.replace(result, model=None, surfaces=[])  # (they hold the bodies)
        del model, run
        gc.collect()
        again = plain_solve(build_sphere(p), backend)
        if plain is None or again["total_s"] < plain["total_s"]:
            plain = again
    t = result.timings
    return {
        "example": "sphere", "method": "vfem", "backend": backend,
        "facets_across_a": p.facets_per_radius * 2 ** p.refinement,
        "dofs": dofs,
        "contact_dofs": contact_dofs,
        "vfem_s": vfem_s, "plain_solve_s": plain["total_s"],
        "ratio": vfem_s / plain["total_s"],
        "ratio_without_assembly": (vfem_s - t.get("assemble_s", 0.0))
        / (plain["total_s"] - plain["assemble_s"]),
        "plain_factorize_s": plain["factorize_s"],
        "search_s": t.get("search_s", 0.0), "assemble_s": t.get("assemble_s", 0.0),
        "factorize_s": t.get("factorize_s", 0.0), "steps_s": t.get("steps_s", 0.0),
        "iterations": int(sum(s.iterations for s in result.steps)),
        "converged": result.converged, "message": result.message,
        "invariants_passed": all(s.invariants.get("passed", False) for s in result.steps),
        "peak_mib": peak,
        "p_max_error": h["sphere"]["p_max_error"] if h else float("nan"),
        "rms_error_over_p0": h["sphere"]["rms_error_over_p0"] if h else float("nan"),
        "a_error_over_facet": (abs(h["sphere"]["a_estimate"] - h["a_theory"]) / h["facet_size"]
                               if h else float("nan")),
    }


def patch_case(method: str = "vfem", backend: str | None = None) -> dict:
    """The patch test (every case of the patch example) with contact ``method``: the largest
    deviation of the contact pressure from the exact uniform one, over the cases."""
    from vfem_examples import patch

    p = patch.Parameters()
    worst, iterations = 0.0, 0
    for n_lower, n_upper, nu in patch.cases():
        model = patch.build(p, n_lower, n_upper, nu)
        if method != "vfem":
            model.contact = dataclasses.replace(model.contact, method=method)
        case = patch.measure(model, Analysis(model, backend).run(), p)
        worst = max(worst, case.get("pressure_deviation", float("inf")))
        iterations += sum(case["iterations"])
    return {"method": method, "patch_error": worst, "patch_iterations": iterations}


def run_isolated(kind: str, **kwargs) -> dict:
    """Run :func:`hertz_case` (``kind="hertz"``, ``kwargs``: ``dofs`` or ``level``,
    ``variant``, ``order``, ``backend``, ``method``), :func:`whole_run_case` (``"run"``) or
    :func:`patch_case` (``"patch"``) in a fresh Python process; its row (which the process
    writes to a file)."""
    with tempfile.TemporaryDirectory(prefix="vfem-bench-") as tmp:
        row = Path(tmp) / "row.json"
        out = subprocess.run([sys.executable, "-m", "vfem_tools.bench", json.dumps([kind, kwargs]),
                              str(row)], capture_output=True, text=True, check=False)
        if out.returncode != 0 or not row.exists():
            from vfem.errors import AnalysisError

            tail = (out.stderr or out.stdout).strip().splitlines()[-3:]
            raise AnalysisError(f"benchmark case {kind} {kwargs} failed: {' | '.join(tail)}")
        return json.loads(row.read_text(encoding="utf-8"))


def _warm_up(backend: str | None, method: str) -> None:
    """Solve a tiny Hertz model first, so that the timed case does not pay for this process's
    one-time costs (imports, loading a backend's library, first calls into NumPy and
    scikit-fem) that the plain solve after it would not pay."""
    hertz_case(HertzParameters(facets_per_half_width=4, max_element_size=0.2, steps=1),
               backend, method)


def _case(kind: str, kwargs: dict) -> dict:
    _warm_up(kwargs.get("backend"), kwargs.get("method", "vfem"))
    if kind == "sphere":  # and a tiny 3D model: the 3D code paths' first calls
        from vfem_examples.sphere import SphereParameters

        sphere_case(SphereParameters(facets_per_radius=2, max_element_size=4.0, steps=1),
                    kwargs.get("backend"))
    if kind == "run":
        p = hertz_parameters(kwargs.get("dofs"), kwargs.get("level"))
        return whole_run_case(p, kwargs.get("backend"))
    if kind == "patch":
        return patch_case(kwargs.get("method", "vfem"), kwargs.get("backend"))
    if kind == "sphere":
        p = sphere_parameters(kwargs.get("dofs"), kwargs.get("level"))
        return sphere_case(p, kwargs.get("backend"), repeat=kwargs.get("repeat", 1))
    p = hertz_parameters(kwargs.get("dofs"), kwargs.get("level"),
                         kwargs.get("variant", "paired"), kwargs.get("order", 1))
    return hertz_case(p, kwargs.get("backend"), kwargs.get("method", "vfem"), repeat=2)


HEADER = (f"{'dofs':>9} {'contact':>7} {'method':>10} {'backend':>8} {'vfem s':>8} "
          f"{'plain s':>8} {'ratio':>6} {'w/o asm':>7} {'iters':>6} {'p_max err':>10} "
          f"{'peak MiB':>9}")


SPHERE_HEADER = (f"{'dofs':>9} {'contact':>7} {'n/a':>4} {'backend':>8} {'vfem s':>8} "
                 f"{'plain s':>8} {'ratio':>6} {'iters':>5} {'p_max err':>10} "
                 f"{'a err/facet':>11} {'peak MiB':>9}")


def format_sphere_row(r: dict) -> str:
    return (f"{r['dofs']:>9} {r['contact_dofs']:>7} {r['facets_across_a']:>4} "
            f"{r['backend']:>8} {r['vfem_s']:>8.2f} {r['plain_solve_s']:>8.2f} "
            f"{r['ratio']:>6.2f} {r['iterations']:>5} {r['p_max_error']:>+10.3%} "
            f"{r['a_error_over_facet']:>11.2f} {r['peak_mib']:>9.0f}")


def sphere_markdown(rows: list[dict]) -> str:
    """The sphere benchmark's rows as a Markdown table."""
    lines = ["| dofs | contact dofs | facets across a | backend | vfem s | plain solve s | "
             "ratio | iterations | p_max error | contact radius error / facet | peak MiB |",
             "|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['dofs']:,} | {r['contact_dofs']:,} | {r['facets_across_a']} | "
                     f"{r['backend']} | {r['vfem_s']:.2f} | {r['plain_solve_s']:.2f} | "
                     f"{r['ratio']:.2f} | {r['iterations']} | {r['p_max_error']:+.3%} | "
                     f"{r['a_error_over_facet']:.2f} | {r['peak_mib']:.0f} |")
    return "\n".join(lines) + "\n"


def format_row(r: dict) -> str:
    return (f"{r['dofs']:>9} {r['contact_dofs']:>7} {r['method']:>10} {r['backend']:>8} "
            f"{r['vfem_s']:>8.2f} {r['plain_solve_s']:>8.2f} {r['ratio']:>6.2f} "
            f"{r['ratio_without_assembly']:>7.2f} {r['iterations']:>6} "
            f"{r['p_max_error']:>+10.4%} {r['peak_mib']:>9.0f}")


def markdown(table: dict) -> str:
    """The tables of ``vfem bench`` (``{"hertz": rows, "patch": rows, "calculix": rows}``) as
    Markdown, for docs/benchmarks.md."""
    out = ["| dofs | contact dofs | method | backend | vfem s | plain s | ratio | ratio w/o "
           "assembly | iterations | factorizations | p_max error | peak MiB |",
           "|---:|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in table.get("hertz", []):
        out.append(f"| {r['dofs']:,} | {r['contact_dofs']:,} | {r['method']} | {r['backend']} | "
                   f"{r['vfem_s']:.2f} | {r['plain_solve_s']:.2f} | {r['ratio']:.2f} | "
                   f"{r['ratio_without_assembly']:.2f} | {r['iterations']} | "
                   f"{r['factorizations']} | {r['p_max_error']:+.4%} | "
                   f"{r['peak_mib']:,.0f} |".replace(",", " "))
    if table.get("patch"):
        out += ["", "| method | patch-test error | iterations |", "|---|---:|---:|"]
        out += [f"| {r['method']} | {r['patch_error']:.1e} | {r['patch_iterations']} |"
                for r in table["patch"]]
    if table.get("calculix"):
        out += ["", "| dofs | ccx s | increments | iterations | raw p_max error | nodal p_max "
                "error | vfem s | vfem p_max error | ccx / vfem |",
                "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        out += [f"| {r['dofs']:,} | {r['ccx_s']:.2f} | {r['ccx_increments']} | "
                f"{r['ccx_iterations_total']} | {r['ccx_p_max_error_raw']:+.2%} | "
                f"{r['ccx_p_max_error_nodal']:+.4%} | {r['vfem_s']:.2f} | "
                f"{r['vfem_p_max_error']:+.4%} | {r['ratio']:.0f} |".replace(",", " ")
                for r in table["calculix"]]
    return "\n".join(out) + "\n"


def speed_benchmark(sizes: list[dict], backends: list[str | None], methods: list[str],
                    variant: str = "paired", order: int = 1, isolate: bool = True,
                    print_row: Callable[[str], None] | None = None) -> list[dict]:
    """Every size (``{"dofs": n}`` or ``{"level": L}``) x backend x method; rows.

    ``isolate``: each case in a fresh process, warmed up, the faster of two solves (the speed
    tables); otherwise one solve each in this process (the convergence study,
    ``vfem study hertz``, which wants the errors)."""
    rows = []
    if print_row:
        print_row(HEADER)
    for size in sizes:
        for method in methods:
            for backend in backends:
                if isolate:
                    row = run_isolated("hertz", **size, variant=variant, order=order,
                                       backend=backend, method=method)
                else:
                    p = hertz_parameters(**size, variant=variant, order=order)
                    row = hertz_case(p, backend, method)
                rows.append(row)
                if print_row:
                    print_row(format_row(row))
    return rows


CALCULIX_HEADER = (f"{'level':>5} {'dofs':>8} {'ccx s':>8} {'incs':>5} {'iters':>7} "
                   f"{'raw err':>9} {'nodal err':>10} {'vfem s':>8} {'vfem err':>9} "
                   f"{'ccx/vfem':>9}")


def calculix_rows(levels: list[int | dict], print_row: Callable[[str], None] | None = None,
                  ccx: str = "ccx", threads: int = 1, penalty: float = 1e11,
                  timeout: float = 600.0, keep: str | Path | None = None,
                  backend: str | None = None) -> list[dict]:
    """vfem and CalculiX on the same Hertz meshes; ``[]`` when ``ccx`` is not installed.

    Per level (or size, ``{"dofs": n}``): vfem's analysis time (as :func:`hertz_case` measures
    it, the fastest of two, with ``backend``) and p_max error;
    the wall time of the ccx process (deck writing and result reading excluded), its
    increments (load steps) and iterations (``ccx_iterations_total`` counts the contact-making
    first step's too, as the printed table does), and its p_max error read two ways: ccx's own
    contact pressure on the slave nodes ("raw", CPRESS) and the cylinder's nodal contact forces
    ``K u`` per undeformed tributary length (vfem's reading). ``keep``: a folder for ccx's
    files, one sub-folder per level.
    """
    if shutil.which(ccx) is None:
        return []
    from .calculix import run, write_deck

    rows = []
    if print_row:
        print_row(CALCULIX_HEADER)
    for level in levels:  # a refinement level, or a size as vfem bench takes it ({"dofs": n})
        p = (hertz_parameters(**level) if isinstance(level, dict)
             else HertzParameters(refinement=level))
        tag = (f"level{level}" if not isinstance(level, dict)
               else "_".join(f"{k}{v}" for k, v in level.items()))
        model = build(p)
        v = hertz_case(p, backend, repeat=2)  # vfem timed as vfem bench times it
        vfem_s = v["vfem_s"]
        with tempfile.TemporaryDirectory(prefix="vfem-bench-ccx-") as tmp:
            deck = write_deck(model, Path(tmp) / f"hertz_{tag}.inp", penalty=penalty)
            c = run(deck, ccx=ccx, threads=threads, timeout=timeout,
                    p0=theory(p)["p0_theory"],
                    keep=None if keep is None else Path(keep) / tag)
        row = {
            "level": p.refinement, "facets_across_a": p.facets_per_half_width * 2**p.refinement,
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
            "vfem_backend": v["backend"],
            "vfem_iterations": v["iterations"],
            "vfem_converged": v["converged"],
            "vfem_p_max_error": v["p_max_error"],
            "ratio": c["wall_s"] / vfem_s,
        }
        rows.append(row)
        if print_row:
            print_row(f"{p.refinement:>5} {row['dofs']:>8} {row['ccx_s']:>8.2f} "
                      f"{row['ccx_increments']:>5} {row['ccx_iterations_total']:>7} "
                      f"{row['ccx_p_max_error_raw']:>+9.3%} {row['ccx_p_max_error_nodal']:>+10.4%} "
                      f"{vfem_s:>8.2f} {row['vfem_p_max_error']:>+9.4%} {row['ratio']:>9.1f}")
    return rows


SPHERE_CALCULIX_HEADER = (f"{'dofs':>8} {'n/a':>4} {'ccx s':>8} {'incs':>5} {'iters':>6} "
                          f"{'raw err':>9} {'nodal err':>10} {'ccx RMS':>8} {'force err':>9} "
                          f"{'vfem s':>8} {'vfem err':>9} {'vfem RMS':>8} {'ccx/vfem':>9}")


def sphere_calculix_row(size: dict, vfem: dict, ccx: str = "ccx", threads: int = 1,
                        penalty: float = SPHERE_PENALTY, timeout: float = 600.0,
                        keep: str | Path | None = None) -> dict:
    """CalculiX on the sphere example's mesh of ``size`` (``{"dofs": n}`` or ``{"level": L}``,
    as :func:`sphere_parameters` takes it) beside vfem's row ``vfem`` (:func:`sphere_case`, run
    just before on the same mesh): the wall time of the ccx process with ``threads`` threads
    (deck writing and result reading excluded), its increments and iterations (the
    contact-making first step's included in ``ccx_iterations_total``), its p_max error read
    two ways, ccx's own CPRESS ("raw") and the sphere's nodal contact forces ``K u`` per
    undeformed tributary area (vfem's reading, :func:`vfem_tools.calculix.nodal_reading`), the
    RMS of that reading's difference from Hertz's over r < a (over p0, as
    :func:`vfem_examples.sphere.evaluate` measures vfem's), and its total contact force against
    the applied one. A ccx run stopped at ``timeout`` seconds
    gives a row with ``ccx_timed_out`` and NaN readings. ``keep``: a folder for ccx's files."""
    from vfem.errors import VfemError
    from vfem_examples.sphere import build as build_sphere
    from vfem_examples.sphere import theory as sphere_theory

    from .calculix import run, write_deck

    p = sphere_parameters(**size)
    model = build_sphere(p)
    th = sphere_theory(p)
    applied = p.force / (4.0 if p.quarter else 1.0)
    tag = "_".join(f"{k}{v}" for k, v in size.items())
    nan = float("nan")
    with tempfile.TemporaryDirectory(prefix="vfem-bench-ccx-") as tmp:
        deck = write_deck(model, Path(tmp) / f"sphere_{tag}.inp", penalty=penalty)
        try:
            c = run(deck, ccx=ccx, threads=threads, timeout=timeout,
                    p0=th["p0_theory"],
                    keep=None if keep is None else Path(keep) / tag)
            timed_out = False
        except VfemError as exc:
            if "did not finish" not in str(exc):
                raise
            c, timed_out = {}, True
    dofs = int(sum(b.mesh.p.size for b in model.bodies))
    rms = nan
    if c:
        a, p0 = th["a_theory"], th["p0_theory"]
        r = np.hypot(*c["slave"]["x"][:, :2].T)
        inside = r < a
        hertz = p0 * np.sqrt(1.0 - (r[inside] / a) ** 2)
        rms = float(np.sqrt(np.mean((c["slave"]["pressure_nodal"][inside] - hertz) ** 2)) / p0)
    row = {
        "example": "sphere", "facets_across_a": p.facets_per_radius * 2 ** p.refinement,
        "dofs": dofs, "ccx_s": c.get("wall_s", nan), "ccx_timed_out": timed_out,
        "ccx_timeout_s": timeout, "ccx_threads": threads, "ccx_solver": c.get("solver", ""),
        "ccx_equations": c.get("equations", 0), "ccx_increments": c.get("increments", 0),
        "ccx_iterations": c.get("iterations", 0), "ccx_cutbacks": c.get("cutbacks", 0),
        "ccx_contact_step_iterations": c.get("contact_step_iterations", 0),
        "ccx_iterations_total": c.get("iterations", 0) + c.get("contact_step_iterations", 0),
        "ccx_penalty": penalty,
        "ccx_p_max_error_raw": c.get("p_max_error_raw", nan),
        "ccx_p_max_error_nodal": c.get("p_max_error_nodal", nan),
        "ccx_flat_p_max_error_nodal": c.get("p_max_master_error_nodal", nan),
        "ccx_rms_error_over_p0": rms,
        "ccx_total_contact_force": c.get("contact_normal_force", nan),
        # the force balance: the z component of ccx's total contact force on the sphere (its
        # "normal force" sums the contact elements' own normals: 4e-4 more at 7.6k dofs)
        "ccx_force_error": (abs(c["total_contact_force"][-1]) / applied - 1.0 if c else nan),
        "ccx_nodal_residual": c.get("nodal_residual", nan),
        "vfem_s": vfem["vfem_s"], "vfem_backend": vfem["backend"],
        "vfem_iterations": vfem["iterations"], "vfem_converged": vfem["converged"],
        "vfem_p_max_error": vfem["p_max_error"],
        "vfem_rms_error_over_p0": vfem.get("rms_error_over_p0", nan),
        "ratio": c.get("wall_s", nan) / vfem["vfem_s"],
    }
    return row


def format_sphere_calculix_row(r: dict) -> str:
    ccx = (f"{'> ' + format(r['ccx_timeout_s'], '.0f'):>8}" if r["ccx_timed_out"]
           else f"{r['ccx_s']:>8.2f}")
    return (f"{r['dofs']:>8} {r['facets_across_a']:>4} {ccx} {r['ccx_increments']:>5} "
            f"{r['ccx_iterations_total']:>6} {r['ccx_p_max_error_raw']:>+9.2%} "
            f"{r['ccx_p_max_error_nodal']:>+10.3%} {r['ccx_rms_error_over_p0']:>8.3%} "
            f"{r['ccx_force_error']:>+9.1e} {r['vfem_s']:>8.2f} {r['vfem_p_max_error']:>+9.3%} "
            f"{r['vfem_rms_error_over_p0']:>8.3%} {r['ratio']:>9.1f}")


def sphere_calculix_markdown(rows: list[dict]) -> str:
    """The sphere's CalculiX rows as a Markdown table."""
    lines = ["| dofs | facets across a | ccx s | increments | iterations | raw p_max error | "
             "nodal p_max error | ccx RMS / p0 | ccx force error | vfem s | vfem p_max error | "
             "vfem RMS / p0 | ccx / vfem |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        ccx = f"> {r['ccx_timeout_s']:.0f}" if r["ccx_timed_out"] else f"{r['ccx_s']:.2f}"
        lines.append(f"| {r['dofs']:,} | {r['facets_across_a']} | {ccx} | "
                     f"{r['ccx_increments']} | {r['ccx_iterations_total']} | "
                     f"{r['ccx_p_max_error_raw']:+.2%} | {r['ccx_p_max_error_nodal']:+.3%} | "
                     f"{r['ccx_rms_error_over_p0']:.3%} | {r['ccx_force_error']:+.1e} | "
                     f"{r['vfem_s']:.2f} | {r['vfem_p_max_error']:+.3%} | "
                     f"{r['vfem_rms_error_over_p0']:.3%} | {r['ratio']:.0f} |".replace(",", " "))
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # one case: python -m vfem_tools.bench '["hertz", {...}]' ROW.json
    import logging

    logging.basicConfig(level=logging.WARNING)
    kind, kwargs = json.loads(sys.argv[1])
    Path(sys.argv[2]).write_text(json.dumps(_case(kind, kwargs)), encoding="utf-8")
