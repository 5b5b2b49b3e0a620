"""How the 2D figures are drawn fast (issue 40): every figure written by vfem.io.plots.save, laid
out tight and drawn once, into the same pixels as matplotlib's own tight_layout + savefig, which
draws it twice; cells filled as one image (vfem.io.plots._fill), each pixel the colour of the
cell its centre lies in."""

import numpy as np
import pytest

pytest.importorskip("matplotlib")


def _figure(plt):
    from matplotlib.collections import PolyCollection

    rng = np.random.default_rng(1)
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.add_collection(PolyCollection(rng.random((500, 3, 2)), array=rng.random(500)),
                      autolim=False)
    ax.set_title("cells")
    fig.colorbar(ax.collections[0], ax=ax)
    return fig


def test_a_figure_is_drawn_once_into_the_same_pixels(tmp_path, monkeypatch):
    import matplotlib.image as mi
    from matplotlib.figure import Figure

    from vfem.io import plots

    plt = plots.require_matplotlib()
    draws = []
    real = Figure.draw
    monkeypatch.setattr(Figure, "draw", lambda self, r: draws.append(1) or real(self, r))

    fig = _figure(plt)
    fig.tight_layout()
    fig.savefig(tmp_path / "matplotlib.png", dpi=130)
    plt.close(fig)
    twice = len(draws)
    draws.clear()
    plots.save(plt, _figure(plt), tmp_path / "vfem.png")

    assert len(draws) == 1 <= twice  # (matplotlib 3.6 to 3.11 at least: twice == 2)
    np.testing.assert_array_equal(mi.imread(tmp_path / "vfem.png"),
                                  mi.imread(tmp_path / "matplotlib.png"))


def test_cells_filled_as_an_image_take_the_pixels_whose_centres_they_hold():
    """_fill against a point-in-polygon test of every pixel centre: random convex quadrilaterals
    and triangles (either orientation) that do not overlap, some beyond the window; a centre
    in a cell takes its colour, one in none stays transparent. (A centre on an edge could go to
    either cell: none of these lies within round-off of one.)"""
    from matplotlib.path import Path as Curve

    from vfem.io import plots

    plt = plots.require_matplotlib()
    rng = np.random.default_rng(3)
    window = (0.0, 2.0, 0.0, 1.0)
    layers, cells = [], []
    for k in (3, 4):
        polys, colours = [], []
        for cx in np.arange(-0.15, 2.2, 0.3):
            for cy in np.arange(0.1 if k == 3 else 0.25, 1.2, 0.3):
                angles = np.sort(rng.uniform(0, 2 * np.pi, k))
                poly = np.column_stack([cx + 0.07 * np.cos(angles), cy + 0.07 * np.sin(angles)])
                polys.append(poly if rng.random() < 0.5 else poly[::-1])
                colours.append(rng.uniform(0.1, 1.0, 4))
        layers.append((np.array(polys), np.array(colours)))
        cells += list(zip(polys, colours))
    fig, ax = plt.subplots()
    plots._fill(ax, window, layers)
    image = ax.get_images()[0].get_array()
    plt.close(fig)
    nx, ny = plots._image_shape(window)
    assert image.shape == (ny, nx, 4)
    gx, gy = np.meshgrid((np.arange(nx) + 0.5) * 2.0 / nx, (np.arange(ny) + 0.5) * 1.0 / ny)
    centres = np.column_stack([gx.ravel(), gy.ravel()])
    expected = np.zeros((ny * nx, 4))
    for poly, colour in cells:
        expected[Curve(poly).contains_points(centres)] = colour
    expected = expected.reshape(ny, nx, 4)
    np.testing.assert_array_equal(image, expected)
    assert (image[..., 3] > 0).mean() > 0.05  # something was drawn
