"""Writing a results folder's files so that none is ever half written: each goes to a temporary
name and is renamed into place (an analysis that fails or is killed later never damages what
was already written). A leaf of :mod:`vfem.io`: the writers (:mod:`vfem.io.results`), the
figures (:mod:`vfem.io.replot`) and the folder's record (:mod:`vfem.io.folders`) all use it, and
it imports none of them.
"""

from __future__ import annotations

import json
import os
from pathlib import Path


def _atomic_write(path: Path, write) -> None:
    """``write(tmp)`` then rename ``tmp`` to ``path`` (``path`` is whole or as it was)."""
    tmp = path.with_name(path.name + ".part")
    write(tmp)
    os.replace(tmp, path)


def write_summary(out: Path, summary: dict) -> Path:
    """``out/summary.json`` (the folder made if needed), written whole."""
    Path(out).mkdir(parents=True, exist_ok=True)
    path = Path(out) / "summary.json"
    _atomic_write(path, lambda p: p.write_text(json.dumps(summary, indent=2) + "\n",
                                               encoding="utf-8"))
    return path


def _safe(name: str) -> str:
    """A file-name-safe version of a body name."""
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name) or "body"
