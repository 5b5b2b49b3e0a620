"""How the paired variant's contact pairs are made, once, from the bodies' surfaces (thesis
§4.3; :class:`~vfem.contact.formulations.pairset.PairSet` builds them with these): which side of
each pair of bodies carries compatibility (the one that gives way more per unit length: its
compliance density), its nodes over the other surface, their normals, gaps and transfer, and the
equilibrium side's nodes held where they would penetrate (issue 37). Functions of the formulation
(``form``) whose pairs they make.
"""

from __future__ import annotations

import logging

import numpy as np

from ..geometry import (
    EDGE_RATIO,
    ContactPair,
    ContactSurface,
    Overlap,
    Side,
    SurfacePair,
    approach_gaps,
    common_normal,
    facing,
    held_edges,
    held_force_directions,
    held_nodes,
    overlap,
    read_facets,
    zone_mask,
)

log = logging.getLogger(__name__)


#: the most nodes whose flexibility gives a surface's median compliance
#: (:func:`compliance_density`): one back-substitution each on the matrix-free route.
#: Above every model measured before issue 22 (the 981k-dof sphere reads 3,061), so none of
#: their answers moved.
SIDE_SAMPLE = 4096


#: a body forced onto the compatibility side (``contact.compatibility_side``) against the rules'
#: choice is warned about when its facets over the other surface are this many times larger
#: (median sizes): it resolves the traction on its own facets (the tilted cube of issue 37, its
#: facets twice the 24 block's and three times the 36 block's: 1.5-1.8 times a rigid reference,
#: ``benchmarks/tilted_cube.py``)
FORCED_COARSER = 1.5


def make_pair(form, sides: SurfacePair, density_i: tuple[float, bool],
               density_j: tuple[float, bool]
               ) -> tuple[ContactPair | None, list[ContactPair]]:
    """The pair of the two ``sides`` (:class:`~vfem.contact.geometry.sides.SurfacePair`, the
    lower body's first: bodies i <= j, both with candidate facets), from their compliance
    densities against each other (:func:`compliance_density`), or None where they do not
    face each other; and with the formulation's ``both_surfaces`` the nodes held by point
    forces (pairs with ``point`` set, :func:`~vfem.contact.geometry.held.held_nodes`): the
    equilibrium side's, and the compatibility side's beyond the other patch's ends.

    Where the side the rules choose leaves no node paired at all (neither its own nodes
    over the other surface nor the other's held against it: a tilted box's corner over a
    block's corner, the two meeting edge on edge) and the other side would pair some, the
    other side carries compatibility. **Why**: a platen pushing such a box had nothing to
    hold it and the analysis stopped at the first step (random model 3d-17); with the
    block on the compatibility side the box's corner nodes are held against it and the
    model solves.

    A pair in the formulation's ``given_sides`` is carried by the body given there. Returns
    (pair, held, the body carrying compatibility, -1 where neither faces the other)."""
    given = form.given_sides.get(sides.bodies)
    if given is not None:
        return make_pair_sided(form, sides, density_i, density_j, carrier=given)
    pair, held, fine = make_pair_sided(form, sides, density_i, density_j)
    if form.settings.compatibility_side is None and not count_nodes(pair, held):
        other = make_pair_sided(form, sides, density_i, density_j, flip=True)
        if count_nodes(*other[:2]):
            log.info("contact pair: no node paired with the first side on the "
                     "compatibility side; the other side carries it")
            return other
    return pair, held, fine


def count_nodes(pair: ContactPair | None, held: list[ContactPair]) -> int:
    return (len(pair.nodes) if pair is not None else 0) + sum(len(h.nodes) for h in held)


