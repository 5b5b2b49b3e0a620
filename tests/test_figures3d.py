"""The figures of a 3D model's run (issue 39, item 5; :mod:`vfem.io.figures3d`): a pressure map
per body in contact, with friction a stick/slip map, the deformed outlines, von Mises on the
surfaces, and a line for each figure not drawn and why — drawn by ``vfem run`` and the same
redrawn by ``vfem plot``; then the geometry they stand on (the plane fit, the boundary faces of
hexahedral and tetrahedral boxes, the feature edges).

The model: a small block pressed into a base and pushed sideways (Coulomb friction), and a
third body that never touches anything, so its pressure map is left out with a note.
"""

from __future__ import annotations

import contextlib
import io
import json
import types

import numpy as np
import pytest

from models import box_mesh, input_file, prescribed, support, toml_body
from vfem.cli import main
from vfem.io import figures3d
from vfem.io.figures3d import boundary_faces, outline_edges, plane_fit, view_axes

pytest.importorskip("matplotlib")

MODEL = input_file(
    "tiny3d",
    toml_body("base", box_mesh(x0=-1.0, y0=-1.0, z0=-0.5, width=2.0, depth=2.0, height=0.5,
                               nx=4, ny=4, nz=1), support("bottom"), contact_boundaries=["top"]),
    toml_body("block", box_mesh(x0=-0.3, y0=-0.3, z0=0.0, width=0.6, depth=0.6, height=0.3,
                                nx=3, ny=3, nz=1),
              prescribed("top", "z", -0.005), prescribed("top", "x", 0.0005),
              prescribed("top", "y", 0.0), contact_boundaries=["bottom"]),
    toml_body("far", box_mesh(x0=2.0, y0=2.0, z0=0.5, width=0.3, depth=0.3, height=0.3, nx=1,
                              ny=1, nz=1, tetrahedra=True), support("bottom"),
              contact_boundaries=["bottom"]),
    contact={"friction": 0.3}, load_factors=[1.0])
DRAWN = {"pressure_base.png", "pressure_block.png", "stick_slip_block.png", "deformed.png",
         "history.png", "von_mises.png"}


