"""Contact between bodies under large displacements: the paired variant, current configuration.

With small displacements (:class:`~vfem.contact.formulations.paired.PairedContact`) the bodies are
paired once, on the undeformed geometry, and each body's response to its contact forces is linear.
Here the bodies may slide far and deform much (thesis Chapters 2-3; the method's claim is "any
amount of sliding of the touching surfaces without requiring rediscretization"), so every iteration

1. **re-pairs** the surfaces on the current geometry: every compatibility-side node finds its
   virtual node on the opposing surface as it now lies, with that surface's current normal
   (continuous along it, :func:`~vfem.contact.geometry.pairing.virtual_nodes`); the transfer of
   the traction to the opposing nodes is re-integrated over the current overlap of the two surfaces.
   Tractions stay nominal (per undeformed length of the compatibility side), so the two sides'
   forces remain equal and opposite in total, and act along the current normals;
2. **linearizes** every large-kinematics body at its current state (Newton's system of
   :class:`~vfem.nonlinear.NonlinearBody`: out-of-balance force, tangent stiffness, material and
   geometric) under the contact forces it carries, factorized once;
3. **corrects** the bodies and the traction values together, by Newton's method on the whole
   problem (vfem-method §3.1: each body keeps its own factorization, the contact is resolved at
   the global level on the contact dofs): each body's correction with its contact forces held,
   plus its tangent flexibility times the change of those forces; the traction values solve the
   linearised contact problem on the contact dofs, complementarity included
   (:func:`~vfem.contact.solvers.complementarity.linear_complementarity`: traction >= 0, penetration
   <= tolerance, one of the two zero), so the set of touching nodes is found on the tangent model,
   by small dense solves.

It stops when the penetrations are within tolerance, no node is in tension and every body is in
equilibrium (residual within ``BODY_TOLERANCE`` of its reference force); each body is then
equilibrated under the converged contact forces by :meth:`~vfem.nonlinear.NonlinearBody.equilibrate`
(one or no correction), which makes that state the one the solver commits.

Why not equilibrate every body under its contact forces in every iteration, and correct the
tractions in between (the small-displacement variant's iteration, a body's response there being
one back-substitution)? Measured on the gasket example with backs moving 0.5 each (a thin soft half
ring crushed by a stiff one):

* under dead contact forces alone a thin curved body can be close to buckling although the
  contact holds it firmly: the soft half's smallest tangent eigenvalue fell from 13.6 at rest to
  1.15 at load factor 0.785, heading for zero near 0.84, while with the normal motion of its
  contact nodes held it was 46 and rising. Its own Newton iteration then diverged from a
  residual of 1e-5 of its reference, and the steps were cut to nothing. Here the bodies are never
  solved under the contact forces alone: the Newton correction sees the contact through the
  linearised complementarity conditions;
* the forces follow the normals, which turn with the surfaces (the coupling below): left out of
  the correction, with each iterate's forces along the last iterate's normals, the iteration
  took 24 iterations at load factor 0.75 and, as the soft half softened, cycled at penetrations
  of 1e-3 for 100;
* at the first touch of two curved bodies, closing the overlap of the touching nodes exactly and
  releasing those then in tension (the small-displacement correction) asks for alternating
  tractions 30 times larger than the contact force (-7.7e4 to 3.4e4 at 7 nodes for a contact
  settling at 2.5e3 at one node); equilibrated under those, the body was crushed.

The contact forces' turning with the surfaces (follower forces) enters the linearisation: the
derivative of the nodal forces with respect to the positions of the nodes in contact and of the
opposing nodes around their virtual nodes, at fixed traction values, found by differences of the
pairing (geometry only: the loaded nodes' normals, :meth:`LargeDeformationContact._normals_at`,
the coordinates that move disjoint sets of them perturbed together); the transfer is held in it
(a held node's point force moves with its virtual node, :mod:`.large_held`).

The step's increments of the prescribed displacements enter with the first correction, so the
first iterate of a step is the tangent prediction of the whole step, contact included: the
overlap that holding the last contact forces while the loads move on would make is never formed.

Which surface of a pair carries compatibility is decided once, on the undeformed geometry (the
softer one), and the rind check guards every corrected iterate as with small displacements. A body
with ``kinematics = "small"`` may take part: it is paired in the current configuration too, with
its constant flexibility, always in equilibrium with its contact forces.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp

from ...bodies.mechanics import prefetch
from ...errors import AnalysisError, InputError
from ..capabilities import Capabilities
from ..geometry import ContactPairs, ContactSurface, overlap, virtual_nodes
from ..solvers import Check, iterate, linear_complementarity
from ..state import ContactState, IterationRecord, SolveResult, closing_motion
from .follower import follower_stiffness
from .large_held import hold_protruding, pair_held, set_guards
from .pairset import PairSet

log = logging.getLogger(__name__)

#: A body is in equilibrium when its out-of-balance force is within this fraction of its
#: reference force (:class:`~vfem.nonlinear.NewtonStep`); the final equilibration then takes it
#: to the Newton tolerance of :meth:`~vfem.nonlinear.NonlinearBody.equilibrate`.
BODY_TOLERANCE = 1e-8

#: How many times a correction is halved when it would turn an element inside out.
MAX_DAMPING = 6


def _concatenate(parts: list[np.ndarray]) -> np.ndarray:
    """The parts one after the other; empty where there are none (no contact pair)."""
    return np.concatenate(parts) if parts else np.zeros(0)


class LargeDeformationContact(PairSet):
    """Frictionless contact with large displacements and sliding (see the module docstring)."""

    capabilities = Capabilities(
        name="paired", orders=(1,), kinematics=("small", "large"), dimensions=(2, 3),
        orders_3d=(1,), sides=True)

    keep_all_nodes = True  # which nodes are over the other surface changes as bodies slide

    def __init__(self, surfaces: list[ContactSurface], pairs: ContactPairs, settings,
                 backend: str | None = None, sides: dict | None = None, executor=None,
                 friction: type | None = None):
        for i, s in enumerate(surfaces):
            # (the facet kind's order: ``s.order`` counts a 2D facet's nodes; a 3D body that
            # touches nothing has no kind and no candidate; a body paired with none may be
            # quadratic: a plastic thick cylinder)
            if s.kind is not None and s.kind.order != 1 and pairs.opponents(i):
                raise InputError(f"body {s.body.name!r}: large-displacement contact needs "
                                 "linear elements (order 1)")
        #: the equilibrium side's nodes held too where they would penetrate (issue 37's held
        #: nodes, paired anew in every iteration: :meth:`penetrations`); not yet with friction
        self.both_surfaces = friction is None
        # (its own pairs, built on the undeformed geometry, which side carries compatibility
        # and which nodes decided once; :meth:`penetrations` moves them to the current one)
        super().__init__(surfaces, pairs, settings, backend, sides, executor=executor,
                         friction=friction)
        self._offsets = np.cumsum([0] + [s.dim * s.nc for s in surfaces])

    # -- the bodies' current state ----------------------------------------------------------------

    def _full_force(self, i: int, F: np.ndarray) -> np.ndarray:
        s = self.surfaces[i]
        f = np.zeros(s.body.ndofs)
        f[s.candidate_dofs] = F.ravel()
        return f

    def positions(self, state: ContactState) -> list[np.ndarray]:
        """The tracked nodes' current positions: the trial states of the large-kinematics bodies,
        the linear response of the others."""
        x = super().positions(state)
        for i, s in enumerate(self.surfaces):
            u = s.body.mechanics.trial_displacement()
            if u is not None:  # a body with its own trial state (the linear ones have none)
                x[i] = s.X + u[s.tracked_dofs].reshape(-1, s.dim)
        return x

    def pairing_positions(self, state: ContactState) -> list[np.ndarray]:
        """The pairs follow the current configuration."""
        return self.positions(state)

    # -- pairing in the current configuration ---------------------------------------------------

    def penetrations(self, state: ContactState) -> list[np.ndarray]:
        """Re-pair every contact pair on the current geometry and return the penetrations (> 0
        overlap) of the pairs' compatibility-side nodes (:meth:`PairedContact._overlap`: a node
        that is not over the other surface measures its distance from its end)."""
        x = self.positions(state)
        out = []
        for k, pair in enumerate(self.contact_pairs):
            if pair.point:  # (after the compatibility pairs: their patches are current)
                out.append(pair_held(self, state, k, x))
                continue
            sf, sc = self.surfaces[pair.fine], self.surfaces[pair.coarse]
            geo = overlap(sf, sc, x[pair.fine], x[pair.coarse], pair.nodes, pair.zones)
            if geo is None:  # the surfaces no longer face each other anywhere
                pair.carries = np.zeros(len(pair.nodes), dtype=bool)
                pair.mass = sp.csr_array(pair.mass.shape)
                pair.transfer = sp.csr_array(pair.transfer.shape)
                pair.patches = None
                self.tractions(state, k)[:] = 0.0
                out.append(np.full(len(pair.nodes), -np.inf))
                continue
            pair.normal, pair.interp, pair.rind_depth = geo.normal, geo.interp, geo.rind_depth
            # a node that is not over the other surface, or whose facets do not overlap it,
            # carries nothing
            pair.mass, pair.transfer = geo.mass, geo.transfer
            pair.carries = geo.carries & ~geo.beyond
            pair.patches = geo.fpatch, geo.cpatch
            self.tractions(state, k)[~pair.carries] = 0.0
            out.append(-geo.gap)
        return out

    # -- the iteration ----------------------------------------------------------------------------

    def solve(self, state: ContactState, on_iteration=None) -> SolveResult:
        """Newton's method on the bodies and the traction values together (module docstring),
        by :func:`~vfem.contact.solvers.iteration.iterate`.

        The history records, per iteration, the largest penetration and, as its equilibrium
        error, the largest out-of-balance force of a body relative to its reference force.
        """
        cfg = self.settings
        tol = self.penetration_tolerance
        self._refused = None

        def check(it: int) -> Check:
            pens = self.penetrations(state)
            self.assemble_forces(state)  # the tractions along the current normals
            lins = self._linearize(state)
            traction_values = self.traction_values(state)
            errs, pen_err, contact, tension = self.compatibility_errors(pens, traction_values)
            body_err = max((lin.residual / lin.reference for lin in lins if lin is not None),
                           default=0.0)
            # a body whose prescribed displacements still lack their step's increment (the
            # first iteration of a step) is not in equilibrium, whatever its residual
            settled = all(lin.prescribed_met for lin in lins if lin is not None)
            need, _, _ = self._platen_terms(state, lins)
            platen_ok = self._platen_on_force(state, need)
            other_err, other_ok, other_what = self._further_errors(state)
            protruding = hold_protruding(self, state, pens, traction_values)
            return Check(
                IterationRecord(it, max(pen_err, other_err), body_err, contact, tension,
                                platen_error=-need),
                (pen_err <= tol and tension == 0 and platen_ok and settled
                 and body_err <= BODY_TOLERANCE and other_ok and not protruding),
                lambda: self._iteration_sets(state, traction_values),
                max(pen_err, body_err, other_err),
                lambda: self.pairings(state, pens),
                lambda: (f"no convergence in {cfg.max_iterations} iterations (penetration "
                         f"{pen_err:.3g}{self.worst_node(errs)}, body residual "
                         f"{body_err:.3g}{other_what}, {tension} nodes in tension)"),
                finish=lambda: self._finish(state), extra=(pens, lins))

        def correct(it: int, c: Check) -> None:
            pens, lins = c.extra
            if it > 0:  # the first iterate is the last converged state, at the new loads
                self._check_rind(pens)
            self._correct_all(state, pens, lins)

        return iterate(cfg, check, correct, on_iteration)

    def _further_errors(self, state: ContactState) -> tuple[float, bool, str]:
        """The errors of conditions beside the normal ones (the friction part's): the largest,
        whether they hold, and what a message says of them. None without friction."""
        if self.friction is not None:
            return self.friction.further_errors(state)
        return 0.0, True, ""

    def _iteration_sets(self, state: ContactState, traction_values: list[np.ndarray]):
        """The sets the cycle watch compares between iterations: the contact set (with
        friction, the part's: the slip sets and directions too)."""
        if self.friction is not None:
            return self.friction.iteration_sets(state, traction_values)
        return self.contact_sets(traction_values)

    def _linearize(self, state: ContactState) -> list:
        """Newton's system of every body whose response is not linear (None for the others,
        :meth:`~vfem.bodies.mechanics.BodyMechanics.linearize`)."""
        return [s.body.mechanics.linearize(state.load_factor, state.platen_displacement,
                                           self._full_force(i, F), s.condensed_dofs,
                                           s.candidate_dofs, self.backend)
                for i, (s, F) in enumerate(zip(self.surfaces, state.forces))]

    def _finish(self, state: ContactState) -> None:
        """Equilibrate every body that iterates under the converged contact forces (what the
        solver commits; one correction at most; a linear body is already in equilibrium)."""
        for i, (s, F) in enumerate(zip(self.surfaces, state.forces)):
            s.body.mechanics.equilibrate(state.load_factor, state.platen_displacement,
                                         self._full_force(i, F))
        if self.friction is not None:  # the slips accumulated, the anchors moved
            self.friction.finish(state)

    def _platen_on_force(self, state: ContactState, need: float) -> bool:
        """Whether the platen's reaction is on its force: ``need`` (:meth:`_platen_terms`)
        within :meth:`~vfem.contact.formulations.group.SurfaceGroup.platen_allowance` (a zero force:
        of the forces its reaction sums, issue 37)."""
        return self.platen_body is None or abs(need) <= self.group.platen_allowance(state)

    def _platen_terms(self, state: ContactState, lins: list) -> tuple[float, float, np.ndarray]:
        """The platen's missing force after the bodies' corrections with the contact forces
        held, its stiffness and its candidate nodes' motion per unit platen motion."""
        i = self.platen_body
        if i is None:
            return 0.0, 0.0, np.zeros(0)
        s = self.surfaces[i]
        if lins[i] is None:
            return (state.platen_force - self.group.platen_reaction(state), s.body.platen_stiffness,
                    self.platen_motion[i].ravel())
        lin = lins[i]
        return (state.platen_force - lin.platen_reaction, lin.platen_stiffness,
                lin.platen_motion[s.candidate_dofs])

    # -- the forces follow the surfaces ----------------------------------------------------------

    def _normals_at(self, state: ContactState, x: list[np.ndarray]) -> list:
        """Per contact pair, the loaded nodes (positions in the pair's nodes, traction nonzero),
        the normals their tractions act along with the bodies' tracked nodes at ``x`` (the
        opposing surface's normal at the virtual node, wherever that now is), the facets of
        the opposing surface their virtual nodes lie on, and (held nodes: their point force
        reaches the other surface at the virtual node, which moves as they slide) the
        interpolation there, else None."""
        out = []
        for k, pair in enumerate(self.contact_pairs):
            on = np.flatnonzero(self.tractions(state, k) != 0)
            if not len(on):
                out.append((on, np.zeros((0, self.surfaces[pair.fine].dim)),
                            np.zeros(0, dtype=int), None))
                continue
            sf, sc = self.surfaces[pair.fine], self.surfaces[pair.coarse]
            # (a loaded node is over the other surface; perturbed past its edge, it keeps the
            # normal there: the one-sided derivative, not a 90-degree turn over the step h;
            # a held node's force acts along the interpolated normal too, :func:`held_now`)
            normal, _, interp, seg, _ = virtual_nodes(sf, sc, x[pair.fine], x[pair.coarse],
                                                      pair.nodes[on], *pair.patches,
                                                      beyond_normal=False)
            out.append((on, normal, seg, interp if pair.point else None))
        return out

    def _traction_vectors(self, state: ContactState, k: int, on: np.ndarray,
                          normal: np.ndarray) -> np.ndarray:
        """Pair k's traction vectors at its nodes ``on`` with ``normal`` there (linear in it:
        given a change of the normals, the change of the vectors): q n (friction adds s t,
        t the normal turned by +90 degrees: the friction part's)."""
        if self.friction is not None:
            return self.friction.traction_vectors(state, k, on, normal)
        return self.tractions(state, k)[on, None] * normal

    def _traction_change(self, state: ContactState, k: int, on: np.ndarray, normal: np.ndarray,
                         perturbed: np.ndarray, h: float) -> np.ndarray:
        """The change of pair k's traction vectors at its nodes ``on`` per unit perturbation
        when their normals move from ``normal`` to ``perturbed`` (by ``h``): the traction is
        linear in the normal here (and with 2D friction, the tangent the normal turned), so
        the traction of the normals' difference quotient (where the friction part's tangents
        are not linear in the normal, 3D, its own difference)."""
        if self.friction is not None and self.friction.turns(k):
            return self.friction.traction_change(state, k, on, normal, perturbed, h)
        return self._traction_vectors(state, k, on, (perturbed - normal) / h)

    def _forces_at(self, state: ContactState, x: list[np.ndarray]) -> np.ndarray:
        """All bodies' candidate nodal forces (stacked) of the state's traction values with the
        bodies' tracked nodes at ``x``: the traction acts along the opposing surface's normal at
        the virtual node, wherever that now is (the transfer held; a held node's point force
        reaches the other surface where its virtual node now is)."""
        out = [np.zeros((s.nc, s.dim)) for s in self.surfaces]
        for k, (pair, (on, normal, _, interp)) in enumerate(zip(self.contact_pairs,
                                                                 self._normals_at(state, x))):
            if not len(on):
                continue
            qn = self._traction_vectors(state, k, on, normal)
            out[pair.fine] += pair.mass[:, pair.nodes[on]] @ qn
            out[pair.coarse] -= (pair.transfer[:, pair.nodes[on]] if interp is None
                                 else interp.T) @ qn
        return np.concatenate([F.ravel() for F in out])

    def _follower_stiffness(self, state: ContactState, coloured: bool = True
                            ) -> tuple[np.ndarray, np.ndarray]:
        """The follower stiffness (:func:`~vfem.contact.formulations.follower.
        follower_stiffness`): the derivative of the candidate forces with respect to the
        candidate positions at fixed traction values, its nonzero columns J and B[:, J]."""
        return follower_stiffness(self, state, coloured)

    # -- the correction -------------------------------------------------------------------------

    def _correct_all(self, state: ContactState, pens: list[np.ndarray], lins: list) -> None:
        """One Newton correction of the bodies and the traction values together.

        On the stacked candidate dofs of all bodies: their motion is ``a + M dq`` for a change
        dq of the traction values of the nodes that may touch, ``a`` the bodies' own Newton
        corrections with the contact forces held, ``M dq`` their tangent flexibility times the
        change of the forces, the forces' turning included (``du = C (A dq + B du)``, solved on
        the coordinates B depends on). The linearised penetrations give the complementarity
        problem for dq; each body then moves by its own correction plus the response of its full
        mesh to the change of its forces (one more solve with its factorization). With friction
        the unknowns of a node are its normal and tangential traction values
        (:meth:`directions`), and :meth:`_solve_linearised` finds the stick and slip sets
        too.
        """
        tol = self.penetration_tolerance
        off = self._offsets
        nt = off[-1]
        # over MPI ranks every body's tangent on its owner, all owners at once
        # (vfem.bodies.mechanics.prefetch; nothing in serial)
        prefetch(self.executor, lins)
        C = [lin.flexibility[: s.dim * s.nc] if lin is not None else s.C
             for s, lin in zip(self.surfaces, lins)]
        a = np.concatenate([lin.correction[s.candidate_dofs] if lin is not None
                            else np.zeros(s.dim * s.nc) for s, lin in zip(self.surfaces, lins)])
        J, Bj = self._follower_stiffness(state)
        CB = np.zeros((nt, len(J)))
        for b in range(len(self.surfaces)):
            CB[off[b]:off[b + 1]] = C[b] @ Bj[off[b]:off[b + 1]]
        coupled = np.eye(len(J)) - CB[J]

        def with_follower(u):
            """u + C B du_J with du_J solving du_J = u_J + (C B)_J du_J (columns of u)."""
            if not len(J):
                return u, np.zeros((0,) + u.shape[1:])
            duJ = np.linalg.solve(coupled, u[J])
            return u + CB @ duJ, duJ

        a, aJ = with_follower(a)
        # the nodes that may touch: those carrying traction, and those within reach of the
        # deepest linearised penetration
        lin_pens, sets = [], []
        for k, (pair, p) in enumerate(zip(self.contact_pairs, pens)):
            p = p - self._normal_motion(pair, a, np.arange(len(pair.nodes)))
            reach = max(tol, float(np.max(p, initial=0.0)))
            lin_pens.append(p)
            carrying = self.tractions(state, k) != 0
            sets.append(np.flatnonzero(pair.carries & (carrying | (p > -reach))))
        directions = [self.directions(k) for k in range(len(self.contact_pairs))]
        m = sum(len(s_) * len(dirs) for s_, dirs in zip(sets, directions))
        # force patterns per unit traction value, stacked candidate dofs x m (per pair, the
        # set's normal unknowns, then its tangential ones)
        A = np.zeros((nt, m))
        col = 0
        for k, s_ in enumerate(sets):
            pair = self.contact_pairs[k]
            dim = self.surfaces[pair.fine].dim
            for direction in directions[k]:
                n = direction[s_]
                cols = slice(col, col + len(s_))
                for d in range(dim):  # component d of every node's force: every dim-th dof
                    A[off[pair.fine] + d:off[pair.fine + 1]:dim, cols] += (
                        pair.mass[:, pair.nodes[s_]].toarray() * n[:, d])
                    A[off[pair.coarse] + d:off[pair.coarse + 1]:dim, cols] -= (
                        pair.transfer[:, pair.nodes[s_]].toarray() * n[:, d])
                col += len(s_)
        CA = np.zeros((nt, m))
        for b in range(len(self.surfaces)):
            CA[off[b]:off[b + 1]] = C[b] @ A[off[b]:off[b + 1]]
        M, MJ = with_follower(CA)
        W = np.zeros((m, m))
        p = np.zeros(m)
        q0 = np.zeros(m)
        need, stiffness, motion = self._platen_terms(state, lins)
        platen = self.platen_body is not None and state.platen_force != 0.0
        v = np.zeros(nt)  # the candidate nodes' motion per unit platen motion
        if platen:
            v[off[self.platen_body]:off[self.platen_body + 1]] = motion
        rates = [-self._normal_motion(pair, v, np.arange(len(pair.nodes)))
                 for pair in self.contact_pairs]  # penetration per unit platen motion
        row = 0
        for k, s_ in enumerate(sets):
            pair = self.contact_pairs[k]
            for j, direction in enumerate(directions[k]):
                rows = slice(row, row + len(s_))
                if j == 0:  # penetration decrease per unit traction value
                    W[rows] = self._normal_motion(pair, M, s_)
                    p[rows] = lin_pens[k][s_]
                    q0[rows] = self.tractions(state, k)[s_]
                else:  # the slip along the tangent per unit traction value
                    W[rows] = self._motion_along(pair, direction, M, s_)
                    p[rows] = self.friction.slip_now(state, k, s_, direction) \
                        + self._motion_along(pair, direction, a, s_)
                    q0[rows] = self.friction.shear(state, k)[s_, j - 1]  # (n, ntan): j-th
                row += len(s_)
        rate = _concatenate([r[s_] for r, s_ in zip(rates, sets)])
        dR = -motion @ A[off[self.platen_body]:off[self.platen_body + 1]] if platen else None
        if platen and m == 0 and stiffness == 0.0:
            # nothing may touch yet and nothing else holds the platen's body: move the platen
            # just far enough to close the smallest gap
            q, dplaten = q0, closing_motion(_concatenate(lin_pens), _concatenate(rates), need)
        else:
            q, dplaten = self._solve_linearised(state, W, q0, p, tol, sets,
                                                rate if platen else None, dR, stiffness, need)
        dq = q - q0
        dF = A @ dq + (Bj @ (aJ + MJ @ dq) if len(J) else 0.0)
        moves = []
        for i, lin in enumerate(lins):
            if lin is None:
                moves.append(None)
                continue
            du = lin.correction + lin.solve(self._full_force(i, dF[off[i]:off[i + 1]]))
            if platen and i == self.platen_body:
                du = du + dplaten * lin.platen_motion
            moves.append(du)
        self._move(state, sets, dq, dplaten, moves,
                   [dF[off[i]:off[i + 1]].reshape(-1, s.dim) for i, s in enumerate(self.surfaces)])

    def _solve_linearised(self, state: ContactState, W: np.ndarray, q0: np.ndarray,
                          p: np.ndarray, tol: float, sets: list[np.ndarray], rate, dR,
                          stiffness: float, need: float) -> tuple[np.ndarray, float]:
        """The traction values of the linearised contact problem (and the platen's motion):
        complementarity on the normal ones
        (:func:`~vfem.contact.solvers.complementarity.linear_complementarity`), the held nodes
        joining only where they would penetrate and their guard's nodes do not all touch
        (:func:`~.large_held.set_guards`; those that find no set with the others are refused, and
        :meth:`_excused` leaves them to invariant (b), as under small kinematics); with
        friction, the part's stick and slip sets too."""
        if self.friction is not None:
            return self.friction.solve_linearised(state, W, q0, p, tol, sets, rate, dR,
                                                  stiffness, need)
        reserve, guard = set_guards(self, sets)
        refused = np.zeros(len(q0), dtype=bool)
        out = linear_complementarity(W, q0, p, tol, rate, dR, stiffness, need,
                                     reserve=reserve, guard=guard, refused=refused)
        offsets = self._unknown_offsets()
        self._refused = np.zeros(offsets[-1], dtype=bool)
        starts = np.cumsum([0] + [len(s_) for s_ in sets])
        for k, s_ in enumerate(sets):
            self._refused[offsets[k] + s_] = refused[starts[k]:starts[k + 1]]
        if self._refused.any():
            log.info("%d held nodes found no contact set with the others: left out",
                     int(self._refused.sum()))
        return out

    def _motion_along(self, pair, direction: np.ndarray, u: np.ndarray, nodes: np.ndarray
                      ) -> np.ndarray:
        """``direction . (u_fine - u_coarse at the virtual node)`` of the pair's nodes for
        stacked candidate motions u (vector or columns)."""
        off = self._offsets
        sf, sc = self.surfaces[pair.fine], self.surfaces[pair.coarse]
        uf = u[off[pair.fine]:off[pair.fine + 1]].reshape((sf.nc, sf.dim) + u.shape[1:])
        uc = u[off[pair.coarse]:off[pair.coarse + 1]].reshape((sc.nc, sc.dim) + u.shape[1:])
        w = pair.interp[nodes]
        rel = uf[pair.nodes[nodes]] - (w @ uc.reshape(sc.nc, -1)).reshape((w.shape[0],)
                                                                          + uc.shape[1:])
        return np.einsum("id,id...->i...", direction[nodes], rel)

    def _add_unknowns(self, state: ContactState, sets: list[np.ndarray], dq: np.ndarray
                      ) -> None:
        """Add a correction of the unknowns (the order of :meth:`_correct_all`'s columns; with
        friction, the part's normal and tangential ones)."""
        if self.friction is not None:
            self.friction.add_unknowns(state, sets, dq)
            return
        pos = 0
        for k, s_ in enumerate(sets):
            self.tractions(state, k)[s_] += dq[pos:pos + len(s_)]
            pos += len(s_)

    def _normal_motion(self, pair, u: np.ndarray, nodes: np.ndarray) -> np.ndarray:
        """Penetration decrease g . (u_fine - u_coarse at the virtual node) of the pair's nodes
        for stacked candidate motions u (vector or columns), g the direction the gap is read
        along (:meth:`~vfem.contact.geometry.pairing.ContactPair.reading`: the normal; a held
        node's, the facet's)."""
        return self._motion_along(pair, pair.reading(0, pair.normal), u, nodes)

    def _move(self, state: ContactState, sets: list[np.ndarray], dq: np.ndarray,
              dplaten: float, moves: list, dF: list[np.ndarray]) -> None:
        """Apply a correction, halved while it would turn an element inside out.

        The nodal contact forces change by their linearised change ``dF``: a small-kinematics
        body's position follows its forces, and must be where the correction put it when the
        next iteration pairs the surfaces (they are then assembled anew, on the new geometry).
        """
        fraction = 1.0
        for attempt in range(MAX_DAMPING + 1):
            moved = []
            try:
                for s, du in zip(self.surfaces, moves):
                    if du is not None:
                        s.body.mechanics.move(fraction * du)
                        moved.append((s.body, du))
                break
            except AnalysisError as exc:
                for body, du in moved:
                    body.mechanics.move(-fraction * du)
                if attempt == MAX_DAMPING:
                    raise
                fraction *= 0.5
                log.info("contact correction halved (%s)", exc)
        self._add_unknowns(state, sets, fraction * dq)
        state.platen_displacement += fraction * dplaten
        for F, d in zip(state.forces, dF):
            F += fraction * d
        for pair in self.contact_pairs:
            state.released[pair.fine][pair.nodes] = False


__all__ = ["LargeDeformationContact", "BODY_TOLERANCE", "MAX_DAMPING"]
