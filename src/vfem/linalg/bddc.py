"""One stiffness split into subdomains and solved by BDDC: the same small interface as a
factorization (``solve(b)`` for a vector or a block of columns, ``trailing_inverse``), so that a
body's condensation (:func:`vfem.bodies.condensation.setup`) uses it unchanged (issue 43).

The matrix ``A`` (n x n, symmetric positive definite: a body's stiffness on its free dofs) is
the sum of subdomain matrices ``A = sum_i R_i^T A_i R_i``: ``A_i`` the stiffness of subdomain
i's elements alone (its Neumann matrix) on its dofs ``R_i`` (:mod:`vfem.bodies.subdomains`
assembles and checks them). A dof of one subdomain only is *interior* (I); one shared by two
or more is on the *interface* (Γ). The interior unknowns are eliminated subdomain by subdomain
(a sparse factorization of each ``A_II^i``, any backend of :func:`vfem.linalg.factorize`),
which leaves the interface problem

    S u_Γ = g,   S = sum_i R_iΓ^T (A_ΓΓ^i - A_ΓI^i (A_II^i)^-1 A_IΓ^i) R_iΓ,

solved by the preconditioned conjugate gradient method. The preconditioner is BDDC (balancing
domain decomposition by constraints; Dohrmann 2003, Mandel and Dohrmann 2003): a subset Π of
the interface dofs is *primal* (continuous across subdomains, one global unknown each), the
rest *dual*. Each application

1. weights the residual by counting (``1 / number of subdomains sharing the dof``),
2. solves each subdomain's Neumann problem with its primal dofs held at zero
   (``A_rr^i``, its non-primal block, factorized once),
3. solves the coarse problem on the primal dofs, ``S_Π = sum_i (A_ΠΠ^i - A_Πr^i
   (A_rr^i)^-1 A_rΠ^i)``, assembled once and factorized,
4. adds the coarse correction to the local solutions and averages them back with the same
   weights.

The primal dofs are chosen by the caller such that every ``A_rr^i`` is nonsingular (each
subdomain is held against its rigid motions by its primal dofs or its supports): the coarse
problem then carries the floating subdomains' rigid motions, which is why the iterations stay
bounded as the subdomains multiply (docs/scaling.md, "One body over subdomains").

Everything the iteration touches is precomputed once: index maps, the sparse blocks
``A_IΓ``, ``A_ΓΓ``, ``A_Πr``, and the dense coarse extension restricted to the dual dofs
(``X_Δ = ((A_rr)^-1 A_rΠ)[Δ]``). An iteration is two sparse solves per subdomain (``A_II`` in
``S``, ``A_rr`` in the preconditioner) and one coarse solve, on all columns of a block at once.
"""

from __future__ import annotations

import logging
import time

import numpy as np
import scipy.sparse as sp

log = logging.getLogger(__name__)

#: PCG stops when every column's residual ``|g - S u_Γ|`` is at most this times ``|g|``. The
#: interface error is then at most ``cond(S) * RTOL`` relative; cond(S) grows as the mesh
#: size over the element size (about 1/h, not 1/h^2 as cond(A): a Schur complement; measured
#: 218 to 2,270 on 2,000 to 8,000-dof squares and cubes, docs/scaling.md §4), so 1e-12 keeps
#: the displacements equal to a direct solve's to better than 1e-8 of the largest (measured:
#: 1e-14 to 1e-13, tests/test_subdomains.py and benchmarks/subdomains.py), at a few more
#: iterations than 1e-8 would take.
RTOL = 1e-12
#: an iteration count no well-posed split problem reaches (measured: 8 to 40); beyond it the
#: split solve stops with an AnalysisError instead of returning an unconverged answer
MAX_ITERATIONS = 1000


class _Empty:
    """The factorization of a 0 x 0 matrix (a subdomain with no interior dofs)."""

    def solve(self, b):
        return np.zeros_like(b)


def _factor(A, backend, what):
    from . import factorize

    if A.shape[0] == 0:
        return _Empty()
    return factorize(A.tocsc(), backend, what=what)