def _main(*args) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = main(list(args))
    return status, err.getvalue()


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The model run by ``vfem run`` (its folder and what it printed on stderr)."""
    root = tmp_path_factory.mktemp("figures3d")
    path = root / "tiny3d.toml"
    path.write_text(MODEL, encoding="utf-8")
    status, err = _main("run", str(path), "--out", str(root / "out"))
    assert status == 0, err
    return root / "out", err


def _not_drawn(err: str) -> list[str]:
    return [line.removeprefix("vfem: not drawn: ") for line in err.splitlines()
            if line.startswith("vfem: not drawn: ")]


def test_a_3d_run_draws_its_figures_and_vfem_plot_redraws_them(run):
    """The run draws the pressure maps of the two bodies in contact, the stick/slip map of the
    block (whose nodes carry the pair's compatibility), the deformed outlines, von Mises and
    the history; summary.json lists them; ``vfem plot`` redraws the same set."""
    out, _ = run
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert set(summary["figures"]) == DRAWN
    assert {p.name for p in out.glob("*.png")} == DRAWN
    assert all((out / name).stat().st_size > 10_000 for name in DRAWN)
    for p in out.glob("*.png"):
        p.unlink()
    status, err = _main("plot", str(out))
    assert status == 0, err
    assert {p.name for p in out.glob("*.png")} == DRAWN
    assert _not_drawn(err) == summary["figures_notes"]


def test_what_is_not_drawn_is_recorded_and_said(run):
    """The body that never touches has no pressure or stick/slip map, the base (whose nodes
    carry no pair's compatibility) no stick/slip map: one line each, recorded in summary.json
    and printed by ``vfem run`` as ``vfem: not drawn: <figure>: <why>``."""
    out, err = run
    notes = json.loads((out / "summary.json").read_text(encoding="utf-8"))["figures_notes"]
    assert _not_drawn(err) == notes
    assert {n.split(":")[0] for n in notes} == {"pressure_far.png", "stick_slip_far.png",
                                                "stick_slip_base.png"}
    far = next(n for n in notes if n.startswith("pressure_far.png"))
    assert "no node of 'far' in contact at step 1" in far and "most loaded" in far
    assert figures3d.MOST_LOADED in far
    assert "compatibility" in next(n for n in notes if n.startswith("stick_slip_base.png"))


def test_too_many_faces_for_von_mises_is_a_note(run, monkeypatch, tmp_path):
    """Over :data:`MAX_FACES` boundary faces, von_mises.png is not drawn, and a note says how
    many and where to look instead."""
    from vfem.io.replot import Folder

    monkeypatch.setattr(figures3d, "MAX_FACES", 10)
    notes: list[str] = []
    step = Folder(run[0]).steps[-1]
    assert figures3d._von_mises_figure(tmp_path / "vm.png", step, {}, np.eye(3)[2], "", 1.0,
                                       notes) is None
    assert not (tmp_path / "vm.png").exists()
    assert len(notes) == 1 and notes[0].startswith("von_mises.png: ")
    assert "more than the 10" in notes[0] and "ParaView" in notes[0]


# -- geometry ----------------------------------------------------------------------------------


def test_plane_fit_gives_a_tilted_planes_normal_to_round_off():
    rng = np.random.default_rng(3)
    n = np.array([np.sin(0.4) * np.cos(1.1), np.sin(0.4) * np.sin(1.1), np.cos(0.4)])
    e1 = np.cross(n, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    st = rng.uniform(-1.0, 1.0, (40, 2))
    points = np.array([0.3, -2.0, 5.0]) + st[:, :1] * e1 + st[:, 1:] * e2
    centre, fitted, s = plane_fit(points)
    np.testing.assert_allclose(fitted, n, atol=1e-14)  # signed: its largest component > 0
    np.testing.assert_allclose(centre, points.mean(axis=0), atol=1e-14)
    assert s[2] < 1e-13 * s[0]
    u, v, normal = view_axes(fitted)  # 23 degrees off z: its own axes, not x and y
    np.testing.assert_allclose(normal, n, atol=1e-14)
    np.testing.assert_allclose(np.array([u, v, normal]) @ np.array([u, v, normal]).T, np.eye(3),
                               atol=1e-14)
    assert figures3d.axis_label(u).startswith("along (")
    u, v, normal = view_axes([0.01, -0.02, -1.0])  # within 5 degrees of z: the x-y plane
    assert (figures3d.axis_label(u), figures3d.axis_label(v), figures3d.axis_label(normal)) == (
        "x", "y", "z")


def hex_box(nx: int, ny: int, nz: int) -> tuple[np.ndarray, np.ndarray]:
    """A structured box of nx by ny by nz hexahedra (VTK's corner order)."""
    grid = np.stack(np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0), np.arange(nz + 1.0),
                                indexing="ij"), axis=-1).reshape(-1, 3)
    idx = np.arange(len(grid)).reshape(nx + 1, ny + 1, nz + 1)
    c = [idx[i:i + nx, j:j + ny, k:k + nz].ravel()
         for i, j, k in ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
                         (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1))]
    return grid, np.column_stack(c)


#: each hexahedron as six tetrahedra around its diagonal 0-6 (a conforming split)
KUHN = ((0, 1, 2, 6), (0, 2, 3, 6), (0, 3, 7, 6), (0, 7, 4, 6), (0, 4, 5, 6), (0, 5, 1, 6))


@pytest.mark.parametrize("n", [(1, 1, 1), (3, 4, 5), (6, 2, 1)])
def test_boundary_faces_of_a_box_are_its_outer_faces_turned_out(n):
    nx, ny, nz = n
    x, hexes = hex_box(nx, ny, nz)
    quads = 2 * (nx * ny + ny * nz + nz * nx)
    tets = hexes[:, np.array(KUHN)].reshape(-1, 4)
    for cells, cell_type, count in ((hexes, "hexahedron", quads), (tets, "tetra", 2 * quads),
                                    (np.hstack([hexes, hexes, hexes[:, :11]]), "hexahedron27",
                                     quads),
                                    (np.hstack([tets, tets[:, :2], tets]), "tetra10",
                                     2 * quads)):
        faces, owner = boundary_faces(cells, cell_type, x)
        assert len(faces) == count and len(owner) == count
        centre = x.mean(axis=0)
        normal = figures3d._normals(x, faces)
        assert np.all(np.einsum("ij,ij->i", normal, x[faces].mean(axis=1) - centre) > 0)
        assert np.allclose(normal.sum(axis=0), 0.0)  # a closed surface
        assert abs(0.5 * np.linalg.norm(normal, axis=1).sum() - quads) < 1e-9  # unit squares
    assert boundary_faces(hexes, "wedge") is None


