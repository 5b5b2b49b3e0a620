"""Figures from a results directory, without solving: only the files on disk are read.

:func:`plot_results` reads ``results.pvd`` (and the VTU files it lists), ``contact.csv`` and,
if present, ``summary.json`` (see :mod:`vfem.io.results` for their content) and writes:

* ``deformed.png`` — the last step's deformed configuration of every body, true scale, mesh lines,
  windowed on the contact zone (the bounding box of the deformed nodes in contact, padded); when
  that window does not show the whole model, also ``deformed_overall.png`` with everything;
* ``contact_pressure.png`` — the nominal contact pressure against the undeformed x of the nodes
  in contact (against y when they clearly lie along y), per body, at the last step (bold), with
  up to three earlier steps as lighter lines;
* ``history.png`` — per step: iterations, final largest penetration and equilibrium error (from
  ``summary.json``'s ``steps``, when there), and the magnitude of the resultant contact force
  on each body (the sum of the VTU's nodal ``contact_force``; per unit thickness).

Without ``contact.csv`` (results written by an older version), the nodes in contact and their
pressure are taken from the VTU's ``contact_status`` and ``contact_pressure`` point fields.
"""

from __future__ import annotations

import csv
import json
import logging
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import meshio
import numpy as np

from ..errors import InputError
from . import plots
from .results import _safe

log = logging.getLogger(__name__)

# boundary polygon of each VTK cell type (corners and edge midpoints in order around the cell)
_POLYGONS = {"triangle": [0, 1, 2], "triangle6": [0, 3, 1, 4, 2, 5], "quad": [0, 1, 2, 3],
             "quad8": [0, 4, 1, 5, 2, 6, 3, 7], "quad9": [0, 4, 1, 5, 2, 6, 3, 7]}
_STEP_IN_NAME = re.compile(r"^(?P<stem>.*)_step(?P<step>\d+)\.vtu$")


@dataclass
class BodyFrame:
    """One body at one step, as read from its VTU file."""

    part: int
    name: str
    path: Path
    points: np.ndarray  # (n, 2) undeformed
    polygons: np.ndarray  # (m, k) point numbers around each cell
    displacement: np.ndarray  # (n, 2)
    point_data: dict[str, np.ndarray]


@dataclass
class Step:
    step: int
    load_factor: float
    bodies: list[BodyFrame] = field(default_factory=list)


@dataclass
class ContactNodes:
    """The contact candidate nodes of one body at one step (or only its nodes in contact)."""

    node: np.ndarray
    x: np.ndarray  # (n, 2) undeformed
    u: np.ndarray  # (n, 2)
    pressure: np.ndarray
    contact: np.ndarray  # bool


def read_pvd(directory: Path) -> list[tuple[int, float, int, str, Path]]:
    """Entries of ``results.pvd``: (step, load factor, part, body name, VTU path), in file order.

    Steps are numbered from the VTU names (``<body>_step0003.vtu``) when they follow that
    pattern, else in order (a step ends where a body repeats or the load factor changes).
    """
    pvd = Path(directory) / "results.pvd"
    if not pvd.is_file():
        raise InputError(f"no results.pvd in {directory} (not a vfem results directory?)")
    try:
        root = ET.parse(pvd).getroot()
    except ET.ParseError as exc:
        raise InputError(f"{pvd}: not a readable PVD file: {exc}") from None
    raw = []
    for ds in root.iter("DataSet"):
        try:
            t = float(ds.attrib["timestep"])
            part = int(ds.attrib.get("part", "0"))
            file = ds.attrib["file"]
        except (KeyError, ValueError) as exc:
            raise InputError(f"{pvd}: DataSet entry without a valid timestep/part/file "
                             f"({exc})") from None
        raw.append((t, part, file, ds.attrib.get("name")))
    if not raw:
        raise InputError(f"{pvd} lists no results (no converged step was written)")
    out = []
    ordinal, seen, last_t = 0, set(), None
    for t, part, file, name in raw:
        if part in seen or t != last_t:
            ordinal, seen, last_t = ordinal + 1, set(), t
        seen.add(part)
        m = _STEP_IN_NAME.match(Path(file).name)
        step = int(m["step"]) if m else ordinal
        if name is None:
            name = m["stem"] if m else f"body {part}"
        out.append((step, t, part, name, Path(directory) / file))
    return out