class _Subdomain:
    """What one subdomain keeps for the iteration (see the module docstring)."""

    def __init__(self, A_i: sp.spmatrix, dofs: np.ndarray, interface: np.ndarray,
                 primal: np.ndarray, backend, what: str):
        A_i = sp.csr_matrix(A_i)
        on_iface = interface[dofs] >= 0
        self.dofs = dofs
        self.I = np.flatnonzero(~on_iface)
        G = np.flatnonzero(on_iface)
        self.gG = interface[dofs[G]]  # interface numbers of its interface dofs, local order
        self.A_IG = A_i[self.I][:, G].tocsr()
        self.A_GI = self.A_IG.T.tocsr()
        self.A_GG = A_i[G][:, G].tocsr()
        self.A_II = _factor(A_i[self.I][:, self.I], backend, f"{what} (interior)")
        is_p = primal[dofs] >= 0
        R = np.flatnonzero(~is_p)
        P = np.flatnonzero(is_p)
        self.gP = primal[dofs[P]]  # coarse numbers of its primal dofs
        p_of_G = is_p[G]
        self.gD = self.gG[~p_of_G]  # interface numbers of its dual dofs
        self.gGP = self.gG[p_of_G]
        # positions of the dual dofs in R (both sorted by local number)
        self.dual_in_R = np.searchsorted(R, G[~p_of_G])
        self.nR = len(R)
        self.A_rr = _factor(A_i[R][:, R], backend, f"{what} (primal dofs held)")
        self.A_Pr = A_i[P][:, R].tocsr()
        X = np.zeros((len(R), len(P)))  # (A_rr)^-1 A_rΠ
        if len(P):
            X[:] = self.A_rr.solve(np.asarray(A_i[R][:, P].todense())).reshape(X.shape)
        self.S_P = np.asarray(A_i[P][:, P].todense()) - self.A_Pr @ X
        self.S_P = 0.5 * (self.S_P + self.S_P.T)
        self.X_D = np.ascontiguousarray(X[self.dual_in_R])  # only its dual rows are read

    def schur(self, u: np.ndarray) -> np.ndarray:
        """(its interface dofs, k) ``S_i u`` for the global interface block ``u``."""
        uG = u[self.gG]
        y = self.A_II.solve(self.A_IG @ uG).reshape(len(self.I), uG.shape[1])
        return self.A_GG @ uG - self.A_GI @ y  # (a backend may return one column as 1D)


