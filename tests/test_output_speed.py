"""What makes a run's output and figures cheap at any size (issue 19, items 3 and 5): VTU at
zlib level 1, the run's figures drawn from the meshes it has just written, and the cells of a
close-up too small to show drawn as an image's pixels."""

from __future__ import annotations

import zlib

import meshio
import meshio.vtu._vtu as vtu
import numpy as np
import pytest

from vfem.io import files, plots


def _mesh(n: int = 30) -> meshio.Mesh:
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    p = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * n)])
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).ravel()
    quads = np.column_stack([a, a + 1, a + n + 1, a + n])
    u = np.random.default_rng(0).normal(size=(n * n, 3))
    return meshio.Mesh(p, [("quad", quads)], point_data={"displacement": u},
                       cell_data={"von_mises": [np.arange(len(quads), dtype=float)]})


def test_vtu_is_written_at_the_chosen_zlib_level_and_reads_back_unchanged(tmp_path):
    m = _mesh()
    with files.vtu_compression(1):
        assert vtu.zlib.level == 1
        meshio.write(tmp_path / "a.vtu", m, file_format="vtu")
    assert vtu.zlib is zlib  # meshio's own module again after the block
    back = meshio.read(tmp_path / "a.vtu")
    assert np.array_equal(back.points, m.points)
    assert np.array_equal(back.point_data["displacement"], m.point_data["displacement"])
    assert np.array_equal(back.cell_data["von_mises"][0], m.cell_data["von_mises"][0])
    with files.vtu_compression(9):
        meshio.write(tmp_path / "b.vtu", m, file_format="vtu")
    # the level reached zlib: level 9 packs random data no looser than level 1
    assert (tmp_path / "b.vtu").stat().st_size <= (tmp_path / "a.vtu").stat().st_size


def test_a_written_vtu_is_taken_from_memory_until_the_file_changes_or_is_forgotten(tmp_path):
    m = _mesh()
    path = tmp_path / "body_step0001.vtu"
    meshio.write(path, m, file_format="vtu")
    files.remember_vtu(path, m, new_step=True)
    assert files.written_vtu(path) is m
    other = tmp_path / "other.vtu"
    meshio.write(other, m, file_format="vtu")
    files.remember_vtu(other, m, new_step=True)  # a new step: the first is forgotten
    assert files.written_vtu(path) is None and files.written_vtu(other) is m
    path.write_bytes(b"changed")
    meshio.write(other, _mesh(20), file_format="vtu")  # rewritten: another size
    assert files.written_vtu(other) is None
    files.remember_vtu(other, m)
    files.forget_vtus()
    assert files.written_vtu(other) is None


@pytest.mark.parametrize("n", [400])
def test_a_close_up_draws_cells_too_small_to_show_as_pixels_of_their_own_colour(tmp_path, n):
    """A fine mesh in a window: the cells narrower than FINE_CELL_PIXELS image pixels become
    an image whose pixels carry their cells' colours (a field constant per row of cells: each
    row's pixels hold its value); the coarse ones stay polygons."""
    plt = plots.require_matplotlib()
    from matplotlib.image import AxesImage

    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    p = np.column_stack([x.ravel(), y.ravel()])
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).ravel()
    quads = np.column_stack([a, a + 1, a + n + 1, a + n])
    rows = a // n  # the row of cells, 0 at the bottom
    value = rows.astype(float)
    window = (0.0, 1.0, 0.0, 1.0)
    poly = p[quads]
    fine = plots._fine(poly, window)
    assert fine.all()  # 1/399 wide against 3/1000 of the window
    cmap = plt.get_cmap("viridis")
    colours = cmap(value / value.max())
    fig, ax = plt.subplots()
    plots._pixels(ax, window, poly, colours)
    (image,) = [c for c in ax.get_children() if isinstance(c, AxesImage)]
    rgba = np.asarray(image.get_array())
    nx, ny = plots._image_shape(window)
    assert rgba.shape == (ny, nx, 4)
    assert (rgba[..., 3] > 0).all()  # the mesh covers the window: no hole
    # each image row lies within one or two rows of cells: its colour is one of theirs
    for r in (5, ny // 2, ny - 5):
        centre = (r + 0.5) / ny * (n - 1)
        allowed = {tuple(np.round(cmap(k / value.max()), 6)) for k in
                   (int(centre) - 1, int(centre), int(centre) + 1) if 0 <= k <= n - 2}
        seen = {tuple(np.round(c, 6)) for c in rgba[r, :, :4]}
        assert seen <= allowed
    plt.close(fig)
    assert not plots._fine(poly * 1000.0, window).any()  # cells wider than the window