def read_vtu(path: Path, part: int, name: str) -> BodyFrame:
    if not path.is_file():
        raise InputError(f"results.pvd lists {path}, which does not exist")
    try:
        m = meshio.read(path)
    except Exception as exc:  # meshio raises many kinds on a damaged file
        raise InputError(f"{path}: cannot be read as a VTU file: {exc}") from None
    if len(m.cells) != 1:
        raise InputError(f"{path}: expected one block of cells, found {len(m.cells)}")
    block = m.cells[0]
    if block.type not in _POLYGONS:
        raise InputError(f"{path}: cell type {block.type!r} is not one vfem writes "
                         f"({', '.join(_POLYGONS)})")
    if "displacement" not in m.point_data:
        raise InputError(f"{path}: no 'displacement' point field")
    u = np.asarray(m.point_data["displacement"], dtype=float)
    return BodyFrame(part=part, name=name, path=path, points=np.asarray(m.points)[:, :2],
                     polygons=np.asarray(block.data)[:, _POLYGONS[block.type]],
                     displacement=u[:, :2], point_data=dict(m.point_data))


def read_steps(directory: Path) -> list[Step]:
    """Every step listed in ``results.pvd``, with every body's VTU read."""
    steps: dict[int, Step] = {}
    for step, t, part, name, path in read_pvd(directory):
        s = steps.setdefault(step, Step(step, t))
        s.bodies.append(read_vtu(path, part, name))
    for s in steps.values():
        s.bodies.sort(key=lambda b: b.part)
    return [steps[k] for k in sorted(steps)]


