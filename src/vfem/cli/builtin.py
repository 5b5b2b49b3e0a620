"""The built-in examples as the command line reaches them (the package :mod:`vfem_examples`,
beside the library): by name, with ``--set key=value`` changes to their parameters."""

from __future__ import annotations

import dataclasses
import difflib
import shlex
import textwrap
from pathlib import Path

from vfem_examples import EXAMPLES, load

from ..contact.settings import ContactSettings
from ..errors import InputError
from ..schema import NOT_YET


def _parse_value(text: str, current, key: str, cls):
    """Turn ``text`` into the type of the parameter (no eval)."""
    t = text.strip()
    if t.lower() in ("none", "null", "default"):
        return None
    if isinstance(current, str):
        return t  # checked where it is used (e.g. contact.variant names its choices)
    if isinstance(current, bool):
        if t.lower() in ("true", "yes", "1"):
            return True
        if t.lower() in ("false", "no", "0"):
            return False
        raise InputError(f"--set {key}: expected true or false, got {text!r}")
    try:
        return int(t) if isinstance(current, int) else float(t)
    except ValueError:
        raise InputError(f"--set {key}: expected a number, got {text!r}") from None


CONTACT_KEYS = {f.name for f in dataclasses.fields(ContactSettings)}


def build_parameters(example: str, assignments: list[str]):
    """The example's parameters with ``key=value`` overrides applied. ``contact.KEY`` is
    accepted for the example's parameters that are contact settings (``contact.method``)."""
    cls = load(example).Parameters
    params = cls()
    names = [f.name for f in dataclasses.fields(cls)]
    changes = {}
    for item in assignments:
        if "=" not in item:
            raise InputError(f"--set expects key=value, got {item!r}")
        key, value = (s.strip() for s in item.split("=", 1))
        if key.startswith("contact.") and key[len("contact."):] in names and \
                key[len("contact."):] in CONTACT_KEYS:
            key = key[len("contact."):]  # the example's parameter that is this contact setting
        if key not in names and key.split(".")[-1] in NOT_YET:
            raise InputError(f"--set {key}: not a parameter of {example}: "
                             f"{NOT_YET[key.split('.')[-1]]}")
        if key not in names:
            close = difflib.get_close_matches(key, names, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f"; valid keys: {', '.join(names)}"
            raise InputError(f"--set: {example} has no parameter {key!r}{hint}")
        current = getattr(params, key)
        if current is None:
            current = 0.0
        changes[key] = _parse_value(value, current, key, cls)
    return dataclasses.replace(params, **changes)


def example_module(name: str, alternatives: str = ""):
    """The module of a built-in example; an unknown name is refused with the closest one."""
    if not name.strip():
        raise InputError("no model given: name a built-in example "
                         f"({', '.join(EXAMPLES)}) or an input file (.toml)")
    if name not in EXAMPLES and Path(name).is_dir():
        raise InputError(f"{name} is a folder: give an input file (.toml) or a built-in example "
                         f"({', '.join(EXAMPLES)}); to redraw a results folder's figures: "
                         f"vfem plot {name}")
    if name not in EXAMPLES:
        close = difflib.get_close_matches(name, EXAMPLES, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise InputError(f"unknown example {name!r}{hint}; available: {', '.join(EXAMPLES)}"
                         + alternatives)
    return load(name)


def example_configs(name: str, assignments: list[str]) -> dict:
    """The built-in example's model(s) as configurations, by key."""
    example = example_module(name)
    params = build_parameters(name, assignments)
    if hasattr(example, "validate"):
        example.validate(params)  # what run would refuse is not exported either
    if hasattr(example, "configs"):
        return example.configs(params)
    if hasattr(example, "config"):
        return {name: example.config(params)}
    raise InputError(f"the {name} example is the 1D analogy of the method (two springs), not a "
                     "model of bodies: it has no input file")


def export_header(example: str, assignments: list[str]) -> str:
    """The comment lines at the top of a file ``vfem export`` writes: the example, its title
    (the first paragraph of its module's docstring, whole), the command that wrote it and the
    one that solves it. Plain text, as a TOML comment is read: no Markdown (the backticks
    around the commands read as part of them, and ended before the ``--set`` options)."""
    doc = (load(example).__doc__ or example).strip()
    title = " ".join(doc.split("\n\n")[0].split()).replace("``", "")
    sets = "".join(f" --set {shlex.quote(a)}" for a in assignments)
    return "\n".join([f"vfem input file: the built-in example '{example}'.",
                      *textwrap.wrap(title, 96),
                      f"Written by: vfem export {example}{sets}",
                      f"vfem run <this file> solves the same model as: vfem run {example}{sets}",
                      "Keys: docs/input.md."])
