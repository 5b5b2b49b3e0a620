"""3D meshes from Gmsh (.msh) and Abaqus (.inp) files (issue 21, C17): vfem.mesh.imports.

The Gmsh files are made here with the gmsh Python API (the tests that need it are skipped
without it): two stacked unit blocks, the lower one over z in [-1, 0], the upper one over
[0, 1], each its own physical volume (``lower``, ``upper``), not glued (no fragment: each has
its own nodes on z = 0), with the physical surfaces ``left`` (x = 0), ``front`` (y = 0),
``bottom`` and ``top`` shared by both blocks (each body gets its own part), meshed with
hexahedra (transfinite and recombined) or tetrahedra. Written as .msh 4.1 and, by gmsh's own
writer, as .inp (``*ELSET`` of the volumes and of the faces). A TOML model on them is the
3D patch test of tests/test_patch3d.py, whose answer is known: a uniform pressure E D / 2.
Small Abaqus files without gmsh are written as text.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from skfem import Basis, MeshHex1, MeshHex2, MeshTet1, MeshTet2

from models import Raw, input_file, prescribed, rollers, support, table, toml_body
from vfem.cli import main
from vfem.errors import InputError
from vfem.mesh.imports import read_mesh

E, NU, D = 200.0, 0.3, 0.01
EXACT = E * D / 2.0  # the patch test's pressure (tests/test_patch3d.py)


# -- files -----------------------------------------------------------------------------------------


def blocks(path, lower="hex", upper="tet", n_lower=4, n_upper=3, order=1, extra=None,
           version=4.1) -> Path:
    """The two blocks written by gmsh to ``path`` (.msh of ``version`` or .inp by its
    extension).
    ``lower``/``upper``: "hex" (n divisions a side) or "tet" (size 1 / n); ``extra``:
    ``{name: (dim, [volume numbers 1 or 2])}`` more physical groups."""
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("blocks")
        occ = gmsh.model.occ
        lo = occ.addBox(0, 0, -1, 1, 1, 1)
        up = occ.addBox(0, 0, 0, 1, 1, 1)
        occ.synchronize()

        def faces(vol, axis, at):
            return [s for _, s in gmsh.model.getBoundary([(3, vol)], oriented=False)
                    if abs(occ.getCenterOfMass(2, s)[axis] - at) < 1e-9]

        for vol, kind, n in ((lo, lower, n_lower), (up, upper, n_upper)):
            surfaces = [s for _, s in gmsh.model.getBoundary([(3, vol)], oriented=False)]
            if kind == "hex":
                for s in surfaces:
                    for _, c in gmsh.model.getBoundary([(2, s)], oriented=False):
                        gmsh.model.mesh.setTransfiniteCurve(abs(c), n + 1)
                    gmsh.model.mesh.setTransfiniteSurface(s)
                    gmsh.model.mesh.setRecombine(2, s)
                gmsh.model.mesh.setTransfiniteVolume(vol)
            else:
                gmsh.model.mesh.setSize(gmsh.model.getBoundary([(3, vol)], recursive=True),
                                        1.0 / n)
        gmsh.model.addPhysicalGroup(3, [lo], name="lower")
        gmsh.model.addPhysicalGroup(3, [up], name="upper")
        gmsh.model.addPhysicalGroup(2, faces(lo, 0, 0.0) + faces(up, 0, 0.0), name="left")
        gmsh.model.addPhysicalGroup(2, faces(lo, 1, 0.0) + faces(up, 1, 0.0), name="front")
        gmsh.model.addPhysicalGroup(2, faces(lo, 2, -1.0) + faces(up, 2, 0.0), name="bottom")
        gmsh.model.addPhysicalGroup(2, faces(lo, 2, 0.0) + faces(up, 2, 1.0), name="top")
        for name, (dim, which) in (extra or {}).items():
            gmsh.model.addPhysicalGroup(dim, [(lo, up)[k - 1] for k in which], name=name)
        gmsh.model.mesh.generate(3)
        if order == 2:
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
            gmsh.model.mesh.setOrder(2)
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return Path(path)


def prisms(path) -> Path:
    """A block of 6-node prisms (a triangulated square extruded in 2 layers) as physical
    volume ``body``."""
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        square = occ.addRectangle(0, 0, 0, 1, 1)
        out = occ.extrude([(2, square)], 0, 0, 1, numElements=[2], recombine=True)
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [t for d, t in out if d == 3], name="body")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return Path(path)


#: Abaqus C3D8 corners of the unit cube (bottom counter-clockwise seen from +z, then top)
CUBE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                 [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)


def hex_inp(path, n=2, mirrored=False, element="C3D8", nodes_per_element=None) -> Path:
    """An n x n x n grid of hexahedra over the unit cube as Abaqus text: ELSET ``body``, NSETs
    ``bottom`` (z = 0) and ``top`` (z = 1). ``mirrored``: every element's nodes in the
    left-handed order (top face first), so the file's volumes are negative. ``element``: the
    Abaqus name written (``nodes_per_element`` nodes of the grid each, for refused types)."""
    s = np.linspace(0, 1, n + 1)
    x, y, z = (a.ravel() for a in np.meshgrid(s, s, s, indexing="ij"))
    number = np.arange(x.size).reshape(n + 1, n + 1, n + 1) + 1
    lines = ["*Heading", " made by tests/test_import3d.py", "*Node"]
    lines += [f"{k + 1}, {x[k]:.17g}, {y[k]:.17g}, {z[k]:.17g}" for k in range(x.size)]
    lines.append(f"*Element, type={element}, elset=body")
    count = 0
    for i in range(n):
        for j in range(n):
            for k in range(n):
                ids = [number[i + a, j + b, k + c] for a, b, c in CUBE.astype(int)]
                if mirrored:
                    ids = ids[4:] + ids[:4]
                if nodes_per_element is not None:
                    ids = (ids * 3)[:nodes_per_element]
                count += 1
                lines.append(", ".join(str(v) for v in [count, *ids]))
    for name, plane in (("bottom", z < 1e-12), ("top", z > 1 - 1e-12)):
        ids = np.flatnonzero(plane) + 1
        lines.append(f"*Nset, nset={name}")
        lines += [", ".join(str(v) for v in ids[r:r + 8]) for r in range(0, len(ids), 8)]
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


def volumes(mesh):
    """Each element's Jacobian determinant at its quadrature points (scikit-fem's order) and
    the mesh's volume."""
    basis = Basis(mesh, mesh.elem())
    det = mesh._mapping().detDF(basis.quadrature[0])
    return det, float(basis.dx.sum())


