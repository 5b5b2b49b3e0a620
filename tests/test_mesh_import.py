"""Meshes from Gmsh (.msh 4.1) and Abaqus (.inp) files: vfem.mesh.imports.read_mesh.

The files are written by the tests (meshio for .msh, text for .inp), so only the gmsh-built
Hertz test needs gmsh.
"""

import importlib.util
from pathlib import Path

import meshio
import numpy as np
import pytest
from skfem import MeshQuad1, MeshQuad2, MeshTri1, MeshTri2

from vfem.errors import InputError
from vfem.mesh.imports import read_mesh

MAKE_MESH = Path(__file__).resolve().parents[1] / "examples" / "hertz_gmsh" / "make_mesh.py"


# -- small meshes ----------------------------------------------------------------------------------


def grid(x0, x1, y0, y1, nx, ny, first=0):
    """Points (n, 3) of an (nx+1) x (ny+1) grid and the index function n(i, j)."""
    x, y = np.meshgrid(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    pts = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    return pts, lambda i, j: first + i + j * (nx + 1)


def clockwise_quads(n, nx, ny):
    return np.array([[n(i, j), n(i, j + 1), n(i + 1, j + 1), n(i + 1, j)]
                     for j in range(ny) for i in range(nx)])


def triangles(n, nx, ny):
    """Two per cell: the first counter-clockwise, the second clockwise."""
    return np.array([t for j in range(ny) for i in range(nx)
                     for t in ([n(i, j), n(i + 1, j), n(i + 1, j + 1)],
                               [n(i, j), n(i, j + 1), n(i + 1, j + 1)])])


def edge(n, ks, fixed, along_x):
    return np.array([[n(k, fixed), n(k + 1, fixed)] if along_x else [n(fixed, k), n(fixed, k + 1)]
                     for k in ks])


def write_msh(path, points, blocks, names, binary=True):
    """Write a msh 4.1 file with meshio: ``blocks`` [(type, cells, physical tag)], one entity per
    block; ``names`` {name: (tag, dim)}. Nodes are put in the entities meshio needs."""
    dims = {"line": 1, "triangle": 2, "quad": 2, "triangle6": 2, "quad9": 2, "quad8": 2}
    geometrical = [np.full(len(cells), k + 1) for k, (_, cells, _) in enumerate(blocks)]
    dim_tags = np.column_stack([np.zeros(len(points), int), np.arange(len(points)) + 100])
    for order in (2, 1):  # nodes of a curve belong to the curve, the rest to a surface
        for k, (cell_type, cells, _) in enumerate(blocks):
            if dims[cell_type] == order:
                dim_tags[np.unique(cells)] = (order, k + 1)
    mesh = meshio.Mesh(
        points, [(t, c) for t, c, _ in blocks],
        cell_data={"gmsh:physical": [np.full(len(c), tag) for _, c, tag in blocks],
                   "gmsh:geometrical": geometrical},
        point_data={"gmsh:dim_tags": dim_tags},
        field_data={name: np.array(td) for name, td in names.items()},
    )
    present = {tuple(r) for r in dim_tags}
    assert all((dims[t], k + 1) in present for k, (t, _, _) in enumerate(blocks))
    meshio.write(path, mesh, file_format="gmsh", binary=binary)
    return path


NAMES = {"lower": (1, 2), "upper": (2, 2), "bottom": (3, 1), "top": (4, 1), "symmetry": (5, 1),
         "surface": (6, 1), "contact": (7, 1)}


def two_bodies(nx=4, ny=2):
    """A quadrilateral layer [0,2]x[0,1] under a triangle layer [0,2]x[1,2], no shared node, and
    one stray point. Both bodies' x = 0 edges are in one physical curve, ``symmetry``."""
    lo, n = grid(0, 2, 0, 1, nx, ny)
    up, m = grid(0, 2, 1, 2, nx, ny, first=len(lo))
    points = np.vstack([lo, up, [[5.0, 5.0, 0.0]]])
    blocks = [
        ("line", edge(n, range(nx), 0, True), 3),  # bottom
        ("line", edge(m, range(nx), ny, True), 4),  # top
        ("line", edge(n, range(ny), 0, False), 5),  # symmetry, lower
        ("line", edge(m, range(ny), 0, False), 5),  # symmetry, upper
        ("line", edge(n, range(nx), ny, True), 6),  # surface: the lower's top
        ("line", edge(m, range(nx), 0, True), 7),  # contact: the upper's bottom
        ("quad", clockwise_quads(n, nx, ny), 1),
        ("triangle", triangles(m, nx, ny), 2),
    ]
    return points, blocks


@pytest.fixture
def msh(tmp_path):
    points, blocks = two_bodies()
    return write_msh(tmp_path / "two.msh", points, blocks, NAMES)


def areas(mesh):
    x, y = mesh.doflocs[:, mesh.t]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0)


