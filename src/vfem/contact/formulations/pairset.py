"""The paired variant's parts shared by small and large kinematics (:class:`PairSet`, thesis
§4.3): the contact pairs (which side carries compatibility, their nodes, normals, gaps and
transfer), the traction values that are its unknowns, the forces they make, its errors and its
output fields. :class:`~vfem.contact.formulations.paired.PairedContact` (small kinematics) and
:class:`~vfem.contact.formulations.large.LargeDeformationContact` build on it.
"""

from __future__ import annotations

import logging

import numpy as np

from ...errors import RindViolation
from ..geometry import (
    ContactPair,
    ContactPairs,
    ContactSurface,
    zone_mask,
)
from ..state import (
    ContactState,
    FrictionState,
    Pairing,
    SolveResult,
    TractionState,
)
from .group import SurfaceGroup
from .pairmaking import compliance_density, count_nodes, make_pair

log = logging.getLogger(__name__)


class PairSet:
    """The paired variant's parts shared by small and large displacements: the contact pairs
    (which side carries compatibility, their nodes, normals, gaps and transfer), the traction
    values that are its unknowns, the forces they make, its errors and its output fields.

    :class:`~vfem.contact.formulations.paired.PairedContact` (small displacements) and
    :class:`~vfem.contact.formulations.large.LargeDeformationContact` are built on it."""

    def __init__(self, surfaces: list[ContactSurface], pairs: ContactPairs, settings,
                 backend: str | None = None, sides: dict | None = None, executor=None,
                 friction: type | None = None):
        #: the bodies' surfaces, the platen and the full-mesh fields (its data by name too)
        self.group = SurfaceGroup(surfaces, pairs, settings, backend, executor=executor)
        self.group.adopt(self)
        #: per pair (i, j), i < j, the body that carries its compatibility instead of the one
        #: the rules choose (:func:`~vfem.contact.formulations.pairmaking.make_pair`): the
        #: solver's switch after a step that the rules' side could not hold
        #: (:meth:`vfem.solver.Analysis._switch_side`)
        self.given_sides = dict(sides or {})
        sided = [p for p in pairs.sorted()
                 if len(surfaces[p.a.body].facets) and len(surfaces[p.b.body].facets)]
        keys = [p.bodies for p in sided]
        # each body's compliance densities, of each of its sides against the other side, on
        # the rank that owns it (its flexibility), then each pair's geometry on a rank of its
        # own, all at once (vfem.parallel; in serial in order, as before)
        ranks = self.executor
        density = ranks.map(range(len(surfaces)), lambda b: {
            (k, n): compliance_density(self, own, other)
            for k, p in enumerate(sided) for n, (own, other) in enumerate(((p.a, p.b),
                                                                           (p.b, p.a)))
            if own.body == b})
        made = ranks.map(range(len(keys)), lambda k: make_pair(
            self, sided[k], density[keys[k][0]][k, 0], density[keys[k][1]][k, 1]),
            owners=[k % ranks.size for k in range(len(keys))])
        # the compatibility sides' pairs first, then the held nodes (so a pair's index does
        # not depend on whether the other surface is enforced too)
        self.contact_pairs = ([made[k][0] for k in range(len(keys)) if made[k][0] is not None]
                              + [h for k in range(len(keys)) for h in made[k][1]])
        #: per pair (i, j) of bodies that face each other, the body that carries its
        #: compatibility and how many nodes it holds (its own and the other side's held)
        self.carriers = {keys[k]: (made[k][2], count_nodes(made[k][0], made[k][1]))
                         for k in range(len(keys)) if made[k][2] >= 0}
        # penetration p = -(gap0 + n.(u_fine - u_coarse)): its change per unit platen motion
        v = self.platen_motion
        for pair in self.contact_pairs:
            pair.platen_rate = np.einsum(
                "id,id->i", pair.reading(0, pair.normal),
                pair.interp @ v[pair.coarse] - pair.fine_read(v[pair.fine]))
        #: the friction part (built on the pairs: its laws, tangents and history), or None
        #: without friction (:mod:`vfem.contact.formulations.friction_history`)
        self.friction = friction(self, settings) if friction is not None else None

    @property
    def state_type(self) -> type[ContactState]:
        """The state's type: the pairs' traction values, and with friction its history."""
        return self.friction.state_type if self.friction is not None else TractionState

    def new_state(self, load_factor: float = 0.0, platen_displacement: float = 0.0
                  ) -> ContactState:
        """No contact force on any body (a :attr:`state_type`; with friction, the part's
        start, ``friction.start``)."""
        state = self.group.new_state(self.state_type, load_factor, platen_displacement)
        if self.friction is not None:
            self.friction.start(state)
        return state

    def positions(self, state: ContactState) -> list[np.ndarray]:
        """Current coordinates of every body's condensed nodes: the bodies' linear response
        (:meth:`~vfem.contact.formulations.group.SurfaceGroup.positions`; large kinematics
        reads the bodies' mechanics instead)."""
        return self.group.positions(state)

    def fields(self, state: ContactState, result: SolveResult) -> dict:
        """Full-mesh results of a converged state, per body
        (:meth:`~vfem.contact.formulations.group.SurfaceGroup.fields`), and the friction's."""
        out = self.group.fields(state, result)
        if self.friction is not None:
            self.friction.add_fields(out, state)
        return out

    # -- geometry of the pairs (once) -------------------------------------------------------------

    #: nodes that keep every candidate node of the compatibility side (large kinematics, where
    #: which nodes overlap the other surface changes as the bodies slide)
    keep_all_nodes = False

    #: (unknowns,) the held nodes that found no contact set with the others in the last
    #: correction
    #: (:meth:`~vfem.contact.formulations.paired.PairedContact._correct_complementarity`), or None
    _refused = None
    _stale_mask = None
    _stale_changes = 0
    #: :meth:`~vfem.contact.formulations.paired.PairedContact._reserve`, once found
    _reserved = None
    #: (unknowns,) bool: the held nodes that
    #: :meth:`~vfem.contact.formulations.paired.PairedContact.enforce` holds however their
    #: guard stands
    _forced = None

    #: whether the equilibrium side's nodes are held too, where they would penetrate the
    #: compatibility side (issue 37, :func:`~vfem.contact.geometry.held.held_nodes`): the
    #: small-displacement frictionless variant
    both_surfaces = False

    # -- state of the pairs -----------------------------------------------------------------------

    def tractions(self, state: TractionState | FrictionState, k: int) -> np.ndarray:
        """The normal traction values of pair k at its compatibility-side nodes (the unknowns)."""
        pair = self.contact_pairs[k]
        if k not in state.tractions:
            state.tractions[k] = np.zeros(len(pair.nodes))
        return state.tractions[k]

    def traction_values(self, state: ContactState) -> list[np.ndarray]:
        """Every pair's traction values (:meth:`tractions`), in order."""
        return [self.tractions(state, k) for k in range(len(self.contact_pairs))]

    def assemble_forces(self, state: ContactState) -> None:
        """Every body's nodal forces from the pairs' tractions (equilibrium in weak form; with
        friction, the part's normal and tangential ones)."""
        if self.friction is not None:
            self.friction.assemble_forces(state)
            return
        for F in state.forces:
            F[:] = 0.0
        for k, pair in enumerate(self.contact_pairs):
            q = self.tractions(state, k)[:, None] * pair.normal  # traction vector at the fine nodes
            state.forces[pair.fine] += pair.fine_columns() @ q
            state.forces[pair.coarse] -= pair.coarse_columns() @ q

    def compatibility_errors(self, pens: list[np.ndarray], traction_values: list[np.ndarray]
                             ) -> tuple[list[np.ndarray], float, int, int]:
        """Per pair the compatibility error of each node (|penetration| where the node touches
        or carries force, else 0); the largest; the nodes carrying force; those in tension."""
        tol = self.penetration_tolerance
        excused = self._excused(traction_values)
        errs = [np.where((q > 0) | ((p > tol) & ~e), np.abs(p), 0.0)
                for p, q, e in zip(pens, traction_values, excused)]
        largest = max((float(e.max()) for e in errs if len(e)), default=0.0)
        return (errs, largest, sum(int((q > 0).sum()) for q in traction_values),
                sum(int((q < 0).sum()) for q in traction_values))

    def directions(self, k: int) -> list[np.ndarray]:
        """The directions of pair k's traction unknowns at its nodes, each (nodes, dim): the
        normal, then the friction part's tangents (none without friction)."""
        tangential = self.friction.tangent_basis(k) if self.friction is not None else []
        return [self.contact_pairs[k].normal, *tangential]

    def enforce(self, where: dict | None) -> bool:
        """Invariant (b) found the node ``where`` (``{"body", "node", "into"}``: a point
        number of body ``body``, inside body ``into``) deeper inside than it allows: if it is
        a held node that its guard excused (every compatibility node of the facet under it
        touching), hold it wherever it would penetrate for the rest of the step, and say so
        (the step is then solved again); False where it is no such node, or already so held.

        **Why**: the guard leaves a node of the equilibrium side between compatibility nodes
        that touch to the compatibility side's faceting (holding it too makes two conditions
        of nearly one, :meth:`_excused`); where it lies deeper than faceting and linear
        theory's second order explain (invariant (b)'s allowance), it is a contact missed.
        Measured on a stiff punch landing on its fillet on a finer block (random model
        2d-132): a fillet node 3.5e-7 inside beyond its allowance stopped it after six cuts;
        held, it converges (``tests/test_enforce.py``).

        ``where`` None: hold none of them any more (the solver, as each step begins)."""
        if where is None:
            if self._forced is not None and self._forced.any():
                self._forced = None
                self._reserved = None
            return False
        names = [s.body.name for s in self.surfaces]
        if where.get("body") not in names or where.get("into") not in names:
            return False
        b, into = names.index(where["body"]), names.index(where["into"])
        s = self.surfaces[b]
        local = np.flatnonzero(s.nodes[: s.nc] == where.get("node"))
        if not local.size:
            return False
        reserve = self._held_unknowns()
        if self._forced is None:
            self._forced = np.zeros(len(reserve), dtype=bool)
        for pair, pos in zip(self.contact_pairs, self._unknown_offsets()):
            if pair.point and pair.fine == b and pair.coarse == into:
                hit = np.flatnonzero(pair.nodes == local[0])
                if hit.size and not self._forced[pos + hit[0]]:
                    self._forced[pos + hit[0]] = True
                    self._reserved = None  # the guards again, without it
                    log.info("node %s of body %r held against body %r: inside it beyond what "
                             "invariant (b) allows; the step again", where.get("node"),
                             where["body"], where["into"])
                    return True
        return False

    def _unknown_offsets(self) -> np.ndarray:
        """(pairs + 1,) where each pair's unknowns start among all of them (its nodes times
        its directions)."""
        return np.cumsum([0] + [len(p.nodes) * len(self.directions(k))
                                for k, p in enumerate(self.contact_pairs)])

    def _held_unknowns(self) -> np.ndarray:
        """(unknowns,) bool: the unknowns of the held nodes (``point`` pairs)."""
        return np.concatenate([np.full(len(pair.nodes) * len(self.directions(k)), pair.point)
                               for k, pair in enumerate(self.contact_pairs)]
                              or [np.zeros(0, dtype=bool)])

    def _forced_of(self, start: int, n: int) -> np.ndarray:
        """(n,) bool: which of the unknowns ``start:start + n``
        :meth:`~vfem.contact.formulations.paired.PairedContact.enforce` holds."""
        if self._forced is None:
            return np.zeros(n, dtype=bool)
        return self._forced[start:start + n]

    def _excused(self, traction_values: list[np.ndarray]) -> list[np.ndarray]:
        """Per pair, its nodes that may lie inside the other surface: held nodes (``point``
        pairs) not held whose virtual node lies on a facet all of whose nodes are the
        compatibility side's pair nodes carrying force — between them a node of the other
        surface protrudes by the faceting of the compatibility side, and holding it too would
        make two conditions of nearly one (measured on a press fit with facets at other
        angles, when every such node was left out: the held shaft nodes took the load from
        the hub's and its mean pressure moved 1.4 %) — unless
        :meth:`~vfem.contact.formulations.paired.PairedContact.enforce` holds it, invariant (b)
        having found it deeper than faceting explains; and every held node refused in the last
        correction: stale (slid off its facet,
        :meth:`~vfem.contact.formulations.paired.PairedContact._stale`) or finding no contact set
        with the others
        (:meth:`~vfem.contact.formulations.paired.PairedContact._correct_complementarity`). Held,
        then: the equilibrium side's nodes where the compatibility side's around them do not
        all touch (a stiff corner or edge, a convex body's first touch between the other's
        nodes), and the compatibility side's past the other patch's ends."""
        out = []
        pos = 0
        for pair, q in zip(self.contact_pairs, traction_values):
            e = np.zeros(len(q), dtype=bool)
            if self._refused is not None:
                e = self._refused[pos:pos + len(q)].copy()
            pos += len(q)
            guarded = self._guard_touching(pair, traction_values)
            if guarded is not None and len(q):
                free = ~self._forced_of(pos - len(q), len(q))
                e |= (q[: len(pair.nodes)] <= 0) & guarded & free
            out.append(e)
        return out

    def _guard_touching(self, pair: ContactPair, traction_values: list[np.ndarray]
                        ) -> np.ndarray | None:
        """(m,) for a held pair (``point``), whether every node of each held node's guard
        (the compatibility nodes of the facet under it) carries force; None for a pair that
        is not held or has no compatibility pair."""
        forward = self._guarding_pair(pair) if pair.point and pair.guard is not None else None
        if forward is None:
            return None
        touching = np.zeros(self.surfaces[pair.coarse].nc + 1, dtype=bool)
        touching[self.contact_pairs[forward].nodes] = traction_values[forward] > 0
        # (-1, beyond the other patch, reads the last entry: never touching)
        return touching[pair.guard].all(axis=1)

    def _guarding_pair(self, held: ContactPair) -> int | None:
        """The index of the compatibility pair of the same two bodies as the ``point`` pair
        ``held``, whose nodes guard its nodes; None if there is none."""
        return next((j for j, f in enumerate(self.contact_pairs) if not f.point
                     and f.fine == held.coarse and f.coarse == held.fine), None)

    def worst_node(self, errs: list[np.ndarray]) -> str:
        """Where the largest of ``errs`` (per pair, over its nodes) is, for messages:
        ' at node N of body B'."""
        worst = max(((float(e.max()), k) for k, e in enumerate(errs) if len(e)), default=None)
        if worst is None or worst[0] <= 0:
            return ""
        pair = self.contact_pairs[worst[1]]
        sf = self.surfaces[pair.fine]
        node = int(sf.nodes[pair.nodes[int(np.argmax(errs[worst[1]]))]])
        return f" at node {node} of body {sf.body.name!r}"

    def contact_sets(self, traction_values: list[np.ndarray]
                     ) -> list[tuple[str, np.ndarray, np.ndarray]]:
        """Per pair, the compatibility side's (body name, node numbers, carrying-force mask):
        what :class:`~vfem.contact.state.CycleWatch` compares between
        iterations."""
        out = []
        for pair, q in zip(self.contact_pairs, traction_values):
            sf = self.surfaces[pair.fine]
            out.append((sf.body.name, sf.nodes[pair.nodes], q > 0))
        return out

    def _check_rind(self, pens: list[np.ndarray]) -> None:
        for pair, p in zip(self.contact_pairs, pens):
            deep = p > pair.rind_depth
            if deep.any():
                k = int(np.flatnonzero(deep)[0])
                sf, sc = self.surfaces[pair.fine], self.surfaces[pair.coarse]
                exc = RindViolation(
                    f"node {int(sf.nodes[pair.nodes[k]])} of body {sf.body.name!r} went "
                    f"{p[k]:.3g} deep into body {sc.body.name!r}, past its outer layer of "
                    "elements: the step is too large")
                exc.bodies = (sf.body.name, sc.body.name)  # (the solver's side switch)
                raise exc

    # -- what the results need --------------------------------------------------------------------

    def pairings(self, state: ContactState, pens: list[np.ndarray] | None = None
                 ) -> list[Pairing]:
        """Per body: normal force, penetration and contact status for the output fields."""
        pens = self.penetrations(state) if pens is None else pens
        out = []
        for i, s in enumerate(self.surfaces):
            nc = s.nc
            force = np.zeros(nc)
            pen = np.zeros(nc)
            other = np.full(nc, -1)
            normal = np.zeros((nc, s.dim))
            touching = np.zeros(nc, dtype=bool)
            compat = np.zeros(nc, dtype=bool)  # nodes where this body carries compatibility
            for k, pair in enumerate(self.contact_pairs):
                if pair.point and pair.fine == i:
                    # held nodes: the force they add is in the body's total (the branches
                    # here), and they touch where held; their penetration field stays the
                    # compatibility side's reading (a held node's linearised gap past the
                    # other patch's end is read along the direction to it)
                    touching[pair.nodes] |= self.tractions(state, k) > 0
                    continue
                if pair.point:
                    continue  # the compatibility side: its total force is read below
                if pair.fine == i:
                    # in contact: where the traction is positive (a free node next to the
                    # contact still takes its share of N q as nodal force)
                    f = np.einsum("ij,ij->i", state.forces[i][pair.nodes], pair.normal)
                    on = np.abs(f) > 0
                    force[pair.nodes[on]] = f[on]
                    touching[pair.nodes] = self.tractions(state, k) > 0
                    compat[pair.nodes] = True
                    pen[pair.nodes] = pens[k]
                    other[pair.nodes[on]] = pair.coarse
                    normal[pair.nodes] = pair.normal
                if pair.coarse == i:  # (and both, for a pair of two sides of one body)
                    nn = s.node_normals()
                    f = -np.einsum("ij,ij->i", state.forces[i], nn)
                    on = np.abs(state.forces[i]).sum(axis=1) > 0
                    if pair.zones[1] is not None:  # the equilibrium side's nodes alone
                        on &= zone_mask(s, pair.zones[1])
                    force[on] = f[on]
                    other[on] = pair.fine
                    normal[on] = -nn[on]
            zeros = np.zeros(nc)
            out.append(Pairing(other=other, facet=np.zeros(nc, int), t=zeros, normal=normal,
                               penetration=pen, embedded=pen > 0, stiffness=zeros,
                               virtual_stiffness=zeros, force=force, virtual_force=force.copy(),
                               participating=np.where(compat, touching, force > 0) | (
                                   touching & ~compat),
                               pressure=np.zeros(nc)))
        x = self.pairing_positions(state)
        for k, pair in enumerate(self.contact_pairs):
            if pair.point:  # point forces: no traction field (their force is in F)
                continue
            q = self.tractions(state, k)
            out[pair.fine].pressure[pair.nodes] += q
            out[pair.coarse].pressure += self._traction_on_other_side(k, q, x)
        return out

    def pairing_positions(self, state: ContactState) -> list[np.ndarray]:
        """The tracked positions the pairs are built on: undeformed (linear kinematics)."""
        return [s.X for s in self.surfaces]

    def _traction_on_other_side(self, k: int, q: np.ndarray, x: list[np.ndarray]
                                ) -> np.ndarray:
        """(nc,) pair k's traction read at the equilibrium side's nodes: the compatibility
        side's traction field ``q`` (its nodal values, interpolated as the forces integrate it)
        at each node's closest point on the compatibility patch, zero beyond its ends.

        This is the traction the forces ``F = -T q`` integrate (the same field, eq. 4.4.11),
        read pointwise: a nodal force over a tributary length would instead average it with
        the neighbours' (and halve the tributary on a symmetry plane, where the reading then
        dips by a few percent under a peak).
        """
        pair = self.contact_pairs[k]
        sf, sc = self.surfaces[pair.fine], self.surfaces[pair.coarse]
        out = np.zeros(sc.nc)
        if pair.patches is None or not np.any(q):
            return out
        fpatch, cpatch = pair.patches
        xf, xc = x[pair.fine], x[pair.coarse]
        nodes = np.unique(sc.facets[cpatch])
        seg, t, _, _, tf = sf.closest(xc[nodes], xf, fpatch,
                                      sc.node_normals(xc, cpatch)[nodes])
        qf = np.zeros(sf.nc)
        qf[pair.nodes] = q
        p = sf.traction_interpolation(seg, t) @ qf
        p[sf.beyond(seg, tf, sf.patch_boundary(fpatch))] = 0.0
        out[nodes] = p
        return out
