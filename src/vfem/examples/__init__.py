"""Built-in examples: each reproduces a result of Underhill's thesis (see ``docs/examples.md``).

Every example module provides ``Parameters`` (a frozen dataclass of its settings), ``run(params,
out, on_step=None) -> summary`` and ``report(summary) -> lines`` (what the CLI prints).
"""

from __future__ import annotations

import importlib

EXAMPLES = ("springs", "hertz", "patch", "wedge", "block", "gasket")


def load(name: str):
    """The module of a built-in example."""
    return importlib.import_module(f"{__name__}.{name}")
