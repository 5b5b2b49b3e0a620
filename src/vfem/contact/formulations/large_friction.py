"""Coulomb friction under large displacements and sliding (issue 20, item 3).

The small-kinematics friction (:mod:`vfem.contact.formulations.friction`) measures a node's slip as
the change of its relative tangential displacement against its virtual node on the undeformed pairs.
When the bodies slide far and turn, that measure means nothing: the virtual node moves along the
opposing surface, facet after facet. Here, as in the frictionless large-displacement variant
(:mod:`vfem.contact.formulations.large`), every iteration pairs the surfaces on the current
geometry, and:

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
  loop of small dense solves (:meth:`LargeFriction.solve_linearised`), the return map
  onto the cone per node of the small-kinematics variant;
* **at convergence** each node's slip is accumulated and its anchor moves to its virtual node.

The linearisation of the slip uses the interpolation at the virtual node for the anchor's motion
(the two coincide for a sticking node, to the step's normal offset); the slip itself is measured
exactly in every check, so this affects the rate of the iteration, not its answer. A node that
comes into contact within a step sticks at the point it was over at the last converged step
until the iteration finds it slipping (the small-kinematics variant's interpolation of the touch
point is not made here). Coulomb with one coefficient and with static and dynamic ones; the
elasto-plastic law and a force-controlled platen are small-kinematics only for now.

**In 3D** (issue 21) the same, with two tangents per node measured from a global axis chosen
once per node (:meth:`LargeFriction._basis`), anchors kept as a facet and its nodes'
shape-function values at the point, and the cone a disk whose slip direction turns in the
linearised solve (:meth:`LargeFriction.solve_linearised`); docs/method.md §11,
*In 3D*.
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from ...errors import AnalysisError
from ..geometry import tangent_axes, tangents, virtual_nodes
from ..laws import (
    CONE_TOLERANCE,
    beyond_cone,
    magnitudes,
    reaches_cone,
)
from ..state import ContactState, FrictionState
from .composed import Composed
from .friction import HELD, plane_normals
from .friction_history import FrictionHistory
from .large import LargeDeformationContact

log = logging.getLogger(__name__)

#: 3D: the largest |n . axis| of a contact normal and the axis its first tangent is measured
#: from (:meth:`LargeFriction._basis`); the axis was the least aligned with the
#: undeformed normal (|n . axis| <= 0.577), so a normal may turn by at least 36 degrees
TURNED = 0.95


class LargeFriction(FrictionHistory):
    """The friction part of the paired variant under large displacements (module docstring):
    :class:`~vfem.contact.formulations.large.LargeDeformationContact` holds it as ``friction``
    and asks it for the tangential unknowns, their traction vectors, rows and errors."""

    def __init__(self, form, settings) -> None:
        super().__init__(form, settings)
        #: 3D: per pair and node, the global axis whose projection on the current tangent plane
        #: is the first tangent (:func:`~vfem.contact.geometry.tangent_basis.tangents`): the one
        #: least aligned with the node's own undeformed outward normal (on a symmetry plane, in the
        #: plane), so the tangents follow the turning normal smoothly and the choice depends on
        #: nothing but the mesh (not on where the pairing first put the node: a node beyond the
        #: other surface has the direction to its edge as pair normal, nearly in the surface's
        #: plane, and the axis across the surface then met the normal once the other body slid over
        #: it). None in 2D.
        self._axes = [tangent_axes(plane_normals(sf, p, sf.node_normals()[p.nodes]))
                      if sf.dim == 3 else None
                      for p, sf in ((p, form.surfaces[p.fine]) for p in form.contact_pairs)]
        # (the elasto-plastic law and a force-controlled platen are refused before, by
        # vfem.contact.formulations.formulation.check_capabilities)

    # -- the traction field ----------------------------------------------------------------------

    def _basis(self, k: int, on: np.ndarray, normal: np.ndarray) -> list[np.ndarray]:
        """Pair k's tangents at its nodes ``on`` with unit ``normal`` there: 2D the normal
        turned by +90 degrees; 3D the projection of each node's axis (:attr:`_axes`) on the
        tangent plane, and the normal times it (the normal less its part across a symmetry
        plane at a node on one, :func:`~vfem.contact.formulations.friction.plane_normals`)."""
        if self._axes[k] is None:
            return tangents(normal)
        flat, turned = self._turned(k, on, normal)
        axes = self._axes[k][on]
        # (a node whose normal has turned onto its axis: the least aligned axis now; its
        # tangents then jump, which :meth:`further_errors` refuses where it carries traction)
        if turned.any():
            axes = axes.copy()
            axes[turned] = tangent_axes(flat[turned])
        return tangents(flat, axes)

    def tangent_basis(self, k: int) -> list[np.ndarray]:
        """Pair k's unit tangents at its nodes, on the current geometry."""
        on = np.arange(len(self.form.contact_pairs[k].nodes))
        return self._basis(k, on, self.form.contact_pairs[k].normal)

    def traction_vectors(self, state, k, on, normal):
        """``q n + s t`` at the nodes ``on`` (2D: t is ``normal`` turned by +90 degrees; 3D:
        ``q n + s1 t1 + s2 t2``, the tangents of :meth:`_basis`)."""
        s = self.shear(state, k)[on]
        return self.form.tractions(state, k)[on, None] * normal + sum(
            s[:, j, None] * t for j, t in enumerate(self._basis(k, on, normal)))

    def turns(self, k: int) -> bool:
        """Whether pair k's tangents are not linear in its normal (3D: measured from an axis,
        :meth:`_basis`), so that their change is the traction vectors' own difference
        (:meth:`traction_change`); in 2D the tangent is the normal turned, linear in it."""
        return self._axes[k] is not None

    def traction_change(self, state, k, on, normal, perturbed, h):
        """3D (:meth:`turns`): the tangents are not linear in the normal: the difference of
        the traction vectors themselves."""
        return (self.traction_vectors(state, k, on, perturbed)
                - self.traction_vectors(state, k, on, normal)) / h

    def assemble_forces(self, state: ContactState) -> None:
        """Every body's nodal forces from the pairs' normal and tangential tractions, along the
        current normals and tangents."""
        for F in state.forces:
            F[:] = 0.0
        for k, pair in enumerate(self.form.contact_pairs):
            on = np.arange(len(pair.nodes))
            traction = self.traction_vectors(state, k, on, pair.normal)
            state.forces[pair.fine] += pair.mass[:, pair.nodes] @ traction
            state.forces[pair.coarse] -= pair.transfer[:, pair.nodes] @ traction

    def add_unknowns(self, state, sets, dq) -> None:
        """Per pair, the set's normal traction values, then its tangential ones (tangent by
        tangent)."""
        pos = 0
        for k, s_ in enumerate(sets):
            n = len(s_)
            self.form.tractions(state, k)[s_] += dq[pos:pos + n]
            shear = self.shear(state, k)
            for j in range(shear.shape[1]):
                shear[s_, j] += dq[pos + (1 + j) * n:pos + (2 + j) * n]
            pos += (1 + shear.shape[1]) * n
        for k in range(len(self.form.contact_pairs)):  # no shear without a normal traction
            self.shear(state, k)[self.form.tractions(state, k) <= 0] = 0.0

    # -- anchors and slips -----------------------------------------------------------------------

    def _virtual_points(self, x: list[np.ndarray]) -> list[np.ndarray]:
        """Per pair, each node's virtual node at positions ``x`` as a material point of the
        opposing surface (what :attr:`FrictionState.anchor` keeps: 2D ``facet + t``, 3D the
        facet and its nodes' shape-function values, :meth:`ContactSurface.material_points`)."""
        out = []
        for pair in self.form.contact_pairs:
            sf, sc = self.form.surfaces[pair.fine], self.form.surfaces[pair.coarse]
            if pair.patches is None:  # (nothing over the other surface: no anchor read)
                out.append(sc.unset_material_points(len(pair.nodes)))
                continue
            _, _, interp, seg, _ = virtual_nodes(sf, sc, x[pair.fine], x[pair.coarse],
                                                 pair.nodes, *pair.patches)
            out.append(sc.material_points(seg, interp))
        return out

    def _anchor_positions(self, k: int, xc: np.ndarray, anchor: np.ndarray) -> np.ndarray:
        """Where the opposing surface's material points ``anchor`` (:meth:`_virtual_points`)
        now are."""
        return self.form.surfaces[self.form.contact_pairs[k].coarse].material_positions(anchor, xc)

    def _relative(self, state, k, x) -> np.ndarray:
        """Pair k's nodes' positions less their anchors' (module docstring)."""
        pair = self.form.contact_pairs[k]
        return x[pair.fine][pair.nodes] - self._anchor_positions(k, x[pair.coarse],
                                                                 self.anchor(state, k))

    def slips(self, state: FrictionState, x: list[np.ndarray] | None = None
              ) -> list[np.ndarray]:
        """Per pair, each node's slip within the step: its distance from its anchor along each
        current tangent, (n, ntan) (module docstring)."""
        x = self.form.positions(state) if x is None else x
        out = []
        for k in range(len(self.form.contact_pairs)):
            d = self._relative(state, k, x)
            out.append(np.column_stack([np.einsum("ij,ij->i", d, tj)
                                        for tj in self.tangent_basis(k)]))
        return out

    def slip_now(self, state, k, s_, direction) -> np.ndarray:
        """The slips of pair k's nodes ``s_`` along ``direction`` (a tangent at its nodes; the
        linearised tangential rows' start): :meth:`slips` of this pair and these nodes."""
        d = self._relative(state, k, self.form.positions(state))[s_]
        return np.einsum("ij,ij->i", d, direction[s_])

    def start(self, state: FrictionState) -> None:
        """The state before the first step (no contact force): each node anchored at its
        virtual node on the undeformed surfaces."""
        x = self.form.positions(state)
        self.form.penetrations(state)  # the pairs on this geometry
        for k, v in enumerate(self._virtual_points(x)):
            state.anchor[k] = v

    # -- the iteration ---------------------------------------------------------------------------

    def _turned(self, k: int, on: np.ndarray | None = None, normal: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
        """3D: pair k's normals at its nodes ``on`` (all; ``normal`` there, else the pair's)
        less their part across a symmetry plane, and which have turned to within
        ``arccos(TURNED)`` of the axis their tangents are measured from (:meth:`_basis`)."""
        pair = self.form.contact_pairs[k]
        flat = plane_normals(self.form.surfaces[pair.fine], pair, normal, on)
        axes = self._axes[k] if on is None else self._axes[k][on]
        return flat, np.abs(flat[np.arange(len(flat)), axes]) > TURNED

    def further_errors(self, state: FrictionState) -> tuple[float, bool, str]:
        """The friction's errors: a sticking node's slip, a slipping node's slip against its
        traction, a tangential traction outside its cone. 3D: a node carrying traction whose
        normal has turned onto the axis of its tangents stops the analysis (:meth:`_basis`)."""
        for k, pair in enumerate(self.form.contact_pairs):
            if self._axes[k] is None:
                continue
            bad = np.flatnonzero(self._turned(k)[1] & (self.form.tractions(state, k) > 0))
            if len(bad):
                sf = self.form.surfaces[pair.fine]
                raise AnalysisError(
                    f"body {sf.body.name!r}, contact node {sf.nodes[pair.nodes[bad[0]]]}: its "
                    "contact normal has turned onto the axis its friction tangents are measured "
                    "from (within 18 degrees); 3D friction with large kinematics takes contact "
                    "normals turning by up to about 35 degrees from the undeformed ones")
        err, excess, _, _ = self.friction_errors(state, self.slips(state))
        ok = err <= self.form.penetration_tolerance and excess <= CONE_TOLERANCE
        return err, ok, f", tangential slip error {err:.3g}"

    def iteration_sets(self, state, traction_values):
        """The sets the cycle watch compares: contact, slip and the slip directions."""
        return self._sets(state)

    def finish(self, state: FrictionState) -> None:
        """After the bodies are equilibrated (as without friction), accumulate each node's slip
        and anchor it at its virtual node."""
        x = self.form.positions(state)
        self.form.penetrations(state)  # the pairs on the equilibrated geometry
        slips = self.slips(state, x)
        self._increments = []
        for k, (g, v) in enumerate(zip(slips, self._virtual_points(x))):
            on = self.form.tractions(state, k) > 0
            increment = np.where(on[:, None], g, 0.0)
            self.accumulated_slip(state, k)[:] += magnitudes(increment)
            self._increments.append(increment)
            self.anchor(state, k)[:] = v

    def _coefficients(self, state: FrictionState, sets: list[np.ndarray]):
        """Over the nodes of the linearised problem (each pair's ``sets`` in turn), per node:
        its law's dynamic and static coefficients, the one its traction must reach to slip
        (:meth:`onset`), and whether its pair has friction at all."""
        def each(read) -> np.ndarray:
            return np.concatenate([read(state, k)[s_] for k, s_ in enumerate(sets)]
                                  or [np.zeros(0)])

        acts = np.concatenate([np.full(len(s_), self.laws[k].acts) for k, s_ in enumerate(sets)]
                              or [np.zeros(0, bool)])
        return each(self.dynamic), each(self.static), each(self.onset), acts

    def solve_linearised(self, state, W, q0, p, tol, sets, rate, dR, stiffness, need):
        """The normal and tangential traction values of the linearised problem, in any
        dimension.

        Rows and columns per pair: the set's normal unknowns, then those along its first
        tangent, then (3D) along its second. After a change dx of the unknowns the penetrations
        are ``p_n - W_n dx`` and the slips ``p_t + W_t dx``. Find the contact set (q >= 0,
        penetration <= tol, one of them zero) and, among the nodes in contact, the sticking ones
        (slip 0 along every tangent, ``|s| <= mu_s q``) and the slipping ones (``s = -mu q
        sigma``, sigma the unit direction of the slip in the tangent space: +-1 with one
        tangent): an active-set loop, every violation swapped at once, each set one dense solve,
        until no set changes (at most ``10 m + 10`` sets; a set that comes back ends it with the
        last solution, the Newton iteration going on from there). A tangent along which no
        traction moves the node (a symmetry plane through the contact, :data:`HELD`) carries no
        tangential traction, and a node held along one tangent slides along the other only;
        nor has a frictionless pair's node a tangential unknown.

        Where a slipping node has two free tangents (3D), sigma turns with the solution: as in
        the small-kinematics variant
        (:meth:`~vfem.contact.formulations.friction.SmallFriction._correct_frictional`), its
        traction is ``-mu q sigma + s_perp e``, e across sigma, and its row asks its slip across
        sigma to vanish, linearised in the turn of sigma: ``e . slip + (sigma . slip) / |s|
        s_perp = 0`` (a semismooth Newton step on the disk); sigma is then read from the new
        traction and the solve repeated, with the sets swapped as before, until no set changes
        and no slip crosses its sigma by more than the tolerance. (Taking the predicted slip's
        direction as the next sigma, a fixed point, diverges at a node that slips little: its
        own traction turns its slip more than the slip turns it.) A set that comes back is one
        of the same contact and slipping nodes, and with one tangent of the same slip directions
        (one of two; with two, sigma turns continuously).
        """
        m = len(q0)
        sizes = [len(s_) for s_ in sets]
        nodes = sum(sizes)
        ntan = m // nodes - 1 if nodes else 1  # unknowns per node: the normal and the tangents
        pair_of = np.concatenate([np.full(n, k) for k, n in enumerate(sizes)]
                                 or [np.zeros(0, int)])
        starts = np.cumsum([0] + [(1 + ntan) * n for n in sizes])[:-1]
        nrm = np.concatenate([starts[k] + np.arange(n) for k, n in enumerate(sizes)]
                             or [np.zeros(0, int)]).astype(int)
        offset = np.repeat(sizes, sizes).astype(int)
        tng = nrm[:, None] + offset[:, None] * (1 + np.arange(ntan))  # (nodes, ntan)
        mu, mu_static, mu_now, acts = self._coefficients(state, sets)
        q, S, P = q0[nrm], q0[tng], p[tng]
        diagonal = np.abs(np.diag(W))
        held = diagonal[tng] <= HELD * diagonal.max(initial=0.0)
        free = ~held & acts[:, None]  # the tangents friction acts along
        rough = free.any(axis=1)
        both = free.sum(axis=1) > 1  # a slipping node's sigma may turn

        def unit(v):
            v = np.where(free, v, 0.0)
            size = magnitudes(v)
            return np.divide(v, size[:, None], out=np.zeros_like(v), where=size[:, None] > 0)

        contact = (q > 0) | (p[nrm] > tol)
        size = magnitudes(np.where(free, S, 0.0))
        slipping = contact & (q > 0) & reaches_cone(size, q, mu_now) & (size > 0) & rough
        sigma = np.where((size > 0)[:, None], unit(-S), unit(P))
        # a node that comes into contact having moved along the other surface since the last
        # converged step slips the way it moved, until its traction says it sticks
        entering = contact & (q <= 0) & (magnitudes(np.where(free, P, 0.0)) > tol) & rough
        slipping |= entering
        sigma[entering] = unit(P)[entering]
        seen: set[bytes] = set()
        x = q0.copy()
        slip = np.where(free, P, 0.0)  # the slip predicted at x
        for _ in range(10 * m + 10):
            stick = contact & ~slipping & rough
            slide = contact & slipping
            # the nodes whose sigma turns: slipping along two free tangents, with a traction and
            # a slip along sigma to turn it by (and a dynamic coefficient: with mu = 0 its
            # traction is zero, and the compliance below would divide by it)
            q_now = x[nrm]
            turning = (slide & both & (q_now > 0) & (mu > 0)
                       & (np.einsum("ij,ij->i", sigma, slip) > 0))
            turn = np.flatnonzero(turning)
            across_dir = (np.column_stack([-sigma[turn, 1], sigma[turn, 0]]) if len(turn)
                          else np.zeros((0, ntan)))
            cols = np.concatenate([nrm[contact]] + [tng[stick & free[:, j], j]
                                                    for j in range(ntan)])
            n_normal = int(contact.sum())
            # rows: the normal and sticking ones, then each turning node's slip across sigma
            rows_W = np.vstack([W[cols], np.einsum("ij,ijm->im", across_dir, W[tng[turn]])])
            target = rows_W @ q0 + np.concatenate([
                p[cols[:n_normal]], -p[cols[n_normal:]],
                -np.einsum("ij,ij->i", across_dir, P[turn])])
            position = np.full(m, -1)
            position[cols] = np.arange(len(cols))
            ties = -mu[:, None] * sigma  # s = ties q (+ s_perp e) on a slipping node
            A = rows_W[:, cols]
            for j in range(ntan):
                A[:, position[nrm[slide]]] += rows_W[:, tng[slide, j]] * ties[slide, j]
            if len(turn):
                A = np.hstack([A, np.einsum("ij,mij->mi", across_dir, rows_W[:, tng[turn]])])
                compliance = np.einsum("ij,ij->i", sigma[turn], slip[turn]) \
                    / (mu[turn] * q_now[turn])
                A[len(cols) + np.arange(len(turn)), len(cols) + np.arange(len(turn))] += \
                    compliance
            x = np.zeros(m)
            if len(target):
                try:
                    y = np.linalg.solve(A, target)
                except np.linalg.LinAlgError:  # dependent rows: the least-squares solution
                    y = np.linalg.lstsq(A, target, rcond=None)[0]
                x[cols] = y[:len(cols)]
                for j in range(ntan):
                    x[tng[slide, j]] = ties[slide, j] * x[nrm[slide]]
                if len(turn):
                    x[tng[turn]] += across_dir * y[len(cols):, None]
            dx = x - q0
            pen = p[nrm] - W[nrm] @ dx
            slip = np.where(free, P + (W[tng.ravel()] @ dx).reshape(-1, ntan), 0.0)
            qn, sn = x[nrm], x[tng]
            # sigma from the new traction (where it turned), and the slip's parts along it and
            # across it
            new_sigma = sigma.copy()
            new_sigma[turn] = unit(-sn)[turn]
            along = np.einsum("ij,ij->i", new_sigma, slip)
            across = magnitudes(slip - along[:, None] * new_sigma)
            leave = contact & (qn < 0)
            join = ~contact & (pen > tol)
            over = stick & beyond_cone(magnitudes(np.where(free, sn, 0.0)), qn, mu_static)
            back = slide & (along < -tol)
            crossing = slide & both & (across > tol)
            sigma = new_sigma
            if not (leave.any() or join.any() or over.any() or back.any()):
                if not crossing.any():
                    break
                # not turning yet (no traction or no slip along sigma): the slip's direction
                late = crossing & ~turning
                sigma[late] = unit(slip)[late]
                continue
            # (with one tangent a node's slip direction is one of two, part of the set; with
            # two it turns continuously, and the set is the contact and slipping nodes alone)
            key = np.concatenate([contact, slipping]
                                 + ([sigma[:, 0] > 0] if ntan == 1 else [])).tobytes()
            if key in seen and not crossing.any():
                log.debug("frictional linearised contact: a set came back")
                break
            seen.add(key)
            contact = (contact & ~leave) | join
            moved = join & (magnitudes(slip) > tol) & rough
            sigma[over] = unit(-sn)[over]
            sigma[moved] = unit(slip)[moved]
            slipping = (slipping | over | moved) & ~back & contact
        x[nrm] = np.where(x[nrm] > 0, x[nrm], 0.0)
        for j in range(ntan):
            x[tng[:, j]] = np.where((x[nrm] > 0) & free[:, j], x[tng[:, j]], 0.0)
        # which nodes slide (the static coefficient holds the others); a frictionless pair's
        # nodes in contact are free, as under small kinematics: counted as sticking, their
        # slip was an error no traction could correct, and a frictionless pair in a frictional
        # model never converged once its nodes moved along the other surface
        for k, s_ in enumerate(sets):
            self.sliding(state, k)[:] = False
            self.sliding(state, k)[s_] = ((slipping | ~acts) & contact)[pair_of == k]
        return x, 0.0

#: the paired variant with friction under large displacements: the frictionless formulation
#: composed with the friction part (the laws it takes: :class:`~vfem.contact.laws.FrictionLaw`)
FrictionalLargeContact = Composed(
    LargeDeformationContact, LargeFriction,
    dataclasses.replace(LargeDeformationContact.capabilities, name="paired, frictional",
                        friction=("coefficients", "slip")))

__all__ = ["FrictionalLargeContact", "LargeFriction"]
