"""The same model in CalculiX: write a vfem model as a ``ccx`` input deck, run it, read it back.

For comparing vfem with a general-purpose code on the *same mesh* (docs/benchmarks.md, *Hertz in
CalculiX*):

* :func:`write_deck` writes a two-body, linear-element, small-kinematics :class:`~vfem.solver.Model`
  (the Hertz example's, or any like it) as a CalculiX deck: the same nodes and elements (3-node
  triangles as CPE3, 4-node quadrilaterals as CPE4; CPS3/CPS4 for plane stress), each counter-
  clockwise in the x-y plane as ccx requires, unit thickness; one linear elastic material per
  body; supports and prescribed displacements as ``*BOUNDARY``; a force-controlled platen as
  ``*EQUATION`` ties of its nodes' platen component to one reference node that carries the
  ``*CLOAD``; frictionless surface-to-surface penalty contact (``*CONTACT PAIR, TYPE=SURFACE TO
  SURFACE``) between the bodies' contact candidate facets, the softer body the slave.
* :func:`run` runs ``ccx`` in a temporary folder, times it, and reads the results: ccx's own
  nodal contact pressure on the slave surface (CPRESS of ``*CONTACT FILE, CSTR``: "raw"), the
  total contact force ccx reports, and the slave body's nodal contact forces recomputed as
  ``K u`` (its stiffness, the same elements as ccx's, times ccx's displacements) per undeformed
  tributary length, the reading :func:`vfem.examples.hertz.evaluate` makes of vfem's results.

The core never imports this module.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from skfem import Basis, ElementVector, MeshTri, asm
from skfem.models.elasticity import linear_elasticity

from ..contact.search import project_points
from ..errors import InputError, VfemError

if TYPE_CHECKING:
    from ..solver import Model

DOF = {"x": 1, "y": 2}


@dataclass
class BodyDeck:
    """Where one body's nodes and elements went in the deck (ccx numbers from 1)."""

    name: str
    node_offset: int  # ccx node = node_offset + point + 1
    element_offset: int  # ccx element = element_offset + element + 1
    element_type: str
    contact_facets: np.ndarray  # facet ids (into mesh.facets) in the body's contact surface
    flipped: int  # elements whose node order was reversed to make them counter-clockwise


@dataclass
class Deck:
    """A written CalculiX deck and what :func:`run` needs to read its results."""

    path: Path
    model: Model
    bodies: list[BodyDeck]
    slave: str
    master: str
    reference_node: int | None  # ccx node carrying the platen force (None: no platen)
    penalty: float | None
    tension: float
    approach: float | None  # the platen's displacement in the first, contact-making step
    steps: list[float] = field(default_factory=list)  # load factor at the end of each load step

    def body(self, name: str) -> BodyDeck:
        return next(b for b in self.bodies if b.name == name)


# -- writing -------------------------------------------------------------------------------------


def _check_supported(model) -> None:
    """Refuse what the deck writer cannot express (one message per kind of problem)."""
    model.validate()
    if len(model.bodies) != 2:
        raise InputError(f"CalculiX deck: the writer handles two bodies in contact, model "
                         f"{model.name!r} has {len(model.bodies)}")
    for b in model.bodies:
        if b.order != 1 or b.large:
            raise InputError(f"CalculiX deck: body {b.name!r} must have linear elements (order "
                             f"1) and small kinematics, got order {b.order} and kinematics "
                             f"{b.kinematics!r}")
        if b.tractions:
            raise InputError(f"CalculiX deck: body {b.name!r} has tractions, which the writer "
                             "does not translate")
        if any(pd.amplitude is not None for pd in b.prescribed):
            raise InputError(f"CalculiX deck: body {b.name!r} has a prescribed displacement "
                             "with an amplitude, which the writer does not translate")
        if b.platen is not None and b.platen.amplitude is not None:
            raise InputError(f"CalculiX deck: body {b.name!r} has a platen force with an "
                             "amplitude, which the writer does not translate")


