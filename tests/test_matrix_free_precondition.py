"""The matrix-free route's preconditioner, sparse rows and side choice (issue 40, item 3).

GMRES on W is preconditioned by H^-1 L H^-1 (FETI's lumped preconditioner with stiffness
scaling, written for the paired variant's W: :mod:`vfem.contact.solvers.matrix_free`), whose
spectrum against W stays in about [1, 2.5] as the contact zone grows (measured on the plates of
``benchmarks/matrix_free.py``: [1.01, 2.48] at 18 divisions, [1.03, 2.53] at 40), so GMRES needs
about 17-19 products a solve to 1e-12 at every size where the diagonal needed 66, 110, 210.
These tests hold it to the dense route's answers, to that spectrum and count, check that the
sparse rows it is built from are the dense route's, and that the side choice's half
back-substitution gives the whole one's compliances.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from vfem.contact.solvers import matrix_free as mf
from vfem.contact.solvers import pair_flexibility as pf
from vfem.contact.solvers.bordered import bordered_solve
from vfem.solver import Analysis
from vfem_examples import stack

#: the mid-size case: two plates, 24 divisions (676 compatibility unknowns, 1,153 in all)
DIVISIONS = 24
#: GMRES products a solve with the lumped preconditioner: measured 19 at 18, 24, 40 and 70
#: divisions (spectrum in [1, 2.5]: about 19 steps of a Krylov method to 1e-12); the bound
#: leaves half again
LUMPED_PRODUCTS = 30


def plates(route: str, divisions: int = DIVISIONS) -> Analysis:
    p = stack.Parameters(blocks=2, divisions=divisions, thickness=0.1, shrink=0.2,
                         press=0.0005, flexibility=route)
    analysis = Analysis(stack.build(p))
    result = analysis.run()
    assert result.converged and result.flexibility == route
    return analysis


@pytest.fixture(scope="module")
def both():
    """(matrix-free analysis, dense analysis) of the mid-size plates."""
    return plates("matrix_free"), plates("dense")


def first_pair(analysis) -> np.ndarray:
    offsets = analysis.contact._full[3]
    return np.arange(offsets[0], offsets[1])


def rhs_for(n: int) -> np.ndarray:
    return 1e-4 * (1.0 + 0.5 * np.sin(np.arange(n)))


def test_preconditioned_gmres_reaches_the_dense_answer_in_few_products(both, monkeypatch):
    free, dense = both
    op, W = free.contact._full[0], dense.contact._full[0]
    index = first_pair(free)
    assert len(index) > mf.DIRECT_UP_TO  # GMRES, not the small sets' direct solve
    rhs = rhs_for(len(index))
    exact = np.linalg.solve(W[np.ix_(index, index)], rhs)
    x, _ = op.solve(index, rhs)
    assert np.abs(x - exact).max() <= 1e-9 * np.abs(exact).max()
    size, products, how = op.history[-1]
    assert how == "lumped" and size == len(index)
    assert products <= LUMPED_PRODUCTS
    # the diagonal (the preconditioner before) needs several times as many
    monkeypatch.setattr(mf, "PRECONDITIONER", "diagonal")
    y, _ = op.solve(index, rhs)
    assert op.history[-1][2] == "diagonal"
    assert op.history[-1][1] >= 2 * products
    assert np.abs(y - exact).max() <= 1e-9 * np.abs(exact).max()


def test_the_preconditioned_spectrum_is_bounded(both):
    """Eigenvalues of M W on the first pair's unknowns: real parts in [0.9, 3] (measured
    [1.0, 2.5]); the diagonal's spread 0.1 to 15 at 40 divisions."""
    free, dense = both
    op, W = free.contact._full[0], dense.contact._full[0]
    index = first_pair(free)
    M = op.precondition(index)
    assert M is not None
    A = W[np.ix_(index, index)]
    MA = np.column_stack([M(column) for column in A.T])
    ev = np.linalg.eigvals(MA)
    assert ev.real.min() >= 0.9 and ev.real.max() <= 3.0
    assert np.abs(ev.imag).max() <= 0.05
    d = np.linalg.eigvals(A / np.abs(op.diagonal[index])[:, None])
    assert d.real.max() / d.real.min() > 10 * ev.real.max() / ev.real.min()


def test_the_bordered_system_agrees_with_the_dense_solve(both):
    free, dense = both
    op, W = free.contact._full[0], dense.contact._full[0]
    index = first_pair(free)
    n = len(index)
    rhs = rhs_for(n)
    A = W[np.ix_(index, index)]
    # the platen closing every gap alike; its reaction the mean traction value; its own
    # stiffness as large as the contact's (both halves of its equation alike)
    column, row = -np.ones(n), np.full(n, 1.0 / n)
    corner = 2.0 * abs(row @ np.linalg.solve(A, column))
    border = (column, row, corner, 1e-4 * corner)
    x, d = op.solve(index, rhs, border)
    xe, de = bordered_solve(A, *border[:3], rhs, border[3], lu_first=True)
    assert np.abs(x - xe).max() <= 1e-9 * np.abs(xe).max()
    assert abs(d - de) <= 1e-9 * abs(de)
    assert op.history[-1][2] == "lumped" and op.history[-1][1] <= LUMPED_PRODUCTS + 5


