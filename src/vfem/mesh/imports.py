"""Meshes from files: one body's elements and named boundaries from a Gmsh or Abaqus mesh.

:func:`read_mesh` reads a mesh file with meshio and returns a scikit-fem mesh for one body,
with ``mesh.boundaries`` (name -> boundary facet indices) that supports, loads, platens and
``contact_boundaries`` can name. Conventions:

Formats (chosen by the file's extension)
    ``.msh``: Gmsh, format 4.1 as gmsh writes it by default (2.2 is read too). ``.inp``: an
    Abaqus input file with its nodes and elements at the top level (no parts and instances: one
    ``*Node`` section), as gmsh and most meshers write it.

Element types
    3-node triangles -> ``MeshTri1``, 4-node quadrilaterals -> ``MeshQuad1``, 6-node triangles ->
    ``MeshTri2``, 9-node quadrilaterals -> ``MeshQuad2`` (node order as meshio gives it: corners,
    then the midpoints of edges 0-1, 1-2, ..., then the centre). One body has one element type.
    Abaqus plane-strain names (``CPE3``, ``CPE4``, ``CPE4R``, ``CPE6``, ...) are read as the
    plane-stress ones meshio knows (``CPS3``, ``CPS4``, ...): only the connectivity is used.

The body (``cells``)
    The name of the group holding the body's elements: a Gmsh *physical surface* (a physical
    group of dimension 2) or an Abaqus *ELSET* (``*Elset`` or ``elset=`` on ``*Element``; names
    compared exactly, then ignoring case as Abaqus does). ``None``: every 2D element in the file.
    Only the nodes of the selected elements are kept, renumbered in their order in the file. The
    mesh must lie in the plane z = 0 (z is dropped). Elements are made counter-clockwise (positive
    area), their nodes reordered where the file has them clockwise.

3D files
    A file with 3D elements (tetrahedra, hexahedra) makes 3D bodies: 4-node tetrahedra ->
    ``MeshTet1``, 8-node hexahedra -> ``MeshHex1``, 10-node tetrahedra -> ``MeshTet2``, 27-node
    hexahedra -> ``MeshHex2`` (Abaqus ``C3D4``, ``C3D8``/``C3D8R``/..., ``C3D10``; meshio's
    VTK node order put in scikit-fem's: ``skfem.io.meshio.INV_HEX_MAPPING`` for hexahedra).
    Elements of negative volume (left-handed node order) are mirrored, so every element has a
    positive Jacobian in scikit-fem's order. ``cells`` names a *physical volume* (dimension 3)
    or an ELSET of volume elements; ``None``: every 3D element of the file, its 2D elements
    being boundaries. Boundaries: every *physical surface* (Gmsh) or ELSET of faces (Abaqus,
    e.g. ``CPS3``, ``CPS4``, ``S3``, ``M3D4`` as gmsh writes them) holds the body's boundary
    facets whose corner nodes are those of one of its faces; every NSET the facets whose
    corners all lie in it. Refused: 20-node hexahedra, wedges (prisms), pyramids, and a
    physical surface of a 3D file named as a body.

Boundaries
    Gmsh: every *physical curve* (dimension 1) becomes a boundary of the same name, holding the
    body's boundary facets that coincide with the group's line elements (matched by their two end
    nodes). Abaqus: every *NSET* becomes a boundary holding the boundary facets whose vertices all
    lie in the set, and every ELSET of line elements one holding the facets that coincide with
    them (an NSET and an ELSET of the same name: the union). A group that touches none of the
    body's facets is absent from that body: one file with two bodies can use one physical curve
    ``symmetry`` for the symmetry edges of both, each body getting its own part. Two bodies that
    should not be glued must not share nodes (in Gmsh: separate surfaces, no fragment).

Errors
    Every problem with the file is an :class:`~vfem.errors.InputError` naming the file: missing,
    unreadable, no such group (with the names available and a "did you mean"), a group without 2D
    elements, unsupported or mixed element types, z not zero, and whatever
    :func:`~vfem.mesh.checks.check_mesh` finds (degenerate, inverted or overlapping elements,
    duplicate nodes, several pieces).

Limits of meshio 5.3 that show here: a Gmsh file saved with ``Mesh.SaveAll = 1`` that has
elements outside every physical group cannot be read (meshio's tags do not line up; save the
physical groups only, gmsh's default); of two Gmsh physical groups of different dimensions with
the same name only one is seen. meshio's Abaqus reader puts an ``*Element, elset=NAME`` set on
the wrong cell block when an earlier ``*Element`` line has no ``elset``; those sets are rebuilt
here from the file's ``*Element`` lines.
"""

