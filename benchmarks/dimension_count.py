"""Where the code assumes two dimensions: a count by pattern, per file (issue 18, item 3).

    python benchmarks/dimension_count.py            # the count over src/vfem, per file
    python benchmarks/dimension_count.py --lines    # and every line counted
    python benchmarks/dimension_count.py --root /tmp/before/src/vfem   # another checkout
    python benchmarks/dimension_count.py --tests    # the tests of the dimension instead (issue 38)

A line counts once if it matches any of :data:`PATTERNS`: the forms 2D takes in this code (dofs
as ``2n, 2n+1``, arrays of two columns, ``reshape(-1, 2)``, strided ``::2`` dof slices, a normal
by a 90° rotation, the components named ``("x", "y")``, two-node facets read as ``[:, 0]`` and
``[:, 1]`` ends, closed-form 2×2 determinants). A pattern count is a measure, not a proof: it
finds the 2D forms written the way this code writes them; it was checked by reading the lines it
lists (``--lines``). The closing note of issue 18 gives the count before and after.
"""

from __future__ import annotations

import argparse
import io
import re
import sys
import tokenize
from collections import Counter
from pathlib import Path

#: name -> the regular expression of one form of the 2D assumption
PATTERNS: dict[str, str] = {
    "dofs 2n, 2n+1": (r"\b2 \* \w+(\[[^\]]*\])?(, | \+ 1)|\b2 \* \w+ \+ 1\b"
                      r"|2 \* s\.nc|2 \* self\.nc"),
    "two columns": r"zeros\(\(\w[\w.\[\]\s:+*-]*, 2\)|reshape\(\(?[-\w.]+, 2\b|\(\w+\.nc, 2\)",
    "strided dofs": r"::2\b|\d::2|\+ d::2|d:[\w\[\] +]*:2\b",
    "90-degree normal": r"\[:, 1\], -|-\w+\[:, 1\], \w+\[:, 0\]|\[:, \[1, 0\]\]",
    "components x, y": r"\(\"x\", \"y\"\)|\{\"x\": 0, \"y\": 1\}",
    "two-node facet ends": r"\w+\[:, 0\], \w+\[:, 1\]|ends\[:, [01]\]|facets\[:, :2\]",
    "2x2 closed forms": r"\[0, 0\] \* \w+\[1, 1\]|\[\.\.\., 0, 0\] \* \w+\[\.\.\., 1, 1\]",
    "range(2) components": r"for \w+ in range\(2\)",
}

#: ``--tests``: the forms a test of the dimension takes (a branch on it), what issue 38 wants in
#: the geometry layer alone: a dimension compared (``dim == 3``, ``s.dim != 2``), an array's
#: number of axes compared (the tangential arrays, ``(n,)`` in 2D and ``(n, 2)`` in 3D), a
#: normal's or a point's columns compared (``normal.shape[1] == 2``, ``len(pos) == 3``), and the
#: 3D twins called by name
#: (``_three_d(``, ``..._3d(``)
TESTS: dict[str, str] = {
    "dimension compared": r"\bdim\b\s*(==|!=|<=?|>=?)\s*[123]\b|\b[123]\s*(==|!=)\s*\w*\.?dim\b",
    # (not a matrix-free operator's vector-or-block test, ``vector = x.ndim == 1``)
    "axes compared": r"(?<!vector = )\b\w+(\[\w+\])?\.ndim\b\s*(==|!=|<=?|>=?)\s*\d",
    # (not a facet's node count: a quadratic 2D facet's three columns)
    "normal's columns": r"normals?\w*\.shape\[(1|-1)\]\s*(==|!=)\s*[23]\b|len\(pos\)\s*==\s*3\b",
    "3D twin by name": r"\b\w*(_3d|three_d)\(",
}

#: ``--tests``: the geometry layer of issue 38 (search, facet kinds, surfaces, pairing, transfer):
#: the stages ``contact/search/`` and ``contact/geometry/``
GEOMETRY = ("contact/search/", "contact/geometry/")

#: patterns read on the raw line (their form is a string)
RAW = ("components x, y",)