def facet_midpoints(mesh, name):
    return mesh.p[:, mesh.facets[:, mesh.boundaries[name]]].mean(axis=1)


# -- Gmsh ------------------------------------------------------------------------------------------


def test_meshio_writes_msh_41(msh):
    assert msh.read_bytes().startswith(b"$MeshFormat\n4.1 ")


def test_gmsh_quadrilateral_body(msh):
    mesh = read_mesh(msh, cells="lower")
    assert isinstance(mesh, MeshQuad1)
    assert mesh.p.shape == (2, 15) and mesh.nelements == 8
    assert np.all(areas(mesh) > 0)  # clockwise in the file
    assert np.isclose(areas(mesh).sum(), 2.0)
    assert set(mesh.boundaries) == {"bottom", "symmetry", "surface"}
    for name, axis, value, count in (("bottom", 1, 0.0, 4), ("surface", 1, 1.0, 4),
                                     ("symmetry", 0, 0.0, 2)):
        facets = mesh.boundaries[name]
        assert len(facets) == count
        assert np.all(np.isin(facets, mesh.boundary_facets()))
        assert np.allclose(mesh.p[axis, mesh.facets[:, facets]], value)
    assert np.all(mesh.p[1] <= 1.0)  # only this body's nodes


def test_gmsh_triangle_body_and_shared_name(msh):
    mesh = read_mesh(str(msh), cells="upper")
    assert isinstance(mesh, MeshTri1)
    assert mesh.p.shape == (2, 15) and mesh.nelements == 16
    assert np.all(areas(mesh) > 0)
    assert np.isclose(areas(mesh).sum(), 2.0)
    assert np.all(mesh.p[1] >= 1.0)
    assert set(mesh.boundaries) == {"top", "symmetry", "contact"}
    sym = facet_midpoints(mesh, "symmetry")
    assert len(mesh.boundaries["symmetry"]) == 2
    assert np.allclose(sym[0], 0.0) and np.all(sym[1] > 1.0)  # its own part of `symmetry`
    assert np.allclose(facet_midpoints(mesh, "contact")[1], 1.0)
    assert np.allclose(facet_midpoints(mesh, "top")[1], 2.0)


def test_gmsh_whole_file_single_type(tmp_path):
    points, blocks = two_bodies()
    blocks = [b for b in blocks if b[0] != "triangle"]
    path = write_msh(tmp_path / "lower.msh", points, blocks, NAMES, binary=False)
    mesh = read_mesh(path)  # every 2D cell: the quadrilaterals; the stray point dropped
    assert isinstance(mesh, MeshQuad1)
    assert mesh.p.shape == (2, 15)
    assert set(mesh.boundaries) == {"bottom", "symmetry", "surface"}