def _counter_clockwise(mesh) -> tuple[np.ndarray, int]:
    """(nodes per element, nelements) connectivity with every element counter-clockwise (ccx
    expands plane elements into solids along +z and refuses a negative Jacobian)."""
    t = mesh.t.copy()
    x = mesh.p[:, t]
    area2 = ((x[0, 1] - x[0, 0]) * (x[1, 2] - x[1, 0])
             - (x[0, 2] - x[0, 0]) * (x[1, 1] - x[1, 0]))
    cw = area2 < 0
    order = [0, 2, 1] if t.shape[0] == 3 else [0, 3, 2, 1]
    t[:, cw] = t[order][:, cw]
    return t, int(cw.sum())


def _faces(mesh, t: np.ndarray, facets: np.ndarray) -> list[tuple[int, int]]:
    """(element, face label k) of each facet: ccx's edge Sk of a plane element joins its local
    nodes k and k + 1 (the last one to the first)."""
    out = []
    n = t.shape[0]
    for f in facets:
        e = int(mesh.f2t[0, f])
        ends = set(mesh.facets[:, f].tolist())
        for k in range(n):
            if {int(t[k, e]), int(t[(k + 1) % n, e])} == ends:
                out.append((e, k + 1))
                break
    return out


def _num(v: float) -> str:
    """A real as ccx reads it: at most 20 characters (it reads numbers with a 20-character
    format), full precision where that fits, else 14 significant digits."""
    text = repr(float(v))
    return text if len(text) <= 20 else f"{v:.13e}"


def _tag(name: str) -> str:
    """A name as a ccx set or surface name (upper case, word characters)."""
    return re.sub(r"\W", "_", name.upper())


def _lines(values, per_line: int = 8) -> list[str]:
    values = list(values)
    return [", ".join(str(v) for v in values[i:i + per_line])
            for i in range(0, len(values), per_line)]


def _initial_gap(s, m) -> float:
    """The smallest distance from a slave candidate node to the master's candidate facets."""
    pts = s.X[: s.nc]
    a, b = m.X[m.facets[:, 0]], m.X[m.facets[:, 1]]
    _, _, dist = project_points(pts, a, b)
    return float(dist.min()) if len(dist) else 0.0