#: where the remaining lines are, by layer (first match); what the restructuring wants is every
#: 2D line of the contact core in its geometry layer
GROUPS = (
    ("geometry layer (contact/geometry/surface.py, contact/search/closest.py, "
     "contact/geometry/facets.py)",
     ("contact/geometry/surface.py", "contact/search/closest.py", "contact/geometry/facets.py")),
    ("bodies and their 2D mechanics (bodies, nonlinear, kinematics, materials, result types)",
     ("bodies/", "nonlinear.py", "kinematics.py", "materials/", "result_types.py")),
    ("the thesis variant (kept 2D, issue 18 item 7)", ("contact/formulations/algorithm.py",)),
    ("the independent invariant check", ("contact/invariants/",)),
    ("the classical baselines", ("contact/formulations/baselines.py",)),
    ("the rest of the contact core", ("contact/",)),
    ("meshes", ("mesh/",)),
    ("figures, files and the command line", ("io/", "cli/")),
    ("elsewhere", ("",)),
)


def code_lines(text: str) -> list[str]:
    """Each line of ``text`` with its strings and comments blanked (docstrings do not count)."""
    lines = [list(line) for line in text.splitlines()]
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type not in (tokenize.STRING, tokenize.COMMENT):
            continue
        (r0, c0), (r1, c1) = tok.start, tok.end
        for r in range(r0, r1 + 1):
            row = lines[r - 1]
            a = c0 if r == r0 else 0
            b = c1 if r == r1 else len(row)
            row[a:b] = " " * (b - a)
    return ["".join(row) for row in lines]


def count(root: Path, patterns: dict[str, str] = PATTERNS
          ) -> tuple[Counter, Counter, list[tuple[str, int, str, str]]]:
    per_file: Counter = Counter()
    per_kind: Counter = Counter()
    lines = []
    compiled = {k: re.compile(v) for k, v in patterns.items()}
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        text = path.read_text()
        for no, (line, code) in enumerate(zip(text.splitlines(), code_lines(text)), 1):
            if not code.strip():
                continue
            # the component names are strings: read on the line itself, where it has code
            kind = next((k for k, rx in compiled.items()
                         if rx.search(line if k in RAW else code)), None)
            if kind is not None:
                per_file[rel] += 1
                per_kind[kind] += 1
                lines.append((rel, no, kind, line.strip()))
    return per_file, per_kind, lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", type=Path,
                        default=Path(__file__).resolve().parents[1] / "src" / "vfem")
    parser.add_argument("--lines", action="store_true", help="list every line counted")
    parser.add_argument("--tests", action="store_true",
                        help="count the tests of the dimension (branches on it) instead")
    args = parser.parse_args(argv)
    per_file, per_kind, lines = count(args.root, TESTS if args.tests else PATTERNS)
    total = sum(per_file.values())
    groups = GROUPS
    if args.tests:
        contact = [f for f in per_file if f.startswith("contact/") and not f.startswith(GEOMETRY)]
        print(f"{total} tests of the dimension in {len(per_file)} files under {args.root}; "
              f"{sum(per_file[f] for f in contact)} in {len(contact)} contact modules outside "
              "its geometry layer")
        groups = (("the geometry layer (" + ", ".join(GEOMETRY) + ")", GEOMETRY),
                  ("the rest of contact", ("contact/",)), ("elsewhere", ("",)))
    else:
        print(f"{total} lines assume 2D in {len(per_file)} files under {args.root}")
    grouped: Counter = Counter()
    for f, n in per_file.items():
        grouped[next(name for name, prefixes in groups if f.startswith(prefixes))] += n
    for name, _ in groups:
        if grouped[name]:
            print(f"  {grouped[name]:4d}  {name}")
    print("by form:")
    for kind, n in per_kind.most_common():
        print(f"  {n:4d}  {kind}")
    print("by file:")
    for f, n in per_file.most_common():
        print(f"  {n:4d}  {f}")
    if args.lines:
        for rel, no, kind, text in lines:
            print(f"{rel}:{no}: [{kind}] {text}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
