"""A body's flexibility on its contact surface, applied through its own factorization (issue 22):
what the matrix-free route (:mod:`vfem.contact.solvers.matrix_free`) and the side rules read of a
body instead of its dense condensed block (``ContactSurface.G``). With the surfaces (the geometry
stage of contact): a body's condensation to its surface, below the solvers that use it.
"""

from __future__ import annotations

import numpy as np

#: candidate nodes solved for at once when a surface's nodal flexibilities are computed
PROBE_CHUNK = 96


class SurfaceFlexibility:
    """A body's flexibility on its contact candidates, applied through its factorization.

    ``apply(F)``: the motion of the surface's condensed dofs (its candidates', and the rind's
    where the formulation reads it) under nodal forces ``F`` on its candidate dofs, supports
    held: ``G F`` of the dense route, by one back-substitution (several columns at once).
    """

    def __init__(self, surface):
        body = surface.body
        self.body = body
        self.dim = surface.dim
        self.n_free = len(body.free_dofs)
        self._col_pos, self._col_free = body.free_positions(surface.candidate_dofs)
        self._row_pos, self._row_free = body.free_positions(surface.condensed_dofs)
        self.n_cols = len(surface.candidate_dofs)
        self._cand_dofs = surface.candidate_dofs.reshape(-1, self.dim)
        self.n_rows = len(surface.condensed_dofs)

    def apply(self, F: np.ndarray, rows: int | None = None) -> np.ndarray:
        """The condensed dofs' motion (their first ``rows``, default all) under candidate-dof
        forces ``F`` ((n_cols,) or (n_cols, k))."""
        F = np.asarray(F, dtype=float)
        vector = F.ndim == 1
        F2 = F[:, None] if vector else F
        k = F2.shape[1]
        rhs = np.zeros((self.n_free, k))
        rhs[self._col_pos[self._col_free]] = F2[self._col_free]
        x = self.body.factor.solve(rhs if k > 1 else rhs[:, 0])
        x = x.reshape(self.n_free, k)
        n = self.n_rows if rows is None else rows
        out = np.zeros((n, k))
        ok = self._row_free[:n]
        out[ok] = x[self._row_pos[:n][ok]]
        return out[:, 0] if vector else out

    def normal_compliance(self, nodes: np.ndarray, normals: np.ndarray) -> np.ndarray:
        """n^T C_jj n at candidate nodes ``nodes`` along unit ``normals``: each node's motion
        along its normal under a unit force along it; what ``ContactSurface.normal_stiffness``
        inverts (the side choice's compliance densities, whose values also blend the two
        surfaces' normals: exact, not estimated).

        f^T K^-1 f for f the unit force: where the body's factorization is a Cholesky one
        (PARDISO's positive definite type, K = P^T L L^T P) that is |L^-1 P f|^2, a forward
        substitution alone (``forward_solve``, PARDISO's: half a back-substitution's work,
        equal to round-off); otherwise a whole back-substitution. :data:`PROBE_CHUNK` nodes
        at a time."""
        nodes = np.asarray(nodes, dtype=int)
        d = self.dim
        out = np.zeros(len(nodes))
        factor = self.body.factor
        half = getattr(factor, "cholesky", False)  # (other backends: the whole solve)
        for start in range(0, len(nodes), PROBE_CHUNK):
            chunk = nodes[start:start + PROBE_CHUNK]
            n = normals[start:start + PROBE_CHUNK]
            cols = d * chunk[:, None] + np.arange(d)  # (k, d)
            k = np.arange(len(chunk))
            free = self._col_free[cols]
            if half:  # |L^-1 P f|^2, f the unit force on the node's free dofs
                rhs = np.zeros((self.n_free, len(chunk)), order="F")
                rhs[self._col_pos[cols][free], np.broadcast_to(k[:, None], cols.shape)[free]] \
                    = n[free]
                y = factor.forward_solve(rhs)
                out[start:start + len(chunk)] = np.einsum("ik,ik->k", y, y)
                continue
            F = np.zeros((self.n_cols, len(chunk)))
            F[cols, k[:, None]] = n
            U = self.apply(F, rows=self.n_cols)
            out[start:start + len(chunk)] = np.einsum("kd,kd->k", U[cols, k[:, None]], n)
        return out

    def local_blocks(self, nodes: np.ndarray) -> np.ndarray:
        """(len(nodes), dim, dim) a cheap stand-in for the flexibility's diagonal blocks at
        candidate nodes ``nodes``: the inverse of each node's own block of the stiffness (its
        dofs held by the neighbours alone). It scales as the flexibility does with the element
        size and the modulus (1 / (E h) in 3D), which is what a preconditioner needs, at no
        back-substitution; a supported dof gets zero."""
        d = self.dim
        dofs = self._cand_dofs[np.asarray(nodes, dtype=int)]  # (k, d)
        K = self.body.K
        blocks = np.stack([np.stack([np.asarray(K[dofs[:, a], dofs[:, b]]).ravel()
                                     for b in range(d)], axis=1) for a in range(d)], axis=1)
        free = self._col_free.reshape(-1, d)[np.asarray(nodes, dtype=int)]
        mask = free[:, :, None] & free[:, None, :]
        blocks = np.where(mask, blocks, np.eye(d)[None])
        inv = np.linalg.inv(blocks)
        return np.where(mask, inv, 0.0)
