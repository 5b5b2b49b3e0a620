"""Figures from a results directory, without solving: only the files on disk are read.

Every figure vfem draws is drawn here, from a results folder (:class:`Folder`): a run writes
its files, then calls :func:`plot_results` on its folder, and ``vfem plot`` calls the same, so
both draw the same figures from the same data. ``summary.json``'s ``figure_set`` says which
figures: a built-in example's (its module's ``figures(folder)``; what they need beyond the
results files, e.g. Hertz's half-width or a linear prediction, the example writes into
``summary.json``'s ``figure_data`` or as extra VTU files, :func:`write_frames`), or ``"input"``
for an input file's run, whose generic figures are these (also drawn for a folder that
records no figure set, e.g. one written before figure sets were recorded):

* ``deformed.png`` — the last step's deformed configuration of every body, true scale, mesh lines,
  windowed on the contact zone (the bounding box of the deformed nodes in contact, padded); when
  that window does not show the whole model, also ``deformed_overall.png`` with everything;
* ``contact_pressure.png`` — the nominal contact pressure against the undeformed x of the nodes
  in contact (against y when they clearly lie along y), per body, at the last step (bold), with
  up to three earlier steps as lighter lines;
* ``history.png`` — per step: iterations, final largest penetration and equilibrium error (from
  ``summary.json``'s ``steps``, when there), and the magnitude of the resultant contact force
  on each body (the sum of the VTU's nodal ``contact_force``; per unit thickness);
* ``von_mises.png`` — the last step's deformed bodies filled by the VTU's element ``von_mises``;
* ``friction.png`` (a run with friction) — the last step's tangential traction against x at the
  nodes that carry a pair's compatibility, sticking and slipping nodes marked apart, between
  the Coulomb limit ±mu q (q the normal traction there; both of the static/dynamic law's
  coefficients): a slipping node lies on it, a sticking one within.

A 3D model's are :mod:`vfem.io.figures3d`'s: ``pressure_<body>.png`` (and with friction
``stick_slip_<body>.png``) per body in contact, ``deformed.png``, ``von_mises.png``, with
``history.png``; what they leave undrawn is said in ``summary.json``'s ``figures_notes``.

Without ``contact.csv`` (results written by an older version), the nodes in contact and their
pressure are taken from the VTU's ``contact_status`` and ``contact_pressure`` point fields.
"""

from __future__ import annotations

import csv
import json
import logging
import re
import shlex
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import meshio
import numpy as np

from ..contact.laws import friction_law as contact_friction_law
from ..contact.laws import law_bounds, law_record, law_text
from ..errors import InputError
from . import figures3d, plots
from .files import _safe, forget_vtus, write_summary, written_vtu

log = logging.getLogger(__name__)

# boundary polygon of each VTK cell type (corners and edge midpoints in order around the cell)
_POLYGONS = {"triangle": [0, 1, 2], "triangle6": [0, 3, 1, 4, 2, 5], "quad": [0, 1, 2, 3],
             "quad8": [0, 4, 1, 5, 2, 6, 3, 7], "quad9": [0, 4, 1, 5, 2, 6, 3, 7]}
#: The 3D cell types vfem writes (:meth:`vfem.bodies.Body.cells`): a frame keeps their nodes
_SOLIDS = ("tetra", "hexahedron", "tetra10", "hexahedron27")
_STEP_IN_NAME = re.compile(r"^(?P<stem>.*)_step(?P<step>\d+)\.vtu$")


@dataclass
class BodyFrame:
    """One body at one step, as read from its VTU file. A 3D body's (tetrahedra, hexahedra:
    ``dim`` 3) has its three coordinates and displacement components, and in ``polygons`` its
    cells' nodes in VTK's order (``cell_type`` says which cells)."""

    part: int
    name: str
    path: Path
    points: np.ndarray  # (n, 2) undeformed; (n, 3) in 3D
    polygons: np.ndarray  # (m, k) point numbers around each cell; 3D: the cells' nodes
    displacement: np.ndarray  # (n, 2); (n, 3) in 3D
    point_data: dict[str, np.ndarray]
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)  # one value per cell
    cell_type: str = ""  # VTK's name of the cells (meshio's: triangle, ..., tetra, hexahedron)

    @property
    def dim(self) -> int:
        """2, or 3 for a 3D body."""
        return int(self.points.shape[1])


