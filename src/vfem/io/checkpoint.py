"""Checkpoints: each converged step saved so that an interrupted run can be continued.

After every converged step the results directory gets ``checkpoint/stepNNNN.npz``, written to a
temporary name and renamed (so a file there is always whole). It holds the step's results (the
fields its VTU files were written from, its iteration history) and the complete state after it:
contact forces and traction values, platen, load factor, the state of each large-kinematics body
and the step control (:class:`vfem.solver.Checkpoint`). ``vfem run ... --resume DIR`` reads them
back — NumPy arrays and one JSON text, never pickles — and continues from the last one, to the
same answer as a run that was never interrupted.

A fingerprint of the model (meshes, materials, boundary conditions, contact settings, load
schedule) is stored in every file; resuming a different model is refused. With it goes the
same model setting by setting (:func:`describe`), so the refusal names the settings that
differ, each as stored and as now.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import zipfile
from pathlib import Path

import numpy as np

from ..contact.state import (
    STATE_TYPES,
    BaselineState,
    ContactState,
    IterationRecord,
    TractionState,
)
from ..errors import InputError
from ..solver import BodyStepResult, Checkpoint, Model, StepResult

FOLDER = "checkpoint"
#: the array fields of a body's step results (the per-boundary reaction totals, a dict, go into
#: the JSON text)
_FIELDS = [f.name for f in dataclasses.fields(BodyStepResult)
           if f.name not in ("reactions", "resultant_components")]


def fingerprint(model: Model) -> str:
    """A hash of everything that defines the model's answer (not its name or output)."""
    h = hashlib.sha256()
    h.update(repr((model.load_factors, model.contact, model.contact_pairs)).encode())
    for b in model.bodies:
        h.update(repr((b.name, type(b.mesh).__name__, b.material, b.supports, b.prescribed,
                       b.tractions, b.platen, b.contact_boundaries, b.order, b.kinematics,
                       b.law)).encode())
        if b.dim == 3:  # a default support (every component) apart from an explicit ("x", "y")
            h.update(repr([b.support_components(s) for s in b.supports]).encode())
        if b.self_contact:  # (only where set: the checkpoints of before it still resume)
            h.update(b"self_contact")
        for a in (b.mesh.p, b.mesh.t):
            h.update(np.ascontiguousarray(a).tobytes())
        for name in sorted(b.mesh.boundaries or {}):
            h.update(name.encode() + np.asarray(b.mesh.boundaries[name]).tobytes())
    return h.hexdigest()


#: The most characters of a setting's value a refusal quotes (a long load schedule is cut).
_VALUE_CHARS = 60
#: The most differing settings a refusal names (then how many more).
_NAMED = 4


def describe(model: Model) -> dict[str, str]:
    """What :func:`fingerprint` covers, setting by setting, each value in words: keys as the
    input file names them where it does (``contact.friction``,
    ``bodies.<name>.material.youngs_modulus``, ``bodies.<name>.supports[0].components``,
    ``steps.load_factors``), a body's mesh by its size and a hash of its nodes, elements and
    boundaries. Stored beside the fingerprint, so a resume of another model names what
    differs (:func:`differences`)."""
    out: dict[str, str] = {"steps.load_factors": _text(model.load_factors),
                           "contact_pairs": _text(model.contact_pairs),
                           "bodies": _text([b.name for b in model.bodies])}
    _flatten("contact", model.contact, out)
    for b in model.bodies:
        key = f"bodies.{b.name}"
        h = hashlib.sha256()
        for a in (b.mesh.p, b.mesh.t):
            h.update(np.ascontiguousarray(a).tobytes())
        for name in sorted(b.mesh.boundaries or {}):
            h.update(name.encode() + np.asarray(b.mesh.boundaries[name]).tobytes())
        out[f"{key}.mesh"] = (f"{b.mesh.p.shape[1]} nodes and {b.mesh.t.shape[1]} elements "
                              f"(hash {h.hexdigest()[:8]})")
        for name in ("material", "supports", "prescribed", "tractions", "platen",
                     "contact_boundaries", "order", "kinematics", "law"):
            _flatten(f"{key}.{name}", getattr(b, name), out)
        if b.self_contact:
            out[f"{key}.self_contact"] = "true"
        if b.dim == 3:  # the components a 3D support fixes: by default x, y and z
            for i, sup in enumerate(b.supports):
                out[f"{key}.supports[{i}].components"] = _text(b.support_components(sup))
    return out