from __future__ import annotations

import contextlib
import difflib
import io
import logging
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from skfem import (
    ElementHex1,
    ElementHex2,
    ElementTetP1,
    ElementTetP2,
    Mesh,
    MeshHex1,
    MeshHex2,
    MeshQuad1,
    MeshQuad2,
    MeshTet1,
    MeshTet2,
    MeshTri1,
    MeshTri2,
)
from skfem.io.meshio import INV_HEX_MAPPING

from ..errors import InputError
from .checks import check_mesh

log = logging.getLogger(__name__)

#: meshio cell type -> (scikit-fem mesh class, number of vertices, node order reversing it)
_SUPPORTED = {
    "triangle": (MeshTri1, 3, [0, 2, 1]),
    "quad": (MeshQuad1, 4, [0, 3, 2, 1]),
    "triangle6": (MeshTri2, 3, [0, 2, 1, 5, 4, 3]),
    "quad9": (MeshQuad2, 4, [0, 3, 2, 1, 7, 6, 5, 4, 8]),
}
_LINES = ("line", "line3")  # boundary elements; their first two nodes are the ends
#: 3D: meshio cell type -> (scikit-fem mesh class, number of vertices, its element, the
#: scikit-fem node of each local node: meshio's (VTK's) order -> scikit-fem's)
_SOLIDS = {
    "tetra": (MeshTet1, 4, ElementTetP1, list(range(4))),
    "hexahedron": (MeshHex1, 8, ElementHex1, list(INV_HEX_MAPPING[:8])),
    "tetra4": (MeshTet1, 4, ElementTetP1, list(range(4))),  # meshio 5.3's name for C3D4H
    "tetra10": (MeshTet2, 4, ElementTetP2, list(range(10))),
    "hexahedron27": (MeshHex2, 8, ElementHex2, list(INV_HEX_MAPPING)),
}
#: 3D: boundary elements (faces) of a volume mesh; their first 3 or 4 nodes are the corners
_FACES = {"triangle": 3, "triangle6": 3, "triangle7": 3, "quad": 4, "quad8": 4, "quad9": 4}
#: Element types vfem does not read, said plainly (meshio's names, the Abaqus and Gmsh ones)
_UNSUPPORTED_3D = {
    "hexahedron20": "20-node hexahedra (Abaqus C3D20, C3D20R; Gmsh with "
                    "Mesh.SecondOrderIncomplete = 1): use 8- or 27-node hexahedra",
    "wedge": "6-node wedges or prisms (Abaqus C3D6; Gmsh prisms): use tetrahedra or hexahedra",
    "wedge15": "15-node wedges (Abaqus C3D15): use tetrahedra or hexahedra",
    "wedge18": "18-node wedges (Gmsh prisms of order 2): use tetrahedra or hexahedra",
    "pyramid": "pyramids (Abaqus C3D5; Gmsh pyramids): use tetrahedra or hexahedra",
    "pyramid13": "13-node pyramids: use tetrahedra or hexahedra",
    "pyramid14": "14-node pyramids: use tetrahedra or hexahedra",
}
_SURFACES = ("triangle", "quad", "polygon")  # a cell type of dimension 2 starts with one of these