def quadratic_grid(nx, ny, triangles6):
    """Quadratic elements on [0,2]x[0,1], written clockwise; quad9 or triangle6."""
    pts, n = grid(0, 2, 0, 1, 2 * nx, 2 * ny)
    cells = []
    for j in range(0, 2 * ny, 2):
        for i in range(0, 2 * nx, 2):
            a, b, c, d = n(i, j), n(i, j + 2), n(i + 2, j + 2), n(i + 2, j)  # clockwise
            ab, bc, cd, da, mid = n(i, j + 1), n(i + 1, j + 2), n(i + 2, j + 1), n(i + 1, j), \
                n(i + 1, j + 1)
            if triangles6:
                cells += [[a, b, c, ab, bc, mid], [a, c, d, mid, cd, da]]
            else:
                cells.append([a, b, c, d, ab, bc, cd, da, mid])
    bottom = np.array([[n(i, 0), n(i + 2, 0), n(i + 1, 0)] for i in range(0, 2 * nx, 2)])
    return pts, np.array(cells), bottom


@pytest.mark.parametrize("kind", ["triangle6", "quad9"])
def test_gmsh_quadratic(tmp_path, kind):
    pts, cells, bottom = quadratic_grid(3, 2, kind == "triangle6")
    path = write_msh(tmp_path / "q.msh", pts, [("line", bottom[:, :2], 2), (kind, cells, 1)],
                     {"body": (1, 2), "bottom": (2, 1)})
    mesh = read_mesh(path, "body")
    assert isinstance(mesh, MeshTri2 if kind == "triangle6" else MeshQuad2)
    nv = mesh.nvertices
    assert nv == 4 * 3 and mesh.doflocs.shape[1] == len(pts)
    assert np.all(areas(mesh) > 0)
    # each facet's node sits at its midpoint: the quadratic nodes follow the reordering
    f = mesh.facets
    assert np.allclose(mesh.doflocs[:, nv + np.arange(mesh.nfacets)],
                       0.5 * (mesh.p[:, f[0]] + mesh.p[:, f[1]]))
    if kind == "quad9":
        centres = mesh.doflocs[:, nv + mesh.nfacets + np.arange(mesh.nelements)]
        assert np.allclose(centres, mesh.p[:, mesh.t].mean(axis=1))
    assert np.allclose(facet_midpoints(mesh, "bottom")[1], 0.0)
    assert len(mesh.boundaries["bottom"]) == 3


# -- Abaqus ----------------------------------------------------------------------------------------


def write_inp(path, nx=4, ny=2):
    """The two bodies as an Abaqus input file: the lower in CPE4 (clockwise, no elset on its
    *Element line), the upper in CPS3 with ``elset=Upper`` on its *Element line."""
    lo, n = grid(0, 2, 0, 1, nx, ny)
    up, m = grid(0, 2, 1, 2, nx, ny, first=len(lo))
    pts = np.vstack([lo, up])
    quads, tris = clockwise_quads(n, nx, ny), triangles(m, nx, ny)
    contact = edge(m, range(nx), 0, True)
    lines = ["*Heading", "two stacked layers", "** a comment", "*Node"]
    lines += [f"{k + 1}, {x:.6f}, {y:.6f}" for k, (x, y, _) in enumerate(pts)]
    eid = 1
    blocks = {}
    for header, cells in (("*Element, type=CPE4", quads), ("*Element, type=CPS3, elset=Upper",
                                                           tris),
                          ("*Element, type=T2D2, elset=contact", contact)):
        lines.append(header)
        blocks[header] = list(range(eid, eid + len(cells)))
        for c in cells:
            lines.append(", ".join(str(v) for v in [eid, *(c + 1)]))
            eid += 1
    lower_ids = blocks["*Element, type=CPE4"]
    lines += ["*Elset, elset=lower, generate", f"{lower_ids[0]}, {lower_ids[-1]}, 1"]
    bottom = [n(i, 0) + 1 for i in range(nx + 1)]
    symmetry = [n(0, j) + 1 for j in range(ny + 1)] + [m(0, j) + 1 for j in range(ny + 1)]
    lines += ["*Nset, nset=bottom", ", ".join(map(str, bottom))]
    lines += ["*Nset, nset=symmetry", ", ".join(map(str, symmetry))]
    lines += ["*Nset, nset=corner", str(n(nx, ny) + 1)]  # one node: touches no facet
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


