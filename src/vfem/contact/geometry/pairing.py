"""Pairing and gaps of the paired variant: which facets of two surfaces face each other, each
compatibility-side node's virtual node on the other surface (its normal, gap and interpolation,
thesis §4.3), and the overlap of a pair with its traction transfer
(:mod:`vfem.contact.geometry.transfer`).

Shared by the small-displacement (:mod:`vfem.contact.formulations.paired`, once, undeformed) and the
large-displacement paired variant (:mod:`vfem.contact.formulations.large`, every iteration, current
configuration).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .kept import Kept
from .surface import ContactSurface
from .transfer import transfer_matrices


@dataclass
class ContactPair:
    """A compatibility surface ("fine") against an equilibrium one ("coarse"), undeformed geometry.

    Arrays over the pair's nodes of the compatibility side (m of them, ``nodes`` in its local
    numbering).
    """

    fine: int  # body index
    coarse: int
    nodes: np.ndarray  # (m,) candidate nodes of the fine body in this pair
    normal: np.ndarray  # (m, 2) outward normal of the coarse surface at the virtual node
    gap0: np.ndarray  # (m,) undeformed gap (> 0 open)
    # (the three sparse, a few entries a row or column: issue 40)
    interp: sp.csr_array  # (m, nc_coarse) virtual node = interp @ coarse candidate nodes
    transfer: sp.csr_array  # (nc_coarse, nc_fine) coarse nodal force per unit fine traction
    mass: sp.csr_array  # (nc_fine, nc_fine) the fine surface's N over the overlap
    rind_depth: np.ndarray  # (m,) thickness of the coarse element under each virtual node
    carries: np.ndarray  # (m,) whose traction reaches the other surface
    patches: tuple[np.ndarray, np.ndarray] | None  # each side's facets facing the other
    platen_rate: np.ndarray | None = None  # (m,) penetration change per unit platen motion
    #: the equilibrium side's nodes held against the compatibility side (both surfaces
    #: enforced, issue 37): ``fine`` is then the equilibrium body, each unknown a point force
    #: at its node (``mass`` the identity there) that reaches the compatibility side through
    #: the shape functions at its virtual node (``transfer`` = ``interp`` transposed); they
    #: join the contact set only where the node would penetrate
    point: bool = False
    #: (m, k) per held node, the other surface's nodes around its virtual node (the nodes of
    #: the facet it lies on; -1 beyond the other patch): while they all touch, the held node
    #: is not held (:func:`~vfem.contact.solvers.complementarity.linear_complementarity`'s
    #: ``guard``)
    guard: np.ndarray | None = None
    #: (m, dim) where the gap is read along another direction than the force acts (held
    #: nodes, :func:`~.held.held_nodes`): the penetration is ``-(gap0 + gap_normal . (u_f - u_c))``
    #: while the force acts along ``normal``; None: along ``normal``
    gap_normal: np.ndarray | None = None
    #: (m,) per held node, the size of the facet its virtual node lies on: a node that has
    #: slid along it by more is no longer over it, and is not held (small kinematics pairs
    #: once; :meth:`~vfem.contact.formulations.paired.PairedContact._stale`)
    reach: np.ndarray | None = None
    #: (m, nc_fine) held points that are not nodes of the ``fine`` body (3D: where a stiff
    #: box's edge crosses the other surface's facets, :func:`~.held.held_edges`): each point's
    #: position, and its force's share, over the body's candidate nodes (``nodes`` is then
    #: the nearer corner, for messages and output); None: the points are ``nodes``
    at: sp.csr_array | None = None
    #: the facets of the ``fine`` and ``coarse`` surfaces on the pair's sides, within which
    #: it is paired again as the bodies move (:class:`~.sides.Side`; None: all)
    zones: tuple[np.ndarray | None, np.ndarray | None] = (None, None)
    #: (m,) bool, held nodes paired anew as the bodies move (large kinematics): those that are
    #: features of their own surface at rest (:func:`~.held.held_nodes`' ``features``), held
    #: whatever the other side's nodes around them do; None: none
    feature: np.ndarray | None = None

    def fine_columns(self) -> np.ndarray:
        """(nc_fine, m) the fine body's nodal force per unit traction value of each unknown."""
        return self.mass[:, self.nodes] if self.at is None else self.at.T

    def coarse_columns(self) -> np.ndarray:
        """(nc_coarse, m) the coarse body's nodal force per unit traction value of each
        unknown."""
        return self.transfer[:, self.nodes] if self.at is None else self.interp.T

    def fine_read(self, v: np.ndarray) -> np.ndarray:
        """(m, ...) the fine body's nodal values ``v`` ((nc or more, ...)) at the pair's
        points: at its nodes, or interpolated (:attr:`at`)."""
        if self.at is None:
            return v[self.nodes]
        nc = self.at.shape[1]
        return (self.at @ v[:nc].reshape(nc, -1)).reshape((self.at.shape[0],) + v.shape[1:])

    def reading(self, j: int, direction: np.ndarray) -> np.ndarray:
        """The direction along which the unknowns ``j`` (0 the normal ones) read the relative
        displacement, whose forces act along ``direction``."""
        return self.gap_normal if j == 0 and self.gap_normal is not None else direction


