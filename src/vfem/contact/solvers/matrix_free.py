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
conjugate gradients do not apply), preconditioned by FETI's lumped preconditioner written for
this W (below); a small set (up to :data:`DIRECT_UP_TO` unknowns) is solved with its block
formed from its columns, all at once, those of earlier sets kept (:meth:`PairOperator.columns`).

**The preconditioner** (issue 40). Per body b let D_b be the nodal forces on its candidate dofs
per unit traction value ((dim nc_b, m): N's rows on the compatibility side, -T's on the other,
:func:`~vfem.contact.solvers.pair_flexibility.force_rows`), R_b the reading of their motion
((m, dim nc_b): + at each pair's point along its reading direction, - at its virtual point
through the interpolation weights, :func:`~vfem.contact.solvers.pair_flexibility.read_rows`)
and C_b = S_b^-1 its flexibility there (S_b: the Schur complement of its stiffness on those
dofs), so that W = sum_b R_b C_b D_b. For any stand-in Q_b of C_b let

    H = sum_b R_b Q_b D_b,     L = sum_b R_b Q_b S_b Q_b D_b,     M = H^-1 L H^-1.

With Q_b = C_b, H = W and L = W, so M = W^-1: M is FETI's B_D S B_D^T with the scaled jump
B_D = H^-1 R Q (R for B, D for B^T; the "K-scaling" that weighs the bodies by flexibility:
for one node between springs k_1 and k_2, H = 1/k_1 + 1/k_2 = L and M is W^-1 exactly). Here
Q_b is each node's own (dim, dim) block of the stiffness, inverted
(``SurfaceFlexibility.local_blocks``, zero on supported dofs) and S_b is the stiffness's own
block on the candidate dofs K_cc (the *lumped* preconditioner): H and L are sparse (m, m) —
H has N's and T's pattern, L two rings of neighbours more (at 8,771 unknowns 281k and 634k
entries) — formed once, each body's part on its owner; H is factorized (SuperLU) once per
contact set. An application: two sparse triangular solves and a sparse product, no
back-substitution. Where H cannot be factorized on a set, or GMRES does not converge with M,
the set is solved again with H's diagonal (the preconditioner before issue 40, its estimate
of W's diagonal: :attr:`PairOperator.diagonal`). A platen's bordered system is preconditioned
by the block factorization with M for W^-1 (:func:`bordered_preconditioner`).

Why this one: GMRES products to 1e-12 (restart 200) on the first contact set of
``benchmarks/matrix_free.py``'s plates (0.1 thick, 2 layers), and of thick ones (0.5, 8
layers), and the real parts of the spectrum of the preconditioned W (W formed, each candidate
applied to it; the Dirichlet one with each body's exact S_b):

    plates, divisions (set)   diagonal           H^-1 alone        lumped M          Dirichlet
    thin, 18 (400)            64 [0.16, 6.6]     14 [0.93, 1.7]    17 [1.01, 2.5]    9 [1.00, 1.2]
    thin, 40 (1,764)          108 [0.11, 15]     25 [0.80, 3.9]    17 [1.03, 2.5]    11 [1.00, 1.4]
    thick, 16 (324)           69 [0.15, 29]      21 [0.90, 7.3]    23 [1.02, 10]     10 [1.00, 1.6]
    thick, 32 (1,156)         121 [0.11, 62]     31 [0.81, 16]     23 [1.03, 10]     12 [1.00, 2.0]

The diagonal's smallest eigenvalues are N's checkerboard modes (N is the facets' consistent
mass: on bilinear facets its highest mode is 1/9 of its lumped one) and its largest the
flexibility's smooth modes; H^-1 takes out N (and the bodies' relative stiffness), K_cc the
short waves of the flexibility, and the lumped M's spectrum then stays put as the zone grows
(19-20 products a solve at 18, 40, 70 and 100 divisions: docs/scaling.md), whatever the
bodies' stiffness ratio (the plates at 30 divisions, moduli 1, 29 and 1,000 to 1: 18-20
products a solve, the diagonal 48-83) and on graded meshes (the sphere and its platen, 141
unknowns: 33, the diagonal 57). The Dirichlet
preconditioner counts fewer products (9-12) but applies S_b: a solve with each body's stiffness
less its candidate dofs, a second factorization of every body and two more back-substitutions
per product, which cost more than the 6-11 products it saves; the sparse approximate inverse
of a node's neighbourhood (its local dense flexibility) needs W's or C's entries there, a
back-substitution per node or probing polluted by C's slow (1/r) decay. The lumped M costs
nothing beside a product.

