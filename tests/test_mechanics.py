"""A body's mechanics (vfem.bodies.mechanics): the tangent flexibility of a large-kinematics body
from the Schur complement of its tangent, checked against the inverse tangent itself, and the
fall-back for a tangent that is not positive definite."""

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import MeshQuad

from vfem import linalg
from vfem.bodies import Body, Support
from vfem.bodies.mechanics import LargeMechanics, LinearMechanics, _tangent_factorization
from vfem.materials import LinearElastic


def large_block():
    m = MeshQuad.init_tensor(np.linspace(0, 2, 7), np.linspace(0, 1, 4))
    m = m.with_boundaries({"bottom": lambda x: x[1] < 1e-9, "top": lambda x: x[1] > 1 - 1e-9})
    body = Body("block", m, LinearElastic(1000.0, 0.3), supports=(Support("bottom"),),
                kinematics="total")
    body.setup()
    return body


def test_each_kinematics_has_its_mechanics():
    body = large_block()
    assert isinstance(body.mechanics, LargeMechanics)
    small = Body("b", body.mesh, body.material, supports=(Support("bottom"),))
    small.setup()
    assert isinstance(small.mechanics, LinearMechanics)
    assert small.saved_state() == {}


@pytest.mark.parametrize("stretch", [0.0, 0.05])
def test_the_tangent_flexibility_is_the_inverse_tangent_on_the_contact_dofs(stretch,
                                                                            monkeypatch):
    """Flexibility rows of the tracked dofs (the top's nodes and one more) for the candidate
    dofs (the top's): the block of the inverse tangent, at rest and stretched (the tangent then
    has its geometric part)."""
    body = large_block()
    top = np.flatnonzero(body.mesh.p[1] > 1 - 1e-9)
    candidate = np.column_stack([2 * top, 2 * top + 1]).ravel()
    tracked = np.concatenate([candidate, [2 * 8, 2 * 8 + 1]])  # an interior node as well
    force = np.zeros(body.ndofs)
    force[candidate[1::2]] = stretch * 1000.0 / len(top)  # pulls the top up
    if stretch:
        body.equilibrate(1.0, 0.0, force)
    routes = []

    def recorded(*args):
        factor, x = _tangent_factorization(*args)
        routes.append(factor.trailing_inverse is not None)
        return factor, x

    monkeypatch.setattr("vfem.bodies.mechanics._tangent_factorization", recorded)
    lin = body.linearize(1.0, 0.0, force, tracked, candidate)
    assert routes == []  # the residual alone until the system is asked for
    flexibility = lin.flexibility
    assert routes == [True]  # positive definite: the Schur complement's route
    assert lin.flexibility is flexibility and routes == [True]  # factorized once
    R, ref, K, D, pending = body.nonlinear.linearize(1.0, force)
    free = np.setdiff1d(np.arange(body.ndofs), D)
    inverse = np.zeros((body.ndofs, body.ndofs))
    inverse[np.ix_(free, free)] = np.linalg.inv(K[free][:, free].toarray())
    expected = inverse[np.ix_(tracked, candidate)]
    np.testing.assert_allclose(lin.flexibility, expected, rtol=0,
                               atol=1e-10 * np.abs(expected).max())


