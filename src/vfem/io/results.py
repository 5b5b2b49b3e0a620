"""Results on disk: a VTU file per body and converged step, a PVD index, contact.csv,
reactions.csv, summary.json.

ParaView opens ``results.pvd`` as a time series (time = load factor) holding every body; each entry
gives the load factor (``timestep``), the body's index in the model (``part``), its name (``name``)
and the VTU file (``file``). Point fields: ``displacement`` (3 components, z = 0, so ParaView's
*Warp By Vector* works), ``contact_force`` (nodal force applied by the other bodies),
``contact_pressure`` (nominal: normal contact force per undeformed tributary length, the
traction averaged with the node's shape function), ``contact_traction`` (the formulation's
nominal traction at the node: in the paired variant its unknowns q on the compatibility side,
read at the other side's nodes; elsewhere as ``contact_pressure``), ``contact_status``
(1 in contact, 0 free), ``penetration`` (> 0 overlapping), ``reaction`` (3 components, z = 0:
the nodal force the supports, prescribed displacements and platen apply to the body, zero on
unconstrained dofs; :attr:`vfem.bodies.results.BodyStepResult.reaction`); with friction also
``contact_shear`` (3 components, z = 0: the tangential traction), ``slip_increment``,
``accumulated_slip`` and ``friction_status`` (0 free, 1 stick, 2 slip, -1 on nodes that carry
no pair's compatibility; :mod:`vfem.contact.formulations.friction`). Cell fields:
``stress_xx``, ``stress_yy``, ``stress_xy``, ``stress_zz``, ``von_mises`` (element averages).
Quadratic elements are written as VTK's 6-node triangles and 9-node quadrilaterals, with the
fields at every node.

A 3D body (tetrahedra, hexahedra: :attr:`vfem.bodies.Body.dim` 3) is written with its own
coordinates and its vectors' three components (nothing padded), as VTK's ``tetra`` and
``hexahedron`` cells, quadratic ones as ``tetra10`` and ``hexahedron27``
(:meth:`vfem.bodies.Body.cells`: every cell's VTK volume positive), and the six stresses
``stress_xx``, ``stress_yy``, ``stress_zz``, ``stress_yz``, ``stress_xz``, ``stress_xy`` with
``von_mises``. Its CSV files gain the z columns: ``contact.csv`` ``z`` after ``y``, ``uz`` after
``uy`` and ``shear_z`` after ``shear_y`` (:func:`contact_columns`), ``reactions.csv`` ``Rz``
(:func:`reaction_columns`); ``summary.json``'s forces have three components. A 2D model's files
are as they were.

``contact.csv`` (when the writer is given the contact surfaces, as :func:`run_writing` does): one
row per converged step, body and contact candidate node, columns ``step, load_factor, body, node,
x, y, ux, uy, pressure, gap, status``: ``node`` the point number in the body (the VTU's point
index), ``x, y`` its undeformed coordinates, ``ux, uy`` its displacement, ``pressure`` the
nominal contact pressure (as ``contact_pressure``), ``gap`` = -``penetration`` (negative:
overlapping; 0 where the contact algorithm measured none, e.g. the coarse side of a paired
contact), ``status`` ``contact`` (in contact: ``contact_status`` 1), ``carrying`` (not in contact
itself, its own gap open, yet carrying contact force: the opposing surface's equilibrium
correction put it there through a virtual element, as at the nodes beside a stiff punch's corner;
:func:`carrying`), or ``free``; with friction then ``shear_x, shear_y, slip_increment,
accumulated_slip, friction`` (``stick``, ``slip``, ``free``, or empty on nodes that carry no
pair's compatibility). Numbers are written with 17 significant digits (round-trip exact).

``reactions.csv``: one row per converged step, body and boundary carrying a support, a prescribed
displacement or a platen, columns ``step, load_factor, body, boundary, Rx, Ry``: the total force
that boundary's conditions apply to the body, summed over the dofs they constrain (a corner dof
two boundaries constrain counts in both rows); then a row ``(total)`` per body and step, the
body's total, which counts each constrained dof once (as ``summary.json``'s ``total``) and so is
the sum of the boundaries' rows only where they share no dof. Sign: the force *on the body*,
so with the contact force and the applied loads it sums to zero; a platen pushing a body down
gives a negative ``Ry``, equal to the platen's force at the step (``Platen.force_at``). Same 17
digits as ``contact.csv``.

Files are written as each step converges, into a temporary name first and then renamed, so an
analysis that fails or is killed later never damages what was already written; with them come
the step's checkpoint (:mod:`vfem.io.checkpoint`, for ``--resume``) and a ``summary.json`` of the
steps so far (``"status": "running"``), which the example's or input file's own summary replaces
at the end.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import logging
import time
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from ..bodies.stresses import stress as body_stress
from ..contact.geometry import ContactSurface
from ..errors import InputError
from ..result_types import BodyStepResult, phase_table
from ..solver import Analysis, AnalysisResult, Model, StepResult
from .files import (  # noqa: F401 (write_summary: importers)
    _atomic_write,
    _safe,
    forget_vtus,
    remember_vtu,
    vtu_compression,
    write_summary,
)

log = logging.getLogger(__name__)

# vfem.bodies.stresses.stress keys -> the VTU's cell field names (3D: also the shears yz, xz)
_CELL_FIELD = {"sxx": "stress_xx", "syy": "stress_yy", "sxy": "stress_xy", "szz": "stress_zz",
               "syz": "stress_yz", "sxz": "stress_xz"}
#: contact.csv's columns of a 2D model (:func:`contact_columns`: a 3D one's add z and uz)
CONTACT_COLUMNS = ("step", "load_factor", "body", "node", "x", "y", "ux", "uy", "pressure",
                   "gap", "status")
#: contact.csv's further columns under friction (``contact.friction`` > 0), 2D (3D: shear_z)
FRICTION_COLUMNS = ("shear_x", "shear_y", "slip_increment", "accumulated_slip", "friction")
#: contact.csv's ``friction`` column: BodyStepResult.friction_status by name (empty where -1:
#: a node that carries no pair's compatibility)
FRICTION_STATUS = ("free", "stick", "slip")
#: reactions.csv's columns of a 2D model (:func:`reaction_columns`: a 3D one's add Rz)
REACTION_COLUMNS = ("step", "load_factor", "body", "boundary", "Rx", "Ry")


def contact_columns(dim: int = 2, friction: bool = False) -> tuple[str, ...]:
    """contact.csv's columns for a model of dimension ``dim``: :data:`CONTACT_COLUMNS` in 2D;
    in 3D ``z`` after ``y`` and ``uz`` after ``uy``; then, with ``friction``,
    :data:`FRICTION_COLUMNS` (3D: ``shear_z`` after ``shear_y``)."""
    if dim == 2:
        return CONTACT_COLUMNS + (FRICTION_COLUMNS if friction else ())
    axes = "xyz"[:dim]
    out = (*CONTACT_COLUMNS[:4], *axes, *(f"u{a}" for a in axes), *CONTACT_COLUMNS[8:])
    if friction:
        out += (*(f"shear_{a}" for a in axes), *FRICTION_COLUMNS[2:])
    return out


def reaction_columns(dim: int = 2) -> tuple[str, ...]:
    """reactions.csv's columns for a model of dimension ``dim``: :data:`REACTION_COLUMNS` in
    2D, with ``Rz`` in 3D."""
    return REACTION_COLUMNS[:4] + tuple(f"R{a}" for a in "xyz"[:dim])


def _padded(v: np.ndarray) -> np.ndarray:
    """A 2D body's (n, 2) vectors with z = 0 appended (VTK's points and vectors have 3)."""
    v = np.asarray(v)
    return np.column_stack([v, np.zeros(len(v))])


def _vector(v: np.ndarray) -> np.ndarray:
    """A 3D body's (n, 3) vectors, as they are."""
    return np.asarray(v)


