"""Closest-point projection and point location in the rind."""

import numpy as np
from skfem import MeshTri

from vfem.bodies import Body, Support
from vfem.contact.search import outward_normals, project_points
from vfem.contact.surface import ContactSurface
from vfem.materials import LinearElastic


def test_projection_onto_segments():
    a = np.array([[0.0, 0.0], [1.0, 0.0]])
    b = np.array([[1.0, 0.0], [2.0, 1.0]])
    pts = np.array([[0.25, 0.5], [0.25, -0.3], [3.0, 3.0], [-1.0, 0.0]])
    seg, t, d = project_points(pts, a, b)
    np.testing.assert_array_equal(seg, [0, 0, 1, 0])
    np.testing.assert_allclose(t, [0.25, 0.25, 1.0, 0.0])
    np.testing.assert_allclose(d, [0.5, 0.3, np.hypot(1, 2), 1.0])
    n = outward_normals(a, b)
    np.testing.assert_allclose(n[0], [0.0, -1.0])  # (t_y, -t_x)


def test_surface_orientation_and_rind_location():
    mesh = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5)).with_boundaries(
        {"top": lambda x: x[1] > 1 - 1e-9, "bottom": lambda x: x[1] < 1e-9})
    body = Body("b", mesh, LinearElastic(1.0, 0.3), supports=(Support("bottom"),))
    body.setup()
    s = ContactSurface.build(body, mesh.boundaries["top"])
    xa, xb = s.segments(s.X)
    np.testing.assert_allclose(outward_normals(xa, xb), np.tile([0.0, 1.0], (len(xa), 1)))
    np.testing.assert_allclose(s.tributary.sum(), 1.0)
    found = s.locate(s.X, np.array([[0.3, 0.9], [0.3, 1.1], [0.3, 0.5], [0.999, 0.76]]))
    assert found[0] >= 0 and found[3] >= 0  # in the outer layer of elements
    assert found[1] == -1  # outside the body
    assert found[2] == -1  # inside, but deeper than the rind