class Step:
    """One step of a results folder: its number, load factor and bodies. The bodies' VTU files
    are read when ``bodies`` is first asked for, so that a figure of the last step does not
    read every step (issue 19: at 1M dofs, reading ten VTU files took 4 s of the figures)."""

    def __init__(self, step: int, load_factor: float, bodies: list[BodyFrame] | None = None,
                 files: list[tuple[int, str, Path]] | None = None):
        self.step = step
        self.load_factor = load_factor
        self._bodies = bodies
        self._files = list(files or [])  # (part, name, path) of each body's VTU

    @property
    def bodies(self) -> list[BodyFrame]:
        if self._bodies is None:
            frames = [read_vtu(path, part, name) for part, name, path in self._files]
            self._bodies = sorted(frames, key=lambda b: b.part)
        return self._bodies

    def __repr__(self) -> str:
        return f"Step({self.step}, {self.load_factor})"


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
        summary = Path(directory) / "summary.json"
        if summary.is_file():  # a run that converged no step writes its summary alone
            try:
                said = str(json.loads(summary.read_text(encoding="utf-8")).get("message", ""))
            except (OSError, ValueError, AttributeError):
                said = ""
            raise InputError(f"{directory}: its run wrote no step to draw (no results.pvd: it "
                             "stopped before its first step converged)"
                             + (f"; the run said: {said}" if said else ""))
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
        m = written_vtu(path) or meshio.read(path)  # a run's own last step: not read again
    except Exception as exc:  # meshio raises many kinds on a damaged file
        raise InputError(f"{path}: cannot be read as a VTU file: {exc}") from None
    if len(m.cells) != 1:
        raise InputError(f"{path}: expected one block of cells, found {len(m.cells)}")
    block = m.cells[0]
    if block.type not in _POLYGONS and block.type not in _SOLIDS:
        raise InputError(f"{path}: cell type {block.type!r} is not one vfem writes "
                         f"({', '.join([*_POLYGONS, *_SOLIDS])})")
    if "displacement" not in m.point_data:
        raise InputError(f"{path}: no 'displacement' point field")
    u = np.asarray(m.point_data["displacement"], dtype=float)
    if block.type in _SOLIDS:  # a 3D body: every coordinate, the cells as they are
        dim, cells = 3, np.asarray(block.data)
    else:
        dim, cells = 2, np.asarray(block.data)[:, _POLYGONS[block.type]]
    return BodyFrame(part=part, name=name, path=path, points=np.asarray(m.points)[:, :dim],
                     polygons=cells, displacement=u[:, :dim], point_data=dict(m.point_data),
                     cell_data={k: np.asarray(v[0]).ravel() for k, v in m.cell_data.items()},
                     cell_type=block.type)


def read_steps(directory: Path) -> list[Step]:
    """Every step listed in ``results.pvd``; each body's VTU is read when its step's
    ``bodies`` are first asked for (:class:`Step`)."""
    steps: dict[int, Step] = {}
    for step, t, part, name, path in read_pvd(directory):
        if not path.is_file():  # said at once, not when the step is first drawn
            raise InputError(f"results.pvd lists {path}, which does not exist")
        steps.setdefault(step, Step(step, t))._files.append((part, name, path))
    return [steps[k] for k in sorted(steps)]


