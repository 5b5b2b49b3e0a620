"""Both surfaces enforced (issue 37, docs/method.md §6): the equilibrium side's nodes and edges
held by point forces against the compatibility surface — the thesis's virtual node the other way
round (§4.3). Which of its nodes a pair holds (every node of the equilibrium side's patch over
the compatibility side, and the compatibility side's nodes just past the other patch's ends:
:func:`held_nodes`), which points along its sharp edges (where an edge crosses a facet edge
of the other surface: :func:`held_edges`, 3D), read along the normal of the facet under them,
and the directions their forces act in (:func:`held_force_directions`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .pairing import Overlap, _unit_motion, blended_normal, ray_entry, ray_facet, virtual_nodes
from .surface import ContactSurface


def held_nodes(s: ContactSurface, so: ContactSurface, patch: np.ndarray, opatch: np.ndarray,
               nodes: np.ndarray | None = None, features: bool = False,
               approach=None, far: bool = False
               ) -> tuple[Overlap, np.ndarray, np.ndarray] | None:
    """Nodes of ``s`` held against the patch ``opatch`` of ``so`` by point forces (issue 37:
    both surfaces enforced), undeformed: by default every node of ``s``'s patch ``patch``
    (the equilibrium side's), else ``nodes``. Each has its virtual node on the other patch
    (the thesis's device, §4.3, the other way round), or, beyond the patch's end, the end
    itself with the direction to it as normal, if it lies within two facets of it; the gap
    along the normal of the other surface's facet there, the line the node must not cross
    (not the pair's common normal, :func:`~vfem.contact.geometry.pairing.common_normal`: at a stiff
    body's corner that is its own nodal normal, the bisector of its two faces, along which the
    corner could still slide into the other surface: measured 4 % of the push on a turned square;
    nor the normal interpolated between the facet's nodal normals: a node held along a direction
    turned from the facet's by an angle a reads the facet's motion d across it as n.d, short
    of the true approach by about |d| sin(a) — the block's corner under a coarse quarter disk
    faceted at 5 degrees sank 1e-3 (all of the push) through a gap of 0.13). ``far``: keep the
    nodes past the patch at any distance (large kinematics pairs them anew as they slide);
    else only within two facets of its end. As transfer a point
    force: ``mass`` the identity at the node, ``transfer`` the other side's shape functions at
    the virtual node (so the two forces balance exactly). Returned with each node's guard:
    the nodes of the facet its virtual node lies on (-1 beyond the patch), and that facet's
    size (how far the node may slide along it before its pairing is stale).

    **Why**: the compatibility side's nodes over the other surface leave that surface free
    between them and past their ends: a stiff body's corner or edge (a node of the equilibrium
    side) then sinks into a softer, finer surface between its nodes, and a node of the
    softer surface just past the stiff body's edge slides under it (the tilted cube of issue
    37: a corner 9.2e-3 inside). Held only where it would penetrate
    (:func:`~vfem.contact.solvers.complementarity.linear_complementarity`'s ``reserve``), such a
    node changes nothing where the two surfaces fit (a flat interface, a convex compatibility
    side) and gives the force where they do not.
    """
    if nodes is None:
        nodes = np.unique(s.facets[patch])
    if not len(nodes):
        return None
    normal, gap, interp, seg, past = virtual_nodes(s, so, s.X, so.X, nodes, patch, opatch,
                                                   facet_normal=True)
    reach = 2.0 * (float(s.sizes[patch].max()) + float(so.sizes[opatch].max()))
    keep = ~past | (np.abs(gap) <= reach) | far
    if not keep.any():
        return None
    nodes, interp, normal, gap, seg, past = (v[keep] for v in (nodes, interp, normal, gap, seg,
                                                               past))
    if approach is not None:
        interp = ray_pairing(s, so, opatch, nodes, (normal, gap, interp, seg), past, approach(
            Overlap(nodes, normal, gap, interp, None, past, None, None, None, patch, opatch)))
    # (sparse: the identity at the nodes, and their virtual nodes' weights transposed)
    mass = sp.csr_array((np.ones(len(nodes)), (nodes, nodes)), shape=(s.nc, s.nc))
    transfer = point_transfer(interp, nodes, so.nc, s.nc)
    geo = Overlap(nodes, normal, gap, interp, so.rind_depth[seg], past,
                  np.ones(len(nodes), dtype=bool), mass, transfer, patch, opatch)
    guard = np.where(past[:, None], -1, so.facets[seg])
    size = so.sizes[seg]
    if features:
        # a node whose own surface turns more within the other side's facet than that
        # facet's surface does is a feature of its own (a fillet's tangent point, a stiff
        # polygon's vertex over a flat face), not the other side's faceting: held even
        # between compatibility nodes in contact
        own, other = _own_turning(s, patch, nodes, size), _facet_turning(so, opatch, seg)
        guard[~past & (own > 2.0 * other + FEATURE_TURNING)] = -1
    return geo, guard, size


def point_transfer(interp, nodes: np.ndarray, nc_other: int, nc_own: int) -> sp.csr_array:
    """(nc_other, nc_own) the other surface's nodal forces per unit point force at each of
    ``nodes``: the shape functions at its virtual node (``interp``'s rows), transposed, so
    the two forces balance exactly."""
    w = sp.coo_array(interp)
    return sp.csr_array((w.data, (w.col, np.asarray(nodes)[w.row])), shape=(nc_other, nc_own))


def held_now(s: ContactSurface, so: ContactSurface, x: np.ndarray, xo: np.ndarray,
             nodes: np.ndarray, patch: np.ndarray, opatch: np.ndarray, feature: np.ndarray
             ) -> tuple:
    """Held nodes of ``s`` (:func:`held_nodes`) paired anew at tracked positions ``x``, ``xo``
    (large kinematics, every iteration:
    :class:`~vfem.contact.formulations.large.LargeDeformationContact`): (force direction,
    gap direction, gap, interp, transfer, rind depth, past, guard). Each node's virtual node is
    its closest point on the other patch ``opatch``; the gap is read along the normal of the
    facet there (the line the node must not cross, as :func:`held_nodes` reads it) and the
    force acts along the other surface's normal interpolated there (continuous as the node
    slides over a vertex, which Newton's method needs: the facet's normal jumps there; the
    small-kinematics blend with the node's own normal, :func:`held_force_directions`, is for
    a pairing made once, whose facet turns away as the bodies slide). Beyond the patch, the
    direction to its end for both. The guard: the nodes of the facet under each node, -1
    beyond the patch and where ``feature`` (the node a feature of its own, held between
    compatibility nodes in contact, as :func:`held_nodes` finds at rest)."""
    gap_normal, gap, interp, seg, past, force = virtual_nodes(
        s, so, x, xo, nodes, patch, opatch, facet_normal=True, interpolated=True)
    guard = np.where((past | feature)[:, None], -1, so.facets[seg])
    return (force, gap_normal, gap, interp, point_transfer(interp, nodes, so.nc, s.nc),
            so.rind_depth[seg], past, guard)


#: degrees: the least angle between the normals of a surface's two facets across an edge (at
#: the contact surface's own boundary, its facet's and the body's next boundary facet's) that
#: makes it an edge of its own, held where it crosses the other surface (:func:`held_edges`):
#: a box's edge turns 90 degrees, a sphere or cylinder faceted at a few degrees does not count
#: (its faceting is what the other side's nodes and invariant (b)'s allowance see)
EDGE_FEATURE = 30.0


#: samples per facet of the other surface along an edge, where :func:`held_edges` looks for
#: the facets it crosses (then found to round-off by bisection)
EDGE_SAMPLES = 4


#: of the other surface's facet size: a crossing nearer than this to a corner of the edge that
#: lies over the other patch is left to that corner (:func:`held_edges`; two conditions of
#: nearly one)
EDGE_NEAR = 0.02


#: the least product of the local coordinates' changes across a bilinear facet for which an
#: edge is held at the midpoint between its crossings too (:func:`_twisted`)
EDGE_TWIST = 0.05


def held_edges(s: ContactSurface, so: ContactSurface, patch: np.ndarray, opatch: np.ndarray,
               feature: bool, approach=None) -> tuple | None:
    """3D: the points where the sharp edges of ``s``'s patch ``patch`` (:data:`EDGE_FEATURE`:
    a stiff box's edges, a block's rim) cross the edges of the other patch ``opatch``'s
    facets, held against it by point forces as its nodes are (:func:`held_nodes`), undeformed.
    Returns (at, nodes, normal, gap, interp, guard, reach, rind) or None: ``at`` (m, nc) the
    points on ``s`` (linear along the edge between its two corners), ``nodes`` the nearer
    corner (for messages and output), the normal of the other facet where the point meets it
    (gap and force), its interpolation on ``so``, the guard (the facet's nodes, or -1 where
    ``feature``: held whatever the other side's nodes around it do), the facet's size (how
    far the point may slide before its pairing is stale) and the thickness of the other
    body's element under it (the rind check). Points over the other patch are kept at any
    gap, as its nodes are.

    Where ``approach`` is given (``approach(read, read_other, normal)``, the loads' relative
    motion, :meth:`~vfem.contact.formulations.pairmaking.relative_motion`), a point that
    approaches its closest facet clearly (within 60 degrees of its inward normal) is read where the
    ray along that motion enters the other patch (:func:`ray_facet`): the facet under it, and its
    pairing; others at their closest point, and only where they lie over (or under) that
    facet, not off its edge past a corner of the other surface.

    **Why**: the compatibility side's nodes and the equilibrium side's vertices leave the
    edges free between their vertices. A stiff, coarse cube tilted 10 degrees and pushed
    0.02 edge first into a finer, 2000 times softer block had its edge 0.0117 below the
    block's deformed surface between its vertices, where one block facet spans the edge, and
    read 0.84 of the force of the block on a rigid cube with that edge held
    (``benchmarks/tilted_cube.py``). Along a line the other surface is linear between the
    edges of its facets (bilinear facets too along a line parallel to a side; obliquely,
    :func:`_twisted`), so holding the crossings holds the edge, and where the edge leaves
    the other patch, the last point over it (a box's edge across a block's edge: the box's
    edge inside the block by 18 % of the push at the block's rim, random model 3d-51). The
    compatibility side's edges too: a soft block's rim under an overhanging stiff punch lay
    between the block's rim nodes inside the punch's facets (random models 3d-6, 3d-41,
    3d-47). Read by closest point at rest, a point far from the other surface (a block's rim
    0.47 below a sphere-ended punch's cap) is under a facet near the cap's lowest point, not
    the one it meets: the crossings were missed and the rim went 0.9 of the push into the
    cap (3d-14). A point within :data:`EDGE_NEAR` of a facet of a corner over the patch is
    left to the corner (two conditions of nearly one)."""
    if s.dim != 3 or s.kind.order != 1 or not len(patch) or not len(opatch):
        return None
    ends = s.kind.edge_nodes(s.facets)  # (nf, ne, 2)
    nf, ne = ends.shape[:2]
    keys, inverse, counts = np.unique(np.sort(ends.reshape(-1, 2), axis=1), axis=0,
                                      return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    facet = np.repeat(np.arange(nf), ne)
    order = np.argsort(inverse, kind="stable")
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    f1, f2 = facet[order[first]], facet[order[first + counts - 1]]
    n = s.facet_normals()
    in_patch = np.zeros(nf, dtype=bool)
    in_patch[patch] = True
    symmetric = np.zeros(len(keys), dtype=bool)
    np.logical_or.at(symmetric, inverse, s.symmetry_edges.reshape(-1))
    cos_feature = np.cos(np.radians(EDGE_FEATURE))
    sharp = np.einsum("ij,ij->i", n[f1], n[f2]) < cos_feature
    # an edge of the candidate surface's own boundary is sharp where the body's boundary
    # turns there (a box's face named alone), not where the candidates merely end on a face
    ends_ = counts == 1
    if ends_.any():
        sharp[ends_] = _body_turn(s, keys[ends_], f1[ends_]) < cos_feature
    edges = keys[sharp & (in_patch[f1] | in_patch[f2]) & ~symmetric]
    if not len(edges):
        return None
    xa, xb = s.X[edges[:, 0]], s.X[edges[:, 1]]
    length = np.linalg.norm(xb - xa, axis=1)
    h = float(np.median(so.sizes[opatch]))
    k = np.clip(np.ceil(EDGE_SAMPLES * length / h).astype(int), 2, 400)
    edge = np.repeat(np.arange(len(edges)), k + 1)
    t = np.concatenate([np.linspace(0.0, 1.0, kk + 1) for kk in k])

    boundary = so.patch_boundary(opatch)

    def point(e, tt):
        return (1 - tt)[:, None] * xa[e] + tt[:, None] * xb[e]

    def label(e, tt, u):
        """The facet of the other patch under each point, -1 beyond the patch: where the ray
        along ``u`` enters it, or (rows of ``u`` nan) the closest."""
        p = point(e, tt)
        ray = ~np.isnan(u[:, 0])
        out = np.full(len(p), -1)
        if ray.any():
            out[ray] = ray_facet(so, p[ray], u[ray], opatch)[1]
        if (~ray).any():  # (the closest point only where there is no ray: the bisection's
            q = p[~ray]   # 40 passes read every crossing)
            seg, xi, _, m, tf = so.closest(q, None, opatch)
            out[~ray] = np.where(so.beyond(seg, tf, boundary) | ~over_facet(q, seg, xi, m),
                                 -1, seg)
        return out

    def meet(p, u):
        """Where each point meets the other patch, along its ray (rows of ``u`` not nan) or
        at its closest point: (facet, local coordinates, normal, over the patch)."""
        ray = ~np.isnan(u[:, 0])
        q = p.copy()
        over = np.ones(len(p), dtype=bool)
        if ray.any():
            dist, _ = ray_facet(so, p[ray], u[ray], opatch)
            over[ray] = np.isfinite(dist)
            q[ray] = p[ray] + np.where(np.isfinite(dist), dist, 0.0)[:, None] * u[ray]
        # (a ray that enters at an edge of two facets meets the one that faces it)
        seg, tt, _, m, tf = so.closest(q, None, opatch, np.where(ray[:, None], u, 0.0))
        over &= ray | (~so.beyond(seg, tf, boundary) & over_facet(p, seg, tt, m))
        return seg, tt, m, over

    def over_facet(p, seg, xi, m):
        """Whether each point lies over (or under) its closest facet, within 60 degrees of
        its normal, not past a corner of the other surface off the facet's edge (a box's
        edge 0.42 above a block's top, closest to the block's side at its rim: gap 0 along
        that side's normal), or on it."""
        c, _ = so.surface_map(seg, xi)
        d = p - c
        dist = np.linalg.norm(d, axis=1)
        return ((np.abs(np.einsum("ij,ij->i", d, m)) >= 0.5 * dist)
                | (dist <= 1e-3 * so.sizes[seg]))

    u_s = _edge_approach(s, so, opatch, edges, edge, t, point(edge, t), approach)
    lab = label(edge, t, u_s)
    change = np.flatnonzero((edge[1:] == edge[:-1]) & (lab[1:] != lab[:-1]))
    e, lo, hi, u, s_lo, s_hi = _crossings(label, edge[change], t[change], t[change + 1],
                                          u_s[change], lab[change], lab[change + 1])
    # (where the edge leaves the patch, the last point over it: the patch's own edge)
    tc = np.where(s_hi < 0, lo, np.where(s_lo < 0, hi, 0.5 * (lo + hi)))
    # one point where two changes meet (a sample on a vertex of the other surface, read on a
    # third facet by the ray's tie: two changes bisected to one point, two equal conditions)
    order = np.lexsort((tc, e))
    e, tc, u, s_lo, s_hi = e[order], tc[order], u[order], s_lo[order], s_hi[order]
    again = np.zeros(len(e), dtype=bool)
    again[1:] = (e[1:] == e[:-1]) & ((tc[1:] - tc[:-1]) * length[e[1:]] <= EDGE_NEAR * h)
    e, tc, u, s_lo, s_hi = e[~again], tc[~again], u[~again], s_lo[~again], s_hi[~again]
    # (a point within EDGE_NEAR of a facet of a corner over the patch is left to that
    # corner: two conditions of nearly one; a corner beyond the patch holds nothing)
    near = np.where(s_hi < 0, tc, np.where(s_lo < 0, 1 - tc, np.minimum(tc, 1 - tc)))
    away = near * length[e] > EDGE_NEAR * h
    if so.kind.corners == 4 and so.kind.order == 1:  # and across twisted bilinear facets
        te, tt_, tu = _twisted(len(edges), point, k, u_s, e, tc, label, meet)
        e, tc, u = np.r_[e[away], te], np.r_[tc[away], tt_], np.r_[u[away], tu]
    else:
        e, tc, u = e[away], tc[away], u[away]
    if not len(e):
        return None
    pts = point(e, tc)
    # each point paired where it meets the other patch: along its ray, else the closest point
    seg, tt, m, keep = meet(pts, u)  # (over the other patch, at any gap)
    closest, _ = so.surface_map(seg, tt)
    gap = np.einsum("ij,ij->i", pts - closest, m)
    if not keep.any():
        return None
    e, tc, seg, tt, m, gap = e[keep], tc[keep], seg[keep], tt[keep], m[keep], gap[keep]
    rows = np.arange(len(e))
    at = sp.csr_array((np.r_[1 - tc, tc], (np.r_[rows, rows], np.r_[edges[e, 0], edges[e, 1]])),
                      shape=(len(e), s.nc))
    nodes = np.where(tc < 0.5, edges[e, 0], edges[e, 1])
    guard = np.full((len(e), so.facets.shape[1]), -1) if feature else so.facets[seg]
    return (at, nodes, m, gap, so.interpolation(seg, tt), guard, so.sizes[seg],
            so.rind_depth[seg])


def _crossings(label, e: np.ndarray, lo: np.ndarray, hi: np.ndarray, u: np.ndarray,
               s_lo: np.ndarray, s_hi: np.ndarray, rounds: int = 16) -> tuple:
    """Every change of the facet under the edges ``e`` between the samples ``lo`` and ``hi``
    whose labels (:func:`held_edges`' ``label``, along directions ``u``) are ``s_lo`` and
    ``s_hi``, found by bisection: (e, lo, hi, u, s_lo, s_hi) of each change, ``lo`` and
    ``hi`` round-off apart, ``s_hi`` the label just past it.

    **Why**: two crossings can fall between two samples (the edge passing near a vertex of
    the other surface, its facets' edges a fraction of a sample apart); one bisection finds
    one of them, the facet just past it not ``s_hi``. A stiff block's edge under a soft
    cylinder's face (random model 3d-5 of seed 2) crossed two facet edges 0.19 of a facet
    apart; the second was not held and the edge lay 2.1 % of the push inside the cylinder
    there. Each change found whose far label is not ``s_hi`` starts a search of its own
    between it and the sample."""
    found = []
    for _ in range(rounds):
        if not len(e):
            break
        top = hi.copy()
        for _ in range(40):  # bisection to where the facet under the edge changes
            mid = 0.5 * (lo + hi)
            same = label(e, mid, u) == s_lo
            lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        past = label(e, hi, u)
        found.append((e, lo, hi, u, s_lo, past))
        more = past != s_hi
        e, lo, hi, u, s_lo, s_hi = e[more], hi[more], top[more], u[more], past[more], s_hi[more]
    return tuple(np.concatenate(parts) for parts in zip(*found)) if found else (
        e, lo, hi, u, s_lo, s_hi)


def _twisted(ne: int, point, k: np.ndarray, u: np.ndarray, e: np.ndarray, tc: np.ndarray,
             label, meet) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The midpoints of the pieces of ``ne`` edges (``point(edge, t)`` their points; ``k``
    sample intervals each, ``u`` the samples' directions) between their ends and the
    crossings ``e``, ``tc`` that lie over one bilinear facet of the other patch and cross it
    obliquely (its local coordinates changing by at least :data:`EDGE_TWIST` in product):
    (edge, parameter, direction) each; ``label`` and ``meet`` :func:`held_edges`' own.

    **Why**: a bilinear facet along a line oblique to its sides is quadratic, c s (1 - s)
    off the chord between the line's crossings of its edges, c the facet's twist (x1 - x2 +
    x3 - x4 of its corners, along its normal) times the product of the local coordinates'
    changes, largest at the midpoint whatever its sign. A flat cylinder's rim across a soft
    block's twisted hexahedron faces (random model 3d-59) lay 5.1 % of the push inside the
    block between crossings held at their gaps. Where the product is small the midpoint adds
    nearly the crossings' own condition (two of nearly one)."""
    ea = np.r_[np.arange(ne), np.arange(ne), e]
    ta = np.r_[np.zeros(ne), np.ones(ne), tc]
    order = np.lexsort((ta, ea))
    ea, ta = ea[order], ta[order]
    same = (ea[1:] == ea[:-1]) & (ta[1:] - ta[:-1] > 1e-9)
    em, a, b = ea[:-1][same], ta[:-1][same], ta[1:][same]
    tm = 0.5 * (a + b)
    starts = np.r_[0, np.cumsum(k + 1)[:-1]]
    um = u[starts[em] + np.rint(tm * k[em]).astype(int)]
    lab = label(em, tm, um) if len(em) else np.zeros(0, dtype=int)
    on = lab >= 0
    em, a, b, tm, um, lab = em[on], a[on], b[on], tm[on], um[on], lab[on]
    if not len(em):
        return np.zeros(0, dtype=int), np.zeros(0), np.zeros((0, u.shape[1]))
    s1, x1, _, o1 = meet(point(em, a + 0.25 * (b - a)), um)
    s3, x3, _, o3 = meet(point(em, a + 0.75 * (b - a)), um)
    d = 2.0 * (x3 - x1)  # the local coordinates' change over the piece
    use = o1 & o3 & (s1 == lab) & (s3 == lab) & (np.abs(d[:, 0] * d[:, 1]) >= EDGE_TWIST)
    return em[use], tm[use], um[use]


def _edge_approach(s: ContactSurface, so: ContactSurface, opatch: np.ndarray, edges: np.ndarray,
                   edge: np.ndarray, t: np.ndarray, points: np.ndarray, approach) -> np.ndarray:
    """(m, dim) the unit direction along which each point of an edge (``edges[edge]`` at
    ``t``, at ``points``) approaches the other patch ``opatch``, nan where it does not clearly
    (within 60 degrees of the closest facet's inward normal) or ``approach`` is None.
    ``approach(read, read_other, normal)``: the relative motion under the loads
    (:meth:`~vfem.contact.formulations.pairmaking.relative_motion`) given how to read a field
    of each side's candidate nodes at the points and at their closest points."""
    out = np.full(points.shape, np.nan)
    if approach is None:
        return out
    seg, tt, _, m, _ = so.closest(points, None, opatch)
    a, b = edges[edge, 0], edges[edge, 1]
    phi, nodes = so.shape(tt), so.facets[seg]

    def read(field: np.ndarray) -> np.ndarray:
        return (1 - t)[:, None] * field[a] + t[:, None] * field[b]

    def read_other(field: np.ndarray) -> np.ndarray:
        return np.einsum("kn,knd->kd", phi, field[nodes])

    u, moving = _unit_motion(approach(read, read_other, m))
    clear = moving & (np.einsum("ij,ij->i", m, u) <= -0.5)
    out[clear] = u[clear]
    return out


def _body_turn(s: ContactSurface, edges: np.ndarray, facet: np.ndarray) -> np.ndarray:
    """(k,) the cosine between the candidate ``facet``'s normal and the normal of the body's
    other boundary facet across each of ``edges`` (candidate numbers; 1 where there is none)."""
    mesh = s.body.mesh
    c = s.kind.corners
    bf = mesh.boundary_facets()
    corners = mesh.facets[:c, bf].T  # (nb, c) point numbers
    pairs = np.sort(np.stack([corners, np.roll(corners, -1, axis=1)], axis=2), axis=2)
    pairs, owner = pairs.reshape(-1, 2), np.repeat(bf, c)
    want = np.sort(s.nodes[edges], axis=1)
    # each boundary facet edge's rank among the wanted ones (one sort, not a scan per edge)
    span = int(max(pairs.max(initial=0), want.max(initial=0))) + 1
    key, wkey = pairs[:, 0] * span + pairs[:, 1], want[:, 0] * span + want[:, 1]
    order = np.argsort(wkey)
    pos = np.clip(np.searchsorted(wkey[order], key), 0, len(wkey) - 1)
    hit = wkey[order][pos] == key
    k, f = order[pos[hit]], owner[hit]
    other = f != s.facet_ids[facet[k]]
    k, f = k[other], f[other]
    p = mesh.p.T
    q = p[mesh.facets[:c, f].T]  # (m, c, 3)
    m = np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0])
    inner = p[mesh.t[:, mesh.f2t[0, f]].T].mean(axis=1)
    m *= (np.sign(np.einsum("ij,ij->i", m, q.mean(axis=1) - inner))
          / np.maximum(np.linalg.norm(m, axis=1), 1e-300))[:, None]
    out = np.ones(len(edges))
    out[k] = np.einsum("ij,ij->i", m, s.facet_normals()[facet[k]])
    return out


def ray_pairing(s: ContactSurface, so: ContactSurface, opatch: np.ndarray, nodes: np.ndarray,
                pairing: tuple, past: np.ndarray, approach: np.ndarray) -> sp.csr_array:
    """Held nodes of ``s`` paired where they will meet ``so``: (in place on ``pairing`` =
    (normal, gap, interp, facet), :func:`held_nodes`' closest-point pairing, interp returned
    with its rows replaced: it is sparse) the virtual node
    moved to where the ray along the loads' relative motion ``approach`` ((m, dim)) enters
    the patch ``opatch`` (:func:`ray_entry`), the gap read along that facet's normal; only
    where the node approaches that facet clearly (within 60 degrees of its inward normal).

    **Why**: small kinematics holds a node against the line of one facet. Paired at its
    closest point, a node that meets the other surface a facet or more further along (a
    block's corner under a soft quarter disk's flank, gap 0.13, 26 times the push: the
    closest point 0.043 from where the corner lands) is held against a facet that then turns
    as that body deforms, and the corner sank 12 % of the push into the disk; held where the
    ray enters, the facet is the one it lands on."""
    normal, gap, interp, seg = pairing
    u, moving = _unit_motion(approach)
    use = ~past & moving & (np.einsum("ij,ij->i", normal, u) <= -0.5)
    if not use.any():
        return interp
    idx = np.flatnonzero(use)
    t = ray_entry(so, s.X[nodes[idx]], u[idx])
    idx, t = idx[np.isfinite(t)], t[np.isfinite(t)]
    if not len(idx):
        return interp
    hit = s.X[nodes[idx]] + t[:, None] * u[idx]
    seg2, t2, dist, m, tf = so.closest(hit, None, opatch)
    # (near the closest point: within the facet it lies on, as a node may slide before its
    # pairing is stale)
    near = np.linalg.norm(hit - interp[idx] @ so.X[: so.nc], axis=1) <= so.sizes[seg[idx]]
    on = (near & (dist <= 0.25 * so.sizes[seg2])
          & ~so.beyond(seg2, tf, so.patch_boundary(opatch))
          & (np.einsum("ij,ij->i", m, u[idx]) <= -0.5))
    idx, seg2, t2, m = idx[on], seg2[on], t2[on], m[on]
    if not len(idx):
        return interp
    point, _ = so.surface_map(seg2, t2)
    normal[idx] = m
    gap[idx] = np.einsum("ij,ij->i", s.X[nodes[idx]] - point, m)
    seg[idx] = seg2
    return _replace_rows(interp, idx, so.interpolation(seg2, t2))


def _replace_rows(A: sp.csr_array, idx: np.ndarray, B: sp.csr_array) -> sp.csr_array:
    """``A`` with its rows ``idx`` replaced by the rows of ``B`` (both sparse)."""
    keep = np.ones(A.shape[0], dtype=bool)
    keep[idx] = False
    a, b = sp.coo_array(A), sp.coo_array(B)
    on = keep[a.row]
    return sp.csr_array((np.r_[a.data[on], b.data],
                         (np.r_[a.row[on], np.asarray(idx)[b.row]], np.r_[a.col[on], b.col])),
                        shape=A.shape)


#: radians: the least turning of a held node's own surface that makes it a feature
#: (:func:`held_nodes`): a straight surface (round-off off it) cannot protrude
FEATURE_TURNING = 1e-6


def _own_turning(s: ContactSurface, patch: np.ndarray, nodes: np.ndarray, length: np.ndarray
                 ) -> np.ndarray:
    """(m,) how far the patch ``patch`` of ``s`` turns within ``length / 2`` of each of
    ``nodes`` (undeformed): twice the largest angle between the node's normal and the normals
    of the patch facets with a vertex that near (a vertex turning by a gives a; a circle of
    radius R, about length / R)."""
    facets = s.facets[patch]
    fn = s.kind.facet_normals(s.X, facets)
    nn = s.node_normals(None, patch)[nodes]
    # the patch facets with a vertex within length / 2 of each node (sparse: node x facet)
    verts = np.unique(facets[:, : s.kind.corners])
    near = cKDTree(s.X[verts]).query_ball_point(s.X[nodes], 0.5 * length * (1 + 1e-9))
    rows = np.repeat(np.arange(len(nodes)), [len(v) for v in near])
    cols = verts[np.concatenate([np.asarray(v, dtype=int) for v in near])] if len(rows) else \
        np.zeros(0, dtype=int)
    A = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(nodes), s.nc))
    pairs = (A @ s.incidence(patch)).tocoo()
    cos = np.clip(np.einsum("ij,ij->i", nn[pairs.row], fn[pairs.col]), -1.0, 1.0)
    out = np.zeros(len(nodes))
    np.maximum.at(out, pairs.row, np.arccos(cos))
    return 2.0 * out