#: Abaqus element names meshio 5.3 does not know, read as the meshio type of the same shape
_ABAQUS_ALIASES = {
    **dict.fromkeys(["CPE3", "CPE3H", "CPS3"], "triangle"),
    **dict.fromkeys(["CPE4", "CPE4H", "CPE4I", "CPE4IH", "CPE4R", "CPE4RH", "CPS4I"], "quad"),
    **dict.fromkeys(["CPE6", "CPE6H", "CPE6M", "CPE6MH", "CPS6", "CPS6M"], "triangle6"),
    **dict.fromkeys(["CPE8", "CPE8H", "CPE8R", "CPE8RH", "CPS8", "CPS8R"], "quad8"),
    # faces of 3D meshes (boundaries only), as gmsh writes them: membranes and plane elements
    **dict.fromkeys(["M3D3"], "triangle"),
    **dict.fromkeys(["M3D4", "M3D4R"], "quad"),
    **dict.fromkeys(["M3D6"], "triangle6"),
    **dict.fromkeys(["M3D8", "M3D8R"], "quad8"),
    **dict.fromkeys(["M3D9", "M3D9R"], "quad9"),
    **dict.fromkeys(["C3D5", "C3D5H"], "pyramid"),
    **dict.fromkeys(["C3D6H"], "wedge"),
    **dict.fromkeys(["C3D15H"], "wedge15"),
}

_FORMATS = {".msh": "gmsh", ".inp": "abaqus"}
_EXPECTED = "a Gmsh mesh (.msh, format 4.1 as gmsh writes it) or an Abaqus input file (.inp)"


@dataclass
class _Group:
    """A named group of the file: elements per cell block, or nodes (an Abaqus NSET)."""

    name: str
    kind: str  # "physical surface", "physical curve", "physical point", "ELSET", "NSET"
    blocks: dict[int, np.ndarray] = field(default_factory=dict)  # block -> element indices
    nodes: np.ndarray | None = None  # NSET: indices of the file's points


def read_mesh(path: str | os.PathLike, cells: str | None = None) -> Mesh:
    """Read one body's mesh and named boundaries from a Gmsh ``.msh`` or Abaqus ``.inp`` file.

    Args:
        path: the mesh file.
        cells: the group holding the body's elements: a Gmsh physical surface (physical
            volume in a file with 3D elements) or an Abaqus ELSET; ``None`` for every 2D
            element in the file (every 3D element, if it has any).

    Returns:
        A ``MeshTri1``, ``MeshQuad1``, ``MeshTri2`` or ``MeshQuad2`` with counter-clockwise
        elements, only the body's nodes, and ``mesh.boundaries`` (name -> boundary facet indices)
        from the file's physical curves (Gmsh) or node sets and line element sets (Abaqus) that
        touch the body; from a file with 3D elements a ``MeshTet1``, ``MeshHex1``,
        ``MeshTet2`` or ``MeshHex2`` of positive volumes, its boundaries from the physical
        surfaces, face element sets and node sets. See the module's docstring.

    Raises:
        InputError: the file is missing or unreadable, or the selection makes no valid mesh.
    """
    if cells is not None and not isinstance(cells, str):
        raise InputError(f"mesh file {str(path)!r}: cells must be a group name or None, "
                         f"not {cells!r}")
    path = Path(path)
    if not path.exists():
        raise InputError(f"mesh file {str(path)!r}: no such file")
    if not path.is_file():
        raise InputError(f"mesh file {str(path)!r}: not a file")
    fmt = _FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise InputError(f"mesh file {str(path)!r}: unknown extension {path.suffix!r}; "
                         f"expected {_EXPECTED}")
    raw = _read_raw(path, fmt)
    where = f"mesh file {str(path)!r}"
    try:
        groups = _gmsh_groups(raw) if fmt == "gmsh" else _abaqus_groups(raw, path)
    except Exception as e:  # malformed tags or sets that meshio let through
        raise InputError(f"{where}: cannot make sense of its groups ({type(e).__name__}: {e}); "
                         f"expected {_EXPECTED}") from None

    dim = 3 if any(_dim(b.type) == 3 for b in raw.cells) else 2  # a volume mesh: 3D bodies
    what = f"{where}, {f'every {dim}D element' if cells is None else f'group {cells!r}'}"
    try:
        selected = _select(raw, groups, cells, fmt, where, dim)
        if dim == 3:
            mesh, old_to_vertex = _build_3d(raw, selected, what)
            boundaries = _boundaries_3d(raw, groups, mesh, old_to_vertex)
        else:
            mesh, old_to_vertex = _build(raw, selected, what)
            boundaries = _boundaries(raw, groups, mesh, old_to_vertex)
        mesh = mesh.with_boundaries(boundaries)
    except InputError:
        raise
    except Exception as e:  # inconsistent connectivity that meshio let through
        raise InputError(f"{what}: cannot make a mesh of it ({type(e).__name__}: {e})") from None
    log.info("%s: %d nodes, %d %s elements, boundaries %s", what, mesh.doflocs.shape[1],
             mesh.nelements, type(mesh).__name__, ", ".join(boundaries) or "none")
    return mesh


