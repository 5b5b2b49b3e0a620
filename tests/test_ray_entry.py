"""``vfem.contact.geometry.pairing.ray_entry`` (issue 37): how far a point travels along a direction
before it enters a body through its contact surface — the test that scales a gap to the loads'
approach only where the other surface is there to meet (``approach_gaps``).

Exact references: a box's top face (z = 1.5 in 3D, y = 0 in 2D) is met from a height h along a
unit direction d at h / (-d_z); a ray that points away, passes beside the box, or leaves the
body through the face from inside meets nothing (inf). Tolerances: round-off of the
intersection (a few ulps of the box's size).
"""

import numpy as np
import pytest

from vfem.bodies import Body, Support
from vfem.contact.geometry.pairing import ray_entry
from vfem.contact.geometry.surface import ContactSurface
from vfem.materials import LinearElastic
from vfem.mesh import rectangle
from vfem.mesh.solids import box

TOL = 1e-12


def _surface3d(cells, order):
    mesh = box(0.0, 0.0, 0.0, 1.0, 2.0, 1.5, nx=2, ny=3, nz=2, tetrahedra=cells == "tet")
    body = Body("box", mesh, LinearElastic(200.0, 0.3), supports=(Support("bottom"),),
                order=order, contact_boundaries=("top",))
    return ContactSurface.build(body, mesh.boundaries["top"])


def _surface2d(order):
    mesh = rectangle(x0=0.0, y0=-1.0, width=2.0, height=1.0, nx=5, ny=2)
    body = Body("block", mesh, LinearElastic(200.0, 0.3), supports=(Support("bottom"),),
                order=order, contact_boundaries=("top",))
    return ContactSurface.build(body, mesh.boundaries["top"])


@pytest.mark.parametrize(("cells", "order"), [("tet", 1), ("hex", 1), ("tet", 2), ("hex", 2)])
def test_rays_onto_a_box_top_in_3d(cells, order):
    s = _surface3d(cells, order)
    down = np.array([0.0, 0.0, -1.0])
    slant = np.array([0.3, -0.2, -1.0]) / np.linalg.norm([0.3, -0.2, -1.0])
    points = np.array([[0.37, 1.21, 1.9],   # above the top, straight down: 0.4
                       [0.21, 0.77, 1.6],   # above, slanting: 0.1 / cos
                       [0.37, 1.21, 1.9],   # above, pointing up: never
                       [1.4, 1.0, 1.9],     # beside the box: never
                       [0.5, 1.0, 1.2]])    # inside, leaving through the top: never
    dirs = np.array([down, slant, -down, down, -down])
    t = ray_entry(s, points, dirs)
    assert t[0] == pytest.approx(0.4, abs=TOL)
    assert t[1] == pytest.approx(0.1 / -slant[2], abs=TOL)
    assert np.all(np.isinf(t[2:]))


@pytest.mark.parametrize("order", [1, 2])
def test_rays_onto_a_block_top_in_2d(order):
    s = _surface2d(order)
    slant = np.array([0.6, -0.8])
    points = np.array([[0.9, 0.25], [1.1, 0.4], [0.9, 0.25], [2.5, 0.25], [1.0, -0.5]])
    dirs = np.array([[0.0, -1.0], slant, [0.0, 1.0], [0.0, -1.0], [0.0, 1.0]])
    t = ray_entry(s, points, dirs)
    assert t[0] == pytest.approx(0.25, abs=TOL)
    assert t[1] == pytest.approx(0.4 / 0.8, abs=TOL)
    assert np.all(np.isinf(t[2:]))


@pytest.mark.parametrize("dim", [2, 3])
def test_the_nearby_pieces_first_find_what_every_piece_finds(dim, monkeypatch):
    """``ray_facet`` tests each ray against the pieces near its first ``RAY_REACH`` piece
    radii first, every piece only for the rays that enter none of those (issue 40): on a
    finely meshed face (above ``RAY_NEAR_FROM`` pieces), rays from heights of 0 to 30 piece
    sizes, some through vertices and edges (ties: the lowest piece), the same distances and
    facets, bit for bit, as every piece against every ray."""
    from vfem.contact.geometry import pairing

    if dim == 3:
        mesh = box(0.0, 0.0, 0.0, 1.0, 1.0, 0.2, nx=12, ny=12, nz=1)
        face, n_facets = "top", 144
    else:
        mesh = rectangle(x0=0.0, y0=-0.2, width=1.0, height=0.2, nx=100, ny=1)
        face, n_facets = "top", 100
    body = Body("b", mesh, LinearElastic(200.0, 0.3), supports=(Support("bottom"),),
                contact_boundaries=(face,))
    s = ContactSurface.build(body, mesh.boundaries[face])
    assert len(s.facets) == n_facets
    rng = np.random.default_rng(3)
    k = 400
    top = s.X[:, -1].max()
    xy = rng.uniform(0.0, 1.0, (k, dim - 1))
    xy[:40] = np.round(xy[:40] * 12) / 12  # over vertices and edges of the mesh
    h = top + rng.uniform(0.0, 30.0 / 12, k)
    points = np.column_stack([xy, h])
    d = np.column_stack([rng.normal(0.0, 0.15, (k, dim - 1)), -np.ones(k)])
    d[::7] *= -1  # some pointing away
    d /= np.linalg.norm(d, axis=1)[:, None]
    near = pairing.ray_facet(s, points, d)
    monkeypatch.setattr(pairing, "RAY_NEAR_FROM", 10**9)  # every piece against every ray
    every = pairing.ray_facet(s, points, d)
    assert np.isfinite(near[0]).sum() > k // 2 and np.isinf(near[0]).sum() > k // 10
    assert (np.isfinite(near[0]) & (near[0] > pairing.RAY_REACH * 0.08)).any()  # far ones too
    np.testing.assert_array_equal(near[0], every[0])
    np.testing.assert_array_equal(near[1], every[1])