#: A pressure below this fraction of the body's largest is round-off, not a force carried
CARRYING = 1e-12


def carrying(r: BodyStepResult, nodes: np.ndarray) -> np.ndarray:
    """Which of ``nodes`` carry contact force though not in contact themselves
    (``contact_status`` 0): a compressive nominal pressure above round-off of the body's
    largest (:data:`CARRYING`; a tensile one is no contact force carried). Their own gap is
    open, and the force is the opposing surface's, which its equilibrium correction placed on
    them through a virtual element (the block's nodes beside a stiff punch's corner carry its
    corner's force). They read ``carrying`` in ``contact.csv``, not ``free`` (issue 39)."""
    pressure = r.contact_pressure[nodes]
    largest = float(np.abs(r.contact_pressure).max(initial=0.0))
    return (pressure > CARRYING * largest) & (r.contact_status[nodes] == 0)


def contact_csv_status(r: BodyStepResult, nodes: np.ndarray) -> list[str]:
    """``contact.csv``'s status of each of ``nodes``: ``contact``, ``carrying`` or ``free``."""
    words = np.where(r.contact_status[nodes] > 0, "contact",
                     np.where(carrying(r, nodes), "carrying", "free"))
    return words.tolist()


class ResultsWriter:
    """Writes the VTU/PVD series step by step into ``out`` (created if needed).

    ``surfaces``: the analysis's contact surfaces (``Analysis.surfaces``, one per body); when
    given, every step also rewrites ``contact.csv`` with the rows of all steps so far. Every
    step rewrites ``reactions.csv`` with the rows of all steps so far.
    """

    def __init__(self, out: Path, model: Model, surfaces: list[ContactSurface] | None = None):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.model = model
        self.entries: list[tuple[float, str, str]] = []  # (time, body, file)
        self.surfaces: dict[str, ContactSurface] | None = None
        if surfaces is not None:
            self.surfaces = {s.body.name: s for s in surfaces}
            missing = [b.name for b in model.bodies if b.name not in self.surfaces]
            if missing:
                raise InputError(f"model {model.name!r}: no contact surface given for body "
                                 f"{', '.join(map(repr, missing))}")
        self.contact_rows: list[list[str]] = []
        self.reaction_rows: list[list[str]] = []
        #: contact.csv's columns: the friction's too when the model has friction
        self.friction = model.contact.frictional
        #: the model's dimension (every body's, :meth:`Model.validate`): the CSV files' columns
        self.dim = model.bodies[0].dim if model.bodies else 2

    def restore(self, steps: list[StepResult]) -> None:
        """Take up the series of an earlier run whose ``steps`` are already on disk (their
        VTU files are kept; the PVD, contact.csv and reactions.csv are rebuilt from them)."""
        for step in steps:
            for body in self.model.bodies:
                self.entries.append((step.load_factor, body.name, self._vtu_name(body, step)))
            if self.surfaces is not None:
                self.add_contact_rows(step)
            self.add_reaction_rows(step)

    @staticmethod
    def _vtu_name(body, step: StepResult) -> str:
        return f"{_safe(body.name)}_step{step.step:04d}.vtu"

    def write_step(self, step: StepResult) -> None:
        for k, body in enumerate(self.model.bodies):
            r = step.bodies[body.name]
            reaction = r.reaction if r.reaction is not None else np.zeros_like(r.contact_force)
            cell_type, conn = body.cells()
            npts = body.npoints
            if npts < 2**31:  # 32-bit connectivity, as VTK's own: 8 % less to compress at 1M
                conn = np.asarray(conn, dtype=np.int32)
            pad = _vector if body.dim == 3 else _padded  # 2D: z = 0 appended
            stress = body_stress(body, r.displacement.ravel())
            name = self._vtu_name(body, step)
            m = meshio.Mesh(
                points=pad(body.points.T),
                cells=[(cell_type, conn)],
                point_data={"displacement": pad(r.displacement),
                            "contact_force": pad(r.contact_force),
                            "contact_pressure": r.contact_pressure,
                            "contact_traction": r.contact_traction,
                            "contact_status": r.contact_status.astype(np.int32),
                            "penetration": r.penetration,
                            "reaction": pad(reaction)},
                cell_data={_CELL_FIELD.get(k, k): [v] for k, v in stress.items()},
            )
            if body.subdomains > 1:  # the split body's partition (issue 43)
                from ..bodies.subdomains import body_partition

                m.cell_data["subdomain"] = [body_partition(body).astype(np.int32)]
            # friction's fields (vfem.contact.formulations.friction)
            if r.contact_shear is not None:
                m.point_data.update({
                    "contact_shear": pad(r.contact_shear),
                    "slip_increment": r.slip_increment,
                    "accumulated_slip": r.accumulated_slip,
                    "friction_status": np.asarray(r.friction_status, dtype=np.int32)})
            with vtu_compression():
                _atomic_write(self.out / name,
                              lambda p, m=m: meshio.write(p, m, file_format="vtu"))
            remember_vtu(self.out / name, m, new_step=k == 0)  # for the run's own figures
            self.entries.append((step.load_factor, body.name, name))
        self.write_pvd()
        if self.surfaces is not None:
            self.add_contact_rows(step)
            self.write_contact_csv()
        self.add_reaction_rows(step)
        self.write_reactions_csv()

    def add_contact_rows(self, step: StepResult) -> None:
        """Keep the rows of ``step``'s contact candidate nodes for ``contact.csv``."""
        for body in self.model.bodies:
            s = self.surfaces[body.name]
            r = step.bodies[body.name]
            nodes = np.asarray(s.nodes[: s.nc], dtype=int)
            X = body.points[:, nodes].T
            u = r.displacement[nodes]
            gap = 0.0 - r.penetration[nodes]  # 0.0 - x: no "-0" for an unmeasured gap
            status = contact_csv_status(r, nodes)
            dim = body.dim
            for k, n in enumerate(nodes):
                self.contact_rows.append(
                    [str(step.step), _num(step.load_factor), body.name, str(int(n)),
                     *(_num(X[k, c]) for c in range(dim)), *(_num(u[k, c]) for c in range(dim)),
                     _num(r.contact_pressure[n]), _num(gap[k]), status[k]]
                    + (self._friction_row(r, n, dim) if self.friction else []))

    @staticmethod
    def _friction_row(r: BodyStepResult, n: int, dim: int = 2) -> list[str]:
        """A contact.csv row's friction columns (:data:`FRICTION_COLUMNS`, with shear_z in
        3D) for point ``n``."""
        if r.contact_shear is None:  # a step written without them (an older checkpoint)
            return [""] * (dim + 3)
        status = int(r.friction_status[n])
        return [*(_num(r.contact_shear[n, c]) for c in range(dim)),
                _num(r.slip_increment[n]), _num(r.accumulated_slip[n]),
                FRICTION_STATUS[status] if status >= 0 else ""]

    def add_reaction_rows(self, step: StepResult) -> None:
        """Keep the rows of ``step``'s per-boundary support reactions for ``reactions.csv``."""
        for body in self.model.bodies:
            r = step.bodies[body.name]
            for boundary, components in r.reactions.items():
                self.reaction_rows.append([str(step.step), _num(step.load_factor), body.name,
                                           boundary, *map(_num, components)])
            if r.reactions:  # the body's total: each constrained dof once
                # as summary.json's total, to the last digit
                self.reaction_rows.append([str(step.step), _num(step.load_factor), body.name,
                                           TOTAL_ROW, *map(_num, total(r.reaction))])

    def write_contact_csv(self) -> None:
        _write_csv(self.out / "contact.csv", contact_columns(self.dim, self.friction),
                   self.contact_rows)

    def write_reactions_csv(self) -> None:
        _write_csv(self.out / "reactions.csv", reaction_columns(self.dim), self.reaction_rows)

    def write_pvd(self) -> None:
        lines = ['<?xml version="1.0"?>',
                 '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
                 "  <Collection>"]
        parts = {b.name: i for i, b in enumerate(self.model.bodies)}
        for t, body, f in self.entries:
            lines.append(f'    <DataSet timestep="{t:.17g}" group="" part="{parts[body]}" '
                         f"name={quoteattr(body)} file={quoteattr(f)}/>")
        lines += ["  </Collection>", "</VTKFile>", ""]
        _atomic_write(self.out / "results.pvd",
                      lambda p: p.write_text("\n".join(lines), encoding="utf-8"))