def test_abaqus_bodies_and_sets(tmp_path):
    path = write_inp(tmp_path / "two.inp")
    lower = read_mesh(path, "lower")
    assert isinstance(lower, MeshQuad1) and lower.p.shape == (2, 15)
    assert np.all(areas(lower) > 0)
    assert set(lower.boundaries) == {"bottom", "symmetry"}  # contact, corner: not this body's
    assert np.allclose(facet_midpoints(lower, "bottom")[1], 0.0)
    assert len(lower.boundaries["bottom"]) == 4
    assert np.allclose(facet_midpoints(lower, "symmetry")[0], 0.0)
    assert len(lower.boundaries["symmetry"]) == 2

    upper = read_mesh(path, "upper")  # Abaqus names ignore case
    assert isinstance(upper, MeshTri1) and upper.p.shape == (2, 15)
    assert np.all(areas(upper) > 0) and np.all(upper.p[1] >= 1.0)
    assert set(upper.boundaries) == {"symmetry", "contact"}
    assert np.allclose(facet_midpoints(upper, "contact")[1], 1.0)
    assert len(upper.boundaries["contact"]) == 4
    assert np.all(facet_midpoints(upper, "symmetry")[1] > 1.0)


# -- errors ----------------------------------------------------------------------------------------


def raises(path, cells=None, *words):
    with pytest.raises(InputError) as info:
        read_mesh(path, cells)
    message = str(info.value)
    assert Path(path).name in message
    for w in words:
        assert w in message, message
    return message


def test_missing_file(tmp_path):
    raises(tmp_path / "nowhere.msh", None, "no such file")


def test_unknown_group(msh):
    message = raises(msh, "lowr", "no group named 'lowr'", "did you mean", "'lower'")
    assert "upper" in message  # the available names


def test_group_without_2d_elements(msh):
    raises(msh, "bottom", "physical curve", "no 2D elements")


def test_mixed_types(msh, tmp_path):
    raises(msh, None, "quad", "triangle", "cells =")
    raises(write_inp(tmp_path / "two.inp"), None, "quad", "triangle", "cells =")


def test_a_chosen_group_that_mixes_types_is_not_told_to_choose_itself(tmp_path):
    """Issue 17: the remedy for a group of mixed elements selected with ``cells`` is to change
    the mesh, not to select that same group again."""
    path = write_inp(tmp_path / "two.inp")
    path.write_text(path.read_text() + "*Elset, elset=both, generate\n1, 16, 1\n")
    message = raises(path, "both", "mixes quad and triangle", "one element type")
    assert "cells = 'both'" not in message


@pytest.mark.parametrize("name, content", [
    ("garbage.msh", b"this is not a mesh\n"),
    ("binary.msh", bytes(range(256)) * 4),
    ("garbage.inp", b"*Node\n1, 0.0, zero\n"),
    ("empty.inp", b""),
    ("mesh.vtk", b"# vtk DataFile\n"),
])
def test_garbage_files(tmp_path, name, content):
    path = tmp_path / name
    path.write_bytes(content)
    raises(path, None, ".msh")


def test_unsupported_type_and_not_planar(tmp_path):
    pts, n = grid(0, 1, 0, 1, 2, 2)
    quad8 = np.array([[n(0, 0), n(2, 0), n(2, 2), n(0, 2), n(1, 0), n(2, 1), n(1, 2), n(0, 1)]])
    path = write_msh(tmp_path / "q8.msh", pts, [("quad8", quad8, 1)], {"body": (1, 2)})
    raises(path, "body", "quad8", "unsupported")
    pts[:, 2] = pts[:, 0]
    quads = clockwise_quads(n, 2, 2)
    path = write_msh(tmp_path / "tilted.msh", pts, [("quad", quads, 1)], {"body": (1, 2)})
    raises(path, None, "not planar")


# -- the Gmsh-built Hertz example (needs gmsh) ---------------------------------------------------


