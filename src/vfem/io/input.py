"""Input files: TOML in, checked against the configuration classes, TOML out.

``load(path)`` reads an input file into a :class:`~vfem.config.ModelConfig`. Every key is checked
against the dataclass that owns it (its name, its type, finiteness): the first problem found is
raised as one :class:`~vfem.errors.InputError` that names the file, where in it (``bodies[1]
(flat).material``) and the key, with the closest valid key for a misspelt one. TOML cannot
execute anything; nothing here evaluates text.

``dumps(config)`` writes a configuration back as TOML (keys at their defaults left out), which is
how the built-in examples' input files under ``examples/`` are made (``vfem export``).
``reference()`` is the key reference of ``docs/input.md``, generated from the same classes
(``vfem reference`` prints it).
"""

from __future__ import annotations

import dataclasses
import inspect
import json
import math
import tomllib
import typing
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..config import (
    SHAPES,
    SOLID_SHAPES,
    BodyConfig,
    Curve,
    MeshSpec,
    ModelConfig,
    Output,
    Steps,
)
from ..errors import InputError
from ..materials import MATERIALS
from ..schema import (
    _join,
    _kind,
    _listify,
    _Problem,
    _reject_unknown,
    _suggest,
    _type_name,
    convert,
)

#: Where each configuration class sits in an input file (for messages and the reference).
SECTIONS = {
    "ModelConfig": "top level",
    "ContactSettings": "[contact]",
    "PairFriction": "[[contact.pairs]]",
    "Steps": "[steps]",
    "Output": "[output]",
    "BodyConfig": "[[bodies]]",
    "MeshSpec": "[bodies.mesh]",
    "Curve": "[bodies.mesh.curve]",
    **{table.__name__: "[bodies.material]" for table in MATERIALS},
    "Support": "[[bodies.supports]]",
    "PrescribedDisplacement": "[[bodies.prescribed]]",
    "Traction": "[[bodies.tractions]]",
    "Platen": "[bodies.platen]",
}


# -- reading -------------------------------------------------------------------------------------

def load(path: str | Path, assignments: Sequence[str] = ()) -> ModelConfig:
    """Read and check an input file; ``assignments``: ``KEY=VALUE`` changes to its keys first
    (:func:`apply_assignments`, the command line's ``--set``)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"input file {str(path)!r} does not exist" if not path.exists()
                         else f"input file {str(path)!r} is not a file")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read it ({exc})") from None
    return loads(text, str(path), assignments)


def loads(text: str, source: str = "<input>", assignments: Sequence[str] = ()) -> ModelConfig:
    """Check TOML text (``source`` names it in messages), after ``assignments``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{source}: not valid TOML: {exc}") from None
    if assignments:
        apply_assignments(data, assignments)
        source += " with --set " + " --set ".join(assignments)
    try:
        return from_data(ModelConfig, data, "")
    except _Problem as exc:
        raise InputError(f"{source}: {exc}") from None


def apply_assignments(data: dict, assignments: Sequence[str]) -> None:
    """Change parsed TOML ``data`` in place by ``KEY=VALUE`` assignments (``--set``).

    ``KEY`` is dotted: ``contact.variant``, ``steps.count``; a body by its name or number,
    ``bodies.punch.material.youngs_modulus``; an entry of an array of tables by its number,
    ``bodies.punch.prescribed.0.value``. ``VALUE`` is read as a TOML value (``1e10``, ``true``,
    ``[["x", "y"]]``, ``"text"``), a bare word as a string (``thesis``). Missing tables are
    made; the keys and values are then checked like the file's own (an unknown key is named).
    """
    for item in assignments:
        if "=" not in item:
            raise InputError(f"--set expects KEY=VALUE, got {item!r}")
        key, text = (s.strip() for s in item.split("=", 1))
        try:
            value = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            value = text
        parts = key.split(".")
        if not all(parts):
            raise InputError(f"--set {key}: not a key (dotted names, e.g. contact.variant)")
        node: Any = data
        for k, part in enumerate(parts[:-1]):
            here = ".".join(parts[:k + 1])
            if isinstance(node, list):
                node = _entry(node, part, here)
            elif isinstance(node, dict):
                if part not in node:
                    if parts[k + 1].isdigit():  # an entry of an array the file does not have
                        raise InputError(f"--set {key}: the file has no {here!r} to take entry "
                                         f"{parts[k + 1]} of; add it to the file")
                    node[part] = {}
                node = node[part]
            else:
                raise InputError(f"--set {key}: {'.'.join(parts[:k])} is {_kind(node)}, "
                                 "not a table")
        last = parts[-1]
        if isinstance(node, list):
            index = _index(node, last, key)
            node[index] = value
        elif isinstance(node, dict):
            node[last] = value
        else:
            raise InputError(f"--set {key}: {'.'.join(parts[:-1])} is {_kind(node)}, not a table")


