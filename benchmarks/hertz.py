"""Hertz benchmark: vfem against one plain linear solve of the same bodies, by refinement.

    python benchmarks/hertz.py [LEVEL ...]        # same as: vfem bench hertz --levels ...
    VFEM_VARIANT=thesis python benchmarks/hertz.py  # the thesis's plain reading
"""

import os
import sys

from vfem.bench import hertz_benchmark

if __name__ == "__main__":
    levels = [int(a) for a in sys.argv[1:]] or [0, 1, 2, 3, 4]
    hertz_benchmark(levels, print_row=print, variant=os.environ.get("VFEM_VARIANT", "paired"))
