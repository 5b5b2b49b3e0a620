"""The contact correction without dense blocks (issue 22): the flexibility applied, not formed.

The dense route condenses each body to its contact candidates (PARDISO's Schur complement,
inverted: ``ContactSurface.G``, (dim nc)^2 numbers) and forms the pair matrix W over every pair
node from it (:func:`~vfem.contact.solvers.pair_flexibility.pair_matrix`). Both grow
as the square of the contact zone: a 3D flat-on-flat interface of 100 x 100 facets has some 30,000
contact dofs, 7 GB for one body's block and minutes of dense factorization.

Here neither is formed. A body's flexibility on its candidates is applied to a set of nodal
forces by one back-substitution through its own (plain) factorization
(:class:`~vfem.contact.geometry.flexibility.SurfaceFlexibility`), and W to a vector of traction
values by one such back-substitution per body (:class:`PairOperator`): the forces the traction
values make (the same sparse ``N`` and ``T`` rows the dense route uses, eq. 4.4.11), each body's
motion under them, read at the pair nodes and their virtual nodes along the directions (eq. 4.2.4 in
matrix form). The linear complementarity problem of the correction
(:func:`~vfem.contact.solvers.complementarity.linear_complementarity`) is then solved with the same
block principal pivoting, each set's system by GMRES on this operator (W is not symmetric: the
paired variant reads penetrations at the virtual nodes but applies forces through N and T, so
conjugate gradients do not apply), preconditioned by an estimate of W's diagonal from each
node's own block of its body's stiffness (``SurfaceFlexibility.local_blocks``: no
back-substitution).

The answers are the dense route's to the iteration's tolerance (:data:`RTOL`, relative to the
right-hand side: the penetrations closed agree to about 1e-11 of the largest, the traction
values to 1e-8 or better; tests/test_matrix_free.py).
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, gmres

from ...executor import SERIAL
from .bordered import bordered_solve

log = logging.getLogger(__name__)

#: GMRES's tolerance on each active set's system, relative to its right-hand side
RTOL = 1e-12
#: GMRES's restart length and the most restarts
RESTART, MAX_RESTARTS = 200, 50


class PairOperator:
    """W applied to traction values without forming it (the module docstring), with the
    platen's column and row (penetration change per unit platen motion, platen reaction per
    unit traction value) as the dense route has them.

    ``dF``: per body, the sparse nodal forces on its candidate dofs per unit traction value
    ((dim nc, m), :func:`~vfem.contact.solvers.pair_flexibility.force_rows`); ``flex``:
    per body its :class:`~vfem.contact.geometry.flexibility.SurfaceFlexibility`; ``pairs``,
    ``directions``, ``offsets``: how the unknowns are laid out (pair by pair, direction by
    direction, node by node).
    """

    def __init__(self, surfaces, flex, dF, pairs, directions, offsets, executor=SERIAL):
        self.surfaces = surfaces
        self.executor = executor  # each body on the rank that owns it (vfem.executor)
        self.flex = flex
        self.dF = dF
        self.pairs = pairs
        self.directions = directions
        self.offsets = offsets
        self.m = int(offsets[-1])
        self.interp = [sp.csr_matrix(p.interp) for p in pairs]
        #: held points on a fine body's edge (``ContactPair.at``), sparse; None at its nodes
        self.at = [None if p.at is None else sp.csr_matrix(p.at) for p in pairs]
        self.bodies = sorted({b for p in pairs for b in (p.fine, p.coarse)})
        self.diagonal = self._diagonal()
        self.applications = 0  # columns of W applied, for the log and the benchmark

    def matvec(self, x: np.ndarray) -> np.ndarray:
        """W x for x (m,) or (m, k): one back-substitution per body."""
        x = np.asarray(x, dtype=float)
        vector = x.ndim == 1
        X = x[:, None] if vector else x
        k = X.shape[1]
        self.applications += k

        def move(b: int) -> np.ndarray:
            s = self.surfaces[b]
            f = self.dF[b] @ X  # (dim nc, k)
            u = self.flex[b].apply(np.asarray(f), rows=s.dim * s.nc) if f.any() else \
                np.zeros((s.dim * s.nc, k))
            return u.reshape(s.nc, s.dim, k)

        # each body on the rank that owns it, all at once (vfem.parallel; in order in serial)
        motion = self.executor.map(self.bodies, move)
        out = np.zeros((self.m, k))
        for i, pair in enumerate(self.pairs):
            n = len(pair.nodes)
            uf = pair.fine_read(motion[pair.fine])
            uc_flat = motion[pair.coarse].reshape(len(motion[pair.coarse]), -1)
            uc = (self.interp[i] @ uc_flat).reshape(uf.shape)
            for j, direction in enumerate(self.directions[i]):
                rows = slice(self.offsets[i] + j * n, self.offsets[i] + (j + 1) * n)
                out[rows] = np.einsum("id,idk->ik", pair.reading(j, direction), uf - uc)
        return out[:, 0] if vector else out

    def _diagonal(self) -> np.ndarray:
        """An estimate of W's diagonal (the preconditioner): each unknown's own force's motion
        read at itself, from stand-ins for the bodies' nodal flexibility blocks
        (``SurfaceFlexibility.local_blocks``) and the sparse force rows.

        A pair node's traction value moves its own node and its neighbours (its row of N)
        and, through T, the coarse nodes under it; W_ii reads node i's motion and its virtual
        node's along the direction. Only the diagonal blocks of each body's flexibility are
        kept (one node's force read at the same node) and those only estimated, so this is not
        W's diagonal but scales as it does: enough to weigh the unknowns of graded meshes and of
        bodies of different stiffness against each other."""
        diag = np.zeros(self.m)
        blocks = {}
        for b in self.bodies:
            s = self.surfaces[b]
            touched = np.unique(self.dF[b].nonzero()[0] // s.dim)
            blocks[b] = (touched, self.flex[b].local_blocks(touched))
        for i, pair in enumerate(self.pairs):
            n = len(pair.nodes)
            for j, direction in enumerate(self.directions[i]):
                cols = np.arange(self.offsets[i] + j * n, self.offsets[i] + (j + 1) * n)
                value = np.zeros(n)
                for b, read, sign in ((pair.fine, self.at[i], 1.0),
                                      (pair.coarse, self.interp[i], -1.0)):
                    s = self.surfaces[b]
                    touched, B = blocks[b]
                    local = np.full(s.nc, -1)
                    local[touched] = np.arange(len(touched))
                    f = self.dF[b][:, cols].tocoo()  # forces (body dof, unknown)
                    node, comp = f.row // s.dim, f.row % s.dim
                    # motion of each forced node (its own block) per unit traction value
                    u = B[local[node], :, comp] * f.data[:, None]  # (entries, dim)
                    if read is None:  # read at the pair node itself
                        at = pair.nodes[f.col] == node
                        weight = at.astype(float)
                    else:  # read at the virtual node (or a held point on the fine side's
                        # edge): the interpolation's weight of the forced node
                        weight = np.asarray(read[f.col, node]).ravel()
                    contrib = np.einsum("ed,ed->e", u, pair.reading(j, direction)[f.col]) \
                        * weight
                    np.add.at(value, f.col, sign * contrib)
                diag[cols] = value
        return diag

    def solve(self, index: np.ndarray, rhs: np.ndarray, border=None, x0=None
              ) -> tuple[np.ndarray, float]:
        """The traction values on unknowns ``index`` (zero elsewhere) with W's block there
        times them equal to ``rhs``; with ``border`` = (column, row, corner, extra) the bordered
        system of :func:`~vfem.contact.solvers.bordered.bordered_solve` (the platen's motion the
        last unknown). GMRES to :data:`RTOL`, preconditioned by the diagonal."""
        index = np.asarray(index, dtype=int)
        na = len(index)
        bordered = border is not None
        size = na + (1 if bordered else 0)
        if size == 0:
            return np.zeros(0), 0.0
        b = np.concatenate([rhs, [border[3]]]) if bordered else np.asarray(rhs, float)
        if bordered and border[2] == 0.0 and not np.any(border[1]):
            # the platen's equation says nothing (no node of its body in the set, nothing
            # else holding it): singular, solved by least squares on the set's block, formed
            # here from na columns, as the dense route does (bordered_solve)
            E = np.zeros((self.m, na))
            E[index, np.arange(na)] = 1.0
            block = self.matvec(E)[index] if na else np.zeros((0, 0))
            return bordered_solve(block, border[0], border[1], border[2], rhs, border[3])

        def apply(v):
            full = np.zeros(self.m)
            full[index] = v[:na]
            w = self.matvec(full)[index]
            if not bordered:
                return w
            col, row, corner, _ = border
            return np.concatenate([w + col * v[na], [row @ v[:na] + corner * v[na]]])

        d = np.abs(self.diagonal[index])
        d = np.where(d > 0, d, d.max() if d.size and d.max() > 0 else 1.0)
        if bordered:
            # the platen's row: its own stiffness, or else its largest coupling to the set
            corner = abs(border[2]) or (np.abs(border[1]).max() if na else 0.0) or 1.0
            d = np.concatenate([d, [corner]])
        A = LinearOperator((size, size), matvec=apply, dtype=float)
        M = LinearOperator((size, size), matvec=lambda v: v / d, dtype=float)
        start = None
        if x0 is not None:
            start = np.concatenate([x0, [0.0]]) if bordered else np.asarray(x0, dtype=float)
        bnorm = float(np.linalg.norm(b))
        if bnorm == 0.0:
            return np.zeros(na), 0.0
        x, info = gmres(A, b, x0=start, rtol=RTOL, atol=0.0, restart=min(RESTART, size),
                        maxiter=MAX_RESTARTS, M=M)
        residual = float(np.linalg.norm(apply(x) - b)) / bnorm
        if info != 0 and residual > 1e3 * RTOL:
            raise np.linalg.LinAlgError(
                f"the matrix-free contact solve did not converge on {na} contact unknowns "
                f"(relative residual {residual:.2e} after {MAX_RESTARTS} restarts of "
                f"{RESTART})")
        log.debug("matrix-free set of %d unknowns: relative residual %.2e", na, residual)
        return (x[:na], float(x[na])) if bordered else (x, 0.0)


def matrix_free_refusal(settings, bodies) -> str | None:
    """Why the matrix-free route cannot serve a model, or None where it can: it serves the
    paired variant of the virtual finite element method under small kinematics without
    friction (friction's tangential unknowns and the large-kinematics tangents are formed
    dense; a later step)."""
    if settings.method != "vfem":
        return f"the {settings.method} baseline solves one global system"
    if settings.variant != "paired":
        return "the thesis variant reads the flexibility node by node"
    large = [b.name for b in bodies if b.iterates]
    if large:
        return f"body {large[0]!r} has large kinematics"
    if settings.frictional:
        return "the model has friction"
    return None


__all__ = ["PairOperator", "matrix_free_refusal"]