# -- reading ---------------------------------------------------------------------------------------


def _read_raw(path: Path, fmt: str):
    """The file through meshio's reader, its messages logged, any failure an InputError."""
    import meshio

    if fmt == "abaqus":
        _register_abaqus_aliases()
    reader = meshio.gmsh.read if fmt == "gmsh" else meshio.abaqus.read
    messages = io.StringIO()
    try:
        with contextlib.redirect_stderr(messages), contextlib.redirect_stdout(messages):
            raw = reader(str(path))
    except (Exception, SystemExit) as e:
        kind = "Gmsh" if fmt == "gmsh" else "Abaqus"
        detail = str(e).strip() or f"not a {kind} file meshio understands"
        if "gmsh:physical" in detail:  # meshio 5.3 and elements outside the physical groups
            detail += " Save the physical groups only: gmsh's Mesh.SaveAll = 0, the default"
        raise InputError(f"mesh file {str(path)!r}: cannot be read as {kind} ({detail}); "
                         f"expected {_EXPECTED}") from None
    finally:
        for line in messages.getvalue().splitlines():
            if line.strip():
                log.warning("meshio, reading %s: %s", path, line.strip())
    if len(raw.points) == 0 or not raw.cells:
        raise InputError(f"mesh file {str(path)!r}: no nodes or elements found; "
                         f"expected {_EXPECTED}")
    return raw


def _register_abaqus_aliases() -> None:
    """Teach meshio's Abaqus reader the plane-strain element names (same connectivity)."""
    try:
        from meshio.abaqus import _abaqus
    except ImportError:  # a meshio without this module: its own table then
        return
    for name, cell_type in _ABAQUS_ALIASES.items():
        _abaqus.abaqus_to_meshio_type.setdefault(name, cell_type)


def _dim(cell_type: str) -> int:
    if cell_type == "vertex":
        return 0
    if cell_type.startswith("line"):
        return 1
    return 2 if cell_type.startswith(_SURFACES) else 3


def _gmsh_groups(raw) -> list[_Group]:
    """Physical groups: from ``field_data`` (name -> [tag, dim]), the elements of each from
    ``cell_sets`` (msh 4, every physical tag of an entity) and ``gmsh:physical`` (msh 2 and 4,
    the first tag)."""
    kinds = {0: "physical point", 1: "physical curve", 2: "physical surface",
             3: "physical volume"}
    physical = raw.cell_data.get("gmsh:physical")
    groups = []
    for name, value in raw.field_data.items():
        tag, dim = (int(v) for v in np.asarray(value).ravel()[:2])
        group = _Group(name, kinds.get(dim, f"physical group of dimension {dim}"))
        sets = raw.cell_sets.get(name)
        for k, block in enumerate(raw.cells):
            if _dim(block.type) != dim:
                continue
            mask = np.zeros(len(block.data), dtype=bool)
            if physical is not None and k < len(physical):
                mask |= np.asarray(physical[k]).ravel() == tag
            if sets is not None and k < len(sets) and sets[k] is not None:
                mask[np.asarray(sets[k], dtype=int)] = True
            if mask.any():
                group.blocks[k] = np.flatnonzero(mask)
        groups.append(group)
    return groups


