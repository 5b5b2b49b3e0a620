"""Built-in examples: each reproduces a result of Underhill's thesis (see ``docs/examples.md``).

Every example module provides ``Parameters`` (a frozen dataclass of its settings), ``run(params,
out, on_step=None) -> summary`` and ``report(summary) -> lines`` (what the CLI prints). Those with
bodies also describe their model as data, ``config(params)`` (or ``configs(params)`` for several
models): that is what ``build`` solves and what ``vfem export`` writes as ``examples/*.toml``.
"""

from __future__ import annotations

import importlib

from vfem.io import replot

EXAMPLES = ("springs", "hertz", "patch", "wedge", "block", "gasket", "sliding", "punch",
            "cattaneo", "sphere", "press_fit", "cattaneo3d", "circular_punch", "stack",
            "indentation", "thick_cylinder", "block_indentation",
            "sphere_indentation", "axisymmetric_sphere", "axisymmetric_press_fit",
            "oring", "ring_crush")


def load(name: str):
    """The module of a built-in example."""
    return importlib.import_module(f"{__name__}.{name}")


# the figure sets of the folders the examples' runs write (vfem plot, and each run's own figures)
replot.register_examples(EXAMPLES, load)