def make_pair_sided(form, sides: SurfacePair, density_i: tuple[float, bool],
                     density_j: tuple[float, bool], flip: bool = False,
                     carrier: int | None = None
                     ) -> tuple[ContactPair | None, list[ContactPair], int]:
    """:func:`make_pair` with the compatibility side the rules choose, or (``flip``) the other,
    or (``carrier``) the one given."""
    a, b = sides.a, sides.b
    si, sj = form.surfaces[a.body], form.surfaces[b.body]
    (ci, ei), (cj, ej) = density_i, density_j
    if ci == 0.0 and cj == 0.0 and not (form.keep_all_nodes and _face(form, a, b)):
        return None, [], -1  # no facet of either faces the other
    if ei != ej and (ci if ei else cj) * EDGE_RATIO >= max(ci, cj):
        # the contact zone ends at an edge of one surface (a corner over the other): that
        # surface carries compatibility, unless it is much stiffer
        fine, coarse = (a, b) if ei else (b, a)
    elif abs(ci - cj) > 1e-9 * max(ci, cj):
        fine, coarse = (a, b) if ci > cj else (b, a)
    else:  # equal: a rule that does not depend on the order of the bodies (by name, then by
        # the sides' boundaries; the two sides a surface found of itself: its side 1)
        fine, coarse = (a, b) if ((si.body.name, a.boundaries or (), a.part)
                                  < (sj.body.name, b.boundaries or (), b.part)) else (b, a)
    chosen = fine
    if form.settings.compatibility_side is not None:  # forced (for testing)
        names = (si.body.name, sj.body.name)
        if form.settings.compatibility_side in names:
            fine, coarse = (a, b) if si.body.name == form.settings.compatibility_side \
                else (b, a)
    if flip:
        fine, coarse = coarse, fine
    if carrier is not None:  # given (the solver's switch)
        fine, coarse = (a, b) if carrier == a.body else (b, a)
    c_fine, c_coarse = (ci, cj) if fine is a else (cj, ci)
    zones = (fine.facets, coarse.facets)
    fine_side, chosen = fine, chosen.body
    fine, coarse = fine.body, coarse.body
    sf, sc = form.surfaces[fine], form.surfaces[coarse]
    nodes = (facing_nodes(form, fine_side, sides.b if fine_side is sides.a else sides.a)
             if form.keep_all_nodes else None)
    geo = overlap(sf, sc, nodes=nodes, zones=zones)
    if geo is None:
        return None, [], fine
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
    if not form.keep_all_nodes:
        loose |= ~geo.carries
    past = geo.nodes[loose]
    if not form.keep_all_nodes:  # only the nodes over the other surface take part
        keep = geo.carries & ~geo.beyond
        geo = geo.subset(keep)
        common_normal(sf, sc, geo, c_fine, c_coarse)
    log.info("contact pair: %s (compatibility, %d nodes) against %s (equilibrium)",
             sf.body.name, len(geo.nodes), sc.body.name)
    # (none of the compatibility side's nodes over the other surface — a coarse soft
    # surface passing over a stiff block's corner — leaves the held nodes: that corner
    # held against the soft surface is then the whole contact)
    cfg = form.settings
    both = form.both_surfaces and (
        cfg.relaxation == 1.0 and (cfg.relaxed_iterations == 0
                                   or cfg.first_relaxation == 1.0)
        and cfg.release_iterations == 1)
    gap = geo.gap
    # (the relaxed corrections too: one problem, whichever way it is solved)
    if form.both_surfaces and not form.keep_all_nodes and len(geo.nodes):
        gap = approach_gaps(sf, sc, geo, approach_motion(form, fine, coarse, geo))
    pair = ContactPair(fine, coarse, geo.nodes, geo.normal, gap, geo.interp,
                       geo.transfer, geo.mass, geo.rind_depth, geo.carries,
                       (geo.fpatch, geo.cpatch), zones=zones) if len(geo.nodes) else None
    if not both:
        # (the thesis's relaxed corrections, §5.6, act one correction of the bodies at a
        # time on the compatibility side's nodes alone)
        return pair, [], fine
    if form.keep_all_nodes:
        coarse_side = sides.b if fine_side is sides.a else sides.a
        return pair, held_anew(form, coarse_side, fine_side, geo, c_coarse < c_fine), fine
    held = []
    for own, other, which, equilibrium in (
            (coarse, fine, None, True),  # the equilibrium side's nodes
            (fine, coarse, past, False)):  # the compatibility side's beyond the other patch
        if which is not None and not len(which):
            continue
        # (which side is which by its role: the two sides of one body are one body)
        patches = (geo.cpatch, geo.fpatch) if equilibrium else (geo.fpatch, geo.cpatch)
        c_own, c_other = (c_coarse, c_fine) if equilibrium else (c_fine, c_coarse)
        own_zones = zones[::-1] if equilibrium else zones
        # a stiffer surface's own features (its vertices, not the other side's faceting)
        # are held even between compatibility nodes in contact: the softer side must
        # take their shape (:func:`held_nodes`)
        made = held_nodes(form.surfaces[own], form.surfaces[other], *patches, which,
                          features=c_own < c_other,
                          approach=lambda g, o=own, t=other: approach_motion(form, o, t, g))
        if made is None:
            continue
        h, guard, reach = made
        if not equilibrium:  # beyond the other patch: nothing of the compatibility side's
            guard = np.full_like(guard, -1)
        log.info("contact pair: %d nodes of %s held against %s", len(h.nodes),
                 form.surfaces[own].body.name, form.surfaces[other].body.name)
        force = held_force_directions(form.surfaces[own], patches[0], h, c_own, c_other)
        held.append(ContactPair(own, other, h.nodes, force, h.gap, h.interp,
                                h.transfer, h.mass, h.rind_depth, h.carries,
                                (h.fpatch, h.cpatch), point=True, guard=guard,
                                gap_normal=h.normal, reach=reach, zones=own_zones))
    # and each side's edges where they cross the other side's facets (3D): a stiff box's
    # edge between its vertices, a soft block's rim under an overhanging punch
    for own, other, patches, feature, own_zones in (
            (coarse, fine, (geo.cpatch, geo.fpatch), c_coarse < c_fine, zones[::-1]),
            (fine, coarse, (geo.fpatch, geo.cpatch), True, zones)):
        edges = held_edges(
            form.surfaces[own], form.surfaces[other], *patches, feature=feature,
            approach=lambda *a, o=own, t=other: relative_motion(form, o, t, *a))
        if edges is None:
            continue
        at, nodes, normal, gap, interp, guard, reach, rind = edges
        log.info("contact pair: %d points of %s's edges held against %s", len(nodes),
                 form.surfaces[own].body.name, form.surfaces[other].body.name)
        held.append(ContactPair(own, other, nodes, normal, gap, interp, None, None, rind,
                                np.ones(len(nodes), dtype=bool), patches,
                                point=True, guard=guard, gap_normal=normal, reach=reach,
                                at=at, zones=own_zones))
    return pair, held, fine