def _flatten(key: str, value, out: dict[str, str]) -> None:
    """``value`` under ``key`` in ``out``: a dataclass field by field, a sequence of them item
    by item (``key[0]``, with its length), anything else as text."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            _flatten(f"{key}.{f.name}", getattr(value, f.name), out)
    elif isinstance(value, (tuple, list)) and value and all(
            dataclasses.is_dataclass(v) and not isinstance(v, type) for v in value):
        out[f"{key} (count)"] = str(len(value))
        for i, v in enumerate(value):
            _flatten(f"{key}[{i}]", v, out)
    else:
        out[key] = _text(value)


def _text(value) -> str:
    """A setting's value as a short text (numbers as Python writes them, arrays as lists)."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, (np.floating, np.integer)):
        value = value.item()
    elif isinstance(value, (tuple, list)):
        value = [v.item() if isinstance(v, (np.floating, np.integer)) else v for v in value]
    return repr(value)


def differences(stored: dict[str, str], now: dict[str, str]) -> str:
    """The settings that differ between two :func:`describe` texts, in words:
    "contact.friction: stored 0.3, now 0.2; ..." (at most :data:`_NAMED`, then how many more;
    the meshes last, which often differ only because a setting they are made from does);
    "" when none."""
    keys = [k for k in dict.fromkeys([*stored, *now]) if stored.get(k) != now.get(k)]
    keys.sort(key=lambda k: k.endswith(".mesh"))  # stable: otherwise in the model's order

    def value(text: str | None) -> str:
        if text is None:
            return "(none)"
        return text if len(text) <= _VALUE_CHARS else text[:_VALUE_CHARS - 3] + "..."

    named = [f"{k}: stored {value(stored.get(k))}, now {value(now.get(k))}"
             for k in keys[:_NAMED]]
    if len(keys) > _NAMED:
        named.append(f"and {len(keys) - _NAMED} more")
    return "; ".join(named)


def write(out: Path, model: Model, checkpoint: Checkpoint, model_fingerprint: str,
          description: dict[str, str] | None = None) -> Path:
    """Save the last step of ``checkpoint`` (its results and the state after it);
    ``model_fingerprint``: :func:`fingerprint` of ``model``, and ``description``, its
    :func:`describe` (None: made here), computed once per run."""
    step = checkpoint.steps[-1]
    state = checkpoint.state
    arrays: dict[str, np.ndarray] = {}
    for i, b in enumerate(model.bodies):
        r = step.bodies[b.name]
        for f in _FIELDS:
            if getattr(r, f) is not None:
                arrays[f"field_{i}_{f}"] = getattr(r, f)
        for key, value in checkpoint.bodies.get(b.name, {}).items():
            arrays[f"body_{i}_{key}"] = np.asarray(value)
    for i, (F, rel) in enumerate(zip(state.forces, state.released)):
        arrays[f"force_{i}"], arrays[f"released_{i}"] = F, rel
    for name, value in state.unknowns().items():  # the formulation's own unknowns
        arrays[f"unknown_{name}"] = value
    meta = {
        "fingerprint": model_fingerprint,
        "model": describe(model) if description is None else description,
        "step": {"step": step.step, "load_factor": step.load_factor,
                 "iterations": step.iterations, "converged": step.converged,
                 "platen_displacement": step.platen_displacement, "cuts": step.cuts,
                 "fixed_point": step.fixed_point, "invariants": step.invariants,
                 "compatibility_switched": step.compatibility_switched,
                 "yielded": step.yielded,
                 "history": [dataclasses.asdict(h) for h in step.history]},
        "reactions": {b.name: {k: list(v) for k, v in step.bodies[b.name].reactions.items()}
                      for b in model.bodies},
        "state": {"load_factor": state.load_factor,
                  "platen_displacement": state.platen_displacement,
                  "platen_force": state.platen_force,
                  "type": type(state).__name__, "unknowns": sorted(state.unknowns()),
                  "tangential": "columns"},
        "bodies": {b.name: sorted(checkpoint.bodies.get(b.name, {})) for b in model.bodies},
        "control": {"target": checkpoint.target, "level": checkpoint.level,
                    "easy": checkpoint.easy,
                    "sides": [[int(v) for v in row] for row in checkpoint.sides]},
    }
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    folder = Path(out) / FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"step{step.step:04d}.npz"
    tmp = folder / f"step{step.step:04d}.part.npz"
    np.savez(tmp, **arrays)
    os.replace(tmp, path)
    return path