def read_contact_csv(path: Path) -> dict[tuple[int, str], ContactNodes]:
    """``contact.csv`` by (step, body name)."""
    rows: dict[tuple[int, str], list[list]] = {}
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            missing = {"step", "body", "node", "x", "y", "ux", "uy", "pressure", "status"} - set(
                reader.fieldnames or ())
            if missing:
                raise InputError(f"{path}: missing column(s) {', '.join(sorted(missing))}")
            for r in reader:
                rows.setdefault((int(r["step"]), r["body"]), []).append(
                    [int(r["node"]), float(r["x"]), float(r["y"]), float(r["ux"]),
                     float(r["uy"]), float(r["pressure"]), r["status"] == "contact"])
    except (ValueError, KeyError, TypeError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{path}: malformed row ({exc})") from None
    out = {}
    for key, rs in rows.items():
        node, x, y, ux, uy, p, on = (np.array(c) for c in zip(*rs))
        out[key] = ContactNodes(node.astype(int), np.column_stack([x, y]),
                                np.column_stack([ux, uy]), p.astype(float), on.astype(bool))
    return out


def _contact_nodes(frame: BodyFrame) -> ContactNodes:
    """Nodes in contact from a VTU's point fields (when there is no contact.csv)."""
    pd = frame.point_data
    if "contact_status" not in pd or "contact_pressure" not in pd:
        raise InputError(f"{frame.path}: no contact_status/contact_pressure point fields "
                         "(and no contact.csv)")
    on = np.asarray(pd["contact_status"]).ravel() > 0
    node = np.flatnonzero(on)
    return ContactNodes(node, frame.points[node], frame.displacement[node],
                        np.asarray(pd["contact_pressure"], dtype=float).ravel()[node],
                        np.ones(len(node), dtype=bool))


def plot_results(directory: Path | str) -> list[Path]:
    """Write ``deformed.png`` (and maybe ``deformed_overall.png``), ``contact_pressure.png`` and
    ``history.png`` into ``directory`` from its results files; return the paths written.

    Raises :class:`~vfem.errors.InputError` naming the path when the directory, its
    ``results.pvd`` or a VTU file it lists is missing or unreadable.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError(f"results directory {directory} does not exist")
    steps = read_steps(directory)
    csv_path = directory / "contact.csv"
    table = read_contact_csv(csv_path) if csv_path.is_file() else None
    summary = None
    summary_path = directory / "summary.json"
    if summary_path.is_file():
        try:
            summary = json.loads(summary_path.read_text(encoding="utf-8"))
        except (ValueError, UnicodeDecodeError) as exc:
            raise InputError(f"{summary_path}: not valid JSON: {exc}") from None

    def contact(step: Step, frame: BodyFrame) -> ContactNodes:
        if table is None:
            return _contact_nodes(frame)
        c = table.get((step.step, frame.name))
        if c is None:  # body names in the pvd may be the file-safe ones (older files)
            c = next((v for (s, n), v in table.items() if s == step.step and _safe(n) ==
                      frame.name), None)
        if c is None:
            e = np.zeros(0)
            return ContactNodes(e.astype(int), np.zeros((0, 2)), np.zeros((0, 2)), e,
                                e.astype(bool))
        return c

    written = _deformed(directory, steps, contact)
    written.append(_pressure(directory, steps, contact,
                             "contact.csv" if table is not None else "VTU fields"))
    written.append(_history(directory, steps, summary))
    for p in written:
        log.info("wrote %s", p)
    return written


def _deformed(directory: Path, steps: list[Step], contact) -> list[Path]:
    last = steps[-1]
    bodies = [(b.name, b.points, b.polygons, b.displacement) for b in last.bodies]
    xs = np.vstack([b.points + b.displacement for b in last.bodies])
    lo, hi = xs.min(axis=0), xs.max(axis=0)
    extent = float((hi - lo).max()) or 1.0
    touching = [c.x[c.contact] + c.u[c.contact] for c in (contact(last, b) for b in last.bodies)]
    touching = np.vstack(touching) if touching else np.zeros((0, 2))
    label = f"step {last.step}, load factor {last.load_factor:.6g}"
    out = []
    path = directory / "deformed.png"
    if len(touching):
        clo, chi = touching.min(axis=0), touching.max(axis=0)
        pad = max(0.5 * float((chi - clo).max()), 0.05 * extent)
        window = (clo[0] - pad, chi[0] + pad, clo[1] - pad, chi[1] + pad)
        plots.configurations(path, [(label, bodies)], "Deformed configuration (true scale), "
                             "contact zone", window)
        out.append(path)
        if window[0] > lo[0] or window[1] < hi[0] or window[2] > lo[1] or window[3] < hi[1]:
            whole = directory / "deformed_overall.png"
            plots.configurations(whole, [(label, bodies)], "Deformed configuration (true scale)")
            out.append(whole)
    else:
        plots.configurations(path, [(label, bodies)], "Deformed configuration (true scale), "
                             "no node in contact")
        out.append(path)
    return out


def _pressure(directory: Path, steps: list[Step], contact, source: str) -> Path:
    last = len(steps) - 1
    shown = sorted({int(round(k)) for k in np.linspace(0, last, 4)}) if last else [0]
    nodes = {(k, b.name): contact(steps[k], b) for k in shown for b in steps[k].bodies}
    # against x, unless the nodes in contact clearly lie along y (a vertical contact)
    xy = np.vstack([c.x[c.contact] for c in nodes.values()] + [np.zeros((0, 2))])
    axis = 1 if len(xy) and np.ptp(xy[:, 1]) > 2.0 * np.ptp(xy[:, 0]) else 0
    profiles: dict[str, list] = {b.name: [] for b in steps[-1].bodies}
    for k in shown:
        s = steps[k]
        for b in s.bodies:
            c = nodes[k, b.name]
            on = c.contact
            profiles.setdefault(b.name, []).append(
                (f"step {s.step} (load factor {s.load_factor:.4g})", c.x[on, axis],
                 c.pressure[on]))
    path = directory / "contact_pressure.png"
    plots.contact_pressure_profiles(
        path, profiles, "Contact pressure at the nodes in contact\n(nominal: normal force / "
        f"undeformed length; from {source})", xlabel=f"{'xy'[axis]} (undeformed)",
        ylabel="contact pressure")
    return path


def _history(directory: Path, steps: list[Step], summary: dict | None) -> Path:
    panels = []
    rows = summary.get("steps") if isinstance(summary, dict) else None
    if isinstance(rows, list) and rows and all(isinstance(r, dict) and "step" in r
                                               for r in rows):
        x = np.array([r["step"] for r in rows], dtype=float)

        def series(key):
            if all(isinstance(r.get(key), (int, float)) for r in rows):
                return x, np.array([r[key] for r in rows], dtype=float)
            return None

        if (it := series("iterations")) is not None:
            panels.append(("contact iterations", {"iterations": it}, False))
        errs = {label: s for label, key in (("largest penetration", "max_penetration"),
                                            ("largest equilibrium error",
                                             "max_equilibrium_error"))
                if (s := series(key)) is not None}
        if errs:
            panels.append(("final errors of the step", errs, True))
    force = {}
    for name in dict.fromkeys(b.name for s in steps for b in s.bodies):
        xs, ys = [], []
        for s in steps:
            for b in s.bodies:
                if b.name == name and "contact_force" in b.point_data:
                    f = np.asarray(b.point_data["contact_force"], dtype=float)[:, :2]
                    xs.append(s.step)
                    ys.append(float(np.linalg.norm(f.sum(axis=0))))
        if xs:
            force[name] = (np.array(xs, dtype=float), np.array(ys))
    panels.append(("|resultant contact force| on body\n(sum of nodal contact_force)", force,
                   False))
    path = directory / "history.png"
    lf = ", ".join(f"{s.load_factor:.4g}" for s in steps[:12]) + (", ..." if len(steps) > 12
                                                                   else "")
    plots.history_panels(path, panels, "step", f"Steps (load factors {lf})")
    return path