def write_deck(model, path, *, slave: str | None = None, penalty: float | None = 1e11,
               tension: float = 0.0, steps: str = "one", approach: float | None = None,
               max_increments: int = 1000) -> Deck:
    """Write ``model`` as a CalculiX input deck at ``path`` (see the module docstring).

    Args:
        model: a two-body :class:`~vfem.solver.Model` with linear elements, small kinematics,
            supports, prescribed displacements (no amplitude) and at most one platen (no
            amplitude).
        path: the ``.inp`` file to write.
        slave: the slave body's name; default the one with the smaller Young's modulus.
        penalty: the contact stiffness (pressure per unit overclosure) of ccx's linear
            pressure-overclosure law; ``None``: ``PRESSURE-OVERCLOSURE=HARD`` (ccx chooses its
            own stiffness, which on the Hertz problem is far too soft: p_max 9 % low). The
            default, 1e11, gives the Hertz problem a penetration of 3e-7 at p0, 1.7e-4 of the
            cylinder's indentation (docs/benchmarks.md has the measured choice).
        tension: the linear law's second constant, sigma_inf (its tension at large
            clearances), which ccx says is "only relevant for node-to-surface contact" (it
            replaces 0 by a default of its own): surface-to-surface contact makes contact
            elements only where a slave integration point penetrates (measured: the same
            results with 0, 1 and 1.4e5).
        steps: ``"one"``: one ccx step to the last load factor, ccx's automatic increments
            starting with the first load factor (load factors that do not rise steadily get one
            step each); ``"model"``: one ccx step per model step.
        approach: with a platen, a first ccx step pushes the platen this far (towards its
            force) under displacement control, so that contact holds the body when force
            control starts (ccx starts with no contact elements, and a body that only contact
            holds is singular then); default the initial gap plus 1e-6 times the model's size.
        max_increments: ccx's limit on the increments of a step.
    """
    _check_supported(model)
    if steps not in ("one", "model"):
        raise InputError(f"CalculiX deck: steps must be 'one' or 'model', got {steps!r}")
    names = [b.name for b in model.bodies]
    if slave is None:
        slave = min(model.bodies, key=lambda b: b.material.youngs_modulus).name
    if slave not in names:
        raise InputError(f"CalculiX deck: no body named {slave!r} for the slave surface; the "
                         f"model has {', '.join(names)}")
    i_slave = names.index(slave)
    master = names[1 - i_slave]
    tags = {n: _tag(n) for n in names}
    _, surfaces = model.contact_surfaces()
    size = max(float(np.linalg.norm(np.ptp(b.mesh.p, axis=1))) for b in model.bodies)

    out = ["*HEADING", f"vfem model {model.name!r} written by vfem.tools.calculix"]
    decks: list[BodyDeck] = []
    node_off = elem_off = 0
    for b, s in zip(model.bodies, surfaces):
        mesh, tag = b.mesh, tags[b.name]
        t, flipped = _counter_clockwise(mesh)
        kind = (("CPE" if b.material.plane == "strain" else "CPS")
                + ("3" if isinstance(mesh, MeshTri) else "4"))
        out.append(f"** body {b.name}: nodes {node_off + 1}-{node_off + mesh.p.shape[1]}, "
                   f"elements {elem_off + 1}-{elem_off + t.shape[1]} ({kind})")
        out.append(f"*NODE, NSET=N_{tag}")
        out += [f"{node_off + i + 1}, {_num(x)}, {_num(y)}"
                for i, (x, y) in enumerate(mesh.p.T.tolist())]
        out.append(f"*ELEMENT, TYPE={kind}, ELSET=E_{tag}")
        out += [f"{elem_off + e + 1}, " + ", ".join(str(node_off + k + 1) for k in conn)
                for e, conn in enumerate(t.T.tolist())]
        held = {x.boundary for x in (*b.supports, *b.prescribed)}
        held |= {b.platen.boundary} if b.platen else set()
        for name in sorted(held):
            nodes = np.unique(mesh.facets[:, mesh.boundaries[name]]) + node_off + 1
            out.append(f"*NSET, NSET=B_{tag}_{_tag(name)}")
            out += _lines(nodes.tolist())
        out.append(f"*SURFACE, NAME=S_{tag}, TYPE=ELEMENT")
        out += [f"{elem_off + e + 1}, S{k}" for e, k in _faces(mesh, t, s.facet_ids)]
        out += [f"*MATERIAL, NAME=M_{tag}", "*ELASTIC",
                f"{_num(b.material.youngs_modulus)}, {_num(b.material.poissons_ratio)}",
                f"*SOLID SECTION, ELSET=E_{tag}, MATERIAL=M_{tag}", "1."]
        decks.append(BodyDeck(b.name, node_off, elem_off, kind, np.asarray(s.facet_ids),
                              flipped))
        node_off += mesh.p.shape[1]
        elem_off += t.shape[1]

    supports = [f"B_{tags[b.name]}_{_tag(sup.boundary)}, {DOF[c]}, {DOF[c]}"
                for b in model.bodies for sup in b.supports for c in sup.components]
    out += ["*BOUNDARY", *supports]

    def prescribed(factor: float) -> list[str]:
        return [f"B_{tags[b.name]}_{_tag(pd.boundary)}, {DOF[pd.component]}, "
                f"{DOF[pd.component]}, {_num(factor * pd.value)}"
                for b in model.bodies for pd in b.prescribed]

    ref = None
    platen_body = next((b for b in model.bodies if b.platen is not None), None)
    if platen_body is not None:
        pl = platen_body.platen
        dof = DOF[pl.component]
        offset = decks[names.index(platen_body.name)].node_offset
        nodes = np.unique(platen_body.mesh.facets[:, platen_body.mesh.boundaries[pl.boundary]])
        nodes = nodes + offset + 1
        ref = int(nodes[0])
        out.append(f"** the platen: the {pl.component} displacement of every node of "
                   f"{platen_body.name}'s {pl.boundary!r} equals that of node {ref}")
        out.append("*EQUATION")
        for n in nodes[1:].tolist():
            out += ["2", f"{n}, {dof}, 1., {ref}, {dof}, -1."]

    out += ["*SURFACE INTERACTION, NAME=CONTACT"]
    if penalty is None:
        out += ["*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD"]
    else:
        out += ["*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
                f"{_num(penalty)}, {_num(tension)}"]
    out += ["*CONTACT PAIR, INTERACTION=CONTACT, TYPE=SURFACE TO SURFACE",
            f"S_{tags[slave]}, S_{tags[master]}"]

    if ref is not None:
        if approach is None:
            gap = _initial_gap(surfaces[i_slave], surfaces[1 - i_slave])
            approach = max(gap, 0.0) + 1e-6 * size
        towards = float(np.sign(pl.force)) or 1.0
        out += ["** step 1: the platen pushed under displacement control until contact holds "
                "the body", "*STEP, INC=100", "*STATIC", "1., 1., 1e-5, 1.", "*BOUNDARY",
                f"{ref}, {dof}, {dof}, {_num(towards * approach)}", "*END STEP"]
    factors = [float(f) for f in model.load_factors]
    rising = all(np.diff(np.r_[0.0, factors]) > 0)
    if steps == "one" and rising:
        plan = [(factors[0], factors[-1])]
    else:
        plan = [(f, f) for f in factors]
    output = [f"*NODE PRINT, NSET=N_{tags[slave]}", "U", f"*NODE PRINT, NSET=N_{tags[master]}",
              "U", f"*CONTACT PRINT, SLAVE=S_{tags[slave]}, MASTER=S_{tags[master]}", "CF",
              "*CONTACT FILE", "CSTR"]
    previous = 0.0
    for first, factor in plan:
        span = abs(factor - previous)
        out += [f"*STEP, INC={max_increments}", "*STATIC",
                f"{_num(min(abs(first - previous), span))}, {_num(span)}, {_num(1e-5 * span)}, "
                f"{_num(span)}"]
        if ref is not None:
            # OP=NEW releases the platen's reference node: force control from here on
            out += ["*BOUNDARY, OP=NEW", *supports, *prescribed(factor),
                    "*CLOAD", f"{ref}, {dof}, {_num(factor * pl.force)}"]
        elif prescribed(factor):
            out += ["*BOUNDARY", *prescribed(factor)]
        out += [*output, "*END STEP"]
        previous = factor
    path = Path(path)
    path.write_text("\n".join(out) + "\n", encoding="ascii")
    return Deck(path, model, decks, slave, master, ref, penalty, tension, approach,
                [f for _, f in plan])