#: A facet faces the other body when its outward normal and the other surface's normal where
#: it is closest make an angle of at least 120 degrees (cosine <= -0.5). A flat punch's sides
#: (90 degrees to the block it presses) so do not face the block, and its corners end its
#: contact surface; the facets of a smooth or mildly angled surface (a faceted cylinder, a
#: shallow wedge, a chamfer up to 60 degrees) all do.
FACING = 0.5


def opposed(n: np.ndarray, m: np.ndarray) -> np.ndarray:
    """(k,) whether unit normals ``n`` and ``m`` ((k, dim)) face each other: at least 120
    degrees apart (:data:`FACING`). What :func:`facing` asks of a facet and the other surface,
    and the split of a surface that touches itself (:func:`~.own_sides.split`) of a facet and
    what it sees."""
    return np.einsum("ij,ij->i", n, m) <= -FACING

#: A surface with an edge inside the contact zone (an end of its patch over the other surface)
#: carries compatibility unless it gives way this many times less per unit length than the
#: other: a node-free corner of the equilibrium side would otherwise indent the compatibility
#: side between its nodes (measured on the thesis's block example, equal materials: 2.7e-4, a
#: thousand times the penetration tolerance). A much stiffer surface with the edge (a rigid
#: punch) stays on the equilibrium side: as compatibility side it would hold a traction the
#: soft surface cannot control.
EDGE_RATIO = 4.0


def facing(s: ContactSurface, x: np.ndarray, so: ContactSurface, xo: np.ndarray,
           zone: np.ndarray | None = None, ozone: np.ndarray | None = None) -> np.ndarray:
    """The candidate facets of ``s`` (at tracked positions ``x``) that face the body of ``so``
    (at ``xo``): its patch in their pair (:data:`FACING`). ``zone``, ``ozone``: the pair's
    sides, the facets of each surface that take part (:class:`~.sides.ContactPairs`; None:
    all).

    Kept on ``s`` for the last few arguments: a pair's set-up asks for the same patches
    three times (each side's compliance for the side choice, then the overlap), a third of
    the pair set-up of the sphere at 100k dofs (issue 40)."""
    kept = s.__dict__.setdefault("_facing", Kept(FACING_KEPT))
    # (whose: a shallow copy of s would share the answers)
    key = (id(s), so, *(None if a is None else np.asarray(a) for a in (x, xo, zone, ozone)))
    return kept.get(key, lambda: _facing(s, x, so, xo, zone, ozone)).copy()


#: how many of :func:`facing`'s last answers a surface keeps
FACING_KEPT = 4