def _facet_turning(s: ContactSurface, patch: np.ndarray, facet: np.ndarray) -> np.ndarray:
    """(m,) how far the surface ``s`` turns across each of its facets ``facet``: the largest
    angle between the nodal normals (over the patch ``patch``) at its corners."""
    c = s.facets[facet][:, : s.kind.corners]
    return corner_spread(s.X[c], s.node_normals(None, patch)[c])[1]


def corner_spread(x: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Of facets given by their corners' positions ``x`` and nodal normals ``normals`` (both
    (m, corners, dim)): (m,) the largest distance between two corners and (m,) the largest
    angle between two corners' normals, how far the surface turns across the facet."""
    size = np.zeros(len(x))
    turn = np.zeros(len(x))
    for a in range(x.shape[1]):
        for b in range(a + 1, x.shape[1]):
            size = np.maximum(size, np.linalg.norm(x[:, a] - x[:, b], axis=1))
            cos = np.clip(np.einsum("ij,ij->i", normals[:, a], normals[:, b]), -1.0, 1.0)
            turn = np.maximum(turn, np.arccos(cos))
    return size, turn


def held_force_directions(s: ContactSurface, patch: np.ndarray, held: Overlap, c_own: float,
                          c_other: float) -> np.ndarray:
    """The directions of the held nodes' point forces (:func:`held_nodes`; their gaps read
    along ``held.normal``, the other facet's normal): over the other surface, the pair's
    common normal (:func:`~vfem.contact.geometry.pairing.common_normal`: the other facet's normal
    blended with minus the node's own, each weighted by its body's stiffness per unit length, ``c``
    the compliance densities), so that a stiff body's node pushes along its own face as the
    compatibility side's nodes around it do; beyond the other patch's end, the direction to it.

    **Why**: the force along the other facet's normal turned a stiff gasket's held nodes'
    forces 20 degrees off its face's normal when the gaskets had slid by several elements.
    The gap stays read along the facet's normal, the line the node must not cross: a
    positive scale of a gap changes nothing of where it closes."""
    n = blended_normal(held.normal, s.node_normals(None, patch)[held.nodes], c_own, c_other)
    # (a blend that turns more than 60 degrees from the facet's normal — a node facing away —
    # keeps the facet's)
    keep = held.beyond | (np.einsum("ij,ij->i", n, held.normal) < 0.5)
    return np.where(keep[:, None], held.normal, n)
