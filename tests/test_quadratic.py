"""Quadratic elements (6-node triangles, 9-node quadrilaterals): bodies, contact, output."""


import meshio
import numpy as np
import pytest
from skfem import Basis, ElementTriP2, ElementVector, MeshQuad, MeshTri

from vfem.bodies import Body, Support
from vfem.errors import InputError
from vfem.io.results import ResultsWriter
from vfem.materials import LinearElastic
from vfem.mesh import graded_quarter_disk
from vfem.mesh.quadratic import curved
from vfem.solver import Analysis
from vfem_examples import patch
from vfem_examples.hertz import HertzParameters, build, evaluate


@pytest.fixture(scope="module")
def hertz_quadratic():
    p = HertzParameters(order=2)
    result = Analysis(build(p)).run()
    return p, result, evaluate(result, p)


@pytest.mark.parametrize("mesh", [MeshTri().refined(2), MeshQuad().refined(2)])
def test_points_carry_dofs_2k_and_2k_plus_1(mesh):
    body = Body("b", mesh.with_boundaries({"left": lambda x: x[0] < 1e-9}),
                LinearElastic(1.0, 0.3), supports=(Support("left"),), order=2)
    body.setup()
    assert np.allclose(body.basis.doflocs[:, ::2], body.points)
    assert np.allclose(body.basis.doflocs[:, 1::2], body.points)


def test_curved_mesh_puts_the_arc_midpoints_on_the_circle():
    mesh = graded_quarter_disk(1.0, 0.01, 0.1, 0.2, plateau=0.05)
    m2 = curved(mesh, "contact", (0.0, 1.0), 1.0)
    body = Body("c", m2, LinearElastic(1.0, 0.2), supports=(Support("symmetry", ("x",)),),
                order=2)
    pts = body.points[:, body.boundary_points("contact")]
    assert np.allclose(np.hypot(pts[0], pts[1] - 1.0), 1.0, atol=1e-14)
    # interior midpoints stay on their chords
    assert np.allclose(Basis(m2, ElementVector(ElementTriP2())).doflocs[:, ::2], body.points)


@pytest.mark.parametrize("pair", [(4, 7), (2, 10)])
@pytest.mark.parametrize("nu", [0.0, 0.3])
def test_patch_test_with_quadratic_elements_to_round_off(pair, nu):
    p = patch.Parameters(order=2)
    for lower, upper in (pair, pair[::-1]):
        case = patch.run_case(p, lower, upper, nu)
        assert case["converged"]
        assert case["pressure_deviation"] < 1e-10
        assert case["stress_deviation"] < 1e-10


def test_hertz_with_quadratic_elements(hertz_quadratic):
    _, result, h = hertz_quadratic
    assert result.converged
    assert abs(h["p_max_error"]) < 0.002
    assert h["rms_error_over_p0"] < 0.01
    # both bodies read the same pressure, and the force crosses the contact exactly
    assert h["p_max_flat"] == pytest.approx(h["p_max"], rel=0.003)
    assert h["total_contact_force"] == pytest.approx(1530.0, rel=1e-9)
    assert h["total_contact_force_flat"] == pytest.approx(1530.0, rel=1e-9)
    last = result.steps[-1].history[-1]
    assert last.max_penetration <= 1e-9


def test_quadratic_results_are_written_as_quadratic_cells(hertz_quadratic, tmp_path):
    _, result, _ = hertz_quadratic
    writer = ResultsWriter(tmp_path, result.model)
    writer.write_step(result.steps[-1])
    for body in result.model.bodies:
        m = meshio.read(tmp_path / f"{body.name}_step0005.vtu")
        kind = "triangle6" if isinstance(body.mesh, MeshTri) else "quad9"
        assert m.cells[0].type == kind
        conn = m.cells[0].data
        pts = m.points[:, :2]
        # VTK's order: each edge midpoint lies between that edge's vertices (on straight edges)
        nv = 3 if kind == "triangle6" else 4
        for e in range(nv):
            mid = pts[conn[:, nv + e]]
            ends = 0.5 * (pts[conn[:, e]] + pts[conn[:, (e + 1) % nv]])
            assert np.median(np.linalg.norm(mid - ends, axis=1)) < 1e-12
        assert len(m.point_data["displacement"]) == body.npoints


def test_thesis_variant_refuses_quadratic_elements():
    with pytest.raises(InputError, match="linear elements only"):
        build(HertzParameters(order=2, variant="thesis")).validate()


def test_order_must_be_one_or_two():
    with pytest.raises(InputError, match="order must be 1"):
        build(HertzParameters(order=3)).validate()


def test_the_traction_on_a_three_node_facet_is_linear_on_each_half():
    """Issue 37, item 3: values >= 0 give a traction >= 0 everywhere (a quadratic interpolant
    of (1, 0, 0) dips to -1/8), and a uniform one is represented exactly."""
    from vfem.contact.geometry.facets import Segment

    t = np.linspace(0.0, 1.0, 201)
    psi = Segment(2).traction_shape(t)
    assert np.allclose(psi.sum(axis=1), 1.0, atol=1e-15)
    assert psi.min() >= 0.0
    assert np.allclose(psi[[0, 100, 200]], [[1, 0, 0], [0, 0, 1], [0, 1, 0]])
    assert Segment(2).shape(t)[:, 0].min() < -0.1  # what it replaces


FIRST_TOUCH = """
name = "first touch"

[[bodies]]
name = "upper"
order = 2
[bodies.mesh]
shape = "graded_quarter_disk"
growth = 1.877699212077418
h_contact = 0.04372436006048939
h_max = 0.26234616036293634
radius = 1.0
translate = [-0.1708265941656228, 0.1060511622993913]
[bodies.material]
youngs_modulus = 1.8114553765280772
poissons_ratio = 0.21053021531223978
[[bodies.supports]]
boundary = "top"
components = ["x"]
[bodies.platen]
boundary = "top"
component = "y"
force = -0.0001398393751266381

[[bodies]]
name = "block"
order = 2
[bodies.mesh]
shape = "rectangle"
height = 0.7032566960060398
nx = 27
ny = 5
triangles = true
width = 2.455175479501359
x0 = 0.0
y0 = -0.7032566960060398
[bodies.material]
youngs_modulus = 1.4799400570558947
poissons_ratio = 0.16806609940323092
[[bodies.supports]]
boundary = "bottom"

[steps]
load_factors = [0.16666666666666666, 0.3333333333333333, 0.5, 1.0]
"""


def test_a_quadratic_body_landing_on_one_node_is_not_in_tension():
    """A quadratic quarter disk on a platen lands on one node of a quadratic block (the
    random-model study's 2d-236, benchmarks/random_models.py): before, its first step stopped
    on invariant (c) (a tensile nodal force 7.8 % of the largest, from the quadratic traction's
    dip past the one node touching). Now every step converges with the invariants, and the
    platen's force is carried."""
    from vfem.io.input import loads

    result = Analysis(loads(FIRST_TOUCH).build()).run()
    assert result.converged, result.message
    fy = result.steps[-1].bodies["block"].contact_force[:, 1].sum()
    # the platen's force, to its own tolerance (contact.platen_tolerance, 1e-5 of it)
    assert fy == pytest.approx(-0.0001398393751266381, rel=1e-5)