def _facing(s: ContactSurface, x: np.ndarray, so: ContactSurface, xo: np.ndarray,
            zone: np.ndarray | None, ozone: np.ndarray | None) -> np.ndarray:
    """:func:`facing`, computed."""
    facets = np.arange(len(s.facets)) if zone is None else np.asarray(zone, dtype=int)
    if len(facets) == 0 or len(so.facets) == 0 or (ozone is not None and not len(ozone)):
        return np.zeros(0, dtype=int)
    n = s.facet_normals(x)
    faces = np.zeros(len(s.facets), dtype=bool)
    for _, m, _ in read_facets(s, facets, x, so, xo, ozone, n[facets]):
        faces[facets] |= opposed(n[facets], m)
    # and a facet over which a vertex of the other surface lies, facing it: a punch's corner
    # that has slid past the end of the face it pressed presses the block's facet beyond (left
    # out, the corner went into the block unheld: large kinematics, equal stiffness, 3e-3 deep)
    verts = so.vertices if ozone is None else np.intersect1d(so.vertices, so.facets[ozone])
    vn = so.node_normals(xo)[verts]
    seg, _, dist, _, tf = s.closest(xo[verts], x, zone, vn)
    reach = 2.0 * (s.sizes[facets].max()
                   + (so.sizes.max() if ozone is None else so.sizes[ozone].max()))
    over = s.kind.strictly_inside(tf) & (dist < reach) & opposed(vn, n[seg])
    faces[seg[over]] = True
    return np.flatnonzero(faces)


def read_facets(s: ContactSurface, facets: np.ndarray, x: np.ndarray | None,
                 so: ContactSurface, xo: np.ndarray | None, ofacets: np.ndarray | None,
                 normals: np.ndarray):
    """For each of the kind's readings (``s.kind.readings``; 2D:
    :data:`~vfem.contact.geometry.facets.FACET_READINGS`): the closest point on ``so`` (its facets
    ``ofacets``, all if None) of that point of each of ``facets`` of ``s`` (positions ``x``,
    ``xo``; ties by ``normals``), as (facet of so, its normal there, unclamped xi)."""
    n = len(facets)
    readings = s.kind.readings
    k = len(readings)
    pts, _ = s.surface_map(np.tile(facets, k), np.repeat(readings, n, axis=0), x)
    # one projection for all the readings (each point's is its own)
    seg, _, _, m, tf = so.closest(pts, xo, ofacets, np.tile(normals, (k, 1)))
    for i in range(k):
        part = slice(i * n, (i + 1) * n)
        yield seg[part], m[part], tf[part]


def virtual_nodes(sf: ContactSurface, sc: ContactSurface, xf: np.ndarray, xc: np.ndarray,
                  nodes: np.ndarray, fpatch: np.ndarray, cpatch: np.ndarray,
                  beyond_normal: bool = True, facet_normal: bool = False,
                  interpolated: bool = False):
    """The virtual nodes of ``nodes`` of ``sf`` on the patch ``cpatch`` of ``sc`` (positions
    ``xf``, ``xc``): (normal, gap, interp, facet, beyond) — see :func:`overlap`.
    ``beyond_normal=False``: a node beyond the patch keeps the normal interpolated at its
    virtual node instead of the direction to it (the large-kinematics follower term's
    differences, :meth:`~vfem.contact.formulations.large.LargeDeformationContact._normals_at`: a
    loaded node on the patch's edge that a perturbation moves past it would otherwise turn its
    normal by 90 degrees over the perturbation). ``facet_normal``: the normal of the facet
    at the virtual node instead of the interpolated one (:func:`~.held.held_nodes`), and with
    ``interpolated`` the interpolated one too, at the end (the held nodes of large kinematics:
    their gap read along the facet's, their force along the interpolated one,
    :func:`~.held.held_now`).
    """
    pts = xf[nodes]
    seg, t, _, m, tf = sc.closest(pts, xc, cpatch, sf.node_normals(xf, fpatch)[nodes])
    closest, _ = sc.surface_map(seg, t, xc)
    past = sc.beyond(seg, tf, sc.patch_boundary(cpatch))
    interp = sc.interpolation(seg, t)
    d = pts - closest
    dn = np.linalg.norm(d, axis=1)

    def unit(normal):
        if beyond_normal:
            normal = np.where((past & (dn > 0))[:, None],
                              d / np.maximum(dn, 1e-300)[:, None], normal)
        return normal / np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]

    normal = unit(m.copy() if facet_normal else sc.normals_at(seg, t, xc, cpatch))
    out = normal, np.einsum("ij,ij->i", d, normal), interp, seg, past
    if interpolated:
        return *out, unit(sc.normals_at(seg, t, xc, cpatch))
    return out


