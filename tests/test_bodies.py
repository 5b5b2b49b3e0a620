"""Bodies on scikit-fem: elasticity, supports, flexibility, and clear errors for bad input."""

import numpy as np
import pytest
from skfem import MeshQuad, MeshTri

from vfem.bodies import Body, PrescribedDisplacement, Support, Traction
from vfem.bodies.loads import boundary_dofs
from vfem.bodies.stresses import stress
from vfem.errors import InputError
from vfem.materials import LinearElastic


def block(mesh_cls=MeshTri, n=3):
    mesh = mesh_cls.init_tensor(np.linspace(0, 2, 2 * n + 1), np.linspace(0, 1, n + 1))
    return mesh.with_boundaries({"left": lambda x: x[0] < 1e-9, "bottom": lambda x: x[1] < 1e-9,
                                 "top": lambda x: x[1] > 1 - 1e-9,
                                 "right": lambda x: x[0] > 2 - 1e-9})


@pytest.mark.parametrize("mesh_cls", [MeshTri, MeshQuad])
@pytest.mark.parametrize("plane", ["strain", "stress"])
def test_uniform_pressure_gives_the_exact_uniform_state(mesh_cls, plane):
    """Patch test of the body: a roller-supported block under uniform pressure on top."""
    E, nu, q = 200.0, 0.3, 2.0
    body = Body("block", block(mesh_cls), LinearElastic(E, nu, plane),
                supports=(Support("left", ("x",)), Support("bottom", ("y",))),
                tractions=(Traction("top", (0.0, -q)),))
    body.setup()
    u = body.u_load.reshape(-1, 2)
    Ep, nup = (E / (1 - nu**2), nu / (1 - nu)) if plane == "strain" else (E, nu)
    eps_y, eps_x = -q / Ep, nup * q / Ep
    x, y = body.mesh.p
    np.testing.assert_allclose(u[:, 1], eps_y * y, atol=1e-12)
    np.testing.assert_allclose(u[:, 0], eps_x * x, atol=1e-12)
    s = stress(body, body.u_load)
    np.testing.assert_allclose(s["syy"], -q, rtol=1e-10)
    np.testing.assert_allclose(s["sxx"], 0, atol=1e-10)


def test_prescribed_displacement_and_flexibility_is_the_inverse_stiffness():
    body = Body("block", block(), LinearElastic(1e3, 0.25),
                supports=(Support("left"),),
                prescribed=(PrescribedDisplacement("right", "x", 0.01),))
    body.setup()
    right = boundary_dofs(body, "right", "x")
    np.testing.assert_allclose(body.u_load[right], 0.01)
    dofs = body.free_dofs[:7]
    cols = body.flexibility_columns(dofs)
    C = cols[dofs]
    np.testing.assert_allclose(C, C.T, rtol=1e-10, atol=1e-14)
    Kinv = np.linalg.inv(body.K_ff.toarray())
    np.testing.assert_allclose(C, Kinv[:7, :7], rtol=1e-9)


@pytest.mark.parametrize(("E", "nu", "match"), [
    (-1.0, 0.3, "youngs_modulus"), (1.0, 0.5, "poissons_ratio"), (1.0, 0.7, "poissons_ratio"),
    (float("nan"), 0.3, "youngs_modulus")])
def test_bad_material_is_named(E, nu, match):
    body = Body("seal", block(), LinearElastic(E, nu), supports=(Support("left"),))
    with pytest.raises(InputError, match=f"body 'seal'.*{match}"):
        body.setup()


@pytest.mark.parametrize(("supports", "free"), [
    ((), "translation"), ((Support("bottom", ("y",)),), "translation in x"),
    ((Support("left", ("x",)),), "translation in y")])
def test_unsupported_body_is_refused_with_the_free_motion(supports, free):
    body = Body("gasket", block(), LinearElastic(1.0, 0.3), supports=supports)
    with pytest.raises(InputError, match=f"body 'gasket' is not supported.*{free}"):
        body.setup()


def test_unknown_boundary_is_named():
    body = Body("plate", block(), LinearElastic(1.0, 0.3), supports=(Support("botom"),))
    with pytest.raises(InputError, match="no boundary named 'botom'"):
        body.setup()