def _write_csv(path: Path, columns: tuple[str, ...], rows: list[list[str]]) -> None:
    """``columns`` then ``rows``, written atomically (a reader never sees half a file)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    w.writerows(rows)
    _atomic_write(path, lambda p: p.write_text(buf.getvalue(), encoding="utf-8"))


class BackgroundOutput:
    """One thread that writes each converged step's files (VTU, PVD, CSV, checkpoint, progress
    summary), in the order the steps converge, while the analysis goes on with the next step
    (issue 19, item 5: writing was a third of a large run; zlib releases the interpreter while
    it compresses, the factorizations and back-substitutions while they run). A writing error
    is raised at the next step or at :meth:`finish`, which waits for every file: a run that
    stops, for any reason, leaves each step it completed written whole."""

    def __init__(self):
        from concurrent.futures import ThreadPoolExecutor

        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="vfem-output")
        self._pending: list = []

    def submit(self, job) -> None:
        """Queue ``job()`` after those already queued (raising an earlier job's error)."""
        still = []
        for f in self._pending:
            if f.done():
                f.result()
            else:
                still.append(f)
        self._pending = still + [self._pool.submit(job)]

    def finish(self) -> float:
        """Wait for every queued job (raising the first error); the seconds waited."""
        t0 = time.perf_counter()
        try:
            for f in self._pending:
                f.result()
        finally:
            self._pending = []
            self._pool.shutdown(wait=True)
        return time.perf_counter() - t0


def run_writing(model: Model, out: Path | None, on_step=None, resume: bool = False,
                backend: str | None = None) -> tuple[Analysis, AnalysisResult]:
    """Solve ``model``, writing into ``out`` (nothing when None) as each step converges: its
    VTU files, the PVD, contact.csv and reactions.csv, its checkpoint
    (:mod:`vfem.io.checkpoint`) and a ``summary.json`` of the steps done so far; then call
    ``on_step``. A run stopped at any moment leaves every completed step readable.

    ``resume``: continue from the last checkpoint in ``out`` (written by an earlier run of the
    same model) instead of from the start; the steps already there are kept as they are.
    ``backend``: the linear-algebra backend (:mod:`vfem.linalg`; None: the chosen one).
    """
    from . import checkpoint

    analysis = Analysis(model, backend)
    analysis.setup()
    writer = ResultsWriter(out, model, analysis.surfaces) if out is not None else None
    start = None
    if writer is not None:
        model_fingerprint = checkpoint.fingerprint(model)
        model_description = checkpoint.describe(model)
        if resume:
            start = checkpoint.read(out, model)
            if start is not None:
                writer.restore(start.steps)
                log.info("resuming %s after step %d (load factor %.6g)", out,
                         len(start.steps), start.state.load_factor)
        else:
            checkpoint.clear(out)

    background = BackgroundOutput() if writer is not None else None

    def step_done(step: StepResult) -> None:
        if writer is not None:
            # what the files hold is taken now (the checkpoint and the steps are copies); the
            # writing overlaps the next step
            saved, steps = analysis.checkpoint(), list(analysis.steps)

            def job() -> None:
                writer.write_step(step)
                checkpoint.write(out, model, saved, model_fingerprint, model_description)
                write_summary(out, progress_summary(model, steps, "running"))

            background.submit(job)
        if on_step is not None:
            on_step(step)

    step_done.iteration = getattr(on_step, "iteration", None)  # see Analysis.run
    try:
        result = analysis.run(step_done, start=start)
    finally:
        waited = background.finish() if background is not None else 0.0
    # the output phase: the time the run waited for its files (the rest overlapped the steps)
    for key in ("output_s", "total_s"):
        result.timings[key] = result.timings.get(key, 0.0) + waited
    if writer is not None:
        write_summary(out, progress_summary(model, result.steps,
                                            "complete" if result.converged else "stopped",
                                            result.message))
    return analysis, result


def run_example(model: Model, out: Path, summarize, draw=None, on_step=None,
                resume: bool = False) -> dict:
    """What a built-in example's ``run`` does: solve ``model`` writing each step into ``out``
    (:func:`run_writing`), ``summarize(result)`` into its summary and write ``summary.json``;
    then, if ``draw`` is given, its figures: ``draw(model, result, summary)`` adds to the
    summary (and to ``out``) what the example's figures need beyond the results files (True:
    nothing), and
    :func:`vfem.io.replot.draw_run` draws them from the folder, as ``vfem plot`` redraws them
    (figure set: the summary's ``example``)."""
    out = Path(out)
    _, result = run_writing(model, out, on_step, resume)
    summary = summarize(result)
    summary.setdefault("timings", result.timings)
    write_summary(out, summary)
    if draw:  # a function, or True: the figures need nothing beyond the files
        from .replot import draw_run

        t0 = time.perf_counter()
        if callable(draw):
            draw(model, result, summary)
        draw_run(out, summary, summary["example"], model)
        summary["timings"]["figures_s"] = time.perf_counter() - t0
    forget_vtus()
    finish_summary(out, summary)
    return summary


def mpi_ranks() -> dict:
    """``{"mpi_ranks": N}`` for a run over N > 1 MPI ranks (vfem.parallel); nothing for a
    serial run (its summary as before)."""
    from ..parallel import current

    size = current().size
    return {"mpi_ranks": size} if size > 1 else {}


def subdomain_summary(model: Model) -> dict:
    """``{"subdomains": {body: sizes}}`` for the bodies split into subdomains (issue 43): the
    count, each subdomain's elements and dofs, the interface's and the coarse problem's dofs
    (:func:`vfem.bodies.subdomains.split_solve`), and the PCG iterations of its solves (the
    most, and how many solves: where this rank solved the body); nothing when no body is
    split (a summary as before)."""
    out = {}
    for body in model.bodies:
        if body.subdomains > 1 and hasattr(body, "subdomain_sizes"):
            factor = getattr(body, "factor", None)
            factor = getattr(factor, "factor", factor)  # over MPI ranks: the owner's own
            its = getattr(factor, "iterations", None)
            out[body.name] = {**body.subdomain_sizes, **({
                "pcg_iterations_max": int(max(its)), "pcg_solves": len(its)} if its else {})}
    return {"subdomains": out} if out else {}


def finish_summary(out: Path, summary: dict) -> None:
    """Add the phase table of the run (:func:`vfem.result_types.phase_table`: seconds per
    phase, from its ``timings``) to ``summary``, log it (``vfem -v``) and write
    ``summary.json``."""
    summary["phases"] = phase_table(summary.get("timings", {}))
    total = sum(summary["phases"].values()) or 1.0
    log.info("phases of the run:\n%s", "\n".join(
        f"  {label:40s} {s:9.3f} s  {100 * s / total:5.1f} %"
        for label, s in summary["phases"].items()))
    write_summary(out, summary)


def progress_summary(model: Model, steps: list[StepResult], status: str, message: str = ""
                     ) -> dict:
    """The ``summary.json`` of an analysis while it runs (and after, until the example or input
    file's own summary replaces it): valid JSON describing the steps done so far."""
    return {"model": model.name, "status": status,
            "converged": {"running": None, "complete": True, "stopped": False}[status],
            "message": message or f"{len(steps)} steps done so far",
            "steps": [step_record(s) for s in steps]}


def step_record(step: StepResult) -> dict:
    """The fields every example's ``summary.json`` gives per step; ``invariants``: the
    independent checks of the converged state
    (:meth:`vfem.contact.invariants.measures.Invariants.record`; empty when the step was not
    checked); the forces on each body (:func:`force_record`)."""
    last = step.history[-1] if step.history else None
    return {"step": step.step, "load_factor": step.load_factor, "iterations": step.iterations,
            "converged": step.converged, "cuts": step.cuts,
            "stopped_at_fixed_point": step.fixed_point,
            "max_penetration": last.max_penetration if last else 0.0,
            "max_equilibrium_error": last.max_equilibrium_error if last else 0.0,
            "invariants": step.invariants, **force_record(step),
            **({"compatibility_switched": step.compatibility_switched}
               if step.compatibility_switched else {}),
            **({"yielded_points": step.yielded} if step.yielded else {})}


def frictional_work(steps: list[StepResult]) -> list[float]:
    """Per step, the work the friction took from the bodies: minus the sum, over every node of
    every body, of the step's final tangential contact force (``friction_force``, the part of
    the contact force the tangential traction makes) times the node's displacement in the step
    (from the step before; from zero for the first). Over a closed loop of loading it is the
    loop's area (the Cattaneo model's shear cycle, ``tests/test_friction.py``). The normal
    forces are left out: where a contact grows (a press), their end-of-step force times the
    closing of the gaps it made is the step's discretisation, not dissipation (it read as much
    "frictional work" at mu = 1e-3 as at 0.3). 0 for a step without friction's fields."""
    out, before = [], {}
    for step in steps:
        work = 0.0
        for name, r in step.bodies.items():
            if r.friction_force is not None:
                du = r.displacement - before.get(name, 0.0)
                work -= float(np.einsum("ij,ij->", r.friction_force, du))
        out.append(work)
        before = {name: r.displacement for name, r in step.bodies.items()}
    return out


def external_work(result: AnalysisResult) -> list[float]:
    """Per step, the work done on the bodies from outside them: the supports, prescribed
    displacements and platen (each body's nodal ``reaction``) and the applied loads (its
    tractions at the step's load factor), times each node's displacement in the step, by the
    trapezoidal rule (the mean of the forces at the step's start and end: exact for a force
    linear in the displacement over the step). The measure against which the frictional work
    is told from round-off (:func:`vfem.io.runner.dissipated`). A body whose reactions were
    not computed (a step read back from an older checkpoint) counts its applied loads only."""
    bodies = {b.name: b for b in result.model.bodies}
    out: list[float] = []
    before: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for step in result.steps:
        work = 0.0
        for name, r in step.bodies.items():
            u = np.asarray(r.displacement, dtype=float)
            force = bodies[name].applied_load(step.load_factor).reshape(u.shape)
            if r.reaction is not None:
                force = force + r.reaction
            u0, f0 = before.get(name, (np.zeros_like(u), np.zeros_like(u)))
            work += 0.5 * float(np.einsum("ij,ij->", force + f0, u - u0))
            before[name] = (u, force)
        out.append(work)
    return out


def total(force: np.ndarray) -> list[float]:
    """The resultant (x, y), or (x, y, z) in 3D, of nodal forces (n, 2 or 3), summed per
    component (the same digits wherever a total is reported)."""
    force = np.asarray(force, dtype=float)
    return [float(force[:, c].sum()) for c in range(force.shape[1])]


def imbalance(contact: list[float], reaction: list[float], applied: list[float],
              components: tuple[int, ...] | None = None) -> float:
    """``|contact + reaction + applied| / |contact|`` for a body's resultant forces (x, y), of
    ``components`` alone if given (a body of revolution's axial one): 0 when the body is in
    equilibrium. Without contact force, relative to the larger of the other two (0 when all
    three are zero)."""
    c, r, a = (np.asarray(v, dtype=float) for v in (contact, reaction, applied))
    scale = float(np.linalg.norm(c)) or max(float(np.linalg.norm(r)), float(np.linalg.norm(a)))
    if components is not None:  # (the scale: every component, the forces the body carries)
        c, r, a = (v[list(components)] for v in (c, r, a))
    return float(np.linalg.norm(c + r + a)) / scale if scale > 0 else 0.0


#: The ``boundary`` of a body's total in ``reactions.csv``.
TOTAL_ROW = "(total)"


def force_record(step: StepResult) -> dict:
    """Per body of a converged step: ``contact_force`` (x, y) the resultant of the nodal
    contact forces; ``reactions``: ``{"total": [Rx, Ry], "boundaries": {name: [Rx, Ry]}}``,
    the force the supports,
    prescribed displacements and platen apply to the body (the total counts each constrained
    dof once, each boundary sums the dofs its own conditions constrain, see
    :attr:`vfem.bodies.results.BodyStepResult.reactions`); ``applied_load`` the resultant of its
    tractions at the step's load factor; ``reaction_imbalance``: :func:`imbalance` of the three,
    which balance (0 up to the solver's residual); ``resultant_components``, for the bodies
    whose sums of some components are no resultants (a body of revolution's radial forces
    cancel round the ring), the components that are (absent otherwise). The last three
    leave out a body whose
    reactions were not computed (a step read back from an older checkpoint)."""
    out: dict = {"contact_force": {name: total(r.contact_force)
                                   for name, r in step.bodies.items()},
                 "reactions": {}, "applied_load": {}, "reaction_imbalance": {}}
    for name, r in step.bodies.items():
        if r.reaction is None:
            continue
        contact, reaction = out["contact_force"][name], total(r.reaction)
        applied = [float(v) for v in (r.applied_load if r.applied_load is not None
                                      else np.zeros(len(reaction)))]
        out["reactions"][name] = {"total": reaction,
                                  "boundaries": {k: [float(v) for v in xy]
                                                 for k, xy in r.reactions.items()}}
        out["applied_load"][name] = applied
        out["reaction_imbalance"][name] = imbalance(contact, reaction, applied,
                                                    r.resultant_components)
        if r.resultant_components is not None:  # a body of revolution: its axial force alone
            out.setdefault("resultant_components", {})[name] = list(r.resultant_components)
    return out


def example_summary(name: str, result: AnalysisResult, parameters) -> dict:
    """The keys every example's ``summary.json`` starts with (its own evaluation follows): the
    contact settings that ran (:func:`vfem.io.replot.contact_settings`: with friction, its
    laws); with friction, per step the work it dissipated and ``frictional_work_total``
    (:func:`friction_summary`)."""
    from .replot import contact_settings

    out = {"example": name, "converged": result.converged, "message": result.message,
           "steps": [step_record(s) for s in result.steps],
           "dofs": int(sum(b.ndofs for b in result.model.bodies)),
           "parameters": dataclasses.asdict(parameters), "timings": result.timings,
           "linear_solver": result.backend, "contact_flexibility": result.flexibility,
           **mpi_ranks(), **subdomain_summary(result.model),
           "contact_settings": contact_settings(result.model)}
    out.update(friction_summary(result, out["steps"]))
    return out


def contact_sizes(result: AnalysisResult) -> dict:
    """Per body its nodes, dofs and contact candidate nodes (``bodies``), and the contact dofs
    of the model (``contact_dofs``): the sizes a 3D example's summary gives beside
    :func:`example_summary`'s."""
    return {"bodies": {s.body.name: {"nodes": int(s.body.npoints), "dofs": int(s.body.ndofs),
                                     "contact_candidate_nodes": int(s.nc)}
                       for s in result.surfaces},
            "contact_dofs": int(sum(s.dim * s.nc for s in result.surfaces))}


def solid_summary(name: str, result: AnalysisResult, parameters, key: str, evaluate) -> dict:
    """A 3D example's ``summary.json`` (sphere, press fit, circular punch):
    :func:`example_summary`, the bodies' sizes (:func:`contact_sizes`), the pressure measure and,
    when the last step is at full load, ``evaluate(result, parameters)`` under ``key``."""
    summary = example_summary(name, result, parameters)
    summary.update(contact_sizes(result), pressure_measure="nominal: nodal contact force / "
                   "undeformed tributary area")
    if result.steps and result.steps[-1].load_factor == 1.0:
        summary[key] = evaluate(result, parameters)
    return summary


def friction_summary(result: AnalysisResult, records: list[dict]) -> dict:
    """With friction (the model's ``contact.frictional``): each step's record (``records``,
    one per ``result.steps``) gets its ``frictional_work`` (:func:`frictional_work`) and its
    ``external_work`` (:func:`external_work`, the scale that tells the former from
    round-off), and the returned keys are ``frictional_work_total`` and
    ``external_work_total``; without friction nothing changes and the keys are none (a
    frictionless run's summary stays as it was)."""
    if not result.model.contact.frictional:
        return {}
    work = frictional_work(result.steps)
    outside = external_work(result)
    for record, w, e in zip(records, work, outside, strict=True):
        record["frictional_work"] = w
        record["external_work"] = e
    return {"frictional_work_total": float(sum(work)),
            "external_work_total": float(sum(outside))}


def _num(x: float) -> str:
    """A float in 17 significant digits (reads back exactly)."""
    return f"{float(x):.17g}"
