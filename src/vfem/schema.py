"""Checking values against the types the configuration classes and built-in shapes declare: the
one place an input file's values, a ``--set`` change and a shape's parameters given in Python are
read and refused (one message naming where).

A neutral module (issue 18): :mod:`vfem.config` (shape parameters) and :mod:`vfem.io.input` (the
input file) both use it, and it imports neither.
"""

from __future__ import annotations

import dataclasses
import difflib
import inspect
import math
import types
import typing
from collections.abc import Callable, Sequence
from typing import Any

from .errors import InputError


class _Problem(InputError):
    """A problem at a place in the file; turned into an InputError naming the file (an
    InputError itself, so that :func:`from_data` called on its own raises one too)."""

    def __init__(self, where: str, message: str):
        super().__init__(f"{where}: {message}" if where else message)


def convert(tp, value, where: str, nested=None):
    """``value`` checked against type ``tp`` (and converted: arrays to tuples); a dataclass
    ``tp`` is read by ``nested(tp, value, where)`` (the input file's reader,
    :func:`vfem.io.input.from_data`)."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if tp is Any:
        return value
    if origin in (typing.Union, types.UnionType):
        inner = [a for a in args if a is not type(None)]
        if len(inner) == 1:
            return convert(inner[0], value, where, nested)
        if isinstance(value, dict) and all(dataclasses.is_dataclass(a) for a in inner):
            # tables of several kinds (a body's material): the kind whose keys hold the
            # table's, else the one sharing most keys with it, whose reader then names
            # what is wrong (an unknown key, with the nearest valid one)
            return convert(_table_kind(inner, value), value, where, nested)
        for a in inner:
            try:
                return convert(a, value, where, nested)
            except _Problem:
                continue
        raise _Problem(where, f"expected {_type_name(tp)}, got {_kind(value)}")
    if dataclasses.is_dataclass(tp):
        if nested is None:
            raise _Problem(where, f"cannot read a table here ({tp.__name__})")
        return nested(tp, value, where)
    if origin in (tuple, Sequence) or tp in (tuple, Sequence):
        if not isinstance(value, list):
            raise _Problem(where, f"expected {_type_name(tp)}, got {_kind(value)}")
        if origin is tuple and args and args[-1] is not Ellipsis:
            if len(value) != len(args):
                raise _Problem(where, f"expected {len(args)} values, got {len(value)}")
            return tuple(convert(a, v, f"{where}[{i}]", nested)
                         for i, (a, v) in enumerate(zip(args, value)))
        item = args[0] if args else Any
        return tuple(convert(item, v, f"{where}[{i}]", nested) for i, v in enumerate(value))
    if tp is bool:
        if not isinstance(value, bool):
            raise _Problem(where, f"expected true or false, got {_kind(value)}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise _Problem(where, f"expected an integer, got {_kind(value)}")
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise _Problem(where, f"expected a number, got {_kind(value)}")
        if not math.isfinite(value):
            raise _Problem(where, f"must be a finite number, got {value!r}")
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            raise _Problem(where, f"expected a string, got {_kind(value)}")
        return value
    raise _Problem(where, f"cannot read a value of type {tp!r}")  # a bug in the classes


def _table_kind(kinds: list, value: dict):
    """Of the dataclasses ``kinds``, the first whose fields hold every key of the table
    ``value``; else the one with most of its keys (the first of equals)."""
    def known(kind) -> int:
        names = {f.name for f in dataclasses.fields(kind)}
        return sum(key in names for key in value)
    fits = [kind for kind in kinds if known(kind) == len(value)]
    return fits[0] if fits else max(kinds, key=known)


def _reject_unknown(data: dict, valid: list[str], where: str, owner: str = "") -> None:
    for key in data:
        if key not in valid:
            place = f"{where} ({owner})" if owner else where
            raise _Problem(place, f"unknown key {key!r}" + _suggest(key, valid)
                           + f"; valid keys: {', '.join(valid)}")


#: Keys a user reaches for that name something vfem does not do yet: said so, not "did you
#: mean" a key that happens to be spelled alike.
NOT_YET = {"friction": "friction is set for a model's contact: contact.friction = mu, Coulomb's "
                       "coefficient, or [[contact.pairs]], in an input file (the paired "
                       "variant; of the built-in examples cattaneo and sliding have a friction "
                       "parameter: --set friction=0.3)",
           "self_contact": "self_contact is a body's key in an input file ([[bodies]] "
                           "self_contact = true: its surface finds its own two sides), or name "
                           "the two sides as a pair: contact_pairs = [['ring:upper', "
                           "'ring:lower']]"}


def _suggest(key: str, valid: list[str]) -> str:
    if key in NOT_YET:
        return f" ({NOT_YET[key]})"
    close = difflib.get_close_matches(key, valid, n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _join(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


def _kind(value) -> str:
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, str):
        return f"the string {value!r}"
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    return type(value).__name__


def _listify(v):
    return [_listify(x) for x in v] if isinstance(v, (list, tuple)) else v


def _type_name(tp) -> str:
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin in (typing.Union, types.UnionType):
        inner = [a for a in args if a is not type(None)]
        return " or ".join(dict.fromkeys(_type_name(a) for a in inner))  # (one "table")
    if dataclasses.is_dataclass(tp):
        return "table"
    if origin is tuple and args and args[-1] is not Ellipsis:
        return "[" + ", ".join(_type_name(a) for a in args) + "]"
    if origin in (tuple, Sequence):
        item = args[0] if args else Any
        if dataclasses.is_dataclass(item):
            return "array of tables"
        name = _type_name(item)
        return f"array of {name}" if name.endswith("]") else f"array of {name}s"
    return {bool: "boolean", int: "integer", float: "number", str: "string",
            Any: "value"}.get(tp, getattr(tp, "__name__", str(tp)))


def check_parameters(function: Callable, parameters: Sequence[tuple[str, Any]],
                     label: str) -> None:
    """Check ``function``'s keyword ``parameters`` given in Python (a built-in shape's
    ``MeshSpec.parameters``) as an input file's are checked, against its type hints: types, the
    length of pairs, finite numbers. Unknown names are left to ``function``, which refuses them;
    a problem is named ``<label>: <name>``."""
    hints = typing.get_type_hints(function)
    names = inspect.signature(function).parameters
    for name, value in parameters:
        if name in names:
            convert(hints.get(name, Any), _listify(value), f"{label}: {name}")