def held_anew(form, own: Side, other: Side, geo: Overlap, features: bool
              ) -> list[ContactPair]:
    """Large kinematics (the formulation's ``keep_all_nodes``): the equilibrium side ``own``'s
    nodes held against the compatibility side ``other`` (the pair's overlap ``geo``), every
    candidate node of it nearer that side than any other (:func:`facing_nodes`), which the
    formulation pairs anew in every iteration
    (:meth:`~vfem.contact.formulations.large.LargeDeformationContact.penetrations`, the gap
    along the facet's normal, the force along the interpolated one); here found at rest with
    the nodes that are features of their own surface (``features``: own the stiffer,
    :func:`~vfem.contact.geometry.held.held_nodes`). The compatibility side's nodes past the
    other patch and (3D) the sharp edges, which small kinematics holds too, are not: that
    pairing is made once, at rest, and as the bodies slide those nodes change.

    **Why**: the compatibility side's nodes alone leave the other surface free between them.
    Under large kinematics (and for every plastic body, which the Newton formulation solves)
    a stiff, coarse body's vertex then sank into a softer, finer block between its nodes: 26
    of the random study's 60 2D models with a plastic block (and 25 of 60 with both bodies
    elastic under total Lagrangian kinematics) converged with a node of the upper body inside
    the block by 2 % to 95 % of the push, within the solver's faceting allowance
    (``benchmarks/random_models.py --plastic``, ``--large``)."""
    so, sc = form.surfaces[own.body], form.surfaces[other.body]
    made = held_nodes(so, sc, geo.cpatch, geo.fpatch, facing_nodes(form, own, other),
                      features=features, far=True)
    if made is None:
        return []
    h, guard, _ = made
    feature = ~h.beyond & (guard == -1).all(axis=1)
    log.info("contact pair: %d nodes of %s held against %s", len(h.nodes), so.body.name,
             sc.body.name)
    return [ContactPair(own.body, other.body, h.nodes, h.normal, h.gap, h.interp, h.transfer,
                        h.mass, h.rind_depth, ~h.beyond, (geo.cpatch, geo.fpatch),
                        point=True, guard=np.where(h.beyond[:, None], -1, guard),
                        gap_normal=h.normal, zones=(own.facets, other.facets),
                        feature=feature)]


