"""A body's contact surface: candidate facets and nodes, their rind, and the flexibility on them.

The contact algorithm never sees a body's full mesh. It sees, per body:

* the **candidate facets** — exterior facets that may touch another body (within the search
  distance in the undeformed configuration), oriented so that ``(t_y, -t_x)`` of the facet
  tangent is the outward normal;
* the **candidate nodes** — the nodes of those facets, where contact forces may act;
* the **rind** — the outer layer of elements (every element with a node on the candidate surface),
  in which embedded nodes of other bodies are located (thesis §5.6);
* the **flexibility** ``G = K^-1`` restricted to rows (candidate + rind nodes) and columns
  (candidate dofs), computed once with the body's own factorization (linear bodies). Its square
  block on the candidate dofs is ``C`` of vfem-method §3.3: static condensation and Castigliano
  reduction in one object (reduced stiffness of dof i = 1 / C_ii).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ...bodies import Body
from .bodymesh import (
    element_volumes,
    locate_in_simplices,
    simplices,
    symmetry_planes,
    triangles,
)
from .facets import (
    FacetKind,
    Segment,
    kind_of,
)
from .measure import facet_mass_entries, virtual_quadrature

log = logging.getLogger(__name__)

#: radians: facets meeting at a larger angle are an edge of the body, across which nodal
#: normals are not averaged (:meth:`ContactSurface.normals_at`); a faceted curve turns less
#: per facet (a quarter circle in two facets: 45 degrees)
FEATURE_ANGLE = np.radians(60.0)


@dataclass
class ContactSurface:
    """Everything about one body that contact needs; arrays are indexed by *local* node number.

    Attributes:
        body: the body.
        facet_ids: (nf,) indices of the candidate facets in ``mesh.facets``.
        facets: (nf, 2) local node numbers, ordered so the outward normal is (t_y, -t_x) (the
            first node to the second); with quadratic elements (nf, 3), the midpoint third. In
            3D (nf, 3/6/4/9) triangles or quadrilaterals, corners counter-clockwise seen from
            outside (:class:`~vfem.contact.geometry.facets.Triangle`,
            :class:`~vfem.contact.geometry.facets.Quad`). What a facet is (its shape functions,
            normals, closest point, patch boundary, readings, overlap quadrature) is its ``kind``
            (:mod:`vfem.contact.geometry.facets`).
        nodes: (nt,) point numbers (``Body.points``) of the tracked nodes; the first ``nc`` are
            the candidate nodes (on candidate facets), the rest the other vertices of the rind
            elements.
        nc: number of candidate nodes.
        X: (nt, dim) undeformed coordinates of the tracked nodes.
        lengths: (nf,) undeformed facet lengths (3D: the square roots of their areas; ``sizes``).
        tributary: (nc,) each candidate node's consistent share of a unit pressure on the
            undeformed candidate facets (half of each adjacent facet for linear elements; 1/6 and
            2/3 for a quadratic facet's ends and midpoint): nodal force / tributary is the
            nominal pressure.
        rind: (ne, 3) triangles of the rind (quadrilaterals split in two), local node numbers;
            in 3D (ne, 4) tetrahedra (hexahedra split in six, :func:`~.bodymesh.simplices`).
        G: (2 nr, 2 nc) flexibility rows of the condensed dofs (:attr:`condensed_dofs`: the
            tracked nodes' with ``rind_rows``, else only the candidates', nr = nc) for the
            candidate dofs.
        platen_row: (2 nc,) the platen reaction per unit contact force on the candidate dofs.
        kind: the :class:`~vfem.contact.geometry.facets.FacetKind` of the facets:
            ``Segment(order)`` in 2D (set from ``facets`` when not given), ``Triangle(order)`` or
            ``Quad(order)`` in 3D (None for a 3D surface without candidate facets).
    """

    body: Body
    facet_ids: np.ndarray
    facets: np.ndarray
    nodes: np.ndarray
    nc: int
    X: np.ndarray
    lengths: np.ndarray
    tributary: np.ndarray
    rind: np.ndarray
    G: np.ndarray | None = None
    platen_row: np.ndarray | None = None
    #: whether the flexibility keeps the rows of the rind's nodes (a formulation that
    #: ``reads_rind``, :class:`~vfem.contact.capabilities.Capabilities`) or only the candidates'
    rind_rows: bool = True
    #: whether ``C`` equals its transpose to the last bit (set by :meth:`compute_flexibility`)
    exactly_symmetric: bool = False
    #: what a facet is (:mod:`vfem.contact.geometry.facets`): ``Segment(order)`` in 2D, ``Triangle``
    #: or ``Quad`` in 3D; None for a 3D surface without candidate facets
    kind: FacetKind | None = None

    def __post_init__(self):
        if self.kind is None and self.X.shape[1] == 2:
            self.kind = Segment(self.facets.shape[1] - 1)

    @classmethod
    def build(cls, body: Body, facet_ids: np.ndarray, tributary: bool = True
              ) -> ContactSurface:
        """The surface of ``body``'s candidate facets ``facet_ids``; ``tributary`` False: its
        tributary areas (from the facets' mass matrices, the costliest part) left to
        :meth:`set_tributary` (made where the body's work is: :mod:`vfem.parallel`)."""
        mesh = body.mesh
        fn = body.facet_points(facet_ids).copy()  # (nf, 2 or 3) point numbers
        if body.dim == 3 and not len(fn):
            return cls._untouched(body, fn)
        kind = Segment(fn.shape[1] - 1) if body.dim == 2 else kind_of(3, fn)
        # Orient each facet so that its normal points away from its element.
        elem = mesh.f2t[0, facet_ids]
        centroid = mesh.p[:, mesh.t[:, elem]].mean(axis=1).T
        kind.orient(mesh.p, fn, centroid)

        cand = np.unique(fn)
        rind_elems = np.flatnonzero(np.isin(mesh.t, cand).any(axis=0))
        rind_nodes = np.setdiff1d(np.unique(mesh.t[:, rind_elems]), cand)
        nodes = np.concatenate([cand, rind_nodes])
        local = np.full(body.npoints, -1)
        local[nodes] = np.arange(len(nodes))
        t_rind = (triangles(mesh.t[:, rind_elems]) if body.dim == 2
                  else simplices(mesh, mesh.t[:, rind_elems]))
        X = body.points[:, nodes].T.copy()
        facets = local[fn]
        if body.dim == 2:
            lengths = np.linalg.norm(X[facets[:, 1]] - X[facets[:, 0]], axis=1)
        else:  # a 3D facet's size: the square root of its area
            lengths = np.sqrt(kind.areas(X, facets))
        surface = cls(body=body, facet_ids=np.asarray(facet_ids), facets=facets, nodes=nodes,
                      nc=len(cand), X=X, lengths=lengths, tributary=np.zeros(len(cand)),
                      rind=local[t_rind], kind=kind)
        if tributary:
            surface.set_tributary()
        return surface

    def set_tributary(self, entries=None) -> None:
        """A unit pressure's consistent nodal forces (``tributary``): the integral of each
        shape function, from the facets' mass matrices (``entries``: theirs, made elsewhere,
        :meth:`_facet_mass_entries`; else made here)."""
        if entries is not None:
            self._mass_entries = entries
        if len(self.facets):
            ones = np.ones(len(self.facets))
            self.tributary = np.asarray(self.mass_matrix(ones).sum(axis=1)).ravel()

    @classmethod
    def _untouched(cls, body: Body, fn: np.ndarray) -> ContactSurface:
        """The surface of a 3D body without candidate facets (in no pair that may touch,
        :func:`~vfem.contact.formulations.formulation.bodies_that_may_touch`): no candidate, no
        rind, no kind."""
        none = np.zeros(0, dtype=np.int64)
        return cls(body=body, facet_ids=none, facets=fn.astype(np.int64), nodes=none, nc=0,
                   X=np.zeros((0, 3)), lengths=np.zeros(0), tributary=np.zeros(0),
                   rind=np.zeros((0, 3), dtype=np.int64))

    @property
    def order(self) -> int:
        """1: two-node facets (linear elements); 2: three-node facets (quadratic elements)."""
        return self.facets.shape[1] - 1

    def interpolation(self, seg: np.ndarray, t: np.ndarray) -> np.ndarray:
        """(len(seg), nc) the values of the candidate nodes' shape functions at local
        coordinates ``t`` of facets ``seg``: row k @ nodal values = the value at point k."""
        return self._rows(seg, self.shape(t))

    def traction_interpolation(self, seg: np.ndarray, t: np.ndarray) -> np.ndarray:
        """As :meth:`interpolation` for a contact traction's nodal values
        (:meth:`~vfem.contact.geometry.facets.FacetKind.traction_shape`)."""
        return self._rows(seg, self.kind.traction_shape(t))

    def _rows(self, seg: np.ndarray, values: np.ndarray) -> sp.csr_array:
        """Sparse (len(seg), nc): a facet's few nodes a row (issue 40: stored dense, the
        virtual nodes' weights of two 152 x 152 plates took 4 GB)."""
        k = self.facets.shape[1]
        rows = np.repeat(np.arange(len(seg)), k)
        return sp.csr_array((np.asarray(values, dtype=float).reshape(-1),
                             (rows, self.facets[seg].reshape(-1))), shape=(len(seg), self.nc))

    def shape(self, t: np.ndarray) -> np.ndarray:
        """(n, 2 or 3) facet shape functions at local coordinates t (0 at the first node, 1 at
        the second), in the column order of ``facets``."""
        return self.kind.shape(t)

    # -- dofs -----------------------------------------------------------------------------------

    @property
    def dim(self) -> int:
        """The dimension of the body's space (the columns of ``X``)."""
        return self.X.shape[1]

    def dofs_of(self, nodes: np.ndarray) -> np.ndarray:
        """The body's dofs of its points ``nodes``, interleaved by component (x, y[, z] of
        each point in turn: the body's numbering)."""
        return (self.dim * np.asarray(nodes)[:, None] + np.arange(self.dim)).ravel()

    @property
    def candidate_dofs(self) -> np.ndarray:
        """Body dofs of the candidate nodes."""
        return self.dofs_of(self.nodes[: self.nc])

    @property
    def tracked_dofs(self) -> np.ndarray:
        """Body dofs of the tracked nodes (the candidates first)."""
        return self.dofs_of(self.nodes)

    @property
    def condensed_dofs(self) -> np.ndarray:
        """The body dofs its stiffness is condensed to (ordered last in its factorization): the
        tracked nodes' with :attr:`rind_rows`, else the candidate nodes' alone."""
        return self.tracked_dofs if self.rind_rows else self.candidate_dofs

    def compute_flexibility(self, matrix_free: bool = False, remote: bool = False) -> None:
        """The flexibility rows of the condensed dofs for the candidate dofs, and the platen row.

        Taken from the body's factorization (condensed dofs ordered last, see ``vfem.linalg``),
        or else one back-substitution per candidate dof. The platen's reaction per unit force at
        a candidate dof is, by reciprocity, minus that dof's motion under a unit platen motion.
        ``matrix_free`` (issue 22): no dense block at all; the flexibility is applied through
        the body's factorization when asked (:attr:`flexibility`,
        :class:`~vfem.contact.geometry.flexibility.SurfaceFlexibility`). ``remote``: the body is
        another MPI rank's, which alone reads its dense flexibility (:mod:`vfem.parallel`): none
        here.
        """
        body = self.body
        nc2 = self.dim * self.nc
        rows = self.condensed_dofs
        self.platen_row = -body.u_platen[self.candidate_dofs]
        if matrix_free:
            from .flexibility import SurfaceFlexibility

            self.G = None
            self.flexibility = SurfaceFlexibility(self)
            self.exactly_symmetric = False
            return
        if remote:
            self.G = None
            return
        if getattr(body, "condensed_flexibility", None) is not None and \
                len(body.condensed_flexibility) == len(rows):
            self.G = (body.condensed_flexibility if len(rows) == nc2
                      else body.condensed_flexibility[:, :nc2].copy())
            body.condensed_flexibility = None  # the surface keeps the rows it reads (issue 19)
            self.exactly_symmetric = True  # each backend mirrors its inverse (vfem.linalg)
        else:
            cols = body.flexibility_columns(self.candidate_dofs)
            self.G = cols[rows]
            self.exactly_symmetric = False  # back-substitutions: symmetric to round-off

    #: the flexibility applied through the body's factorization (matrix-free route, issue 22),
    #: None where it is formed (``G``)
    flexibility = None

    @property
    def matrix_free(self) -> bool:
        """Whether the flexibility is applied (issue 22), not formed."""
        return self.G is None and self.flexibility is not None

    def motion(self, F: np.ndarray) -> np.ndarray:
        """The condensed dofs' motion under nodal forces ``F`` on the candidate dofs ((dim nc,)
        or (dim nc, k)): ``G F``, formed or applied (:attr:`flexibility`)."""
        if self.matrix_free:
            return self.flexibility.apply(F)
        return self.G @ F

    def node_normals(self, x: np.ndarray | None = None, facets: np.ndarray | None = None
                     ) -> np.ndarray:
        """(nc, 2) outward unit normals at the candidate nodes (mean of the adjacent facets',
        of the subset ``facets`` if given; zero at nodes on none), undeformed or at tracked
        positions ``x``."""
        ids = np.arange(len(self.facets)) if facets is None else np.asarray(facets)
        x = self.X if x is None else x
        n = self.kind.facet_normals(x, self.facets[ids])
        out = np.zeros((self.nc, self.dim))
        for col in self.facets[ids].T:
            np.add.at(out, col, n)
        return out / np.maximum(np.linalg.norm(out, axis=1), 1e-300)[:, None]

    def incidence(self, facets: np.ndarray | None = None) -> sp.csr_matrix:
        """(nc, len(facets)) the node-facet incidence (1 where a facet of the subset
        ``facets``, all by default, has the node among its nodes); the whole surface's found
        once."""
        if getattr(self, "_incidence", None) is None:
            f = self.facets
            self._incidence = sp.csr_matrix(
                (np.ones(f.size), (f.ravel(), np.repeat(np.arange(len(f)), f.shape[1]))),
                shape=(self.nc, len(f)))
        return self._incidence if facets is None else self._incidence[:, facets].tocsr()

    def normals_at(self, seg: np.ndarray, t: np.ndarray, x: np.ndarray | None = None,
                   facets: np.ndarray | None = None) -> np.ndarray:
        """(m, dim) outward unit normals at local coordinates ``t`` of facets ``seg``: the
        facet's corner normals interpolated, each the mean of the normals of the facets
        around that corner (of the subset ``facets``) that turn from facet ``seg`` by less than
        :data:`FEATURE_ANGLE` — smooth along a faceted curve, but not across an edge of the
        body, undeformed or at tracked positions ``x``.

        **Why**: with the plain nodal normals (:meth:`node_normals`, the mean of all the
        facets around a node) a box's top facet next to its side reads a normal tilted 45
        degrees towards the side at the edge's nodes: a cylinder's face over a block's edge
        had its gaps read along it, took a sideways motion of the edge as closing, and lay
        50 % of the push inside the block (random model 3d-54)."""
        ids = np.arange(len(self.facets)) if facets is None else np.asarray(facets)
        x = self.X if x is None else x
        fn = self.kind.facet_normals(x, self.facets[ids])
        own = self.kind.facet_normals(x, self.facets[seg])
        inc = self.incidence(ids)
        phi = self.shape(t)
        out = np.zeros((len(seg), self.dim))
        cos = np.cos(FEATURE_ANGLE)
        for k in range(self.facets.shape[1]):
            rows = inc[self.facets[seg, k]].tocoo()
            keep = np.einsum("ij,ij->i", fn[rows.col], own[rows.row]) >= cos
            corner = np.zeros((len(seg), self.dim))
            np.add.at(corner, rows.row[keep], fn[rows.col[keep]])
            corner = np.where(np.linalg.norm(corner, axis=1)[:, None] > 0, corner, own)
            corner /= np.linalg.norm(corner, axis=1)[:, None]
            out += phi[:, k, None] * corner
        return out / np.maximum(np.linalg.norm(out, axis=1), 1e-300)[:, None]

    def feature_nodes(self, facets: np.ndarray | None = None) -> np.ndarray:
        """(nc,) True at the nodes where two of the facets around them (of the subset
        ``facets``) turn by more than :data:`FEATURE_ANGLE`: an edge or corner of the body
        (a block's corner, a box's edge), where its surface has no normal of its own; the
        nodal normal there (:meth:`node_normals`) is only a bisector."""
        ids = np.arange(len(self.facets)) if facets is None else np.asarray(facets)
        if not len(ids):
            return np.zeros(self.nc, dtype=bool)
        fn = self.kind.facet_normals(self.X, self.facets[ids])
        inc = self.incidence(ids)  # (nc, len(ids))
        # the pairs of facets that share a node, those of them that turn, and per node how
        # many such pairs it lies in (the diagonal of inc @ turned @ inc^T)
        pairs = (inc.T @ inc).tocoo()
        turned = np.einsum("ij,ij->i", fn[pairs.row], fn[pairs.col]) < np.cos(FEATURE_ANGLE)
        turned = sp.csr_matrix((np.ones(int(turned.sum())), (pairs.row[turned],
                                pairs.col[turned])), shape=pairs.shape)
        return np.asarray((inc @ turned).multiply(inc).sum(axis=1)).ravel() > 0

    @property
    def rind_depth(self) -> np.ndarray:
        """(nf,) thickness of the element behind each candidate facet: its area / facet length
        (3D: its volume / facet area)."""
        if not hasattr(self, "_rind_depth"):
            mesh = self.body.mesh
            elem = mesh.f2t[0, self.facet_ids]
            if self.dim == 3:
                self._rind_depth = element_volumes(mesh, elem) / self.areas
                return self._rind_depth
            pts = mesh.p[:, mesh.t[:, elem]]  # (2, nv, nf)
            x, y = pts[0], pts[1]
            area = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y,
                                       axis=0))
            self._rind_depth = area / self.lengths
        return self._rind_depth

    @property
    def vertex_valence(self) -> np.ndarray:
        """(nc,) how many candidate facets each candidate node is a vertex of."""
        return np.bincount(self.facets[:, : self.kind.corners].ravel(),
                           minlength=self.nc)[: self.nc]

    @property
    def vertices(self) -> np.ndarray:
        """The candidate facets' vertices (their end nodes, not a quadratic facet's middle)."""
        return np.unique(self.facets[:, : self.kind.corners])

    @property
    def surface_ends(self) -> np.ndarray:
        """(nc,) True at the ends of the candidate surface (nodes on a single candidate facet)."""
        if not hasattr(self, "_ends"):
            self._ends = self.vertex_valence == 1
        return self._ends

    @property
    def C(self) -> np.ndarray:
        """Flexibility on the candidate dofs, (2 nc, 2 nc)."""
        return self.G[: self.dim * self.nc]

    def normal_stiffness(self, nodes: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """Castigliano stiffness of candidate nodes along unit normals: 1 / (n^T C_jj n).

        The force per unit displacement of that node along ``n`` with every other dof of the body
        free (vfem-method §3.3). A node whose motion along ``n`` is fully prevented by supports
        gets an infinite stiffness.
        """
        if self.matrix_free:  # one back-substitution a node (issue 22)
            c = self.flexibility.normal_compliance(nodes, normal)
        else:
            C, k = self.C, self.dim
            c = 0.0
            for d in range(k):  # the symmetric form, its off-diagonal terms once, doubled
                for e in range(d, k):
                    cde = C[k * nodes + d, k * nodes + e]
                    c = c + (cde * normal[:, d] * normal[:, e] if d == e
                             else 2 * cde * normal[:, d] * normal[:, e])
        with np.errstate(divide="ignore"):
            return np.where(c > 0, 1.0 / np.maximum(c, 1e-300), np.inf)

    def normal_flexibility(self, nodes: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """n_s^T C_st n_t over the candidate nodes ``nodes`` (their unit normals ``normal``):
        the normal motion of each node per unit normal force at each (eq. 4.2.4 in matrix
        form, §4.5.2)."""
        C, k = self.C, self.dim
        out = 0.0
        for d in range(k):
            for e in range(k):
                out = out + (normal[:, d, None] * C[np.ix_(k * nodes + d, k * nodes + e)]
                             * normal[None, :, e])
        return out

    # -- geometry -------------------------------------------------------------------------------

    def segments(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Start and end points of the candidate facets for tracked positions ``x``."""
        return x[self.facets[:, 0]], x[self.facets[:, 1]]

    def curve(self, seg: np.ndarray, t: np.ndarray, x: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
        """Position and tangent dx/dt at local coordinates ``t`` of facets ``seg``.

        The facet is the curve its nodes interpolate: straight for two nodes, a parabola through
        the midpoint for three (curved quadratic meshes), for nodal positions ``x`` (default:
        undeformed).
        """
        x = self.X if x is None else x
        return self.kind.curve(x, self.facets[seg], t)

    def surface_map(self, seg: np.ndarray, xi: np.ndarray, x: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
        """(pos, jn) at local coordinates ``xi`` of facets ``seg`` (positions ``x``, default
        undeformed): the position and the Jacobian times the unit outward normal, whose norm is
        the measure per unit local coordinate (:meth:`FacetKind.surface_map`)."""
        x = self.X if x is None else x
        return self.kind.surface_map(x, self.facets[seg], xi)

    def facet_normals(self, x: np.ndarray | None = None) -> np.ndarray:
        """(nf, dim) unit outward normals of the candidate facets (their chords), undeformed or
        at tracked positions ``x``."""
        x = self.X if x is None else x
        return self.kind.facet_normals(x, self.facets)

    def weight(self, points: np.ndarray) -> np.ndarray | float:
        """The measure of the body's boundary per unit of its mesh's length at undeformed
        ``points`` (..., dim): its section's (:meth:`vfem.bodies.section.Section.weight`; 1 in
        plane strain, plane stress and 3D). N*, the quadratures and the overlap quadrature
        of the transfer multiply by it."""
        return self.body.section.weight(np.moveaxis(points, -1, 0))

    @property
    def sizes(self) -> np.ndarray:
        """(nf,) undeformed facet sizes: their lengths in 2D, the square roots of their areas
        in 3D (``lengths`` holds them)."""
        return self.lengths

    @property
    def areas(self) -> np.ndarray:
        """(nf,) undeformed facet measures: their lengths in 2D, their areas in 3D."""
        return self.lengths if self.dim == 2 else self.lengths ** 2

    def project(self, points: np.ndarray, x: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Closest point on the candidate surface (undeformed, or at tracked positions ``x``)
        for each point: (facet, t, distance, outward normal there); :meth:`closest`."""
        return self.closest(points, x)[:4]

    def closest(self, points: np.ndarray, x: np.ndarray | None = None,
                facets: np.ndarray | None = None, point_normals: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Closest point on the candidate facets (or on the subset ``facets``), undeformed or at
        tracked positions ``x``, for each point.

        Returns (facet, t, distance, outward facet normal there, t_free). The chords give the
        facet, a first t and ``t_free``, the unclamped coordinate along the chord (outside
        [0, 1]: the point lies beyond that end of the facet); on curved facets a few Newton
        steps then find the closest point on the curve. Ties between facets are broken by
        ``point_normals`` (:func:`~vfem.contact.search.closest.project_points`);
        :meth:`FacetKind.closest`.
        """
        x = self.X if x is None else x
        ids = np.arange(len(self.facets)) if facets is None else np.asarray(facets)
        return self.kind.closest(points, x, self.facets, ids, point_normals)

    def patch_boundary(self, patch: np.ndarray):
        """The boundary of a patch of candidate facets (facet numbers ``patch``), as
        :meth:`beyond` and :meth:`on_boundary` read it (:meth:`FacetKind.patch_boundary`; in 2D
        (nc,) True at the patch's end vertices). In 3D an edge on a symmetry plane of the body
        (:attr:`symmetry_edges`) is not a boundary: the model goes on across it as the patch's
        mirror image, so a point whose closest point lies past it is over the mirrored patch,
        not beyond the surface (a quarter sphere's pole on a flat: read as beyond, the flat's
        node under it had no virtual node and the sphere went through it)."""
        boundary = self.kind.patch_boundary(self.facets, patch, self.nc)
        if self.dim == 3 and self.symmetry_edges.any():
            boundary = boundary & ~self.symmetry_edges
        return boundary

    @property
    def symmetry_edges(self) -> np.ndarray:
        """3D: (nf, edges) True at each candidate facet's edges whose two corners lie on one
        symmetry plane of the body (:func:`~.bodymesh.symmetry_planes`; the planes' facets are
        flat, so such an edge lies in the plane)."""
        if not hasattr(self, "_symmetry_edges"):
            ends = self.kind.edge_nodes(self.facets)  # (nf, edges, 2) candidate numbers
            points = self.nodes[ends]
            out = np.zeros(ends.shape[:2], dtype=bool)
            for nodes, _ in symmetry_planes(self.body):
                out |= np.isin(points, nodes).all(axis=2)
            self._symmetry_edges = out
        return self._symmetry_edges

    def boundary_nodes(self, boundary) -> np.ndarray:
        """(nc,) True at the candidate nodes on a patch boundary (:meth:`patch_boundary`)."""
        return self.kind.boundary_nodes(self.facets, boundary, self.nc)

    def beyond(self, seg: np.ndarray, xi_free: np.ndarray, boundary) -> np.ndarray:
        """Points whose closest point on a patch (boundary ``boundary``) is on its boundary,
        outside the facet ``seg`` there (unclamped ``xi_free``): not over the patch."""
        return self.kind.beyond(self.facets, seg, xi_free, boundary)

    def on_boundary(self, seg: np.ndarray, xi_free: np.ndarray, boundary) -> np.ndarray:
        """Points whose closest point on a patch is one of its boundary vertices (to 1e-9)."""
        return self.kind.on_boundary(self.facets, seg, xi_free, boundary)

    def material_points(self, seg: np.ndarray, interp: np.ndarray) -> np.ndarray:
        """Points on facets ``seg`` (interpolation rows ``interp``) as material points of the
        surface (a friction anchor; 2D: ``facet + t``)."""
        return self.kind.material_points(self.facets, seg, interp)

    def unset_material_points(self, n: int) -> np.ndarray:
        """``n`` material points read nowhere yet: zeros, as :meth:`material_points` has them."""
        return self.kind.material_points(self.facets, np.zeros(n, int), np.zeros((n, self.nc)))

    def material_positions(self, points: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Where the material points ``points`` (:meth:`material_points`) are at positions
        ``x``."""
        return self.kind.material_positions(x, self.facets, points)

    def locate(self, x_tracked: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Rind triangle (3D: tetrahedron) containing each point (current configuration), or -1
        (:func:`~.bodymesh.locate_in_simplices`)."""
        return locate_in_simplices(x_tracked, self.rind, points)

    def quadrature(self, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Gauss points of the virtual elements on each candidate facet: (xi, phi, w), the
        weights times the undeformed length (:func:`.measure.virtual_quadrature`)."""
        return virtual_quadrature(self, order)

    def mass_matrix(self, facet_weight: np.ndarray) -> sp.csr_matrix:
        """Redistribution matrix N* over the facets with nonzero weight (eq. 4.4.10), (nc, nc).

        scikit-fem integrates ``phi phi^T`` on each undeformed candidate facet once; N* for a set
        of facets (the thesis's N*: unloaded facets left out) is the sum of their entries.
        """
        if not hasattr(self, "_mass_entries"):
            self._mass_entries = self._facet_mass_entries()
        facet, rows, cols, vals = self._mass_entries
        return sp.csr_matrix((vals * facet_weight[facet], (rows, cols)), shape=(self.nc, self.nc))

    def _facet_mass_entries(self):
        """(facet, row, col, value) of every nonzero of every facet's mass matrix
        (:func:`.measure.facet_mass_entries`)."""
        return facet_mass_entries(self)


def patch_ends(s: ContactSurface, patch: np.ndarray) -> np.ndarray:
    """(nc,) True at the ends of a patch of facets (vertices on one facet of it): a 2D
    surface's :meth:`ContactSurface.patch_boundary`."""
    return s.patch_boundary(patch)


def beyond(s: ContactSurface, seg: np.ndarray, t_free: np.ndarray, ends: np.ndarray
           ) -> np.ndarray:
    """Points whose closest point on a patch is one of its ends (``ends``), outside the end
    facet's normal strip (``t_free`` off [0, 1]): they are not over the patch
    (:meth:`ContactSurface.beyond`)."""
    return s.beyond(seg, t_free, ends)


