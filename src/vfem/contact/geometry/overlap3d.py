"""Overlap quadrature for the exact transfer in 3D (issue 21, item 3; plan C8).

The 3D counterpart of the point generation in
:func:`vfem.contact.geometry.transfer.transfer_matrices`: quadrature points on the part of each
facet of the *compatibility* side that lies over the *opposing* (equilibrium) side, with the
opposing facet and local coordinates of each point, so that one point set integrates both

* ``N[i, k] = int phi_i(y) phi_k(y) dy`` (the compatibility side with itself, eq. 4.4.11) and
* ``T[c, k] = int psi_c(pi(y)) phi_k(y) dy`` (the opposing side's shape functions at the
  projection ``pi(y)`` against the compatibility side's),

with the same meaning and the same layout as in 2D: ``N`` is (compatibility nodes)², ``T`` has
the **opposing** side's nodes as rows and the compatibility side's as columns. Since the
opposing shape functions sum to one at every point, ``sum_c T[c, k] = sum_i N[i, k]`` to
round-off for any geometry (the two sides' forces ``N q`` and ``-T q`` balance), and where the
rule is exact a uniform traction crosses non-matching meshes exactly.

:func:`transfer_matrices` reaches it through the ``Triangle``/``Quad`` facet kinds'
``overlap_quadrature`` (:mod:`vfem.contact.geometry.facets`, plan C8), which keeps the points and
the compatibility side's local coordinates and weights.

**Facets.** Linear triangles ``(nf, 3)`` and bilinear quadrilaterals ``(nf, 4)``, one kind per
surface, corners numbered around the facet (either way: a compatibility facet's frame follows
its own numbering, and an opposing facet's image may run either way round); local coordinates
are scikit-fem's: ``RefTri`` (0,0), (1,0), (0,1) with shape functions ``1 - xi - eta, xi,
eta``; ``RefQuad`` [0, 1]² with ``(1-xi)(1-eta), xi(1-eta), xi eta, (1-xi) eta``.

**Projection: along the compatibility facet's normal.** Each compatibility facet ``f`` gets a
plane (through its centroid, normal ``n_f``: the triangle's normal, for a quadrilateral that of
its diagonals' cross product) and an in-plane orthonormal frame. The opposing facet's corners
are projected orthogonally onto that plane (along ``n_f``), and everything after that is 2D in
the frame: the clipping, the triangulation, the points, and the local coordinates on both
sides (the compatibility facet's own map is projected onto its plane too, which changes nothing
for a flat facet). This is the transfer's ``pi`` for a **flat interface**: there the opposing
facets lie in (or parallel to) the compatibility plane, the orthogonal projection is the
closest-point map, the projected opposing facets tile the compatibility facet without gap or
overlap (neighbours share projected corners and edges), and every polygon is exact. It is one
normal per compatibility facet, not the opposing side's nodal normals of the 2D cuts (the
variant in the plan's §3.1): on a curved interface two neighbouring compatibility facets
project the opposing side along different normals, so their overlaps may cross or leave a
sliver along their common edge, as wide as the opposing corners' distance from the plane times
the angle between the normals — with the surfaces touching, O(h³ kappa²) for facets of size h
on a curvature kappa: second order, as 2D on curves — while ``sum_c T = sum_i N`` holds to
round-off anyway.

**Clipping.** Sutherland–Hodgman of the projected opposing polygon (convex: a triangle, or a
convex quadrilateral) against the half-planes of the convex compatibility facet, all pairs at
once, one numpy pass per compatibility edge (3 or 4 passes) on a buffer as wide as the largest
polygon so far. The overlap is then convex and fanned into triangles from its first vertex;
sub-triangles below ``1e-14`` of their compatibility facet's area are dropped.

**Gauss rule: exact for the integrand.** On a sub-triangle, for flat parallelogram (or triangle)
facets, local coordinates are affine functions of the in-plane position, so a P1 shape function
is a polynomial of degree 1 and a Q1 one of degree 2 there. ``N`` integrates ``phi phi`` and
``T`` ``phi psi``, of degree ``deg_c + max(deg_c, deg_o)``: 2 for triangles against triangles,
3 for triangles against quadrilaterals, 4 with a quadrilateral compatibility side. Degree 2 uses
the 3-point rule at (1/6, 1/6, 2/3) (weights 1/3); 3 and 4 use Radon's 7-point degree-5 rule (the
6-point degree-4 rule has no closed form as simple; every weight is positive in both), whose
points and weights are written in closed form so the rule is exact to round-off. Non-parallelogram
quadrilaterals have a rational inverse map, for which no polynomial rule is exact: still balanced
(``sum_c T = sum_i N``) and the overlap areas still exact, the transfer of a uniform traction then
accurate to the rule's order only.

**Local coordinates** at each point: on triangles by the affine inverse (exact); on
quadrilaterals by Newton's iteration on the projected bilinear map, started from the
parallelogram of corners 0, 1, 3 (exact on a parallelogram, where no step is taken; else at
most 25 steps, to 1e-15 in the reference square). The **weight** is the area measure on the
compatibility facet: the plane's area, times ``|x_xi x x_eta| / |det J_plane|`` at the point on
a quadrilateral (1 on a flat one; the facet's true surface measure on a warped one). Undeformed
positions give the nominal measure, as 2D.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

#: sub-triangles (and overlaps) smaller than this fraction of their compatibility facet's area
#: are dropped: slivers and segments where two facets only touch
SLIVER = 1e-14

# Gauss rules on a triangle in barycentric coordinates, weights summing to 1 (times the area)
_RULE2 = (np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]]),
          np.full(3, 1 / 3))
_S15 = np.sqrt(15.0)
_A, _B = (6 - _S15) / 21, (6 + _S15) / 21
_WA, _WB = (155 - _S15) / 1200, (155 + _S15) / 1200
_RULE5 = (np.array([[1 / 3, 1 / 3, 1 / 3],
                    [1 - 2 * _A, _A, _A], [_A, 1 - 2 * _A, _A], [_A, _A, 1 - 2 * _A],
                    [1 - 2 * _B, _B, _B], [_B, 1 - 2 * _B, _B], [_B, _B, 1 - 2 * _B]]),
          np.array([9 / 40, _WA, _WA, _WA, _WB, _WB, _WB]))


def shape_values(xi: np.ndarray, corners: int) -> np.ndarray:
    """Linear (3 corners) or bilinear (4) shape functions at local coordinates ``xi`` (q, 2):
    (q, corners), scikit-fem's ``RefTri`` / ``RefQuad`` order."""
    x, y = xi[:, 0], xi[:, 1]
    if corners == 3:
        return np.stack([1 - x - y, x, y], axis=1)
    if corners == 4:
        return np.stack([(1 - x) * (1 - y), x * (1 - y), x * y, (1 - x) * y], axis=1)
    raise ValueError(f"facets of {corners} corners: 3 (triangles) or 4 (quadrilaterals)")