def approach_motion(form, fine: int, coarse: int, geo: Overlap) -> np.ndarray:
    """(m, dim) how the pair's nodes move relative to their virtual nodes under the
    loads alone (small kinematics, at load factor 1): the loads' and prescribed
    displacements' motion, or where that is none, the platen's, in the sense that closes
    the gap (:func:`~vfem.contact.geometry.pairing.approach_gaps`)."""
    nc = form.surfaces[coarse].nc
    return relative_motion(form, fine, coarse, lambda f: f[geo.nodes],
                                 lambda f: geo.interp @ f[:nc], geo.normal)


def relative_motion(form, own: int, other: int, read, read_other,
                     normal: np.ndarray) -> np.ndarray:
    """(m, dim) :func:`approach_motion` for points of surface ``own`` against ``other``:
    ``read(field)`` and ``read_other(field)`` give a field of each side's candidate nodes
    ((nc, dim)) at the points and at their virtual points; ``normal`` the other side's,
    for the platen's sense."""
    s, so = form.surfaces[own], form.surfaces[other]

    def relative(of_own: np.ndarray, of_other: np.ndarray) -> np.ndarray:
        return read(of_own) - read_other(of_other)

    def load(s: ContactSurface) -> np.ndarray:
        return s.body.load_displacement(1.0, s.candidate_dofs).reshape(-1, s.dim)

    out = relative(load(s), load(so))
    platen = relative(form.platen_motion[own], form.platen_motion[other])
    sense = -np.sign(np.einsum("ij,ij->i", platen, normal))[:, None]
    none = np.linalg.norm(out, axis=1) <= 1e-12 * max(float(np.abs(s.X).max()), 1e-300)
    return np.where(none[:, None], sense * platen, out)


def _face(form, a: Side, b: Side) -> bool:
    """Whether facets of each side face the other (:func:`~vfem.contact.geometry.pairing.facing`)
    though none lies over it: under large kinematics such a pair is made all the same, its
    nodes re-paired on the current geometry at every iteration, so that two sides that will
    meet only after a large deformation are paired when they do (a bore's two halves, each
    over nothing of the other at rest: their closest points are the other's end)."""
    s, so = form.surfaces[a.body], form.surfaces[b.body]
    return bool(len(facing(s, s.X, so, so.X, a.facets, b.facets))
                and len(facing(so, so.X, s, s.X, b.facets, a.facets)))


def compliance_density(form, side: Side, other: Side) -> tuple[float, bool]:
    """How much a side (body i's surface, or its zone) facing the ``other`` (body j's) gives
    way, per unit length, where the two meet (below, "i" and "j" are the sides):
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
    s, so = form.surfaces[side.body], form.surfaces[other.body]
    zone, ozone = side.facets, other.facets
    patch, opatch = facing(s, s.X, so, so.X, zone, ozone), facing(so, so.X, s, s.X, ozone, zone)
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
    # ends of the patch at a corner of the body (another facet of the side, not facing j,
    # meets it there), not where the candidates, the side or the boundary stop
    valence = s.vertex_valence if zone is None else np.bincount(
        s.facets[zone][:, : s.kind.corners].ravel(), minlength=s.nc)[: s.nc]
    ends = np.flatnonzero(s.boundary_nodes(s.patch_boundary(patch)) & (valence >= 2))
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


def facing_nodes(form, side: Side, other: Side) -> np.ndarray:
    """The candidate nodes of ``side`` (its zone's) nearer the ``other`` side than any other
    side they may meet: the other side of each pair of which a side of this body holds them
    (:meth:`~vfem.contact.geometry.sides.ContactPairs.facing`)."""
    s = form.surfaces[side.body]
    meets = [(own, o) for own, o in form.pairs.facing(side) if len(form.surfaces[o.body].facets)]
    k = next(k for k, (own, o) in enumerate(meets) if own is side and o is other)
    return np.flatnonzero(nearest_side(form, s, meets) == k)


def nearest_side(form, s: ContactSurface, meets: list[tuple[Side, Side]]) -> np.ndarray:
    """(nc,) for each candidate node of surface ``s`` the index in ``meets`` ((own side,
    other side) pairs) of the other side closest to it among the pairs whose own side holds
    it (-1: none)."""
    points = s.X[: s.nc]
    best = np.full(len(points), -1)
    dist = np.full(len(points), np.inf)
    for k, (own, other) in enumerate(meets):
        _, _, d, _ = form.surfaces[other.body].closest(points, None, other.facets)[:4]
        if own.facets is not None:  # only the nodes of the own side's zone meet it
            d = np.where(zone_mask(s, own.facets), d, np.inf)
        closer = d < dist
        best[closer], dist[closer] = k, d[closer]
    return best
