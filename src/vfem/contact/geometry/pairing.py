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
from scipy.spatial import cKDTree

from .facets import FACET_READINGS  # noqa: F401 - here too for those who import it here
from .surface import ContactSurface, beyond, patch_ends  # noqa: F401 - likewise
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
    interp: np.ndarray  # (m, nc_coarse) virtual node = interp @ coarse candidate nodes
    transfer: np.ndarray  # (nc_coarse, nc_fine) coarse nodal force per unit fine traction value
    mass: np.ndarray  # (nc_fine, nc_fine) the fine surface's N over the overlap
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
    #: nodes, :func:`held_nodes`): the penetration is ``-(gap0 + gap_normal . (u_f - u_c))``
    #: while the force acts along ``normal``; None: along ``normal``
    gap_normal: np.ndarray | None = None
    #: (m,) per held node, the size of the facet its virtual node lies on: a node that has
    #: slid along it by more is no longer over it, and is not held (small kinematics pairs
    #: once; :meth:`~vfem.contact.formulations.paired.PairedContact._stale`)
    reach: np.ndarray | None = None
    #: (m, nc_fine) held points that are not nodes of the ``fine`` body (3D: where a stiff
    #: box's edge crosses the other surface's facets, :func:`held_edges`): each point's
    #: position, and its force's share, over the body's candidate nodes (``nodes`` is then
    #: the nearer corner, for messages and output); None: the points are ``nodes``
    at: np.ndarray | None = None

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
        return (self.at @ v[:nc].reshape(nc, -1)).reshape((len(self.at),) + v.shape[1:])

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

#: A surface with an edge inside the contact zone (an end of its patch over the other surface)
#: carries compatibility unless it gives way this many times less per unit length than the
#: other: a node-free corner of the equilibrium side would otherwise indent the compatibility
#: side between its nodes (measured on the thesis's block example, equal materials: 2.7e-4, a
#: thousand times the penetration tolerance). A much stiffer surface with the edge (a rigid
#: punch) stays on the equilibrium side: as compatibility side it would hold a traction the
#: soft surface cannot control.
EDGE_RATIO = 4.0