def test_the_outline_of_a_box_is_its_twelve_edges():
    """Seen along an axis, a box's outline is its edges (the folds of 90 degrees) and nothing
    of its flat faces, tetrahedra or hexahedra; a cylinder seen from its side adds its
    silhouette."""
    nx, ny, nz = 3, 4, 2
    x, hexes = hex_box(nx, ny, nz)
    for cells, kind in ((hexes, "hexahedron"), (hexes[:, np.array(KUHN)].reshape(-1, 4),
                                                  "tetra")):
        faces, _ = boundary_faces(cells, kind, x)
        (edges,) = outline_edges(x, faces, [np.array([0.0, -1.0, 0.0])])
        assert len(edges) == 4 * (nx + ny + nz)
        bound = np.isclose(x[edges], 0.0) | np.isclose(x[edges], [nx, ny, nz])  # (e, 2, 3)
        assert np.all(bound.all(axis=1).sum(axis=1) >= 2)  # each on two of the box's faces
    # a 16-sided prism (one layer of hexahedra around its axis z): seen along y its outline
    # is its two end polygons (the folds) and the silhouette, two lines along z
    t = np.linspace(0.0, 2.0 * np.pi, 17)[:-1]
    ring = np.column_stack([np.cos(t), np.sin(t)])
    x = np.vstack([np.column_stack([r * ring, np.full(16, z)]) for z in (0.0, 1.0)
                   for r in (0.5, 1.0)])
    k = np.arange(16)
    j = (k + 1) % 16
    hexes = np.column_stack([k, 16 + k, 16 + j, j, 32 + k, 48 + k, 48 + j, 32 + j])
    faces, _ = boundary_faces(hexes, "hexahedron", x)
    (edges,) = outline_edges(x, faces, [np.array([0.0, -1.0, 0.0])])
    vertical = x[edges[:, 0], 2] != x[edges[:, 1], 2]
    assert np.sum(~vertical) == 4 * 16  # the end rings, inner and outer, top and bottom
    np.testing.assert_allclose(np.sort(x[edges[vertical, 0], 0]), [-1.0, -0.5, 0.5, 1.0],
                               atol=1e-12)  # the silhouettes of the outer and inner sides


# -- the reviewer's cases (issue 39, item 5's review) --------------------------------------------

#: a unit cube's corners in VTK's hexahedron order
CUBE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1],
                 [0, 1, 1]], dtype=float)
TETRA = CUBE[[0, 1, 3, 4]]


def quadratic_cell(cell_type: str) -> tuple[np.ndarray, np.ndarray]:
    """One quadratic cell's points (corners, then mid-side nodes at the middle of what they lie
    between, then hexahedron27's body centre) and its (1, k) connectivity."""
    corners = TETRA if cell_type == "tetra10" else CUBE
    x = np.vstack([corners] + [corners[list(m)].mean(axis=0) for m in figures3d.MIDS[cell_type]]
                  + ([corners.mean(axis=0)] if cell_type == "hexahedron27" else []))
    return x, np.arange(len(x))[None, :]


def frame(x: np.ndarray, cells: np.ndarray, cell_type: str, name: str = "b", **point_data):
    return types.SimpleNamespace(points=x, polygons=cells, cell_type=cell_type, name=name,
                                 point_data=point_data, displacement=np.zeros_like(x),
                                 cell_data={})


def candidates(x: np.ndarray, touching) -> types.SimpleNamespace:
    """The nodes at z = 0 as contact candidates (contact.csv's), ``touching`` in contact."""
    node = np.flatnonzero(np.isclose(x[:, 2], 0.0) | np.isin(np.arange(len(x)), touching))
    on = np.isin(node, touching)
    return types.SimpleNamespace(node=node, contact=on, pressure=np.where(on, 2.0, 0.0))


def maps(tmp_path, body, contact) -> tuple[list, list[str]]:
    """:func:`figures3d._contact_maps` of ``body`` alone, at one step, into ``tmp_path``."""
    folder = types.SimpleNamespace(directory=tmp_path, contact_source="contact.csv",
                                   contact=lambda step, b: contact)
    step = types.SimpleNamespace(bodies=[body], step=1, load_factor=1.0)
    notes: list[str] = []
    written, _ = figures3d._contact_maps(folder, step, [1.0], {}, "", notes)
    return written, notes