class BDDCSolve:
    """A sparse SPD matrix split into subdomains, solved by BDDC-preconditioned CG on the
    interface; ``solve(b)`` and ``trailing_inverse`` as a factorization's
    (:func:`vfem.linalg.factorize`).

    Args:
        n: the matrix's size.
        matrices: each subdomain's matrix ``A_i`` on its dofs.
        dofs: each subdomain's dofs (sorted global numbers, 0..n-1).
        primal: (n,) bool, the primal dofs (all on the interface).
        backend: the factorization backend of the subdomain and coarse matrices.
        trailing: dofs whose block of ``A^-1`` to compute (``trailing_inverse``): by block PCG
            on their unit columns, one right-hand side per dof.
        rtol: PCG's relative residual (:data:`RTOL`).
        what: names the matrix in messages and the log, e.g. ``"body 'flat'"``.
    """

    name = "bddc"

    def __init__(self, n: int, matrices, dofs, primal: np.ndarray, backend=None,
                 trailing: np.ndarray | None = None, rtol: float = RTOL,
                 what: str = "a matrix"):
        t0 = time.perf_counter()
        self.shape = (n, n)
        self.what = what
        self.rtol = rtol
        count = np.zeros(n, dtype=int)
        for d in dofs:
            count[d] += 1
        if (count == 0).any():
            raise ValueError(f"{what}: {int((count == 0).sum())} dofs in no subdomain")
        on_iface = count > 1
        if (primal & ~on_iface).any():
            raise ValueError(f"{what}: a primal dof not on the interface")
        self.interface = np.flatnonzero(on_iface)
        iface_no = -np.ones(n, dtype=int)
        iface_no[self.interface] = np.arange(len(self.interface))
        primal_dofs = np.flatnonzero(primal)
        primal_no = -np.ones(n, dtype=int)
        primal_no[primal_dofs] = np.arange(len(primal_dofs))
        self.weight = 1.0 / count[self.interface]  # counting weights
        self.subdomains = [
            _Subdomain(A_i, np.asarray(d, dtype=int), iface_no, primal_no, backend,
                       f"{what}, subdomain {i}")
            for i, (A_i, d) in enumerate(zip(matrices, dofs, strict=True))]
        # the coarse matrix, assembled from the subdomains' dense blocks
        rows, cols, vals = [], [], []
        for s in self.subdomains:
            rows.append(np.repeat(s.gP, len(s.gP)))
            cols.append(np.tile(s.gP, len(s.gP)))
            vals.append(s.S_P.ravel())
            del s.S_P
        m = len(primal_dofs)
        S_c = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                            shape=(m, m)) if m else sp.csc_matrix((0, 0))
        self.coarse = _factor(S_c, backend, f"{what}, coarse problem")
        self.primal_iface = iface_no[primal_dofs]  # the primal dofs' interface numbers
        self.n_primal = m
        self.iterations: list[int] = []  # per solve, the most any column took
        self.setup_s = time.perf_counter() - t0
        log.info("%s: %d subdomains, %d interface dofs, %d primal; set up in %.2f s", what,
                 len(self.subdomains), len(self.interface), m, self.setup_s)
        self.trailing_inverse = None
        self.order = None
        if trailing is not None and len(trailing):
            trailing = np.asarray(trailing, dtype=int)
            E = np.zeros((n, len(trailing)))
            E[trailing, np.arange(len(trailing))] = 1.0
            t1 = time.perf_counter()
            inv = self.solve(E)[trailing]
            self.trailing_inverse = 0.5 * (inv + inv.T)
            log.info("%s: the flexibility on %d trailing dofs by block PCG in %.2f s (%d "
                     "iterations)", what, len(trailing), time.perf_counter() - t1,
                     self.iterations[-1])

    # -- the interface operator and its preconditioner --------------------------------------

    def _schur(self, u: np.ndarray) -> np.ndarray:
        out = np.zeros_like(u)
        for s in self.subdomains:
            out[s.gG] += s.schur(u)  # a subdomain's interface dofs are distinct: no add.at
        return out

    def _precondition(self, r: np.ndarray) -> np.ndarray:
        k = r.shape[1]
        rw = r * self.weight[:, None]
        coarse_rhs = np.zeros((self.n_primal, k))
        local = []
        for s in self.subdomains:
            rR = np.zeros((s.nR, k))
            rR[s.dual_in_R] = rw[s.gD]
            wR = s.A_rr.solve(rR).reshape(s.nR, k)
            local.append(wR[s.dual_in_R])
            coarse_rhs[s.gP] += rw[s.gGP] - s.A_Pr @ wR
        uP = self.coarse.solve(coarse_rhs).reshape(self.n_primal, k)
        z = np.zeros_like(r)
        for s, wD in zip(self.subdomains, local):
            z[s.gD] += wD - s.X_D @ uP[s.gP]
        z *= self.weight[:, None]  # the weighted average of the subdomains' values
        z[self.primal_iface] = uP  # continuous: one value, every subdomain's
        return z

    # -- solves ------------------------------------------------------------------------------

    def _pcg(self, g: np.ndarray) -> np.ndarray:
        """Independent PCG on each column of ``g`` (interface, k), all columns' operator
        applications together; a converged column leaves the block."""
        x = np.zeros_like(g)
        r = g.copy()
        norm0 = np.linalg.norm(g, axis=0)
        active = np.flatnonzero(norm0 > 0)
        if not len(active):
            self.iterations.append(0)
            return x
        z = self._precondition(r[:, active])
        p = np.zeros_like(g)
        p[:, active] = z
        rz = np.zeros(g.shape[1])
        rz[active] = np.einsum("ij,ij->j", r[:, active], z)
        worst = 1.0
        for it in range(1, MAX_ITERATIONS + 1):
            pa = p[:, active]
            q = self._schur(pa)
            alpha = rz[active] / np.einsum("ij,ij->j", pa, q)
            x[:, active] += alpha * pa
            r[:, active] -= alpha * q
            res = np.linalg.norm(r[:, active], axis=0) / norm0[active]
            worst = float(res.max())
            active = active[res > self.rtol]
            if not len(active):
                self.iterations.append(it)
                return x
            z = self._precondition(r[:, active])
            rz_new = np.einsum("ij,ij->j", r[:, active], z)
            p[:, active] = z + (rz_new / rz[active]) * p[:, active]
            rz[active] = rz_new
        from ..errors import AnalysisError

        raise AnalysisError(f"{self.what}: the subdomains' interface problem did not converge "
                            f"in {MAX_ITERATIONS} iterations (relative residual {worst:.1e}, "
                            f"asked {self.rtol:.0e}); is the body held against every "
                            "rigid-body motion? Try fewer subdomains")

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A^-1 b`` for a vector or a block of columns (n, k)."""
        b = np.asarray(b, dtype=float)
        vector = b.ndim == 1
        B = b[:, None] if vector else b
        k = B.shape[1]
        # eliminate the interiors: g = b_Γ - sum_i A_ΓI^i (A_II^i)^-1 b_I^i
        g = B[self.interface].copy()
        interior = []
        for s in self.subdomains:
            yI = s.A_II.solve(B[s.dofs[s.I]]).reshape(len(s.I), k)
            interior.append(yI)
            g[s.gG] -= s.A_GI @ yI
        uG = self._pcg(g)
        x = np.empty_like(B)
        x[self.interface] = uG
        for s, yI in zip(self.subdomains, interior):
            # u_I = (A_II)^-1 (b_I - A_IΓ u_Γ) = y_I - (A_II)^-1 A_IΓ u_Γ
            x[s.dofs[s.I]] = yI - s.A_II.solve(s.A_IG @ uG[s.gG]).reshape(len(s.I), k)
        log.debug("%s: split solve of %d column%s, %d PCG iterations", self.what, k,
                 "" if k == 1 else "s", self.iterations[-1])
        return x[:, 0] if vector else x