def facet_centres(mesh, name):
    return mesh.doflocs[:, mesh.facets[:, mesh.boundaries[name]]].mean(axis=1)


# -- reading ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("suffix, version", [(".msh", 4.1), (".msh", 2.2), (".inp", None)])
def test_volumes_become_bodies_and_surfaces_boundaries(tmp_path, suffix, version):
    path = blocks(tmp_path / f"blocks{suffix}", version=version or 4.1)
    if suffix == ".msh":
        assert path.read_bytes().startswith(f"$MeshFormat\n{version} ".encode())
    lower, upper = read_mesh(path, "lower"), read_mesh(path, "upper")
    assert isinstance(lower, MeshHex1) and isinstance(upper, MeshTet1)
    assert lower.nvertices == 5 ** 3 and lower.nelements == 4 ** 3
    for mesh, z0 in ((lower, -1.0), (upper, 0.0)):
        det, volume = volumes(mesh)
        assert det.min() > 0  # positive in scikit-fem's node order
        assert abs(volume - 1.0) < 1e-13
        assert np.allclose(mesh.p.min(axis=1), [0, 0, z0])
        assert {"left", "front", "bottom", "top"} <= set(mesh.boundaries)
        for name, axis, at in (("left", 0, 0.0), ("front", 1, 0.0), ("bottom", 2, z0),
                               ("top", 2, z0 + 1.0)):
            assert np.allclose(facet_centres(mesh, name)[axis], at), name
        # every boundary facet on those four faces (the others: right, back)
        named = np.concatenate([mesh.boundaries[k] for k in ("left", "front", "bottom", "top")])
        assert len(np.unique(named)) == len(named)
        assert 3 * len(named) == 2 * len(mesh.boundary_facets())
    assert all(len(lower.boundaries[k]) == 16 for k in ("left", "front", "bottom", "top"))


def test_hexahedra_in_either_handedness_come_out_positive(tmp_path):
    """The Abaqus (and VTK, Gmsh) node order of a hexahedron is not scikit-fem's
    (``MeshHex1``); elements listed left-handed are mirrored. Both files give the same mesh
    with positive Jacobians, and NSETs become the faces whose corners all lie in them."""
    meshes = [read_mesh(hex_inp(tmp_path / f"cube{m}.inp", mirrored=m), "body")
              for m in (False, True)]
    for mesh in meshes:
        assert isinstance(mesh, MeshHex1) and mesh.nelements == 8
        det, volume = volumes(mesh)
        assert det.min() > 0 and abs(volume - 1.0) < 1e-14
        assert np.allclose(det, 1 / 8)  # the map of a cube of side 1/2
        assert set(mesh.boundaries) == {"bottom", "top"}
        assert len(mesh.boundaries["bottom"]) == 4 and len(mesh.boundaries["top"]) == 4
        assert np.allclose(facet_centres(mesh, "top")[2], 1.0)
    assert np.array_equal(meshes[0].p, meshes[1].p)