@pytest.mark.parametrize("cell_type, node, triangles", [
    ("tetra10", 4, 4),  # the mid-edge node between corners 0 and 1 (the reviewer's)
    ("hexahedron20", 8, 6),  # the mid-edge node between corners 0 and 1
    ("hexahedron27", 24, 8)])  # the bottom face's centre
def test_a_mid_side_node_alone_in_contact_is_drawn_and_counted(tmp_path, cell_type, node,
                                                               triangles):
    """Only a quadratic cell's mid-side node in contact: the face it lies on is the contact
    surface, that node drawn and counted among the nodes in contact, the face split through its
    mid-side nodes (so the contours show their pressure), and the pressure map drawn."""
    x, cells = quadratic_cell(cell_type)
    body = frame(x, cells, cell_type)
    contact = candidates(x, [node])
    (s,) = figures3d.surfaces(body, contact, figures3d.boundary_faces(cells, cell_type, x))
    assert int(s.contact.sum()) == 1 and s.nodes[s.contact].tolist() == [node]
    np.testing.assert_array_equal(s.nodes, contact.node)  # the bottom face's every node
    assert len(s.triangles) == triangles and s.pressure.max() == 2.0
    assert len(s.edges) == (6 if cell_type == "tetra10" else 8)  # through the mid-edge nodes
    assert figures3d.axis_label(s.axes[2]) == "z"
    written, notes = maps(tmp_path, body, contact)
    assert [p.name for p in written] == ["pressure_b.png"] and notes == []


def test_nodes_in_contact_on_no_candidate_face_are_a_note(tmp_path):
    """A body whose nodes in contact lie on none of the faces of its candidates (here the
    mid-edge node between corner 0, a candidate, and 3, not one) has no surface to map: its
    pressure and stick/slip maps are left out with a note, not a crash."""
    x, cells = quadratic_cell("tetra10")
    body = frame(x, cells, "tetra10", friction_status=np.zeros(len(x)))
    contact = candidates(x, [7])
    assert figures3d.surfaces(body, contact, figures3d.boundary_faces(cells, "tetra10", x)) == []
    written, notes = maps(tmp_path, body, contact)
    assert written == [] and [n.split(":")[0] for n in notes] == ["pressure_b.png",
                                                                 "stick_slip_b.png"]
    assert "no boundary face of 'b' holds its nodes in contact (1 at step 1" in notes[0]