def read_contact_csv(path: Path) -> dict[tuple[int, str], ContactNodes]:
    """``contact.csv`` by (step, body name); a 3D model's (columns ``z`` and ``uz``) with the
    three coordinates and displacement components."""
    rows: dict[tuple[int, str], list[list]] = {}
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            names = set(reader.fieldnames or ())
            axes = "xyz" if {"z", "uz"} <= names else "xy"
            missing = {"step", "body", "node", "x", "y", "ux", "uy", "pressure", "status"} - names
            if missing:
                raise InputError(f"{path}: missing column(s) {', '.join(sorted(missing))}")
            for r in reader:
                rows.setdefault((int(r["step"]), r["body"]), []).append(
                    [int(r["node"]), *(float(r[a]) for a in axes),
                     *(float(r[f"u{a}"]) for a in axes), float(r["pressure"]),
                     r["status"] == "contact"])
    except (ValueError, KeyError, TypeError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{path}: malformed row ({exc})") from None
    out = {}
    dim = len(axes)
    for key, rs in rows.items():
        columns = [np.array(c) for c in zip(*rs)]
        node, p, on = columns[0], columns[-2], columns[-1]
        out[key] = ContactNodes(node.astype(int), np.column_stack(columns[1:1 + dim]),
                                np.column_stack(columns[1 + dim:1 + 2 * dim]), p.astype(float),
                                on.astype(bool))
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


class Folder:
    """A results folder as its files give it: ``summary.json`` (``{}`` when absent), the steps of
    ``results.pvd`` (read on first use) and the nodes of ``contact.csv`` (or, for results
    without it, the VTU's contact fields). Every figure is drawn from one of these, never from
    a solver's objects, so ``vfem plot`` redraws what the run drew."""

    def __init__(self, directory: Path | str, summary: dict | None = None):
        self.directory = Path(directory)
        if self.directory.is_file():
            raise InputError(f"{self.directory} is a file, not a results folder: give the folder "
                             "a run wrote (vfem run ... writes results/<name>)")
        if not self.directory.is_dir():
            raise InputError(f"results directory {self.directory} does not exist")
        self.summary = read_summary(self.directory) if summary is None else summary
        self._steps: list[Step] | None = None
        self._table: dict | None = None
        #: what the figures left undrawn, and why: "<figure>: <why>" each
        self.notes: list[str] = []

    @property
    def has_steps(self) -> bool:
        """Whether the folder holds a ``results.pvd`` (an analysis that converged no step, or
        an example without bodies, writes none)."""
        return (self.directory / "results.pvd").is_file()

    @property
    def steps(self) -> list[Step]:
        if self._steps is None:
            self._steps = read_steps(self.directory)
        return self._steps

    def step(self, number: int) -> Step:
        """The step numbered ``number`` (as in the VTU names and contact.csv)."""
        found = next((s for s in self.steps if s.step == number), None)
        if found is None:
            raise InputError(f"{self.directory}: summary.json names step {number}, which "
                             "results.pvd does not list")
        return found

    def contact(self, step: Step, frame: BodyFrame) -> ContactNodes:
        """The contact candidate nodes of ``frame``'s body at ``step``."""
        if self._table is None:
            path = self.directory / "contact.csv"
            self._table = read_contact_csv(path) if path.is_file() else {}
        if not self._table:
            return _contact_nodes(frame)
        c = self._table.get((step.step, frame.name))
        if c is None:  # body names in the pvd may be the file-safe ones (older files)
            c = next((v for (s, n), v in self._table.items() if s == step.step and _safe(n) ==
                      frame.name), None)
        if c is None:
            e = np.zeros(0)
            return ContactNodes(e.astype(int), np.zeros((0, 2)), np.zeros((0, 2)), e,
                                e.astype(bool))
        return c

    @property
    def contact_source(self) -> str:
        return "contact.csv" if (self.directory / "contact.csv").is_file() else "VTU fields"

    def frames(self, label: str) -> list[BodyFrame]:
        """The extra configuration ``label`` an example recorded for its figures
        (:func:`write_frames`; ``summary.json``'s ``figure_data.frames``), in body order."""
        files = (self.summary.get("figure_data") or {}).get("frames", {}).get(label)
        if not files:
            raise InputError(f"{self.directory}/summary.json records no configuration "
                             f"{label!r} under figure_data.frames")
        return [read_vtu(self.directory / f, k, name) for k, (name, f) in enumerate(files.items())]

    def sub(self, name: str) -> Folder:
        """A sub-folder's results (the wedge's ``caseN``), with no summary of its own."""
        return Folder(self.directory / name, summary={})


def read_summary(directory: Path) -> dict:
    """``summary.json`` of a results folder ({} when there is none)."""
    path = Path(directory) / "summary.json"
    if not path.is_file():
        return {}
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not valid JSON: {exc}") from None
    return summary if isinstance(summary, dict) else {}


def write_frames(out: Path, label: str, model, displacements: dict[str, np.ndarray]
                 ) -> dict[str, str]:
    """Write a configuration that is not a converged step (a linear prediction, contact
    ignored) as one VTU per body, ``<body>_<label>.vtu`` (displacement only), so the figure
    that shows it can be redrawn from the folder; returns {body: file name} for
    ``summary.json``'s ``figure_data.frames[label]``."""
    files = {}
    for body in model.bodies:
        cell_type, conn = body.cells()
        dim = body.dim
        u = np.asarray(displacements[body.name], dtype=float).reshape(-1, dim)
        name = f"{_safe(body.name)}_{label}.vtu"
        if dim == 3:  # a 3D body's points and vectors as they are
            points, displacement = body.points.T, u
        else:  # z = 0
            points = np.column_stack([body.points.T, np.zeros(body.npoints)])
            displacement = np.column_stack([u, np.zeros(len(u))])
        m = meshio.Mesh(points=points, cells=[(cell_type, conn)],
                        point_data={"displacement": displacement})
        meshio.write(Path(out) / name, m, file_format="vtu")
        files[body.name] = name
    return files


def contact_label(summary: dict) -> str:
    """The contact method and variant a run used, for figure titles: "contact: vfem, paired
    variant" or "contact: lagrange" (a classical method has no variant). Read from
    ``summary.json``: ``contact_settings`` (written with the figures), else the input file's
    ``config.contact``, else the example's ``parameters`` (the defaults where none says)."""
    for source in (summary.get("contact_settings"),
                   (summary.get("config") or {}).get("contact"), summary.get("parameters")):
        if isinstance(source, dict) and ("variant" in source or "method" in source):
            break
    else:
        source = {}
    method = source.get("method", "vfem")
    variant = source.get("variant", summary.get("variant", "paired"))
    return f"contact: vfem, {variant} variant" if method == "vfem" else f"contact: {method}"


def contact_settings(model) -> dict:
    """``summary.json``'s ``contact_settings``: the contact ``method`` and ``variant`` of
    ``model`` and, with friction (``contact.frictional``), ``friction``: the law that ran and
    its coefficients (:func:`friction_law`: ``law`` and ``mu``, or ``mu_static`` and
    ``mu_dynamic``, ...) where every pair of bodies ran the same one, else ``law`` ``"per
    pair"``; then ``pairs``, each pair of bodies that may touch with its own law."""
    out = {"variant": model.contact.variant, "method": model.contact.method}
    if model.contact.frictional:
        pairs = [friction_law(model.contact.pair_friction(a, b))
                 for a, b in model.pairs().names(model.bodies)]
        laws = [{k: v for k, v in p.items() if k != "bodies"} for p in pairs]
        common = laws[0] if laws and all(law == laws[0] for law in laws) else {"law": "per pair"}
        out["friction"] = {**common, "pairs": pairs}
    return out


def friction_law(pair) -> dict:
    """One pair's friction (:class:`vfem.contact.settings.PairFriction`) as data: ``bodies``,
    then what its law records of itself (:func:`vfem.contact.laws.law_record`: ``law`` and its
    coefficients by name — ``coulomb``: ``mu``; ``static_dynamic``: ``mu_static`` (a sticking
    node starts to slip) and ``mu_dynamic`` (a slipping one); ``elastoplastic``: ``mu`` and
    ``slip_stiffness``; ``frictionless`` where the pair has no friction)."""
    return {"bodies": list(pair.bodies), **law_record(contact_friction_law(pair))}


def friction_laws_text(settings: dict | None) -> str:
    """The friction laws of ``contact_settings`` (:func:`contact_settings`) in words, for the
    closing screen and the figures: "upper/lower: Coulomb, mu = 0.3" or "base/block: static
    mu = 0.3, dynamic mu = 0.2" (pairs joined by "; "); "" without friction."""
    friction = (settings or {}).get("friction") or {}
    return "; ".join(f"{'/'.join(p.get('bodies') or ())}: {law_text(p)}"
                     for p in friction.get("pairs") or ())


#: set by :func:`defer`: runs write their results and leave the figures to ``vfem plot``
_deferred = False


def defer(on: bool = True) -> None:
    """Make every later run in this process leave its figures undrawn (``vfem run
    --no-figures``): the results, and what the figures need in ``summary.json``, are written as
    always, and ``vfem plot`` draws the same figures from the folder when asked. matplotlib's
    fixed costs (its import, text layout, PNG encoding: about a second for a few figures) then
    stay out of the run, which matters for batches of runs and for small models."""
    global _deferred
    _deferred = bool(on)


def draw_run(out: Path | str, summary: dict, figure_set: str, model=None) -> list[str]:
    """What a run does once its results are written: record in ``summary`` the ``figure_set``
    (a built-in example's name or ``"input"``) and ``model``'s contact method and variant
    (``contact_settings``, for the titles), write ``summary.json``, draw the figures from the
    folder (:func:`plot_results`, as ``vfem plot`` does) and record their names, relative to
    ``out``, as ``figures``. Returns those names.

    Without matplotlib nothing is drawn: ``figures`` is empty and ``figures_not_drawn`` says
    why and how to get it (:func:`vfem.io.plots.matplotlib_missing`; ``vfem run`` prints it);
    everything else is written, so ``vfem plot`` draws the figures once it is installed. The
    same when the figures are deferred (:func:`defer`, ``vfem run --no-figures``)."""
    out = Path(out)
    summary["figure_set"] = figure_set
    if model is not None:
        summary["contact_settings"] = contact_settings(model)
    summary.pop("figures_not_drawn", None)
    summary.pop("figures_notes", None)
    missing = (f"--no-figures (vfem plot {out} draws them)" if _deferred
               else plots.matplotlib_missing())
    if missing is not None:
        log.info("figures not drawn: %s", missing)
        summary["figures"] = []
        summary["figures_not_drawn"] = missing
        write_summary(out, summary)
        return []
    write_summary(out, summary)
    notes: list[str] = []
    try:
        summary["figures"] = [p.relative_to(out).as_posix() for p in plot_results(out, notes)]
    finally:
        forget_vtus()  # the run's last step was drawn from memory; a redraw reads the files
    if notes:  # what was not drawn, and why ("<figure>: <why>"; vfem run prints them)
        summary["figures_notes"] = notes
    write_summary(out, summary)
    return summary["figures"]


#: the built-in examples whose figure sets a results folder may name, and the loader of their
#: modules (each with ``figures(folder)``, or without, drawing none): handed in by
#: :mod:`vfem_examples` when it is imported (:func:`register_examples`; the ``vfem`` command
#: imports it), since the examples are a package beside the library, which never imports them
#: (issue 38); none until then
_examples: tuple[tuple[str, ...], Callable[[str], object]] = ((), lambda name: None)


def register_examples(names: Iterable[str], load: Callable[[str], object]) -> None:
    """Make the built-in examples ``names`` (their modules by ``load(name)``) the figure sets
    that :func:`plot_results` draws for the folders their runs wrote."""
    global _examples
    _examples = (tuple(names), load)


def plot_results(directory: Path | str, notes: list[str] | None = None) -> list[Path]:
    """Draw a results folder's figures from its files; return the paths written.

    Which figures: ``summary.json``'s ``figure_set``, the built-in example whose run wrote the
    folder (its module's ``figures(folder)``) or ``"input"`` (an input file's run); without one
    (results written before figure sets were recorded) the generic figures of an input-file run
    (none for the examples that draw none, springs and patch):
    ``deformed.png`` (and maybe ``deformed_overall.png``), ``contact_pressure.png``,
    ``history.png`` and ``von_mises.png``; the same for an example's run that did not finish,
    whose own figures need its finished run's evaluation (:func:`unfinished_example` says
    so). A run draws its figures by calling this after writing its files, so ``vfem plot``
    redraws the same figures from the same data.

    ``notes``, when given, gets what was not drawn and why, "<figure>: <why>" each (a 3D
    model's body with no node in contact has no pressure map, :mod:`vfem.io.figures3d`).

    Raises :class:`~vfem.errors.InputError` naming the path when the directory, its
    ``results.pvd`` or a VTU file it lists is missing or unreadable, and naming the fix when
    matplotlib is not installed (:func:`vfem.io.plots.require_matplotlib`).
    """
    EXAMPLES, load = _examples

    plots.require_matplotlib()
    folder = Folder(directory)
    name = folder.summary.get("figure_set")
    example = folder.summary.get("example")
    if name is None and example in EXAMPLES and not hasattr(load(example), "figures"):
        name = example  # an example that draws no figure (springs, patch: no results files)
    if name is None and (why := unfinished_example(folder.directory)):
        log.info("%s", why)  # vfem plot says so (cli.cmd_plot)
    if name not in (None, "input"):
        if name not in EXAMPLES:
            known = ", ".join(EXAMPLES) or "none loaded: import vfem_examples first"
            raise InputError(f"{folder.directory}/summary.json: figure_set {name!r} is not a "
                             f"built-in example ({known}) nor 'input'")
        draw = getattr(load(name), "figures", None)
        written = draw(folder) if draw is not None else []
    else:
        written = generic(folder)
    for p in written:
        log.info("wrote %s", p)
    if notes is not None:
        notes.extend(folder.notes)
    return written


def unfinished_example(directory: Path | str) -> str | None:
    """Why ``vfem plot`` draws the generic figures of a folder that a built-in example's run
    wrote: the run did not finish (interrupted, or still running: ``summary.json`` is the
    summary of the steps so far, :func:`vfem.io.results.progress_summary`), and the example's
    own figures are drawn from its finished run's evaluation (Hertz's theory, the shear
    profiles, the reactions over the slide), which its ``summary.json`` does not hold yet. One
    line: which example, how far it came, why, and how to finish it; None where the folder's
    figures are its own (a finished run, an input file's run, not a results folder)."""
    EXAMPLES, load = _examples
    from .folders import read_record

    directory = Path(directory)
    if not directory.is_dir():
        return None
    try:
        summary = read_summary(directory)
    except InputError:
        return None
    if summary.get("figure_set") is not None or "example" in summary:
        return None  # the run finished: its summary says whose figures
    run = read_record(directory) or summary.get("run") or {}
    name = run.get("target")
    if name not in EXAMPLES or getattr(load(name), "figures", None) is None:
        return None
    done = len(summary.get("steps") or []) or len(list(directory.glob("checkpoint/step*.npz")))
    sets = "".join(f" --set {shlex.quote(str(a))}" for a in run.get("settings") or ())
    return (f"{directory}: an unfinished run of the {name} example ({done} step"
            f"{'' if done == 1 else 's'} done: interrupted, or still running); its own figures "
            "need the finished run's evaluation, so the generic figures of the steps done are "
            f"drawn instead; to finish it: vfem run {name}{sets} --resume "
            f"{shlex.quote(str(directory))}")


def generic(folder: Folder) -> list[Path]:
    """The figures of an input file's run (see :func:`plot_results`). A 3D model's are
    :mod:`vfem.io.figures3d`'s (pressure and stick/slip maps per contact surface, the deformed
    outlines, von Mises on the surfaces), with ``history.png``; what they leave undrawn, and
    why, goes to ``folder.notes``."""
    steps = folder.steps
    label = contact_label(folder.summary)
    if any(b.dim == 3 for b in steps[-1].bodies):
        written = figures3d.figures(folder, steps, label, magnification_for(steps),
                                    folder.notes)
        written.append(_history(folder.directory, steps, folder.summary or None))
        for note in folder.notes:
            log.info("not drawn: %s", note)
        return written
    written = _deformed(folder.directory, steps, folder.contact, label)
    written.append(_pressure(folder.directory, steps, folder.contact, folder.contact_source,
                             label))
    written.append(_history(folder.directory, steps, folder.summary or None))
    if "contact_shear" in steps[-1].bodies[0].point_data:  # a run with friction
        written.append(_friction(folder.directory, steps[-1], label, folder.summary))
    # the most stressed step (a load that is held and then removed ends unloaded)
    peak = max(steps, key=lambda s: max(float(_cell_field(b, "von_mises").max(initial=0.0))
                                        for b in s.bodies))
    scale = magnification_for(steps)
    written.append(von_mises(folder, peak, "von_mises.png",
                             f"von Mises stress, step {peak.step} (load factor "
                             f"{peak.load_factor:.6g}), the most stressed\n{label}",
                             magnification=scale))
    return written


def von_mises(folder: Folder, step: Step, name: str, title: str,
              window: tuple[float, float, float, float] | None = None,
              magnification: float = 1.0) -> Path:
    """``name``: ``step``'s deformed bodies filled by the VTU's element ``von_mises`` field."""
    bodies = []
    for b in step.bodies:
        vm = _cell_field(b, "von_mises")
        bodies.append((b.name, b.points, b.polygons, b.displacement, vm))
    path = folder.directory / name
    plots.von_mises(path, bodies, title, magnification, window)
    return path


def _cell_field(frame: BodyFrame, name: str) -> np.ndarray:
    if name not in frame.cell_data:
        raise InputError(f"{frame.path}: no {name!r} cell field")
    return np.asarray(frame.cell_data[name], dtype=float)


def plane_section(frame: BodyFrame, axis: int, at: float, cell_field: str | None = None
                  ) -> tuple:
    """A 3D body's faces that lie in the plane ``x[axis] = at`` (a symmetry plane of its
    model), for drawing as a 2D mesh: (points (n, 2), faces (m, k), displacement (n, 2)), the
    two other coordinates in order (y = 0: x and z). Linear cells (tetrahedra, hexahedra).
    With ``cell_field``, a fourth: that cell field of the VTU at each face's cell (m,)."""
    cells = np.asarray(frame.polygons)
    faces = figures3d.CELL_FACES.get(cells.shape[1])  # VTK's faces of the linear cells
    keep = [a for a in range(3) if a != axis]
    if faces is None or not len(cells):
        empty = np.zeros((0, 2)), np.zeros((0, 3), dtype=int), np.zeros((0, 2))
        return empty if cell_field is None else (*empty, np.zeros(0))
    x = frame.points
    tol = 1e-9 * max(float(np.ptp(x, axis=0).max()), 1e-300)
    on = np.abs(x[:, axis] - at) <= tol
    found, owner = [], []
    for face in faces:
        f = cells[:, face]
        inside = on[f].all(axis=1)
        found.append(f[inside])
        owner.append(np.flatnonzero(inside))
    chosen = np.sort(np.unique(np.sort(np.vstack(found), axis=1), axis=0,
                               return_index=True)[1])
    f = np.vstack(found)[chosen]
    out = x[:, keep], f, frame.displacement[:, keep]
    if cell_field is None:
        return out
    return *out, _cell_field(frame, cell_field)[np.concatenate(owner)[chosen]]


def magnification_for(steps: list[Step]) -> float:
    """A magnification that makes the largest displacement of ``steps`` about 5 % of the
    model's size (1, 2 or 5 times a power of ten; 1 where it already is, or more): small
    deformations stay visible, large ones are drawn true to scale."""
    size = max((float(np.ptp(b.points, axis=0).max()) for s in steps for b in s.bodies),
               default=0.0)
    largest = max((float(np.linalg.norm(b.displacement, axis=1).max(initial=0.0))
                   for s in steps for b in s.bodies), default=0.0)
    if not (size > 0 and largest > 0) or largest >= 0.05 * size:
        return 1.0
    wanted = 0.05 * size / largest
    power = 10.0 ** np.floor(np.log10(wanted))
    return float(max(m * power for m in (1, 2, 5) if m * power <= wanted))


def _deformed(directory: Path, steps: list[Step], contact, method: str) -> list[Path]:
    last = steps[-1]
    scale = magnification_for(steps)
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
        plots.configurations(path, [(label, bodies)], f"Deformed configuration, contact zone\n"
                             f"{method}", window, magnification=scale)
        out.append(path)
        if window[0] > lo[0] or window[1] < hi[0] or window[2] > lo[1] or window[3] < hi[1]:
            whole = directory / "deformed_overall.png"
            plots.configurations(whole, [(label, bodies)], f"Deformed configuration\n{method}",
                                 magnification=scale)
            out.append(whole)
    else:
        plots.configurations(path, [(label, bodies)], "Deformed configuration, no node in "
                             f"contact\n{method}", magnification=scale)
        out.append(path)
    return out


#: The most steps the generic pressure figure draws (more would not be told apart).
MAX_PROFILES = 6


def _pressure(directory: Path, steps: list[Step], contact, source: str, method: str) -> Path:
    # every step up to MAX_PROFILES; beyond, that many spread evenly, the title says so
    last = len(steps) - 1
    shown = sorted({int(round(k)) for k in np.linspace(0, last, min(len(steps), MAX_PROFILES))})
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
        path, profiles, "Contact pressure at the nodes in contact"
        + ("" if len(shown) == len(steps) else f", {len(shown)} of {len(steps)} steps")
        + f"\n(nominal: normal force / undeformed length; from {source})\n{method}",
        xlabel=f"{'xy'[axis]}, undeformed ({plots.LENGTH})",
        ylabel=f"nominal contact pressure ({plots.LENGTH})")
    return path


