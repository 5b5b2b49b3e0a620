"""``python -m vfem.cli``: the ``vfem`` command, as ``python -m vfem``."""

import sys

from . import main

sys.exit(main())