def _abaqus_groups(raw, path: Path) -> list[_Group]:
    """ELSETs (``*Elset`` and ``elset=`` on ``*Element``) and NSETs.

    meshio 5.3 gives an ``*Element, elset=NAME`` set to the wrong cell block when an earlier
    ``*Element`` has none; those sets are rebuilt here from the ``*Element`` lines themselves.
    """
    headers = _abaqus_element_headers(path)
    on_elements: dict[str, list[int]] = {}
    if headers is not None and len(headers) == len(raw.cells):
        for k, name in enumerate(headers):
            if name:
                on_elements.setdefault(name, []).append(k)
    else:
        log.warning("%s: *Element lines do not match meshio's cell blocks; element sets given "
                    "on them are taken from meshio as they are", path)
    groups = []
    for name, blocks in on_elements.items():
        groups.append(_Group(name, "ELSET", {k: np.arange(len(raw.cells[k].data))
                                             for k in blocks}))
    for name, per_block in raw.cell_sets.items():
        if name in on_elements:
            continue
        group = _Group(name, "ELSET")
        for k, ids in enumerate(per_block):
            ids = np.asarray(ids, dtype=int).ravel() if ids is not None else np.array([], int)
            if k < len(raw.cells) and ids.size:
                group.blocks[k] = np.unique(ids)
        groups.append(group)
    for name, ids in raw.point_sets.items():
        groups.append(_Group(name, "NSET", nodes=np.unique(np.asarray(ids, dtype=int))))
    return groups


def _abaqus_element_headers(path: Path) -> list[str | None] | None:
    """The ``elset=`` of each ``*Element`` keyword line, in order; None with ``*Include``."""
    headers: list[str | None] = []
    with open(path, errors="replace") as f:
        for line in f:
            if not line.startswith("*") or line.startswith("**"):
                continue
            keyword, _, rest = line.partition(",")
            keyword = keyword.strip().lstrip("*").strip().upper()
            if keyword == "INCLUDE":
                return None
            if keyword == "ELEMENT":
                params = {}
                for item in rest.split(","):
                    key, _, value = item.partition("=")
                    params[key.strip().upper()] = value.strip()
                headers.append(params.get("ELSET") or None)
    return headers


# -- selecting the body ----------------------------------------------------------------------------


def _select(raw, groups: list[_Group], cells: str | None, fmt: str, where: str, dim: int = 2
            ) -> tuple[str, np.ndarray]:
    """The selected elements: (meshio cell type, connectivity (n, nodes) in the file's points).
    ``dim``: the bodies' dimension, 3 in a file with 3D elements (its 2D elements are then
    boundaries), else 2."""
    body_kind = ("physical volume" if dim == 3 else "physical surface") if fmt == "gmsh" \
        else "ELSET"
    bodies = sorted({g.name for g in groups
                     if any(_dim(raw.cells[k].type) == dim for k in g.blocks)})
    listing = (f"{body_kind}s with {dim}D elements in the file: {', '.join(bodies)}" if bodies
               else f"the file has no {body_kind}s with {dim}D elements")
    if cells is None:
        chosen = {k: np.arange(len(b.data)) for k, b in enumerate(raw.cells)
                  if _dim(b.type) == dim}
        if not chosen:
            found = sorted({b.type for b in raw.cells})
            raise InputError(f"{where}: no 2D elements (found {', '.join(found)}); vfem reads "
                             f"2D meshes of triangles or quadrilaterals")
        label = "the file"
    else:
        group = _find(groups, cells, fmt)
        if group is None:
            names = sorted({g.name for g in groups})
            close = difflib.get_close_matches(cells, names, n=3, cutoff=0.5)
            hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
            raise InputError(f"{where}: no group named {cells!r} ({listing}){hint}")
        chosen = {k: ids for k, ids in group.blocks.items() if _dim(raw.cells[k].type) == dim}
        if not chosen and dim == 3 and any(_dim(raw.cells[k].type) == 2 for k in group.blocks):
            raise InputError(f"{where}: group {cells!r} ({group.kind}) holds 2D elements of a 3D "
                             f"mesh, but a body of a file with 3D elements is 3D; name the "
                             f"{body_kind} of the body's elements ({listing}): the file's "
                             f"surfaces become its boundaries")
        if not chosen:
            raise InputError(f"{where}: group {cells!r} ({group.kind}) has no {dim}D elements; "
                             f"name the {body_kind} of the body's elements ({listing})")
        label = f"group {cells!r}"

    types = sorted({raw.cells[k].type for k, ids in chosen.items() if len(ids)})
    if not types:
        raise InputError(f"{where}: {label} selects no elements")
    readable = _SOLIDS if dim == 3 else _SUPPORTED
    unsupported = [t for t in types if t not in readable]
    if unsupported and dim == 3:
        why = "; ".join(_UNSUPPORTED_3D[t] for t in unsupported if t in _UNSUPPORTED_3D)
        raise InputError(f"{where}: {label} has elements of unsupported type "
                         f"{', '.join(unsupported)}; vfem reads "
                         f"{', '.join(t for t in _SOLIDS if t != 'tetra4')} in 3D"
                         + (f" ({why})" if why else ""))
    if unsupported:
        raise InputError(f"{where}: {label} has elements of unsupported type "
                         f"{', '.join(unsupported)}; vfem reads {', '.join(_SUPPORTED)}")
    if len(types) > 1:
        others = [b for b in bodies if b != cells]
        if cells is not None:  # the group chosen is itself mixed: the mesh must change
            how = ("mesh the group with one element type (in Gmsh, Mesh.RecombineAll or none"
                   + (", and no prisms or pyramids" if dim == 3 else "")
                   + f"), or split it into a {body_kind} per type, one body each")
        elif others:
            how = f"select one body's elements with cells = {others[0]!r}"
        else:
            how = f"give each body its own {body_kind} and select one with cells = ..."
        raise InputError(f"{where}: {label} mixes {' and '.join(types)} elements, but one body "
                         f"must have one element type; {how} ({listing})")
    t = np.vstack([np.asarray(raw.cells[k].data)[ids] for k, ids in chosen.items()
                   if raw.cells[k].type == types[0] and len(ids)])
    _, first = np.unique(t, axis=0, return_index=True)  # an element in two blocks: once
    return types[0], t[np.sort(first)]


