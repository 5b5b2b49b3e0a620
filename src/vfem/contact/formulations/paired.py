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

from ...errors import PlatenUnheld, PlatenUnpaired, RindViolation
from ..capabilities import Capabilities
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
from ..laws import relaxation, release_tension
from ..solvers import (
    Check,
    ReusedFactor,
    bordered_matrix,
    bordered_solve,
    iterate,
    linear_complementarity,
)
from ..state import (
    ContactState,
    IterationRecord,
    Pairing,
    SolveResult,
    TractionState,
    closing_motion,
)
from .group import SurfaceGroup

log = logging.getLogger(__name__)

#: the most nodes whose flexibility gives a surface's median compliance
#: (:meth:`PairSet._compliance_density`): one back-substitution each on the matrix-free route.
#: Above every model measured before issue 22 (the 981k-dof sphere reads 3,061), so none of
#: their answers moved.
SIDE_SAMPLE = 4096

#: changes of the stale held nodes (:meth:`PairedContact._update_stale`) in one solve after
#: which they only accumulate
STALE_CHANGES = 5


#: a body forced onto the compatibility side (``contact.compatibility_side``) against the rules'
#: choice is warned about when its facets over the other surface are this many times larger
#: (median sizes): it resolves the traction on its own facets (the tilted cube of issue 37, its
#: facets twice the 24 block's and three times the 36 block's: 1.5-1.8 times a rigid reference,
#: ``benchmarks/tilted_cube.py``)
FORCED_COARSER = 1.5


class PairSet(SurfaceGroup):
    """The paired variant's parts shared by small and large displacements: the contact pairs
    (which side carries compatibility, their nodes, normals, gaps and transfer), the traction
    values that are its unknowns, the forces they make, its errors and its output fields.

    :class:`PairedContact` (small displacements) and
    :class:`~vfem.contact.formulations.large.LargeDeformationContact` are built on it."""

    def __init__(self, surfaces: list[ContactSurface], pairs: set[frozenset[int]], settings,
                 backend: str | None = None, sides: dict | None = None, executor=None):
        super().__init__(surfaces, pairs, settings, backend, executor=executor)
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

    # -- geometry of the pairs (once) -------------------------------------------------------------

    #: nodes that keep every candidate node of the compatibility side (large kinematics, where
    #: which nodes overlap the other surface changes as the bodies slide)
    keep_all_nodes = False

    #: (unknowns,) the held nodes that found no contact set with the others in the last
    #: correction (:meth:`_correct_complementarity`), or None
    _refused = None
    _stale_mask = None
    _stale_changes = 0
    #: :meth:`_reserve`, once found
    _reserved = None
    #: (unknowns,) bool: the held nodes :meth:`enforce` holds however their guard stands
    _forced = None

    #: whether the equilibrium side's nodes are held too, where they would penetrate the
    #: compatibility side (issue 37, :func:`~vfem.contact.geometry.pairing.held_nodes`): the
    #: small-displacement frictionless variant
    both_surfaces = False

    def _make_pair(self, i: int, j: int, density_i: tuple[float, bool],
                   density_j: tuple[float, bool]
                   ) -> tuple[ContactPair | None, list[ContactPair]]:
        """The pair of bodies i < j (both with candidate facets), from their compliance
        densities against each other (:meth:`_compliance_density`), or None where they do not
        face each other; and with :attr:`both_surfaces` the nodes held by point forces (pairs
        with ``point`` set, :func:`~vfem.contact.geometry.pairing.held_nodes`): the equilibrium
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
        for j in self.opponents(i):
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
        :meth:`PairedContact.enforce` holds."""
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
        the hub's and its mean pressure moved 1.4 %) — unless :meth:`enforce` holds it,
        invariant (b) having found it deeper than faceting explains; and every held node
        refused in the last correction: stale (slid off its facet, :meth:`_stale`) or
        finding no contact set with the others (:meth:`_correct_complementarity`). Held,
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
        what :class:`~vfem.contact.formulations.algorithm.CycleWatch` compares between
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