def _index(array: list, part: str, where: str) -> int:
    """The position in an array named by a number or, for tables with names, a name."""
    if part.isdigit():
        i = int(part)
        if i < len(array):
            return i
        raise InputError(f"--set {where}: the array has {len(array)} entries (0 to "
                         f"{len(array) - 1})")
    names = [e.get("name") for e in array if isinstance(e, dict)]
    if part in names:
        return names.index(part)
    listed = ", ".join(repr(n) for n in names if n is not None)
    raise InputError(f"--set {where}: no entry named {part!r}"
                     + (f"; there are {listed}" if listed else "; give its number (0, 1, ...)"))


def _entry(array: list, part: str, where: str):
    entry = array[_index(array, part, where)]
    if not isinstance(entry, (dict, list)):
        raise InputError(f"--set {where}: {_kind(entry)}, not a table")
    return entry


def _convert(tp, value, where: str):
    """``value`` checked against type ``tp``, tables read by :func:`from_data`."""
    return convert(tp, value, where, from_data)


def from_data(cls, data: Any, where: str):
    """An instance of dataclass ``cls`` from parsed TOML ``data``, every key checked."""
    if not isinstance(data, dict):
        raise _Problem(where, f"expected a table, got {_kind(data)}")
    if cls is MeshSpec:
        return _mesh_spec(data, where)
    if cls is Steps and "count" in data and "load_factors" in data:
        raise _Problem(where, "give count or load_factors, not both (count would be ignored)")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    _reject_unknown(data, list(fields), where)
    values = {}
    for name, f in fields.items():
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                meaning = help_texts(cls).get(name, "").rstrip(".").replace("``", "")
                raise _Problem(where, f"missing key {name!r}" + (f" ({meaning})" if meaning
                                                                 else ""))
            continue
        here = _join(where, name)
        if cls is ModelConfig and name == "bodies":
            values[name] = _bodies(data[name], here)
        else:
            values[name] = _convert(hints[name], data[name], here)
    try:
        return cls(**values)
    except (TypeError, ValueError) as exc:  # a class's own check: it may name the key itself
        message = str(exc)
        raise _Problem("" if message.startswith(f"{where}.") else where, message) from None


def _bodies(data: Any, where: str) -> tuple[BodyConfig, ...]:
    if not isinstance(data, list) or not data:
        raise _Problem(where, "expected one or more [[bodies]] tables")
    out = []
    for i, item in enumerate(data):
        name = item.get("name") if isinstance(item, dict) else None
        label = f"bodies[{i}]" + (f" ({name})" if isinstance(name, str) else "")
        out.append(from_data(BodyConfig, item, label))
    return tuple(out)


