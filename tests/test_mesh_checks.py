"""Mesh checks before solving (vfem.mesh.checks): each problem is one message that names the
body, the problem, the first offending element or node and where it is."""

import numpy as np
import pytest
from skfem import MeshQuad, MeshQuad2, MeshTri, MeshTri2

from vfem import Body, LinearElastic, Model, Support
from vfem.errors import InputError
from vfem.mesh import rectangle
from vfem.mesh.checks import check_mesh

STEEL = LinearElastic(200e3, 0.3)


def refused(mesh, *words) -> str:
    with pytest.raises(InputError) as info:
        check_mesh(mesh, "body 'b'")
    message = str(info.value)
    assert message.startswith("body 'b': ")
    for w in words:
        assert w in message, message
    return message


def two_squares(gap: float) -> MeshTri:
    """Two unit squares of two triangles each, side by side ``gap`` apart."""
    a = MeshTri()
    p = np.hstack([a.p, a.p + np.array([[1.0 + gap], [0.0]])])
    t = np.hstack([a.t, a.t + 4])
    return MeshTri(p, t, sort_t=False, validate=False)


@pytest.mark.parametrize("mesh", [
    MeshTri().refined(2),  # scikit-fem sorts the nodes of its triangles: mixed orientation
    MeshQuad().refined(2),  # init's quadrilaterals are clockwise
    MeshTri2.from_mesh(MeshTri().refined(1)),
    MeshQuad2.from_mesh(MeshQuad().refined(1)),
    rectangle(nx=3, ny=2, triangles=True),
], ids=["tri", "quad", "tri6", "quad9", "rectangle"])
def test_sound_meshes_pass_whatever_their_element_orientation(mesh):
    check_mesh(mesh, "body 'b'")


def test_node_moved_past_the_opposite_edge_is_an_overlap_of_neighbours():
    m = MeshTri().refined(2)
    centre = int(np.flatnonzero(np.all(np.isclose(m.p, 0.5), axis=0))[0])
    p = m.p.copy()
    p[0, centre] += 0.4  # past the edges of the triangles on its right
    message = refused(MeshTri(p, m.t, sort_t=False), "overlap", "inverted (folded) element",
                      "same side of their shared edge")
    assert "(0.9, 0.5)" in message  # the moved node is an end of the edge named


def test_non_convex_quadrilateral_is_inverted_inside():
    m = MeshQuad().refined(2)
    p = m.p.copy()
    k = int(np.flatnonzero(np.all(np.isclose(m.p, 0.25), axis=0))[0])
    p[0, k] += 0.4
    refused(MeshQuad(p, m.t), "inverted", "Jacobian changes sign", "(0.65, 0.25)")


@pytest.mark.parametrize("cls", [MeshTri2, MeshQuad2])
def test_curved_edge_bowed_past_the_element_is_inverted(cls):
    m2 = cls.from_mesh(MeshTri() if cls is MeshTri2 else MeshQuad())
    d = m2.doflocs.copy()
    d[:, m2.nvertices] += [0.0, 3.0]  # a facet midpoint far into (and past) its element
    refused(cls(d, m2.t, sort_t=False), "inverted", "element 0")


def test_zero_area_element():
    p = np.array([[0.0, 1.0, 2.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    refused(MeshTri(p, np.array([[0, 1, 2], [0, 1, 3]]).T, sort_t=False),
            "zero area", "element 0", "[(0, 0), (1, 0), (2, 0)]")


def test_duplicate_nodes_name_both_and_the_position():
    refused(two_squares(0.0), "2 pair(s) of nodes at the same position", "nodes 1 and 4",
            "(1, 0)", "crack", "merge")


def test_pieces_are_counted_and_the_smallest_located():
    a = MeshTri().refined(1)
    p = np.hstack([a.p, np.array([[5.0, 6.0, 5.0], [0.0, 0.0, 1.0]])])
    t = np.hstack([a.t, np.array([[a.nvertices, a.nvertices + 1, a.nvertices + 2]]).T])
    refused(MeshTri(p, t, sort_t=False), "2 separate pieces", "the smallest, 1 element(s)",
            f"node {a.nvertices} at (5, 0)", "its own body")


def test_node_in_no_element_and_coordinates_not_finite():
    p = np.array([[5.0, 0.0, 1.0, 0.0], [5.0, 0.0, 0.0, 1.0]])
    refused(MeshTri(p, np.array([[1, 2, 3]]).T, sort_t=False), "belong to no element",
            "node 0 at (5, 5)")
    p = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, np.nan]])
    refused(MeshTri(p, np.array([[0, 1, 2]]).T, sort_t=False), "node 2", "not finite")


def test_every_route_to_a_model_checks_the_mesh():
    """Model.validate (Python API), Analysis and the input file (via Body.validate) alike."""
    mesh = two_squares(0.0).with_boundaries({"left": lambda x: x[0] < 1e-9})
    body = Body("glued", mesh, STEEL, supports=(Support("left"),))
    with pytest.raises(InputError, match="body 'glued': 2 pair"):
        Model("m", [body]).validate()


def test_a_boundary_that_holds_no_facet_is_refused():
    mesh = rectangle(nx=2, ny=2).with_boundaries({"nowhere": lambda x: x[0] > 5.0,
                                                  "left": lambda x: x[0] < 1e-9})
    body = Body("b", mesh, STEEL, supports=(Support("left"), Support("nowhere")))
    with pytest.raises(InputError, match="boundary 'nowhere' holds no facet"):
        body.validate()


@pytest.mark.parametrize("shape, parameters, words", [
    ("rectangle", {"nx": 10**9, "ny": 10**9}, "more than the 2,000,000"),
    ("gasket", {"n_around": 0}, "n_around, n_through >= 1"),
    ("wedge_plate", {"h_contact": -0.05}, "element sizes must be positive"),
    ("graded_layer", {"width": 5.0, "thickness": 1.0, "h_contact": 1e-12, "h_max": 1e-12},
     "too small for a line"),
    ("wedge_plate_grid", {"columns": 10**18}, "more than the 2,000,000"),
    ("gasket", {"centre": ()}, "centre: expected 2 values"),
    ("rectangle", {"width": float("nan")}, "width: must be a finite number"),
])
def test_shape_parameters_that_cannot_make_a_mesh_are_refused_at_once(shape, parameters, words):
    """Sizes that are not positive, counts past the limit (instead of a hang or an allocation
    of exabytes), parameters of the wrong shape given in Python."""
    import time

    from vfem.config import MeshSpec, as_parameters

    start = time.perf_counter()
    with pytest.raises(InputError, match=f"mesh shape {shape!r}"):
        try:
            MeshSpec(shape=shape, parameters=as_parameters(**parameters)).make()
        except InputError as exc:
            assert words in str(exc), str(exc)
            raise
    assert time.perf_counter() - start < 2.0