class PairedContact(PairSet):
    """Frictionless contact with one condition per nodal force, small displacements (see the
    module docstring)."""

    capabilities = Capabilities(
        name="paired", orders=(1, 2), kinematics=("small",), dimensions=(2, 3),
        friction=("frictionless",), orders_3d=(1, 2))
    both_surfaces = True

    def __init__(self, surfaces: list[ContactSurface], pairs: set[frozenset[int]], settings,
                 backend: str | None = None, sides: dict | None = None, executor=None):
        super().__init__(surfaces, pairs, settings, backend, sides, executor=executor)
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
        opposite by construction (see the module docstring)."""
        cfg = self.settings
        tol = self.penetration_tolerance
        self._refused = None
        self._stale_mask, self._stale_changes = None, 0
        self.assemble_forces(state)

        def check(it: int) -> Check:
            pens = self.penetrations(state)
            traction_values = [self.tractions(state, k) for k in range(len(self.contact_pairs))]
            self._check_rind(pens)
            stale_moved = self._update_stale(state, traction_values, pens)
            errs, pen_err, contact, tension = self.compatibility_errors(pens, traction_values)
            platen_ok = self.platen_met(state)
            rec = IterationRecord(it, pen_err, 0.0, contact, tension,
                                  platen_error=self.platen_reaction(state) - state.platen_force)
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
            if not self.platen_met(state):
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
        q0 = np.concatenate([self.tractions(state, k) for k in range(len(self.contact_pairs))]
                            or [np.zeros(0)])
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
            need = state.platen_force - self.platen_reaction(state)
            # a held node touching counts where the platen's force presses it in (a body
            # landing on its corner), not where it pulls the body away
            presses = np.sign(need) * rate > 1e-9 * float(np.abs(rate).max(initial=0.0))
            if not (touch & (~reserve | presses)).any():
                if not self.platen_met(state):
                    self._close_gap(state, pens)
                return None, 0.0
            return linear_complementarity(
                W, q0, p, tol, rate, dR, body.platen_stiffness,
                state.platen_force - self.platen_reaction(state), factor=self._factor,
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
        for k, (pair, pos) in enumerate(zip(self.contact_pairs, self._offsets())):
            if pair.point and pair.reach is not None and pair.gap_normal is not None:
                d = relative[k]
                n = pair.gap_normal
                slide = d - np.einsum("ij,ij->i", d, n)[:, None] * n
                over = pair.guard[:, 0] >= 0  # (beyond the other patch: read to its end)
                out[pos:pos + len(pair.nodes)] = over & (
                    np.linalg.norm(slide, axis=1) > pair.reach)
        return out

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
        for pair, pos in zip(self.contact_pairs, self._offsets()):
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

    def _offsets(self) -> np.ndarray:
        """(pairs + 1,) where each pair's unknowns start among all of them (its nodes times
        its directions)."""
        return np.cumsum([0] + [len(p.nodes) * len(self.directions(k))
                                for k, p in enumerate(self.contact_pairs)])

    def _held_unknowns(self) -> np.ndarray:
        """(unknowns,) bool: the unknowns of the held nodes (``point`` pairs)."""
        return np.concatenate([np.full(len(pair.nodes) * len(self.directions(k)), pair.point)
                               for k, pair in enumerate(self.contact_pairs)]
                              or [np.zeros(0, dtype=bool)])

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
        offsets = self._offsets()
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
                          state.platen_force - self.platen_reaction(state))
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
        extra = state.platen_force - self.platen_reaction(state)
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
        return W[np.ix_(index, index)], dp_dplaten[index], dR[index]

    def _full_flexibility(self):
        """W, the penetration change per unit platen motion and the platen reaction per unit
        traction value over every node of every pair (stacked pair by pair, with the offsets).

        The body forces per unit traction value are sparse (a node's traction reaches the few
        nodes of its facets and of the opposing facets under it), so each body's motion is its
        flexibility C times a sparse matrix, computed once. Where the surfaces' flexibility is
        applied, not formed (issue 22), W is the
        :class:`~vfem.contact.solvers.matrix_free.PairOperator` that applies it.
        """
        directions, offsets, dF = self._force_rows()
        m = int(offsets[-1])
        if any(s.matrix_free for s in self.surfaces):
            from ..solvers import PairOperator

            W = PairOperator(self.surfaces, [s.flexibility for s in self.surfaces], dF,
                             self.contact_pairs, directions, offsets, self.executor)
            dp_dplaten = np.concatenate(
                [pair.platen_rate if j == 0 else self._tangent_platen_rate(k, direction)
                 for k, pair in enumerate(self.contact_pairs)
                 for j, direction in enumerate(directions[k])] or [np.zeros(0)])
            return W, dp_dplaten, self._platen_rows(dF, m), offsets
        def motion(b: int) -> np.ndarray:  # C f as (f^T C^T)^T, on the body's owner
            s, f = self.surfaces[b], dF[b]
            return np.asarray((f.T @ (s.C if s.exactly_symmetric else s.C.T)).T).reshape(
                s.nc, s.dim, m)

        du = self.executor.map(range(len(self.surfaces)), motion)
        W = np.zeros((m, m))
        dp_dplaten = np.zeros(m)
        for k, pair in enumerate(self.contact_pairs):
            n = len(pair.nodes)
            uf = pair.fine_read(du[pair.fine])  # (nodes, dim, m)
            coarse = du[pair.coarse]  # the virtual nodes' motion: a few coarse nodes each
            uc = (sp.csr_matrix(pair.interp) @ coarse.reshape(len(coarse), -1)).reshape(uf.shape)
            for j, direction in enumerate(directions[k]):
                rows = slice(offsets[k] + j * n, offsets[k] + (j + 1) * n)
                # along the normal: penetration p = -(gap0 + n.(u_f - u_c)), W = -dp/dq; along
                # a tangent t: the relative displacement t.(u_f - u_c) per unit traction
                W[rows] = np.einsum("id,idm->im", pair.reading(j, direction), uf - uc)
                dp_dplaten[rows] = pair.platen_rate if j == 0 else self._tangent_platen_rate(
                    k, direction)
        return W, dp_dplaten, self._platen_rows(dF, m), offsets

    def _force_rows(self):
        """Per pair the directions of its unknowns, the unknowns' offsets, and per body the
        sparse nodal forces on its candidate dofs per unit traction value ((dim nc, m))."""
        directions = [self.directions(k) for k in range(len(self.contact_pairs))]
        offsets = np.cumsum([0] + [len(p.nodes) * len(dirs)
                                   for p, dirs in zip(self.contact_pairs, directions)])
        m = int(offsets[-1])
        parts: list[list] = [[] for _ in self.surfaces]  # (rows, cols, values) per body
        for k, pair in enumerate(self.contact_pairs):
            n = len(pair.nodes)
            for body, columns, sign in ((pair.fine, pair.fine_columns(), 1.0),
                                        (pair.coarse, pair.coarse_columns(), -1.0)):
                r, c = np.nonzero(columns)
                v = sign * columns[r, c]
                dim = self.surfaces[body].dim
                for j, direction in enumerate(directions[k]):
                    for d in range(dim):  # the force along the direction's components
                        parts[body].append((dim * r + d, offsets[k] + j * n + c,
                                            v * direction[c, d]))
        dF = [sp.csr_matrix((np.concatenate([p[2] for p in ps]) if ps else [],
                             (np.concatenate([p[0] for p in ps]) if ps else [],
                              np.concatenate([p[1] for p in ps]) if ps else [])),
                            shape=(s.dim * s.nc, m))
              for s, ps in zip(self.surfaces, parts)]  # body forces per unit traction value
        return directions, offsets, dF

    def _platen_rows(self, dF, m: int) -> np.ndarray:
        """The platen's reaction per unit traction value (zero without a platen)."""
        dR = np.zeros(m)
        if self.platen_body is not None:
            s = self.surfaces[self.platen_body]
            dR = np.asarray(dF[self.platen_body].T @ s.platen_row).ravel()
        return dR

    def directions(self, k: int) -> list[np.ndarray]:
        """The directions of pair k's traction unknowns at its nodes, each (nodes, dim): the
        normal alone (frictionless; a frictional formulation adds the tangents)."""
        return [self.contact_pairs[k].normal]

    def _tangent_platen_rate(self, k: int, tangent: np.ndarray) -> np.ndarray:
        """The change of pair k's relative tangential displacement t.(u_f - u_c) per unit
        platen motion (with friction: :mod:`vfem.contact.formulations.friction`)."""
        pair, v = self.contact_pairs[k], self.platen_motion
        return np.einsum("id,id->i", tangent, pair.fine_read(v[pair.fine])
                         - pair.interp @ v[pair.coarse])

    def _close_gap(self, state: ContactState, pens: list[np.ndarray]) -> None:
        """Nothing touches: move the platen just far enough to close the smallest gap."""
        need = state.platen_force - self.platen_reaction(state)
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