# -- running and reading -------------------------------------------------------------------------


_FLOAT = r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?"


def _dat_blocks(text: str, title: str) -> list[np.ndarray]:
    """Every table of the ``.dat`` file whose heading starts with ``title``: rows of numbers."""
    blocks = []
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.strip().startswith(title):
            rows = []
            j = i + 1
            while j < len(lines) and not lines[j].strip():
                j += 1
            while j < len(lines) and lines[j].strip():
                rows.append([float(v) for v in lines[j].split()])
                j += 1
            blocks.append(np.array(rows))
    return blocks


def _contact_statistics(text: str) -> dict:
    """The last "statistics for slave set" block of the ``.dat`` file (``*CONTACT PRINT, CF``)."""
    start = text.rfind("statistics for slave set")
    if start < 0:
        return {}
    body = text[start:].splitlines()
    out = {}
    for i, line in enumerate(body):
        nums = None
        for j in range(i + 1, min(i + 4, len(body))):
            if body[j].strip():
                nums = [float(v) for v in re.findall(_FLOAT, body[j])]
                break
        if line.strip().startswith("total surface force"):
            out["force"] = nums[:3]
        elif line.strip().startswith("area,  normal force"):
            out["area"], out["normal_force"], out["shear_force"] = nums[:3]
            break
    return out


