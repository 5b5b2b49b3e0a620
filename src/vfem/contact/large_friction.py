"""Coulomb friction under large displacements and sliding (issue 20, item 3).

The small-kinematics friction (:mod:`vfem.contact.friction`) measures a node's slip as the change
of its relative tangential displacement against its virtual node on the undeformed pairs. When
the bodies slide far and turn, that measure means nothing: the virtual node moves along the
opposing surface, facet after facet. Here, as in the frictionless large-displacement variant
(:mod:`vfem.contact.large`), every iteration pairs the surfaces on the current geometry, and:

* **the anchor** of a compatibility-side node is a *material point of the opposing surface*:
  where its virtual node was at the last converged step, kept as that surface's facet and
  parameter (``FrictionState.anchor`` holds ``facet + t``). The slip within the step is the
  node's distance from that point along the current tangent, ``g = t . (x_node - x_anchor)``,
  with ``x_anchor`` where the opposing surface's motion has now carried the point: the slip
  history is convected along the opposing surface as it moves and deforms;
* **the unknowns** of a node are its normal and tangential traction values; both sides' forces
  come from the one traction field ``q n + s t`` along the current normal and tangent (so they
  balance to round-off, as without friction), and both turn with the surfaces (the follower
  term of the Newton correction differentiates ``q n + s t``, t being n turned by 90 degrees);
* **the Newton correction** of the bodies and the tractions together (the frictionless
  variant's, :meth:`LargeDeformationContact._correct_all`) solves, on the linearised model, the
  normal conditions (complementarity, as without friction) and the tangential ones: a sticking
  node's slip vanishes, a slipping one's traction sits on the Coulomb cone ``s = -mu sigma q``
  opposing its slip. The stick and slip sets are found on the linearised model by an active-set
  loop of small dense solves (:meth:`FrictionalLargeContact._solve_linearised`), the return map
  onto the cone per node of the small-kinematics variant;
* **at convergence** each node's slip is accumulated and its anchor moves to its virtual node.

The linearisation of the slip uses the interpolation at the virtual node for the anchor's motion
(the two coincide for a sticking node, to the step's normal offset); the slip itself is measured
exactly in every check, so this affects the rate of the iteration, not its answer. A node that
comes into contact within a step sticks at the point it was over at the last converged step
until the iteration finds it slipping (the small-kinematics variant's interpolation of the touch
point is not made here). Coulomb with one coefficient and with static and dynamic ones; the
elasto-plastic law and a force-controlled platen are small-kinematics only for now.
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from .friction import CONE_TOLERANCE, HELD, FrictionHistory, tangents
from .large import LargeDeformationContact
from .pairing import virtual_nodes
from .state import ContactState, FrictionState

log = logging.getLogger(__name__)


class FrictionalLargeContact(FrictionHistory, LargeDeformationContact):
    """The paired variant with Coulomb friction under large displacements (module docstring)."""

    capabilities = dataclasses.replace(LargeDeformationContact.capabilities,
                                       name="paired, frictional",
                                       friction=("frictionless", "coulomb"))
    state_type = FrictionState

    def __init__(self, surfaces, pairs, settings, backend: str | None = None):
        super().__init__(surfaces, pairs, settings, backend)
        self._init_friction(settings)
        # (the elasto-plastic law and a force-controlled platen are refused before, by
        # vfem.contact.formulation.check_capabilities)

    # -- the traction field ----------------------------------------------------------------------

    def directions_now(self, k: int) -> list[np.ndarray]:
        """The current normal, then the tangent: the order of each pair's unknowns."""
        return [self.contact_pairs[k].normal, self.tangent(k)]

    def _traction_vectors(self, state, k, on, normal):
        """``q n + s t`` at the nodes ``on`` (t: ``normal`` turned by +90 degrees)."""
        return (self.tractions(state, k)[on, None] * normal
                + self.shear(state, k)[on, None] * tangents(normal)[0])

    def assemble_forces(self, state: ContactState) -> None:
        """Every body's nodal forces from the pairs' normal and tangential tractions, along the
        current normals and tangents."""
        for F in state.forces:
            F[:] = 0.0
        for k, pair in enumerate(self.contact_pairs):
            on = np.arange(len(pair.nodes))
            traction = self._traction_vectors(state, k, on, pair.normal)
            state.forces[pair.fine] += pair.mass[:, pair.nodes] @ traction
            state.forces[pair.coarse] -= pair.transfer[:, pair.nodes] @ traction

    def _add_unknowns(self, state, sets, dq) -> None:
        """Per pair, the set's normal traction values, then its tangential ones."""
        pos = 0
        for k, s_ in enumerate(sets):
            n = len(s_)
            self.tractions(state, k)[s_] += dq[pos:pos + n]
            self.shear(state, k)[s_] += dq[pos + n:pos + 2 * n]
            pos += 2 * n
        for k in range(len(self.contact_pairs)):  # no shear without a normal traction
            self.shear(state, k)[self.tractions(state, k) <= 0] = 0.0

    # -- anchors and slips -----------------------------------------------------------------------

    def _virtual_points(self, x: list[np.ndarray]) -> list[np.ndarray]:
        """Per pair, each node's virtual node at positions ``x`` as ``facet + t`` on the
        opposing surface (what :attr:`FrictionState.anchor` keeps)."""
        out = []
        for pair in self.contact_pairs:
            sf, sc = self.surfaces[pair.fine], self.surfaces[pair.coarse]
            if pair.patches is None:
                out.append(np.zeros(len(pair.nodes)))
                continue
            _, _, interp, seg, _ = virtual_nodes(sf, sc, x[pair.fine], x[pair.coarse],
                                                 pair.nodes, *pair.patches)
            out.append(sc.material_points(seg, interp))
        return out

    def _anchor_positions(self, k: int, xc: np.ndarray, anchor: np.ndarray) -> np.ndarray:
        """Where the opposing surface's material points ``anchor`` (``facet + t``) now are."""
        return self.surfaces[self.contact_pairs[k].coarse].material_positions(anchor, xc)

    def slips(self, state: FrictionState, x: list[np.ndarray] | None = None
              ) -> list[np.ndarray]:
        """Per pair, each node's slip within the step: its distance from its anchor along the
        current tangent (module docstring)."""
        x = self.positions(state) if x is None else x
        out = []
        for k, pair in enumerate(self.contact_pairs):
            xa = self._anchor_positions(k, x[pair.coarse], self.anchor(state, k))
            out.append(np.einsum("ij,ij->i", x[pair.fine][pair.nodes] - xa, self.tangent(k)))
        return out

    def _slip_now(self, state, k, s_, direction) -> np.ndarray:
        """The slips of pair k's nodes ``s_`` (the linearised tangential rows' start)."""
        return self.slips(state)[k][s_]

    def new_state(self, load_factor: float = 0.0, platen_displacement: float = 0.0
                  ) -> ContactState:
        """No contact force; each node anchored at its virtual node on the undeformed
        surfaces."""
        state = super().new_state(load_factor, platen_displacement)
        x = self.positions(state)
        self.penetrations(state)  # the pairs on this geometry
        for k, v in enumerate(self._virtual_points(x)):
            state.anchor[k] = v
        return state

    # -- the iteration ---------------------------------------------------------------------------

    def _further_errors(self, state: FrictionState) -> tuple[float, bool, str]:
        """The friction's errors: a sticking node's slip, a slipping node's slip against its
        traction, a tangential traction outside its cone."""
        err, excess, _, _ = self.friction_errors(state, self.slips(state))
        ok = err <= self.penetration_tolerance and excess <= CONE_TOLERANCE
        return err, ok, f", tangential slip error {err:.3g}"

    def _iteration_sets(self, state, traction_values):
        return self._sets(state)

    def _finish(self, state: FrictionState) -> None:
        """Equilibrate the bodies (as without friction), then accumulate each node's slip and
        anchor it at its virtual node."""
        super()._finish(state)
        x = self.positions(state)
        self.penetrations(state)  # the pairs on the equilibrated geometry
        slips = self.slips(state, x)
        self._increments = []
        for k, (g, v) in enumerate(zip(slips, self._virtual_points(x))):
            on = self.tractions(state, k) > 0
            increment = np.where(on, g, 0.0)
            self.accumulated_slip(state, k)[:] += np.abs(increment)
            self._increments.append(increment)
            self.anchor(state, k)[:] = v

    def _solve_linearised(self, state, W, q0, p, tol, sets, rate, dR, stiffness, need):
        """The normal and tangential traction values of the linearised problem.

        Rows and columns per pair: the set's normal unknowns, then its tangential ones. After
        a change dx of the unknowns the penetrations are ``p_n - W_n dx`` and the slips
        ``p_t + W_t dx``. Find the contact set (q >= 0, penetration <= tol, one of them zero)
        and, among the nodes in contact, the sticking ones (slip 0, ``|s| <= mu_s q``) and the
        slipping ones (``s = -mu sigma q``, the slip along sigma): an active-set loop, every
        violation swapped at once, each set one dense solve, until no set changes (at most
        ``10 m + 10`` sets; a set that comes back ends it with the last solution, the Newton
        iteration going on from there).
        """
        m = len(q0)
        pair_of = np.concatenate([np.full(len(s_), k) for k, s_ in enumerate(sets)]
                                 or [np.zeros(0, int)])
        starts = np.cumsum([0] + [2 * len(s_) for s_ in sets])[:-1]
        nrm = np.concatenate([starts[k] + np.arange(len(s_)) for k, s_ in enumerate(sets)]
                             or [np.zeros(0, int)]).astype(int)
        tng = nrm + np.repeat([len(s_) for s_ in sets], [len(s_) for s_ in sets]).astype(int)
        mu = np.array([self.laws[k][0] for k in pair_of])
        mu_static = np.array([self.laws[k][1] for k in pair_of])
        was_sliding = np.concatenate([self.sliding(state, k)[s_] for k, s_ in enumerate(sets)]
                                     or [np.zeros(0, bool)])
        q, s = q0[nrm], q0[tng]
        contact = (q > 0) | (p[nrm] > tol)
        mu_now = np.where(was_sliding, mu, mu_static)
        slipping = contact & (q > 0) & (np.abs(s) >= (1.0 - CONE_TOLERANCE) * mu_now * q) \
            & (s != 0) & (mu_static > 0)
        sigma = np.where(s != 0, -np.sign(s), np.sign(p[tng]))
        # a node whose relative tangential motion no traction moves (a symmetry plane through
        # the contact, both bodies held along it) has no tangential unknown, as under small
        # kinematics (HELD); nor has a frictionless pair's
        diagonal = np.abs(np.diag(W))
        held = diagonal[tng] <= HELD * diagonal.max(initial=0.0)
        frictionless = (mu_static == 0.0) | held
        # a node that comes into contact and has moved along the other surface since the last
        # converged step slips the way it moved, until its traction says it sticks
        entering = contact & (q <= 0) & (np.abs(p[tng]) > tol) & ~frictionless
        slipping |= entering
        seen: set[bytes] = set()
        x = q0.copy()
        for _ in range(10 * m + 10):
            stick = contact & ~slipping & ~frictionless
            slide = contact & slipping
            cols = np.concatenate([nrm[contact], tng[stick]])
            rows = cols
            ties = np.where(frictionless, 0.0, -mu * sigma)  # s = tie q on slipping nodes
            x = np.zeros(m)
            # known: the nodes off contact carry nothing; solve for the rest
            A = W[np.ix_(rows, cols)].copy()
            tied_q = nrm[slide | (contact & frictionless)]
            tied_s = tng[slide | (contact & frictionless)]
            tie = ties[slide | (contact & frictionless)]
            position = np.full(m, -1)
            position[cols] = np.arange(len(cols))
            A[:, position[tied_q]] += W[np.ix_(rows, tied_s)] * tie
            # rows: normal W_n x = p_n + W_n x0 (no penetration left); tangential
            # W_t x = W_t x0 - p_t (no slip left)
            normal_row = np.isin(rows, nrm)
            b = W[rows] @ q0 + np.where(normal_row, p[rows], -p[rows])
            if len(cols):
                try:
                    x[cols] = np.linalg.solve(A, b)
                except np.linalg.LinAlgError:  # dependent rows: the least-squares solution
                    x[cols] = np.linalg.lstsq(A, b, rcond=None)[0]
                x[tied_s] = tie * x[tied_q]
            dx = x - q0
            pen = p[nrm] - W[nrm] @ dx
            slip = p[tng] + W[tng] @ dx
            qn, sn = x[nrm], x[tng]
            leave = contact & (qn < 0)
            join = ~contact & (pen > tol)
            over = stick & (np.abs(sn) > (1.0 + CONE_TOLERANCE) * mu_static * qn)
            back = slide & (sigma * slip < -tol)
            if not (leave.any() or join.any() or over.any() or back.any()):
                break
            key = np.concatenate([contact, slipping, sigma > 0]).tobytes()
            if key in seen:
                log.debug("frictional linearised contact: a set came back")
                break
            seen.add(key)
            contact = (contact & ~leave) | join
            moved = join & (np.abs(slip) > tol) & ~frictionless
            sigma = np.where(over, -np.sign(sn), np.where(moved, np.sign(slip), sigma))
            slipping = (slipping | over | moved) & ~back & contact
        x[nrm] = np.where(x[nrm] > 0, x[nrm], 0.0)
        x[tng] = np.where(x[nrm] > 0, x[tng], 0.0)
        # which nodes slide (the static coefficient holds the others)
        for k, s_ in enumerate(sets):
            self.sliding(state, k)[:] = False
            self.sliding(state, k)[s_] = (slipping & contact)[pair_of == k]
        return x, 0.0


__all__ = ["FrictionalLargeContact"]
