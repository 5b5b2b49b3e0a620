"""Each contact set's system solved from the factors of a set near it
(:meth:`vfem.contact.solvers.bordered.ReusedFactor.solve_set`, issue 40): the same solutions as
a factorization of the set itself, to the set's conditioning times round-off; the same
singular sets; a set near a factorized one not factorized; the same contact set from the
complementarity with the factors kept as without them."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from vfem.contact.solvers import bordered
from vfem.contact.solvers.bordered import ReusedFactor, bordered_matrix
from vfem.contact.solvers.complementarity import linear_complementarity

EPS = np.finfo(float).eps


def flexibility(n: int, seed: int = 0) -> np.ndarray:
    """A nonsymmetric matrix like a pair flexibility W: a dominant positive diagonal, coupling
    that falls off with the distance between the nodes (W of the stacks is nonsymmetric to
    its own size)."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.random(n))
    W = np.exp(-30 * np.abs(x[:, None] - x[None, :])) * (0.5 + rng.random((n, n)))
    return W + n ** 0.5 * np.eye(n)


def reference(W, a, b, border=None):
    M = W[np.ix_(a, a)]
    if border is not None:
        M = bordered_matrix(M, *border)
    return np.linalg.solve(M, b), np.linalg.cond(M)


def sets(n: int, seed: int):
    """A walk over sets: most steps flip a few nodes, some many (a new factorization)."""
    rng = np.random.default_rng(seed)
    mask = rng.random(n) < 0.6
    for step in range(40):
        share = 0.3 if step % 7 == 0 else 0.01
        mask = mask ^ (rng.random(n) < share)
        yield np.flatnonzero(mask), step


@pytest.mark.parametrize("bordered_system", [False, True])
def test_every_set_solves_as_its_own_factorization(bordered_system):
    n = 240
    W = flexibility(n)
    rng = np.random.default_rng(3)
    # a platen: its motion's effect on each node's gap and each node's force on it (fixed
    # per node, as the formulation's), no stiffness of its own
    column, row = -rng.random(n), rng.random(n)
    factor, updated = ReusedFactor(), 0
    for a, _ in sets(n, seed=1):
        b = rng.standard_normal(len(a) + bordered_system)
        border = (column[a], row[a], 0.0) if bordered_system else None
        x = factor.solve_set(W, a, b, border)
        ref, cond = reference(W, a, b, border)
        # LU's own error (backward error n eps, times the conditioning), either way
        assert np.linalg.norm(x - ref) <= 2 * len(b) * EPS * cond * np.linalg.norm(ref)
        updated += isinstance(factor._set[2], bordered._Checked)
    assert updated >= 20  # most sets came from a factorized one


def test_a_set_near_a_factorized_one_is_not_factorized(monkeypatch):
    n = 300
    W = flexibility(n, seed=2)
    orders = []
    whole = bordered._factorized
    monkeypatch.setattr(bordered, "_factorized", lambda A: orders.append(A.shape[0]) or whole(A))
    factor = ReusedFactor()
    a = np.arange(0, 200)
    factor.solve_set(W, a, np.ones(200))
    assert orders == [200]
    near = np.r_[np.arange(3, 200), 250, 251]  # three out, two in
    x = factor.solve_set(W, near, np.ones(199))
    assert orders == [200, 5]  # the 5 x 5 system alone
    assert np.allclose(x, np.linalg.solve(W[np.ix_(near, near)], np.ones(199)), rtol=1e-12)
    factor.solve_set(W, a, np.ones(200))  # the first set again: kept, nothing factorized
    assert orders == [200, 5]


def test_a_set_with_a_repeated_condition_is_singular_either_way():
    """A node whose condition repeats another's (W's row and column copied: two nodes at one
    point) makes the set singular; solved from a base that lacks it, the set is still found
    singular (the k x k system, or the residual check sending it to a whole factorization)."""
    n = 120
    W = flexibility(n, seed=4)
    W[:, 101] = W[:, 100]
    W[101, :] = W[100, :]
    factor = ReusedFactor()
    base = np.r_[np.arange(0, 100), 100]
    assert factor.solve_set(W, base, np.ones(101)) is not None
    assert factor.solve_set(W, np.r_[base, 101], np.ones(102)) is None
    assert ReusedFactor().solve_set(W, np.r_[base, 101], np.ones(102)) is None


def test_a_border_without_a_node_of_the_platens_body_is_singular():
    W = flexibility(80, seed=5)
    a = np.arange(60)
    factor = ReusedFactor()
    factor.solve_set(W, a, np.ones(60))
    border = (np.zeros(60), np.zeros(60), 0.0)  # the platen's body has no node in the set
    assert factor.solve_set(W, a, np.ones(61), border) is None


def test_a_sparse_w_solves_each_set_as_its_own_factorization():
    n = 200
    W = flexibility(n, seed=6)
    W[np.abs(np.arange(n)[:, None] - np.arange(n)[None, :]) > 20] = 0.0
    Ws = sp.csr_matrix(W)
    factor = ReusedFactor()
    for a, _ in sets(n, seed=7):
        b = np.ones(len(a))
        ref, cond = reference(W, a, b)
        x = factor.solve_set(Ws, a, b)
        assert np.linalg.norm(x - ref) <= 2 * len(b) * EPS * cond * np.linalg.norm(ref)


def test_factorized_sets_are_kept_within_ws_own_memory():
    n = 100
    W = flexibility(n, seed=8)
    factor = ReusedFactor()
    rng = np.random.default_rng(9)
    for _ in range(12):
        a = np.flatnonzero(rng.random(n) < 0.5)  # far apart: each factorized whole
        factor.solve_set(W, a, np.ones(len(a)))
        assert sum(len(base.index) ** 2 for base in factor._bases) <= W.size
    assert len(factor._bases) >= 2


def test_the_complementarity_finds_the_same_set_with_the_factors_kept():
    """A contact problem whose pivoting passes through sets a few nodes apart: with the
    factors kept (sets from their neighbours) and without (each set by numpy), the same
    set and the same values to the conditioning's round-off."""
    n = 300
    W = flexibility(n, seed=10)
    rng = np.random.default_rng(11)
    p = 0.02 * rng.standard_normal(n) + 0.005  # penetrations, most nodes in
    q0 = np.zeros(n)
    plain, _ = linear_complementarity(W, q0, p, 1e-12)
    kept, _ = linear_complementarity(W, q0, p, 1e-12, factor=ReusedFactor())
    assert np.array_equal(plain > 0, kept > 0)
    cond = np.linalg.cond(W)
    assert np.linalg.norm(kept - plain) <= 2 * n * EPS * cond * np.linalg.norm(plain)