def _bilinear(corners: np.ndarray):
    """The facet map ``x = c0 + xi a + eta b + xi eta c`` of corners (p, k, d): (c0, a, b, c),
    each (p, d); ``c`` = 0 for triangles (corners 0, 1, 2) and parallelograms."""
    c0 = corners[:, 0]
    if corners.shape[1] == 3:
        return c0, corners[:, 1] - c0, corners[:, 2] - c0, np.zeros_like(c0)
    return (c0, corners[:, 1] - c0, corners[:, 3] - c0,
            c0 - corners[:, 1] + corners[:, 2] - corners[:, 3])


def _degree(corners: int) -> int:
    return 1 if corners == 3 else 2


def _inverse_map(corners2d: np.ndarray, row: np.ndarray, p: np.ndarray,
                 iterations: int = 25) -> np.ndarray:
    """Local coordinates (q, 2) of points ``p`` (q, 2) in the 2D facets ``corners2d[row]``
    ((f, k, 2), ``row`` (q,)): the affine inverse for triangles (exact), Newton on the bilinear
    map for quadrilaterals, started from the parallelogram on corners 0, 1, 3 (exact there)."""
    c0, a, b, c = (v[row] for v in _bilinear(corners2d))

    def solve(j0, j1, r):  # [j0 j1]^-1 r, column by column
        det = j0[:, 0] * j1[:, 1] - j0[:, 1] * j1[:, 0]
        det = np.where(det == 0.0, 1.0, det)  # a facet seen edge-on: its points carry no area
        return np.stack([(r[:, 0] * j1[:, 1] - r[:, 1] * j1[:, 0]) / det,
                         (j0[:, 0] * r[:, 1] - j0[:, 1] * r[:, 0]) / det], axis=1)

    xi = solve(a, b, p - c0)
    if corners2d.shape[1] == 3:
        return xi
    todo = np.flatnonzero(np.abs(c).max(axis=1) > 0)  # parallelograms: already exact
    for _ in range(iterations):
        if not len(todo):
            break
        x, e, ct = xi[todo, :1], xi[todo, 1:], c[todo]
        res = c0[todo] + x * a[todo] + e * b[todo] + (x * e) * ct - p[todo]
        step = solve(a[todo] + e * ct, b[todo] + x * ct, res)
        xi[todo] -= step
        todo = todo[np.abs(step).max(axis=1) > 1e-15]
    return xi