def _frd_contact_pressure(path: Path) -> dict[int, float]:
    """CPRESS per node of the last CONTACT block of the ``.frd`` file (``*CONTACT FILE, CSTR``).

    Fixed columns: ``-1``, the node in 10 characters, then 12 characters per value (COPEN,
    CSLIP1, CSLIP2, CPRESS, CSHEAR1, CSHEAR2)."""
    lines = path.read_text(errors="replace").splitlines()
    start = max((i for i, line in enumerate(lines) if line.startswith(" -4  CONTACT")),
                default=-1)
    out: dict[int, float] = {}
    if start < 0:
        return out
    for line in lines[start + 1:]:
        if line.startswith(" -3"):
            break
        if line.startswith(" -1"):
            out[int(line[3:13])] = float(line[13 + 3 * 12: 13 + 4 * 12])
    return out


def _sta(text: str) -> list[dict]:
    """The increments of the ``.sta`` file: step, increment, attempts, iterations."""
    rows = []
    for line in text.splitlines():
        parts = line.split()
        if len(parts) >= 7 and parts[0].isdigit() and parts[1].isdigit():
            rows.append({"step": int(parts[0]), "increment": int(parts[1]),
                         "attempts": int(parts[2].rstrip("U")), "iterations": int(parts[3])})
    return rows


def _stiffness(body):
    """The body's stiffness on its points (dof 2k: x of point k), the elements ccx's are."""
    basis = Basis(body.mesh, ElementVector(body.element()))
    lam, mu = body.material.lame()
    return asm(linear_elasticity(lam, mu), basis).tocsr()


def _constrained(body) -> np.ndarray:
    """Dofs held by supports, prescribed displacements and the platen (not contact's)."""
    dofs = []
    comps = [(s.boundary, c) for s in body.supports for c in s.components]
    comps += [(pd.boundary, pd.component) for pd in body.prescribed]
    if body.platen is not None:
        comps.append((body.platen.boundary, body.platen.component))
    for boundary, c in comps:
        nodes = np.unique(body.mesh.facets[:, body.mesh.boundaries[boundary]])
        dofs.append(2 * nodes + DOF[c] - 1)
    return np.unique(np.concatenate(dofs)) if dofs else np.zeros(0, dtype=int)


def nodal_reading(body, facets: np.ndarray, u: np.ndarray) -> dict:
    """The body's nodal contact forces ``K u`` on the nodes of ``facets`` and the nominal pressure.

    ``u``: (npoints, 2) displacements. On a contact node the only forces besides contact are the
    reactions of its constrained components, which are left out; the pressure is the size of
    what remains over the node's undeformed tributary length (half of each facet it ends), as
    :func:`vfem.examples.hertz.evaluate` reads vfem's. ``residual`` is the largest ``|K u|`` on a
    free dof off the contact surface (zero in exact arithmetic: the check that the elements and
    the displacements read back are ccx's), relative to the largest nodal contact force.
    """
    K = _stiffness(body)
    f = (K @ np.asarray(u, dtype=float).ravel()).reshape(-1, 2)
    held = np.zeros(2 * body.npoints, dtype=bool)
    held[_constrained(body)] = True
    held = held.reshape(-1, 2)
    ends = body.mesh.facets[:, facets]
    nodes = np.unique(ends)
    lengths = np.linalg.norm(np.diff(body.mesh.p[:, ends], axis=1)[:, 0], axis=0)
    tributary = np.zeros(body.npoints)
    np.add.at(tributary, ends[0], 0.5 * lengths)
    np.add.at(tributary, ends[1], 0.5 * lengths)
    force = np.where(held[nodes], 0.0, f[nodes])
    pressure = np.linalg.norm(force, axis=1) / tributary[nodes]
    off = np.ones(body.npoints, dtype=bool)
    off[nodes] = False
    free_off = np.where(held[off], 0.0, f[off])
    scale = float(np.abs(force).max()) or 1.0
    return {"nodes": nodes, "force": force, "pressure": pressure,
            "tributary": tributary[nodes], "total_force": force.sum(axis=0),
            "residual": float(np.abs(free_off).max(initial=0.0)) / scale}