def _mesh_spec(data: dict, where: str) -> MeshSpec:
    own = [f.name for f in dataclasses.fields(MeshSpec) if f.name != "parameters"]
    shape = data.get("shape")
    if shape is None:
        _reject_unknown(data, own, where)
        if "file" not in data:
            raise _Problem(where, "give 'shape' (a built-in mesh) or 'file' (a mesh file)")
        params: tuple = ()
    else:
        if not isinstance(shape, str):
            raise _Problem(_join(where, "shape"), f"expected a string, got {_kind(shape)}")
        if shape not in SHAPES:
            raise _Problem(_join(where, "shape"), f"unknown shape {shape!r}"
                           + _suggest(shape, list(SHAPES)) + f"; built-in: {', '.join(SHAPES)}")
        if "file" in data:
            raise _Problem(where, "give either 'shape' or 'file', not both")
        signature = inspect.signature(SHAPES[shape]).parameters
        _reject_unknown(data, own + list(signature), where, f"shape {shape!r}")
        params = []
        for name, par in signature.items():
            if name in data:
                params.append((name, _shape_parameter(shape, name, data[name],
                                                      _join(where, name))))
            elif par.default is inspect.Parameter.empty:
                raise _Problem(where, f"shape {shape!r} needs the parameter {name!r}")
        params = tuple(params)
    hints = typing.get_type_hints(MeshSpec)
    values = {k: _convert(hints[k], data[k], _join(where, k)) for k in own if k in data}
    return MeshSpec(parameters=params, **values)


def _shape_parameter(shape: str, name: str, value, where: str):
    """A built-in shape's parameter checked against the shape function's type hint."""
    return _convert(typing.get_type_hints(SHAPES[shape]).get(name, Any), value, where)


# -- writing -------------------------------------------------------------------------------------

def to_data(obj) -> dict:
    """The TOML data of a configuration object (keys at their defaults left out)."""
    if isinstance(obj, MeshSpec):
        out = {}
        if obj.shape is not None:
            out["shape"] = obj.shape
            out.update({k: _listify(v) for k, v in obj.parameters})
        for f in dataclasses.fields(obj):
            if f.name in ("shape", "parameters"):
                continue
            v = getattr(obj, f.name)
            if v != f.default:
                out[f.name] = to_data(v) if dataclasses.is_dataclass(v) else _listify(v)
        return out
    out = {}
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        default = (f.default if f.default is not dataclasses.MISSING else
                   f.default_factory() if f.default_factory is not dataclasses.MISSING else
                   dataclasses.MISSING)
        if v == default:
            continue
        if dataclasses.is_dataclass(v):
            out[f.name] = to_data(v)
        elif isinstance(v, tuple) and v and dataclasses.is_dataclass(v[0]):
            out[f.name] = [to_data(x) for x in v]
        else:
            out[f.name] = _listify(v)
    if isinstance(obj, BodyConfig) and (_solid(obj.mesh) or obj.mesh.file is not None):
        _exact_components(obj, out)
    return out


def _solid(mesh: MeshSpec) -> bool:
    """Whether a body's mesh is a 3D shape (:data:`vfem.config.SOLID_SHAPES`). A mesh file's
    dimension is not known without reading it (relative to an input file's folder): its
    supports are written as :func:`_exact_components` too, right in 2D and 3D alike."""
    return mesh.shape in SOLID_SHAPES


def _exact_components(body: BodyConfig, out: dict) -> None:
    """A 3D body's supports with their components written where they are given, even as
    ``["x", "y"]``: left out, they read back as every component of the body (x, y and z,
    :class:`vfem.bodies.AllComponents`), which ``["x", "y"]`` compares equal to."""
    from ..bodies import AllComponents

    for support, data in zip(body.supports, out.get("supports", ())):
        if not isinstance(support.components, AllComponents):
            data["components"] = _listify(support.components)


def dumps(config: ModelConfig, header: str = "") -> str:
    """TOML text of ``config``; ``header`` becomes comment lines at the top."""
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    if lines:
        lines.append("")
    _table(to_data(config), [], lines)
    return "\n".join(lines).rstrip() + "\n"


def _table(data: dict, path: list[str], lines: list[str]) -> None:
    scalars = {k: v for k, v in data.items() if not _is_table(v) and not _is_table_array(v)}
    for k, v in scalars.items():
        lines.append(f"{k} = {_value(v)}")
    for k, v in data.items():
        if _is_table(v):
            lines += ["", f"[{'.'.join([*path, k])}]"]
            _table(v, [*path, k], lines)
        elif _is_table_array(v):
            for item in v:
                lines += ["", f"[[{'.'.join([*path, k])}]]"]
                _table(item, [*path, k], lines)


