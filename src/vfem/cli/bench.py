"""``vfem bench`` and ``vfem study``: the timing and convergence studies (their work in
:mod:`vfem_tools.bench`)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from .. import linalg
from ..errors import InputError


def _bench_sphere(args) -> int:
    """``vfem bench sphere``: the sphere example at each size, each case in its own process
    (its peak memory its own): dofs, contact dofs, time, ratio to a plain linear solve of the
    same bodies with the same backend, iterations, p_max error, peak memory; with
    ``--calculix``, CalculiX on the same mesh right after vfem's case (its time, increments,
    iterations and p_max error beside vfem's)."""
    from vfem_tools import bench

    for option in ("patch", "whole_run", "plot"):
        if getattr(args, option):
            raise InputError(f"vfem bench sphere: --{option.replace('_', '-')} is for hertz only")
    if args.methods != ["vfem"] or args.variant != "paired":
        raise InputError("vfem bench sphere: the paired vfem method only (3D contact)")
    if args.calculix and shutil.which("ccx") is None:
        raise InputError("--calculix: ccx is not installed (Debian: apt install calculix-ccx)")
    solvers = args.solver or ["auto"]
    backends = linalg.available() if "all" in solvers else [linalg.resolve(s) for s in solvers]
    sizes = ([{"level": level} for level in args.levels] if args.levels
             else [{"dofs": bench.parse_size(d)} for d in (args.dofs or ["30k", "300k"])])
    say = None if args.quiet else print
    if say:
        say(bench.SPHERE_HEADER)
    rows, ccx_rows = [], []
    for size in sizes:
        for backend in backends:
            row = (bench._case("sphere", {**size, "backend": backend}) if args.in_process
                   else bench.run_isolated("sphere", **size, backend=backend))
            rows.append(row)
            if say:
                say(bench.format_sphere_row(row))
        if args.calculix:  # right after vfem on the same mesh (its first backend's row)
            ccx_rows.append(bench.sphere_calculix_row(
                size, rows[-len(backends)], threads=args.ccx_threads,
                timeout=args.ccx_timeout))
            if say:
                say(bench.SPHERE_CALCULIX_HEADER)
                say(bench.format_sphere_calculix_row(ccx_rows[-1]))
    if args.json:
        keep = {"sphere": rows, "calculix": ccx_rows} if args.calculix else rows
        Path(args.json).write_text(json.dumps(keep, indent=2) + "\n", encoding="utf-8")
    if args.markdown:
        text = bench.sphere_markdown(rows)
        if ccx_rows:
            text += "\n" + bench.sphere_calculix_markdown(ccx_rows)
        Path(args.markdown).write_text(text, encoding="utf-8")
    return 0


def cmd_bench(args) -> int:
    from vfem_tools import bench

    if args.example not in ("hertz", "sphere"):
        raise InputError(f"no benchmark for {args.example!r}; available: hertz, sphere")
    if args.example == "sphere":
        return _bench_sphere(args)
    if args.plot:
        from ..io.plots import require_matplotlib

        require_matplotlib()  # before the benchmark, not after it
    solvers = args.solver or ["auto"]
    backends = linalg.available() if "all" in solvers else [linalg.resolve(s) for s in solvers]
    if args.levels:
        sizes = [{"level": level} for level in args.levels]
    else:
        sizes = [{"dofs": bench.parse_size(d)} for d in (args.dofs or ["10k", "100k"])]
    say = None if args.quiet else print
    if args.whole_run:
        rows = []
        if say:
            say(bench.WHOLE_RUN_HEADER)
        for size in sizes:
            for backend in backends:
                rows.append(bench.run_isolated("run", **size, backend=backend))
                if say:
                    say(bench.format_whole_run(rows[-1]))
        if args.json:
            Path(args.json).write_text(json.dumps(rows, indent=2) + "\n", encoding="utf-8")
        return 0
    rows = bench.speed_benchmark(sizes, backends, args.methods, variant=args.variant,
                                 isolate=not args.in_process, print_row=say)
    table = {"hertz": rows}
    if args.patch:
        if say:
            say(f"{'method':>10} {'patch error':>12} {'iterations':>10}")
        table["patch"] = []
        for method in args.methods:
            row = bench.run_isolated("patch", method=method, backend=backends[0])
            table["patch"].append(row)
            if say:
                say(f"{method:>10} {row['patch_error']:>12.2e} {row['patch_iterations']:>10}")
    if args.calculix:
        if shutil.which("ccx") is None:
            raise InputError("--calculix: ccx is not installed (Debian: apt install "
                             "calculix-ccx)")
        table["calculix"] = bench.calculix_rows(sizes, print_row=say, backend=backends[0],
                                                threads=args.ccx_threads,
                                                timeout=args.ccx_timeout)
    if args.markdown:
        Path(args.markdown).write_text(bench.markdown(table), encoding="utf-8")
    if args.json:
        keep = table if (args.patch or args.calculix) else rows
        Path(args.json).write_text(json.dumps(keep, indent=2) + "\n", encoding="utf-8")
    if args.plot:
        from ..io.plots import benchmark_times

        benchmark_times(Path(args.plot), rows, "Hertz: time against dofs")
    return 0


def cmd_study(args) -> int:
    from vfem_tools.bench import speed_benchmark

    from ..io.plots import convergence, require_matplotlib

    if args.example != "hertz":
        raise InputError(f"no study for {args.example!r}; available: hertz")
    require_matplotlib()  # its figure is its result: refused before the study, not after it
    out = Path(args.out or Path("results") / "hertz_study")
    out.mkdir(parents=True, exist_ok=True)
    series = {}
    for name, variant, order, levels in (
            ("linear, paired", "paired", 1, args.levels),
            ("linear, thesis", "thesis", 1, args.levels),
            ("quadratic, paired", "paired", 2, args.quadratic_levels)):
        if not args.quiet:
            print(f"vfem: hertz refinement study, {name}")
        series[name] = speed_benchmark([{"level": level} for level in levels], [None], ["vfem"],
                                       variant=variant, order=order, isolate=False,
                                       print_row=None if args.quiet else print)
    (out / "study.json").write_text(json.dumps(series, indent=2) + "\n", encoding="utf-8")
    convergence(out / "convergence.png", series,
                "Hertz (thesis §5.2) under refinement: error against Hertz's theory")
    if not args.quiet:
        print(f"vfem: wrote {out}/study.json and {out}/convergence.png")
    return 0
