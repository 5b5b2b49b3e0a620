"""``python -m vfem``: the ``vfem`` command (what ``vfem run --ranks N`` launches on each rank)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