def read(out: Path, model: Model) -> Checkpoint | None:
    """The checkpoint of the last complete step in ``out`` (None if there is none), with the
    results of every step before it. Raises :class:`InputError` when the files were written by
    another model or cannot be read."""
    folder = Path(out) / FOLDER
    files = sorted(folder.glob("step[0-9][0-9][0-9][0-9].npz")) if folder.is_dir() else []
    if not files:
        return None
    expected = fingerprint(model)
    steps: list[StepResult] = []
    for n, path in enumerate(files, start=1):
        if path.name != f"step{n:04d}.npz":
            raise InputError(f"{path}: checkpoint of step {n} missing before it; cannot resume "
                             f"from {out}")
        try:
            with np.load(path, allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files}
            meta = json.loads(arrays.pop("meta").tobytes().decode())
        except (OSError, ValueError, KeyError, zipfile.BadZipFile) as exc:
            raise InputError(f"{path}: not a readable vfem checkpoint ({exc})") from None
        if meta.get("fingerprint") != expected:
            # which settings differ, where the checkpoint recorded them (written since
            # 2026-11-27); else what may differ
            what = (differences(meta["model"], describe(model)) if isinstance(
                meta.get("model"), dict) else "")
            raise InputError(f"{out}: its results were written by a different model ("
                             + (what or "meshes, materials, loads or settings differ")
                             + "); give the same model and options as the run that wrote "
                             "them, or run afresh without --resume")
        steps.append(_step(meta["step"], arrays, model, meta.get("reactions", {})))
    state = _state(meta["state"], arrays, model)
    bodies = {b.name: {key: arrays[f"body_{i}_{key}"] for key in meta["bodies"][b.name]}
              for i, b in enumerate(model.bodies)}
    return Checkpoint(steps, state, bodies, **meta["control"])


def _state(meta: dict, arrays: dict[str, np.ndarray], model: Model) -> ContactState:
    """The contact state of a checkpoint, of the type its formulation keeps
    (:data:`~vfem.contact.state.STATE_TYPES`). A checkpoint written before the states were
    typed (2026-11-25) kept the formulation's unknowns as numbered "multipliers": a baseline's
    pressures and active set (0, 1), the paired variant's traction values per pair."""
    n = len(model.bodies)
    base = ContactState(meta["load_factor"], meta["platen_displacement"],
                        [arrays[f"force_{i}"] for i in range(n)],
                        [arrays[f"released_{i}"] for i in range(n)], meta["platen_force"])
    if "type" in meta:
        cls = STATE_TYPES.get(meta["type"], ContactState)
        unknowns = {k: arrays[f"unknown_{k}"] for k in meta["unknowns"]}
        if meta["type"] == "FrictionState" and meta.get("tangential") != "columns":
            unknowns = _tangential_columns(unknowns, model)
    else:
        old = {int(k): arrays[f"multiplier_{k}"] for k in meta.get("multipliers", [])}
        if model.contact.method != "vfem":
            cls, unknowns = BaselineState, {"pressures": old.get(0, np.zeros(0)),
                                            "active": old.get(1, np.zeros(0)) > 0}
        elif old:
            cls, unknowns = TractionState, {f"traction_{k}": v for k, v in old.items()}
        else:
            cls, unknowns = ContactState, {}
    fields = {f.name: getattr(base, f.name) for f in dataclasses.fields(ContactState)}
    return cls(**fields).with_unknowns(unknowns)


def _tangential_columns(unknowns: dict[str, np.ndarray], model: Model) -> dict[str, np.ndarray]:
    """A frictional checkpoint written before the tangential arrays were (n, ntan) in any
    dimension (2026-11-30): a 2D model kept its tangential traction values (``shear_k``) and,
    under small kinematics, its anchors (``anchor_k``: relative tangential displacements) as
    (n,); they become one column. The large-kinematics anchors are material points of the other
    surface, not tangential arrays, and stay as they are."""
    small = not model.iterates
    out = dict(unknowns)
    for key, value in unknowns.items():
        if value.ndim == 1 and (key.startswith("shear_") or small and key.startswith("anchor_")):
            out[key] = value[:, None]
    return out


def _step(meta: dict, arrays: dict[str, np.ndarray], model: Model,
          reactions: dict[str, dict[str, list[float]]]) -> StepResult:
    step = StepResult(**{**meta, "history": [IterationRecord(**h) for h in meta["history"]]})
    step.bodies = {b.name: BodyStepResult(**{f: arrays[f"field_{i}_{f}"] for f in _FIELDS
                                                if f"field_{i}_{f}" in arrays},
                                          reactions={k: tuple(v) for k, v in
                                                     reactions.get(b.name, {}).items()},
                                          resultant_components=b.section.resultant)
                   for i, b in enumerate(model.bodies)}
    return step


def clear(out: Path) -> None:
    """Remove the checkpoints of an earlier run in ``out`` (a fresh run starts from step 1)."""
    folder = Path(out) / FOLDER
    if folder.is_dir():
        for path in folder.glob("step*.npz"):
            path.unlink()