def facing(s: ContactSurface, x: np.ndarray, so: ContactSurface, xo: np.ndarray) -> np.ndarray:
    """The candidate facets of ``s`` (at tracked positions ``x``) that face the body of ``so``
    (at ``xo``): its patch in their pair (:data:`FACING`)."""
    if len(s.facets) == 0 or len(so.facets) == 0:
        return np.zeros(0, dtype=int)
    n = s.facet_normals(x)
    faces = np.zeros(len(s.facets), dtype=bool)
    for _, m, _ in read_facets(s, np.arange(len(s.facets)), x, so, xo, None, n):
        faces |= np.einsum("ij,ij->i", n, m) <= -FACING
    # and a facet over which a vertex of the other surface lies, facing it: a punch's corner
    # that has slid past the end of the face it pressed presses the block's facet beyond (left
    # out, the corner went into the block unheld: large kinematics, equal stiffness, 3e-3 deep)
    verts = so.vertices
    vn = so.node_normals(xo)[verts]
    seg, _, dist, _, tf = s.closest(xo[verts], x, None, vn)
    reach = 2.0 * (s.sizes.max() + so.sizes.max())
    over = (s.kind.strictly_inside(tf) & (dist < reach)
            & (np.einsum("ij,ij->i", vn, n[seg]) <= -FACING))
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
                  beyond_normal: bool = True, facet_normal: bool = False):
    """The virtual nodes of ``nodes`` of ``sf`` on the patch ``cpatch`` of ``sc`` (positions
    ``xf``, ``xc``): (normal, gap, interp, facet, beyond) — see :func:`overlap`.
    ``beyond_normal=False``: a node beyond the patch keeps the normal interpolated at its
    virtual node instead of the direction to it (the large-kinematics follower term's
    differences, :meth:`~vfem.contact.formulations.large.LargeDeformationContact._normals_at`: a
    loaded node on the patch's edge that a perturbation moves past it would otherwise turn its
    normal by 90 degrees over the perturbation). ``facet_normal``: the normal of the facet
    at the virtual node instead of the interpolated one (:func:`held_nodes`).
    """
    pts = xf[nodes]
    seg, t, _, m, tf = sc.closest(pts, xc, cpatch, sf.node_normals(xf, fpatch)[nodes])
    closest, _ = sc.surface_map(seg, t, xc)
    past = sc.beyond(seg, tf, sc.patch_boundary(cpatch))
    interp = sc.interpolation(seg, t)
    normal = m.copy() if facet_normal else sc.normals_at(seg, t, xc, cpatch)
    d = pts - closest
    dn = np.linalg.norm(d, axis=1)
    if beyond_normal:
        normal = np.where((past & (dn > 0))[:, None], d / np.maximum(dn, 1e-300)[:, None],
                          normal)
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    return normal, np.einsum("ij,ij->i", d, normal), interp, seg, past


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
    of :meth:`~vfem.contact.formulations.paired.PairSet._compliance_density`): where the bodies are
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
    # under the virtual node (pairing._facet_turning), which left a cylinder's rim over a
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
              facets: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`ray_entry` through the facets ``facets`` of ``s`` alone (all where None), and
    the facet each ray enters by (-1 where it meets none)."""
    pieces, facet = _pieces(s)
    if facets is not None:
        mine = np.isin(facet, facets)
        pieces, facet = pieces[mine], facet[mine]
    x = s.X[: s.nc]
    outward = s.facet_normals()[facet]
    out = np.full(len(points), np.inf)
    which = np.full(len(points), -1)
    if not len(pieces):
        return out, which
    scale = max(float(np.ptp(x, axis=0).max(initial=0.0)), 1e-300)
    chunk = max(1, RAY_BLOCK // max(len(pieces), 1))
    for lo in range(0, len(points), chunk):
        p, d = points[lo:lo + chunk, None, :], directions[lo:lo + chunk, None, :]
        entering = np.einsum("pd,nd->np", outward, directions[lo:lo + chunk]) < 0
        if s.dim == 2:
            a, e = x[pieces[:, 0]][None], (x[pieces[:, 1]] - x[pieces[:, 0]])[None]
            ap = a - p

            def cross(u, v):
                return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

            den = cross(d, e)
            ok = np.abs(den) > 1e-14 * scale
            den = np.where(ok, den, 1.0)
            t, r = cross(ap, e) / den, cross(ap, d) / den
            hit = ok & (r >= -1e-12) & (r <= 1 + 1e-12)
        else:  # Moller-Trumbore
            a = x[pieces[:, 0]][None]
            e1 = (x[pieces[:, 1]] - x[pieces[:, 0]])[None]
            e2 = (x[pieces[:, 2]] - x[pieces[:, 0]])[None]
            h = np.cross(d, e2)
            den = np.einsum("npd,npd->np", np.broadcast_to(e1, h.shape), h)
            ok = np.abs(den) > 1e-14 * scale**2
            den = np.where(ok, den, 1.0)
            sv = p - a
            u = np.einsum("npd,npd->np", sv, h) / den
            q = np.cross(sv, np.broadcast_to(e1, sv.shape))
            v = np.einsum("npd,npd->np", np.broadcast_to(d, q.shape), q) / den
            t = np.einsum("npd,npd->np", np.broadcast_to(e2, q.shape), q) / den
            hit = ok & (u >= -1e-12) & (v >= -1e-12) & (u + v <= 1 + 1e-12)
        hit &= entering & (t >= -1e-12 * scale)
        t = np.where(hit, t, np.inf)
        first = t.argmin(axis=1)
        rows = np.arange(len(t))
        out[lo:lo + chunk] = t[rows, first]
        which[lo:lo + chunk] = np.where(np.isfinite(t[rows, first]), facet[first], -1)
    return out, which


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
    motion, :meth:`~vfem.contact.formulations.paired.PairSet._approach`), crosses the line (plane)
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


def held_nodes(s: ContactSurface, so: ContactSurface, patch: np.ndarray, opatch: np.ndarray,
               nodes: np.ndarray | None = None, features: bool = False,
               approach=None) -> tuple[Overlap, np.ndarray, np.ndarray] | None:
    """Nodes of ``s`` held against the patch ``opatch`` of ``so`` by point forces (issue 37:
    both surfaces enforced), undeformed: by default every node of ``s``'s patch ``patch``
    (the equilibrium side's), else ``nodes``. Each has its virtual node on the other patch
    (the thesis's device, §4.3, the other way round), or, beyond the patch's end, the end
    itself with the direction to it as normal, if it lies within two facets of it; the gap
    along the normal of the other surface's facet there, the line the node must not cross
    (not the pair's common normal, :func:`common_normal`: at a stiff body's corner that is
    its own nodal normal, the bisector of its two faces, along which the corner could still
    slide into the other surface: measured 4 % of the push on a turned square; nor the
    normal interpolated between the facet's nodal normals: a node held along a direction
    turned from the facet's by an angle a reads the facet's motion d across it as n.d, short
    of the true approach by about |d| sin(a) — the block's corner under a coarse quarter disk
    faceted at 5 degrees sank 1e-3 (all of the push) through a gap of 0.13); and as transfer a point
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
    keep = ~past | (np.abs(gap) <= reach)
    if not keep.any():
        return None
    nodes, interp, normal, gap, seg, past = (v[keep] for v in (nodes, interp, normal, gap, seg,
                                                               past))
    if approach is not None:
        ray_pairing(s, so, opatch, nodes, (normal, gap, interp, seg), past, approach(
            Overlap(nodes, normal, gap, interp, None, past, None, None, None, patch, opatch)))
    mass = np.zeros((s.nc, s.nc))
    mass[nodes, nodes] = 1.0
    transfer = np.zeros((so.nc, s.nc))
    transfer[:, nodes] = interp.T
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
    motion, :meth:`~vfem.contact.formulations.paired.PairSet._relative_motion`), a point that
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
    at = np.zeros((len(e), s.nc))
    rows = np.arange(len(e))
    at[rows, edges[e, 0]] = 1 - tc
    at[rows, edges[e, 1]] = tc
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
    (:meth:`~vfem.contact.formulations.paired.PairSet._relative_motion`) given how to read a field
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
                pairing: tuple, past: np.ndarray, approach: np.ndarray) -> None:
    """Held nodes of ``s`` paired where they will meet ``so``: (in place on ``pairing`` =
    (normal, gap, interp, facet), :func:`held_nodes`' closest-point pairing) the virtual node
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
        return
    idx = np.flatnonzero(use)
    t = ray_entry(so, s.X[nodes[idx]], u[idx])
    idx, t = idx[np.isfinite(t)], t[np.isfinite(t)]
    if not len(idx):
        return
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
        return
    point, _ = so.surface_map(seg2, t2)
    normal[idx] = m
    gap[idx] = np.einsum("ij,ij->i", s.X[nodes[idx]] - point, m)
    interp[idx] = so.interpolation(seg2, t2)
    seg[idx] = seg2


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
    nn = s.node_normals(None, patch)
    c = s.facets[facet][:, : s.kind.corners]
    out = np.zeros(len(facet))
    for a in range(c.shape[1]):
        for b in range(a + 1, c.shape[1]):
            cos = np.clip(np.einsum("ij,ij->i", nn[c[:, a]], nn[c[:, b]]), -1.0, 1.0)
            out = np.maximum(out, np.arccos(cos))
    return out


def held_force_directions(s: ContactSurface, patch: np.ndarray, held: Overlap, c_own: float,
                          c_other: float) -> np.ndarray:
    """The directions of the held nodes' point forces (:func:`held_nodes`; their gaps read
    along ``held.normal``, the other facet's normal): over the other surface, the pair's
    common normal (:func:`common_normal`: the other facet's normal blended with minus the
    node's own, each weighted by its body's stiffness per unit length, ``c`` the compliance
    densities), so that a stiff body's node pushes along its own face as the compatibility
    side's nodes around it do; beyond the other patch's end, the direction to it.

    **Why**: the force along the other facet's normal turned a stiff gasket's held nodes'
    forces 20 degrees off its face's normal when the gaskets had slid by several elements.
    The gap stays read along the facet's normal, the line the node must not cross: a
    positive scale of a gap changes nothing of where it closes."""
    n = blended_normal(held.normal, s.node_normals(None, patch)[held.nodes], c_own, c_other)
    # (a blend that turns more than 60 degrees from the facet's normal — a node facing away —
    # keeps the facet's)
    keep = held.beyond | (np.einsum("ij,ij->i", n, held.normal) < 0.5)
    return np.where(keep[:, None], held.normal, n)


@dataclass
class Overlap:
    """The pairing of a compatibility surface's nodes with the other surface (one
    configuration; :func:`overlap`). Arrays over ``nodes``."""

    nodes: np.ndarray  # candidate nodes of the compatibility side
    normal: np.ndarray  # (m, 2) the normal along which the gap is measured
    gap: np.ndarray  # (m,) > 0 open
    interp: np.ndarray  # (m, nc_other) virtual node = interp @ the other surface's nodes
    rind_depth: np.ndarray  # (m,) thickness of the other body's element there
    beyond: np.ndarray  # (m,) not over the other surface (no virtual node)
    carries: np.ndarray  # (m,) whose traction reaches the other surface (overlap under it)
    mass: np.ndarray  # (nc_fine, nc_fine) N over the overlap
    transfer: np.ndarray  # (nc_other, nc_fine) T over the overlap
    fpatch: np.ndarray  # the facets of each side that face the other (:func:`facing`)
    cpatch: np.ndarray

    def subset(self, keep: np.ndarray) -> Overlap:
        return Overlap(self.nodes[keep], self.normal[keep], self.gap[keep], self.interp[keep],
                       self.rind_depth[keep], self.beyond[keep], self.carries[keep], self.mass,
                       self.transfer, self.fpatch, self.cpatch)


def overlap(sf: ContactSurface, sc: ContactSurface, xf: np.ndarray | None = None,
             xc: np.ndarray | None = None, nodes: np.ndarray | None = None
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

    ``nodes``: the ``sf`` nodes to pair (default: the nodes of its patch).
    """
    xf = sf.X if xf is None else xf
    xc = sc.X if xc is None else xc
    fpatch, cpatch = facing(sf, xf, sc, xc), facing(sc, xc, sf, xf)
    if not len(fpatch) or not len(cpatch):
        return None
    if nodes is None:
        nodes = np.unique(sf.facets[fpatch])
    normal, gap, interp, seg, past = virtual_nodes(sf, sc, xf, xc, nodes, fpatch, cpatch)
    reach = float(np.abs(gap[~past]).max()) if (~past).any() else 0.0
    mass, transfer = transfer_matrices(sf, sc, fpatch, cpatch,
                                             sc.node_normals(xc, cpatch),
                                             sc.patch_boundary(cpatch), reach, xf, xc)
    carries = mass[:, nodes].any(axis=0)
    return Overlap(nodes, normal, gap, interp, sc.rind_depth[seg], past, carries, mass,
                   transfer, fpatch, cpatch)
