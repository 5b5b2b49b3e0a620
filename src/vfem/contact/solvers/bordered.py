"""The platen's bordered system, which every formulation's compatibility correction solves
(:func:`bordered_solve`), and the pair matrix's factors kept while it recurs, each new contact
set solved from the factors of a set near it (:class:`ReusedFactor`): the solvers' dense
linear algebra, below the formulations, so that
they, the complementarity solver and the matrix-free operator
(:mod:`vfem.contact.solvers.matrix_free`) share it without importing each other."""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...threads import dense_threads


def bordered_solve(W: np.ndarray, column: np.ndarray, row: np.ndarray, corner: float,
                   rhs: np.ndarray, extra: float, lu_first: bool = False
                   ) -> tuple[np.ndarray, float]:
    """The corrections ``x`` and the platen motion ``d`` from the bordered system

        [ W    column ] [x]   [rhs  ]
        [ row  corner ] [d] = [extra]

    ``W``: the compatibility conditions' flexibility (penetration change per unit force or
    traction value at the corrected nodes, eq. 4.2.4 in matrix form); ``column``: their change
    per unit platen motion; ``row``: the platen's reaction per unit correction; ``corner``: the
    platen's own stiffness (zero for a body only contact holds); ``extra``: the force the platen
    still lacks. Least squares (the system may be singular: a platen body without a node in
    contact); ``lu_first``: an LU solve first, least squares (an SVD, ten times dearer) only
    where that fails.
    """
    m = len(rhs)
    A = bordered_matrix(W, column, row, corner)
    b = np.concatenate([rhs, [extra]])
    if lu_first:
        try:
            sol = np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            sol = np.linalg.lstsq(A, b, rcond=None)[0]
    else:
        sol = np.linalg.lstsq(A, b, rcond=None)[0]
    return sol[:m], float(sol[m])


def bordered_matrix(W: np.ndarray, column: np.ndarray, row: np.ndarray, corner: float
                    ) -> np.ndarray:
    """The matrix of :func:`bordered_solve`'s system."""
    m = len(W)
    A = np.zeros((m + 1, m + 1))
    A[:m, :m] = W
    A[:m, m] = column
    A[m, :m] = row
    A[m, m] = corner
    return A