def test_bordered_preconditioner_is_the_exact_inverse_with_the_exact_block():
    rng = np.random.default_rng(3)
    n = 7
    W = rng.standard_normal((n, n)) + n * np.eye(n)
    col, row, corner = rng.standard_normal(n), rng.standard_normal(n), 2.5
    Winv = np.linalg.inv(W)
    P = mf.bordered_preconditioner(lambda v: Winv @ v, (col, row, corner, 0.0), corner)
    A = np.block([[W, col[:, None]], [row[None, :], np.array([[corner]])]])
    PA = np.column_stack([P(c) for c in A.T])
    np.testing.assert_allclose(PA, np.eye(n + 1), atol=1e-12)


def test_small_sets_are_solved_directly_and_their_columns_kept(both):
    free, dense = both
    op, W = free.contact._full[0], dense.contact._full[0]
    index = first_pair(free)[:60]
    rhs = rhs_for(len(index))
    x, _ = op.solve(index, rhs)
    assert op.history[-1][2] == "direct"
    exact = np.linalg.solve(W[np.ix_(index, index)], rhs)
    assert np.abs(x - exact).max() <= 1e-9 * np.abs(exact).max()
    before = op.applications
    y, _ = op.solve(index[5:], rhs[5:])  # a subset: every column kept
    assert op.applications == before
    np.testing.assert_allclose(
        y, np.linalg.solve(W[np.ix_(index[5:], index[5:])], rhs[5:]), rtol=0,
        atol=1e-9 * np.abs(y).max())


def test_a_singular_H_falls_back_to_the_diagonal(both):
    free, dense = both
    op, W = free.contact._full[0], dense.contact._full[0]
    index = first_pair(free)
    saved = op.H, op._kept
    try:
        op.H, op._kept = sp.csr_matrix(op.H.shape), None
        assert op.precondition(index) is None
        x, _ = op.solve(index, rhs_for(len(index)))
        assert op.history[-1][2] == "diagonal"
    finally:
        op.H, op._kept = saved
    exact = np.linalg.solve(W[np.ix_(index, index)], rhs_for(len(index)))
    assert np.abs(x - exact).max() <= 1e-9 * np.abs(exact).max()


def test_sparse_rows_are_the_dense_routes(both):
    """dF from the pairs' nonzero entries equals dF from their columns made dense, entry for
    entry, and sum_b read_b C_b dF_b is the dense route's W."""
    free, dense = both
    form = dense.contact
    pairs = form.contact_pairs
    directions = [form.directions(k) for k in range(len(pairs))]
    offsets, dF = pf.force_rows(form.surfaces, pairs, directions)
    m = int(offsets[-1])
    for b, s in enumerate(form.surfaces):  # the columns of fine_columns, coarse_columns
        rows, cols, vals = [], [], []
        for k, pair in enumerate(pairs):
            n = len(pair.nodes)
            for body, columns, sign in ((pair.fine, pair.fine_columns(), 1.0),
                                        (pair.coarse, pair.coarse_columns(), -1.0)):
                if body != b:
                    continue
                columns = columns.toarray()
                r, c = np.nonzero(columns)
                for j, direction in enumerate(directions[k]):
                    for d in range(s.dim):
                        rows.append(s.dim * r + d)
                        cols.append(offsets[k] + j * n + c)
                        vals.append(sign * columns[r, c] * direction[c, d])
        reference = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                   np.concatenate(cols))), shape=(s.dim * s.nc, m))
        assert (dF[b] != reference).nnz == 0
    read = pf.read_rows(form.surfaces, pairs, directions, offsets)
    W = sum(np.asarray(read[b] @ (s.C @ dF[b].toarray()))
            for b, s in enumerate(form.surfaces))
    Wd = form._full[0]
    assert np.abs(W - Wd).max() <= 1e-12 * np.abs(Wd).max()
    # the nonzero entries of a pair's columns are those of its dense form
    A = pairs[0].transfer
    got = pf.nonzeros(A, cols=pairs[0].nodes)
    dense = A.toarray()[:, pairs[0].nodes]
    want = (*np.nonzero(dense), dense[np.nonzero(dense)])
    order = np.lexsort(got[:2]), np.lexsort(want[:2])
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g[order[0]], w[order[1]])


def test_the_side_choice_compliances_by_half_a_back_substitution(both, monkeypatch):
    """|L^-1 P f|^2 (PARDISO's forward half) is the whole back-substitution's f^T K^-1 f and
    the dense route's n^T C n, node for node."""
    free, dense = both
    s, sd = free.contact.surfaces[0], dense.contact.surfaces[0]
    nodes = np.arange(0, s.nc, 7)
    normals = s.node_normals()[nodes]
    half = s.flexibility.normal_compliance(nodes, normals)
    if not getattr(s.body.factor, "cholesky", False):
        pytest.skip("the body's factorization offers no forward half (not PARDISO)")
    monkeypatch.setattr(type(s.body.factor), "cholesky", property(lambda self: False))
    whole = s.flexibility.normal_compliance(nodes, normals)
    assert np.abs(half - whole).max() <= 1e-12 * whole.max()
    on_dense = 1.0 / sd.normal_stiffness(nodes, normals)
    assert np.abs(half - on_dense).max() <= 1e-10 * on_dense.max()