def test_quadratic_volumes(tmp_path):
    """27-node hexahedra and 10-node tetrahedra (Gmsh order 2, complete): the nodes in
    scikit-fem's order (vertices, edges, faces, centres), checked by their positions."""
    path = blocks(tmp_path / "quadratic.msh", order=2)
    lower, upper = read_mesh(path, "lower"), read_mesh(path, "upper")
    assert isinstance(lower, MeshHex2) and isinstance(upper, MeshTet2)
    assert lower.doflocs.shape[1] == 9 ** 3 and lower.nvertices == 5 ** 3
    assert upper.doflocs.shape[1] == upper.nvertices + upper.edges.shape[1]
    for mesh in (lower, upper):
        det, volume = volumes(mesh)
        assert det.min() > 0 and abs(volume - 1.0) < 1e-12
        nv, ne = mesh.nvertices, mesh.edges.shape[1]
        mid = mesh.doflocs[:, mesh.edges].mean(axis=1)
        assert np.abs(mesh.doflocs[:, nv:nv + ne] - mid).max() < 1e-14
        assert len(mesh.boundaries["top"]) in (16, len(read_mesh(blocks(
            tmp_path / "linear.msh"), "upper").boundaries["top"]))
    nf = lower.facets.shape[1]
    centres = lower.doflocs[:, lower.facets].mean(axis=1)
    assert np.abs(lower.doflocs[:, 125 + lower.edges.shape[1]:][:, :nf] - centres).max() < 1e-14


def test_abaqus_quadratic_tetrahedra(tmp_path):
    path = blocks(tmp_path / "tets.inp", lower="tet", upper="tet", order=2)
    assert "C3D10" in path.read_text()
    mesh = read_mesh(path, "upper")
    assert isinstance(mesh, MeshTet2)
    det, volume = volumes(mesh)
    assert det.min() > 0 and abs(volume - 1.0) < 1e-12
    assert np.allclose(facet_centres(mesh, "top")[2], 1.0)


# -- the patch test from files ---------------------------------------------------------------------


PATCH = input_file(
    "patch3d_files",
    toml_body("lower", Raw("{lower_mesh}"), support("bottom", ["z"]), rollers(), E=Raw("{E}"),
              nu=Raw("{NU}"), contact_boundaries=["top"]),
    toml_body("upper", Raw("{upper_mesh}"), rollers(), prescribed("top", "z", Raw("{minus_D}")),
              E=Raw("{E}"), nu=Raw("{NU}"), contact_boundaries=["bottom"]),
    table("[contact]", variant="paired"))


def patch_file(path, lower_mesh, upper_mesh) -> Path:
    Path(path).write_text(PATCH.format(lower_mesh=lower_mesh, upper_mesh=upper_mesh, E=E, NU=NU,
                                       minus_D=-D))
    return Path(path)


def run(path):
    from vfem.io.input import load
    from vfem.solver import Analysis

    model = load(path).build(Path(path).parent)
    result = Analysis(model).run()
    assert result.converged, result.message
    assert [s.iterations for s in result.steps] == [1]
    assert result.steps[-1].invariants["passed"]
    return model, result.steps[-1]


def box_mesh(z0, n, cells):
    return (f'shape = "box"\nz0 = {z0}\nnx = {n}\nny = {n}\nnz = 2\n'
            + ("tetrahedra = true\n" if cells == "tet" else ""))


@pytest.mark.parametrize("suffix, lower, upper", [
    (".msh", "hex", "tet"), pytest.param(".msh", "tet", "hex", marks=pytest.mark.slow),
    pytest.param(".inp", "hex", "tet", marks=pytest.mark.slow)])
def test_the_patch_test_from_files_gives_the_built_in_answer(tmp_path, suffix, lower, upper):
    """Linear elements (3D contact supports those only). Pressure uniform to round-off on
    both sides of the non-matching interface (measured: 5e-15 relative), and the total force
    the built-in box model's."""
    mesh = blocks(tmp_path / f"blocks{suffix}", lower=lower, upper=upper)
    files = patch_file(tmp_path / "files.toml", f'file = "{mesh.name}"\ncells = "lower"',
                       f'file = "{mesh.name}"\ncells = "upper"')
    shapes = patch_file(tmp_path / "shapes.toml", box_mesh(-1.0, 4, lower), box_mesh(0.0, 3, upper))
    assert main(["-q", "check", str(files)]) == 0
    totals = []
    for path in (files, shapes):
        model, step = run(path)
        for body in model.bodies:
            r = step.bodies[body.name]
            on = r.contact_status > 0
            side = "top" if body.name == "lower" else "bottom"
            touching = np.unique(body.mesh.facets[:, body.mesh.boundaries[side]])
            assert np.array_equal(np.flatnonzero(on), touching)
            assert np.abs(r.contact_pressure[on] / EXACT - 1).max() < 1e-8
        totals.append(step.bodies["upper"].reactions["top"][2])
    assert abs(totals[0] / totals[1] - 1) < 1e-10 and abs(totals[0] + EXACT) < 1e-10