class ReusedFactor:
    """The LU factors of the last matrix solved, kept for as long as the matrix recurs; and
    (:meth:`solve_set`) the factors of the sets of one matrix W, each new set solved from the
    factors of a set near it.

    Under small kinematics the paired variant's pair matrix over an active set is the same
    whenever that set recurs (its flexibility over every pair node is fixed): in the
    iterations that only adjust the traction values, and in the steps whose contact set holds.
    It is factorized when the set changes, not at every solve (issue 19, item 4: the dense solve
    is O(m^3), seconds at a few thousand nodes). Partial pivoting as ``numpy.linalg.solve``.
    """

    def __init__(self):
        self.key = None
        self.factors = None
        self._bases: list[_Base] = []  # solve_set's factorized sets, the latest last
        self._set = None  # solve_set's current set: (W, key, its solver)

    def solve(self, key, matrix, b: np.ndarray) -> np.ndarray | None:
        """The solution of ``matrix() x = b``, ``matrix`` called only when ``key`` is new;
        None when the matrix is singular (an exactly zero pivot)."""
        if key != self.key:
            self.factors = _factorized(matrix())
            self.key = key
        return None if self.factors is None else _solve(self.factors, b)

    def solve_set(self, W, a: np.ndarray, b: np.ndarray, border=None) -> np.ndarray | None:
        """The solution of ``W[a, a] x = b``, or with ``border`` = (column, row, corner) of
        the bordered system (:func:`bordered_matrix`; ``b`` then ends with the border's
        value and so does the solution); None where the matrix is singular (an exactly zero
        pivot), as :meth:`solve`. ``W`` dense, or sparse (SuperLU's factors, its
        fill-reducing ordering and partial pivoting); the same W (its identity is checked)
        for as long as its sets are to be reused.

        The complementarity's sets follow one another with a few nodes in or out (the
        pivoting's last sets on the four-plate stack of ``benchmarks/ranks.py``: 1,777 nodes,
        then 41, 2 and 2 changed), so a new set is solved from the factors of a set already
        factorized, B, where the two differ by at most :data:`UPDATE_SHARE` of the set's
        nodes: the set's system is W over B and the nodes added, S, with the nodes dropped,
        D, held at zero by multipliers that take their rows' place,

            [ W_BB   W_BS   E_D   c_B ] [x_B]   [b_B]
            [ W_SB   W_SS    0    c_S ] [x_S]   [b_S]
            [ E_D'    0      0     0  ] [ l ] = [ 0 ]
            [ r_B    r_S     0     g  ] [ d ]   [ e ]

        (c, r, g: the border, where there is one), eliminated through W_BB's factors: k
        back-substitutions and a k x k system for k = |S| + |D| (+ 1), O(m^2 k) in place of
        the set's O(m^3) factorization. Each solution is refined once on the set's own
        matrix and taken only where its residual is then within LU's own bound, the order
        times the unit round-off times |M| |x| + |b| (backward stable, as the factorization
        it replaces); otherwise, or where the k x k system is singular or nearly
        (:data:`NEAR_SINGULAR`), the set is factorized whole as before. (A sparse W's sets
        are factorized whole: SuperLU's factorization of a stack's block-tridiagonal set
        costs a few of its back-substitutions, 9 ms against 5 ms on the 16-plate stack.)
        Factorized sets are kept while their factors take no more memory than W itself (the
        least recently used dropped first, the latest always kept), so a later step that
        walks the same sets (small kinematics, the held nodes' start) finds them factorized.
        """
        key = (border is not None, a.tobytes())
        if self._set is None or self._set[0] is not W or self._set[1] != key:
            self._set = (W, key, self._prepare(W, a, border))
        solver = self._set[2]
        return None if solver is None else solver(b)

    def _prepare(self, W, a: np.ndarray, border):
        """:meth:`solve_set`'s solver for the set ``a``: a function of the right-hand side,
        or None where the set's matrix is singular."""
        self._bases = [base for base in self._bases if base.W is W]
        if not len(a):  # nothing but the border (or nothing)
            return _bordered_whole(W, a, border) if border is not None else (lambda b: b)
        mask = np.zeros(W.shape[0], dtype=bool)
        mask[a] = True
        best = min(self._bases, key=lambda base: base.distance(mask), default=None)
        dense = not sp.issparse(W)
        if best is not None:
            k = best.distance(mask) + (border is not None)
            if k == 0:  # factorized before
                self._touch(best)
                return best.solve
            if dense and k <= UPDATE_SHARE * len(a):
                solver = _Updated.make(best, W, mask, a, border)
                if solver is not None:
                    self._touch(best)
                    return _Checked(solver, W, a, border,
                                    lambda: self._whole(W, a, mask, border))
        if not dense and border is not None:
            return _bordered_whole(W, a, border)
        return self._whole(W, a, mask, border)

    def _whole(self, W, a: np.ndarray, mask: np.ndarray, border):
        """The set factorized (kept as a base), its bordered system solved from it (or, where
        W over the set is singular, the bordered matrix factorized whole); None where
        singular."""
        factors = _factorized(block(W, a, a, dense=False))
        if factors is None:
            return None if border is None else _bordered_whole(W, a, border)
        base = _Base(W, mask, a, factors)
        self._bases.append(base)
        kept, size = [], 0
        for one in reversed(self._bases):  # the latest first, within W's own entries
            size += one.size
            if size <= _entries(W) or not kept:
                kept.append(one)
        self._bases = kept[::-1]
        if border is None:
            return base.solve
        solver = _Updated.make(base, W, mask, a, border)
        if solver is None:  # the border singular over the set, or nearly: factorized whole
            return _bordered_whole(W, a, border)
        return _Checked(solver, W, a, border, lambda: _bordered_whole(W, a, border))

    def _touch(self, base: _Base) -> None:
        """``base`` the most recently used."""
        self._bases.remove(base)
        self._bases.append(base)