def load_make_mesh():
    spec = importlib.util.spec_from_file_location("hertz_make_mesh", MAKE_MESH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_make_mesh_without_gmsh(monkeypatch, capsys):
    module = load_make_mesh()
    monkeypatch.setitem(__import__("sys").modules, "gmsh", None)  # import gmsh fails
    assert module.main(["--out", "unused.msh"]) == 2
    assert "pip install gmsh" in capsys.readouterr().err


def test_hertz_gmsh_bodies(tmp_path):
    pytest.importorskip("gmsh")
    path = load_make_mesh().build(tmp_path / "hertz.msh", size=0.02, max_size=0.2)
    assert path.read_bytes().startswith(b"$MeshFormat\n4.1 ")
    cylinder = read_mesh(path, "cylinder")
    flat = read_mesh(path, "flat")
    assert isinstance(cylinder, MeshTri1) and isinstance(flat, MeshQuad1)
    assert {"contact", "symmetry", "top"} <= set(cylinder.boundaries)
    assert {"surface", "bottom", "symmetry"} <= set(flat.boundaries)
    for mesh in (cylinder, flat):
        assert np.all(areas(mesh) > 0)
        assert np.sum(np.hypot(*mesh.p) < 1e-12) == 1  # each body its own node at the origin
        assert np.allclose(facet_midpoints(mesh, "symmetry")[0], 0.0)
    arc = cylinder.p[:, cylinder.facets[:, cylinder.boundaries["contact"]]]
    assert np.allclose(np.hypot(arc[0], arc[1] - 1.0), 1.0)
    assert np.allclose(facet_midpoints(flat, "surface")[1], 0.0)
    assert np.allclose(facet_midpoints(flat, "bottom")[1], -0.1)


def test_hertz_gmsh_peak_pressure(tmp_path):
    """The Hertz example on the gmsh meshes (default sizes): p_max within 1 % of Hertz."""
    pytest.importorskip("gmsh")
    from vfem.bodies import Body, Platen, Support
    from vfem.contact.settings import ContactSettings
    from vfem.materials import LinearElastic
    from vfem.solver import Analysis, Model

    path = load_make_mesh().build(tmp_path / "hertz.msh")
    cylinder = Body("cylinder", read_mesh(path, "cylinder"), LinearElastic(1e6, 0.2),
                    supports=(Support("symmetry", ("x",)),),
                    platen=Platen("top", "y", -1530.0), contact_boundaries=("contact",))
    flat = Body("flat", read_mesh(path, "flat"), LinearElastic(3e9, 0.2),
                supports=(Support("bottom", ("x", "y")), Support("symmetry", ("x",))),
                contact_boundaries=("surface",))
    model = Model("hertz-gmsh", [cylinder, flat], ContactSettings(), (0.2, 0.4, 0.6, 0.8, 1.0))
    result = Analysis(model).run()
    assert result.converged
    p_max = result.steps[-1].bodies["cylinder"].contact_pressure.max()
    assert abs(p_max / 31847.7 - 1) < 0.01


def test_a_node_set_off_the_outline_is_no_boundary_and_naming_it_is_refused(tmp_path):
    """NSET ``corner`` holds one node, so it covers no facet of the lower body's outline: the
    body has no such boundary, and a support on it is refused with the names it has."""
    from vfem import Body, LinearElastic, Support

    lower = read_mesh(write_inp(tmp_path / "two.inp"), "lower")
    assert "corner" not in lower.boundaries
    body = Body("lower", lower, LinearElastic(1.0, 0.3), supports=(Support("corner"),))
    with pytest.raises(InputError, match="no boundary named 'corner'; the mesh has bottom, "
                                         "symmetry"):
        body.validate()


@pytest.mark.parametrize("name, words", [
    ("unmerged", ("3 pair(s) of nodes at the same position", "(0, 1)")),
    ("pieces", ("2 separate pieces",)),
    ("inverted", ("inverted", "(1.6, 0.3)")),
])
def test_mesh_checks_name_the_file(name, words):
    raises(Path(__file__).parent / "data" / "meshes" / f"{name}.inp", "body", *words)

