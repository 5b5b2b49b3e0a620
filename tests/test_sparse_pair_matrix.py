"""The pair matrix W kept sparse where few pairs share a body (issue 40, item 4: a stack's W is
block tridiagonal; dense it is O(m^2) memory and O(m^3) solves on every MPI rank): the same
contact state as the dense W's, to round-off, and the same W."""

import numpy as np
import pytest
import scipy.sparse as sp

from vfem.contact.solvers import pair_flexibility
from vfem.solver import Analysis
from vfem_examples import stack


def solved(monkeypatch, sparse: bool, **params):
    monkeypatch.setattr(pair_flexibility, "SPARSE_MIN", 0)
    monkeypatch.setattr(pair_flexibility, "SPARSE_DENSITY", 0.25 if sparse else 0.0)
    model = stack.build(stack.Parameters(**params))
    analysis = Analysis(model)
    result = analysis.run()
    assert result.converged and all(s.invariants["passed"] for s in result.steps)
    return analysis, result


@pytest.mark.parametrize("params", [
    dict(dim=2, blocks=16, divisions=6, layers=2, shrink=0.03, steps=2),
    dict(dim=3, blocks=16, divisions=3, layers=1, shrink=0.03, steps=1),
], ids=["2d-16-plates", "3d-16-plates"])
def test_a_sparse_pair_matrix_gives_the_dense_ones_answers(monkeypatch, params):
    dense, rd = solved(monkeypatch, False, **params)
    sparse, rs = solved(monkeypatch, True, **params)
    Wd, Ws = dense.contact._full[0], sparse.contact._full[0]
    assert isinstance(Wd, np.ndarray) and sp.issparse(Ws)
    # the pairs couple through the bodies they share only: a block tridiagonal W, its
    # entries elsewhere exactly zero in the dense one
    assert Ws.nnz < 0.25 * Ws.shape[0] ** 2
    scale = np.abs(Wd).max()
    np.testing.assert_allclose(Ws.toarray(), Wd, rtol=0, atol=1e-13 * scale)
    # the answers: the solves' round-off times their condition (the dense and sparse
    # factorizations pivot differently), far below 1e-10 of the largest value
    for a, b in zip(rd.steps, rs.steps):
        assert a.load_factor == b.load_factor
        for name, fa in a.bodies.items():
            fb = b.bodies[name]
            for field in ("displacement", "contact_force"):
                x, y = getattr(fa, field), getattr(fb, field)
                top = max(np.abs(x).max(), 1e-300)
                assert np.abs(x - y).max() <= 1e-10 * top, (name, field)
