"""What contact reads of a body's mesh: the facets that may take part in contact and the
symmetry planes, its elements as simplices (quadrilaterals in two triangles, hexahedra in six
tetrahedra) and their volumes, and the points located in them (the rind's check, thesis §4.3:
a node must not pass the other body's outer layer of elements).
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.spatial import cKDTree
from skfem import MeshHex, MeshTet, MeshTri

from ...bodies import Body
from ...mesh.checks import _corners
from .kept import Kept


def symmetry_planes(body) -> list[tuple[np.ndarray, int]]:
    """A 3D body's symmetry planes (:meth:`~vfem.bodies.Body.symmetry_planes`) as the mesh
    nodes on each and its axis."""
    return [(np.unique(body.mesh.facets[:, facets]), axis)
            for facets, axis in body.symmetry_planes()]


def exterior_facets(body: Body) -> np.ndarray:
    """Facets of the body that may take part in contact (indices into ``mesh.facets``)."""
    mesh = body.mesh
    if body.contact_boundaries is not None:
        bnd = np.unique(np.concatenate([np.zeros(0, dtype=np.int64)] + [
            mesh.boundaries[b] for b in body.contact_boundaries])).astype(np.int64)
    else:
        bnd = mesh.boundary_facets()
        excluded = [mesh.boundaries[s.boundary] for s in body.supports]
        excluded += [mesh.boundaries[p.boundary] for p in body.prescribed]
        if body.platen is not None:
            excluded.append(mesh.boundaries[body.platen.boundary])
        if excluded:
            bnd = np.setdiff1d(bnd, np.concatenate(excluded))
    # a body of revolution's axis bounds its section, not the body (Section.not_surface)
    return bnd[~body.section.not_surface(mesh, bnd)]


def _most_distorted(mesh, facet_ids: np.ndarray) -> str:
    """The element behind ``facet_ids`` with the largest ratio of its longest to its shortest
    edge, named with its corners: for an error message."""
    elem = np.unique(mesh.f2t[0, facet_ids])
    corners = mesh.p[:, mesh.t[:, elem]]  # (2, nv, ne)
    edges = np.linalg.norm(np.roll(corners, -1, axis=1) - corners, axis=0)  # (nv, ne)
    ratio = edges.max(axis=0) / np.maximum(edges.min(axis=0), 1e-300)
    k = int(np.argmax(ratio))
    return (f"element {int(elem[k])} (corners at {_corners(mesh.p, mesh.t, int(elem[k]))}; "
            f"edges in ratio {ratio[k]:.3g})")


def triangles(t: np.ndarray) -> np.ndarray:
    """(n, 3) triangles of elements ``t`` (vertices, n): quadrilaterals split in two."""
    if t.shape[0] == 4:
        t = np.hstack([t[[0, 1, 3]], t[[1, 2, 3]]])
    return t.T.copy()


def _kuhn_tets() -> np.ndarray:
    """(6, 4) local vertex numbers of the six tetrahedra of a scikit-fem hexahedron around its
    diagonal from reference corner (0, 0, 0) to (1, 1, 1) (Kuhn's split)."""
    from skfem.refdom import RefHex

    index = {tuple(int(v) for v in c): k for k, c in enumerate(RefHex.p.T)}
    out = []
    for perm in itertools.permutations(range(3)):
        c = [0, 0, 0]
        path = [index[tuple(c)]]
        for axis in perm:
            c[axis] = 1
            path.append(index[tuple(c)])
        out.append(path)
    return np.array(out)


def simplices(mesh, t: np.ndarray) -> np.ndarray:
    """(n, 4) tetrahedra of 3D elements ``t`` (vertices, n) of ``mesh``: tetrahedra as they
    are, hexahedra split in six (:func:`_kuhn_tets`; the 3D :func:`triangles`)."""
    if isinstance(mesh, MeshHex):
        return np.vstack([t[k].T for k in _kuhn_tets()])
    return t[:4].T.copy()


def mesh_simplices(mesh) -> np.ndarray:
    """Every element of ``mesh`` as simplices (its vertices' numbers): triangles in 2D
    (:func:`triangles`), tetrahedra in 3D (:func:`simplices`)."""
    if mesh.p.shape[0] == 2:
        return triangles(mesh.t)
    return simplices(mesh, mesh.t)


def element_volumes(mesh, elem: np.ndarray) -> np.ndarray:
    """(len(elem),) volumes of 3D elements ``elem`` of ``mesh`` (its geometry: straight
    tetrahedra, trilinear hexahedra) by scikit-fem's quadrature of det J, exact for both."""
    from skfem import Basis, ElementHex1, ElementTetP1

    elem = np.asarray(elem, dtype=np.int64)
    if not len(elem):
        return np.zeros(0)
    uniq, inverse = np.unique(elem, return_inverse=True)
    hexa = isinstance(mesh, MeshHex)
    basis = Basis(mesh, ElementHex1() if hexa else ElementTetP1(), elements=uniq,
                  intorder=3 if hexa else 1)
    return basis.dx.sum(axis=1)[inverse.ravel()]


def locate_in_triangles(x: np.ndarray, tri: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The triangle (row of ``tri``, (nt, 3) numbers of the positions ``x`` (n, 2)) containing
    each of ``points`` (m, 2), or -1 (points on an edge count as inside): the 2D
    :func:`locate_in_simplices`."""
    return locate_in_simplices(x, tri, points)


def locate_in_simplices(x: np.ndarray, tri: np.ndarray, points: np.ndarray,
                        keep: bool = False) -> np.ndarray:
    """The simplex (row of ``tri``, (nt, dim + 1) numbers of the positions ``x`` (n, dim))
    containing each of ``points`` (m, dim), or -1: triangles in 2D, tetrahedra in 3D (points
    on an edge or a face count as inside: every barycentric coordinate >= -1e-12).

    Uses scikit-fem's affine mapping of the simplices (``MeshTri``, ``MeshTet``): the inverse
    map gives a point's local coordinates in a simplex. Nearby simplices (by centroid) are
    tried first; points they do not contain are tried against every simplex whose centroid is
    close enough for it to hold them, since elements may be long and thin.

    ``keep``: keep the simplices' search structures for the next call on the same ones
    (:func:`_simplex_search`; let go by :func:`forget_simplex_sets`).
    """
    found = np.full(len(points), -1)
    if len(points) == 0 or len(tri) == 0:
        return found
    three = x.shape[1] == 3
    mapping, centres, tree, reach = _simplex_search(x, tri, keep)

    def inside(tind, pts):
        loc = mapping.invF(pts.T[:, :, None], tind=tind)[:, :, 0]
        eps = 1e-12
        if three:
            return ((loc[0] >= -eps) & (loc[1] >= -eps) & (loc[2] >= -eps)
                    & (1 - loc[0] - loc[1] - loc[2] >= -eps))
        return (loc[0] >= -eps) & (loc[1] >= -eps) & (1 - loc[0] - loc[1] >= -eps)

    k = min(6, len(tri))
    _, near = tree.query(points, k)
    near = near.reshape(len(points), k)
    for j in range(k):
        hit = inside(near[:, j], points) & (found < 0)
        found[hit] = near[hit, j]
    # the rest: every triangle whose centre is close enough for it to hold the point (within
    # the largest centre-to-corner distance of any triangle), a few points at a time
    rest = np.flatnonzero(found < 0)
    for lo in range(0, len(rest), 16):
        idx = rest[lo:lo + 16]
        lists = tree.query_ball_point(points[idx], reach)
        counts = np.fromiter(map(len, lists), dtype=int, count=len(idx))
        cand = np.fromiter(itertools.chain.from_iterable(lists), dtype=int,
                           count=int(counts.sum()))
        owner = np.repeat(idx, counts)
        if len(cand):
            hit = inside(cand, points[owner])
            found[owner[hit]] = cand[hit]  # any triangle that holds the point
    return found


#: the simplex sets whose search structures :func:`_simplex_search` keeps (the last ones)
SIMPLEX_SETS_KEPT = 2
_simplex_sets = Kept(SIMPLEX_SETS_KEPT)


def _simplex_search(x: np.ndarray, tri: np.ndarray, keep: bool) -> tuple:
    """What :func:`locate_in_simplices` searches ``tri`` at ``x`` with: scikit-fem's affine
    mapping of the simplices, their centroids, a KD-tree of those and the largest
    centre-to-corner distance. With ``keep``, kept for the last :data:`SIMPLEX_SETS_KEPT` sets
    (:class:`~.kept.Kept`) until :func:`forget_simplex_sets`: the candidate search asks about
    the same body mesh at every sampled load factor (17 times in ``vfem run cattaneo3d``,
    0.8 s rebuilding them; issue 40)."""
    x, tri = np.asarray(x, dtype=float), np.asarray(tri)

    def make():
        mesh = (MeshTet if x.shape[1] == 3 else MeshTri)(x.T.copy(), tri.T.copy(),
                                                          sort_t=False, validate=False)
        centres = x[tri].mean(axis=1)
        reach = float(np.linalg.norm(x[tri] - centres[:, None], axis=2).max()) * (1 + 1e-9)
        return mesh._mapping(), centres, cKDTree(centres), reach

    return _simplex_sets.get((x, tri), make, keep)


def forget_simplex_sets() -> None:
    """Let go of the search structures :func:`_simplex_search` keeps (a body mesh's every
    simplex: some 200 MB at a million dofs), once the searches that reuse them are done."""
    _simplex_sets.clear()