def _solver(log: str) -> str:
    m = re.search(r"Factoring the system of equations using the (.+?) solver", log)
    return m.group(1).strip() if m else "unknown"


def run(deck: Deck, ccx: str = "ccx", threads: int = 1, timeout: float = 600.0,
        p0: float | None = None, keep: str | Path | None = None) -> dict:
    """Run CalculiX on ``deck`` in a temporary folder and read its results.

    Args:
        deck: what :func:`write_deck` returned.
        ccx: the CalculiX executable.
        threads: ``OMP_NUM_THREADS`` and ccx's ``CCX_NPROC_*`` (stiffness, equation solver,
            results).
        timeout: seconds before ccx is stopped (a :class:`~vfem.errors.VfemError`).
        p0: a reference peak pressure (Hertz's p0): adds ``p_max_error_raw`` and
            ``p_max_error_nodal``.
        keep: a folder to copy ccx's files to (deck, log, .dat, .frd, .sta).

    Returns a dict: ``wall_s`` (the ccx process), ``ccx_total_s`` (ccx's own total),
    ``threads``, ``solver``, ``equations``, ``increments``/``iterations``/``cutbacks`` (the load
    steps; ``contact_step_iterations`` for the first, contact-making step), ``p_max_raw`` (ccx's
    CPRESS on the slave nodes), ``p_max_nodal`` (``K u`` per undeformed tributary length,
    :func:`nodal_reading`), ``p_max_master_nodal`` (the same reading on the master body),
    ``total_contact_force`` (ccx's, on the slave), ``total_contact_force_nodal``,
    ``nodal_residual``, ccx's own ``final_residual_force`` against its ``final_average_force``
    (its last iteration) and per-node arrays under ``slave``.
    """
    exe = shutil.which(ccx)
    if exe is None:
        raise VfemError(f"CalculiX executable {ccx!r} not found on the PATH; install it (Debian: "
                        "apt install calculix-ccx) or pass its path")
    model = deck.model
    env = dict(os.environ)
    for key in ("OMP_NUM_THREADS", "CCX_NPROC_STIFFNESS", "CCX_NPROC_EQUATION_SOLVER",
                "CCX_NPROC_RESULTS"):
        env[key] = str(int(threads))
    with tempfile.TemporaryDirectory(prefix="vfem-ccx-") as tmp:
        work = Path(tmp)
        shutil.copyfile(deck.path, work / "job.inp")
        t0 = time.perf_counter()
        try:
            proc = subprocess.run([exe, "-i", "job"], cwd=work, env=env, capture_output=True,
                                  text=True, timeout=timeout)
        except subprocess.TimeoutExpired as exc:
            raise VfemError(f"CalculiX did not finish within {timeout:g} s on {deck.path}") \
                from exc
        wall = time.perf_counter() - t0
        log = (proc.stdout or "") + (proc.stderr or "")
        if keep is not None:
            keep = Path(keep)
            keep.mkdir(parents=True, exist_ok=True)
            (keep / "ccx.log").write_text(log)
            for f in work.iterdir():
                if f.suffix in (".inp", ".dat", ".frd", ".sta", ".cvg"):
                    shutil.copyfile(f, keep / f.name)
        if proc.returncode != 0 or "*ERROR" in log or "Job finished" not in log:
            tail = "\n".join(line for line in log.splitlines() if line.strip())[-2000:]
            raise VfemError(f"CalculiX failed on {deck.path} (exit status {proc.returncode}); "
                            f"the end of its output:\n{tail}")
        dat = (work / "job.dat").read_text(errors="replace")
        sta = _sta((work / "job.sta").read_text(errors="replace"))
        cpress = _frd_contact_pressure(work / "job.frd")

    total = re.search(r"Total CalculiX Time:\s*(" + _FLOAT + ")", log)
    residual = re.findall(r"largest residual force=\s*(" + _FLOAT + ")", log)
    average = re.findall(r"average force=\s*(" + _FLOAT + ")", log)
    eqs = re.findall(r"number of equations\s*\n\s*(\d+)", log)
    load_steps = [r for r in sta if r["step"] > (1 if deck.reference_node else 0)]
    first = [r for r in sta if deck.reference_node and r["step"] == 1]
    readings = {}
    for name in (deck.slave, deck.master):
        body = next(b for b in model.bodies if b.name == name)
        bd = deck.body(name)
        blocks = _dat_blocks(dat, f"displacements (vx,vy,vz) for set N_{name.upper()}")
        if not blocks:
            raise VfemError(f"CalculiX results: no displacements of body {name!r} in the .dat "
                            "file")
        rows = blocks[-1]
        u = np.zeros((body.npoints, 2))
        u[rows[:, 0].astype(int) - bd.node_offset - 1] = rows[:, 1:3]
        readings[name] = nodal_reading(body, bd.contact_facets, u)
    s = readings[deck.slave]
    bd = deck.body(deck.slave)
    raw = np.array([cpress.get(int(n) + bd.node_offset + 1, 0.0) for n in s["nodes"]])
    stats = _contact_statistics(dat)
    body = next(b for b in model.bodies if b.name == deck.slave)
    out = {
        "wall_s": wall,
        "ccx_total_s": float(total.group(1)) if total else float("nan"),
        "threads": int(threads),
        "cpus_reported": sorted({int(n) for n in re.findall(r"Using up to (\d+) cpu", log)}),
        "solver": _solver(log),
        "equations": int(eqs[-1]) if eqs else 0,
        "dofs": int(sum(2 * b.mesh.p.shape[1] for b in model.bodies)),
        "increments": len(load_steps),
        "iterations": int(sum(r["iterations"] for r in load_steps)),
        "cutbacks": int(sum(r["attempts"] - 1 for r in load_steps)),
        "contact_step_iterations": int(sum(r["iterations"] for r in first)),
        "final_residual_force": float(residual[-1]) if residual else float("nan"),
        "final_average_force": float(average[-1]) if average else float("nan"),
        "penalty": deck.penalty,
        "p_max_raw": float(raw.max()),
        "p_max_nodal": float(s["pressure"].max()),
        "p_max_master_nodal": float(readings[deck.master]["pressure"].max()),
        "total_contact_force": stats.get("force", [float("nan")] * 3)[:2],
        "contact_normal_force": abs(stats.get("normal_force", float("nan"))),
        "total_contact_force_nodal": [float(v) for v in s["total_force"]],
        "nodal_residual": s["residual"],
        "slave": {"x": body.mesh.p[:, s["nodes"]].T, "pressure_raw": raw,
                  "pressure_nodal": s["pressure"], "force": s["force"]},
    }
    if p0:
        out["p0"] = p0
        out["p_max_error_raw"] = out["p_max_raw"] / p0 - 1.0
        out["p_max_error_nodal"] = out["p_max_nodal"] / p0 - 1.0
        out["p_max_master_error_nodal"] = out["p_max_master_nodal"] / p0 - 1.0
    return out
