"""The contact set by complementarity on the condensed system (issue 20, item 6).

Given the pair flexibility W over every contact node (the penetration decrease per unit traction
value, each body's own factorization behind it: eq. 4.2.4 in matrix form), the traction values
q >= 0 of the exact contact state solve a linear complementarity problem: at every node
q >= 0, penetration <= 0 and one of the two zero. The thesis's iteration finds that set one
correction at a time, each correction a back-substitution through every body (§4.3-4.5; Hertz
7, 4, 4, 4, 4 corrections per step). Here the set is found on the condensed system alone, by
small dense solves: under small kinematics W is exact, so one correction of the bodies then
meets every condition, and under large kinematics (:mod:`vfem.contact.formulations.large`) it is the
linearised problem of one Newton correction.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp

from .bordered import ReusedFactor, block, bordered_solve

log = logging.getLogger(__name__)


def linear_complementarity(W, q0: np.ndarray, p: np.ndarray, tol: float,
                           dp_dplaten: np.ndarray | None = None, dR: np.ndarray | None = None,
                           stiffness: float = 0.0, need: float = 0.0,
                           max_pivots: int | None = None, factor: ReusedFactor | None = None,
                           reserve: np.ndarray | None = None, guard: np.ndarray | None = None,
                           rounds: int | None = None, refused: np.ndarray | None = None
                           ) -> tuple[np.ndarray, float]:
    """The traction values q >= 0 of the linearised contact problem, and the platen motion.

    From traction values ``q0`` with (linearised) penetrations ``p``, the penetrations after the
    change are ``p - W (q - q0) + dp_dplaten d`` (``d`` the platen motion, solved with the
    platen's equilibrium ``dR . (q - q0) + stiffness d = need`` when ``dp_dplaten`` is given).
    Find q with, at every node, q >= 0, penetration <= tol and one of the two zero: the nodes
    with q > 0 close their gaps exactly.

    Block principal pivoting (every violation swapped at once), which finds the set in a few
    solves; if a set repeats (it may cycle), one violation at a time, the lowest index first
    (Murty's rule, finite when W is a P-matrix; where it is not, a set met again under that
    rule is a cycle, and the search ends there with no set). A set on which the platen's
    equilibrium cannot hold (nothing else holds its body) takes the nodes that touch within the
    tolerance. Without a complementary solution in ``max_pivots`` solves (or at a cycle), the
    last set's solution with its negative values set to zero.

    ``W``: the matrix (:class:`DenseSystem`), or an operator with its ``matvec`` and ``solve``
    (:class:`~vfem.contact.solvers.matrix_free.PairOperator`, issue 22). ``factor``: with a matrix,
    keep the LU factors of the last set's matrix (:class:`ReusedFactor`; a step whose set is
    the last step's solves with the same factors); without it, every set's bordered system is
    solved by least squares.

    ``reserve`` (bool over the nodes): nodes held back until the others' set is found — the
    held nodes (issue 37, :func:`~vfem.contact.geometry.held.held_nodes`), even those that
    carried force before. Only if one of them then penetrates do they take part in the pivoting, so
    where none would (a flat interface, a convex compatibility side) the answer is the
    compatibility side's set alone, unchanged; a held node that only touches within
    round-off, whose condition repeats its neighbours', never makes a set's matrix singular.
    ``rounds``: of held nodes joining (default :data:`STAGES`; 0: the reserve nodes never
    join). ``guard`` ((nodes, k) indices, -1 for none): a reserve node is in the set only
    while not all of its guard's nodes are — the compatibility side's nodes around its
    virtual node: between nodes in contact a node of the other surface protrudes by the
    faceting of the compatibility side (a mesh that resolves the surface between its nodes
    only as they lie), not by a contact missed; where one of them is open, the node of the
    other surface between them is a contact of its own (a convex punch's lowest node first
    touching between a flat block's nodes). ``refused`` (bool over the nodes, read and
    written): the reserve nodes that may not join (given), and those that could not —
    where the nodes of a round find no complementary set together (two conditions of
    nearly one: a held node beside a compatibility node of the other side at almost the
    same point, or conforming curved surfaces whose facets do not match), they join one at
    a time, the deepest first, and each that still finds none is refused, its penetration
    left to invariant (b).
    """
    n = len(q0)
    max_pivots = max_pivots or 10 * n + 10
    platen = dp_dplaten is not None
    system = W if hasattr(W, "matvec") else DenseSystem(W, factor)
    Wq0 = system.matvec(q0)

    def on(active):
        """q (zero off the set) and d that close the set's gaps exactly; the penetrations."""
        a = np.flatnonzero(active)
        q = np.zeros(n)
        d = 0.0
        rhs = p[a] + Wq0[a]
        if platen:
            extra = need + float(dR @ q0)
            q[a], d = system.solve(a, rhs, (-dp_dplaten[a], dR[a], stiffness, extra), q0[a])
        elif len(a):
            q[a], _ = system.solve(a, rhs, None, q0[a])
        pen = p - system.matvec(q - q0) + (d * dp_dplaten if platen else 0.0)
        return q, d, pen

    reserve = np.zeros(n, dtype=bool) if reserve is None else reserve

    def excused(active):
        """The reserve nodes whose guard is wholly in the set."""
        if guard is None:
            return np.zeros(n, dtype=bool)
        on_set = np.concatenate([active, [False]])  # index -1: never in the set
        wholly = on_set[guard].all(axis=1) & (guard != -1).any(axis=1)
        return reserve & wholly

    def off(q, d):
        """Whether the platen's equilibrium does not hold, to the round-off of its terms
        (not of ``need`` alone: in a Newton iteration near its solution the platen's missing
        force is itself round-off, and its equilibrium "failed" by the round-off of the
        contact forces, which let the held nodes that touch join as if the platen were
        short: on the Hertz example at 1 % of its force, total and updated Lagrangian then
        converged 3e-4 apart, four held flat nodes carrying force in one, where they agree
        to 1e-12: ``tests/test_large.py``)."""
        if not platen:
            return False
        terms = float(np.abs(dR) @ (np.abs(q) + np.abs(q0))) + abs(stiffness * d) + abs(need)
        return abs(float(dR @ (q - q0)) + stiffness * d - need) > 1e-9 * terms

    def pivoting(active, eligible, limit):
        """Block principal pivoting over the ``eligible`` nodes from the set ``active``:
        (q, d, penetrations, set, whether it is complementary)."""
        seen, once = set(), set()
        single = False
        for pivot in range(limit):
            q, d, pen = on(active)
            wrong = (active & (q < 0)) | (~active & eligible & (pen > tol))
            if off(q, d):  # the platen needs the nodes touching it to push
                wrong |= ~active & eligible & (pen > -tol)
            if not wrong.any():
                log.debug("complementarity: the contact set in %d solves", pivot + 1)
                return q, d, pen, active, True
            key = active.tobytes()
            if single and key in once:
                # one violation at a time, the next set is a function of this one: a set
                # met again is a cycle that never ends (W is not a P-matrix here: held nodes)
                log.debug("complementarity: one-at-a-time pivoting cycles after %d solves",
                          pivot + 1)
                return q, d, pen, active, False
            if single:
                once.add(key)
            single = single or key in seen
            seen.add(key)
            if single:
                wrong[np.flatnonzero(wrong)[0] + 1:] = False
            active = active ^ wrong
        return q, d, pen, active, False

    def join(active, eligible, new, limit):
        """The set with the nodes ``new`` joined, (q, d, penetrations, set), or None where
        pivoting finds no complementary one. A single node that finds none may take the place
        of a node of the set: with held nodes W need not be a P-matrix (a held node's force
        and gap directions differ), and beside a compatibility node at almost its point the
        two conditions' minor is negative: with both, the held node's value is negative,
        without it, it penetrates, and pivoting cycles between the two sets, where the held
        node alone, the other open, is complementary (random model 2d-137: a coarse half
        disk's lowest vertex 0.0037 from a block node). Tried: the nodes of the set whose
        values the node's joining raised most (:data:`SWAPS` of them)."""
        try:
            q, d, pen, found, ok = pivoting(active | new, eligible, limit)
        except np.linalg.LinAlgError:  # a set whose conditions repeat one another
            ok = False
        if ok:
            return q, d, pen, found
        if new.sum() != 1 or not active.any():
            return None
        try:
            before, after = on(active)[0], on(active | new)[0]
        except np.linalg.LinAlgError:
            return None
        raised = np.flatnonzero(active)
        raised = raised[np.argsort(-(after - before)[raised], kind="stable")][:SWAPS]
        for j in raised:
            if after[j] <= before[j]:
                break
            trial = active | new
            trial[j] = False
            try:
                q, d, pen, found, ok = pivoting(trial, eligible, limit)
            except np.linalg.LinAlgError:
                continue
            if ok and found[new].all():
                return q, d, pen, found
        return None

    # the compatibility sides' set first, the held nodes waiting
    eligible = ~reserve
    # (with held nodes, from the nodes that penetrate with no contact force at all: with them
    # the problem need not have one solution, and starting from the last step's set would
    # make the answer depend on the path — unloading would not mirror loading)
    start = (p + Wq0 > tol) if reserve.any() else ((q0 > 0) | (p > tol))
    q, d, pen, active, ok = pivoting(start & eligible, eligible, max_pivots)
    if not ok:
        log.debug("linearised contact: no complementary set in %d solves", max_pivots)
        return np.maximum(q, 0.0), d
    # then the held nodes that penetrate where the compatibility side's nodes around them do
    # not all touch, until none is left (each stage a complementarity problem of its own)
    refused = np.zeros(n, dtype=bool) if refused is None else refused
    for _ in range(STAGES if rounds is None else rounds):
        # (and, where the platen finds no node of the compatibility side to push, the held
        # nodes that touch: a body that lands on its corner)
        new = reserve & ~eligible & ~excused(active) & (pen > tol)
        if platen and off(q, d):
            # the platen short of its force: the held nodes that touch, where its force
            # presses them in (a body landing on its corner; not one pulled away)
            short = need - float(dR @ (q - q0)) - stiffness * d
            scale = 1e-9 * float(np.abs(dp_dplaten).max(initial=0.0))
            new |= reserve & ~eligible & (pen > -tol) & (np.sign(short) * dp_dplaten > scale)
        new &= ~refused
        if not new.any():
            break
        limit = min(max_pivots, 20 + n)
        found = join(active, eligible | new, new, limit)
        if found is None:  # one at a time, the deepest first
            for i in np.flatnonzero(new)[np.argsort(-pen[new], kind="stable")]:
                one = np.zeros(n, dtype=bool)
                one[i] = True
                found = join(active, eligible | one, one, limit)
                if found is None:
                    refused[i] = True
                else:
                    q, d, pen, active = found
                    eligible = eligible | one
            continue
        q, d, pen, active = found
        eligible = eligible | new
    else:  # the rounds spent: those still waiting to join are refused (invariant (b) judges)
        refused |= reserve & ~eligible & ~excused(active) & (pen > tol)
    return q, d


#: at most this many nodes of the set a held node that finds no set may take the place of
#: (:func:`linear_complementarity`'s ``join``)
SWAPS = 3

#: at most this many rounds of held nodes joining the contact set
#: (:func:`linear_complementarity`)
STAGES = 10


class DenseSystem:
    """W formed (the dense route): its products, and each set's system solved with the
    factors of :class:`ReusedFactor` where given (each new set from those of a set near it:
    :meth:`ReusedFactor.solve_set`; else least squares for a bordered set,
    ``numpy.linalg.solve`` for a plain one). The matrix-free route's counterpart is
    :class:`~vfem.contact.solvers.matrix_free.PairOperator` (issue 22)."""

    def __init__(self, W, factor: ReusedFactor | None = None):
        self.W = W  # dense, or sparse (pairs that share no body: pair_matrix's sparse_ok)
        # (a sparse W's sets always through factors: SuperLU's, kept while the call lasts)
        self.factor = ReusedFactor() if factor is None and sp.issparse(W) else factor

    def matvec(self, x: np.ndarray) -> np.ndarray:
        return self.W @ x

    def solve(self, a: np.ndarray, rhs: np.ndarray, border=None, x0=None
              ) -> tuple[np.ndarray, float]:
        """The values on set ``a`` that close its gaps: ``W[a, a] x = rhs``, or with
        ``border`` = (column, row, corner, extra) the platen's bordered system
        (:func:`~vfem.contact.solvers.bordered.bordered_solve`). ``x0`` (a first guess) is not
        needed."""
        W, factor = self.W, self.factor
        if border is not None:
            column, row, corner, extra = border
            x = None
            if factor is not None:
                x = factor.solve_set(W, a, np.concatenate([rhs, [extra]]),
                                     (column, row, corner))
            if x is None:  # singular (no node of the platen's body in the set): least squares
                return bordered_solve(block(W, a, a), column, row, corner, rhs, extra)
            return x[:-1], float(x[-1])
        x = None if factor is None else factor.solve_set(W, a, rhs)
        # (singular: numpy's LinAlgError, for the pivoting to see)
        return (np.linalg.solve(block(W, a, a), rhs) if x is None else x), 0.0


__all__ = ["DenseSystem", "linear_complementarity"]
