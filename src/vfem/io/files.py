"""Writing a results folder's files so that none is ever half written: each goes to a temporary
name and is renamed into place (an analysis that fails or is killed later never damages what
was already written). A leaf of :mod:`vfem.io`: the writers (:mod:`vfem.io.results`), the
figures (:mod:`vfem.io.replot`) and the folder's record (:mod:`vfem.io.folders`) all use it, and
it imports none of them.
"""

from __future__ import annotations

import json
import os
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

#: the zlib level of vfem's VTU files: 1 writes a 1M-point body's step in 1.8 s against 3.3 s
#: at zlib's default (6), for a file 1 % larger (93 against 94 MiB; ``python
#: benchmarks/vtu_output.py``, issue 19, item 5); ParaView inflates any level alike
VTU_ZLIB_LEVEL = 1


class _ZlibAt:
    """The :mod:`zlib` module with ``compress`` at one level: what meshio's VTU writer sees
    while :func:`vtu_compression` is in force (meshio offers no level of its own)."""

    def __init__(self, level: int):
        self.level = level

    def compress(self, data: bytes) -> bytes:
        return zlib.compress(data, self.level)

    def __getattr__(self, name: str):
        return getattr(zlib, name)


@contextmanager
def vtu_compression(level: int = VTU_ZLIB_LEVEL) -> Iterator[None]:
    """meshio's VTU writer compressing at zlib ``level`` inside the block; unchanged (its
    default level) if meshio's writer is not laid out as expected (another meshio)."""
    try:
        import meshio.vtu._vtu as vtu
    except ImportError:  # pragma: no cover - meshio is a dependency
        yield
        return
    if getattr(vtu, "zlib", None) is not zlib:
        yield
        return
    vtu.zlib = _ZlibAt(level)
    try:
        yield
    finally:
        vtu.zlib = zlib


def _atomic_write(path: Path, write) -> None:
    """``write(tmp)`` then rename ``tmp`` to ``path`` (``path`` is whole or as it was)."""
    tmp = path.with_name(path.name + ".part")
    write(tmp)
    os.replace(tmp, path)


#: the VTU meshes of the last step written in this process, by file: path -> (the file's
#: (mtime, size) when written, the meshio.Mesh). A run's figures, drawn from the files it just
#: wrote (vfem.io.replot), take the mesh from here instead of reading and inflating the file
#: again (issue 19: at 1M dofs, 1 s of the figures); a file changed since is read.
_written: dict[Path, tuple[tuple[int, int], object]] = {}


def remember_vtu(path: Path, mesh, new_step: bool = False) -> None:
    """Keep ``mesh``, just written to ``path`` (``new_step``: forget the previous step's)."""
    if new_step:
        _written.clear()
    st = os.stat(path)
    _written[Path(path).resolve()] = ((st.st_mtime_ns, st.st_size), mesh)


def forget_vtus() -> None:
    """Drop the meshes kept by :func:`remember_vtu` (a run's figures are drawn: ``vfem plot``
    reads the files)."""
    _written.clear()


def written_vtu(path: Path):
    """The mesh this process last wrote to ``path``, if the file is still that one; else None."""
    key = Path(path).resolve()
    entry = _written.get(key)
    if entry is None:
        return None
    try:
        st = os.stat(key)
    except OSError:
        return None
    return entry[1] if entry[0] == (st.st_mtime_ns, st.st_size) else None


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
