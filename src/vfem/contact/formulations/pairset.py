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
    EDGE_RATIO,
    ContactPair,
    ContactSurface,
    Overlap,
    approach_gaps,
    common_normal,
    facing,
    held_edges,
    held_force_directions,
    held_nodes,
    overlap,
    read_facets,
)
from ..state import (
    ContactState,
    Pairing,
    SolveResult,
    TractionState,
)
from .group import SurfaceGroup

log = logging.getLogger(__name__)


#: the most nodes whose flexibility gives a surface's median compliance
#: (:meth:`PairSet._compliance_density`): one back-substitution each on the matrix-free route.
#: Above every model measured before issue 22 (the 981k-dof sphere reads 3,061), so none of
#: their answers moved.
SIDE_SAMPLE = 4096


#: a body forced onto the compatibility side (``contact.compatibility_side``) against the rules'
#: choice is warned about when its facets over the other surface are this many times larger
#: (median sizes): it resolves the traction on its own facets (the tilted cube of issue 37, its
#: facets twice the 24 block's and three times the 36 block's: 1.5-1.8 times a rigid reference,
#: ``benchmarks/tilted_cube.py``)
FORCED_COARSER = 1.5


class PairSet:
    """The paired variant's parts shared by small and large displacements: the contact pairs
    (which side carries compatibility, their nodes, normals, gaps and transfer), the traction
    values that are its unknowns, the forces they make, its errors and its output fields.

    :class:`~vfem.contact.formulations.paired.PairedContact` (small displacements) and
    :class:`~vfem.contact.formulations.large.LargeDeformationContact` are built on it."""

    def __init__(self, surfaces: list[ContactSurface], pairs: set[frozenset[int]], settings,
                 backend: str | None = None, sides: dict | None = None, executor=None):
        #: the bodies' surfaces, the platen and the full-mesh fields (its data by name too)
        self.group = SurfaceGroup(surfaces, pairs, settings, backend, executor=executor)
        self.group.adopt(self)
        #: per pair (i, j), i < j, the body that carries its compatibility instead of the one
        #: the rules choose (:meth:`_make_pair`): the solver's switch after a step that the
        #: rules' side could not hold (:meth:`vfem.solver.Analysis._switch_side`)
        self.given_sides = dict(sides or {})
        keys = [tuple(sorted(pp)) for pp in sorted(pairs, key=sorted)]
        keys = [(i, j) for i, j in keys if len(surfaces[i].facets) and len(surfaces[j].facets)]
        # each body's compliance densities against the bodies it may touch on the rank that
        # owns it (its flexibility), then each pair's geometry on a rank of its own, all at
        # once (vfem.parallel; in serial in order, as before)
        ranks = self.executor
        partners = {b: [j if i == b else i for i, j in keys if b in (i, j)]
                    for b in range(len(surfaces))}
        density = ranks.map(range(len(surfaces)), lambda b: {
            j: self._compliance_density(b, j) for j in partners[b]})
        made = ranks.map(range(len(keys)), lambda k: self._make_pair(
            *keys[k], density[keys[k][0]][keys[k][1]], density[keys[k][1]][keys[k][0]]),
            owners=[k % ranks.size for k in range(len(keys))])
        # the compatibility sides' pairs first, then the held nodes (so a pair's index does
        # not depend on whether the other surface is enforced too)
        self.contact_pairs = ([made[k][0] for k in range(len(keys)) if made[k][0] is not None]
                              + [h for k in range(len(keys)) for h in made[k][1]])
        #: per pair (i, j) of bodies that face each other, the body that carries its
        #: compatibility and how many nodes it holds (its own and the other side's held)
        self.carriers = {keys[k]: (made[k][2], self._count(made[k][0], made[k][1]))
                         for k in range(len(keys)) if made[k][2] >= 0}
        # penetration p = -(gap0 + n.(u_fine - u_coarse)): its change per unit platen motion
        v = self.platen_motion
        for pair in self.contact_pairs:
            pair.platen_rate = np.einsum(
                "id,id->i", pair.reading(0, pair.normal),
                pair.interp @ v[pair.coarse] - pair.fine_read(v[pair.fine]))

    #: the unknowns are the pairs' traction values
    state_type = TractionState

    def new_state(self, load_factor: float = 0.0, platen_displacement: float = 0.0
                  ) -> ContactState:
        """No contact force on any body (a :attr:`state_type`)."""
        return self.group.new_state(self.state_type, load_factor, platen_displacement)

    def positions(self, state: ContactState) -> list[np.ndarray]:
        """Current coordinates of every body's condensed nodes: the bodies' linear response
        (:meth:`~vfem.contact.formulations.group.SurfaceGroup.positions`; large kinematics
        reads the bodies' mechanics instead)."""
        return self.group.positions(state)

    def fields(self, state: ContactState, result: SolveResult) -> dict:
        """Full-mesh results of a converged state, per body
        (:meth:`~vfem.contact.formulations.group.SurfaceGroup.fields`)."""
        return self.group.fields(state, result)

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

    def _make_pair(self, i: int, j: int, density_i: tuple[float, bool],
                   density_j: tuple[float, bool]
                   ) -> tuple[ContactPair | None, list[ContactPair]]:
        """The pair of bodies i < j (both with candidate facets), from their compliance
        densities against each other (:meth:`_compliance_density`), or None where they do not
        face each other; and with :attr:`both_surfaces` the nodes held by point forces (pairs
        with ``point`` set, :func:`~vfem.contact.geometry.held.held_nodes`): the equilibrium
        side's, and the compatibility side's beyond the other patch's ends.

        Where the side the rules choose leaves no node paired at all (neither its own nodes
        over the other surface nor the other's held against it: a tilted box's corner over a
        block's corner, the two meeting edge on edge) and the other side would pair some, the
        other side carries compatibility. **Why**: a platen pushing such a box had nothing to
        hold it and the analysis stopped at the first step (random model 3d-17); with the
        block on the compatibility side the box's corner nodes are held against it and the
        model solves.

        A pair in :attr:`given_sides` is carried by the body given there. Returns (pair, held,
        the body carrying compatibility, -1 where neither faces the other)."""
        given = self.given_sides.get((i, j))
        if given is not None:
            return self._make_pair_sided(i, j, density_i, density_j, carrier=given)
        pair, held, fine = self._make_pair_sided(i, j, density_i, density_j)
        if self.settings.compatibility_side is None and not self._count(pair, held):
            other = self._make_pair_sided(i, j, density_i, density_j, flip=True)
            if self._count(*other[:2]):
                log.info("contact pair: no node paired with the first side on the "
                         "compatibility side; the other side carries it")
                return other
        return pair, held, fine

    @staticmethod
    def _count(pair: ContactPair | None, held: list[ContactPair]) -> int:
        return (len(pair.nodes) if pair is not None else 0) + sum(len(h.nodes) for h in held)

    def _make_pair_sided(self, i: int, j: int, density_i: tuple[float, bool],
                         density_j: tuple[float, bool], flip: bool = False,
                         carrier: int | None = None
                         ) -> tuple[ContactPair | None, list[ContactPair], int]:
        """:meth:`_make_pair` with the compatibility side the rules choose, or (``flip``) the
        other, or (``carrier``) the one given."""
        si, sj = self.surfaces[i], self.surfaces[j]
        (ci, ei), (cj, ej) = density_i, density_j
        if ci == 0.0 and cj == 0.0:
            return None, [], -1  # no facet of either faces the other
        if ei != ej and (ci if ei else cj) * EDGE_RATIO >= max(ci, cj):
            # the contact zone ends at an edge of one surface (a corner over the other): that
            # surface carries compatibility, unless it is much stiffer
            fine, coarse = (i, j) if ei else (j, i)
        elif abs(ci - cj) > 1e-9 * max(ci, cj):
            fine, coarse = (i, j) if ci > cj else (j, i)
        else:  # equal: a rule that does not depend on the order of the bodies
            fine, coarse = (i, j) if si.body.name < sj.body.name else (j, i)
        chosen = fine
        if self.settings.compatibility_side is not None:  # forced (for testing)
            names = (si.body.name, sj.body.name)
            if self.settings.compatibility_side in names:
                fine, coarse = (i, j) if si.body.name == self.settings.compatibility_side \
                    else (j, i)
        if flip:
            fine, coarse = coarse, fine
        if carrier is not None:  # given (the solver's switch)
            fine, coarse = (i, j) if carrier == i else (j, i)
        sf, sc = self.surfaces[fine], self.surfaces[coarse]
        nodes = (self._facing_nodes(fine, coarse) if self.keep_all_nodes else None)
        geo = overlap(sf, sc, nodes=nodes)
        if geo is None:
            return None, [], fine
        c_fine, c_coarse = (ci, cj) if fine == i else (cj, ci)
        if fine != chosen and (carrier is not None or not flip):
            ratio = float(np.median(sf.sizes[geo.fpatch]) / np.median(sc.sizes[geo.cpatch]))
            if ratio >= FORCED_COARSER:
                log.warning(
                    "contact pair: %r carries compatibility (%s) with facets %.3g times the "
                    "size of %r's: its traction is resolved on its own facets, and where the "
                    "contact zone is narrower than they are the force can be far off (a tilted "
                    "cube's edge: 1.5-1.8 times a rigid reference, docs/benchmarks.md)",
                    sf.body.name, "switched to it: the other side could not hold the contact"
                    if carrier is not None else "contact.compatibility_side", ratio,
                    sc.body.name)
        # the compatibility side's nodes beyond the other patch, and those over it whose
        # facets carry none of its traction (a stiff box's corner over a block's corner, its
        # facet over the block's top by a quarter: it went 45 % of the push into the block,
        # random model 3d-17): held as points, as the equilibrium side's nodes are
        loose = geo.beyond.copy()
        if not self.keep_all_nodes:
            loose |= ~geo.carries
        past = geo.nodes[loose]
        if not self.keep_all_nodes:  # only the nodes over the other surface take part
            keep = geo.carries & ~geo.beyond
            geo = geo.subset(keep)
            common_normal(sf, sc, geo, c_fine, c_coarse)
        log.info("contact pair: %s (compatibility, %d nodes) against %s (equilibrium)",
                 sf.body.name, len(geo.nodes), sc.body.name)
        # (none of the compatibility side's nodes over the other surface — a coarse soft
        # surface passing over a stiff block's corner — leaves the held nodes: that corner
        # held against the soft surface is then the whole contact)
        cfg = self.settings
        both = self.both_surfaces and (
            cfg.relaxation == 1.0 and (cfg.relaxed_iterations == 0
                                       or cfg.first_relaxation == 1.0)
            and cfg.release_iterations == 1)
        gap = geo.gap
        # (the relaxed corrections too: one problem, whichever way it is solved)
        if self.both_surfaces and len(geo.nodes):
            gap = approach_gaps(sf, sc, geo, self._approach(fine, coarse, geo))
        pair = ContactPair(fine, coarse, geo.nodes, geo.normal, gap, geo.interp,
                           geo.transfer, geo.mass, geo.rind_depth, geo.carries,
                           (geo.fpatch, geo.cpatch)) if len(geo.nodes) else None
        if not both:
            # (the thesis's relaxed corrections, §5.6, act one correction of the bodies at a
            # time on the compatibility side's nodes alone)
            return pair, [], fine
        held = []
        for own, other, which in (
                (coarse, fine, None),  # the equilibrium side's nodes
                (fine, coarse, past)):  # the compatibility side's beyond the other patch
            if which is not None and not len(which):
                continue
            patches = (geo.cpatch, geo.fpatch) if own == coarse else (geo.fpatch, geo.cpatch)
            c_own, c_other = (c_coarse, c_fine) if own == coarse else (c_fine, c_coarse)
            # a stiffer surface's own features (its vertices, not the other side's faceting)
            # are held even between compatibility nodes in contact: the softer side must
            # take their shape (:func:`held_nodes`)
            made = held_nodes(self.surfaces[own], self.surfaces[other], *patches, which,
                              features=c_own < c_other,
                              approach=lambda g, o=own, t=other: self._approach(o, t, g))
            if made is None:
                continue
            h, guard, reach = made
            if own == fine:  # beyond the other patch: nothing of the compatibility side's
                guard = np.full_like(guard, -1)
            log.info("contact pair: %d nodes of %s held against %s", len(h.nodes),
                     self.surfaces[own].body.name, self.surfaces[other].body.name)
            force = held_force_directions(self.surfaces[own], patches[0], h, c_own, c_other)
            held.append(ContactPair(own, other, h.nodes, force, h.gap, h.interp,
                                    h.transfer, h.mass, h.rind_depth, h.carries,
                                    (h.fpatch, h.cpatch), point=True, guard=guard,
                                    gap_normal=h.normal, reach=reach))
        # and each side's edges where they cross the other side's facets (3D): a stiff box's
        # edge between its vertices, a soft block's rim under an overhanging punch
        for own, other, patches, feature in (
                (coarse, fine, (geo.cpatch, geo.fpatch), c_coarse < c_fine),
                (fine, coarse, (geo.fpatch, geo.cpatch), True)):
            edges = held_edges(
                self.surfaces[own], self.surfaces[other], *patches, feature=feature,
                approach=lambda *a, o=own, t=other: self._relative_motion(o, t, *a))
            if edges is None:
                continue
            at, nodes, normal, gap, interp, guard, reach, rind = edges
            log.info("contact pair: %d points of %s's edges held against %s", len(nodes),
                     self.surfaces[own].body.name, self.surfaces[other].body.name)
            held.append(ContactPair(own, other, nodes, normal, gap, interp, None, None, rind,
                                    np.ones(len(nodes), dtype=bool), patches,
                                    point=True, guard=guard, gap_normal=normal, reach=reach,
                                    at=at))
        return pair, held, fine

    def _approach(self, fine: int, coarse: int, geo: Overlap) -> np.ndarray:
        """(m, dim) how the pair's nodes move relative to their virtual nodes under the
        loads alone (small kinematics, at load factor 1): the loads' and prescribed
        displacements' motion, or where that is none, the platen's, in the sense that closes
        the gap (:func:`~vfem.contact.geometry.pairing.approach_gaps`)."""
        nc = self.surfaces[coarse].nc
        return self._relative_motion(fine, coarse, lambda f: f[geo.nodes],
                                     lambda f: geo.interp @ f[:nc], geo.normal)

    def _relative_motion(self, own: int, other: int, read, read_other,
                         normal: np.ndarray) -> np.ndarray:
        """(m, dim) :meth:`_approach` for points of surface ``own`` against ``other``:
        ``read(field)`` and ``read_other(field)`` give a field of each side's candidate nodes
        ((nc, dim)) at the points and at their virtual points; ``normal`` the other side's,
        for the platen's sense."""
        s, so = self.surfaces[own], self.surfaces[other]

        def relative(of_own: np.ndarray, of_other: np.ndarray) -> np.ndarray:
            return read(of_own) - read_other(of_other)

        def load(s: ContactSurface) -> np.ndarray:
            return s.body.load_displacement(1.0, s.candidate_dofs).reshape(-1, s.dim)

        out = relative(load(s), load(so))
        platen = relative(self.platen_motion[own], self.platen_motion[other])
        sense = -np.sign(np.einsum("ij,ij->i", platen, normal))[:, None]
        none = np.linalg.norm(out, axis=1) <= 1e-12 * max(float(np.abs(s.X).max()), 1e-300)
        return np.where(none[:, None], sense * platen, out)

    def _compliance_density(self, i: int, j: int) -> tuple[float, bool]:
        """How much body i's surface facing j gives way, per unit length, where the two meet:
        the median nodal flexibility along the normal (1 / Castigliano stiffness) over the median
        facet length, over i's facets that face j and lie over j's surface facing i; and whether
        an end of i's surface facing j lies over j's (an edge of i inside the contact zone).

        The compatibility side must be the one whose own flexibility carries the pair: the
        softer surface, and of two equally stiff ones the finer. A much stiffer surface with a
        finer mesh would hold a traction that the other surface cannot control, and the
        pressures would oscillate (measured on Hertz with the flat as compatibility side:
        nodal pressures up to 56 % off). Only the facets where the surfaces overlap count, so
        the mesh far from the contact (a coarse far field, a long exterior facet) does not
        decide it. Of more than :data:`SIDE_SAMPLE` such nodes, that many evenly spread over
        them give the median: where the flexibility is applied, not formed (issue 22), each
        node read costs a back-substitution, and both routes must choose alike.
        """
        s, so = self.surfaces[i], self.surfaces[j]
        patch, opatch = facing(s, s.X, so, so.X), facing(so, so.X, s, s.X)
        if not len(patch) or not len(opatch):
            return 0.0, False
        oends = so.patch_boundary(opatch)
        normals = s.facet_normals()[patch]
        inside = np.zeros(len(patch), dtype=bool)  # a facet over the other surface, even partly
        for seg, _, tf in read_facets(s, patch, None, so, None, opatch, normals):
            inside |= ~so.beyond(seg, tf, oends)
        over = patch[inside]
        if not len(over):
            return 0.0, False
        # ends of the patch at a corner of the body (another candidate facet, not facing j,
        # meets it there), not where the candidates or the boundary stop
        ends = np.flatnonzero(s.boundary_nodes(s.patch_boundary(patch))
                              & (s.vertex_valence >= 2))
        normals = s.node_normals(None, patch)
        seg, _, _, _, tf = so.closest(s.X[ends], None, opatch, normals[ends])
        shared = so.on_boundary(seg, tf, oends)
        # (where both surfaces end together, at a symmetry plane, there is no edge)
        edge = bool((~so.beyond(seg, tf, oends) & ~shared).any())
        nodes = np.unique(s.facets[over])
        normals = s.node_normals(None, over)[nodes]
        if len(nodes) > SIDE_SAMPLE:  # a large zone: the median of evenly spread nodes
            pick = np.unique(np.linspace(0, len(nodes) - 1, SIDE_SAMPLE).round().astype(int))
            nodes, normals = nodes[pick], normals[pick]
        stiffness = s.normal_stiffness(nodes, normals)
        flexibility = 1.0 / stiffness[np.isfinite(stiffness) & (stiffness > 0)]
        return (float(np.median(flexibility) / np.median(s.sizes[over]))
                if len(flexibility) else 0.0), edge

    def _facing_nodes(self, i: int, j: int) -> np.ndarray:
        s = self.surfaces[i]
        return np.flatnonzero(self._nearest_body(i, s.X[: s.nc]) == j)

    def _nearest_body(self, i: int, points: np.ndarray) -> np.ndarray:
        best = np.full(len(points), -1)
        dist = np.full(len(points), np.inf)
        for j in self.group.opponents(i):
            _, _, d, _ = self.surfaces[j].project(points)
            closer = d < dist
            best[closer], dist[closer] = j, d[closer]
        return best

    # -- state of the pairs -----------------------------------------------------------------------

    def tractions(self, state: TractionState, k: int) -> np.ndarray:
        """The normal traction values of pair k at its compatibility-side nodes (the unknowns)."""
        pair = self.contact_pairs[k]
        if k not in state.tractions:
            state.tractions[k] = np.zeros(len(pair.nodes))
        return state.tractions[k]

    def assemble_forces(self, state: ContactState) -> None:
        """Every body's nodal forces from the pairs' tractions (equilibrium in weak form)."""
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
            if pair.point and pair.guard is not None and len(q):
                forward = self._guarding_pair(pair)
                if forward is not None:
                    touching = np.zeros(self.surfaces[pair.coarse].nc + 1, dtype=bool)
                    touching[self.contact_pairs[forward].nodes] = traction_values[forward] > 0
                    # (-1, beyond the other patch, reads the last entry: never touching)
                    free = ~self._forced_of(pos - len(q), len(q))
                    e |= (q[: len(pair.nodes)] <= 0) & touching[pair.guard].all(axis=1) & free
            out.append(e)
        return out

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
                elif pair.coarse == i:
                    nn = s.node_normals()
                    f = -np.einsum("ij,ij->i", state.forces[i], nn)
                    on = np.abs(state.forces[i]).sum(axis=1) > 0
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
