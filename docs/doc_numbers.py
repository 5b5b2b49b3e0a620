"""The numbers in the README and docs that a run writes, not a hand (issue 17, item 9).

A block of a Markdown file between

    <!-- numbers: NAME -->
    ...
    <!-- /numbers: NAME -->

is the output of the generator NAME below, which runs the command the text names. Regenerate
after a change that moves them, and check that they are current:

    python3 docs/doc_numbers.py               # check every block: exit 1 and a diff if stale
    python3 docs/doc_numbers.py --write       # rewrite every block from fresh runs
    python3 docs/doc_numbers.py --write NAME  # one block (python3 docs/doc_numbers.py --list)

``tests/test_doc_numbers.py`` runs the quick ones in the test suite and the long ones with
``-m slow``, so a block that is stale fails a test. Comparison ignores what differs from run to
run and machine to machine: wall-clock times and round-off (numbers below 1e-12).
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import functools
import io
import json
import math
import os
import re
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _vfem(*argv: str) -> str:
    """What ``vfem ARGV`` prints, run in a fresh folder (its results under ``results/``)."""
    from vfem.cli import main

    here = os.getcwd()
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        out = io.StringIO()
        try:
            with contextlib.redirect_stdout(out):
                status = main(list(argv))
        finally:
            os.chdir(here)
    if status != 0:
        raise RuntimeError(f"vfem {' '.join(argv)} exited {status}")
    return out.getvalue()


def readme_hertz() -> str:
    """README, "What you get": the screen of ``vfem run hertz`` (steps 2 to 4 elided)."""
    lines = _vfem("run", "hertz").rstrip("\n").splitlines()
    steps = [k for k, x in enumerate(lines) if x.lstrip().startswith("step ")]
    if len(steps) > 2:
        lines = lines[: steps[0] + 1] + ["  ..."] + lines[steps[-1]:]
    return "```\n$ vfem run hertz\n" + "\n".join(lines) + "\n```\n"


def _study(levels: list[int], quadratic: list[int]) -> dict:
    from vfem.cli import main

    with tempfile.TemporaryDirectory() as tmp:
        with contextlib.redirect_stdout(io.StringIO()):
            status = main(["-q", "study", "hertz", "--out", tmp, "--levels",
                           *map(str, levels), "--quadratic-levels", *map(str, quadratic)])
        if status != 0:
            raise RuntimeError(f"vfem study hertz exited {status}")
        return json.loads((Path(tmp) / "study.json").read_text())


def accuracy_hertz_study() -> str:
    """docs/accuracy.md: the table of ``vfem study hertz`` (defaults: five linear levels, four
    quadratic)."""
    series = _study([0, 1, 2, 3, 4], [0, 1, 2, 3])
    rows = ["| series | facets across a | dofs | p_max | flat p_max | RMS | RMS (averaged) | "
            "iterations |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for name, runs in series.items():
        for k, r in enumerate(runs):
            cells = [name if k == 0 else "", str(r["facets_across_a"]),
                     _thousands(r["dofs"], 0), _percent(r["p_max_error"], 3, True),
                     _percent(r["p_max_flat_error"], 3, True),
                     _percent(r["rms_error_over_p0"], 2), _percent(r["rms_error_averaged"], 2),
                     str(r["iterations"])]
            rows.append("|" + "|".join(f" {c} " if c else " " for c in cells) + "|")
    return "\n".join(rows) + "\n"


@functools.cache
def _run(argv, status_expected: int = 0, contact_rows: bool = False):
    """``summary.json`` of ``vfem run ARGV`` (a tuple; run once per process in a fresh folder,
    silenced), and with ``contact_rows`` also ``contact.csv``'s rows; ``status_expected``: its
    exit status (1: the thesis variant, which stops outside its tolerance, issue 37)."""
    import csv

    from vfem.cli import main

    with tempfile.TemporaryDirectory() as tmp:
        with contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            status = main(["-q", "run", *argv, "--out", tmp])
        if status != status_expected:
            raise RuntimeError(f"vfem run {' '.join(argv)} exited {status}")
        summary = json.loads((Path(tmp) / "summary.json").read_text())
        if not contact_rows:
            return summary
        with open(Path(tmp) / "contact.csv", newline="", encoding="utf-8") as f:
            return summary, list(csv.DictReader(f))


def _summary(*argv: str, status_expected: int = 0) -> dict:
    """``summary.json`` of ``vfem run ARGV`` (:func:`_run`)."""
    return _run(argv, status_expected)


def _thousands(x: float, digits: int) -> str:
    return f"{x:,.{digits}f}".replace(",", " ")


def _percent(x: float, digits: int, sign: bool = False) -> str:
    """A fraction as a percentage, with a typographic minus (as the docs' tables write it)."""
    return f"{100 * x:{'+' if sign else ''}.{digits}f} %".replace("-", "−")


def gasket_results() -> str:
    """docs/examples.md, Gasket: the results table of ``vfem run gasket``."""
    s = _summary("gasket")
    steps = s["steps"]
    overlap = s["overlap_ignoring_contact"][s["first_overlap_step"] - 1]
    rows = ["| | |", "|---|---|",
            f"| first overlap (linear prediction) | step {s['first_overlap_step']} "
            f"({overlap:.4f}) |",
            f"| largest contact force | {_thousands(s['largest_force'], 2)} at step "
            f"{s['largest_force_step']} |",
            f"| mirror error max_k \\|F(k) − F(20−k)\\| / max F | {s['mirror_error']:.1e} |",
            f"| reversibility: largest \\|u\\| after step {len(steps)} | "
            f"{s['reversibility']:.1f} |",
            f"| forces on the two gaskets | balance to {s['max_force_imbalance']:.1e} |",
            "| residual penetration (algorithm's own) | ≤ "
            f"{max(x['max_penetration'] for x in steps):.1e} |",
            f"| contact iterations, {len(steps)} steps | {sum(x['iterations'] for x in steps)} |"]
    return "\n".join(rows) + "\n"


def examples_block() -> str:
    """docs/examples.md, Block: what ``vfem run block`` measures (its summary and the small
    block's nodal pressure along its top face, from contact.csv)."""
    import numpy as np

    s, rows = _run(("block", "--no-figures"), contact_rows=True)
    b = s["block"]
    steps = s["steps"]
    last = str(steps[-1]["step"])
    top = sorted((float(r["x"]), float(r["pressure"])) for r in rows
                 if r["step"] == last and r["body"] == "small" and float(r["y"]) == 0.0)
    x = np.array([p[0] for p in top])
    p = np.array([p[1] for p in top])

    def at(where: float) -> str:
        k = int(np.argmin(np.abs(x - where)))
        return f"{p[k]:.1f} at {x[k]:.2f}"

    factors = ", ".join(f"{x['load_factor']:g}" for x in steps)
    iterations = {x["iterations"] for x in steps}
    each = (f"{iterations.pop()} iteration{'s' if len(steps) > 1 else ''} each"
            if len(iterations) == 1 else
            "iterations " + ", ".join(str(x["iterations"]) for x in steps))
    lines = [
        f"Measured (`vfem run block`, {s['dofs']} dofs, paired variant):",
        "",
        f"* Converged. The one step is cut to {len(steps)} ({factors}) because the "
        "prediction's 0.05",
        "  overlap is deeper than the element behind the small block's face (the rind rule, "
        "thesis §5.6),",
        f"  {each.replace('iterations each', 'iteration each')}.",
        f"* Contact force {b['contact_force']:.2f}; the fixed block's support reaction equals "
        f"it to {b['balance_error_small']:.1e} and the press's",
        f"  to {b['balance_error_large']:.1e} (relative).",
        f"* Residual penetration {b['max_penetration']:.1e} (tolerance "
        f"{b['penetration_tolerance']:.1e}). Checked independently both ways, every node of",
        "  either block against the other block's surface "
        "(`vfem.result_types.largest_penetrations`):",
        f"  {b['largest_penetration_any_node']:.1e}.",
        f"* The nodal pressure is nearly uniform away from the corner ({at(0.0)}, "
        f"{at(0.19)}) and",
        f"  rises towards it: {at(0.41)}, {at(0.45)}, {at(0.48)} (the corner's stress "
        "singularity).",
        f"  The corner node itself reads {b['corner_pressure']:.1f}: its tributary length "
        "reaches past the singular point.",
    ]
    return "\n".join(lines) + "\n"


def gasket_linear() -> str:
    """docs/examples.md, Gasket, why this mesh: one linear element through the thickness
    against the default quadratic one, the largest (step-10) force of each."""
    linear = _summary("gasket", "--set", "order=1", "--no-figures")
    quadratic = _summary("gasket", "--no-figures")
    a, b = linear["largest_force"], quadratic["largest_force"]
    return ("* One *linear* element through the thickness locks in bending. With it the "
            f"step-{linear['largest_force_step']} force is\n"
            f"  {_thousands(a, 0)}, {100 * (a / b - 1):.0f} % above the quadratic mesh's "
            f"{_thousands(b, 0)} (forces here are with the transfer fix described\n  below).\n")


def patch_thesis() -> str:
    """docs/examples.md, Contact patch test: the thesis variant's largest deviations from the
    uniform state, with the defaults and with ``tight=true``, and how many cases stop at its
    fixed point outside its tolerance (both runs end not converged, exit status 1)."""
    runs = [_summary("patch", "--set", "variant=thesis", status_expected=1),
            _summary("patch", "--set", "variant=thesis", "--set", "tight=true",
                     status_expected=1)]

    def key(c: dict) -> tuple:
        pair = tuple(sorted((c["lower_elements"], c["upper_elements"])))
        return pair, c["poissons_ratio"], (c["lower_elements"], c["upper_elements"])

    rows = {}
    for k, s in enumerate(runs):
        for c in s["cases"]:
            pair, nu, order = key(c)
            # nu = 0.3 (the sliding base): both orders give the same, one row for the pair
            label = (f"{order[0]}/{order[1]}", nu) if nu == 0 else (
                f"{pair[0]}/{pair[1]}, {pair[1]}/{pair[0]}", nu)
            entry = rows.setdefault(label, [0.0] * 4)
            entry[2 * k] = max(entry[2 * k], c["pressure_deviation"])
            entry[2 * k + 1] = max(entry[2 * k + 1], c["stress_deviation"])
    lines = ["| lower/upper | ν | pressure, defaults | σ_y, defaults | pressure, tight | "
             "σ_y, tight |", "|---|---|---|---|---|---|"]
    for (label, nu), v in rows.items():
        if nu != 0 and "," not in label:
            continue
        lines.append(f"| {label} | {nu:g} | " + " | ".join(f"{x:.1e}" for x in v) + " |")
    stopped = [sum(not c["converged"] for c in s["cases"]) for s in runs]
    lines += ["", f"Not converged with either: with the defaults {stopped[0]} of "
              f"{len(runs[0]['cases'])} cases, with `tight=true` {stopped[1]}, stop at the "
              "variant's fixed point outside its tolerance (exit status 1; `errors.md`)."]
    return "\n".join(lines) + "\n"


def examples_cattaneo() -> str:
    """docs/examples.md, Cattaneo: the steps of the shear of ``vfem run cattaneo``."""
    s = _summary("cattaneo")
    rows = ["| Q/(μP) | c/a, theory | outermost sticking node / a | shear error, largest / RMS "
            "(% of μp0) |", "|---|---|---|---|"]
    for r in s["cattaneo"]["steps"]:
        error = (f"{100 * r['shear_max_error']:.1f} % / {100 * r['shear_rms_error']:.1f} %"
                 if "shear_max_error" in r else "")
        rows.append(f"| {r['Q_over_muP']:.3f} | {r['c_over_a']:.3f} | "
                    f"{r['last_sticking_over_a']:.3f} | {error} |")
    return "\n".join(rows) + "\n"


def gasket_steps() -> str:
    """docs/examples.md, Gasket: the loading steps that carry force (``vfem run gasket``)."""
    steps = _summary("gasket")["steps"]
    n = len(steps)
    rows = ["| step | load factor | F | iterations (loading) | nodes in contact soft/stiff | "
            "gap bridged | force off normal |", "|---|---|---|---|---|---|---|"]
    for x in steps:
        k = x["step"]
        if x["force_magnitude"] <= 0 or 2 * k > n:
            continue
        c = x["current_configuration"]
        rows.append(f"| {k if 2 * k == n else f'{k}, {n - k}'} | {x['load_factor']:.1f} | "
                    f"{_thousands(x['force_magnitude'], 2)} | {x['iterations']} | "
                    f"{x['contact_nodes']['soft']}/{x['contact_nodes']['stiff']} | "
                    f"{c['max_loaded_gap']:.4f} | {c['max_force_angle_deg']:.1f}° |")
    return "\n".join(rows) + "\n"


def _pct(x: float, digits: int = 3) -> str:
    return _percent(x, digits, True)


def examples_hertz() -> str:
    """docs/examples.md, Hertz: the default mesh with each variant, method and element order,
    and with coarser flats (``vfem run hertz --set ...``)."""
    paired = _summary("hertz")
    h = paired["hertz"]
    steps = paired["steps"]
    tol = max((x["invariants"] or {}).get("allowed", 0.0) for x in steps)
    flat_diff = h["p_max_flat"] / h["p_max"] - 1
    lines = [
        f"Default mesh ({_thousands(paired['dofs'], 0)} dofs, "
        f"{paired['parameters']['facets_per_half_width']} facets across a), default (paired) "
        "variant:", "",
        f"* p_max {_thousands(h['p_max'], 1)} ({_pct(h['p_max_error'])}); half-width "
        f"{h['a_estimate']:.4f} (theory {h['a_theory']:.4f}, one facet = "
        f"{h['contact_facet_length']:.4f}).",
        f"* RMS error over |x| < a {100 * h['rms_error_over_p0']:.2f} % of p0 "
        f"({100 * h['rms_error_averaged']:.2f} % against Hertz averaged as the nodes read it).",
        f"* Contact force {h['total_contact_force']:.2f}, carried by the flat exactly "
        f"({h['total_contact_force_flat']:.2f}); the flat reads p_max "
        f"{_thousands(h['p_max_flat'], 1)} ({_pct(flat_diff, 2)} from the cylinder's).",
        f"* {', '.join(str(x['iterations']) for x in steps[:-1])} and {steps[-1]['iterations']} "
        f"iterations in the {len(steps)} steps; residual penetrations at most "
        f"{max(x['max_penetration'] for x in steps):.0e} (the invariant check allows "
        f"{tol:.0e}).", ""]
    thesis = _summary("hertz", "--set", "variant=thesis", status_expected=1)
    t = thesis["hertz"]
    outside = sum(x["stopped_at_fixed_point"] for x in thesis["steps"])
    lines += ["The thesis variant (`--set variant=thesis`), not converged: "
              f"{outside} of {len(thesis['steps'])} steps stop at its fixed point outside its "
              "tolerance (exit status 1, `errors.md`):", "",
              f"* p_max {_pct(t['p_max_error'])}, half-width {t['a_estimate']:.4f}, RMS "
              f"{100 * t['rms_error_over_p0']:.2f} %.",
              f"* {', '.join(str(x['iterations']) for x in thesis['steps'])} iterations.",
              f"* Its flat reads p_max {_pct(t['p_max_flat'] / t['p_max'] - 1, 1)} from the "
              f"cylinder's and carries {t['total_contact_force_flat']:.1f}.", ""]
    base = {m: _summary("hertz", "--set", f"contact.method={m}")["hertz"]
            for m in ("lagrange", "penalty", "augmented")}
    lines += ["The classical baselines (`--set contact.method=...`; `baselines.md`; node-to-"
              "segment, the cylinder's nodes against the flat's facets): p_max "
              + ", ".join(f"{_pct(b['p_max_error'])} ({m})" for m, b in base.items())
              + "; the flat, as master, reads p_max "
              + ", ".join(f"{_pct(b['p_max_flat'] / b['p_max'] - 1, 0)}" for b in base.values())
              + " from the cylinder's.", ""]
    quad = _summary("hertz", "--set", "order=2")
    q = quad["hertz"]
    lines += [f"Quadratic elements (`--set order=2`: 6-node triangles with the cylinder's arc "
              "curved through its facet midpoints, 9-node quadrilaterals in the flat; paired "
              f"variant), default mesh, {_thousands(quad['dofs'], 0)} dofs: p_max "
              f"{_thousands(q['p_max'], 1)} ({_pct(q['p_max_error'])}), RMS "
              f"{100 * q['rms_error_over_p0']:.2f} %, the flat reads "
              f"{_pct(q['p_max_flat'] / q['p_max'] - 1, 2)} from the cylinder's, contact force "
              f"{q['total_contact_force']:.2f}, {sum(x['iterations'] for x in quad['steps'])} "
              "iterations.", ""]
    ratios = {r: _summary("hertz", "--set", f"flat_size_ratio={r}")["hertz"]["p_max_error"]
              for r in (0.5, 3, 5, 10)}
    lines += ["With the flat's facets 0.5, 3, 5 and 10 times the cylinder's (`--set "
              "flat_size_ratio=R`), p_max is " + ", ".join(_pct(e) for e in ratios.values())
              + " (paired; `tests/test_hertz.py`)."]
    return "\n".join(lines) + "\n"


def method_pressure_reading() -> str:
    """docs/method.md §6: the table of ``python3 benchmarks/pressure_reading.py``."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "pressure_reading", ROOT / "benchmarks" / "pressure_reading.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    import vfem
    from vfem_examples.hertz import HertzParameters, build, theory

    rows = ["| facets across a | reading | p_max | largest error, abs(x) < 0.8a | RMS, abs(x) < a "
            "| at x = 0 |", "|---|---|---|---|---|---|"]
    for n in (12, 24, 48):
        p = HertzParameters(facets_per_half_width=n)
        th = theory(p)
        runs = [(str(n), build(p))]
        if n == 12:
            runs.append(("12, mirrored full model", bench.mirrored(p)))
        for label, model in runs:
            for name, e in bench.errors(vfem.solve(model), th["a_theory"],
                                        th["p0_theory"]).items():
                rows.append(f"| {label} | {name} | {e[0]:+.3f} | {e[1]:.3f} | {e[2]:.3f} | "
                            f"{e[3]:+.3f} |".replace("-", "−"))
    return "\n".join(rows) + "\n"


def baselines_hertz() -> str:
    """docs/baselines.md: each method on the Hertz example's default mesh (level 0), the
    penalty and augmented Lagrangian at several penalties."""
    from vfem.contact.settings import ContactSettings
    from vfem.solver import Analysis
    from vfem_examples.hertz import HertzParameters, build, evaluate

    default = ContactSettings.penalty_factor
    cases = [("vfem (paired, for reference)", "vfem", None),
             ("lagrange", "lagrange", None), ("penalty, ε default", "penalty", 1.0),
             ("penalty, 10 ε", "penalty", 10.0), ("penalty, 0.1 ε", "penalty", 0.1),
             ("penalty, 1e-3 ε", "penalty", 1e-3), ("penalty, 1e-5 ε", "penalty", 1e-5),
             ("augmented, ε default", "augmented", 1.0),
             ("augmented, 1e-5 ε", "augmented", 1e-5)]
    rows = ["| method | p_max | solves per step | factorizations | penetration | "
            "contact force |", "|---|---|---|---|---|---|"]
    for label, method, scale in cases:
        p = HertzParameters(method=method, penalty_factor=default * (scale or 1.0))
        analysis = Analysis(build(p))
        result = analysis.run()
        h = evaluate(result, p)
        solves = ", ".join(str(x.iterations) for x in result.steps)
        factorizations = getattr(analysis.contact, "factorizations", len(result.model.bodies))
        penetration = max(x.history[-1].max_penetration for x in result.steps)
        rows.append(f"| {label} | {_pct(h['p_max_error'], 4)} | {solves}"
                    + (" (contact iterations)" if method == "vfem" else "")
                    + f" | {factorizations}" + (" (one per body)" if method == "vfem" else "")
                    + f" | {max(penetration, 0.0):.1e} | {h['total_contact_force']:.7g} |")
    return "\n".join(rows) + "\n"


def _wedge_ratio(r: float) -> str:
    return f"{r:g}" if r >= 1 else f"1/{1 / r:g}"


def examples_wedge() -> str:
    """docs/examples.md, Wedge: the five cases of ``vfem run wedge`` (graded mesh)."""
    rows = ["| case | E_wedge/E_plate | steps | iterations (per step) | thesis | plate share | "
            "wedge share | contact force | contact to x |", "|---|---|---|---|---|---|---|---|---|"]
    for c in _summary("wedge", "--set", "figures=false")["cases"]:
        its = c["iterations"]
        rows.append(f"| {c['case']} | {_wedge_ratio(c['modulus_ratio'])} | {len(its)} | "
                    f"{c['total_iterations']} "
                    + (f"({min(its)} each)" if min(its) == max(its) else f"({min(its)}–{max(its)})")
                    + f" | {c['thesis_iterations']} "
                    f"| {_percent(c['plate_share'], 2)} | {_percent(c['wedge_share'], 2)} | "
                    f"{c['contact_force']:.5g} | {c['contact_extent']:.2f} |")
    return "\n".join(rows) + "\n"


def examples_wedge_coarse() -> str:
    """docs/examples.md, Wedge: the one-step run on the coarse mesh
    (``vfem run wedge --set mesh=coarse``)."""
    rows = ["| case | iterations | thesis | plate share | contact force |",
            "|---|---|---|---|---|"]
    for c in _summary("wedge", "--set", "figures=false", "--set", "mesh=coarse")["cases"]:
        rows.append(f"| {c['case']} | {c['total_iterations']} | {c['thesis_iterations']} | "
                    f"{_percent(c['plate_share'], 2)} | {c['contact_force']:.5g} |")
    return "\n".join(rows) + "\n"


def examples_sliding() -> str:
    """docs/examples.md, Sliding: the frictionless slide (``vfem run sliding``)."""
    s = _summary("sliding", "--no-figures")
    e = s["sliding"]
    steps = s["steps"]
    mean = abs(e["normal_reaction_mean"])
    return "\n".join([
        "| quantity | value |", "|---|---|",
        f"| steps converged | {sum(x['converged'] for x in steps)} of {len(steps)}, "
        f"{sum(x['iterations'] for x in steps)} contact iterations, "
        f"{sum(x['cuts'] for x in steps)} step cuts |",
        f"| normal reaction, mean over the steady slide ({e['steady_steps']} steps) | "
        f"{mean:.3f} |",
        f"| its largest deviation from the mean | "
        f"{100 * e['normal_reaction_max_deviation']:.3f} % (acceptance: 2 %) |",
        f"| tangential reaction, largest | {e['tangential_reaction_max']:.1e} "
        f"({e['tangential_reaction_max'] / mean:.1e} of the normal one) |",
        f"| largest residual penetration of the block's nodes | "
        f"{e['largest_residual_penetration']:.1e} (tolerance {e['penetration_tolerance']:.1e}) |",
        f"| largest penetration of any node of either body, deformed surfaces | "
        f"{e['largest_penetration_any_node']:.1e} |",
    ]) + "\n"


def examples_sliding_friction() -> str:
    """docs/examples.md, Sliding: the slide with friction (``vfem run sliding --set
    friction=0.3``)."""
    s = _summary("sliding", "--no-figures", "--set", "friction=0.3")
    e = s["sliding"]
    f = e["friction"]
    steps = s["steps"]
    return "\n".join([
        "| quantity | value |", "|---|---|",
        f"| steps converged | {sum(x['converged'] for x in steps)} of {len(steps)}, "
        f"{sum(x['iterations'] for x in steps)} contact iterations, "
        f"{sum(x['cuts'] for x in steps)} step cuts |",
        f"| nodes in contact, slid | {f['slipping_nodes']} slipping, {f['sticking_nodes']} "
        "sticking |",
        f"| tangential / normal reaction, steady slide ({e['steady_steps']} steps) | "
        f"{f['reaction_ratio_min']:.5f} to {f['reaction_ratio_max']:.5f} |",
        f"| tangential tractions' force / normal tractions', slid | "
        f"{f['friction_over_normal_part']:.5f} |",
        f"| normal tractions' resultant, leaning against the slide | "
        f"{f['normal_part_tilt']:.4f} rad |",
        f"| tan(atan μ − that lean) | {math.tan(math.atan(f['mu']) - f['normal_part_tilt']):.5f} |",
        f"| frictional work over the run | {s['frictional_work_total']:.4g} |",
    ]) + "\n"


def examples_sphere() -> str:
    """docs/examples.md, Sphere: the default run (``vfem run sphere``)."""
    s = _summary("sphere")
    h = s["hertz"]
    sph, flat = h["sphere"], h["flat"]
    steps = s["steps"]
    return "\n".join([
        f"Default model ({_thousands(s['dofs'], 0)} dofs, {_thousands(s['contact_dofs'], 0)} "
        f"contact dofs, quarter model, facets a/{s['parameters']['facets_per_radius']} = "
        f"{h['facet_size']:.3f} on the sphere, {h['flat_facet_size']:.3f} on the flat):",
        "",
        f"* p_max {_thousands(sph['p_max'], 1)} (theory {_thousands(h['p0_theory'], 1)}, "
        f"{_percent(sph['p_max_error'], 2, True)}); the flat reads "
        f"{_percent(flat['p_max_error'], 2, True)}.",
        f"* Contact radius {sph['a_estimate']:.4f} (theory {h['a_theory']:.4f}: "
        f"{abs(sph['a_estimate'] - h['a_theory']) / h['facet_size']:.2f} of a facet); around "
        f"the circle the edge's radius varies by {sph['contour_spread']:.3f} "
        f"({sph['contour_spread'] / h['facet_size']:.2f} of a facet).",
        f"* RMS error over r < a {_percent(sph['rms_error_over_p0'], 2)} of p0.",
        f"* Contact force {sph['total_contact_force']:.2f} on the sphere and "
        f"{flat['total_contact_force']:.2f} on the flat (applied {h['applied_force']:g}).",
        f"* {' and '.join(str(x['iterations']) for x in steps)} iterations in the "
        f"{len(steps)} steps; "
        + ("every invariant passed at every step." if all(
            (x["invariants"] or {}).get("passed", False) for x in steps)
           else "an invariant FAILED at some step."),
    ]) + "\n"


def examples_sphere_study() -> str:
    """docs/examples.md, Sphere: the refinement study, the whole sphere and the bodies listed
    the other way round (``tests/test_sphere.py``'s slow study; about five minutes)."""
    from vfem.solver import Analysis
    from vfem_examples import sphere

    rows = ["| model | facets across a | dofs | p_max error | flat's p_max error | "
            "contact radius error / facet | edge's spread / facet | RMS over r < a |",
            "|---|---:|---:|---:|---:|---:|---:|---:|"]
    cases = [("quarter", {"facets_per_radius": n}) for n in (6, 8, 12)]
    cases += [("whole", {"quarter": False}), ("quarter, flat first", {"swap_bodies": True}),
              ("quarter, tetrahedral sphere", {"sphere_cells": "tet"}),
              ("quarter, tetrahedra both", {"sphere_cells": "tet", "flat_cells": "tet"})]
    cases += [("quarter, quadratic tetrahedra both", {"sphere_cells": "tet", "flat_cells": "tet",
                                                      "order": 2, "facets_per_radius": n})
              for n in (4, 6)]
    for label, kw in cases:
        p = sphere.Parameters(steps=1, **kw)
        model = sphere.build(p)
        result = Analysis(model).run()
        ev = sphere.evaluate(result, p)
        sph = ev["sphere"]
        ok = result.converged and all(x.invariants["passed"] for x in result.steps)
        rows.append(
            f"| {label}{'' if ok else ' (NOT converged)'} | {p.facets_per_radius} | "
            f"{_thousands(sum(b.ndofs for b in model.bodies), 0)} | "
            f"{_percent(sph['p_max_error'], 2, True)} | "
            f"{_percent(ev['flat']['p_max_error'], 2, True)} | "
            f"{abs(sph['a_estimate'] - ev['a_theory']) / ev['facet_size']:.2f} | "
            f"{sph['contour_spread'] / ev['facet_size']:.2f} | "
            f"{_percent(sph['rms_error_over_p0'], 2)} |")
    return "\n".join(rows) + "\n"


def examples_cattaneo3d() -> str:
    """docs/examples.md, Cattaneo 3D: the steps of the shear of ``vfem run cattaneo3d``."""
    s = _summary("cattaneo3d")
    ev = s["cattaneo3d"]
    steps = s["steps"]
    ok = all((x["invariants"] or {}).get("passed", False) for x in steps)
    rows = [f"Default model ({_thousands(s['dofs'], 0)} dofs, half model, facets "
            f"a/{round(ev['a'] / ev['facet_size'])} = {ev['facet_size']:.3f} on the sphere; "
            f"{sum(x['iterations'] for x in steps)} contact iterations in {len(steps)} steps, "
            + ("every invariant passed at every step" if ok else "an invariant FAILED")
            + f"; tangential forces balanced to "
            f"{max(r['tangential_balance'] for r in ev['steps']):.1e} of μP):", "",
            "| Q/(μP) | c/a, Mindlin | outermost sticking node / a | off c (facets) | "
            "stick/slip edge / a | shear error, largest / RMS (% of μp0) | iterations |",
            "|---:|---:|---:|---:|---:|---:|---:|"]
    for r in ev["steps"]:
        rows.append(f"| {r['Q_over_muP']:.3f} | {r['c_over_a']:.3f} | "
                    f"{r['last_sticking_over_a']:.3f} | {r['last_sticking_off_c_facets']:+.2f} | "
                    f"{r['edge_over_a']:.3f} | {100 * r['shear_max_error']:.1f} % / "
                    f"{100 * r['shear_rms_error']:.1f} % | {r['iterations']} |")
    return "\n".join(rows) + "\n"


def examples_cattaneo3d_study() -> str:
    """docs/examples.md, Cattaneo 3D: the steps nearest Q/(mu P) = 0.3, 0.6, 0.9 at three
    meshes, and the bodies listed the other way round (``tests/test_cattaneo3d.py``'s slow
    acceptance; about three minutes)."""
    import numpy as np

    from vfem.solver import Analysis
    from vfem_examples import cattaneo3d

    rows = ["| facets across a | dofs | Q/(μP) | c/a | outermost sticking node / a | off c "
            "(facets) | shear error, largest / RMS (% of μp0) | iterations | invariants |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    results = {}
    for n in (5, 6, 8):
        p = cattaneo3d.Parameters(facets_per_radius=n)
        model = cattaneo3d.build(p)
        result = Analysis(model).run()
        results[n] = result
        ok = result.converged and all(x.invariants["passed"] for x in result.steps)
        ev = cattaneo3d.evaluate(result, p)
        for i in cattaneo3d.picks(ev["steps"]):
            r = ev["steps"][i]
            rows.append(f"| {n} | {_thousands(sum(b.ndofs for b in model.bodies), 0)} | "
                        f"{r['Q_over_muP']:.3f} | {r['c_over_a']:.3f} | "
                        f"{r['last_sticking_over_a']:.3f} | "
                        f"{r['last_sticking_off_c_facets']:+.2f} | "
                        f"{100 * r['shear_max_error']:.1f} % / "
                        f"{100 * r['shear_rms_error']:.1f} % | {r['iterations']} | "
                        f"{'passed' if ok else 'FAILED'} |")
    p = cattaneo3d.Parameters(swap_bodies=True)
    swapped = Analysis(cattaneo3d.build(p)).run()
    mu_p0 = cattaneo3d.theory(p)["mu_p0"]
    same, diff = True, 0.0
    for a, b in zip(results[6].steps, swapped.steps, strict=True):
        sa, sb = cattaneo3d.stick_slip(results[6], a), cattaneo3d.stick_slip(swapped, b)
        same &= bool(np.array_equal(sa["status"], sb["status"]))
        diff = max(diff, *(float(np.abs(sa[k] - sb[k]).max()) / mu_p0
                           for k in ("shear_x", "shear_y", "normal")))
    rows += ["", f"The flat listed first (a/6): the same stick and slip nodes at every step: "
             f"{'yes' if same else 'NO'}; tractions "
             + ("within 1e-8 of μp0." if diff < 1e-8 else f"off by {diff:.1e} of μp0.")]
    return "\n".join(rows) + "\n"


def examples_circular_punch() -> str:
    """docs/examples.md, Circular punch: the default run (``vfem run circular_punch``) and the
    rim facets' study (``tests/test_circular_punch3d.py``'s slow study; about two minutes)."""
    from vfem.solver import Analysis
    from vfem_examples import circular_punch

    s = _summary("circular_punch")
    b = s["boussinesq"]
    blk, pun = b["block"], b["punch"]
    steps = s["steps"]
    ok = all((x["invariants"] or {}).get("passed", False) for x in steps)
    rows = [
        f"Default model ({_thousands(s['dofs'], 0)} dofs, {_thousands(s['contact_dofs'], 0)} "
        f"contact dofs, quarter model, facets {s['parameters']['rim_size']:g} a at the rim):",
        "",
        f"* The block's nodal pressure over r < {b['inner_radius']:g} a ({blk['nodes_inside']} "
        f"nodes): within {_percent(blk['largest_error'], 2)} of Boussinesq's (the largest at "
        f"r = {blk['largest_error_at']:.3f} a), RMS {_percent(blk['rms_error'], 2)}, at the "
        f"centre {_percent(blk['centre_error'], 2, True)}; the punch's face reads within "
        f"{_percent(pun['largest_error'], 2)}.",
        f"* Contact force {pun['total_contact_force']:.6g} on the punch and "
        f"{blk['total_contact_force']:.6g} on the block (applied {b['applied_force']:g}); block "
        f"nodes beyond the rim carrying force: {blk['nodes_beyond_rim_loaded']}.",
        f"* {sum(x['iterations'] for x in steps)} contact iteration(s) in {len(steps)} step(s); "
        + ("every invariant passed." if ok else "an invariant FAILED."),
        "",
        "| facets at the rim (over a) | dofs | largest error, r < 0.8 a | at r / a | RMS | "
        "centre | invariants |",
        "|---:|---:|---:|---:|---:|---:|---|"]
    for size in (0.04, 0.03, 0.02, 0.015):
        p = circular_punch.Parameters(rim_size=size)
        model = circular_punch.build(p)
        result = Analysis(model).run()
        ev = circular_punch.evaluate(result, p)["block"]
        ok = result.converged and all(x.invariants["passed"] for x in result.steps)
        rows.append(f"| {size:g} | {_thousands(sum(x.ndofs for x in model.bodies), 0)} | "
                    f"{_percent(ev['largest_error'], 2)} | {ev['largest_error_at']:.3f} | "
                    f"{_percent(ev['rms_error'], 2)} | {_percent(ev['centre_error'], 2, True)} | "
                    f"{'passed' if ok else 'FAILED'} |")
    return "\n".join(rows) + "\n"


#: name -> (file, generator, quick: run in the default test suite)
def examples_stack() -> str:
    """docs/examples.md, Stack: ``vfem run stack``, its 2D five-plate form and the flange
    (``examples/stack2d.toml`` and ``examples/flange.toml`` are these models), each on both
    routes to the contact flexibility."""
    rows = ["| model | dofs | contact dofs | press force | base and rims | "
            "interfaces equal and opposite within | invariants | dense = matrix-free within |",
            "|---|---:|---:|---:|---:|---:|---|---:|"]
    for label, sets in (("3D, three plates (defaults)", []),
                        ("2D, five plates, 12 divisions", ["dim=2", "blocks=5", "divisions=12"]),
                        ("flange: 3D, two plates 0.1 thick, 24 divisions",
                         ["blocks=2", "thickness=0.1", "divisions=24", "shrink=0.2",
                          "press=0.0005"])):
        runs = [_summary("stack", *[a for x in sets + [f"flexibility={route}"]
                                    for a in ("--set", x)]) for route in ("dense", "matrix_free")]
        d, m = runs[0]["stack"], runs[1]["stack"]
        apart = abs(d["press_force"] - m["press_force"]) / abs(d["press_force"])
        worst = max(i["equal_and_opposite_error"] for i in d["interfaces"])
        ok = all((x["invariants"] or {}).get("passed", False)
                 for r in runs for x in r["steps"])
        rows.append(f"| {label} | {_thousands(runs[0]['dofs'], 0)} | "
                    f"{_thousands(d['contact_dofs'], 0)} | {d['press_force']:.6g} | "
                    f"{d['held_force']:.6g} | {worst:.0e} | "
                    f"{'passed' if ok else 'FAILED'} | {apart:.0e} |")
    return "\n".join(rows) + "\n"


def examples_indentation() -> str:
    """docs/examples.md, Indentation: ``vfem run indentation`` (defaults)."""
    s = _summary("indentation")
    m = s["indentation"]
    rows = ["| dofs | onset force | Y | no yield at | first yield at | its depth / a (Hertz) "
            "| peak force | points yielded | residual approach | verification |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    passed = sum(r["passed"] for r in s["verification"])
    rows.append(f"| {s['dofs']} | {m['onset_force']:.4g} | {m['yield_stress']:.4g} | "
                f"{m['last_elastic_force']:.2f} | {m['first_yield_force']:.2f} | "
                f"{m['first_yield_depth_over_a']:.3f} ({m['depth_over_a']:.3f}) | "
                f"{m['peak_contact_force']:.4g} | {max(m['yielded_points'])} | "
                f"{m['residual_approach']:.3g} | {passed} of {len(s['verification'])} passed |")
    return "\n".join(rows) + "\n"


def _plastic_indentation(example: str) -> str:
    """The numbers row of ``vfem run EXAMPLE`` (defaults) for the plastic indentations into a
    block or a flat (:mod:`vfem_examples.block_indentation`, ``sphere_indentation``)."""
    s = _summary(example)
    m = s[example]
    rows = ["| dofs | onset force | Y | no yield at | first yield at | its depth / a (Hertz) "
            "| peak force | depression at the peak | dent | verification |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    passed = sum(r["passed"] for r in s["verification"])
    rows.append(f"| {s['dofs']} | {m['onset_force']:.4g} | {m['yield_stress']:.4g} | "
                f"{m['last_elastic_force']:.2f} | {m['first_yield_force']:.2f} | "
                f"{m['first_yield_depth_over_a']:.3f} ({m['depth_over_a']:.3f}) | "
                f"{m['peak_contact_force']:.4g} | {m['depression_at_peak']:.3g} | "
                f"{m['dent']:.3g} | {passed} of {len(s['verification'])} passed |")
    return "\n".join(rows) + "\n"


def examples_block_indentation() -> str:
    """docs/examples.md, Block indentation: ``vfem run block_indentation`` (defaults)."""
    return _plastic_indentation("block_indentation")


def examples_sphere_indentation() -> str:
    """docs/examples.md, Sphere indentation: ``vfem run sphere_indentation`` (defaults)."""
    return _plastic_indentation("sphere_indentation")


def examples_thick_cylinder() -> str:
    """docs/examples.md, Thick cylinder: ``vfem run thick_cylinder`` (defaults)."""
    s = _summary("thick_cylinder")
    m = s["thick_cylinder"]
    rows = ["| pressure p | plastic to c | Hill's p at c | p / Hill − 1 |", "|---:|---:|---:|---:|"]
    for p, c, h in zip(m["pressure"], m["plastic_radius"], m["hill_pressure"]):
        if c is None:
            rows.append(f"| {p:.5g} | elastic | | |")
        else:
            rows.append(f"| {p:.5g} | {c:.4f} | {h:.5g} | {_percent(p / h - 1, 2, sign=True)} |")
    passed = sum(r["passed"] for r in s["verification"])
    rows.append("")
    first = m["run_first_yield_pressure"] / m["first_yield_pressure"] - 1
    rows.append(f"{s['dofs']} dofs; first yield at p = {m['run_first_yield_pressure']:.5g} "
                f"(Lamé {m['first_yield_pressure']:.5g}, {_percent(first, 2, sign=True)}); "
                f"Hill's limit {m['limit_pressure']:.5g}; verification {passed} of "
                f"{len(s['verification'])} passed.")
    return "\n".join(rows) + "\n"


def examples_axisymmetric_sphere() -> str:
    """docs/examples.md, Axisymmetric sphere: ``vfem run axisymmetric_sphere`` coarser (a/6),
    at its default mesh (quadratic, a/12), refined (a/24) and with linear elements."""
    rows = ["| elements | facets over a | dofs | sphere's p_max / p0 − 1 | flat's | fitted a "
            "/ a − 1 | edge / a | verification |", "|---|---:|---:|---:|---:|---:|---:|---|"]
    for label, sets in (("quadratic", ("facets_per_radius=6",)), ("quadratic", ()),
                        ("quadratic", ("facets_per_radius=24",)),
                        ("linear", ("order=1", "facets_per_radius=6")), ("linear", ("order=1",))):
        argv = ["axisymmetric_sphere", "--no-figures"]
        for s in sets:
            argv += ["--set", s]
        s = _summary(*argv)
        m = s["axisymmetric_sphere"]
        passed = sum(r["passed"] for r in s["verification"])
        facets = s["parameters"]["facets_per_radius"]
        rows.append(f"| {label} | {facets} | {_thousands(s['dofs'], 0)} | "
                    f"{_percent(m['sphere_p_max'] / m['p0_theory'] - 1, 2, sign=True)} | "
                    f"{_percent(m['flat_p_max'] / m['p0_theory'] - 1, 2, sign=True)} | "
                    f"{_percent(m['a_fit'] / m['a_theory'] - 1, 2, sign=True)} | "
                    f"{m['edge'] / m['a_theory']:.3f} | {passed} of "
                    f"{len(s['verification'])} passed |")
    return "\n".join(rows) + "\n"


def _signed_percent(x: float) -> str:
    """:func:`_percent` to three decimals with its sign, or in two figures where that would
    read 0.000 % (quadratic elements leave errors of 1e-8, whose sign is theirs)."""
    return _percent(x, 3, sign=True) if abs(x) >= 5e-6 else \
        f"{'−' if x < 0 else '+'}{abs(100 * x):.1e} %"


def examples_axisymmetric_press_fit() -> str:
    """docs/examples.md, Axisymmetric press fit: ``vfem run axisymmetric_press_fit`` at its
    default mesh, coarser, finer, on quadratic elements and with an aluminium hub."""
    rows = ["| run | dofs | hub's p / Lamé − 1 | shaft's (on b + δ) | spread along the fit "
            "| u_r hub | u_r shaft | hoop stress at the bore | push-out / μp·2πbL − 1 "
            "| verification |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for label, sets in (("defaults (elements 0.05 / 0.04)", ()),
                        ("coarser (0.1 / 0.08)", ("shaft_element_size=0.1",
                                                  "hub_element_size=0.08")),
                        ("finer (0.025 / 0.02)", ("shaft_element_size=0.025",
                                                  "hub_element_size=0.02")),
                        ("quadratic", ("order=2",)),
                        ("aluminium hub", ("hub_youngs_modulus=70000",
                                           "hub_poissons_ratio=0.33"))):
        argv = ["axisymmetric_press_fit", "--no-figures"]
        for x in sets:
            argv += ["--set", x]
        s = _summary(*argv)
        m = s["axisymmetric_press_fit"]
        p = m["lame_pressure"]
        spread = max(m["hub"]["pressure_spread"], m["shaft"]["pressure_spread"]) / p
        last = m["push"][-1]["axial_force"]
        passed = sum(r["passed"] for r in s["verification"])
        pc = _signed_percent
        rows.append(
            f"| {label} | {_thousands(s['dofs'], 0)} | "
            f"{pc(m['hub']['mean_pressure'] / p - 1)} | "
            f"{pc(m['shaft']['mean_pressure'] / m['lame_shaft_pressure'] - 1)}"
            f" | {'< 1e-12' if spread < 1e-12 else f'{spread:.1e}'} | "
            f"{pc(m['hub']['u_r_worst'] / m['lame_u_hub'] - 1)} | "
            f"{pc(m['shaft']['u_r_worst'] / m['lame_u_shaft'] - 1)} | "
            f"{pc(m['hoop']['worst_error'])} | "
            f"{pc(last / m['push_out_force_theory'] - 1)} | "
            f"{passed} of {len(s['verification'])} passed |")
    return "\n".join(rows) + "\n"


def examples_oring() -> str:
    """docs/examples.md, O-ring: ``vfem run oring`` at its defaults, each step's lid force per
    unit circumference beside Lindley's, the contact width and peak pressure."""
    s = _summary("oring", "--no-figures")
    m = s["oring"]
    d = s["parameters"]["cross_section"]
    E = s["parameters"]["youngs_modulus"]
    rows = ["| compression | lid force per unit circumference | Lindley's | ratio | contact "
            "width / d | peak pressure / E |", "|---:|---:|---:|---:|---:|---:|"]
    for r in m["steps"]:
        rows.append(f"| {_percent(r['compression'], 0)} | {r['force_per_length']:.4f} | "
                    f"{r['lindley']:.4f} | {r['force_per_length'] / r['lindley']:.2f} | "
                    f"{r['contact_width'] / d:.3f} | {r['peak_pressure'] / E:.3f} |")
    passed = sum(r["passed"] for r in s["verification"])
    touched = m["walls_touched_at"]
    rows.append("")
    rows.append(f"{_thousands(s['dofs'], 0)} dofs; the walls "
                + ("are not touched" if touched is None else
                   f"touched from {_percent(touched, 0)} compression")
                + f"; verification {passed} of {len(s['verification'])} passed.")
    return "\n".join(rows) + "\n"


def examples_ring_crush() -> str:
    """docs/examples.md, Ring crush: ``vfem run ring_crush`` at its defaults, every fourth step
    and each step from the bore's closing on: the plate's travel and force, the bore's
    opening, the self-contact force."""
    s = _summary("ring_crush", "--no-figures")
    m = s["ring_crush"]
    rows = ["| travel | plate's force | bore's opening | self-contact force | nodes in "
            "self-contact |", "|---:|---:|---:|---:|---:|"]
    for k, r in enumerate(m["steps"]):
        if k % 4 == 3 or r["self_contact_force"] > 0:
            opening = r["bore_opening"] if abs(r["bore_opening"]) > 1e-6 else 0.0
            rows.append(f"| {r['travel']:.3f} | {r['force']:.4g} | {opening:.4f} | "
                        f"{r['self_contact_force']:.4g} | {r['self_contact_nodes']} |")
    passed = sum(r["passed"] for r in s["verification"])
    first = m["steps"][0]
    rows.append("")
    rows.append(f"{_thousands(s['dofs'], 0)} dofs; the bore closes at a travel of "
                f"{m['closed_at_travel']:.3f}; the first step's stiffness "
                f"{first['force'] / first['travel']:.4g} (a thin ring's "
                f"{m['thin_ring_stiffness']:.4g}); verification {passed} of "
                f"{len(s['verification'])} passed.")
    return "\n".join(rows) + "\n"


BLOCKS: dict[str, tuple[str, Callable[[], str], bool]] = {
    "readme-hertz": ("README.md", readme_hertz, True),
    "accuracy-hertz-study": ("docs/accuracy.md", accuracy_hertz_study, False),
    "examples-hertz": ("docs/examples.md", examples_hertz, False),
    "method-pressure-reading": ("docs/method.md", method_pressure_reading, False),
    "baselines-hertz": ("docs/baselines.md", baselines_hertz, False),
    "gasket-results": ("docs/examples.md", gasket_results, False),
    "gasket-steps": ("docs/examples.md", gasket_steps, False),
    "examples-cattaneo": ("docs/examples.md", examples_cattaneo, False),
    "examples-wedge": ("docs/examples.md", examples_wedge, False),
    "examples-wedge-coarse": ("docs/examples.md", examples_wedge_coarse, True),
    "examples-sliding": ("docs/examples.md", examples_sliding, False),
    "examples-sliding-friction": ("docs/examples.md", examples_sliding_friction, False),
    "examples-sphere": ("docs/examples.md", examples_sphere, False),
    "examples-sphere-study": ("docs/examples.md", examples_sphere_study, False),
    "examples-cattaneo3d": ("docs/examples.md", examples_cattaneo3d, False),
    "examples-cattaneo3d-study": ("docs/examples.md", examples_cattaneo3d_study, False),
    "examples-circular-punch": ("docs/examples.md", examples_circular_punch, False),
    "examples-stack": ("docs/examples.md", examples_stack, False),
    "examples-indentation": ("docs/examples.md", examples_indentation, False),
    "examples-thick-cylinder": ("docs/examples.md", examples_thick_cylinder, False),
    "examples-block-indentation": ("docs/examples.md", examples_block_indentation, False),
    "examples-sphere-indentation": ("docs/examples.md", examples_sphere_indentation, False),
    "examples-axisymmetric-sphere": ("docs/examples.md", examples_axisymmetric_sphere, False),
    "examples-axisymmetric-press-fit": ("docs/examples.md", examples_axisymmetric_press_fit,
                                        True),
    "examples-oring": ("docs/examples.md", examples_oring, False),
    "examples-ring-crush": ("docs/examples.md", examples_ring_crush, False),
    "examples-block": ("docs/examples.md", examples_block, True),
    "gasket-linear": ("docs/examples.md", gasket_linear, False),
    "patch-thesis": ("docs/examples.md", patch_thesis, False),
}

_TIME = re.compile(r"\b\d+(\.\d+)? s\b")
#: (an exact zero, 0.0e+00, is round-off's too: where one linear solver leaves 7e-17, another
#: may leave nothing)
_ROUND_OFF = re.compile(r"[-+]?\d(\.\d+)?e-(1[3-9]|[2-9]\d|\d{3})\b|[-+]?0(\.0+)?e[-+]00\b")


#: Where a round-off figure was largest (which body and step is round-off's choice too).
_WORST = re.compile(r"\(worst: '[^']*', step \d+\)")

#: The linear solver a closing line names: the fastest installed on the machine that ran it
#: (``vfem.io.runner.solver_words``), with its hint where it is SuperLU.
_SOLVER = re.compile(r", linear solver \w+( \(the slowest: [^)]*\))?")


def normalised(text: str) -> str:
    """``text`` with wall-clock times, round-off numbers (below 1e-12), where the largest
    round-off was and the linear solver's name masked."""
    text = _SOLVER.sub(", linear solver <installed>", text)
    return _WORST.sub("(worst: <where>)", _ROUND_OFF.sub("<round-off>", _TIME.sub("<time> s",
                                                                               text)))


def _span(text: str, name: str) -> tuple[int, int]:
    begin, end = f"<!-- numbers: {name} -->\n", f"<!-- /numbers: {name} -->"
    i = text.find(begin)
    j = text.find(end, i + 1)
    if i < 0 or j < 0:
        raise KeyError(f"no block {name!r} (markers {begin.strip()} ... {end})")
    return i + len(begin), j


def current(name: str) -> str:
    """The block as the file has it now."""
    path = ROOT / BLOCKS[name][0]
    text = path.read_text(encoding="utf-8")
    i, j = _span(text, name)
    return text[i:j]


def stale(name: str) -> str:
    """A diff of the block against a fresh run ("" if current, times and round-off aside)."""
    fresh = BLOCKS[name][1]()
    old = current(name)
    if normalised(old) == normalised(fresh):
        return ""
    return "".join(difflib.unified_diff(old.splitlines(True), fresh.splitlines(True),
                                        f"{BLOCKS[name][0]} ({name})", "fresh run"))


def write(name: str) -> None:
    path = ROOT / BLOCKS[name][0]
    text = path.read_text(encoding="utf-8")
    i, j = _span(text, name)
    path.write_text(text[:i] + BLOCKS[name][1]() + text[j:], encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help="blocks (default: all)")
    parser.add_argument("--write", action="store_true", help="rewrite them from fresh runs")
    parser.add_argument("--list", action="store_true", help="list the blocks")
    args = parser.parse_args(argv)
    if args.list:
        for name, (file, _, quick) in BLOCKS.items():
            print(f"{name:24} {file:20} {'quick' if quick else 'long'}")
        return 0
    names = args.names or list(BLOCKS)
    unknown = [n for n in names if n not in BLOCKS]
    if unknown:
        print(f"unknown blocks {unknown}; available: {', '.join(BLOCKS)}", file=sys.stderr)
        return 2
    status = 0
    for name in names:
        if args.write:
            write(name)
            print(f"wrote {name} into {BLOCKS[name][0]}")
        elif diff := stale(name):
            print(diff)
            status = 1
        else:
            print(f"{name}: current")
    return status


if __name__ == "__main__":
    sys.exit(main())