def _is_table(v) -> bool:
    return isinstance(v, dict)


def _is_table_array(v) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        if not math.isfinite(v):
            raise InputError(f"cannot write the non-finite number {v!r}")
        # the shortest text that reads back as the same number (a NumPy scalar, a float or
        # int subclass, reprs as "np.float64(...)")
        return repr(float(v) if isinstance(v, float) else int(v))
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise InputError(f"cannot write {v!r} to TOML")


# -- the reference -------------------------------------------------------------------------------

def help_texts(cls) -> dict[str, str]:
    """Each attribute's help text, from the ``Attributes:`` section of the class docstring."""
    doc = inspect.cleandoc(cls.__doc__ or "")
    out: dict[str, str] = {}
    lines = doc.splitlines()
    try:
        start = next(i for i, line in enumerate(lines) if line.strip() in ("Attributes:",
                                                                           "Args:"))
    except StopIteration:
        return out
    key = None
    for line in lines[start + 1:]:
        if not line.strip():
            key = None
            continue
        indent = len(line) - len(line.lstrip())
        if indent == 4 and ":" in line:
            key, text = line.strip().split(":", 1)
            out[key] = text.strip()
        elif indent > 4 and key is not None:
            out[key] += " " + line.strip()
        elif indent < 4:
            break
    return out


def _default_text(f) -> str:
    if f.default is not dataclasses.MISSING:
        v = f.default
    elif f.default_factory is not dataclasses.MISSING:
        return "(table)"
    else:
        return "required"
    if v is None:
        return "none"
    return f"`{_value(_listify(v))}`"


def reference() -> str:
    """The key reference of ``docs/input.md`` (generated; a test compares the two)."""
    from ..bodies import Platen, PrescribedDisplacement, Support, Traction
    from ..contact.settings import ContactSettings, PairFriction

    classes = [ModelConfig, ContactSettings, PairFriction, Steps, Output, BodyConfig, MeshSpec,
               Curve, *MATERIALS, Support, PrescribedDisplacement, Traction, Platen]
    out = []
    for cls in classes:
        doc = inspect.cleandoc(cls.__doc__ or "").split("\n\n")[0].replace("\n", " ")
        out += [f"### `{SECTIONS[cls.__name__]}`", "", doc, "",
                "| key | type | default | meaning |", "|---|---|---|---|"]
        hints = typing.get_type_hints(cls)
        helps = help_texts(cls)
        for f in dataclasses.fields(cls):
            if cls is MeshSpec and f.name == "parameters":
                continue
            text = helps.get(f.name, "").replace("|", "\\|")
            out.append(f"| `{f.name}` | {_type_name(hints[f.name])} | {_default_text(f)} | "
                       f"{text} |")
        out.append("")
    out += ["### Mesh shapes (`[bodies.mesh]` with `shape = ...`)", "",
            "The other keys of the mesh table are the shape's parameters.", ""]
    for name, fn in SHAPES.items():
        doc = inspect.cleandoc(fn.__doc__ or "")
        paragraphs = [p.replace("\n", " ") for p in doc.split("\n\n")]
        first = paragraphs[0].split("Named boundaries")[0].strip()
        named = ["Named boundaries" + p.split("Named boundaries", 1)[1]
                 for p in paragraphs if "Named boundaries" in p][:1]
        hints = typing.get_type_hints(fn)
        params = []
        for pname, par in inspect.signature(fn).parameters.items():
            default = ("required" if par.default is inspect.Parameter.empty else
                       "none" if par.default is None else _value(_listify(par.default)))
            params.append(f"`{pname}` ({_type_name(hints.get(pname, Any))}, {default})")
        out += [f"#### `{name}`", "", first, "", "Parameters: " + ", ".join(params) + ".", ""]
        if named:
            out += [named[0].replace(":func:", ""), ""]
    return "\n".join(out).rstrip() + "\n"

