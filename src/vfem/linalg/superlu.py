"""SciPy's SuperLU: always there, the fallback of every other backend.

With ``trailing`` dofs it orders them last, so that the trailing blocks of the factors multiply
to the Schur complement S on them and ``(A^-1)[dofs, dofs] = S^-1``: one factorization and a
dense inverse of the size of the contact surface, instead of one back-substitution per contact
dof. The fill-reducing order of the rest is the minimum-degree order of the node graph (one
vertex per node, so a quarter of the matrix), computed by SuperLU itself.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

log = logging.getLogger(__name__)


def _node_graph_order(A: sp.spmatrix, groups: np.ndarray) -> np.ndarray:
    """A fill-reducing order of the rows of ``A``, from the graph of the groups (nodes)."""
    n, ng = A.shape[0], int(groups.max()) + 1
    D = sp.csr_matrix((np.ones(n), (np.arange(n), groups)), shape=(n, ng))
    P = sp.csr_matrix(A, copy=True)
    P.data[:] = 1.0
    M = (D.T @ P @ D).tocsr()
    M.data[:] = -1.0
    M.setdiag(0.0)
    M.eliminate_zeros()
    degree = -np.asarray(M.sum(axis=1)).ravel()
    M = (M + sp.diags(degree + 1.0)).tocsc()  # diagonally dominant: a symmetric M-matrix
    perm = spla.splu(M, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True}).perm_c
    rank = np.empty(ng, dtype=int)
    rank[np.argsort(perm)] = np.arange(ng)
    return np.argsort(rank[groups], kind="stable")


class SuperLUFactorization:
    """SciPy SuperLU with a symmetric ordering."""

    name = "superlu"

    def __init__(self, A: sp.spmatrix, trailing: np.ndarray | None = None,
                 groups: np.ndarray | None = None, spd: bool = True):
        self.shape = A.shape
        A = sp.csc_matrix(A)
        self.trailing_inverse = None
        self.order = None
        if not spd or trailing is None or len(trailing) == 0:
            # symmetric ordering; SuperLU still pivots off the diagonal where it must
            # (symmetric indefinite matrices: tangents, saddle points)
            self._lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A",
                                 options={"SymmetricMode": True})
            return
        trailing = np.asarray(trailing, dtype=int)
        groups = np.arange(A.shape[0]) if groups is None else np.asarray(groups)
        order = _node_graph_order(A, groups)
        last = np.zeros(A.shape[0], dtype=bool)
        last[trailing] = True
        order = np.concatenate([order[~last[order]], trailing])
        self.order = order
        self._lu = spla.splu(A[order][:, order].tocsc(), permc_spec="NATURAL",
                             diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        n, m = A.shape[0], len(trailing)
        k = n - m
        kept = (np.array_equal(self._lu.perm_c[k:], np.arange(k, n))
                and np.array_equal(self._lu.perm_r[k:], np.arange(k, n)))
        if kept:
            S = self._lu.L[k:, k:].toarray() @ self._lu.U[k:, k:].toarray()
            inv = np.linalg.inv(S)
        else:  # SuperLU moved the trailing block: fall back to one solve per trailing dof
            log.info("trailing block not kept by SuperLU; flexibility by back-substitution")
            E = np.zeros((n, m))
            E[trailing, np.arange(m)] = 1.0
            inv = self.solve(E)[trailing]
        self.trailing_inverse = 0.5 * (inv + inv.T)

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        if self.order is None:
            return self._lu.solve(b)
        x = np.empty_like(b)
        x[self.order] = self._lu.solve(b[self.order])
        return x