def test_the_fallback_flexibility_in_blocks_of_columns_is_the_inverse_tangent(monkeypatch):
    """A tangent whose Cholesky fails (here made to) gives its flexibility by back-substitutions,
    a few candidate dofs at a time (``FALLBACK_COLUMNS``, two here, for fourteen): the block of
    the inverse tangent all the same."""
    from vfem.bodies import mechanics
    from vfem.errors import AnalysisError

    body = large_block()
    top = np.flatnonzero(body.mesh.p[1] > 1 - 1e-9)
    candidate = np.column_stack([2 * top, 2 * top + 1]).ravel()
    force = np.zeros(body.ndofs)
    real = mechanics.factorize

    def no_cholesky(K, backend=None, *, trailing=None, spd=True, **kw):
        if spd and trailing is not None:
            raise AnalysisError("made to fail")
        return real(K, backend, trailing=trailing, spd=spd, **kw)

    monkeypatch.setattr(mechanics, "factorize", no_cholesky)
    monkeypatch.setattr(mechanics, "FALLBACK_COLUMNS", 2)
    lin = body.linearize(1.0, 0.0, force, candidate, candidate)
    R, ref, K, D, pending = body.nonlinear.linearize(1.0, force)
    free = np.setdiff1d(np.arange(body.ndofs), D)
    inverse = np.zeros((body.ndofs, body.ndofs))
    inverse[np.ix_(free, free)] = np.linalg.inv(K[free][:, free].toarray())
    expected = inverse[np.ix_(candidate, candidate)]
    assert len(candidate) == 14
    np.testing.assert_allclose(lin.flexibility, expected, rtol=0,
                               atol=1e-10 * np.abs(expected).max())


@pytest.mark.parametrize("backend", linalg.available())
def test_a_tangent_that_is_not_positive_definite_falls_back_to_back_substitutions(backend):
    """An indefinite tangent: a Cholesky backend (PARDISO, CHOLMOD) fails on it and the body
    falls back to an indefinite factorization (no Schur complement: back-substitutions);
    SuperLU's LU in the same order may succeed, and then its Schur complement's inverse is the
    inverse tangent's block all the same. Either way the solve and the flexibility are right."""
    A = sp.csc_matrix(np.array([[2.0, 0.0, 1.0], [0.0, -1.0, 0.5], [1.0, 0.5, 3.0]]))
    rhs = np.array([1.0, 2.0, 3.0])
    factor, x = _tangent_factorization(A, np.array([2]), np.arange(3), rhs, backend, "test")
    if backend in ("pardiso", "cholmod"):
        assert factor.trailing_inverse is None  # not positive definite: the fallback
    if factor.trailing_inverse is not None:
        np.testing.assert_allclose(factor.trailing_inverse,
                                   np.linalg.inv(A.toarray())[np.ix_([2], [2])], rtol=1e-12)
    np.testing.assert_allclose(A @ x, rhs, rtol=1e-12)
    spd = sp.csc_matrix(np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]]))
    factor, x = _tangent_factorization(spd, np.array([1, 2]), np.arange(3), rhs, None, "test")
    np.testing.assert_allclose(factor.trailing_inverse,
                               np.linalg.inv(spd.toarray())[np.ix_([1, 2], [1, 2])], rtol=1e-12)
    np.testing.assert_allclose(spd @ x, rhs, rtol=1e-12)


@pytest.mark.parametrize("order", [1, 2])
def test_stresses_from_the_average_strain_operator_equal_the_quadrature_average(order):
    """The stresses of a step by one sparse product (bodies/stresses.py) are the quadrature
    average of the stress at the points, as scikit-fem interpolates it (quads and triangles)."""
    from skfem import MeshTri
    from skfem.helpers import sym_grad, trace

    from vfem.bodies.stresses import stress

    for mesh in (MeshQuad.init_tensor(np.linspace(0, 2, 5), np.linspace(0, 1, 4)),
                 MeshTri.init_symmetric().refined(2)):
        mesh = mesh.with_boundaries({"bottom": lambda x: x[1] < 1e-9})
        body = Body("b", mesh, LinearElastic(1000.0, 0.3), supports=(Support("bottom"),),
                    order=order)
        body.setup()
        u = np.random.default_rng(order).normal(size=body.ndofs)
        lam, mu = body.material.lame()
        eps = sym_grad(body.basis.interpolate(u))
        sig = 2 * mu * eps
        sig[0, 0] += lam * trace(eps)
        sig[1, 1] += lam * trace(eps)
        w = body.basis.dx
        got = stress(body, u)
        for key, (i, j) in {"sxx": (0, 0), "syy": (1, 1), "sxy": (0, 1)}.items():
            expected = (sig[i, j] * w).sum(axis=1) / w.sum(axis=1)
            np.testing.assert_allclose(got[key], expected, rtol=0,
                                       atol=1e-12 * np.abs(expected).max())
