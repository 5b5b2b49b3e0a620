"""A body's mesh as finite elements: the element of each displacement component, the points that
carry the dofs and their numbering (scikit-fem's), the facets' points, and VTK's cells for the
output."""

from __future__ import annotations

import numpy as np
from skfem import (
    Basis,
    ElementHex1,
    ElementHex2,
    ElementQuad1,
    ElementQuad2,
    ElementTetP1,
    ElementTetP2,
    ElementTriP1,
    ElementTriP2,
    ElementVector,
    MeshHex,
    MeshTet,
    MeshTri,
)
from skfem.assembly import Dofs
from skfem.io.meshio import HEX_MAPPING
from skfem.mesh.mesh_2d_2 import Mesh2D2

from .assembly import cell_mapping

#: The displacement components by name; a body has the first ``dim`` of them (``Body.dim``).
COMPONENTS = {"x": 0, "y": 1, "z": 2}
AXES = tuple(COMPONENTS)

#: The meshes a body accepts (scikit-fem's classes by name): 2D triangles and quadrilaterals,
#: 3D tetrahedra and hexahedra, each with straight (1) or curved (2: quadratic geometry) sides.
MESHES = ("MeshTri1", "MeshQuad1", "MeshTri2", "MeshQuad2",
          "MeshTet1", "MeshHex1", "MeshTet2", "MeshHex2")
#: The meshes whose own nodes are the quadratic element's points (curved geometry).
_QUADRATIC_GEOMETRY = ("MeshTet2", "MeshHex2")

#: Node permutations that mirror a VTK cell (turn a negative volume positive): a tetrahedron's
#: nodes 1 and 2 swapped, a hexahedron's bottom and top faces swapped, with their edge and face
#: nodes.
_VTK_MIRROR = {
    "tetra": [0, 2, 1, 3],
    "tetra10": [0, 2, 1, 3, 6, 5, 4, 7, 9, 8],
    "hexahedron": [4, 5, 6, 7, 0, 1, 2, 3],
    "hexahedron27": [4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11, 16, 17, 18, 19,
                     20, 21, 22, 23, 25, 24, 26],
}


def element(body):
    """The scalar scikit-fem element of each displacement component."""
    if isinstance(body.mesh, MeshTet):
        return ElementTetP2() if body.order == 2 else ElementTetP1()
    if isinstance(body.mesh, MeshHex):
        return ElementHex2() if body.order == 2 else ElementHex1()
    tri = isinstance(body.mesh, MeshTri)
    if body.order == 2:
        return ElementTriP2() if tri else ElementQuad2()
    return ElementTriP1() if tri else ElementQuad1()


def points(body) -> np.ndarray:
    """(dim, npoints) coordinates of the element nodes (see :class:`~vfem.bodies.Body`)."""
    mesh = body.mesh
    if body.order == 1:
        return mesh.p[:, : mesh.nvertices]
    if isinstance(mesh, Mesh2D2) or type(mesh).__name__ in _QUADRATIC_GEOMETRY:
        return mesh.doflocs  # curved (quadratic) geometry: its nodes are the points
    if body.dim == 3:  # scikit-fem's dofs: vertices, edges, (hexahedra) facets, elements
        parts = [mesh.p, mesh.p[:, mesh.edges].mean(axis=1)]
        if isinstance(mesh, MeshHex):
            parts += [mesh.p[:, mesh.facets].mean(axis=1), mesh.p[:, mesh.t].mean(axis=1)]
        return np.hstack(parts)
    parts = [mesh.p, mesh.p[:, mesh.facets].mean(axis=1)]
    if not isinstance(mesh, MeshTri):
        parts.append(mesh.p[:, mesh.t].mean(axis=1))
    return np.hstack(parts)