def _find(groups: list[_Group], name: str, fmt: str) -> _Group | None:
    """The element group named ``name`` (Abaqus: ignoring case if no exact match)."""
    candidates = [g for g in groups if g.kind != "NSET"]
    for g in candidates:
        if g.name == name:
            return g
    if fmt == "abaqus":
        folded = [g for g in candidates if g.name.upper() == name.upper()]
        if len(folded) == 1:
            return folded[0]
    nsets = [g for g in groups if g.kind == "NSET" and g.name == name]
    return nsets[0] if nsets else None


# -- building the mesh -----------------------------------------------------------------------------


def _build(raw, selected: tuple[str, np.ndarray], what: str) -> tuple[Mesh, np.ndarray]:
    """The scikit-fem mesh of the selected elements, and the map file point -> mesh vertex
    (-1 for points that are not vertices of the body)."""
    cell_type, t = selected
    mesh_type, nv, reverse = _SUPPORTED[cell_type]
    t = np.asarray(t, dtype=np.int64)
    used, t = np.unique(t, return_inverse=True)
    t = t.reshape(-1, len(reverse))
    points = np.asarray(raw.points, dtype=float)[used]
    if points.ndim != 2 or points.shape[1] not in (2, 3) or not np.all(np.isfinite(points)):
        raise InputError(f"{what}: node coordinates are not finite 2D or 3D points")
    xy = points[:, :2]
    scale = float(max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1]), np.abs(xy).max(), 1e-300))
    if points.shape[1] == 3:
        z = np.abs(points[:, 2])
        if z.max() > 1e-9 * scale:
            raise InputError(f"{what}: the mesh is not planar (|z| up to {z.max():.3g}); vfem "
                             f"reads 2D meshes in the plane z = 0")

    clockwise = _signed_area(xy, t[:, :nv]) < 0
    if clockwise.any():
        t[clockwise] = t[clockwise][:, reverse]
        log.debug("%s: %d clockwise elements reordered", what, int(clockwise.sum()))

    p = np.ascontiguousarray(xy.T)
    if mesh_type is MeshTri1:
        mesh = MeshTri1(p, np.ascontiguousarray(t.T), sort_t=False)
    else:
        mesh = mesh_type(p, np.ascontiguousarray(t.T))
    return _checked(mesh, p, t, nv, used, len(raw.points), what)


