"""Coulomb friction in the paired variant: stick and slip, corrected separately from the normal
contact (thesis §1.10 and §4.3.1; issue 20).

The thesis leaves friction undone but states where it goes: in two or three dimensions "one has
to consider equilibrium in directions normal and tangent to the contact surface" (§4.3.1), and
the algorithm is modular for any friction law that needs "only that certain information about
friction resultants be available at the global level" (§1.10). Here that information is one
more traction field per contact pair:

* **Unknowns.** At each compatibility-side node of a pair, besides the normal traction value q,
  a tangential traction value s per tangent direction (dim - 1 of them: one in 2D). Both sides'
  nodal forces come from the one traction field q n + s t, ``F_fine = N (q n + s t)`` and
  ``F_coarse = -T (q n + s t)`` (eq. 4.4.11 as for q), so the tangential forces balance to
  round-off as the normal ones do.
* **Tangential compatibility** (a node that sticks): its relative tangential displacement
  against its virtual node, ``w = t.(u_fine - u_virtual)``, keeps the value it had at the last
  converged step (``FrictionState.anchor``): no slip within the step.
* **The Coulomb law** (a node that slips): ``|s| = mu q`` with s opposing the slip increment
  ``w - anchor``. A node sticks while ``|s| < mu q``; a node with no normal traction carries
  no tangential one. Per pair of bodies (``[[contact.pairs]]``,
  :class:`~vfem.contact.settings.PairFriction`) the law may instead have a static coefficient
  (a node at rest sticks until ``|s|`` reaches ``mu_s q``, then slips at ``mu q``) or be the
  thesis's elasto-plastic friction-slippage law (§1.10: below the cone an elastic slip
  ``s / k_t``, which the sticking rows take up).
* **The correction.** For given sets (in contact; of those, sticking or slipping, and each
  slipping node's direction σ), the conditions are linear in the traction values: the normal
  rows ask each contact node's penetration to close (as without friction), the tangential rows
  each sticking node's slip to vanish, and each slipping node's s is tied to its q by
  ``s = -mu σ q``. One dense solve (the pair flexibility over normal and tangential unknowns,
  each body's own factorization behind it, :meth:`PairedContact._full_flexibility`) meets them
  all; the iteration, as for the normal contact alone, only finds the sets: a sticking node
  whose tangential traction leaves the cone slips (in the direction that traction opposes),
  a slipping node whose slip turns back sticks, a node in tension leaves contact (and its
  tangential traction with it). This is a return map onto the Coulomb cone per node, with no
  penalty and no parameter to tune. The sets are found on the condensed system: after each
  solve the penetrations and slips it makes are predicted from the pair matrix (exact under
  small kinematics), so the bodies see only the settled tractions and a step takes one
  correction of the bodies (:meth:`SmallFriction._settle`).
* **History.** When a step converges, every node's anchor becomes its relative tangential
  displacement and the slip is accumulated (``FrictionState.slip``): friction is path
  dependent, and a step that is cut starts again from the last converged state, anchors
  included (they are part of the state the checkpoints save).

* **3D** (issue 21, C13): two tangents per node (:func:`~vfem.contact.geometry.tangents`),
  the tangential arrays (n, 2) where 2D has (n, 1) (one column per tangent); |s| is the row
  norm and the cone a disk; a slipping node's direction σ = -s / |s| is a unit vector (±1 in
  2D), and it turns: besides the tie along σ its traction has a part
  across σ, solved for with the row that asks its slip across σ to vanish, linearised (a semismooth
  Newton step on the disk, in :meth:`SmallFriction._correct_frictional`); the friction's
  errors add the slip across σ. A roller plane through the contact holds one tangent of its nodes
  only.

Small kinematics here (large: :mod:`vfem.contact.formulations.large_friction`, 2D): the pairs,
normals and tangents are those of the undeformed configuration, as for the frictionless paired
variant.
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from ..geometry import symmetry_planes, tangents
from ..laws import (
    CONE_TOLERANCE,
    magnitudes,
    reaches_cone,
    relaxation,
)
from ..solvers import Check, bordered_matrix, iterate
from ..state import ContactState, FrictionState, IterationRecord, SolveResult
from .composed import Composed
from .friction_history import FrictionHistory
from .paired import PairedContact

log = logging.getLogger(__name__)


#: a tangential unknown whose own flexibility (the pair matrix's diagonal) is below this fraction
#: of the largest is held by the supports (a node on a symmetry plane through the contact; on
#: the Hertz half model its diagonal is round-off, 1.5e-9 of the largest, where the free ones
#: are above 0.07 of it)
HELD = 1e-6


def plane_normals(surface, pair, normal: np.ndarray | None = None,
                  nodes: np.ndarray | None = None) -> np.ndarray:
    """Pair ``pair``'s nodal normals for its tangents: in 3D, at a node on a symmetry plane of
    the compatibility side's body (:func:`symmetry_planes`), the normal less its component
    across the plane (the facets on one side of the plane tilt the averaged normal out of it;
    the plane's axis is then a tangent, :data:`HELD`, and the other tangent lies in the plane:
    without this it would measure mostly the normal's own motion, the normal and that
    tangent's rows proportional). Elsewhere, and in 2D, the pair's normals themselves.
    ``normal`` at ``nodes`` (positions in the pair's nodes): other normals than the pair's, at
    some of its nodes (the large-kinematics variant's current and perturbed normals)."""
    normal = pair.normal if normal is None else normal
    if normal.shape[1] != 3:
        return normal
    points = surface.nodes[pair.nodes if nodes is None else pair.nodes[nodes]]
    out = normal
    for on_plane, axis in symmetry_planes(surface.body):
        at = np.isin(points, on_plane) & (normal[:, axis] != 0.0)
        if at.any():
            out = out.copy() if out is normal else out
            out[at, axis] = 0.0
            out[at] /= np.linalg.norm(out[at], axis=1)[:, None]
    return out


class SmallFriction(FrictionHistory):
    """The friction part of the paired variant under small displacements (module docstring):
    :class:`~vfem.contact.formulations.paired.PairedContact` holds it as ``friction`` and
    hands it the solve."""

    def __init__(self, form, settings) -> None:
        super().__init__(form, settings)
        self._tangents = [tangents(plane_normals(self.form.surfaces[pair.fine], pair))
                          for pair in self.form.contact_pairs]
        #: tangents per node: 1 in 2D, 2 in 3D
        self._ntan = max((len(t) for t in self._tangents), default=1)
        #: per pair, the nodes released from tension in the current solve
        #: (:meth:`_correct_frictional`)
        self._torn = [np.zeros(len(p.nodes), dtype=bool) for p in self.form.contact_pairs]

    def tangent_basis(self, k: int) -> list[np.ndarray]:
        """Pair k's unit tangents at its nodes (the undeformed ones: small kinematics)."""
        return self._tangents[k]

    def _tangential(self, vector: np.ndarray, k: int) -> np.ndarray:
        """Pair k's tangential rows of a vector over the pair matrix's unknowns, in the shape
        of :meth:`shear`: (n, ntan)."""
        n, ntan = len(self.form.contact_pairs[k].nodes), len(self._tangents[k])
        base = self.form._full[3][k]
        return vector[base + n: base + (1 + ntan) * n].reshape(ntan, n).T

    # -- state -----------------------------------------------------------------------------------

    def start(self, state: FrictionState) -> None:
        """The state before the first step (no contact force): the penetrations of the
        unloaded bodies as the last converged ones (where a node that comes into contact in the
        first step touched)."""
        for k, p in enumerate(self.form.penetrations(state)):
            state.penetration[k] = p.copy()

    def free_slips(self, state: FrictionState, relative: list[np.ndarray] | None = None
                   ) -> list[np.ndarray]:
        """Per pair, each node's slip within the step that its law does not take up
        elastically: the relative tangential displacement from its anchor, plus its
        tangential traction over the slip stiffness (the elastoplastic law; nothing for the
        others). A sticking node holds it at zero; a slipping one moves it against its
        traction."""
        return [w - self.anchor(state, k) + self.laws[k].compliance * self.shear(state, k)
                for k, w in enumerate(self.tangential_displacements(state, relative))]

    def tangential_displacements(self, state: ContactState,
                                 relative: list[np.ndarray] | None = None) -> list[np.ndarray]:
        """Per pair, each node's relative tangential displacement against its virtual node,
        ``w = t.(u_fine - u_virtual)`` (linear kinematics, as the penetrations; from
        ``relative``, the formulation's
        :meth:`~vfem.contact.formulations.paired.PairedContact.relative_displacements`, when
        given)."""
        relative = self.form.relative_displacements(state) if relative is None else relative
        return [np.column_stack([np.einsum("ij,ij->i", d, tj) for tj in t])
                for d, t in zip(relative, self._tangents, strict=True)]

    def assemble_forces(self, state: ContactState) -> None:
        """Every body's nodal forces from the pairs' normal and tangential tractions."""
        for F in state.forces:
            F[:] = 0.0
        for k, pair in enumerate(self.form.contact_pairs):
            traction = (self.form.tractions(state, k)[:, None] * pair.normal
                        + self.tangential_traction(state, k))
            state.forces[pair.fine] += pair.mass[:, pair.nodes] @ traction
            state.forces[pair.coarse] -= pair.transfer[:, pair.nodes] @ traction

    # -- the iteration ---------------------------------------------------------------------------

    def solve(self, state: ContactState, on_iteration=None) -> SolveResult:
        """Correct the normal and tangential traction values until every pair's normal and
        tangential compatibility and the Coulomb law hold; then move the anchors (the module
        docstring)."""
        cfg = self.form.settings
        tol = self.form.penetration_tolerance
        self.assemble_forces(state)
        # the nodes released from tension in this solve (see _correct_frictional)
        self._torn = [np.zeros(len(p.nodes), dtype=bool) for p in self.form.contact_pairs]

        def check(it: int) -> Check:
            relative = self.form.relative_displacements(state)  # one back-substitution for both
            pens = self.form.penetrations(state, relative)
            dw = self.free_slips(state, relative)
            traction_values = self.form.traction_values(state)
            self.form._check_rind(pens)
            errs, pen_err, contact, tension = self.form.compatibility_errors(pens, traction_values)
            fric_err, excess, stick, slip = self.friction_errors(state, dw)
            platen_ok = self.form.group.platen_met(state)
            rec = IterationRecord(it, max(pen_err, fric_err), 0.0, contact, tension,
                                  platen_error=self.form.group.platen_error(state))
            log.debug("friction: iteration %d, penetration %.3g, tangential %.3g, cone excess "
                      "%.3g, %d sticking, %d slipping", it, pen_err, fric_err, excess, stick,
                      slip)
            converged = (pen_err <= tol and fric_err <= tol and excess <= CONE_TOLERANCE
                         and tension == 0 and platen_ok)
            return Check(rec, converged,
                         lambda: self._sets(state), max(pen_err, fric_err),
                         lambda: self.form.pairings(state, pens),
                         lambda: (f"no convergence in {cfg.max_iterations} iterations "
                                  f"(penetration {pen_err:.3g}{self.form.worst_node(errs)}, "
                                  f"tangential slip error {fric_err:.3g}, {tension} nodes in "
                                  f"tension)"),
                         finish=lambda: self._converged(state),
                         extra=(pens, dw, platen_ok))

        def correct(it: int, c: Check) -> None:
            pens, dw, platen_ok = c.extra
            if self.form.complementarity(it):
                self._settle(state, pens, dw, it, platen_ok)
            else:
                self._correct_frictional(state, pens, dw, it, platen_ok)
            self.assemble_forces(state)

        return iterate(cfg, check, correct, on_iteration)

    def _settle(self, state: FrictionState, pens: list[np.ndarray], dw: list[np.ndarray],
                it: int, platen_ok: bool) -> None:
        """The contact, stick and slip sets found on the condensed system (issue 20, item 6):
        the corrections of :meth:`_correct_frictional`, each followed by the penetrations and
        slips it makes predicted from the pair matrix instead of measured on the bodies.

        Under small kinematics the prediction is exact (the pair matrix over the normal and
        tangential unknowns is each body's flexibility seen through the fixed pairs), so the
        corrections are those the iteration would make one back-substitution at a time, and
        the sets they settle on are its own; the bodies then see the settled tractions once,
        and the check measures them. The sets are sought for at most ``max_iterations``
        corrections, and no longer once one comes back: the check then measures the last and
        the iteration goes on from there, a correction of the bodies at a time.
        """
        tol = self.form.penetration_tolerance
        # each node's relative tangential displacement, from its free slip (free_slips)
        relative = [d + self.anchor(state, k) - self.laws[k].compliance * self.shear(state, k)
                    for k, d in enumerate(dw)]
        seen = set()
        for inner in range(self.form.settings.max_iterations):
            before = self._unknowns(state)
            dplaten = self._correct_frictional(state, pens, dw, it + inner, platen_ok)
            if dplaten is None:  # nothing touches: the platen moved; measure it
                return
            self.assemble_forces(state)
            G, rate, _, offsets = self.form._full
            # (the change of every unknown: the correction's, and the tension released before)
            motion = G @ (self._unknowns(state) - before)  # penetration decrease (normal
            # rows), slip (tangential rows)
            n = [len(p) for p in pens]
            normal = [slice(offsets[k], offsets[k] + n[k]) for k in range(len(n))]
            pens = [p - motion[r] + rate[r] * dplaten for p, r in zip(pens, normal)]
            relative = [w + self._tangential(motion, k) + self._tangential(rate, k) * dplaten
                        for k, w in enumerate(relative)]
            dw = [w - self.anchor(state, k) + self.laws[k].compliance * self.shear(state, k)
                  for k, w in enumerate(relative)]
            traction_values = self.form.traction_values(state)
            _, pen_err, _, tension = self.form.compatibility_errors(pens, traction_values)
            fric_err, excess, _, _ = self.friction_errors(state, dw)
            platen_ok = self.form.group.platen_met(state)
            if (pen_err <= tol and fric_err <= tol and excess <= CONE_TOLERANCE
                    and tension == 0 and platen_ok):
                log.debug("friction: the sets settled in %d corrections on the pair matrix",
                          inner + 1)
                return
            key = b"".join(m.tobytes() for _, _, m in self._sets(state))
            # (3D: the same sets while the slip directions still turn are no cycle)
            if key in seen and (self._ntan == 1 or self._turning(state, dw) <= tol):
                return
            seen.add(key)

    def _turning(self, state: FrictionState, dw: list[np.ndarray]) -> float:
        """3D: the largest slip across its slip direction sigma = -s / |s| at a slipping node
        (what the direction updates of :meth:`_correct_frictional` remove)."""
        out = 0.0
        for k, w in enumerate(dw):
            s, on = self.shear(state, k), self.status(state, k) == 2
            on &= magnitudes(s) > 0  # (no direction without a traction: friction_errors)
            if on.any():
                sigma = -s[on] / magnitudes(s[on])[:, None]
                along = np.einsum("ij,ij->i", sigma, w[on])
                out = max(out, float(magnitudes(w[on] - along[:, None] * sigma).max()))
        return out

    def _converged(self, state: FrictionState) -> None:
        """A converged step: accumulate each node's slip and anchor it where it now is (the
        step's slip increments are kept for :meth:`add_fields`)."""
        self._increments = []
        relative = self.form.relative_displacements(state)
        for k, p in enumerate(self.form.penetrations(state, relative)):
            state.penetration[k] = p
        for k, w in enumerate(self.tangential_displacements(state, relative)):
            anchor = self.anchor(state, k)
            on = self.form.tractions(state, k) > 0
            # where the node is, less its elastic slip (the elastoplastic law's s / k_t)
            new = w + self.laws[k].compliance * self.shear(state, k)
            increment = np.where(on[:, None], new - anchor, 0.0)
            self.accumulated_slip(state, k)[:] += magnitudes(increment)
            self._increments.append(increment)
            anchor[:] = new

    def _correct_frictional(self, state: FrictionState, pens: list[np.ndarray],
                            dw: list[np.ndarray], it: int, platen_ok: bool = True
                            ) -> float | None:
        """Release tension, sort the contact nodes into sticking and slipping, then one solve of
        the normal and tangential conditions of every pair together (module docstring).
        Returns the platen's motion, or None where nothing touched (the platen then moved to
        close the smallest gap)."""
        tol = self.form.penetration_tolerance
        omega = relaxation(self.form.settings, it)
        if self.form._full is None:
            self.form._full = self.form._full_flexibility()
            diagonal = np.abs(np.diag(self.form._full[0]))
            #: the tangential unknowns whose relative tangential displacement no traction moves
            self._held = diagonal <= HELD * diagonal.max(initial=0.0)
        G, dz_dplaten, dR, offsets = self.form._full
        ntan = self._ntan
        jump = np.zeros(len(G))  # known changes of the unknowns (cone, release)
        # per pair: the unknowns solved for (normal ones, then tangential), the rows (normal
        # and tangential conditions, pair by pair), their targets, and the slipping nodes' ties
        # (per tangent: a node's ties to its q, one per tangent)
        q_cols, s_cols, rows, normal_rows, rhs = [], [], [], [], []
        elastic, compliances = [], []
        tie_q, tie_s, ties = ([[] for _ in range(ntan)] for _ in range(3))
        # 3D, per slipping node: its tangential unknowns, the direction across sigma, the
        # compliance of its traction across sigma and its row's target (below)
        perp_s, perp_dir, perp_c, perp_rhs = [], [], [], []
        for k, pair in enumerate(self.form.contact_pairs):
            n, base = len(pair.nodes), offsets[k]
            law = self.laws[k]
            compliance, acts = law.compliance, law.acts
            p, S = pens[k], self.shear(state, k)  # S: (n, ntan)
            tension, contact = self.form._release_and_hold(state, k, p, platen_ok)
            q = self.form.tractions(state, k)
            was_sliding = self.sliding(state, k)
            self._torn[k] |= tension
            slip = dw[k].copy()
            # A node that comes into contact in the prediction (the first iteration of a step:
            # the new loads with the last contact forces held, linear along the step) touched
            # where its penetration, linear along that path, was zero: it sticks from there
            # (its anchor moves to that point). A node pushed into contact by a correction, or
            # torn off already in this solve, has no such path: it slips the way it moves
            # until its traction says it sticks (held at its anchor, a node on a sliding block
            # was pulled back against its motion and torn off again, over and over). Measured:
            # a block lowered onto another while moving sideways (mu = 1) reads the bonded
            # answer with one step, where slipping every entering node read it 50 % high and
            # failed at mu = 5; anchoring the nodes a correction pushes in too locked a tenth
            # of mu p0 into the edge of a Cattaneo contact while it was pressed.
            entering = contact & (q <= 0)
            fresh = entering & ~self._torn[k] if it == 0 else np.zeros(n, dtype=bool)
            torn = entering & ~fresh
            if fresh.any():
                before = state.penetration.get(k, np.zeros(n))[fresh]
                rise = p[fresh] - before
                tau = np.where((before < 0) & (rise > 0), -before / np.where(rise > 0, rise, 1.0),
                               0.0)
                tau = np.clip(tau, 0.0, 1.0)
                self.anchor(state, k)[fresh] += tau[:, None] * slip[fresh]
                slip[fresh] *= (1.0 - tau)[:, None]
            # a node whose relative tangential motion the supports hold (a symmetry plane through
            # the contact, both bodies held along it) has no tangential unknown: its tangential
            # traction is the supports' (zero on a symmetry plane); nor has a frictionless pair.
            # In 3D a node may be held along one tangent only (a roller plane): it slides along
            # the other.
            held = self._held[base + n: base + (1 + ntan) * n].reshape(ntan, n).T \
                | (not acts)
            node_held = held.all(axis=1)
            # 3D: a node the supports move along a held tangent (both bodies' dofs prescribed
            # there, but not alike: the press fit's shaft end faces pushed past the hub's held
            # ones) slips by that motion, known: its traction there is friction's, -mu q along
            # the slip, a tie like any slipping node's, carried by the supports
            # (2D too: a block's end face pushed along the interface past the other body's
            # held one; issue 42's push-out, in plane strain and in r-z alike)
            driven = contact & (magnitudes(np.where(held, slip, 0.0)) > tol) & acts
            slip[held & ~driven[:, None]] = 0.0  # (round-off: the supports hold it)
            # a node on the cone keeps slipping unless its slip has turned back: the static cone
            # for a node at rest, the dynamic one for a node that slips (the same for Coulomb);
            # sigma, its slip direction, is the one its traction opposes (2D: -sign(s))
            size = magnitudes(S)
            sigma = np.divide(-S, size[:, None], out=np.zeros_like(S), where=size[:, None] > 0)
            reach = reaches_cone(size, q, self.onset(state, k))
            on_cone = (q > 0) & reach & (size != 0)
            amount = magnitudes(slip)
            moving = torn & (amount > tol)
            going = amount > 0
            unit = np.divide(slip, amount[:, None], out=np.zeros_like(slip),
                             where=going[:, None])
            sigma[moving | driven] = unit[moving | driven]
            along = np.einsum("ij,ij->i", sigma, slip)
            slipping = contact & ((on_cone & (along >= -tol)) | moving)
            slipping &= ~node_held
            slipping |= driven
            sticking = contact & ~slipping & ~node_held
            was_sliding[:] = slipping | (contact & (not acts))
            # no tangential traction where held (and none off contact)
            free = (held & ~driven[:, None]) | ~contact[:, None]
            for j in range(ntan):
                jump[base + (1 + j) * n + np.flatnonzero(free[:, j])] = -S[free[:, j], j]
            on = np.flatnonzero(contact)
            stick = [np.flatnonzero(sticking & ~held[:, j]) for j in range(ntan)]
            slide = np.flatnonzero(slipping)
            q_cols.append(base + on)
            s_cols += [base + (1 + j) * n + st for j, st in enumerate(stick)]
            rows += [base + on] + [base + (1 + j) * n + st for j, st in enumerate(stick)]
            normal_rows += [np.ones(len(on), bool)] + [np.zeros(len(st), bool) for st in stick]
            # close the penetrations; undo the slips within the step
            rhs += [omega * p[on]] + [-omega * slip[st, j] for j, st in enumerate(stick)]
            if compliance > 0:  # elastoplastic: the slip s / k_t is elastic
                for j, st in enumerate(stick):
                    elastic.append(base + (1 + j) * n + st)
                    compliances.append(np.full(len(st), compliance))
            mu = self.dynamic(state, k)[slide]
            for j in range(ntan):
                tie = -mu * sigma[slide, j]  # s follows q on the cone
                jump[base + (1 + j) * n + slide] = tie * q[slide] - S[slide, j]
                tie_q[j].append(base + slide)
                tie_s[j].append(base + (1 + j) * n + slide)
                ties[j].append(tie)
            if ntan > 1:
                # 3D: the slip direction sigma turns (the plan's §3.3: a semismooth Newton step
                # on the disk). A slipping node's traction is -mu q sigma plus a part s_perp
                # across sigma, solved for with the row that asks its slip across sigma to
                # vanish, linearised: d(sigma_perp . dw) = sigma_perp . d(dw) + (sigma . dw)
                # / |s| d(s_perp) (sigma turns with s); the next correction reads sigma from
                # the new s. (Not where a roller holds a tangent: sigma lies along the other;
                # nor where s is zero, sigma then the slip's own direction.)
                turn = slide[~held[slide].any(axis=1) & (size[slide] > 0)]
                across = np.column_stack([-sigma[turn, 1], sigma[turn, 0]])
                perp_s.append(base + n * (1 + np.arange(ntan))[None, :] + turn[:, None])
                perp_dir.append(across)
                perp_c.append(np.maximum(np.einsum("ij,ij->i", sigma[turn], slip[turn]), 0.0)
                              / size[turn] + compliance)  # (+ the elastoplastic law's)
                perp_rhs.append(-omega * np.einsum("ij,ij->i", across, slip[turn]))
        self.assemble_forces(state)  # the releases change the forces the platen sees
        q_cols, s_cols = np.concatenate(q_cols), np.concatenate(s_cols)
        if not len(q_cols):
            state.shear.update({k: self._zeros(k) for k in range(len(self.form.contact_pairs))})
            self.assemble_forces(state)
            if not self.form.group.platen_met(state):
                self.form._close_gap(state, pens)
            return None
        cols, rows = np.concatenate([q_cols, s_cols]), np.concatenate(rows)
        tie_q, tie_s, ties = ([np.concatenate(a) for a in b] for b in (tie_q, tie_s, ties))
        position = np.full(len(G), -1)  # unknown -> its column in the system
        position[cols] = np.arange(len(cols))
        Gr = G[rows]
        turning = sum(len(d) for d in perp_dir)
        if turning:  # 3D: the rows of the slip across sigma (a combination of two tangential)
            perp_s, perp_dir = np.concatenate(perp_s), np.concatenate(perp_dir)
            Gr = np.vstack([Gr, np.einsum("ij,ijm->im", perp_dir, G[perp_s])])
        A = Gr[:, cols]
        for tq, ts, t in zip(tie_q, tie_s, ties):  # (one tangent at a time: no index twice)
            A[:, position[tq]] += Gr[:, ts] * t
        if elastic:
            unknowns = np.concatenate(elastic)  # their rows are their own tangential ones
            at = np.full(len(G), -1)
            at[rows] = np.arange(len(rows))
            A[at[unknowns], position[unknowns]] += np.concatenate(compliances)
        b = np.concatenate(rhs) - (Gr[:len(rows)] if turning else Gr) @ jump
        if turning:  # their columns (the traction across sigma) and the compliance
            A = np.hstack([A, np.einsum("ij,mij->mi", perp_dir, Gr[:, perp_s])])
            A[len(rows) + np.arange(turning), len(cols) + np.arange(turning)] += \
                np.concatenate(perp_c)
            b = np.concatenate([b, np.concatenate(perp_rhs) - Gr[len(rows):] @ jump])
        # the platen's motion solved for where it has a force to meet, or (a zero force: a
        # platen holding the body sideways while it is pressed) where its reaction is off it
        if self.form.platen_body is not None and (state.platen_force != 0.0
                                             or not self.form.group.platen_met(state)):
            body = self.form.surfaces[self.form.platen_body].body
            row = dR[cols].copy()
            for tq, ts, t in zip(tie_q, tie_s, ties):
                row[position[tq]] += t * dR[ts]
            extra = state.platen_force - self.form.group.platen_reaction(state) - dR @ jump
            # the rows' change per unit platen motion: penetration reduction (normal rows),
            # relative tangential displacement (tangential rows)
            column = np.where(np.concatenate(normal_rows), -dz_dplaten[rows], dz_dplaten[rows])
            if turning:
                row = np.concatenate([row, np.einsum("ij,ij->i", perp_dir, dR[perp_s])])
                column = np.concatenate([column, np.einsum("ij,ij->i", perp_dir,
                                                           dz_dplaten[perp_s])])
            x = np.linalg.solve(bordered_matrix(A, column, row, body.platen_stiffness),
                                np.concatenate([b, [extra]]))
            x, dplaten = x[:-1], float(x[-1])
        else:
            x, dplaten = np.linalg.solve(A, b), 0.0
        delta = jump.copy()
        if turning:
            delta[perp_s] += perp_dir * x[len(cols):, None]
            x = x[:len(cols)]
        delta[cols] += x
        for tq, ts, t in zip(tie_q, tie_s, ties):
            delta[ts] += t * x[position[tq]]
        for k, pair in enumerate(self.form.contact_pairs):
            n, base = len(pair.nodes), offsets[k]
            self.form.tractions(state, k)[:] += delta[base:base + n]
            self.shear(state, k)[:] += self._tangential(delta, k)
        state.platen_displacement += dplaten
        return dplaten


#: the paired variant with friction, small displacements: the frictionless formulation composed
#: with the friction part (the laws it takes: :class:`~vfem.contact.laws.FrictionLaw`)
FrictionalPairedContact = Composed(
    PairedContact, SmallFriction,
    dataclasses.replace(PairedContact.capabilities, name="paired, frictional",
                        friction=("coefficients", "slip", "compliance"),
                        orders_3d=(1,)))

__all__ = ["FrictionalPairedContact", "SmallFriction"]
