"""The classical baselines' contact constraints (docs/baselines.md): node-to-segment, single
pass (:class:`NodeToSegment`), which :mod:`vfem.contact.formulations.baselines` enforces by
penalty, Lagrange multipliers or the augmented Lagrangian.

Per pair of bodies that may touch, the *slave* surface is the finer one (more candidate nodes per
unit length; of equals, the softer, then the first name in alphabetical order; so the choice never
depends on the order of the bodies) and its candidate nodes are the constraints; the other surface's
candidate facets are the *master segments*. Each slave node is projected on its closest master
segment in the undeformed configuration (:func:`~vfem.contact.search.closest.project_points`, a
KD-tree), once: small displacements, frictionless; a node over a vertex takes the facet it lies
over, then the one facing it (:func:`master_projection`: mirrored nodes, mirrored facets). A node
whose projection falls beyond the end of the master's candidate surface is not over it and has no
row (:func:`~vfem.contact.geometry.surface.beyond` of the master's surface ends: its gap would be
measured to the last facet's line extended, which passes through every node of a surface
collinear with it), and a node that is the slave of several bodies (a block under two
punches) keeps only its row on the closest (:func:`closest_master`): one node constrained
against two bodies made dependent rows and a singular Lagrange system. Its gap, linearised,

    g = n . (x_s + u_s - (N1 (x_1 + u_1) + N2 (x_2 + u_2))) = g0 + B U >= 0,

with ``n`` the master segment's outward normal and ``N1, N2`` its shape functions at the
projection. A row of ``B`` puts the slave node's normal force ``Lambda >= 0`` (compressive) on
the slave node (``+n``) and, spread by ``N1, N2``, on the master's nodes: the contact forces
are ``B^T Lambda``, in balance between the bodies by construction.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..geometry import ContactPairs, ContactSurface, beyond

log = logging.getLogger(__name__)


def modulus(surface: ContactSurface) -> float:
    """The modulus of Hertz's E* of the surface's body: E / (1 - nu^2), E in plane stress
    (its section's, :meth:`~vfem.bodies.section.Section.contact_modulus`)."""
    return surface.body.section.contact_modulus(surface.body.material)


def node_density(surface: ContactSurface) -> float:
    """Candidate nodes per unit length of the candidate surface."""
    length = float(surface.lengths.sum())
    return surface.nc / length if length > 0 else 0.0


def choose_slave(a: ContactSurface, b: ContactSurface) -> tuple[ContactSurface, ContactSurface]:
    """(slave, master) of a pair: the slave is the surface with more candidate nodes per unit
    length (the finer); of equal densities (to 1e-9), the softer (smaller plane-strain modulus);
    of equals in both, the body whose name sorts first. Independent of the order of the bodies.
    """
    da, db = node_density(a), node_density(b)
    if abs(da - db) > 1e-9 * max(da, db):
        return (a, b) if da > db else (b, a)
    ea, eb = modulus(a), modulus(b)
    if ea != eb:
        return (a, b) if ea < eb else (b, a)
    return (a, b) if a.body.name <= b.body.name else (b, a)


@dataclass
class NodeToSegment:
    """The node-to-segment constraints of every pair, one row per slave node.

    Attributes:
        slave, master: (m,) the bodies (indices in the model) of each row's slave node and
            master segment.
        node: (m,) the slave node's candidate number on its surface.
        segment, t: (m,) the master segment (candidate facet) and the local coordinate of the
            projection on it (0 at its first node).
        normal: (m, 2) the master segment's outward unit normal.
        g0: (m,) the undeformed gap (> 0 open, < 0 overlapping).
        weight: (m,) the slave node's tributary length (``ContactSurface.tributary``).
        penalty: (m,) the pair's penalty (pressure per unit penetration).
        B_slave, B_master: (m, N) the gap's slave and master parts per global dof (``B`` is
            their sum): the contact forces are ``B_slave^T Lambda`` on slave nodes and
            ``B_master^T Lambda`` on master nodes.
    """

    slave: np.ndarray
    master: np.ndarray
    node: np.ndarray
    segment: np.ndarray
    t: np.ndarray
    normal: np.ndarray
    g0: np.ndarray
    weight: np.ndarray
    penalty: np.ndarray
    B_slave: sp.csr_matrix
    B_master: sp.csr_matrix
    #: the relative tangential displacement's rows (the master's tangent, its normal turned by
    #: +90 degrees, in place of the normal): Coulomb friction's (lagrange)
    T_slave: sp.csr_matrix | None = None
    T_master: sp.csr_matrix | None = None

    @property
    def B(self) -> sp.csr_matrix:
        return (self.B_slave + self.B_master).tocsr()

    @property
    def Bt(self) -> sp.csr_matrix:
        return (self.T_slave + self.T_master).tocsr()

    def subset(self, keep: np.ndarray) -> NodeToSegment:
        return NodeToSegment(self.slave[keep], self.master[keep], self.node[keep],
                             self.segment[keep], self.t[keep], self.normal[keep], self.g0[keep],
                             self.weight[keep], self.penalty[keep], self.B_slave[keep],
                             self.B_master[keep],
                             None if self.T_slave is None else self.T_slave[keep],
                             None if self.T_master is None else self.T_master[keep])


def node_to_segment(surfaces: list[ContactSurface], pairs: ContactPairs,
                    offsets: np.ndarray, ndofs: int, penalty: float | None,
                    penalty_factor: float) -> NodeToSegment:
    """Project every slave node of every pair on its closest master segment (undeformed
    configuration, vectorised) and assemble the rows of the gaps (COO)."""
    index = {id(s): i for i, s in enumerate(surfaces)}
    parts = []
    for pair in pairs.keys():
        slave, master = choose_slave(surfaces[pair[0]], surfaces[pair[1]])
        if slave.nc == 0 or len(master.facets) == 0:
            continue
        i, j = index[id(slave)], index[id(master)]
        xs = slave.X[: slave.nc]
        seg, t, dist, n, t_free = master_projection(slave, master, xs)
        a, b = master.facets[seg, 0], master.facets[seg, 1]
        xm = (1 - t)[:, None] * master.X[a] + t[:, None] * master.X[b]
        g0 = np.einsum("ij,ij->i", n, xs - xm)
        eps = penalty if penalty is not None else (
            penalty_factor * max(modulus(slave), modulus(master)) / float(slave.lengths.min()))
        log.info("contact pair %s (slave) / %s (master): %d slave nodes, penalty %.6g",
                 slave.body.name, master.body.name, slave.nc, eps)
        parts.append(dict(
            slave=np.full(slave.nc, i), master=np.full(slave.nc, j),
            node=np.arange(slave.nc), segment=seg, t=t, normal=n, g0=g0,
            weight=slave.tributary.copy(), penalty=np.full(slave.nc, eps), distance=dist,
            outside=(t_free < -1e-9) | (t_free > 1 + 1e-9),
            off=beyond(master, seg, t_free, master.surface_ends),
            slave_points=slave.nodes[: slave.nc] + 0, a_points=master.nodes[a],
            b_points=master.nodes[b], slave_offset=offsets[i], master_offset=offsets[j]))
    if not parts:
        empty = sp.csr_matrix((0, ndofs))
        return NodeToSegment(*(np.zeros(0, dtype=int),) * 4, np.zeros(0), np.zeros((0, 2)),
                             np.zeros(0), np.zeros(0), np.zeros(0), empty, empty, empty, empty)

    def cat(key: str) -> np.ndarray:
        return np.concatenate([p[key] for p in parts])

    m = sum(len(p["node"]) for p in parts)
    rows = np.arange(m)
    n = cat("normal")
    t = cat("t")
    dof_s = np.concatenate([p["slave_offset"] + 2 * p["slave_points"] for p in parts])
    dof_a = np.concatenate([p["master_offset"] + 2 * p["a_points"] for p in parts])
    dof_b = np.concatenate([p["master_offset"] + 2 * p["b_points"] for p in parts])
    r2 = np.repeat(rows, 2)
    comp = np.tile([0, 1], m)
    master_cols = np.concatenate([np.repeat(dof_a, 2) + comp, np.repeat(dof_b, 2) + comp])

    def rows_along(d):
        """The slave part and the master part of d . (u_slave - u_master at the projection)."""
        slave_part = sp.csr_matrix((d.ravel(), (r2, np.repeat(dof_s, 2) + comp)),
                                   shape=(m, ndofs))
        vals = np.concatenate([(-(1 - t)[:, None] * d).ravel(), (-t[:, None] * d).ravel()])
        master_part = sp.csr_matrix((vals, (np.tile(r2, 2), master_cols)), shape=(m, ndofs))
        slave_part.eliminate_zeros()  # t = 0 or 1: no entry on the far node (a row of held
        master_part.eliminate_zeros()  # dofs only is then recognised as no constraint)
        return slave_part, master_part

    B_slave, B_master = rows_along(n)
    T_slave, T_master = rows_along(np.column_stack([-n[:, 1], n[:, 0]]))
    c = NodeToSegment(cat("slave"), cat("master"), cat("node"), cat("segment"), t, n,
                      cat("g0"), cat("weight"), cat("penalty"), B_slave, B_master, T_slave,
                      T_master)
    longest = max(float(s.lengths.max()) for s in surfaces if len(s.lengths))
    on = ~cat("off")
    keep = np.zeros(m, dtype=bool)
    keep[on] = closest_master(c.slave[on], c.node[on], cat("distance")[on], cat("outside")[on],
                              1e-9 * longest)
    if not keep.all():
        log.info("node-to-segment: %d slave nodes beyond the end of a master surface and %d "
                 "rows on a farther master left out", int((~on).sum()), int((on & ~keep).sum()))
    return c if keep.all() else c.subset(keep)


def master_projection(slave: ContactSurface, master: ContactSurface, xs: np.ndarray):
    """Each slave node's closest point on the master's candidate facets: (facet, t, distance,
    normal, unclamped t), as :meth:`ContactSurface.closest`, with ties (a node over a vertex)
    broken by the facet that lies under the node, then by the one facing it (the slave's node
    normal), so that mirrored nodes pick mirrored facets: a node under a punch's corner takes
    the punch's face, not its side, and a node beside the corner on the face's line takes the
    side it lies beside, not the face's extension beyond the corner."""
    plain = master.closest(xs)  # ties: the facet the node lies over, then the lowest number
    facing = master.closest(xs, point_normals=slave.node_normals())  # the facing one first
    over = (facing[4] >= -1e-9) & (facing[4] <= 1 + 1e-9)
    return tuple(np.where(over[:, None] if a.ndim == 2 else over, a, b)
                 for a, b in zip(facing, plain))


def closest_master(slave: np.ndarray, node: np.ndarray, distance: np.ndarray,
                   outside: np.ndarray, tie: float) -> np.ndarray:
    """Which rows to keep where a slave node has one row per body it is the slave of (a block
    under two punches): only its row on the closest master surface (distances equal to ``tie``
    are ties; of tied rows, those whose projection lies over the master facet, not beyond its
    end; rows still tied are all kept, so mirrored nodes keep mirrored rows).

    One node constrained against several bodies at once is no contact of a single pass: the
    constraints of two such nodes against the same two master points are linearly dependent
    (a block's nodes under one punch also held level with the other punch's corner, beyond
    its end, where the extended face passes through them), and the saddle point of the
    Lagrange method is singular ("Factor is exactly singular"); penalty and augmented
    methods answer, but with the far body's corner pulling on nodes it does not touch.
    """
    key = slave.astype(np.int64) * (int(node.max(initial=0)) + 1) + node
    # tied with the node's nearest row (judged against it, not by fixed bins of the distance,
    # which put two distances equal to round-off into neighbouring bins)
    _, row = np.unique(key, return_inverse=True)
    nearest = np.full(row.max(initial=-1) + 1, np.inf)
    np.minimum.at(nearest, row, distance)
    far = distance > nearest[row] + max(tie, 0.0)
    order = np.lexsort((outside, far, key))
    first = np.r_[True, key[order][1:] != key[order][:-1]]
    best = np.maximum.accumulate(np.where(first, np.arange(len(order)), 0))
    keep = np.zeros(len(key), dtype=bool)
    keep[order] = ~far[order] & (outside[order] == outside[order][best])
    return keep