The answers are the dense route's to the iteration's tolerance (:data:`RTOL`, relative to the
right-hand side: the penetrations closed agree to about 1e-11 of the largest, the traction
values to 1e-8 or better; tests/test_matrix_free.py, tests/test_matrix_free_precondition.py).
"""

from __future__ import annotations

import logging
import warnings

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, MatrixRankWarning, gmres, splu

from ...executor import SERIAL
from .bordered import bordered_solve

log = logging.getLogger(__name__)

#: GMRES's tolerance on each active set's system, relative to its right-hand side
RTOL = 1e-12
#: GMRES's restart length and the most restarts
RESTART, MAX_RESTARTS = 200, 50
#: the preconditioner of GMRES: ``"lumped"`` (:meth:`PairOperator.precondition`) or
#: ``"diagonal"`` (H's diagonal, the one before issue 40; for comparison:
#: ``benchmarks/matrix_free.py --preconditioner``)
PRECONDITIONER = "lumped"
#: sets of at most this many unknowns are solved with their block formed (:meth:`PairOperator.
#: columns`), not by GMRES: its columns at once cost about a quarter as many products
#: (measured, 32 to 128 columns), below GMRES's 15-35 products a set
DIRECT_UP_TO = 128
#: the most columns of W kept for later small sets (a set and its neighbours in the pivoting
#: share most of their nodes), and the most memory they may take (each m numbers; at least
#: one set's are kept)
KEPT_COLUMNS, KEPT_BYTES = 4 * DIRECT_UP_TO, 64 << 20


class PairOperator:
    """W applied to traction values without forming it (the module docstring), with the
    preconditioner that knows the surfaces' stiffness (:meth:`precondition`).

    ``dF``: per body, the sparse nodal forces on its candidate dofs per unit traction value
    ((dim nc, m), :func:`~vfem.contact.solvers.pair_flexibility.force_rows`); ``read``: per
    body, the sparse readings of its candidate dofs' motion ((m, dim nc),
    :func:`~vfem.contact.solvers.pair_flexibility.read_rows`); ``flex``: per body its
    :class:`~vfem.contact.geometry.flexibility.SurfaceFlexibility`. W = sum over bodies of
    ``read[b] @ C_b @ dF[b]``.
    """

    def __init__(self, surfaces, flex, dF, read, executor=SERIAL):
        self.surfaces = surfaces
        self.executor = executor  # each body on the rank that owns it (vfem.executor)
        self.flex = flex
        self.dF = dF
        self.read = read
        self.m = int(dF[0].shape[1]) if dF else 0
        self.bodies = [b for b in range(len(surfaces)) if dF[b].nnz or read[b].nnz]
        # the preconditioner's two sparse (m, m) matrices, each body's part on its owner
        parts = executor.map(self.bodies, self._lumped)
        self.H = sum((parts[b][0] for b in self.bodies), sp.csr_matrix((self.m, self.m)))
        self.L = sum((parts[b][1] for b in self.bodies), sp.csr_matrix((self.m, self.m)))
        #: H's diagonal: each unknown's own force's motion read at itself through the
        #: nodes' own stiffness blocks, the estimate of W's diagonal that preconditioned
        #: before (and still does where H cannot be factorized)
        self.diagonal = self.H.diagonal()
        self.applications = 0  # columns of W applied, for the log and the benchmark
        #: per GMRES solve: (unknowns, products of W, the preconditioner: "lumped"/"diagonal")
        self.history: list[tuple[int, int, str]] = []
        self._kept = None  # (index, the preconditioner there) of the last set
        self._columns: dict[int, np.ndarray] = {}  # W's columns formed (:meth:`columns`)

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
            return self.flex[b].apply(np.asarray(f), rows=s.dim * s.nc) if f.any() else \
                np.zeros((s.dim * s.nc, k))

        # each body on the rank that owns it, all at once (vfem.parallel; in order in serial)
        motion = self.executor.map(self.bodies, move)
        out = np.zeros((self.m, k))
        for b in self.bodies:
            out += self.read[b] @ motion[b]
        return out[:, 0] if vector else out

    def columns(self, index: np.ndarray) -> np.ndarray:
        """W's columns ``index`` ((m, len(index))), those not kept from earlier sets applied
        at once (a back-substitution of many columns costs a few of one: 32 columns 7-9
        times one, measured on the sphere's and the plates' bodies); up to
        :data:`KEPT_COLUMNS` kept (:data:`KEPT_BYTES`)."""
        missing = [j for j in dict.fromkeys(int(i) for i in index) if j not in self._columns]
        if missing:
            kept = max(DIRECT_UP_TO, min(KEPT_COLUMNS, KEPT_BYTES // (8 * max(self.m, 1))))
            if len(self._columns) + len(missing) > kept:
                self._columns.clear()
            E = np.zeros((self.m, len(missing)))
            E[missing, np.arange(len(missing))] = 1.0
            for j, column in zip(missing, self.matvec(E).T):
                self._columns[j] = column.copy()
        return np.column_stack([self._columns[int(i)] for i in index]) if len(index) else \
            np.zeros((self.m, 0))

    def _lumped(self, b: int) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Body ``b``'s parts of H = sum R Q D and L = sum R Q K Q D (the module docstring):
        Q its nodes' own stiffness blocks inverted (``SurfaceFlexibility.local_blocks``, zero
        on supported dofs), K its stiffness on the candidate dofs that the unknowns force or
        read; sparse (m, m), no back-substitution."""
        s = self.surfaces[b]
        d = s.dim
        R, D = self.read[b].tocsc(), self.dF[b].tocsr()
        dofs = np.union1d(np.flatnonzero(np.diff(R.indptr)), np.flatnonzero(np.diff(D.indptr)))
        nodes = np.unique(dofs // d)
        dofs = (d * nodes[:, None] + np.arange(d)).ravel()
        blocks = self.flex[b].local_blocks(nodes)  # (k, d, d)
        k = len(nodes)
        at = (d * np.arange(k)[:, None, None] + np.arange(d)[:, None]).repeat(d, axis=2)
        Q = sp.csr_matrix((blocks.ravel(), (at.ravel(), at.transpose(0, 2, 1).ravel())),
                          shape=(d * k, d * k))
        cand = s.candidate_dofs[dofs]
        K = sp.csr_matrix(s.body.K)[cand][:, cand]
        RQ = (R[:, dofs] @ Q).tocsr()
        QD = (Q @ D[dofs]).tocsr()
        return (RQ @ D[dofs]).tocsr(), (RQ @ (K @ QD)).tocsr()

    def precondition(self, index: np.ndarray):
        """The preconditioner on the set ``index`` as a function of a vector (the set's
        unknowns): H^-1 L H^-1 there (the module docstring), H's factors kept while the set
        holds; None where H cannot be factorized there (the diagonal then)."""
        if self._kept is not None and np.array_equal(self._kept[0], index):
            return self._kept[1]
        H = self.H[index][:, index].tocsc()
        L = self.L[index][:, index].tocsr()
        apply = None
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", MatrixRankWarning)
                lu = splu(H)
            if np.all(np.isfinite(lu.U.data)):
                def apply(v, lu=lu, L=L):
                    return lu.solve(L @ lu.solve(v))
        except (RuntimeError, MatrixRankWarning) as exc:
            log.debug("matrix-free set of %d unknowns: H not factorized (%s): the diagonal",
                      len(index), exc)
        self._kept = (np.array(index, copy=True), apply)
        return apply

    def solve(self, index: np.ndarray, rhs: np.ndarray, border=None, x0=None
              ) -> tuple[np.ndarray, float]:
        """The traction values on unknowns ``index`` (zero elsewhere) with W's block there
        times them equal to ``rhs``; with ``border`` = (column, row, corner, extra) the bordered
        system of :func:`~vfem.contact.solvers.bordered.bordered_solve` (the platen's motion the
        last unknown). GMRES to :data:`RTOL`, preconditioned by :meth:`precondition` (the
        diagonal where that cannot be factorized, or where GMRES does not converge with it)."""
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
            block = self.columns(index)[index] if na else np.zeros((0, 0))
            return bordered_solve(block, border[0], border[1], border[2], rhs, border[3])
        if 0 < na <= DIRECT_UP_TO:
            # a small set: its block formed from its columns (all at once, those of earlier
            # sets kept) and solved as the dense route solves it
            before = self.applications
            block = self.columns(index)[index]
            try:
                if bordered:
                    x, move = bordered_solve(block, border[0], border[1], border[2], rhs,
                                             border[3], lu_first=True)
                else:
                    x, move = np.linalg.solve(block, rhs), 0.0
            except np.linalg.LinAlgError:
                pass  # singular: GMRES says so, below
            else:
                self.history.append((size, self.applications - before, "direct"))
                return x, move

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
        corner = 1.0
        if bordered:
            # the platen's row: its own stiffness, or else its largest coupling to the set
            corner = abs(border[2]) or (np.abs(border[1]).max() if na else 0.0) or 1.0
        lumped = self.precondition(index) if na and PRECONDITIONER == "lumped" else None

        def preconditioners():
            if lumped is not None and not bordered:
                yield "lumped", lumped
            elif lumped is not None:
                yield "lumped", bordered_preconditioner(lumped, border, corner)
            yield "diagonal", lambda v: (np.concatenate([v[:na] / d, v[na:] / corner])
                                         if bordered else v / d)

        A = LinearOperator((size, size), matvec=apply, dtype=float)
        start = None
        if x0 is not None:
            start = np.concatenate([x0, [0.0]]) if bordered else np.asarray(x0, dtype=float)
        bnorm = float(np.linalg.norm(b))
        if bnorm == 0.0:
            return np.zeros(na), 0.0
        for name, M in preconditioners():
            before = self.applications
            x, info = gmres(A, b, x0=start, rtol=RTOL, atol=0.0, restart=min(RESTART, size),
                            maxiter=MAX_RESTARTS,
                            M=LinearOperator((size, size), matvec=M, dtype=float))
            residual = float(np.linalg.norm(apply(x) - b)) / bnorm
            self.history.append((size, self.applications - before, name))
            if info == 0 or residual <= 1e3 * RTOL:
                break
            log.debug("matrix-free set of %d unknowns: GMRES with the %s preconditioner "
                      "stopped at relative residual %.2e", na, name, residual)
        else:
            raise np.linalg.LinAlgError(
                f"the matrix-free contact solve did not converge on {na} contact unknowns "
                f"(relative residual {residual:.2e} after {MAX_RESTARTS} restarts of "
                f"{RESTART})")
        log.debug("matrix-free set of %d unknowns: relative residual %.2e", na, residual)
        return (x[:na], float(x[na])) if bordered else (x, 0.0)


def bordered_preconditioner(M, border, corner: float):
    """The bordered system's preconditioner from the set's, ``M`` (a stand-in for W^-1): the
    block factorization of [[W, c], [r^T, k]] with M for W^-1, the platen's equation on its
    Schur complement s = k - r^T M c (one more application of M a set); block-diagonal,
    the platen's row scaled by ``corner``, where s vanishes."""
    col, row, k, _ = border
    Mc = M(col)
    s = k - float(row @ Mc)
    if not np.isfinite(s) or abs(s) <= 1e-12 * (abs(k) + float(np.abs(row) @ np.abs(Mc))):
        return lambda v: np.concatenate([M(v[:-1]), v[-1:] / corner])

    def apply(v):
        y = M(v[:-1])
        t = (v[-1] - float(row @ y)) / s
        return np.concatenate([y - Mc * t, [t]])
    return apply


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