def _friction(directory: Path, step: Step, method: str, summary: dict | None = None) -> Path:
    """``friction.png``: at ``step``, the tangential traction (its size, signed by its x
    component) against x at the nodes that carry a pair's compatibility and touch, per body,
    sticking and slipping nodes marked apart (the VTU's ``contact_shear`` and
    ``friction_status``), between the Coulomb limit ±mu q, q the normal traction there (the
    VTU's ``contact_traction``; mu of the body's pairs, :func:`body_friction_limits`): a
    slipping node lies on its line, a sticking one within."""
    bodies, limits = {}, {}
    for b in step.bodies:
        status = np.asarray(b.point_data["friction_status"]).ravel()
        on = status > 0
        shear = np.asarray(b.point_data["contact_shear"])[on, :2]
        signed = np.hypot(shear[:, 0], shear[:, 1]) * np.where(shear[:, 0] < 0, -1.0, 1.0)
        bodies[b.name] = (b.points[on, 0], signed, status[on])
        coefficients = body_friction_limits(summary or {}, b.name)
        if coefficients and "contact_traction" in b.point_data:
            normal = np.asarray(b.point_data["contact_traction"], dtype=float).ravel()[on]
            limits[b.name] = (normal, coefficients)
    path = directory / "friction.png"
    plots.friction_profiles(path, bodies,
                            f"Tangential traction at the nodes in contact, step {step.step} "
                            f"(load factor {step.load_factor:.6g})\n{method}", limits)
    return path


