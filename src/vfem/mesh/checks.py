"""Checks of a body's mesh before anything is assembled, whatever made the mesh.

A mesh can be wrong in ways that the solver would only show much later, or not at all: a
stiffness that will not factorize (a node in no element, a piece with nothing holding it), a
crack no one asked for (two nodes at one position, left unmerged by a mesher), elements that
overlap or turn inside out (negative Jacobian). :func:`check_mesh` finds these for any body —
parametric shapes with user parameters, imported files, meshes built in Python — and raises one
:class:`~vfem.errors.InputError` naming the body, the problem, the first offending element or
node with its coordinates, and what to do. :meth:`vfem.bodies.Body.validate` calls it, so
``vfem check``, ``vfem run`` and :meth:`vfem.model.Model.validate` all go through it.

Node numbers in messages are the body's (as in its results files; an imported mesh keeps only
the body's nodes, numbered in their order in the file); the coordinates locate them in any
numbering. The checks, in the order they run (the first failure is reported):

1. coordinates are finite numbers;
2. every node belongs to an element;
3. no element is degenerate (zero area) or inverted within itself (its Jacobian determinant,
   sampled on a lattice of points that holds the corners, changes sign: a twisted or
   non-convex quadrilateral, a curved edge bowed past the element's other side);
4. no two nodes share a position (within 1e-12 of the mesh's size);
5. no element overlaps a neighbour: the two elements of an interior edge lie on opposite sides
   of it (an element folded over its neighbour, e.g. a node moved past the opposite edge, is
   inverted relative to the mesh even when it is fine by itself). Orientation-independent, so
   scikit-fem meshes whose element nodes are sorted (mixed orientation) pass;
6. the elements form one piece (connected through shared nodes).

3D meshes (tetrahedra, hexahedra, and their quadratic forms) go through the same checks: the
Jacobian determinant of the 3 x 3 map (zero volume: below 1e-10 times the longest edge cubed;
a hexahedron's sampled on a 3 x 3 x 3 lattice, a curved element's on a finer one), and the
neighbours of each interior facet (triangle or quadrilateral) on opposite sides of its plane.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from skfem import Mesh, MeshTri

from ..errors import InputError
from .topology import with_topology

#: Two nodes closer than this times the mesh's size are one position (an unmerged mesh).
DUPLICATE_TOLERANCE = 1e-12
#: An element whose Jacobian determinant is below this times its longest edge squared has
#: (locally) no area: a collapsed edge, three corners in a line.
DEGENERATE_TOLERANCE = 1e-10


def check_mesh(mesh: Mesh, where: str) -> None:
    """Raise :class:`InputError` (prefixed ``where``, e.g. ``"body 'flat'"``) at the first
    problem of ``mesh``: see the module docstring for the checks and their order."""
    nv = mesh.nvertices
    p = np.asarray(mesh.p[:, :nv], dtype=float)
    t = np.asarray(mesh.t)
    bad = np.flatnonzero(~np.isfinite(mesh.doflocs).all(axis=0))
    if bad.size:
        raise InputError(f"{where}: node {bad[0]} has coordinates that are not finite numbers "
                         f"({_xy(mesh.doflocs[:, bad[0]])}); check the mesh's parameters or file")
    used = np.zeros(nv, dtype=bool)
    used[t.ravel()] = True
    if not used.all():
        k = int(np.flatnonzero(~used)[0])
        raise InputError(f"{where}: {int((~used).sum())} node(s) belong to no element (the first: "
                         f"node {k} at {_xy(p[:, k])}), so their stiffness is zero; remove them "
                         "from the mesh")
    if p.shape[0] == 3:
        _check_elements_3d(mesh, p, t, where)
    else:
        _check_elements(mesh, p, t, where)
    _check_duplicates(p, where)
    with_topology(mesh)  # scikit-fem's facets and f2t, the same arrays, built faster
    if p.shape[0] == 3:
        _check_folds_3d(mesh, p, where)
    else:
        _check_folds(mesh, p, where)
    _check_pieces(p, t, where)


def _xy(point) -> str:
    """A point as the messages print it: ``(x, y)`` (``(x, y, z)`` in 3D), 6 significant
    digits."""
    return "(" + ", ".join(f"{float(c):.6g}" for c in point) + ")"


def _corners(p: np.ndarray, t: np.ndarray, e: int) -> str:
    return "[" + ", ".join(_xy(p[:, v]) for v in t[:, e]) + "]"


def _reference_lattice(tri: bool, n: int = 4) -> np.ndarray:
    """(2, k) points of the reference element where the Jacobian is sampled: the corners, the
    edge midpoints and a lattice inside (degree ``n``); scikit-fem's reference triangle is
    (0,0), (1,0), (0,1) and its square [0, 1]^2."""
    s = np.arange(n + 1) / n
    X, Y = np.meshgrid(s, s, indexing="ij")
    X, Y = X.ravel(), Y.ravel()
    if tri:
        keep = X + Y <= 1 + 1e-12
        X, Y = X[keep], Y[keep]
    return np.vstack([X, Y])


def _check_elements(mesh: Mesh, p: np.ndarray, t: np.ndarray, where: str) -> None:
    """Degenerate elements (no area somewhere) and elements inverted within themselves."""
    corners = p[:, t]  # (2, nodes, ne)
    with np.errstate(invalid="ignore", over="ignore"):  # coordinates near overflow
        edge2 = np.max([np.sum((corners[:, (i + 1) % len(t)] - corners[:, i]) ** 2, axis=0)
                        for i in range(len(t))], axis=0)
        if type(mesh).__name__ == "MeshTri1":  # affine: one determinant per element
            a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
            det = ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))[:, None]
        else:  # a bilinear quadrilateral's determinant is linear in x and y: its corners do
            lattice = 1 if type(mesh).__name__ == "MeshQuad1" else 4
            X = _reference_lattice(isinstance(mesh, MeshTri), lattice)
            J = mesh._mapping().J  # (scikit-fem's own detDF refuses a zero determinant)
            det = J(0, 0, X) * J(1, 1, X) - J(0, 1, X) * J(1, 0, X)
    _refuse_bad_determinants(det, DEGENERATE_TOLERANCE * edge2[:, None], p, t, where)


def _refuse_bad_determinants(det: np.ndarray, floor: np.ndarray, p: np.ndarray, t: np.ndarray,
                             where: str) -> None:
    """Raise for the first element whose Jacobian determinant ``det`` (ne, points) changes
    sign (inverted), else for the first whose determinant is somewhere within ``floor`` (ne, 1)
    of zero (degenerate)."""
    det = np.where(np.isfinite(det), det, 0.0)  # overflowed: no usable geometry either
    small = np.abs(det) <= floor
    flips = (det.min(axis=1) < 0) & (det.max(axis=1) > 0)
    degenerate = np.flatnonzero(small.any(axis=1) & ~flips)
    inverted = np.flatnonzero(flips)
    solid = p.shape[0] == 3
    if inverted.size:
        e = int(inverted[0])
        raise InputError(
            f"{where}: {inverted.size} element(s) are inverted: the Jacobian changes sign inside "
            f"them (the first: element {e}, corners at {_corners(p, t, e)}): "
            + ("a twisted or non-convex hexahedron (a corner moved past a face), "
               if solid else "a twisted or non-convex quadrilateral, ")
            + "or a curved edge bowed past the element's other side; fix the mesh or the "
            "shape's parameters")
    if degenerate.size:
        e = int(degenerate[0])
        if solid:
            raise InputError(
                f"{where}: {degenerate.size} element(s) have zero volume (the first: element "
                f"{e}, corners at {_corners(p, t, e)}): corners that coincide or lie in a "
                "plane; fix the mesh or the shape's parameters")
        raise InputError(
            f"{where}: {degenerate.size} element(s) have zero area (the first: element {e}, "
            f"corners at {_corners(p, t, e)}): corners that coincide or lie in a line; fix the "
            "mesh or the shape's parameters")


#: Lattice points per element and chunk in the 3D Jacobian check (bounds its memory).
_CHUNK_POINTS = 1 << 20


def _reference_lattice_3d(tet: bool, n: int) -> np.ndarray:
    """(3, k) points of scikit-fem's reference tetrahedron ((0,0,0), (1,0,0), (0,1,0),
    (0,0,1)) or cube [0, 1]^3 where the Jacobian is sampled: a lattice of degree ``n`` holding
    the corners."""
    s = np.arange(n + 1) / n
    X = np.array([a.ravel() for a in np.meshgrid(s, s, s, indexing="ij")])
    if tet:
        X = X[:, X.sum(axis=0) <= 1 + 1e-12]
    return X


def _det3(J: np.ndarray) -> np.ndarray:
    """Determinants of 3 x 3 matrices ``J`` (3, 3, ...)."""
    return (J[0, 0] * (J[1, 1] * J[2, 2] - J[1, 2] * J[2, 1])
            - J[0, 1] * (J[1, 0] * J[2, 2] - J[1, 2] * J[2, 0])
            + J[0, 2] * (J[1, 0] * J[2, 1] - J[1, 1] * J[2, 0]))


def _check_elements_3d(mesh: Mesh, p: np.ndarray, t: np.ndarray, where: str) -> None:
    """:func:`_check_elements` of tetrahedra and hexahedra (straight or curved): the 3 x 3
    Jacobian's determinant, in closed form for linear tetrahedra (one per element), else
    sampled on a reference lattice (trilinear hexahedra: degree 2, 27 points; curved elements:
    degree 4), a chunk of elements at a time."""
    corners = p[:, t]  # (3, nodes, ne)
    name = type(mesh).__name__
    with np.errstate(invalid="ignore", over="ignore"):  # coordinates near overflow
        edge2 = np.max([np.sum((corners[:, j] - corners[:, i]) ** 2, axis=0)
                        for i, j in mesh.elem.refdom.edges], axis=0)
        floor = DEGENERATE_TOLERANCE * edge2[:, None] ** 1.5
        if name == "MeshTet1":  # affine: one determinant per element
            a, b, c, d = (corners[:, k] for k in range(4))
            det = _det3(np.array([b - a, c - a, d - a]).transpose(1, 0, 2))[:, None]
        else:
            X = _reference_lattice_3d(name.startswith("MeshTet"), 2 if name == "MeshHex1" else 4)
            elem = mesh.elem()
            dofs = mesh.dofs.element_dofs  # the geometry's nodes of each element
            dphi = np.array([elem.lbasis(X, k)[1] for k in range(dofs.shape[0])])  # (k, 3, q)
            det = np.empty((t.shape[1], X.shape[1]))
            step = max(1, _CHUNK_POINTS // X.shape[1])
            for start in range(0, t.shape[1], step):
                x = mesh.doflocs[:, dofs[:, start:start + step]]  # (3, k, chunk)
                det[start:start + step] = _det3(np.einsum("ike,kjq->ijeq", x, dphi))
    _refuse_bad_determinants(det, floor, p, t, where)


def _check_duplicates(p: np.ndarray, where: str) -> None:
    """Two nodes at one position: elements on either side of them are not connected."""
    size = float(np.max(np.ptp(p, axis=1))) if p.shape[1] else 0.0
    pairs = cKDTree(p.T).query_pairs(DUPLICATE_TOLERANCE * max(size, 1e-300),
                                     output_type="ndarray")
    if len(pairs):
        pairs = np.sort(pairs, axis=1)
        i, j = (int(v) for v in pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))][0])
        raise InputError(
            f"{where}: {len(pairs)} pair(s) of nodes at the same position (the first: nodes {i} "
            f"and {j}, at {_xy(p[:, i])}): an unmerged mesh, with a crack between the elements "
            "on either side; merge the duplicate nodes (gmsh: Coherence) or give each piece its "
            "own body")


def _check_folds(mesh: Mesh, p: np.ndarray, where: str) -> None:
    """Neighbours on the same side of their shared edge: one of them is folded over the other."""
    f2t = mesh.f2t
    interior = np.flatnonzero(f2t[1] >= 0)
    if not interior.size:
        return
    a, b = p[:, mesh.facets[0, interior]], p[:, mesh.facets[1, interior]]
    centre = p[:, mesh.t].mean(axis=1)  # (2, ne)

    def side(e):
        c = centre[:, e]
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    folded = np.flatnonzero(side(f2t[0, interior]) * side(f2t[1, interior]) > 0)
    if folded.size:
        f = int(interior[folded[0]])
        e1, e2 = (int(e) for e in f2t[:, f])
        raise InputError(
            f"{where}: {folded.size} pair(s) of neighbouring elements overlap: an inverted "
            f"(folded) element (the first: elements {e1} and {e2} lie on the same side of their "
            f"shared edge from {_xy(p[:, mesh.facets[0, f]])} to {_xy(p[:, mesh.facets[1, f]])}); "
            "fix the mesh or the shape's parameters")


def _check_folds_3d(mesh: Mesh, p: np.ndarray, where: str) -> None:
    """:func:`_check_folds` in 3D: the two elements of an interior facet (triangle or
    quadrilateral) on the same side of its plane (normal: the cross product of a triangle's
    sides, of a quadrilateral's diagonals; origin: the facet's centroid)."""
    f2t = mesh.f2t
    interior = np.flatnonzero(f2t[1] >= 0)
    if not interior.size:
        return
    x = p[:, mesh.facets[:, interior]]  # (3, k, nf)
    if x.shape[1] == 3:
        n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], axis=0)
    else:  # facets in cyclic order (scikit-fem's hexahedra keep it)
        n = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1], axis=0)
    origin = x.mean(axis=1)
    centre = p[:, mesh.t].mean(axis=1)  # (3, ne)

    def side(e):
        return np.einsum("ij,ij->j", n, centre[:, e] - origin)

    folded = np.flatnonzero(side(f2t[0, interior]) * side(f2t[1, interior]) > 0)
    if folded.size:
        f = int(interior[folded[0]])
        e1, e2 = (int(e) for e in f2t[:, f])
        corners = ", ".join(_xy(p[:, v]) for v in mesh.facets[:, f])
        raise InputError(
            f"{where}: {folded.size} pair(s) of neighbouring elements overlap: an inverted "
            f"(folded) element (the first: elements {e1} and {e2} lie on the same side of their "
            f"shared face with corners at [{corners}]); fix the mesh or the shape's parameters")


def _check_pieces(p: np.ndarray, t: np.ndarray, where: str) -> None:
    """Elements not connected through shared nodes: a body must be one piece."""
    nv, ne = p.shape[1], t.shape[1]
    rows = np.repeat(np.arange(ne), t.shape[0])
    incidence = sp.csr_matrix((np.ones(rows.size), (rows, t.T.ravel())), shape=(ne, nv))
    graph = sp.bmat([[None, incidence], [incidence.T, None]], format="csr")
    count, labels = connected_components(graph, directed=False)
    if count > 1:
        element_label = labels[:ne]
        sizes = np.bincount(element_label, minlength=count)
        smallest = int(np.argmin(np.where(sizes > 0, sizes, ne + 1)))
        node = int(np.flatnonzero(labels[ne:] == smallest)[0])
        raise InputError(
            f"{where}: the mesh is {count} separate pieces (elements not connected through "
            f"shared nodes); the smallest, {int(sizes[smallest])} element(s), has node {node} at "
            f"{_xy(p[:, node])}. A piece that nothing holds makes the stiffness singular: give "
            "each piece its own body, or merge the nodes where the pieces should join")