# -- refusals ------------------------------------------------------------------------------------


def refused(capsys, path, *words, command="check"):
    """``vfem check`` (or run) of ``path``: exit status 2, one line naming the problem."""
    args = [command, str(path)] + (["--out", str(Path(path).parent / "out")]
                                   if command == "run" else [])
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err
    return err


def one_body(tmp_path, mesh_lines, name="model.toml", extra="") -> Path:
    path = tmp_path / name
    path.write_text(f'name = "one"\n[[bodies]]\nname = "block"\n[bodies.mesh]\n{mesh_lines}\n'
                    '[bodies.material]\nyoungs_modulus = 1.0\npoissons_ratio = 0.3\n'
                    '[[bodies.supports]]\nboundary = "bottom"\n' + extra)
    return path


@pytest.mark.parametrize("command", ["check", "run"])
def test_a_missing_group(tmp_path, capsys, command):
    blocks(tmp_path / "blocks.msh")
    path = one_body(tmp_path, 'file = "blocks.msh"\ncells = "middle"')
    refused(capsys, path, "body 'block'", "blocks.msh", "no group named 'middle'",
            "physical volumes with 3D elements in the file: lower, upper", command=command)


def test_mixed_element_types_in_one_body(tmp_path, capsys):
    blocks(tmp_path / "blocks.msh", extra={"both": (3, [1, 2])})
    refused(capsys, one_body(tmp_path, 'file = "blocks.msh"\ncells = "both"'),
            "group 'both'", "mixes hexahedron and tetra elements", "one element type")
    refused(capsys, one_body(tmp_path, 'file = "blocks.msh"'),
            "the file mixes hexahedron and tetra", "cells = ")


@pytest.mark.parametrize("element, nodes, words", [
    ("C3D20", 20, ("hexahedron20", "C3D20", "27-node")),
    ("C3D6", 6, ("wedge", "C3D6")),
    ("C3D5", 5, ("pyramid", "C3D5")),
])
def test_unsupported_abaqus_elements(tmp_path, capsys, element, nodes, words):
    hex_inp(tmp_path / "cube.inp", n=1, element=element, nodes_per_element=nodes)
    refused(capsys, one_body(tmp_path, 'file = "cube.inp"\ncells = "body"'),
            "cube.inp", "group 'body'", "unsupported type", "tetra, hexahedron, tetra10, "
            "hexahedron27", *words)


def test_gmsh_prisms_are_refused(tmp_path, capsys):
    prisms(tmp_path / "prisms.msh")
    refused(capsys, one_body(tmp_path, 'file = "prisms.msh"\ncells = "body"'),
            "prisms.msh", "unsupported type wedge", "prisms")


def test_a_surface_of_a_3d_file_is_no_2d_body(tmp_path, capsys):
    blocks(tmp_path / "blocks.msh")
    refused(capsys, one_body(tmp_path, 'file = "blocks.msh"\ncells = "top"'),
            "group 'top' (physical surface) holds 2D elements of a 3D mesh",
            "name the physical volume", "lower, upper")


def test_a_2d_file_in_a_3d_model(tmp_path, capsys):
    """A 2D mesh file where the model's other body is 3D (a 2D file given a 3D translation:
    tests/test_input3d.py)."""
    (tmp_path / "square.inp").write_text(
        "*Node\n1, 0, 0\n2, 1, 0\n3, 1, 1\n4, 0, 1\n*Element, type=CPS4, elset=body\n"
        "1, 1, 2, 3, 4\n*Nset, nset=bottom\n1, 2\n")
    model = one_body(tmp_path, 'file = "square.inp"\ncells = "body"', extra=(
        '[[bodies]]\nname = "box"\n[bodies.mesh]\nshape = "box"\nz0 = 1.5\n'
        '[bodies.material]\nyoungs_modulus = 1.0\npoissons_ratio = 0.3\n'
        '[[bodies.supports]]\nboundary = "top"\n'))
    refused(capsys, model, "bodies must all be plane strain or all plane stress or all "
            "axisymmetric or all 3D", "'block' plane strain", "'box' 3D")


def test_read_mesh_names_file_group_and_type(tmp_path):
    path = hex_inp(tmp_path / "cube.inp", n=1, element="C3D20", nodes_per_element=20)
    with pytest.raises(InputError, match=r"mesh file '.*cube.inp': group 'body' "
                                         r"has elements of unsupported type hexahedron20"):
        read_mesh(path, "body")
