"""``python -m vfem.cli``: the ``vfem`` command, as ``python -m vfem``."""

import sys

from . import main

if __name__ == "__main__":
    sys.exit(main())