#: a set is solved from a factorized set's factors (:meth:`ReusedFactor.solve_set`) where
#: they differ by at most this share of its nodes: k back-substitutions cost about 3 k / m of
#: a dense factorization of order m (measured at m = 1,777: 40 right-hand sides 0.07 of it,
#: 400 0.73)
UPDATE_SHARE = 1 / 6


#: a set's k x k system (:meth:`ReusedFactor.solve_set`) whose smallest pivot is at most this
#: share of the terms it is made of is taken as singular or nearly, and the set factorized
#: whole (which finds it singular only at an exactly zero pivot, as before)
NEAR_SINGULAR = 1e-8


def _entries(W) -> int:
    """W's stored entries."""
    return int(W.nnz) if sp.issparse(W) else int(W.size)


def block(W, rows: np.ndarray, cols: np.ndarray, dense: bool = True):
    """W's block over ``rows`` x ``cols``, dense W or sparse: dense, or (``dense`` False) as
    W is."""
    if sp.issparse(W):
        block = W[rows][:, cols]
        return block.toarray() if dense else sp.csc_matrix(block)
    return W[np.ix_(rows, cols)]


def _factorized(A):
    """A's factors (a dense matrix's LU with partial pivoting, a sparse one's SuperLU), or
    None where a pivot is exactly zero."""
    if sp.issparse(A):
        try:
            return spla.splu(sp.csc_matrix(A))
        except RuntimeError:  # "Factor is exactly singular"
            return None
    with dense_threads(len(A)), warnings.catch_warnings():
        warnings.simplefilter("ignore", sla.LinAlgWarning)  # singular: None
        lu, piv = sla.lu_factor(A, check_finite=False, overwrite_a=True)
    return None if (np.diag(lu) == 0.0).any() else (lu, piv)


def _solve(factors, b: np.ndarray) -> np.ndarray:
    """``b`` through :func:`_factorized`'s factors."""
    if isinstance(factors, tuple):
        with dense_threads(len(factors[0])):
            return sla.lu_solve(factors, b, check_finite=False)
    return factors.solve(np.asarray(b, dtype=float))


def _set_matrix(W, a: np.ndarray, border):
    """The set's own matrix (bordered where there is a border), dense or sparse as W."""
    M = block(W, a, a, dense=False)
    if border is None:
        return M
    column, row, corner = border
    if sp.issparse(M):
        return sp.csr_matrix(sp.bmat([[M, sp.csr_matrix(np.asarray(column)[:, None])],
                                      [sp.csr_matrix(np.asarray(row)[None, :]),
                                       sp.csr_matrix([[corner]])]]))
    return bordered_matrix(M, column, row, corner)


def _bordered_whole(W, a: np.ndarray, border):
    """The bordered system over the set ``a`` factorized whole: its solver, or None where
    singular."""
    factors = _factorized(_set_matrix(W, a, border))
    return None if factors is None else (lambda b: _solve(factors, b))


class _Base:
    """A factorized set of W (:meth:`ReusedFactor.solve_set`)."""

    def __init__(self, W, mask: np.ndarray, index: np.ndarray, factors):
        self.W, self.mask, self.index, self.factors = W, mask, index, factors
        self.size = (len(index) ** 2 if isinstance(factors, tuple)
                     else int(factors.L.nnz + factors.U.nnz))

    def distance(self, mask: np.ndarray) -> int:
        """The nodes in one of the two sets only."""
        return int(np.count_nonzero(self.mask != mask))

    def solve(self, b: np.ndarray) -> np.ndarray:
        return _solve(self.factors, b)


