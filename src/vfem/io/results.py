"""Results on disk: one VTU file per body and converged step, a PVD index, summary.json.

ParaView opens ``results.pvd`` as a time series (time = load factor) holding every body. Point
fields: ``displacement`` (3 components, z = 0, so ParaView's *Warp By Vector* works),
``contact_force`` (nodal force applied by the other bodies), ``contact_pressure`` (nominal: normal
contact force per undeformed tributary length), ``contact_status`` (1 in contact, 0 free),
``penetration``. Cell fields: ``stress_xx``, ``stress_yy``, ``stress_xy``, ``stress_zz``,
``von_mises`` (element averages). Quadratic elements are written as VTK's 6-node triangles and
9-node quadrilaterals, with the fields at every node.

Files are written as each step converges, into a temporary name first and then renamed, so an
analysis that fails later never damages what was already written.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from ..solver import Analysis, AnalysisResult, Model, StepResult


def _atomic_write(path: Path, write) -> None:
    tmp = path.with_name(path.name + ".part")
    write(tmp)
    os.replace(tmp, path)


class ResultsWriter:
    """Writes the VTU/PVD series step by step into ``out`` (created if needed)."""

    def __init__(self, out: Path, model: Model):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.model = model
        self.entries: list[tuple[float, str, str]] = []  # (time, body, file)

    def write_step(self, step: StepResult) -> None:
        for body in self.model.bodies:
            r = step.bodies[body.name]
            cell_type, conn = body.cells()
            npts = body.npoints
            u = np.column_stack([r.displacement, np.zeros(len(r.displacement))])
            stress = body.stress(r.displacement.ravel())
            name = f"{_safe(body.name)}_step{step.step:04d}.vtu"
            m = meshio.Mesh(
                points=np.column_stack([body.points.T, np.zeros(npts)]),
                cells=[(cell_type, conn)],
                point_data={"displacement": u,
                            "contact_force": np.column_stack([r.contact_force,
                                                              np.zeros(npts)]),
                            "contact_pressure": r.contact_pressure,
                            "contact_status": r.contact_status.astype(np.int32),
                            "penetration": r.penetration},
                cell_data={f"stress_{k}" if k != "von_mises" else k: [v]
                           for k, v in stress.items()},
            )
            _atomic_write(self.out / name,
                          lambda p, m=m: meshio.write(p, m, file_format="vtu"))
            self.entries.append((step.load_factor, body.name, name))
        self.write_pvd()

    def write_pvd(self) -> None:
        lines = ['<?xml version="1.0"?>',
                 '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
                 "  <Collection>"]
        parts = {b.name: i for i, b in enumerate(self.model.bodies)}
        for t, body, f in self.entries:
            lines.append(f'    <DataSet timestep="{t:.10g}" group="" part="{parts[body]}" '
                         f"file={quoteattr(f)}/>")
        lines += ["  </Collection>", "</VTKFile>", ""]
        _atomic_write(self.out / "results.pvd",
                      lambda p: p.write_text("\n".join(lines), encoding="utf-8"))


def run_writing(model: Model, out: Path | None, on_step=None) -> tuple[Analysis, AnalysisResult]:
    """Solve ``model``, writing each converged step's VTU files (and the PVD) into ``out`` as
    it converges (nothing written when ``out`` is None), then calling ``on_step``."""
    analysis = Analysis(model)
    analysis.setup()
    writer = ResultsWriter(out, model) if out is not None else None

    def step_done(step: StepResult) -> None:
        if writer is not None:
            writer.write_step(step)
        if on_step is not None:
            on_step(step)

    return analysis, analysis.run(step_done)


def step_record(step: StepResult) -> dict:
    """The fields every example's ``summary.json`` gives per step."""
    last = step.history[-1] if step.history else None
    return {"step": step.step, "load_factor": step.load_factor, "iterations": step.iterations,
            "converged": step.converged, "cuts": step.cuts,
            "stopped_at_fixed_point": step.fixed_point,
            "max_penetration": last.max_penetration if last else 0.0,
            "max_equilibrium_error": last.max_equilibrium_error if last else 0.0}


def write_summary(out: Path, summary: dict) -> Path:
    Path(out).mkdir(parents=True, exist_ok=True)
    path = Path(out) / "summary.json"
    _atomic_write(path, lambda p: p.write_text(json.dumps(summary, indent=2) + "\n",
                                               encoding="utf-8"))
    return path


def _safe(name: str) -> str:
    """A file-name-safe version of a body name."""
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name) or "body"
