"""Hertz benchmark: vfem against one plain linear solve of the same mesh (docs/benchmarks.md).

    python benchmarks/hertz.py --dofs 10k 100k 1M --solver all   # same as: vfem bench hertz ...
    python benchmarks/hertz.py --levels 0 1 2 --methods vfem lagrange --patch

Every option of ``vfem bench hertz`` (``vfem bench --help``).
"""

import sys

from vfem.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "hertz", *sys.argv[1:]]))