def test_the_most_loaded_step_sums_the_nodal_forces_sizes():
    """Contact that balances itself (a plate squeezed from both sides: its resultant zero)
    loads a step more than a small unbalanced force does."""
    def step(*forces):
        return types.SimpleNamespace(bodies=[types.SimpleNamespace(
            points=np.zeros((len(forces), 3)), point_data={"contact_force": np.array(forces)})])

    squeezed = step([0.0, 0.0, 10.0], [0.0, 0.0, -10.0], [0.0, 0.0, 0.0])
    nudged = step([1e-3, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    assert figures3d.total_contact_force(squeezed) == pytest.approx(20.0)
    assert figures3d.total_contact_force(nudged) == pytest.approx(1e-3)
    assert "sum of nodal contact force magnitudes" in figures3d.MOST_LOADED


def test_the_deformed_outlines_fill_their_panels_far_from_the_origin(tmp_path, monkeypatch):
    """A model at x, y, z = 1000-1003: each panel's window is the model's extent (padded),
    not stretched to take in the origin."""
    x, hexes = hex_box(3, 3, 1)
    body = frame(x + 1000.0, hexes, "hexahedron")
    windows = []
    window = figures3d._window
    monkeypatch.setattr(figures3d, "_window", lambda ax, xy: (window(ax, xy), windows.append(
        ax.get_xlim() + ax.get_ylim())))
    step = types.SimpleNamespace(bodies=[body], step=1, load_factor=1.0)
    figures3d._deformed(tmp_path, step, {}, np.eye(3)[2], "", 1.0)
    assert len(windows) == 2
    for lo_x, hi_x, lo_y, hi_y in windows:
        assert 999.8 < lo_x < 1000.0 and 1003.0 < hi_x < 1003.2
        assert 999.8 < lo_y < 1000.0 and 1001.0 < hi_y < 1001.2  # x or y across, z up


def test_2d_and_3d_figures_share_one_edge_table_and_one_friction_legend(tmp_path, monkeypatch):
    """plots' edge table (:func:`vfem.io.plots.polygon_edges`) makes both the 2D outlines and
    the 3D folds, and plots' friction markers mark the 3D stick/slip maps: one implementation
    each. The 2D outline is the edges of one cell only, in ascending order."""
    from vfem.io import plots

    calls = []
    edges = plots.polygon_edges
    monkeypatch.setattr(plots, "polygon_edges", lambda p: calls.append(len(p)) or edges(p))
    quads = np.array([[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]])
    outline = plots._outline(quads)
    assert outline.tolist() == [[0, 1], [0, 3], [1, 2], [2, 5], [3, 6], [5, 8], [6, 7], [7, 8]]
    x, hexes = hex_box(1, 1, 1)
    faces, _ = boundary_faces(hexes, "hexahedron", x)
    (folds,) = outline_edges(x, faces, [np.array([0.0, 0.0, 1.0])])
    assert len(folds) == 12 and calls == [4, 6]
    markers = tuple((v, f"status {v}", style) for v, _, style in plots.FRICTION_MARKERS)
    monkeypatch.setattr(plots, "FRICTION_MARKERS", markers)
    drawn = []
    monkeypatch.setattr(figures3d, "_finish", lambda plt, fig, path, title: (drawn.append(
        fig.axes[0].get_legend_handles_labels()[1]), plt.close(fig)))
    x, cells = quadratic_cell("tetra10")
    s = figures3d.surfaces(frame(x, cells, "tetra10"), candidates(x, [0, 4]),
                           boundary_faces(cells, "tetra10", x))
    figures3d._stick_figure(tmp_path / "s.png", s, np.array([1, 0, -1, 0, 2, 0, 0, 0, 0, 0]), "")
    assert drawn == [["status -1 (1)", "status 0 (3)", "status 2 (1)", "status 1 (1)"]]


NO_CONTACT = input_file(
    "apart",
    toml_body("cube", box_mesh(x0=0.0, y0=0.0, z0=0.0, width=1.0, depth=1.0, height=1.0, nx=1,
                               ny=1, nz=1), support("bottom"), prescribed("top", "z", -0.01)),
    toml_body("wedge", box_mesh(x0=3.0, y0=0.0, z0=0.0, width=1.0, depth=1.0, height=0.5, nx=1,
                                ny=1, nz=1, tetrahedra=True), support("bottom"),
              prescribed("top", "x", 0.01)),
    load_factors=[1.0]).replace('name = "wedge"', 'name = "wedge"\norder = 2')


@pytest.mark.slow
def test_a_run_with_no_contact_anywhere_notes_every_pressure_map(tmp_path):
    """Two bodies that never touch (one of quadratic tetrahedra): each pressure map is left
    out with a note; the deformed outlines, von Mises and the history are drawn. The quadratic
    body's faces' mid-side nodes (:func:`figures3d.face_nodes`) are its edges' middles, as vfem
    writes them."""
    from vfem.io.replot import Folder

    path = tmp_path / "apart.toml"
    path.write_text(NO_CONTACT, encoding="utf-8")
    status, err = _main("run", str(path), "--out", str(tmp_path / "out"))
    assert status == 0, err
    summary = json.loads((tmp_path / "out" / "summary.json").read_text(encoding="utf-8"))
    assert set(summary["figures"]) == {"deformed.png", "von_mises.png", "history.png"}
    assert summary["figures_notes"] == _not_drawn(err) == [
        f"pressure_{b}.png: no node of '{b}' in contact at any step" for b in ("cube", "wedge")]
    wedge = Folder(tmp_path / "out").steps[-1].bodies[1]
    assert wedge.cell_type == "tetra10"
    faces, owner = boundary_faces(wedge.polygons, "tetra10", wedge.points)
    full = figures3d.face_nodes(wedge.polygons, "tetra10", faces, owner)
    assert full.shape == (len(faces), 6)
    x = wedge.points
    np.testing.assert_allclose(x[full[:, 3:]], 0.5 * (x[faces] + x[np.roll(faces, -1, axis=1)]))