def _checked(mesh: Mesh, p: np.ndarray, t: np.ndarray, nv: int, used: np.ndarray,
             npoints: int, what: str) -> tuple[Mesh, np.ndarray]:
    """``mesh`` (built from points ``p`` and elements ``t`` of the file's nodes ``used``, ``nv``
    vertices per element) checked, 2D or 3D, and the file's node -> the mesh's vertex (-1 for a
    node of no element, or a quadratic element's midside node). scikit-fem numbers the vertices
    of quadratic meshes first, in increasing order; the checks: degenerate, inverted or
    overlapping elements, duplicate nodes, several pieces (element numbers are those of the
    selection, in the file's order)."""
    vertices = np.unique(t[:, :nv])
    new_to_vertex = np.full(len(used), -1, dtype=np.int64)
    new_to_vertex[vertices] = np.arange(len(vertices))
    same = np.array_equal(mesh.doflocs[:, : len(vertices)], p[:, vertices])
    if mesh.nvertices != len(vertices) or not same:
        raise InputError(f"{what}: the elements do not form a valid mesh (the quadratic nodes "
                         f"are not shared between neighbouring elements)")
    check_mesh(mesh, what)
    old_to_vertex = np.full(npoints, -1, dtype=np.int64)
    old_to_vertex[used] = new_to_vertex
    return mesh, old_to_vertex