def _frames(points: np.ndarray, facets: np.ndarray):
    """Each facet's plane: origin (its centroid), unit normal and in-plane unit axes (nf, 3)."""
    X = points[facets]
    origin = X.mean(axis=1)
    if facets.shape[1] == 3:
        n = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
    else:
        n = np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 1])
    n /= np.linalg.norm(n, axis=1)[:, None]
    t = X[:, 1] - X[:, 0]
    t -= np.einsum("fd,fd->f", t, n)[:, None] * n
    e1 = t / np.linalg.norm(t, axis=1)[:, None]
    e2 = np.cross(n, e1)
    return origin, n, e1, e2


def _in_plane(X: np.ndarray, origin: np.ndarray, e1: np.ndarray, e2: np.ndarray) -> np.ndarray:
    """Coordinates (p, k, 2) of points X (p, k, 3) projected orthogonally on each pair's plane."""
    r = X - origin[:, None, :]
    return np.stack([np.einsum("pkd,pd->pk", r, e1), np.einsum("pkd,pd->pk", r, e2)], axis=2)


def _clip(subject: np.ndarray, clip: np.ndarray):
    """Sutherland–Hodgman, all pairs at once: ``subject`` (p, ks, 2) convex polygons clipped by
    the convex counter-clockwise ``clip`` (p, kc, 2). Returns vertices (p, w, 2) and counts (p,)
    (rows beyond a count are padding)."""
    p = len(subject)
    V = subject.copy()
    count = np.full(p, subject.shape[1])
    rows = np.arange(p)[:, None]
    kc = clip.shape[1]
    for j in range(kc):
        if not p:
            break
        a = clip[:, j][:, None, :]
        ab = clip[:, (j + 1) % kc][:, None, :] - a
        w = V.shape[1]
        k = np.arange(w)[None, :]
        valid = k < count[:, None]
        nxt = np.where(k + 1 < count[:, None], k + 1, 0)
        d = ab[..., 0] * (V[..., 1] - a[..., 1]) - ab[..., 1] * (V[..., 0] - a[..., 0])
        dn = d[rows, nxt]
        inside, inside_next = d >= 0, dn >= 0
        keep = valid & inside
        cross = valid & (inside != inside_next)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(cross, d / (d - dn), 0.0)
        hit = V + t[..., None] * (V[rows, nxt] - V)
        # per edge: the current vertex (if inside), then the crossing (if any), in order
        cand = np.stack([V, hit], axis=2).reshape(p, 2 * w, 2)
        take = np.stack([keep, cross], axis=2).reshape(p, 2 * w)
        count = take.sum(axis=1)
        pos = np.cumsum(take, axis=1) - 1
        out = np.zeros((p, max(int(count.max(initial=0)), 1), 2))
        r, c = np.nonzero(take)
        out[r, pos[r, c]] = cand[r, c]
        V = out
    return V, count


@dataclass(frozen=True)
class OverlapQuadrature:
    """Quadrature points on the overlap of a compatibility surface with an opposing one.

    One entry per point: ``weight`` (area measure on the compatibility facet),
    ``comp_facet`` / ``comp_xi`` (the compatibility facet and local coordinates, (q,), (q, 2)),
    ``opp_facet`` / ``opp_xi`` (the opposing facet whose projection holds the point and the
    local coordinates there), ``pair`` (the row of the candidate pairs it came from) and
    ``x`` (q, 3), the point on the compatibility facet's plane.
    """

    weight: np.ndarray
    comp_facet: np.ndarray
    comp_xi: np.ndarray
    opp_facet: np.ndarray
    opp_xi: np.ndarray
    pair: np.ndarray
    x: np.ndarray