def blended_normal(other: np.ndarray, own: np.ndarray, c_own: float, c_other: float
                   ) -> np.ndarray:
    """(m, dim) unit normals: the other surface's outward normals ``other`` blended with minus
    the nodes' own ``own``, each weighted by its body's stiffness per unit length (``c`` the
    compliance densities: the stiffer surface weighs more; equal ones meet on the mean)."""
    total = c_own + c_other
    w_other = c_own / total if total > 0 else 0.5
    n = w_other * other - (1.0 - w_other) * own
    return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]


def common_normal(sf: ContactSurface, sc: ContactSurface, geo: Overlap, c_fine: float,
                  c_coarse: float) -> None:
    """Small-strain contact: measure the gaps along one normal that does not depend on which
    surface carries compatibility (in place on ``geo``, undeformed geometry).

    The normal is the two surfaces' outward normals (the other surface's at the virtual node,
    minus the node's own), each weighted by its body's stiffness per unit length (the inverse
    of :meth:`~vfem.contact.formulations.pairmaking.compliance_density`): where the bodies are
    pressed together the stiffer surface keeps its shape and the interface takes its normal, and two
    equally stiff ones meet on the mean plane. Swapping the roles gives the same line.
    **Why**: with the other surface's normal alone, a stiff flat made the compatibility side of
    the Hertz problem took the cylinder's normals, tilted by up to a/R, and a horizontal
    contact force of 2.6 % of the load appeared on the half model, where the cylinder as
    compatibility side has none. Nodes beyond the other surface keep the direction to its end.

    A node at the end of its own patch (its body's corner or edge: a rotated punch's lowest
    corner, a tilted box's edge), or on an edge inside it (its facets there turning by more
    than :data:`~vfem.contact.geometry.surface.FEATURE_ANGLE`: a block's corner whose top and side
    both face a disk's flank), keeps the other surface's normal too: its own surface has no
    normal there that the interface could take (its nodal normal is only a bisector), and the
    corner presses into the other face along that face's normal. **Why**: the blend, turned
    from the other face's normal by a fraction of the angle between the faces, reads the
    corner's slide s along that face as s sin(beta) of approach: a punch rotated 5.8 degrees,
    its corner sliding 5.3e-4 on a block of equal stiffness, lay 4.0e-5 (3.2 % of the push)
    inside it (random model 2d-144; 2d-7, 2d-100, 2d-285 and 3d-5 likewise 2.1-2.6 %). Along
    the face's normal: 0.05 %. Only where
    that face is flat about the virtual node: on a faceted curve the facet of the closest
    point at rest is not the one the corner lands on after a gap of facets, and its normal
    is off by the faceting angle (a stiff block's corner under a soft, coarse quarter disk's
    flank, random model 2d-185: 7.3 % of the push inside on the deformed geometry along the
    flank's normal, none with the blend, which leans to the stiff block's own). The edge
    inside a patch: a block's corner under a quarter disk's flank (one facet of 0.3 there,
    2.3 degrees between the blend and the facet's normal, a slide of 0.016 along it) lay
    3.3 % of the push inside the disk with the blend, 0.7 % along the facet's normal (random
    model 2d-52 of seed 3).
    """
    if not len(geo.nodes):
        return
    n = blended_normal(geo.normal, sf.node_normals(None, geo.fpatch)[geo.nodes], c_fine,
                       c_coarse)
    end = (sf.kind.boundary_nodes(sf.facets, sf.patch_boundary(geo.fpatch), sf.nc)
           | sf.feature_nodes(geo.fpatch))[geo.nodes]
    # (only where the other surface is flat about the virtual node: its nodal normals there
    # all one, the weighted sum as long as the weights; a virtual node at a vertex reads
    # that vertex's normal alone. Measured and not kept: no turning across the whole facet
    # under the virtual node (held._facet_turning), which left a cylinder's rim over a
    # block's edge, random model 3d-54, stopped at its last step)
    w = np.abs(geo.interp)
    flat = np.linalg.norm(w @ sc.node_normals(None, geo.cpatch), axis=1) >= (
        1.0 - 1e-12) * w.sum(axis=1)
    n = np.where((geo.beyond | (end & flat))[:, None], geo.normal, n)
    d = sf.X[geo.nodes] - geo.interp @ sc.X[: sc.nc]  # from the virtual node to the node
    geo.normal = n
    geo.gap = np.einsum("ij,ij->i", d, n)


