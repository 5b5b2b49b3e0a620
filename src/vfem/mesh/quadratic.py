"""Quadratic (curved-facet) versions of straight-sided meshes.

Quadratic elements on straight facets follow a curved surface only through their vertices: the
midpoints sit on the chords, h^2 / (8 R) inside a circle of radius R. On a contact surface that
recess is seen as a gap, and the nodal pressures alternate between vertices and midpoints
(measured on Hertz with 12 facets across the contact: +-3 %). Putting the midpoints of the curved
boundary on the true curve (isoparametric elements) removes it.
"""

from __future__ import annotations

import numpy as np
from skfem import MeshQuad, MeshQuad2, MeshTet, MeshTet2, MeshTri, MeshTri2

from .topology import share_topology, with_topology


def curved(mesh: MeshTri | MeshQuad | MeshTet, boundary: str, centre: tuple[float, ...],
           radius: float) -> MeshTri2 | MeshQuad2 | MeshTet2:
    """The quadratic-geometry mesh of ``mesh`` with the midpoints of ``boundary``'s facets
    moved onto the circle (``centre``, ``radius``) on which its vertices lie; of a tetrahedral
    mesh (3D, issue 21), the midpoints of the edges of ``boundary``'s triangles moved onto the
    sphere (``centre`` of three coordinates). Straight-sided quadratic tetrahedra on a curved
    contact surface make it a polyhedron, whose creases the quadratic traction resolves: on
    the sphere example at a/4 the corners read 2.3 p0 and the midpoints 0.5-1 p0 (p_max
    +132 %); with the midpoints on the sphere, +1.1 % (``docs/method.md`` §12)."""
    if isinstance(mesh, MeshTet):
        with_topology(mesh)
        m2 = MeshTet2.from_mesh(mesh)
        doflocs = m2.doflocs.copy()
        mid = m2.nvertices + np.unique(m2.f2e[:, mesh.boundaries[boundary]])
        c = np.asarray(centre, dtype=float)[:, None]
        r = doflocs[:, mid] - c
        doflocs[:, mid] = c + radius * r / np.linalg.norm(r, axis=0)
        return share_topology(mesh, MeshTet2(doflocs, m2.t, _boundaries=dict(mesh.boundaries),
                                             sort_t=False))
    if mesh.p.shape[0] != 2:
        raise ValueError("curved: a 2D mesh of triangles or quadrilaterals, or a tetrahedral "
                         "one (quadratic hexahedra are not curved here)")
    quad = MeshTri2 if isinstance(mesh, MeshTri) else MeshQuad2
    with_topology(mesh)  # its facets number the midpoints: built once, kept for the result
    m2 = quad.from_mesh(mesh)  # same vertices, elements and facet numbering
    doflocs = m2.doflocs.copy()
    facets = mesh.boundaries[boundary]
    mid = mesh.nvertices + facets
    c = np.asarray(centre, dtype=float)[:, None]
    r = doflocs[:, mid] - c
    doflocs[:, mid] = c + radius * r / np.linalg.norm(r, axis=0)
    return share_topology(mesh, quad(doflocs, m2.t, _boundaries=dict(mesh.boundaries),
                                     sort_t=False))
