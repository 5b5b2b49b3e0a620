"""The paired variant: one condition per contact force, so the exact state is the fixed point.

The thesis's plain reading checks every node of both bodies for both compatibility and
equilibrium: twice as many conditions as there are nodal forces. On non-matching meshes they
cannot all hold, and the iteration stops where the two corrections cancel (docs/method.md §5).
Checking compatibility at the nodes of *both* surfaces instead would force two non-matching
polylines to coincide, which makes any curved interface straight (locking). So each contact pair
splits the two conditions between its two surfaces:

* the surface that gives way more per unit length (median nodal flexibility 1/K over median
  facet length: the softer, and of two equally stiff ones the finer) carries **compatibility**:
  each of its nodes against its virtual node on the other surface;
* the other surface carries **equilibrium** in weak form: its nodal forces are the first one's
  traction re-integrated over its own shape functions, segment by segment (exact).

The rule depends on the geometry only, so listing the bodies in the other order changes nothing.
The unknowns are the normal traction values q at the finer side's nodes, zero at the nodes not in
contact (thesis §4.4, the first of its two options): the traction falls to zero across the last
facet, which is the consistent edge of the contact. Both sides' nodal forces follow from the same
traction, ``F_fine = N q`` (eq. 4.4.11, so a free node next to the contact takes its share too)
and ``F_coarse = -T q``, which makes them equal and opposite in weak form, to round-off.

The compatibility correction is eq. (4.2.4) in matrix form. In 1D the force that closes an overlap
P is ``K_A K_B / (K_A + K_B) P = (1/K_A + 1/K_B)^-1 P``; here it is ``W^-1 p`` with W the
flexibility of the pair seen at the finer side's contact nodes (its own condensed flexibility plus
the coarser side's, mapped through the virtual nodes and the traction transfer). Each body still
uses only its own factorization; the corrections are still forces applied at the global level.
For a fixed set of contact nodes one correction closes every gap exactly, so what is left to find
is which nodes touch: each correction finds that set by complementarity on W over every pair node
(:mod:`vfem.contact.solvers.complementarity`, small dense solves) before the bodies see it, and a
linear step ends after one correction (docs/method.md §5).

Small-strain analyses pair the surfaces in the undeformed configuration (linear kinematics: the
virtual nodes, normals and transfer are fixed, the gap is linear in the displacements).
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp

from ...errors import PlatenUnheld, PlatenUnpaired
from ..capabilities import Capabilities
from ..geometry import (
    ContactPairs,
    ContactSurface,
)
from ..laws import relaxation, release_tension
from ..solvers import (
    Check,
    ReusedFactor,
    bordered_matrix,
    bordered_solve,
    force_rows,
    iterate,
    linear_complementarity,
    pair_matrix,
    platen_rows,
)
from ..state import (
    ContactState,
    IterationRecord,
    SolveResult,
    closing_motion,
)
from .pairset import PairSet

log = logging.getLogger(__name__)


#: changes of the stale held nodes (:meth:`PairedContact._update_stale`) in one solve after
#: which they only accumulate
STALE_CHANGES = 5


class PairedContact(PairSet):
    """Frictionless contact with one condition per nodal force, small displacements (see the
    module docstring)."""

    capabilities = Capabilities(
        name="paired", orders=(1, 2), kinematics=("small",), dimensions=(2, 3),
        orders_3d=(1, 2), sides=True)
    def __init__(self, surfaces: list[ContactSurface], pairs: ContactPairs, settings,
                 backend: str | None = None, sides: dict | None = None, executor=None,
                 friction: type | None = None):
        #: whether the equilibrium side's nodes are held too (issue 37): not yet with friction
        self.both_surfaces = friction is None
        super().__init__(surfaces, pairs, settings, backend, sides, executor=executor,
                         friction=friction)
        #: W, the penetration change per unit platen motion, the platen reaction per unit
        #: traction value and the pairs' offsets (:meth:`_full_flexibility`): the pairs'
        #: geometry is fixed under small kinematics, so they are computed once, when first
        #: needed
        self._full = None
        self._factor = ReusedFactor()  # the pair matrix's factors while the active set holds

    def relative_displacements(self, state: ContactState) -> list[np.ndarray]:
        """Per pair, (nodes, dim) each fine node's displacement less its virtual node's
        (linear kinematics): along the normal it makes the penetration, along the tangent the
        friction's slip (:mod:`vfem.contact.formulations.friction`)."""
        x = self.positions(state)
        out = []
        for pair in self.contact_pairs:
            sf, sc = self.surfaces[pair.fine], self.surfaces[pair.coarse]
            uf = pair.fine_read(x[pair.fine][: sf.nc] - sf.X[: sf.nc])
            uc = pair.interp @ (x[pair.coarse][: sc.nc] - sc.X[: sc.nc])
            out.append(uf - uc)
        return out

    def penetrations(self, state: ContactState, relative: list[np.ndarray] | None = None
                     ) -> list[np.ndarray]:
        """Penetration (> 0 overlap) of every pair's fine nodes, linear kinematics (from
        ``relative``, :meth:`relative_displacements`, when given)."""
        relative = self.relative_displacements(state) if relative is None else relative
        return [-(pair.gap0 + np.einsum("ij,ij->i", d, pair.reading(0, pair.normal)))
                for pair, d in zip(self.contact_pairs, relative, strict=True)]

    def _release_and_hold(self, state: ContactState, k: int, p: np.ndarray, platen_ok: bool
                          ) -> tuple[np.ndarray, np.ndarray]:
        """Pair k's tension release (thesis §5.6: a node in tension gives up its traction over
        ``release_iterations``), then the nodes the next correction holds: those carrying
        traction or penetrating; with a platen short of its force and none of them, those
        touching within the tolerance. Returns (in tension, held)."""
        tol = self.penetration_tolerance
        q = self.tractions(state, k)
        pair = self.contact_pairs[k]
        tension = q < 0
        change, state.released[pair.fine][pair.nodes] = release_tension(
            q, tension, state.released[pair.fine][pair.nodes], self.settings.release_iterations)
        q += change
        held = ~tension & ((q > 0) | (p > tol))
        if not platen_ok and not held.any():
            held = ~tension & (p > -tol)  # touching within tolerance: hold them there
        return tension, held

    # -- the iteration ----------------------------------------------------------------------------

    def solve(self, state: ContactState, on_iteration=None) -> SolveResult:
        """Correct the traction values until every pair's compatibility holds
        (:func:`~vfem.contact.solvers.iteration.iterate`); the forces follow from them, equal and
        opposite by construction (see the module docstring). With friction, the friction
        part's solve (:meth:`~vfem.contact.formulations.friction.SmallFriction.solve`)."""
        if self.friction is not None:
            return self.friction.solve(state, on_iteration)
        cfg = self.settings
        tol = self.penetration_tolerance
        self._refused = None
        self._stale_mask, self._stale_changes = None, 0
        self.assemble_forces(state)

        def check(it: int) -> Check:
            pens = self.penetrations(state)
            traction_values = self.traction_values(state)
            self._check_rind(pens)
            stale_moved = self._update_stale(state, traction_values, pens)
            errs, pen_err, contact, tension = self.compatibility_errors(pens, traction_values)
            platen_ok = self.group.platen_met(state)
            rec = IterationRecord(it, pen_err, 0.0, contact, tension,
                                  platen_error=self.group.platen_error(state))
            return Check(rec, pen_err <= tol and tension == 0 and platen_ok and not stale_moved,
                         lambda: self.contact_sets(traction_values), pen_err,
                         lambda: self.pairings(state, pens),
                         lambda: (f"no convergence in {cfg.max_iterations} iterations "
                                  f"(penetration {pen_err:.3g}{self.worst_node(errs)}, "
                                  f"{tension} nodes in tension)"),
                         extra=(pens, platen_ok))

        def correct(it: int, c: Check) -> None:
            pens, platen_ok = c.extra
            self._correct(state, pens, it, platen_ok)
            self.assemble_forces(state)

        return iterate(cfg, check, correct, on_iteration)

    def complementarity(self, it: int) -> bool:
        """Whether iteration ``it`` finds the contact set on the condensed system
        (:meth:`_correct_complementarity`): unless the settings relax the corrections or
        release tension over several iterations (the thesis's §5.6 devices, which then act one
        correction of the bodies at a time)."""
        return relaxation(self.settings, it) == 1.0 and self.settings.release_iterations == 1

    def _correct(self, state: ContactState, pens: list[np.ndarray], it: int,
                 platen_ok: bool) -> None:
        """The compatibility correction of every pair at once: the contact set by
        complementarity on the pair matrix, or (relaxed settings) tension release, then the
        correction of the nodes carrying traction or penetrating."""
        if self.complementarity(it):
            self._correct_complementarity(state, pens)
            return
        omega = relaxation(self.settings, it)
        active, targets = [], []
        for k, p in enumerate(pens):
            _, S = self._release_and_hold(state, k, p, platen_ok)
            active.append(np.flatnonzero(S))
            targets.append(omega * p[S])
        self.assemble_forces(state)  # the releases change the forces the platen sees
        m = sum(len(a) for a in active)
        if m == 0:
            if not self.group.platen_met(state):
                self._close_gap(state, pens)
            return
        dq, dplaten = self._solve_pairs(state, active, np.concatenate(targets))
        pos = 0
        for k, a in enumerate(active):
            self.tractions(state, k)[a] += dq[pos:pos + len(a)]
            pos += len(a)
        state.platen_displacement += dplaten

    def _correct_complementarity(self, state: ContactState, pens: list[np.ndarray]) -> None:
        """The traction values of every pair's nodes that close every gap at once: the linear
        complementarity problem on the pair matrix W over all pair nodes
        (:func:`~vfem.contact.solvers.complementarity.linear_complementarity`; issue 20, item 6).

        Under small kinematics W is exact (the pairs' geometry is fixed and each body linear),
        so the penetrations after this one correction are those the dense solves predicted: a
        linear step needs one correction, where releasing and adding nodes one correction of
        the bodies at a time took several (Hertz 7, 4, 4, 4, 4). Where nothing touches and a
        platen must find its force, the platen first moves to close the smallest gap.
        """
        if self._full is None:
            self._full = self._full_flexibility()
        W, rate, dR, _ = self._full
        q0 = np.concatenate(self.traction_values(state) or [np.zeros(0)])
        p = np.concatenate(pens or [np.zeros(0)])
        reserve, guard = self._reserve()
        # held nodes whose conditions and the compatibility side's cross (two of nearly one,
        # or conforming curved surfaces whose facets do not match) are refused: the rest of
        # the answer stands, and invariant (b) judges what they leave
        self._refused = (self._stale_mask.copy() if self._stale_mask is not None
                         else np.zeros(len(reserve), dtype=bool))
        q, dplaten = self._complementarity_with(state, pens, W, rate, dR, q0, p, reserve,
                                                (guard, self._refused))
        # the held nodes stale after this correction, predicted on the pairs (linear): where
        # they differ from those it left out where it matters, the set again with them, so
        # that the bodies need not be corrected once more to find out
        while q is not None and self._stale_changes < STALE_CHANGES:
            predicted = self._predicted_stale(state, q, dplaten, reserve)
            if predicted is None:
                break
            stale, pen = predicted
            if not self._stale_moved(stale, self._stale_mask, q, pen):
                break
            self._stale_changes += 1
            self._stale_mask = stale
            self._refused = stale.copy()
            q, dplaten = self._complementarity_with(state, pens, W, rate, dR, q0, p, reserve,
                                                    (guard, self._refused))
        if self._refused.any():
            log.info("%d held nodes found no contact set with the others: left out",
                     int(self._refused.sum()))
        if q is None:
            return
        self._set_tractions(state, q)
        state.platen_displacement += dplaten

    def _complementarity_with(self, state, pens, W, rate, dR, q0, p, reserve, guards):
        """:meth:`_correct_complementarity`'s solve: (q, platen motion), or (None, 0) where
        the platen first closed a gap. ``guards``: the guard of :meth:`_reserve` and the
        held nodes refused (read and written)."""
        guard, refused = guards
        tol = self.penetration_tolerance
        platen = self.platen_body is not None and state.platen_force != 0.0
        if platen:
            body = self.surfaces[self.platen_body].body
            touch = (q0 > 0) | (p > -tol)
            need = state.platen_force - self.group.platen_reaction(state)
            # a held node touching counts where the platen's force presses it in (a body
            # landing on its corner), not where it pulls the body away
            presses = np.sign(need) * rate > 1e-9 * float(np.abs(rate).max(initial=0.0))
            if not (touch & (~reserve | presses)).any():
                if not self.group.platen_met(state):
                    self._close_gap(state, pens)
                return None, 0.0
            return linear_complementarity(
                W, q0, p, tol, rate, dR, body.platen_stiffness,
                state.platen_force - self.group.platen_reaction(state), factor=self._factor,
                reserve=reserve, guard=guard, refused=refused)
        return linear_complementarity(W, q0, p, tol, factor=self._factor, reserve=reserve,
                                      guard=guard, refused=refused)

    def _set_tractions(self, state: ContactState, q: np.ndarray) -> None:
        """Every pair's traction values from ``q``, the complementarity problem's unknowns
        over all pairs' nodes in order."""
        pos = 0
        for k, pair in enumerate(self.contact_pairs):
            self.tractions(state, k)[:] = q[pos:pos + len(pair.nodes)]
            pos += len(pair.nodes)

    def _predicted_stale(self, state: ContactState, q: np.ndarray, dplaten: float,
                         reserve: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The held nodes :meth:`_stale` finds, and every unknown's penetration, in the state
        that the traction values ``q`` and the platen moved by ``dplaten`` make (the bodies'
        linear response to those forces, not yet applied to ``state``); None where no node
        can be stale."""
        if not reserve.any() or self._stale_mask is None:
            return None
        after = state.copy()
        self._set_tractions(after, q)
        after.platen_displacement += dplaten
        self.assemble_forces(after)
        return (self._stale(after, reserve),
                np.concatenate(self.penetrations(after) or [np.zeros(0)]))

    def _update_stale(self, state: ContactState, traction_values: list[np.ndarray],
                      pens: list[np.ndarray]) -> bool:
        """Read which held nodes are stale (:meth:`_stale`) in this state; whether the last
        correction held a node that is stale now, or left out as stale one that is not and
        penetrates, so that the contact set must be found again (the answer is then the stale
        nodes' own fixed point, however the step was reached).
        After :data:`STALE_CHANGES` such changes in one solve the set only grows (no cycle)."""
        reserve = self._reserve()[0]
        if not reserve.any():
            return False
        stale = self._stale(state, reserve)
        before = self._stale_mask if self._stale_mask is not None else np.zeros_like(stale)
        if self._stale_changes >= STALE_CHANGES:
            stale |= before
        moved = self._stale_moved(stale, before,
                                  np.concatenate(traction_values or [np.zeros(0)]),
                                  np.concatenate(pens or [np.zeros(0)]))
        self._stale_changes += int(moved)
        self._stale_mask = stale
        # (a stale node is excused where it is not held: :meth:`_excused`)
        self._refused = stale if self._refused is None else (self._refused | stale)
        return moved

    def _stale_moved(self, stale: np.ndarray, before: np.ndarray, q: np.ndarray,
                     p: np.ndarray) -> bool:
        """Whether the stale held nodes ``stale`` of a state (traction values ``q``,
        penetrations ``p``) differ from those a correction left out, ``before``, where it
        matters: a node held that is stale, or one left out as stale that is not and
        penetrates."""
        return bool(((stale & ~before & (q > 0))
                     | (~stale & before & (p > self.penetration_tolerance))).any())

    def _stale(self, state: ContactState, reserve: np.ndarray) -> np.ndarray:
        """(unknowns,) bool: the held nodes over the other surface that have slid along it,
        relative to it, by more than the facet their virtual node lies on (``reach``): small
        kinematics pairs once, undeformed, so such a node's condition holds it off a facet
        that is no longer under it (the quadratic gasket, whose faces slide 0.5 past each
        other, 20 facets: held there, its stiff nodes bridged gaps of 0.046 in the deformed
        configuration). They are left out; the compatibility side's nodes, and invariant (b),
        judge what is left."""
        out = np.zeros(len(reserve), dtype=bool)
        if not reserve.any():
            return out
        relative = self.relative_displacements(state)
        for k, (pair, pos) in enumerate(zip(self.contact_pairs, self._unknown_offsets())):
            if pair.point and pair.reach is not None and pair.gap_normal is not None:
                d = relative[k]
                n = pair.gap_normal
                slide = d - np.einsum("ij,ij->i", d, n)[:, None] * n
                over = pair.guard[:, 0] >= 0  # (beyond the other patch: read to its end)
                out[pos:pos + len(pair.nodes)] = over & (
                    np.linalg.norm(slide, axis=1) > pair.reach)
        return out

    def _reserve(self) -> tuple[np.ndarray, np.ndarray | None]:
        """(unknowns,) bool: the held nodes (``point`` pairs), which join the contact set
        only where they would penetrate; and (unknowns, k) the unknowns of each one's guard
        (the compatibility side's nodes around its virtual node, -1 for none), or None
        without held nodes. Fixed by the pairs: found once."""
        if self._reserved is None:
            self._reserved = self._find_reserve()
        return self._reserved

    def _find_reserve(self) -> tuple[np.ndarray, np.ndarray | None]:
        pairs = self.contact_pairs
        reserve = self._held_unknowns()
        if not reserve.any():
            return reserve, None
        offsets = self._unknown_offsets()
        width = max(p.guard.shape[1] for p in pairs if p.point)
        guard = np.full((len(reserve), width), -1)
        for k, pair in enumerate(pairs):
            if not pair.point:
                continue
            # the compatibility pair of the same two bodies, whose nodes guard this one's
            forward = self._guarding_pair(pair)
            if forward is None:
                continue
            where = np.full(self.surfaces[pair.coarse].nc + 1, -1)
            where[pairs[forward].nodes] = offsets[forward] + np.arange(
                len(pairs[forward].nodes))
            g = where[pair.guard]  # -1 (beyond) reads the last entry, -1
            guard[offsets[k]:offsets[k] + len(pair.nodes), : g.shape[1]] = g
        if self._forced is not None:
            guard[self._forced] = -1  # held wherever they would penetrate (:meth:`enforce`)
        return reserve, guard

    def _solve_pairs(self, state: ContactState, active: list[np.ndarray], rhs: np.ndarray
                     ) -> tuple[np.ndarray, float]:
        """The traction value corrections of the active nodes (and the platen's motion under a
        platen force) that remove the penetrations ``rhs``: the pair matrix W (bordered by the
        platen's row and column), its factors reused while the active set holds; or W's
        operator (the matrix-free route, issue 22)."""
        if any(s.matrix_free for s in self.surfaces):
            if self._full is None:
                self._full = self._full_flexibility()
            op, dp_dplaten, dR, offsets = self._full
            index = np.concatenate([offsets[k] + a for k, a in enumerate(active)])
            border = None
            if self.platen_body is not None and state.platen_force != 0.0:
                border = (-dp_dplaten[index], dR[index],
                          self.surfaces[self.platen_body].body.platen_stiffness,
                          state.platen_force - self.group.platen_reaction(state))
            return op.solve(index, rhs, border)
        W, dp_dplaten, dR = self._pair_flexibility(state, active)
        bordered = self.platen_body is not None and state.platen_force != 0.0
        key = (bordered,) + tuple(a.tobytes() for a in active)
        if not bordered:
            x = self._factor.solve(key, lambda: W, rhs)
            if x is None:
                raise np.linalg.LinAlgError("the pair matrix is singular")
            return x, 0.0
        body = self.surfaces[self.platen_body].body
        extra = state.platen_force - self.group.platen_reaction(state)
        x = self._factor.solve(
            key, lambda: bordered_matrix(W, -dp_dplaten, dR, body.platen_stiffness),
            np.concatenate([rhs, [extra]]))
        if x is None:  # singular (no node of the platen's body among them): least squares
            return bordered_solve(W, -dp_dplaten, dR, body.platen_stiffness, rhs, extra)
        return x[:-1], float(x[-1])

    def _pair_flexibility(self, state: ContactState, active: list[np.ndarray]):
        """W = d(penetration reduction)/d(traction value) over the active fine nodes of all pairs.

        Also the penetration change per unit platen motion and the platen reaction per unit
        traction value: rows and columns of :meth:`_full_flexibility` (the pairs' geometry is
        fixed under small kinematics, so it is computed once).
        """
        if self._full is None:
            self._full = self._full_flexibility()
        W, dp_dplaten, dR, offsets = self._full
        index = np.concatenate([offsets[k] + a for k, a in enumerate(active)])
        if sp.issparse(W):  # (a sparse W's active block, dense for its factors)
            return W[index][:, index].toarray(), dp_dplaten[index], dR[index]
        return W[np.ix_(index, index)], dp_dplaten[index], dR[index]

    def _full_flexibility(self):
        """W, the penetration change per unit platen motion and the platen reaction per unit
        traction value over every node of every pair (stacked pair by pair, with the offsets:
        :func:`~vfem.contact.solvers.pair_flexibility.pair_matrix`). The body forces per unit
        traction value are sparse (a node's traction reaches the few nodes of its facets and of
        the opposing facets under it), so each body's motion is its flexibility C times a sparse
        matrix, computed once; where the surfaces' flexibility is applied, not formed (issue
        22), W is the operator that applies it."""
        directions = [self.directions(k) for k in range(len(self.contact_pairs))]
        offsets, dF = force_rows(self.surfaces, self.contact_pairs, directions)
        rates = [pair.platen_rate if j == 0 else self._tangent_platen_rate(k, direction)
                 for k, pair in enumerate(self.contact_pairs)
                 for j, direction in enumerate(directions[k])]
        # (kept sparse where few pairs share a body; the friction part reads it dense)
        W, dp_dplaten = pair_matrix(self.surfaces, self.contact_pairs, directions, offsets, dF,
                                    rates, self.executor, sparse_ok=self.friction is None)
        dR = platen_rows(self.surfaces, self.platen_body, dF, int(offsets[-1]))
        return W, dp_dplaten, dR, offsets

    def _tangent_platen_rate(self, k: int, tangent: np.ndarray) -> np.ndarray:
        """The change of pair k's relative tangential displacement t.(u_f - u_c) per unit
        platen motion (with friction: :mod:`vfem.contact.formulations.friction`)."""
        pair, v = self.contact_pairs[k], self.platen_motion
        return np.einsum("id,id->i", tangent, pair.fine_read(v[pair.fine])
                         - pair.interp @ v[pair.coarse])

    def _close_gap(self, state: ContactState, pens: list[np.ndarray]) -> None:
        """Nothing touches: move the platen just far enough to close the smallest gap."""
        need = state.platen_force - self.group.platen_reaction(state)
        moves = [closing_motion(p, pair.platen_rate, need)
                 for pair, p in zip(self.contact_pairs, pens)]
        moves = [d for d in moves if d != 0.0]
        if moves:
            state.platen_displacement += min(moves, key=abs)
            return
        body = self.surfaces[self.platen_body].body
        if body.platen_stiffness == 0.0 and need != 0.0:  # nothing but contact could hold it
            motion = (f"the platen on body {body.name!r} must move it along "
                      f"{'-' if need < 0 else '+'}{body.platen.component} to apply its force "
                      f"({state.platen_force:.6g}), but ")
            if not any(len(pair.nodes) for pair in self.contact_pairs):
                # no node of either body over the other where they face each other: not the
                # platen's sign, the pairing (random model 3d-17: a tilted box over a block's
                # corner; the block forced onto the compatibility side solves it)
                names = " or ".join(sorted(repr(s.body.name) for s in self.surfaces))
                raise PlatenUnpaired(
                    motion + "no node of either body lies over the other's surface where they "
                    "face each other (they meet edge or corner first), so no contact can hold "
                    f"it (contact.compatibility_side = {names}: the body that the log's "
                    "'contact pair' line does not name as the compatibility side)")
            raise PlatenUnheld(
                motion + "that moves it away from every body it may touch: nothing holds it "
                "(a platen force's sign: negative pushes towards -x or -y)")