def body_friction_limits(summary: dict, body: str) -> list[tuple[str, float]]:
    """The bounds of the tangential traction over the normal one at ``body``'s nodes, each
    (what it is, its coefficient), from the laws of the pairs ``body`` belongs to
    (``contact_settings.friction.pairs``, :func:`contact_settings`; for a folder written
    before those were recorded, its input file's ``config.contact``): Coulomb's (and the
    elasto-plastic law's) mu, where a node slips; the static/dynamic law's mu_s, which a
    sticking node reaches before it slips, and mu_d, which a slipping node carries. [] when
    none is known or the body has no friction."""
    pairs = ((summary.get("contact_settings") or {}).get("friction") or {}).get("pairs")
    if pairs is None:  # older results: the input file's keys
        contact = (summary.get("config") or {}).get("contact") or {}
        own = [p for p in contact.get("pairs") or () if body in (p.get("bodies") or ())]
        pairs = [{"law": p.get("law", "coulomb"), "mu": p.get("friction", 0.0),
                  "mu_dynamic": p.get("friction", 0.0),
                  "mu_static": p.get("static_friction") or p.get("friction", 0.0)}
                 for p in own] or [{"law": "coulomb", "mu": contact.get("friction", 0.0)}]
    else:
        pairs = [p for p in pairs if body in (p.get("bodies") or ())]
    out: list[tuple[str, float]] = []
    for p in pairs:
        out += [x for x in law_bounds(p) if x[1] > 0 and x not in out]
    return out


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
                    f = np.asarray(b.point_data["contact_force"], dtype=float)[:, :b.dim]
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