def _pieces(s: ContactSurface) -> tuple[np.ndarray, np.ndarray]:
    """The straight pieces of the surface ``s`` (undeformed): 2D, (k, 2) chords (a quadratic
    facet as its two half chords through its midpoint); 3D, (k, 3) triangles over the facets'
    corners (a quadrilateral as two); with each piece's facet."""
    f = s.facets
    if s.dim == 2:
        if f.shape[1] == 3:
            pieces = np.vstack([f[:, [0, 2]], f[:, [2, 1]]])
            return pieces, np.tile(np.arange(len(f)), 2)
        return f[:, :2], np.arange(len(f))
    corners = s.kind.corners
    if corners == 3:
        return f[:, :3], np.arange(len(f))
    return (np.vstack([f[:, [0, 1, 2]], f[:, [0, 2, 3]]]), np.tile(np.arange(len(f)), 2))


#: points times pieces that :func:`ray_entry` tests at once (its memory: some ten arrays of
#: that many floats)
RAY_BLOCK = 500_000


def ray_entry(s: ContactSurface, points: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """(m,) how far each of ``points`` travels along its unit ``directions`` before it enters
    the body of the surface ``s`` through one of its facets (undeformed; crossing a piece from
    its outer side), inf where the ray meets none. Every piece is tested against every ray
    (blocks of :data:`RAY_BLOCK`): done once per pair, for the nodes that approach."""
    return ray_facet(s, points, directions)[0]


def ray_facet(s: ContactSurface, points: np.ndarray, directions: np.ndarray,
              facets: np.ndarray | None = None, skip: sp.csr_array | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`ray_entry` through the facets ``facets`` of ``s`` alone (all where None), and
    the facet each ray enters by (-1 where it meets none). ``skip``: (rays, facets of ``s``)
    true where that ray passes through that facet as if it were not there (a facet's own
    neighbourhood, :func:`~.own_sides.split`); None: none.

    Each ray is first tested only against the pieces near its first :data:`RAY_REACH` piece
    radii (a k-d tree of the pieces' centres, queried at points along that segment): a piece
    that the segment crosses has its centre within its radius of it, so an entry found there
    is the first. Only the rays that enter nothing that near are tested against every piece.
    **Why**: every piece against every ray was O(rays x pieces): 11.5 s of the 28 s of the
    70-division plates of ``benchmarks/matrix_free.py`` (held nodes' and edges' rays), most of
    the 116,178-contact-dof run's set-up (issue 40, item 2)."""
    pieces, facet = _pieces(s)
    if facets is not None:
        mine = np.isin(facet, facets)
        pieces, facet = pieces[mine], facet[mine]
    out = np.full(len(points), np.inf)
    which = np.full(len(points), -1)
    if not len(pieces) or not len(points):
        return out, which
    x = s.X[: s.nc]
    outward = s.facet_normals()[facet]
    scale = max(float(np.ptp(x, axis=0).max(initial=0.0)), 1e-300)
    verts = x[pieces]
    centre = verts.mean(axis=1)
    radius = float(np.linalg.norm(verts - centre[:, None], axis=2).max())
    rest = np.ones(len(points), dtype=bool)
    if radius > 0 and len(pieces) > RAY_NEAR_FROM:
        ray, piece = _near_pieces(centre, radius, points, directions)
        t = _ray_hits(x, pieces[piece], outward[piece], points[ray], directions[ray], scale)
        if skip is not None:
            t = np.where(_skipped(skip, ray, facet[piece]), np.inf, t)
        reach = RAY_REACH * radius
        first = (t <= reach)  # (beyond it a piece not near the segment may come first)
        ray, piece, t = ray[first], piece[first], t[first]
        order = np.lexsort((piece, t, ray))  # the nearest, the lowest piece on a tie
        ray, piece, t = ray[order], piece[order], t[order]
        lead = np.ones(len(ray), dtype=bool)
        lead[1:] = ray[1:] != ray[:-1]
        out[ray[lead]], which[ray[lead]] = t[lead], facet[piece[lead]]
        rest[ray[lead]] = False
    idx = np.flatnonzero(rest)
    chunk = max(1, RAY_BLOCK // len(pieces))
    every = np.arange(len(pieces))
    for lo in range(0, len(idx), chunk):
        rows = idx[lo:lo + chunk]
        k = len(rows)
        t = _ray_hits(x, pieces, outward, points[rows], directions[rows], scale,
                      np.repeat(np.arange(k), len(pieces)), np.tile(every, k)).reshape(k, -1)
        if skip is not None:
            t = np.where(_skipped(skip, np.repeat(rows, len(pieces)),
                                  np.tile(facet, k)).reshape(k, -1), np.inf, t)
        first = t.argmin(axis=1)
        best = t[np.arange(k), first]
        out[rows] = best
        which[rows] = np.where(np.isfinite(best), facet[first], -1)
    return out, which


def _skipped(skip: sp.csr_array, ray: np.ndarray, facet: np.ndarray) -> np.ndarray:
    """(k,) whether ``skip`` holds each (``ray``, ``facet``) pair: :func:`ray_facet`'s
    facets a ray passes through."""
    if not len(ray):
        return np.zeros(0, dtype=bool)
    return np.asarray(skip[ray, facet]).ravel() != 0


#: piece radii along each ray within which :func:`ray_facet` looks for its entry among the
#: nearby pieces first
RAY_REACH = 8.0

#: below this many pieces :func:`ray_facet` tests every piece against every ray at once
RAY_NEAR_FROM = 64


def _near_pieces(centre: np.ndarray, radius: float, points: np.ndarray,
                 directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(ray, piece) pairs, each once: the pieces whose centres lie within ``radius`` (the
    largest piece's) of a ray's first ``RAY_REACH * radius``, read at points ``radius``
    apart (so within 1.5 ``radius`` of one of them)."""
    from scipy.spatial import cKDTree

    steps = np.arange(int(np.ceil(RAY_REACH)) + 1) * radius
    at = points[:, None, :] + steps[None, :, None] * directions[:, None, :]
    found = cKDTree(centre).query_ball_point(at.reshape(-1, points.shape[1]),
                                              r=1.5 * radius * (1 + 1e-9), workers=-1)
    counts = np.fromiter((len(f) for f in found), dtype=np.int64, count=len(found))
    piece = np.fromiter((j for f in found for j in f), dtype=np.int64, count=int(counts.sum()))
    ray = np.repeat(np.arange(len(found)) // len(steps), counts)
    key = np.unique(ray * len(centre) + piece)
    return key // len(centre), key % len(centre)


def _ray_hits(x: np.ndarray, pieces: np.ndarray, outward: np.ndarray, points: np.ndarray,
              directions: np.ndarray, scale: float, ray: np.ndarray | None = None,
              piece: np.ndarray | None = None) -> np.ndarray:
    """How far each ray travels before it enters its piece from the outer side (inf where it
    does not): rays ``points``, ``directions`` against ``pieces`` (rows of either taken by
    ``ray`` and ``piece`` where given, else row by row), 2D segments or 3D triangles
    (Moller-Trumbore)."""
    if ray is not None:
        points, directions = points[ray], directions[ray]
        pieces, outward = pieces[piece], outward[piece]
    entering = np.einsum("kd,kd->k", outward, directions) < 0
    p, d = points, directions
    if x.shape[1] == 2:
        a, e = x[pieces[:, 0]], x[pieces[:, 1]] - x[pieces[:, 0]]
        ap = a - p

        def cross(u, v):
            return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

        den = cross(d, e)
        ok = np.abs(den) > 1e-14 * scale
        den = np.where(ok, den, 1.0)
        t, r = cross(ap, e) / den, cross(ap, d) / den
        hit = ok & (r >= -1e-12) & (r <= 1 + 1e-12)
    else:  # Moller-Trumbore
        a = x[pieces[:, 0]]
        e1 = x[pieces[:, 1]] - a
        e2 = x[pieces[:, 2]] - a
        h = np.cross(d, e2)
        den = np.einsum("kd,kd->k", e1, h)
        ok = np.abs(den) > 1e-14 * scale**2
        den = np.where(ok, den, 1.0)
        sv = p - a
        u = np.einsum("kd,kd->k", sv, h) / den
        q = np.cross(sv, e1)
        v = np.einsum("kd,kd->k", d, q) / den
        t = np.einsum("kd,kd->k", e2, q) / den
        hit = ok & (u >= -1e-12) & (v >= -1e-12) & (u + v <= 1 + 1e-12)
    hit &= entering & (t >= -1e-12 * scale)
    return np.where(hit, t, np.inf)


def _unit_motion(motion: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(m, dim) the unit directions of ``motion`` (m, dim), and (m,) which of them move at all
    (more than 1e-9 of the largest)."""
    size = np.linalg.norm(motion, axis=1)
    return (motion / np.maximum(size, 1e-300)[:, None],
            size > 1e-9 * float(size.max(initial=0.0)))


def approach_gaps(sf: ContactSurface, sc: ContactSurface, geo: Overlap,
                  approach: np.ndarray) -> np.ndarray:
    """(m,) the compatibility side's gaps along the pair's normal n (``geo.normal``, the
    common normal, :func:`common_normal`), each scaled so that it closes where the node,
    moving relative to its virtual node along ``approach`` ((m, dim) a: the loads' relative
    motion, :meth:`~vfem.contact.formulations.pairmaking.approach_motion`), crosses the line (plane)
    of the other surface's facet at its virtual node: g_m (n.a) / (m.a), m that facet's normal and
    g_m the node's distance from its line (small kinematics, undeformed; issue 37). Only where
    the node approaches clearly (a within 60 degrees of -n and of -m) and the ray along a
    meets the other surface at all (:func:`ray_entry`: not past the other body's edge, where
    the facet's line runs on through nothing); elsewhere, beyond the other patch, or without
    a motion of its own, the gap along n as it is.

    **Why**: a gap g read along n closes after a relative motion a with n.a = -g, where the
    facet's line is crossed at m.a = -g_m: where the gap is many times the push and the
    bodies approach obliquely to the facet, the two differ by about the gap times the angle
    between n and m (a block's corner under a half disk's flank 14 degrees off the horizontal,
    gap 0.0128, push 6.6e-5: the common normal, 1.8 degrees off the flank's, left the corner
    open by 7.8e-5 while it lay 6.5e-5 inside the disk). Reading along m instead makes the
    gap exact for any translation, but reads the bodies' own slide across the facets' kinks
    (a flat's nodes under a faceted cylinder: peak pressures 1.2 % apart between the two
    compatibility sides, within 0.2 % with n); scaling the gap keeps the reading and makes
    the closing exact for the loads' own motion, what the contact forces add read along n as
    before (second order where the gap is small, where the scaling changes little; nothing
    where a is along m). Closing instead where the ray meets the surface, a point of another
    facet than the virtual node's on a curve, put a stiff half disk's nodes 89 % of the push
    into a block (random model 2d-26): the reading is the virtual node's."""
    m, g_m, _, _, _ = virtual_nodes(sf, sc, sf.X, sc.X, geo.nodes, geo.fpatch, geo.cpatch,
                                    facet_normal=True)
    a, moving = _unit_motion(approach)
    na = np.einsum("ij,ij->i", geo.normal, a)
    ma = np.einsum("ij,ij->i", m, a)
    use = ~geo.beyond & moving & (na <= -0.5) & (ma <= -0.5)
    if use.any():
        use[use] = np.isfinite(ray_entry(sc, sf.X[geo.nodes[use]], a[use]))
    return np.where(use, g_m * na / np.where(use, ma, -1.0), geo.gap)


@dataclass
class Overlap:
    """The pairing of a compatibility surface's nodes with the other surface (one
    configuration; :func:`overlap`). Arrays over ``nodes``."""

    nodes: np.ndarray  # candidate nodes of the compatibility side
    normal: np.ndarray  # (m, 2) the normal along which the gap is measured
    gap: np.ndarray  # (m,) > 0 open
    interp: sp.csr_array  # (m, nc_other) virtual node = interp @ the other surface's nodes
    rind_depth: np.ndarray  # (m,) thickness of the other body's element there
    beyond: np.ndarray  # (m,) not over the other surface (no virtual node)
    carries: np.ndarray  # (m,) whose traction reaches the other surface (overlap under it)
    mass: sp.csr_array  # (nc_fine, nc_fine) N over the overlap
    transfer: sp.csr_array  # (nc_other, nc_fine) T over the overlap
    fpatch: np.ndarray  # the facets of each side that face the other (:func:`facing`)
    cpatch: np.ndarray

    def subset(self, keep: np.ndarray) -> Overlap:
        return Overlap(self.nodes[keep], self.normal[keep], self.gap[keep],
                       self.interp[np.flatnonzero(keep) if keep.dtype == bool else keep],
                       self.rind_depth[keep], self.beyond[keep], self.carries[keep], self.mass,
                       self.transfer, self.fpatch, self.cpatch)


def overlap(sf: ContactSurface, sc: ContactSurface, xf: np.ndarray | None = None,
             xc: np.ndarray | None = None, nodes: np.ndarray | None = None,
             zones: tuple[np.ndarray | None, np.ndarray | None] = (None, None)
             ) -> Overlap | None:
    """Where the compatibility surface ``sf`` meets ``sc`` (undeformed, or at tracked
    positions ``xf`` and ``xc``): each node's virtual node, normal and gap, and the
    transfer of the traction (thesis §4.4-4.5).

    Each surface takes part with its **patch**: the facets that face the other body
    (:func:`facing`). A sharp corner of the other body (the edge of a flat punch) so ends
    the patch, and a point of ``sf`` whose closest point on the patch is its end, beyond
    which it lies (outside the end facet's normal strip), is not over the other surface:
    it has no virtual node and its gap is its distance from that end, along the line to it.
    Elsewhere the normal is the patch's, interpolated between its nodal normals
    (continuous along a faceted curve; the facet normal on a flat) at the virtual node.

    ``nodes``: the ``sf`` nodes to pair (default: the nodes of its patch). ``zones``: the
    facets of ``sf`` and ``sc`` on the pair's sides (:class:`~.sides.ContactPairs`; None: all),
    within which each patch lies.
    """
    xf = sf.X if xf is None else xf
    xc = sc.X if xc is None else xc
    fpatch, cpatch = facing(sf, xf, sc, xc, *zones), facing(sc, xc, sf, xf, *zones[::-1])
    if not len(fpatch) or not len(cpatch):
        return None
    if nodes is None:
        nodes = np.unique(sf.facets[fpatch])
    normal, gap, interp, seg, past = virtual_nodes(sf, sc, xf, xc, nodes, fpatch, cpatch)
    reach = float(np.abs(gap[~past]).max()) if (~past).any() else 0.0
    mass, transfer = transfer_matrices(sf, sc, fpatch, cpatch,
                                             sc.node_normals(xc, cpatch),
                                             sc.patch_boundary(cpatch), reach, xf, xc)
    carries = abs(mass[:, nodes]).sum(axis=0) > 0
    return Overlap(nodes, normal, gap, interp, sc.rind_depth[seg], past, carries, mass,
                   transfer, fpatch, cpatch)
