"""Every example's answers, saved and compared: the "no answer changes" check of a refactoring
(issue 18).

    python benchmarks/answers.py save DIR            # run every case, write DIR/<case>.json
    python benchmarks/answers.py compare OLD NEW     # every number alike to 1e-10 relative
    python benchmarks/answers.py compare OLD NEW --ignore iterations   # all but those keys
    python benchmarks/answers.py save DIR hertz gasket_large   # some cases only

The cases: springs, hertz, hertz with quadratic elements, patch, wedge, block, gasket (small and
large kinematics), sliding, the thesis variant on Hertz, the block, the wedge and the patch test
(the block's and the wedge's stop unconverged, before and after: their failures must match too),
each classical baseline on Hertz, Cattaneo's cylinder (and its cycle), the pushed block,
and in 3D the sphere (built in and from its input file), Cattaneo's sphere and the stack of
plates; each is ``vfem run`` of the
built-in example into a fresh folder, and its ``summary.json`` is kept without what differs
from run to run (wall-clock times, the run's command and date, file names). ``compare`` walks
both trees: numbers must agree to 1e-10 relative (to the value, or to the largest magnitude the
same quantity takes in the run where the value is a round-off zero), integers
(iteration counts, steps) and strings exactly; it prints every difference and exits 1 if any.
Take the "before" snapshot at the commit before the change (a ``git worktree`` of it), the
"after" one on the change, and compare.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import re
import sys
import tempfile
from pathlib import Path

CASES: dict[str, list[str]] = {
    "springs": ["springs"],
    "hertz": ["hertz"],
    "hertz_order2": ["hertz", "--set", "order=2"],
    "patch": ["patch"],
    "wedge": ["wedge", "--set", "figures=false"],
    "block": ["block"],
    "gasket": ["gasket"],
    "gasket_large": ["gasket", "--set", "kinematics=total", "--set", "order=1", "--set",
                     "n_through=3", "--set", "back_motion=0.5"],  # as docs/examples.md runs it
    "sliding": ["sliding"],
    # the thesis's plain reading, kept as reference (issue 18, item 7)
    "hertz_thesis": ["hertz", "--set", "variant=thesis"],
    "block_thesis": ["block", "--set", "contact.variant=thesis"],
    "wedge_thesis": ["wedge", "--set", "figures=false", "--set", "contact.variant=thesis"],
    "patch_thesis": ["patch", "--set", "contact.variant=thesis"],
    "hertz_penalty": ["hertz", "--set", "contact.method=penalty"],
    "hertz_lagrange": ["hertz", "--set", "contact.method=lagrange"],
    "hertz_augmented": ["hertz", "--set", "contact.method=augmented"],
    # friction (issue 20): Cattaneo pressed then sheared, the Mindlin-Deresiewicz cycle, a block
    # pushed over another (run from the repository's root)
    "cattaneo": ["cattaneo", "--no-figures"],
    "cattaneo_cycle": ["cattaneo", "--no-figures", "--set", "cycle=true", "--set",
                       "shift=5e-4"],
    "pushed_block": ["examples/friction/pushed_block.toml", "--no-figures"],
    # 3D (issue 40: the fixed costs' changes are 3D first): the sphere, Cattaneo's sphere
    # sheared, the stack of plates, and the sphere from its input file
    "sphere": ["sphere", "--no-figures"],
    "cattaneo3d": ["cattaneo3d", "--no-figures"],
    "stack": ["stack", "--no-figures"],
    "sphere_file": ["examples/sphere.toml", "--no-figures"],
}

#: Keys whose values differ from run to run (or name files), dropped wherever they appear.
VOLATILE = {"timings", "phases", "run", "seconds", "figures", "figure_data", "figure_set",
            "figures_not_drawn", "linear_solver", "peak_mib", "input"}


def clean(value):
    """``value`` without the :data:`VOLATILE` keys, at any depth."""
    if isinstance(value, dict):
        return {k: clean(v) for k, v in value.items() if k not in VOLATILE}
    if isinstance(value, list):
        return [clean(v) for v in value]
    return value


def save(folder: Path, names: list[str]) -> None:
    from vfem.cli import main

    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        with tempfile.TemporaryDirectory() as tmp:
            with contextlib.redirect_stdout(io.StringIO()):
                status = main(["-q", "run", *CASES[name], "--out", tmp])
            if not (Path(tmp) / "summary.json").is_file():
                print(f"{name}: exit {status}, no summary.json written (see the message above)")
                continue
            summary = json.loads((Path(tmp) / "summary.json").read_text())
        (folder / f"{name}.json").write_text(json.dumps(clean(summary), indent=1) + "\n")
        print(f"{name}: exit {status}, {folder / (name + '.json')}")


def pattern(where: str) -> str:
    """The group of quantities a place belongs to: its path with list indices blanked and its
    last key left out (every step's and node's value of it, and its siblings: a tangential
    reaction with the normal ones beside it)."""
    return re.sub(r"\[\d+\]", "[*]", where).rsplit(".", 1)[0]


def scales(value, where: str = "", out: dict | None = None) -> dict[str, float]:
    """Per :func:`pattern`, the largest magnitude the quantity takes (its scale)."""
    out = {} if out is None else out
    if isinstance(value, dict):
        for k, v in value.items():
            scales(v, f"{where}.{k}", out)
    elif isinstance(value, list):
        for k, v in enumerate(value):
            scales(v, f"{where}[{k}]", out)
    elif isinstance(value, float) and math.isfinite(value):
        key = pattern(where)
        out[key] = max(out.get(key, 0.0), abs(value))
    return out


def differences(a, b, where: str = "", scale: dict[str, float] | None = None) -> list[str]:
    """Every place where ``a`` and ``b`` differ beyond round-off: 1e-10 relative to the value,
    or to the largest magnitude of the same quantity over the run (its other steps, nodes and
    components: a reaction that is zero up to round-off, 1e-11 of the forces of the other
    steps, is compared at that scale), whichever is larger, and at least 1e-13 absolute."""
    if scale is None:
        scale = scales(a)
        for k, v in scales(b).items():
            scale[k] = max(scale.get(k, 0.0), v)
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{where}.{k}: only before" for k in a.keys() - b.keys()]
        out += [f"{where}.{k}: only after" for k in b.keys() - a.keys()]
        for k in a.keys() & b.keys():
            out += differences(a[k], b[k], f"{where}.{k}", scale)
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: {len(a)} entries before, {len(b)} after"]
        return [d for k, (x, y) in enumerate(zip(a, b))
                for d in differences(x, y, f"{where}[{k}]", scale)]
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, int) and isinstance(b, int):
        return [] if a == b else [f"{where}: {a!r} before, {b!r} after"]
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        # (1e-13 absolute: measures that are round-off by definition, as the relative force
        # imbalances of 1e-15, move with the order of any floating-point sum)
        floor = max(1e-10 * scale.get(pattern(where), 0.0), 1e-13)
        if math.isclose(a, b, rel_tol=1e-10, abs_tol=floor) or (math.isnan(a) and math.isnan(b)):
            return []
        return [f"{where}: {a!r} before, {b!r} after"]
    return [] if a == b else [f"{where}: {a!r} before, {b!r} after"]


def drop(value, keys: set[str]):
    """``value`` without ``keys``, at any depth."""
    if isinstance(value, dict):
        return {k: drop(v, keys) for k, v in value.items() if k not in keys}
    if isinstance(value, list):
        return [drop(v, keys) for v in value]
    return value


def compare(old: Path, new: Path, ignore: set[str] = frozenset()) -> int:
    status = 0
    for path in sorted(old.glob("*.json")):
        other = new / path.name
        if not other.is_file():
            print(f"{path.stem}: missing after")
            status = 1
            continue
        diffs = differences(drop(json.loads(path.read_text()), ignore),
                            drop(json.loads(other.read_text()), ignore))
        print(f"{path.stem}: {'the same' if not diffs else f'{len(diffs)} differences'}")
        for d in diffs[:20]:
            print(f"  {d}")
        status |= bool(diffs)
    return status


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("save")
    s.add_argument("folder", type=Path)
    s.add_argument("cases", nargs="*", help=f"some of {', '.join(CASES)} (default: all)")
    c = sub.add_parser("compare")
    c.add_argument("old", type=Path)
    c.add_argument("new", type=Path)
    c.add_argument("--ignore", action="append", default=[], metavar="KEY",
                   help="leave this key out at any depth (repeatable): a change meant to alter "
                        "the iteration counts only compares with --ignore iterations --ignore "
                        "history --ignore iteration_counts")
    args = parser.parse_args(argv)
    if args.command == "save":
        unknown = [c for c in args.cases if c not in CASES]
        if unknown:
            parser.error(f"unknown cases {unknown}; choose from {', '.join(CASES)}")
        save(args.folder, args.cases or list(CASES))
        return 0
    return compare(args.old, args.new, set(args.ignore))


if __name__ == "__main__":
    sys.exit(main())