class _Updated:
    """A set solved through a base's factors (the elimination of
    :meth:`ReusedFactor.solve_set`): the base's back-substitutions of the added columns
    ``X = W_BB^-1 [W_BS E_D c_B]`` and the k x k system's factors, made once per set."""

    @classmethod
    def make(cls, base: _Base, W, mask: np.ndarray, a: np.ndarray, border):
        """The solver, or None where the k x k system is singular."""
        self = cls()
        B = base.index
        nb = len(B)
        S = np.flatnonzero(mask & ~base.mask)
        drop = np.flatnonzero(~mask[B])  # D, as positions in B
        ns, nd, bordered = len(S), len(drop), border is not None
        k = ns + nd + bordered
        # each of the set's nodes in B (its position there) or in S
        at = np.minimum(np.searchsorted(B, a), nb - 1)
        self.in_B = np.where(B[at] == a, at, -1)
        self.from_B = np.flatnonzero(self.in_B >= 0)
        self.from_S = np.flatnonzero(self.in_B < 0)
        G = np.zeros((nb, k))  # the base's columns of the added unknowns
        H = np.zeros((k, nb))  # their rows over the base
        C = np.zeros((k, k))   # and among themselves
        if ns:
            G[:, :ns] = block(W, B, S)
            H[:ns] = block(W, S, B)
            C[:ns, :ns] = block(W, S, S)
        G[drop, ns + np.arange(nd)] = 1.0
        H[ns + np.arange(nd), drop] = 1.0
        if bordered:
            column, row = np.asarray(border[0], float), np.asarray(border[1], float)
            G[self.in_B[self.from_B], -1] = column[self.from_B]
            H[-1, self.in_B[self.from_B]] = row[self.from_B]
            C[:ns, -1] = column[self.from_S]
            C[-1, :ns] = row[self.from_S]
            C[-1, -1] = float(border[2])
        self.base, self.k, self.ns, self.bordered, self.nb = base, k, ns, bordered, nb
        self.X = base.solve(G)
        self.H = H
        self.Z = _factorized(C - H @ self.X)
        if self.Z is None:
            return None
        # a pivot at round-off of the terms it came from: the set is singular or nearly
        # (a node whose condition repeats one of the base's), which its own factorization
        # decides as before
        scale = float((np.abs(C) + np.abs(H) @ np.abs(self.X)).max(initial=0.0))
        if np.abs(np.diag(self.Z[0])).min(initial=np.inf) <= NEAR_SINGULAR * scale:
            return None
        return self

    def __call__(self, b: np.ndarray) -> np.ndarray:
        m = len(self.in_B)
        rhs_B = np.zeros(self.nb)
        rhs_B[self.in_B[self.from_B]] = b[self.from_B]
        rhs_k = np.zeros(self.k)
        rhs_k[:self.ns] = b[:m][self.from_S]
        if self.bordered:
            rhs_k[-1] = b[m]
        y = self.base.solve(rhs_B)
        z = _solve(self.Z, rhs_k - self.H @ y)
        y = y - self.X @ z
        x = np.empty(m + self.bordered)
        x[self.from_B] = y[self.in_B[self.from_B]]
        x[self.from_S] = z[:self.ns]
        if self.bordered:
            x[m] = z[-1]
        return x


class _Checked:
    """A set's solver from a base, each solution refined once on the set's own matrix and
    accepted where the residual is then within LU's bound; else ``whole()`` (the set
    factorized) from then on."""

    def __init__(self, solver: _Updated, W, a: np.ndarray, border, whole):
        self.solver, self.whole = solver, whole
        self.M = _set_matrix(W, a, border)
        self.norm = float(np.asarray(abs(self.M).sum(axis=1)).max(initial=0.0))
        self.fallback = None

    def __call__(self, b: np.ndarray) -> np.ndarray | None:
        if self.fallback is None:
            x = self.solver(b)
            x += self.solver(b - self.M @ x)
            r = float(np.abs(b - self.M @ x).max(initial=0.0))
            bound = len(b) * np.finfo(float).eps * (
                self.norm * float(np.abs(x).max(initial=0.0)) + float(np.abs(b).max(initial=0.0)))
            if np.isfinite(r) and r <= bound:
                return x
            self.fallback = self.whole() or (lambda b: None)
        return self.fallback(b)
