"""``vfem verify``: every built-in example at its default size, and the table of how right each
is (each example's ``verification`` list, :mod:`vfem.io.verification`) — a user's check of an
install, in a few minutes. ``--slow`` runs the refined models the examples name
(``VERIFY_SLOW``, ``--set`` assignments) instead."""

from __future__ import annotations

import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

from ..errors import InputError, VfemError
from ..io import replot, verification


def _run_example(name: str, out: Path, slow: bool) -> tuple[dict, float]:
    """Run example ``name`` (its defaults, or with ``slow`` its ``VERIFY_SLOW`` settings) into
    ``out`` as ``vfem run`` does, its figures left undrawn; (summary, seconds)."""
    from vfem_examples import load

    from .builtin import build_parameters

    module = load(name)
    assignments = list(getattr(module, "VERIFY_SLOW", ())) if slow else []
    params = build_parameters(name, assignments)
    if hasattr(module, "validate"):
        module.validate(params)
    if out.exists():  # this command's own folder of an earlier verify
        shutil.rmtree(out)
    start = time.perf_counter()
    summary = module.run(params, out)
    return summary, time.perf_counter() - start


def _folder(out: str | None) -> Path | None:
    """The folder ``--out`` names, refused (InputError) if it is a file or a folder holding
    something else than an earlier ``vfem verify``'s results."""
    if out is None:
        return None
    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"vfem verify --out {folder}: a file, not a folder; name a new or "
                         "empty folder")
    if folder.is_dir() and any(folder.iterdir()) and not (folder / "verify.json").exists():
        raise InputError(f"vfem verify --out {folder}: the folder holds other files (no "
                         "verify.json); name a new or empty folder")
    return folder


def cmd_verify(args) -> int:
    """Run the examples (all, or ``args.examples``), print each one's line as it ends and then
    the table; write ``verify.json`` beside the results when ``--out`` is given. Exit status 0
    when every record passed, 1 otherwise (an example that did not converge, or has no record,
    fails)."""
    from vfem_examples import EXAMPLES

    names = args.examples or list(EXAMPLES)
    unknown = [n for n in names if n not in EXAMPLES]
    if unknown:
        print(f"vfem verify: unknown example {', '.join(map(repr, unknown))}; the examples are "
              f"{', '.join(EXAMPLES)}", file=sys.stderr)
        return 2
    keep = _folder(args.out)
    rows: list[tuple[str, dict]] = []
    report = {"slow": bool(args.slow), "examples": {}}
    failed: list[str] = []
    start = time.perf_counter()
    scratch = tempfile.TemporaryDirectory(prefix="vfem-verify-")
    replot.defer(True)  # the figures are not what is verified: vfem plot draws them
    try:
        root = keep if keep is not None else Path(scratch.name)
        for name in names:
            try:
                summary, seconds = _run_example(name, root / name, args.slow)
            except VfemError as exc:  # one example's failure is its row, not the end of all
                summary, seconds = {"converged": False, "message": str(exc)}, 0.0
            records = summary.get("verification") or []
            ok = bool(summary.get("converged", True)) and verification.passed(records)
            if not ok:
                failed.append(name)
            rows += [(name, r) for r in records]
            report["examples"][name] = {"seconds": seconds, "passed": ok,
                                        "converged": summary.get("converged", True),
                                        "verification": records}
            if not args.quiet:
                done = sum(r["passed"] for r in records)
                what = (f"{done} of {len(records)} passed" if records
                        else "no verification recorded")
                if not summary.get("converged", True):
                    what = f"NOT converged ({summary.get('message', '')}); " + what
                print(f"vfem verify: {name}: {what}, {seconds:.1f} s", flush=True)
    finally:
        replot.defer(False)
        scratch.cleanup()
    total = time.perf_counter() - start
    report["seconds"] = total
    report["passed"] = not failed
    if keep is not None:
        keep.mkdir(parents=True, exist_ok=True)
        (keep / "verify.json").write_text(json.dumps(report, indent=1))
    if not args.quiet:
        print("\n".join(verification.table(rows)))
        checks = len(rows)
        passed = sum(r["passed"] for _, r in rows)
        print(f"vfem verify: {len(names)} examples, {passed} of {checks} checks passed"
              + (f"; failed: {', '.join(failed)}" if failed else "")
              + f"; {total:.0f} s" + (" (--slow)" if args.slow else ""))
    return 1 if failed else 0