def _signed_area(xy: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Signed areas (shoelace) of the polygons ``t`` (n, corners): positive counter-clockwise."""
    x, y = xy[t, 0], xy[t, 1]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)


def _build_3d(raw, selected: tuple[str, np.ndarray], what: str) -> tuple[Mesh, np.ndarray]:
    """:func:`_build` of tetrahedra and hexahedra: nodes put in scikit-fem's local order
    (hexahedra: ``skfem.io.meshio.INV_HEX_MAPPING``, not the VTK/Gmsh/Abaqus order meshio
    gives), and elements of negative volume (Jacobian determinant at the element's centre)
    mirrored, so every element has a positive volume in scikit-fem's order."""
    cell_type, t = selected
    mesh_type, nv, element, order = _SOLIDS[cell_type]
    t = np.asarray(t, dtype=np.int64)[:, order]
    used, t = np.unique(t, return_inverse=True)
    t = t.reshape(-1, len(order))
    points = np.asarray(raw.points, dtype=float)[used]
    if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise InputError(f"{what}: node coordinates are not finite 3D points")

    negative = _signed_volume(points, t, element) < 0
    if negative.any():
        t[negative] = t[negative][:, _mirrored(element)]
        log.debug("%s: %d elements of negative volume reordered", what, int(negative.sum()))

    p = np.ascontiguousarray(points.T)
    mesh = mesh_type(p, np.ascontiguousarray(t.T))
    return _checked(mesh, p, t, nv, used, len(raw.points), what)


def _signed_volume(points: np.ndarray, t: np.ndarray, element) -> np.ndarray:
    """The Jacobian determinant of each element (n, nodes) in scikit-fem's local order at
    the reference element's centre: its sign is the element's orientation."""
    elem = element()
    nv = elem.refdom.nnodes
    centre = np.asarray(elem.doflocs[:nv], dtype=float).mean(axis=0)[:, None]
    dphi = np.array([elem.lbasis(centre, k)[1][:, 0] for k in range(t.shape[1])])  # (k, 3)
    J = np.einsum("eki,kj->eij", points[t], dphi)
    return np.linalg.det(J)


def _mirrored(element) -> list[int]:
    """The local node order that mirrors an element onto itself (its volume's sign flips):
    the reference tetrahedron's x and y swapped, the reference cube's x -> 1 - x."""
    d = np.asarray(element.doflocs, dtype=float)
    tet = element in (ElementTetP1, ElementTetP2)
    image = d[:, [1, 0, 2]] if tet else d * [-1, 1, 1] + [1, 0, 0]
    return [int(np.flatnonzero(np.all(np.abs(d - x) < 1e-12, axis=1))[0]) for x in image]


# -- boundaries ------------------------------------------------------------------------------------


def _boundaries(raw, groups: list[_Group], mesh: Mesh, old_to_vertex: np.ndarray
                ) -> dict[str, np.ndarray]:
    """name -> the mesh's boundary facets on that group, for the groups that touch any."""
    facets = mesh.boundary_facets().astype(np.int64)
    ends = np.sort(mesh.facets[:, facets], axis=0).astype(np.int64)
    nv = mesh.nvertices
    order = np.argsort(ends[0] * nv + ends[1])
    keys, sorted_facets = (ends[0] * nv + ends[1])[order], facets[order]

    def matching(pairs: np.ndarray) -> np.ndarray:
        v = old_to_vertex[pairs]
        v = np.sort(v[(v >= 0).all(axis=1)], axis=1)
        if not len(v) or not len(keys):
            return np.array([], dtype=np.int64)
        wanted = v[:, 0] * nv + v[:, 1]
        pos = np.minimum(np.searchsorted(keys, wanted), len(keys) - 1)
        return sorted_facets[pos[keys[pos] == wanted]]

    found: dict[str, np.ndarray] = {}
    for g in groups:
        if g.nodes is not None:  # NSET: the facets with both ends in the set
            inside = np.zeros(nv, dtype=bool)
            v = old_to_vertex[g.nodes[(g.nodes >= 0) & (g.nodes < len(old_to_vertex))]]
            inside[v[v >= 0]] = True
            hit = facets[inside[ends[0]] & inside[ends[1]]]
        else:
            lines = [np.asarray(raw.cells[k].data)[ids][:, :2] for k, ids in g.blocks.items()
                     if raw.cells[k].type in _LINES]
            if not lines:
                continue
            hit = matching(np.vstack(lines).astype(np.int64))
        if hit.size:
            found[g.name] = np.union1d(found.get(g.name, np.array([], np.int64)), hit)
        else:
            log.debug("%s %r touches none of this body's boundary facets", g.kind, g.name)
    return {name: f.astype(np.int64) for name, f in found.items()}


def _boundaries_3d(raw, groups: list[_Group], mesh: Mesh, old_to_vertex: np.ndarray
                   ) -> dict[str, np.ndarray]:
    """:func:`_boundaries` of a volume mesh: the boundary facets (triangles or quadrilaterals)
    that coincide with a group's face elements (matched by their corner nodes: Gmsh physical
    surfaces, Abaqus ELSETs of triangles or quadrilaterals), or whose corners all lie in an
    NSET."""
    facets = mesh.boundary_facets().astype(np.int64)
    corners = np.sort(mesh.facets[:, facets].T, axis=1).astype(np.int64)  # (nb, 3 or 4)
    k = corners.shape[1]
    nv = mesh.nvertices

    def matching(faces: np.ndarray) -> np.ndarray:
        v = old_to_vertex[faces]
        v = np.sort(v[(v >= 0).all(axis=1)], axis=1)
        if not len(v) or not len(corners):
            return np.array([], dtype=np.int64)
        _, inverse = np.unique(np.vstack([corners, v]), axis=0, return_inverse=True)
        inverse = inverse.ravel()
        return facets[np.isin(inverse[: len(corners)], inverse[len(corners):])]

    found: dict[str, np.ndarray] = {}
    for g in groups:
        if g.nodes is not None:  # NSET: the facets with every corner in the set
            inside = np.zeros(nv, dtype=bool)
            v = old_to_vertex[g.nodes[(g.nodes >= 0) & (g.nodes < len(old_to_vertex))]]
            inside[v[v >= 0]] = True
            hit = facets[inside[corners].all(axis=1)]
        else:
            faces = [np.asarray(raw.cells[b].data)[ids][:, :k] for b, ids in g.blocks.items()
                     if _FACES.get(raw.cells[b].type) == k]
            if not faces:
                continue
            hit = matching(np.vstack(faces).astype(np.int64))
        if hit.size:
            found[g.name] = np.union1d(found.get(g.name, np.array([], np.int64)), hit)
        else:
            log.debug("%s %r touches none of this body's boundary facets", g.kind, g.name)
    return {name: f.astype(np.int64) for name, f in found.items()}
