"""The shared library of test models (issue 38): the models that several test files wrote out
each for itself, as factories that take what the copies differ in.

Input files are TOML text built from tables in the style the tests wrote them (one
``key = value`` a line, ``[[bodies]]`` with its mesh, material and loads in that order), so a
template written here is, to the letter, the text it replaced: the tests that fill it
(``str.format``, ``replace``) or edit it (a ``[[contact.pairs]]`` table before the first
``[[bodies]]``) keep working on it. :class:`Raw` keeps a placeholder or a number's own spelling.

Bodies in Python: the tensor-product rectangles and the two stacked strips whose contact
surfaces the contact core's tests take apart.

Imported as ``from models import ...``, as tests/resume_check.py is: pytest's default (prepend)
import mode puts tests/ (no ``__init__.py``) on ``sys.path``, in each pytest-xdist worker too.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
from skfem import MeshQuad, MeshTri

from vfem.bodies import Body, Support
from vfem.contact.geometry.surface import ContactSurface
from vfem.io.input import loads
from vfem.materials import LinearElastic
from vfem.solver import Model

# -- TOML text -------------------------------------------------------------------------------------


class Raw(str):
    """TOML text written as it stands: a placeholder filled later, or a number's own spelling."""


def toml_value(v) -> str:
    """A Python value as the tests write it in TOML (floats by ``repr``, lists with ", ")."""
    if isinstance(v, Raw):
        return str(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise TypeError(f"no TOML for {v!r}")


def table(header: str, **keys) -> str:
    """One TOML table: its header line and a ``key = value`` line a key (None left out)."""
    lines = [f"{k} = {toml_value(v)}" for k, v in keys.items() if v is not None]
    return "\n".join([header, *lines])


def rectangle_mesh(x0=None, y0=None, width=None, height=None, nx=None, ny=None, **more) -> dict:
    """The keys of a ``shape = "rectangle"`` mesh table, in the tests' order (None left out)."""
    return {"shape": "rectangle", "x0": x0, "y0": y0, "width": width, "height": height,
            "nx": nx, "ny": ny, **more}


def box_mesh(x0=None, y0=None, z0=None, width=None, depth=None, height=None, nx=None, ny=None,
             nz=None, **more) -> dict:
    """The keys of a ``shape = "box"`` mesh table, in the tests' order (None left out)."""
    return {"shape": "box", "x0": x0, "y0": y0, "z0": z0, "width": width, "depth": depth,
            "height": height, "nx": nx, "ny": ny, "nz": nz, **more}


def support(boundary: str, components=None) -> str:
    """A ``[[bodies.supports]]`` table (every component when ``components`` is None)."""
    return table("[[bodies.supports]]", boundary=boundary, components=components)


def rollers() -> str:
    """The 3D rollers: ``[[bodies.supports]]`` left held along x, front along y."""
    return "\n".join([support("left", ["x"]), support("front", ["y"])])


def prescribed(boundary: str, component: str, value, amplitude=None) -> str:
    """A ``[[bodies.prescribed]]`` table: a displacement, along a load curve if one is given."""
    return table("[[bodies.prescribed]]", boundary=boundary, component=component, value=value,
                 amplitude=amplitude)


def platen(boundary: str, component: str, force, amplitude=None) -> str:
    """A ``[bodies.platen]`` table: a force-controlled face, along a load curve if one is given."""
    return table("[bodies.platen]", boundary=boundary, component=component, force=force,
                 amplitude=amplitude)


def traction(boundary: str, value, amplitude=None) -> str:
    """A ``[[bodies.tractions]]`` table."""
    return table("[[bodies.tractions]]", boundary=boundary, value=value, amplitude=amplitude)


def toml_body(name: str, mesh, *tables: str, E=1000.0, nu=0.3, contact_boundaries=None,
              kinematics=None) -> str:
    """A ``[[bodies]]`` entry: its keys, mesh (keys, or Raw text), material, then ``tables``."""
    mesh_table = ("[bodies.mesh]\n" + mesh if isinstance(mesh, Raw)
                  else table("[bodies.mesh]", **mesh))
    return "\n".join([table("[[bodies]]", name=name, contact_boundaries=contact_boundaries,
                            kinematics=kinematics),
                      mesh_table,
                      table("[bodies.material]", youngs_modulus=E, poissons_ratio=nu),
                      *tables])


def input_file(name: str, *parts: str, contact: dict | None = None, load_factors=None) -> str:
    """An input file: its name, ``[contact]``, the ``parts`` (bodies, tables), ``[steps]``."""
    lines = [f"name = {toml_value(name)}"]
    if contact is not None:
        lines.append(table("[contact]", **contact))
    lines.extend(parts)
    if load_factors is not None:
        lines.append(table("[steps]", load_factors=load_factors))
    return "\n" + "\n".join(lines) + "\n"


# -- the models ------------------------------------------------------------------------------------


def pressed(value, component: str = "y", end: float = 1.0) -> str:
    """The top moved by ``value`` over load factors 0 to 0.5, then held (to ``end``)."""
    return prescribed("top", component, value, amplitude=[[0.0, 0.0], [0.5, 1.0], [end, 1.0]])


def slid(value, component: str = "x", end: float = 1.0) -> str:
    """The top held over load factors 0 to 0.5, then moved by ``value`` (at ``end``)."""
    return prescribed("top", component, value, amplitude=[[0.0, 0.0], [0.5, 0.0], [end, 1.0]])


def block_on_base(name: str, base_mesh: dict, block_mesh: dict, *block_loads: str,
                  names=("lower", "upper"), friction=None, kinematics=None,
                  load_factors=None) -> str:
    """TOML: a block with ``block_loads`` on a wider base held at its bottom (E 1000, nu 0.3)."""
    base, block = names
    return input_file(name,
                      toml_body(base, base_mesh, support("bottom"), contact_boundaries=["top"],
                                kinematics=kinematics),
                      toml_body(block, block_mesh, *block_loads, contact_boundaries=["bottom"],
                                kinematics=kinematics),
                      contact=None if friction is None else {"friction": friction},
                      load_factors=load_factors)


def built(text: str, swap: bool = False) -> Model:
    """The model of the input ``text``, its bodies listed the other way round when ``swap``."""
    config = loads(text)
    if swap:
        config = dataclasses.replace(config, bodies=config.bodies[::-1])
    return config.build()


# -- bodies in Python ------------------------------------------------------------------------------


def rect(cls, x0, x1, y0, y1, nx, ny, boundaries=("bottom", "top")):
    """A skfem tensor mesh of ``cls``, nx by ny cells, its ``boundaries`` (of bottom, top, left)."""
    m = cls.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    t = 1e-9
    marks = {"bottom": lambda x: x[1] < y0 + t, "top": lambda x: x[1] > y1 - t,
             "left": lambda x: x[0] < x0 + t}
    return m.with_boundaries({name: marks[name] for name in boundaries})


def strip(cls, y0, y1, nx, name, E=1e9, plane="strain") -> Body:
    """A body: a unit-wide strip of two element rows over [y0, y1], held at its far face."""
    mesh = rect(cls, 0, 1, y0, y1, nx, 2, boundaries=("top", "bottom"))
    return Body(name, mesh, LinearElastic(E, 0.3, plane),
                supports=(Support("bottom" if y0 < 0 else "top"),))


def strip_surfaces(n_lower, n_upper, E=1e9, names=("lower", "upper"), plane="strain"
                   ) -> list[ContactSurface]:
    """Set-up surfaces of two facing strips: quadrilaterals below y = 0, triangles above (of
    the section ``plane`` names)."""
    out = []
    for b, side in ((strip(MeshQuad, -0.5, 0.0, n_lower, names[0], E, plane), "top"),
                    (strip(MeshTri, 0.0, 0.5, n_upper, names[1], E, plane), "bottom")):
        b.setup()
        s = ContactSurface.build(b, b.mesh.boundaries[side])
        s.compute_flexibility()
        out.append(s)
    return out
