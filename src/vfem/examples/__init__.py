"""Built-in examples: each reproduces a result of Underhill's thesis (see ``docs/examples.md``)."""

from __future__ import annotations

EXAMPLES = ("springs", "hertz")