def overlap_quadrature(comp_points: np.ndarray, comp_facets: np.ndarray,
                       opp_points: np.ndarray, opp_facets: np.ndarray, pairs: np.ndarray,
                       max_distance: float | None = None, degree: int | None = None
                       ) -> OverlapQuadrature:
    """Quadrature points of the overlap of each candidate pair (compatibility facet, opposing
    facet), ``pairs`` (p, 2): the opposing facet projected along the compatibility facet's
    normal onto its plane, clipped by the compatibility facet, fanned into triangles and given
    a Gauss rule exact for ``phi_c phi_c`` and ``phi_c psi_o`` (module docstring).

    ``max_distance``: a pair whose opposing corners lie farther than this from the
    compatibility plane (either side) gives no point (2D's ``reach``). Pairs are the caller's
    choice otherwise (:func:`candidate_pairs` finds those whose facets may overlap; facing and
    the patch boundary are the pairing's); a pair listed twice counts twice.

    ``degree``: the degree the rule must integrate exactly, when the facets given are linear
    pieces of quadratic ones (their shape functions of degree 2 in the pieces' coordinates:
    4, Radon's degree-5 rule); default from the corners (module docstring).
    """
    comp_points = np.asarray(comp_points, float)
    opp_points = np.asarray(opp_points, float)
    comp_facets = np.asarray(comp_facets)
    opp_facets = np.asarray(opp_facets)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    kc, ko = comp_facets.shape[1], opp_facets.shape[1]
    for k in (kc, ko):
        if k not in (3, 4):
            raise ValueError(f"facets of {k} corners: 3 (triangles) or 4 (quadrilaterals)")
    origin, n, e1, e2 = _frames(comp_points, comp_facets)
    fc, fo = pairs[:, 0], pairs[:, 1]
    O3 = opp_points[opp_facets[fo]]
    if max_distance is not None:
        h = np.einsum("pkd,pd->pk", O3 - origin[fc][:, None, :], n[fc])
        near = np.abs(h).max(axis=1) <= max_distance
        fc, fo, O3 = fc[near], fo[near], O3[near]
    pair_id = np.nonzero(near)[0] if max_distance is not None else np.arange(len(fc))
    o, u, v = origin[fc], e1[fc], e2[fc]
    C = _in_plane(comp_points[comp_facets[fc]], o, u, v)
    B = _in_plane(O3, o, u, v)
    V, count = _clip(B, C)
    # the fan from each polygon's first vertex; every sub-triangle's area signed like the
    # polygon's (the opposing facets face the other way: their images run clockwise)
    w = V.shape[1]
    if w >= 3:
        k = np.arange(1, w - 1)
        d1 = V[:, 1:-1] - V[:, :1]
        d2 = V[:, 2:] - V[:, :1]
        area = 0.5 * (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0])
        area = np.where(k[None, :] + 1 < count[:, None], area, 0.0)
        area *= np.sign(area.sum(axis=1))[:, None]
    else:
        area = np.zeros((len(V), 0))
    ca = C[:, 1:-1] - C[:, :1]
    cb = C[:, 2:] - C[:, :1]
    facet_area = 0.5 * np.abs(ca[..., 0] * cb[..., 1] - ca[..., 1] * cb[..., 0]).sum(axis=1)
    row, tri = np.nonzero(area > SLIVER * facet_area[:, None])
    if degree is None:
        degree = _degree(kc) + max(_degree(kc), _degree(ko))
    L, gw = _RULE2 if degree <= 2 else _RULE5
    P0, P1, P2 = V[row, 0], V[row, tri + 1], V[row, tri + 2]
    pts = (L[None, :, 0, None] * P0[:, None] + L[None, :, 1, None] * P1[:, None]
           + L[None, :, 2, None] * P2[:, None]).reshape(-1, 2)
    wts = (area[row, tri][:, None] * gw[None, :]).ravel()
    prow = np.repeat(row, len(gw))
    comp_xi = _inverse_map(C, prow, pts)
    opp_xi = _inverse_map(B, prow, pts)
    cf = fc[prow]
    if kc == 4:  # the facet's surface measure over its plane's (1 on a flat facet)
        s, t = comp_xi[:, :1], comp_xi[:, 1:]
        _, a3, b3, c3 = (m[prow] for m in _bilinear(comp_points[comp_facets[fc]]))
        _, a2, b2, c2 = (m[prow] for m in _bilinear(C))
        surf = np.linalg.norm(np.cross(a3 + t * c3, b3 + s * c3), axis=1)
        j0, j1 = a2 + t * c2, b2 + s * c2
        plane = np.abs(j0[:, 0] * j1[:, 1] - j0[:, 1] * j1[:, 0])
        wts = wts * np.where(plane > 0, surf / np.where(plane > 0, plane, 1.0), 1.0)
    x = o[prow] + pts[:, :1] * u[prow] + pts[:, 1:] * v[prow]
    return OverlapQuadrature(weight=wts, comp_facet=cf, comp_xi=comp_xi, opp_facet=fo[prow],
                             opp_xi=opp_xi, pair=pair_id[prow], x=x)


