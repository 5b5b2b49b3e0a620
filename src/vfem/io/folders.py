"""Results folders that cannot be mixed up.

A run writes many files into its results folder: a VTU per body and step, the ParaView series,
``contact.csv``, checkpoints, ``summary.json``, figures (and, for the wedge, a folder per case).
A second run into the same folder must not leave the first run's files beside its own — a
16-step run followed by a 4-step run would otherwise leave ``…_step0005…0016.vtu`` behind, which
ParaView's series grouping picks up — and must never delete a file that vfem did not write.

So every run keeps a record, ``.vfem-run.json``, in its folder: what was run (the command, the
model, the ``--set`` changes, the vfem version, when) and the list of files the run wrote
(updated after every converged step, so a run stopped at any moment still owns its files). A new
run into a folder

- that holds the record of the *same* model (the same example or input file, whatever its
  ``--set`` changes or edits): clears the files listed there, then writes its own;
- that holds another model's results: is refused, naming what is there, unless ``--overwrite``
  is given (then the same clearing);
- written by a vfem older than the record (``summary.json``, no record): clears only the files
  whose names only vfem writes (``*_stepNNNN.vtu``, ``results.pvd``, ``contact.csv``,
  ``reactions.csv``, ``checkpoint/step*.npz``);
- any other file there is left alone.

``--resume`` keeps everything (it continues the same run) and the record's description of the
run, adding the resuming command under ``resumed``; a command refused before it solved anything
changes nothing.
"""

from __future__ import annotations

import datetime
import json
import logging
import re
from pathlib import Path

from .._version import __version__
from ..errors import InputError
from .files import _atomic_write

log = logging.getLogger(__name__)

RECORD = ".vfem-run.json"
#: File names that only vfem writes into a results folder (cleared from folders written before
#: the record existed).
_LEGACY = re.compile(r"(.*_step\d{4}\.vtu|results\.pvd|contact\.csv|reactions\.csv|"
                     r"checkpoint/step\d{4}\.npz)$")


def run_description(command: str, target: str, settings: list[str]) -> dict:
    """What a run is, for its record and ``summary.json`` (``run``): the command line, the
    example's name or the input file's path, the ``--set`` changes, vfem's version, when."""
    return {"command": command, "target": target, "settings": list(settings),
            "vfem_version": __version__,
            "started": datetime.datetime.now().astimezone().isoformat(timespec="seconds")}


def _same_model(a: dict, b: dict) -> bool:
    """The same example or input file (its ``--set`` changes and edits aside: the user chose
    this folder for that model again)."""
    return a.get("target") == b.get("target")


def _files(folder: Path) -> set[str]:
    """Every file under ``folder`` (relative POSIX paths), the record excepted."""
    if not folder.is_dir():
        return set()
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*")
            if p.is_file() and p.name != RECORD}


def read_record(folder: Path) -> dict | None:
    """The record of the run that last wrote ``folder`` (None: none, or unreadable)."""
    try:
        data = json.loads((Path(folder) / RECORD).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


class ResultsFolder:
    """The folder a run writes into, and the files that run owns there.

    Args:
        path: the folder.
        run: :func:`run_description` of the run.
    """

    def __init__(self, path: Path, run: dict):
        self.path = Path(path)
        self.run = run
        self.foreign: set[str] = set()

    def prepare(self, overwrite: bool = False, resume: bool = False) -> list[str]:
        """Make the folder ready for the run: clear what an earlier run of vfem wrote there
        (refused, :class:`InputError`, when that was another model and ``overwrite`` is not
        given); returns the names of the files removed. ``resume``: keep everything."""
        previous = read_record(self.path)
        present = _files(self.path)
        if resume:
            owned = set((previous or {}).get("files") or [])
            self.foreign = present - owned
            if previous is not None:  # the run continued is still the one described
                resumed = [*(previous.get("resumed") or []),
                           {k: self.run[k] for k in ("command", "started") if k in self.run}]
                self.run = {**{k: v for k, v in previous.items() if k != "files"},
                            "resumed": resumed}
            return []
        if previous is not None:
            owned = set(previous.get("files") or []) & present
            if owned and not overwrite and not _same_model(previous, self.run):
                raise InputError(
                    f"{self.path} holds the results of another run ({describe(previous)}); "
                    "name another folder with --out, or add --overwrite to replace them")
        elif (self.path / "summary.json").is_file():  # written before the record existed
            owned = {f for f in present if _LEGACY.match(f)}
        else:
            owned = set()
        removed = []
        for name in sorted(owned):
            try:
                (self.path / name).unlink()
                removed.append(name)
            except FileNotFoundError:
                pass
        for folder in sorted({(self.path / n).parent for n in owned}, reverse=True):
            if folder != self.path:
                try:
                    folder.rmdir()  # only if the run's files were all it held
                except OSError:
                    pass
        if removed:
            log.info("%s: removed %d files of the earlier run", self.path, len(removed))
        self.foreign = present - owned
        self.update()
        return removed

    def update(self) -> None:
        """Write the record: the run and every file in the folder that it did not find there."""
        if not self.path.is_dir():
            return
        record = {**self.run, "files": sorted(_files(self.path) - self.foreign)}
        _atomic_write(self.path / RECORD, lambda p: p.write_text(
            json.dumps(record, indent=1) + "\n", encoding="utf-8"))

    def stamp_summary(self) -> None:
        """Add the run's description to ``summary.json`` (key ``run``), if there is one."""
        path = self.path / "summary.json"
        try:
            summary = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return
        if isinstance(summary, dict) and summary.get("run") != self.run:
            summary["run"] = self.run
            _atomic_write(path, lambda p: p.write_text(json.dumps(summary, indent=2) + "\n",
                                                       encoding="utf-8"))


def describe(run: dict) -> str:
    """``vfem run hertz --set force=2000, vfem 0.1.0, 2026-11-24T22:10:00+00:00``."""
    parts = [run.get("command") or str(run.get("target"))]
    if run.get("vfem_version"):
        parts.append(f"vfem {run['vfem_version']}")
    if run.get("started"):
        parts.append(str(run["started"]))
    return ", ".join(parts)


def default_folder(name: str, settings: list[str]) -> Path:
    """``results/<name>``, with the ``--set`` changes in the name (``results/hertz_force=2000``)
    so that runs with different settings do not share a folder. Always one folder inside
    ``results``: a model's name is made file-name safe (``../x`` or ``/tmp/x`` cannot send the
    results elsewhere; an input file's ``output.directory`` is checked for the same)."""
    safe = re.sub(r"[^A-Za-z0-9_.=+-]", "-", name).lstrip(".") or "model"
    suffix = "".join("_" + re.sub(r"[^A-Za-z0-9.=+-]", "-", s.replace(" ", "")) for s in settings)
    return Path("results") / f"{safe}{suffix}"