def facet_points(body, facets: np.ndarray) -> np.ndarray:
    """(nf, k) points of the given facets: the two vertices, then (order 2) the midpoint.
    In 3D the facet's 3 or 4 vertices (``mesh.facets``), then (order 2) its edges' middles
    (in the order of ``mesh.f2e``: the facet's edges 0-1, 1-2, then 0-2 of a triangle,
    2-3 and 0-3 of a quadrilateral) and a quadrilateral's centre."""
    mesh = body.mesh
    fp = mesh.facets[:, facets].T
    if body.order == 2:
        if body.dim == 3:
            facets = np.asarray(facets)
            cols = [fp, mesh.nvertices + mesh.f2e[:, facets].T]
            if isinstance(mesh, MeshHex):
                cols.append(mesh.nvertices + mesh.edges.shape[1] + facets)
            return np.column_stack(cols)
        fp = np.column_stack([fp, body.mesh.nvertices + np.asarray(facets)])
    return fp


def cells(body) -> tuple[str, np.ndarray]:
    """VTK cell type and (nelements, k) point connectivity, in VTK's node order (after
    :func:`~.condensation.setup`). In 3D: ``tetra``, ``hexahedron``, ``tetra10`` or ``hexahedron27``
    (scikit-fem's hexahedron nodes reordered by ``skfem.io.meshio.HEX_MAPPING``), each cell
    with a positive volume in VTK's convention (a mirrored element's nodes listed
    mirrored)."""
    if body.dim == 3:
        return cells_3d(body)
    tri = isinstance(body.mesh, MeshTri)
    if body.order == 1:
        return ("triangle" if tri else "quad"), body.mesh.t.T
    # scikit-fem's element dofs (x of point k is dof 2k): vertices, then facets in VTK's edge
    # order, then the centre
    conn = body.dof_map.element_dofs[::2].T // 2
    return ("triangle6" if tri else "quad9"), conn


def cells_3d(body) -> tuple[str, np.ndarray]:
    """:func:`cells` of a 3D body."""
    mesh, tet = body.mesh, isinstance(body.mesh, MeshTet)
    if body.order == 1:
        kind = "tetra" if tet else "hexahedron"
        conn = mesh.t if tet else mesh.t[HEX_MAPPING[:8]]
    else:  # scikit-fem's element dofs (x of point k is dof 3k): vertices, edges, ...
        kind = "tetra10" if tet else "hexahedron27"
        conn = body.dof_map.element_dofs[::3] // 3
        conn = conn if tet else conn[HEX_MAPPING]
    conn = np.ascontiguousarray(conn.T)
    x = body.points[:, conn[:, :8 if not tet else 4]]  # (3, ne, corners)
    if tet:
        a, b, c = x[:, :, 1] - x[:, :, 0], x[:, :, 2] - x[:, :, 0], x[:, :, 3] - x[:, :, 0]
    else:  # the trilinear map's Jacobian at the centre, VTK's corner order
        a = (x[:, :, [1, 2, 5, 6]] - x[:, :, [0, 3, 4, 7]]).sum(axis=2)
        b = (x[:, :, [2, 3, 6, 7]] - x[:, :, [1, 0, 5, 4]]).sum(axis=2)
        c = (x[:, :, [4, 5, 6, 7]] - x[:, :, [0, 1, 2, 3]]).sum(axis=2)
    volume = np.einsum("ie,ie->e", np.cross(a, b, axis=0), c)
    mirrored = volume < 0
    if mirrored.any():
        conn[mirrored] = conn[mirrored][:, _VTK_MIRROR[kind]]
    return kind, conn


def basis(body) -> Basis:
    """scikit-fem's ``CellBasis`` of the body's vector element. A 2D body builds it in
    :func:`~.condensation.assemble` and keeps it; a 3D body's assembly and strains work a chunk of
    elements at a time (:func:`~vfem.bodies.assembly.cell_gradients`) and keep none, since
    the whole basis takes more memory than the factorization (147 KB per trilinear
    hexahedron: the million-dof sphere was killed building it), so here it is built on
    first use, for callers that want scikit-fem's view of the body."""
    basis = body.__dict__.get("_basis")
    if basis is None:
        mapping = cell_mapping(body.mesh) if body.dim == 3 else None
        basis = body._basis = Basis(body.mesh, ElementVector(body.element()),
                                    mapping=mapping)
    return basis


def dof_map(body) -> Dofs:
    """scikit-fem's numbering of the body's dofs (the vector element's), as its basis has
    it, without the basis."""
    if not hasattr(body, "_dof_map"):
        body._dof_map = Dofs(body.mesh, ElementVector(body.element()))
    return body._dof_map