def overlap_matrices(quad: OverlapQuadrature, comp_facets: np.ndarray, opp_facets: np.ndarray,
                     n_comp: int, n_opp: int) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """``N`` (n_comp, n_comp) and ``T`` (n_opp, n_comp), CSR, from the points of
    :func:`overlap_quadrature`: ``N[i, k] = sum w phi_i phi_k`` and ``T[c, k] = sum w psi_c
    phi_k`` — 2D's layout (:func:`vfem.contact.geometry.transfer.transfer_matrices`): the
    compatibility side's forces ``N q``, the opposing side's ``-T q`` for the nodal traction values
    ``q`` of the compatibility side; ``T``'s columns sum like ``N``'s."""
    comp_facets = np.asarray(comp_facets)
    opp_facets = np.asarray(opp_facets)
    kc, ko = comp_facets.shape[1], opp_facets.shape[1]
    phi = shape_values(quad.comp_xi, kc) * quad.weight[:, None]
    phi_raw = shape_values(quad.comp_xi, kc)
    psi = shape_values(quad.opp_xi, ko)
    cn = comp_facets[quad.comp_facet]
    on = opp_facets[quad.opp_facet]
    N = sp.coo_matrix(((phi_raw[:, :, None] * phi[:, None, :]).ravel(),
                       (np.repeat(cn, kc, axis=1).ravel(), np.tile(cn, (1, kc)).ravel())),
                      shape=(n_comp, n_comp)).tocsr()
    T = sp.coo_matrix(((psi[:, :, None] * phi[:, None, :]).ravel(),
                       (np.repeat(on, kc, axis=1).ravel(), np.tile(cn, (1, ko)).ravel())),
                      shape=(n_opp, n_comp)).tocsr()
    return N, T


def candidate_pairs(comp_points: np.ndarray, comp_facets: np.ndarray, opp_points: np.ndarray,
                    opp_facets: np.ndarray, reach: float = 0.0) -> np.ndarray:
    """(compatibility facet, opposing facet) pairs (p, 2) whose bounding spheres (about the
    centroids, radius the farthest corner) come within ``reach``, and whose projections on the
    compatibility facet's plane can meet (their centroids' projections no farther apart than
    the two radii): a superset of the pairs with an overlap (:func:`overlap_quadrature`
    projects on that plane, and a projection moves no two points apart), sorted. A k-d tree
    on the centroids, no loop over facets.

    The plane test matters where ``reach`` is large against the facets in contact: the
    pairing's reach grows with the largest facet of either surface, and on the graded sphere
    of ``vfem bench sphere`` at 316k dofs every contact facet met some 700 opposing ones
    within it, whose clipping took 5 s and 0.9 GB to find 6 to 9 overlaps a facet."""
    from scipy.spatial import cKDTree

    def spheres(points, facets):
        X = np.asarray(points, float)[np.asarray(facets)]
        c = X.mean(axis=1)
        return c, np.linalg.norm(X - c[:, None, :], axis=2).max(axis=1)

    cc, rc = spheres(comp_points, comp_facets)
    co, ro = spheres(opp_points, opp_facets)
    if not len(cc) or not len(co):
        return np.zeros((0, 2), dtype=np.int64)
    found = cKDTree(cc).sparse_distance_matrix(cKDTree(co), rc.max() + ro.max() + reach,
                                               output_type="ndarray")
    i, j = found["i"].astype(np.int64), found["j"].astype(np.int64)
    ok = found["v"] <= rc[i] + ro[j] + reach
    i, j = i[ok], j[ok]
    n = _frames(np.asarray(comp_points, float), np.asarray(comp_facets))[1]
    d = co[j] - cc[i]
    along = np.einsum("pd,pd->p", d, n[i])
    apart = np.einsum("pd,pd->p", d, d) - along**2  # squared, in the plane
    meet = apart <= ((rc[i] + ro[j]) * (1.0 + 1e-9)) ** 2 + 1e-300
    out = np.stack([i[meet], j[meet]], axis=1)
    return out[np.lexsort((out[:, 1], out[:, 0]))]
