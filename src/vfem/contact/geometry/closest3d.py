"""Closest points on the facets of a 3D contact surface (issue 21): for each query point, the
nearest of a set of surface facets, the local coordinates and position of the closest point on
it, the distance, the facet's unit outward normal there and the unclamped local coordinates that
tell whether the point lies beyond the facet — the 3D counterpart of
:func:`vfem.contact.search.closest.project_points`. The facets, their kinds and the candidates
are :mod:`vfem.contact.geometry.facets3d`'s.

**The closest point.**

* Linear triangles: Ericson's region classification (*Real-Time Collision Detection*, 5.1.5)
  as masked array expressions: vertex, edge or face region, then the exact closest point of that
  region. No iteration and no tolerance: a point whose closest point is a vertex gets that
  vertex's coordinates exactly, one over an edge a coordinate exactly 0 (or ξ + η = 1).
* Bilinear and quadratic facets: the distance to the facet's chord triangles (a quadrilateral's
  corners split along the diagonal 0-2, a T6's corners) differs from the distance to the facet
  by at most a bound of the facet's warp and curvature (:func:`chord_deviation`), so a
  candidate whose lower bound exceeds the point's best distance so far cannot be nearest and is
  dropped, before each stage: (a) projected Newton on the facet's map ``x(ξ)`` (Hessian
  ``JᵀJ + (x − p)·∂²x``, Gauss-Newton where that is not positive definite; on a bound the
  gradient pushes against, the 1D step along it; steps halved until the distance falls;
  iterates clamped to the reference domain), from the chord triangles' closest point, first
  for each point's nearest chord triangles, whose distance then cuts the other candidates;
  (b) the same Newton from every basin a 7 x 7 lattice over the facet shows (its points no
  farther than their neighbours: a wavy facet can hold two local minima); (c) the facet's
  edges: straight ones (Q4) by the exact segment formula, curved ones (T6, Q9) by a
  safeguarded 1D Newton from both ends and the chord's closest point, only where the chord
  less its bulge comes near enough. The nearest of these is the closest point; the edges win
  ties to round-off, so a point whose closest point lies on an edge or at a corner gets the
  clamped coordinate exactly. Limit: a local minimum whose basin is narrower than a lattice
  cell (1/6 of the facet) and lower than the others could be missed; no mesh of a smooth
  surface has such facets, and the tests' wavy facets (midside nodes 0.3-0.4 of the facet off
  the chord) do not.

**Unclamped coordinates.** ``xi_free = xi + (JᵀJ)⁻¹ Jᵀ (p − x(xi))``, one Gauss-Newton step from
the closest point without clamping: for a flat (affine) facet it is the exact position of the
point's orthogonal projection on the facet's plane, in the facet's coordinates (as 2D's
``t_free`` along the chord); over the facet it equals ``xi`` to round-off, and past an edge it
lies beyond that edge (:func:`outside`), so "beyond the patch" can be judged later.

**Ties** (a point as near, to 1e-9 of the largest facet, to two facets as to its nearest, e.g.
outside a box's edge, equidistant from its two faces): with ``point_normals`` (the outward
normal of the surface the point lies on) the facet whose outward normal at the closest point
is most opposed to it wins (dot product rounded to 9 digits), so a point pairs with the face
that faces it, as in 2D; then the facet the point lies over (``xi_free`` inside its reference
domain, 1e-9); then the lowest facet number. The tie is judged against each point's own
nearest distance (2D's :func:`~vfem.contact.search.closest.project_points` too, since issue
42's random model 2d-49: its fixed distance bins put two distances closer than the tolerance
into neighbouring bins), so two such distances are always tied.
"""

from __future__ import annotations

import numpy as np

from .facets3d import (
    TIE,
    FacetProjection,
    FacetShape,
    _distance,
    _dot,
    _evaluate,
    _unit,
    candidate_pairs,
    checked,
    chord_deviation,
    closest_on_triangles,
    facet_shape,
    outside,
    shape_functions,
)

_NEWTON_STEPS = 40  # 2D projected Newton iterations (quadratic convergence: 4-8 are used)


_EDGE_STEPS = 30  # 1D Newton iterations on a curved edge


_HALVINGS = 30  # step halvings before a Newton iteration gives up


CHUNK = 65536  # point-facet pairs handled at once (bounds the memory of the kernels)


FEW_PAIRS = 4096  # up to this many pairs the Newton stages on curved facets run as one


def _to_domain(kind: FacetShape, xi: np.ndarray) -> np.ndarray:
    """Clamp local coordinates into the reference domain."""
    xi = np.clip(xi, 0.0, 1.0)
    if kind.simplex:
        over = xi.sum(axis=1) > 1
        u = np.clip(0.5 * (xi[over, 0] - xi[over, 1] + 1), 0.0, 1.0)
        xi[over] = np.column_stack([u, 1 - u])
    return xi


def _reduced_step(kind: FacetShape, xi: np.ndarray, g: np.ndarray, H: np.ndarray,
                  G: np.ndarray) -> np.ndarray:
    """Newton step at ``xi`` restricted to the bounds that are not active: a bound is active
    where ``xi`` lies on it and the gradient ``g`` pushes out of the domain there.

    No active bound: −H⁻¹g with the Hessian H (n, 3) (ξξ, ξη, ηη) where it is positive
    definite, else with JᵀJ = G (Gauss-Newton). One: the 1D Newton step along it, with H's
    curvature along it where positive, else a step across the whole edge downhill (the line
    search halves it). Two (a corner): no step."""
    u, v = xi[:, 0], xi[:, 1]
    if kind.simplex:
        fix_u = (u <= 0) & (g[:, 0] > 0)
        fix_v = (v <= 0) & (g[:, 1] > 0)
        slant = (u + v >= 1) & (g[:, 0] + g[:, 1] < 0)
    else:
        fix_u = ((u <= 0) & (g[:, 0] > 0)) | ((u >= 1) & (g[:, 0] < 0))
        fix_v = ((v <= 0) & (g[:, 1] > 0)) | ((v >= 1) & (g[:, 1] < 0))
        slant = np.zeros(len(u), dtype=bool)
    det = H[:, 0] * H[:, 2] - H[:, 1] ** 2
    convex = (H[:, 0] > 0) & (det > 1e-12 * H[:, 0] * H[:, 2])
    M = np.where(convex[:, None], H, G)
    det = M[:, 0] * M[:, 2] - M[:, 1] ** 2
    step = -np.column_stack([M[:, 2] * g[:, 0] - M[:, 1] * g[:, 1],
                             M[:, 0] * g[:, 1] - M[:, 1] * g[:, 0]]) / det[:, None]

    def along(gt, ct):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(ct > 0, -gt / ct, -np.sign(gt))

    zero = np.zeros(len(u))
    du = along(g[:, 0], H[:, 0])
    dv = along(g[:, 1], H[:, 2])
    ds = along(g[:, 0] - g[:, 1], H[:, 0] - 2 * H[:, 1] + H[:, 2])
    corner = (fix_u.astype(int) + fix_v + slant) >= 2
    return np.select(
        [corner[:, None], fix_u[:, None], fix_v[:, None], slant[:, None]],
        [np.zeros_like(step), np.column_stack([zero, dv]), np.column_stack([du, zero]),
         np.column_stack([ds, -ds])], step)


def _newton(kind: FacetShape, X: np.ndarray, p: np.ndarray, xi: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """Projected Newton for min f = ½|x(ξ) − p|² over the reference domain, from ``xi``
    (:func:`_reduced_step` on the active bounds). Every iterate is in the domain and no
    farther from ``p`` than the one before (a step that is not is halved, up to
    :data:`_HALVINGS` times), but for the last step (:func:`_last`), taken as it is.
    Returns (xi, f)."""
    xi = _to_domain(kind, xi)
    pos, J, S = _evaluate(kind, X, xi)
    r = pos - p
    f = 0.5 * _dot(r, r)
    step = np.zeros_like(xi)
    alpha = np.ones(len(p))
    last = np.zeros(len(p), dtype=bool)
    fresh = np.ones(len(p), dtype=bool)  # the step is to be (re)computed at xi
    act = np.arange(len(p))
    for _ in range(_NEWTON_STEPS + _HALVINGS):
        if not len(act):
            break
        new = act[fresh[act]]
        if len(new):
            Jn, rn = J[new], r[new]
            g = (rn[:, None, :] @ Jn)[:, 0]
            G = (np.swapaxes(Jn, 1, 2) @ Jn).reshape(-1, 4)[:, [0, 1, 3]]
            H = G + (rn[:, None, :] @ S[new])[:, 0]
            step[new] = _reduced_step(kind, xi[new], g, H, G)
            alpha[new] = 1.0
            last[new] = _last(step[new], -_dot2(g, step[new]), f[new], p[new])
        trial = _to_domain(kind, xi[act] + alpha[act, None] * step[act])
        move = np.abs(trial - xi[act]).max(axis=1)
        pt_, Jt, St = _evaluate(kind, X[act], trial)
        rt = pt_ - p[act]
        ft = 0.5 * _dot(rt, rt)
        ok = (ft <= f[act]) | last[act]
        acc = act[ok]
        xi[acc], pos[acc], J[acc], S[acc], r[acc], f[acc] = (
            trial[ok], pt_[ok], Jt[ok], St[ok], rt[ok], ft[ok])
        fresh[act] = ok
        alpha[act[~ok]] *= 0.5
        act = act[~last[act] & (move > 0) & (alpha[act] > 0.5 ** _HALVINGS)]
    return xi, f


def _last(step: np.ndarray, decrease: np.ndarray, f: np.ndarray, p: np.ndarray
          ) -> np.ndarray:
    """Whether a Newton step is the last: |step| ≤ 1e-9 in local coordinates (Newton's
    quadratic convergence leaves ~1e-18 after it), or its predicted decrease of
    f = ½|x − p|² within f's round-off (x − p is rounded to ~1e-16 of |p| and |x − p|). It
    is taken without the line search, which could not tell its effect from round-off."""
    size = np.abs(step).reshape(len(step), -1).max(axis=1)
    dist = np.sqrt(2 * f)
    noise = 1e-15 * dist * (np.abs(p).max(axis=1) + dist) + 1e-300
    return (size <= 1e-9) | (decrease <= noise)


def _dot2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]


def _curved_edges(A: np.ndarray, B: np.ndarray, M: np.ndarray, p: np.ndarray, t: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Nearest point to p on quadratic edges from A (s = 0) to B (s = 1) through M (s = 1/2),
    all (n, 3): (s, f) with f = ½|x(s) − p|². x(s) = c0 + c1 s + c2 s²; safeguarded 1D
    Newton (a step that does not come nearer is halved; where f is concave, a step across the
    edge downhill) from both ends and from ``t`` (n,), the chord's closest point (f is a
    quartic: at most two minima in [0, 1])."""
    n, ns = len(p), 3
    c0 = np.repeat(A, ns, axis=0)
    c1 = np.repeat(-3 * A + 4 * M - B, ns, axis=0)
    c2 = np.repeat(2 * A - 4 * M + 2 * B, ns, axis=0)
    q = np.repeat(p, ns, axis=0)
    s = np.column_stack([np.zeros(n), t, np.ones(n)]).ravel()

    def residual(i, s):
        return c0[i] + s[:, None] * c1[i] + (s * s)[:, None] * c2[i] - q[i]

    r = residual(slice(None), s)
    f = 0.5 * _dot(r, r)
    step = np.zeros(len(s))
    alpha = np.ones(len(s))
    last = np.zeros(len(s), dtype=bool)
    fresh = np.ones(len(s), dtype=bool)
    act = np.arange(len(s))
    for _ in range(_EDGE_STEPS + _HALVINGS):
        if not len(act):
            break
        new = act[fresh[act]]
        if len(new):
            d1 = c1[new] + 2 * s[new, None] * c2[new]
            g = _dot(r[new], d1)
            h = _dot(d1, d1) + 2 * _dot(r[new], c2[new])
            step[new] = np.where(h > 0, -g / np.where(h > 0, h, 1.0), -np.sign(g))
            alpha[new] = 1.0
            last[new] = _last(step[new], -g * step[new], f[new], q[new])
        trial = np.clip(s[act] + alpha[act] * step[act], 0.0, 1.0)
        move = np.abs(trial - s[act])
        rt = residual(act, trial)
        ft = 0.5 * _dot(rt, rt)
        ok = (ft <= f[act]) | last[act]
        acc = act[ok]
        s[acc], r[acc], f[acc] = trial[ok], rt[ok], ft[ok]
        fresh[act] = ok
        alpha[act[~ok]] *= 0.5
        act = act[~last[act] & (move > 0) & (alpha[act] > 0.5 ** _HALVINGS)]
    f = f.reshape(n, ns)
    j = f.argmin(axis=1)
    rows = np.arange(n)
    return s.reshape(n, ns)[rows, j], f[rows, j]


def _chord_start(kind: FacetShape, X: np.ndarray, p: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Distance to the chord triangles and the facet coordinates of its closest point."""
    C = X[:, :kind.corners]
    if kind.simplex:
        xi = closest_on_triangles(p, C[:, 0], C[:, 1], C[:, 2])
        r = C[:, 0] + xi[:, :1] * (C[:, 1] - C[:, 0]) + xi[:, 1:] * (C[:, 2] - C[:, 0]) - p
        return np.sqrt(_dot(r, r)), xi
    # triangles 0-1-2 (ξ = s + t, η = t) and 0-2-3 (ξ = s, η = s + t)
    st1 = closest_on_triangles(p, C[:, 0], C[:, 1], C[:, 2])
    st2 = closest_on_triangles(p, C[:, 0], C[:, 2], C[:, 3])
    r1 = C[:, 0] + st1[:, :1] * (C[:, 1] - C[:, 0]) + st1[:, 1:] * (C[:, 2] - C[:, 0]) - p
    r2 = C[:, 0] + st2[:, :1] * (C[:, 2] - C[:, 0]) + st2[:, 1:] * (C[:, 3] - C[:, 0]) - p
    d1, d2 = np.sqrt(_dot(r1, r1)), np.sqrt(_dot(r2, r2))
    xi1 = np.column_stack([st1[:, 0] + st1[:, 1], st1[:, 1]])
    xi2 = np.column_stack([st2[:, 0], st2[:, 0] + st2[:, 1]])
    second = d2 < d1
    return np.where(second, d2, d1), np.where(second[:, None], xi2, xi1)


def _chunks(n: int, size: int = CHUNK) -> list[slice]:
    return [slice(i, i + size) for i in range(0, n, size)]


def _lattice(kind: FacetShape, n: int = 6) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A lattice of local coordinates over the reference domain (n intervals a side), its
    neighbour table (each point's lattice neighbours, padded with itself) and its shape
    functions."""
    ij = [(i, j) for i in range(n + 1) for j in range(n + 1)
          if not kind.simplex or i + j <= n]
    index = {v: k for k, v in enumerate(ij)}
    steps = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1)]
    if not kind.simplex:
        steps += [(1, 1), (-1, -1)]
    nbr = np.array([[index.get((i + di, j + dj), index[i, j]) for di, dj in steps]
                    for i, j in ij])
    xi = np.array(ij, dtype=float) / n
    return xi, nbr, shape_functions(kind, xi)[0]


_LATTICES: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}


def _lattice_starts(kind: FacetShape, X: np.ndarray, p: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Newton starts that catch every basin of the distance on a facet: the points of a
    lattice over the facet (7 x 7, or 28 on a triangle) no farther from p than their lattice
    neighbours. Returns (rows into X and p, starts)."""
    if kind.name not in _LATTICES:
        _LATTICES[kind.name] = _lattice(kind)
    xi, nbr, N = _LATTICES[kind.name]
    rows, starts = [], []
    for c in _chunks(len(p), CHUNK // 16):
        P = N[None] @ X[c]  # (n, samples, 3)
        D = _dot(P - p[c][:, None], P - p[c][:, None])
        r, j = np.nonzero((D[:, :, None] <= D[:, nbr]).all(axis=2))
        rows.append(r + c.start)
        starts.append(xi[j])
    return np.concatenate(rows), np.concatenate(starts).reshape(-1, 2)


def _best_per_row(rows: np.ndarray, n: int, xi: np.ndarray, f: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """For each of n rows the (xi, f) of its entry with the least f (rows without one: f =
    inf)."""
    order = np.lexsort((f, rows))
    first = order[np.r_[0, np.flatnonzero(np.diff(rows[order])) + 1]] if len(rows) else order
    out_xi, out_f = np.zeros((n, 2)), np.full(n, np.inf)
    out_xi[rows[first]], out_f[rows[first]] = xi[first], f[first]
    return out_xi, out_f


def _project_curved(kind: FacetShape, x: np.ndarray, facets: np.ndarray, points: np.ndarray,
                    pt: np.ndarray, fc: np.ndarray, tol: float):
    """Closest points of the candidate pairs (pt, fc) on bilinear or quadratic facets, less
    the pairs that cannot be nearest: (pt, fc, xi).

    In stages, each dropping the pairs whose lower bound (chord-triangle distance less
    :func:`chord_deviation`) exceeds the point's best distance so far (+ ``tol``): the chord
    triangles (their distance plus the deviation bounds the facet's); Newton from the chord
    triangles' closest point (first on each point's nearest chord triangles, whose distance
    cuts the others); Newton from every basin a lattice over the facet shows
    (:func:`_lattice_starts`: a wavy facet can hold two local minima); then the edges
    (straight: exact; curved: 1D Newton, only on edges whose chord comes near enough)."""
    m = len(points)
    corners = kind.corners
    dev = chord_deviation(kind, x[facets])

    def cut(upper_of_pair, lower_of_pair):
        upper = np.full(m, np.inf)
        np.minimum.at(upper, pt, upper_of_pair)
        return lower_of_pair <= upper[pt] + tol

    parts = [_chord_start(kind, x[facets[fc[c], :corners]], points[pt[c]])
             for c in _chunks(len(pt))]
    d_chord = np.concatenate([d for d, _ in parts])
    xi = np.concatenate([v for _, v in parts])
    lower = d_chord - dev[fc]
    keep = cut(d_chord + dev[fc], lower)
    pt, fc, xi, lower, d_chord = pt[keep], fc[keep], xi[keep], lower[keep], d_chord[keep]

    def newton(sel, start):
        parts = [_newton(kind, x[facets[fc[sel[c]]]], points[pt[sel[c]]], start[c])
                 for c in _chunks(len(sel))]
        if not parts:  # no pair left at this stage (every point's best found before it)
            return np.zeros((0, 2)), np.zeros(0)
        return (np.concatenate([v for v, _ in parts]).reshape(-1, 2),
                np.concatenate([v for _, v in parts]))

    if len(pt) <= FEW_PAIRS:
        # few pairs: every start of every pair in one Newton call (fewer numpy calls)
        rows, starts = _lattice_starts(kind, x[facets[fc]], points[pt])
        rows = np.r_[np.arange(len(pt)), rows]
        xi_s, f_s = newton(rows, np.vstack([xi, starts]))
        xi, f = _best_per_row(rows, len(pt), xi_s, f_s)
    else:
        order = np.lexsort((d_chord, pt))
        first = order[np.r_[0, np.flatnonzero(np.diff(pt[order])) + 1]]
        f = np.full(len(pt), np.inf)
        xi[first], f[first] = newton(first, xi[first])
        keep = cut(np.sqrt(2 * f), lower)
        keep[first] = True
        pt, fc, xi, f, lower = pt[keep], fc[keep], xi[keep], f[keep], lower[keep]
        rest = np.flatnonzero(np.isinf(f))
        xi[rest], f[rest] = newton(rest, xi[rest])
        keep = cut(np.sqrt(2 * f), lower)
        pt, fc, xi, f = pt[keep], fc[keep], xi[keep], f[keep]
        rows, starts = _lattice_starts(kind, x[facets[fc]], points[pt])
        xi_s, f_s = newton(rows, starts)
        xi2, f2 = _best_per_row(rows, len(pt), xi_s, f_s)
        better = f2 < f
        xi[better], f[better] = xi2[better], f2[better]

    # the edges: a clamped coordinate there is exact (they win ties)
    V = kind.vertices
    for a, b, mid in kind.edges:
        A, B = x[facets[fc, a]], x[facets[fc, b]]
        p = points[pt]
        d = B - A
        t = np.clip(_dot(p - A, d) / _dot(d, d), 0.0, 1.0)
        rc = A + t[:, None] * d - p
        if mid < 0:
            s_e, f_e, e = t, 0.5 * _dot(rc, rc), np.arange(len(pt))
        else:
            # x(s) − chord(s) = 4 s (1 − s) δ: the edge is no nearer than its chord less |δ|
            M = x[facets[fc, mid]]
            bulge = np.sqrt(_dot(M - 0.5 * (A + B), M - 0.5 * (A + B)))
            e = np.flatnonzero(np.sqrt(_dot(rc, rc)) - bulge <= np.sqrt(2 * f) + tol)
            s_e, f_e = _curved_edges(A[e], B[e], M[e], p[e], t[e])
        # the edge wins a tie to f's round-off: its clamped coordinate is exact
        dist = np.sqrt(2 * f[e])
        win = f_e <= f[e] + 1e-15 * dist * (np.abs(p[e]).max(axis=1) + dist)
        w = e[win]
        xi[w] = V[a] + s_e[win, None] * (V[b] - V[a])
        f[w] = f_e[win]
    return pt, fc, xi


def closest_on_facets(points: np.ndarray, x: np.ndarray, facets: np.ndarray,
                      point_normals: np.ndarray | None = None,
                      pairs: tuple[np.ndarray, np.ndarray] | str | None = None
                      ) -> FacetProjection:
    """Closest point on a set of 3D facets for each point (module docstring).

    Args:
        points: (m, 3) query points.
        x: (npts, 3) node coordinates.
        facets: (nf, k) node indices of the facets, k = 3, 4, 6 or 9 (T3, Q4, T6, Q9), each
            oriented (corners counter-clockwise seen from outside).
        point_normals: (m, 3) unit outward normals of the surface each point lies on, to break
            ties (optional).
        pairs: the candidates: (point indices, facet indices), two equal-length arrays; or
            ``"all"`` (every point against every facet); or None (found here,
            :func:`candidate_pairs`).

    Returns:
        :class:`FacetProjection` (facet, xi, point, distance, normal, xi_free).

    Raises:
        ValueError: facets of another node count, or degenerate (:func:`check_facets`).
    """
    kind = facet_shape(facets)
    facets = np.asarray(facets, dtype=np.int64)
    x = np.asarray(x, dtype=float)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    m, nf = len(points), len(facets)
    surface = checked(x, facets)  # validated once per facet set
    if isinstance(pairs, str):
        if pairs != "all":
            raise ValueError(f"pairs must be (points, facets), 'all' or None, got {pairs!r}")
        pt = np.repeat(np.arange(m, dtype=np.int64), nf)
        fc = np.tile(np.arange(nf, dtype=np.int64), m)
    elif pairs is None:
        pt, fc = candidate_pairs(points, x, facets)
    else:
        pt, fc = (np.asarray(a, dtype=np.int64).ravel() for a in pairs)
    out = FacetProjection(np.full(m, -1, dtype=np.int64), np.full((m, 2), np.nan),
                          np.full((m, 3), np.nan), np.full(m, np.inf), np.full((m, 3), np.nan),
                          np.full((m, 2), np.nan))
    if len(pt) == 0:
        return out
    if "tie" not in surface:
        C = x[facets[:, :kind.corners]]
        diff = C[:, :, None] - C[:, None]
        surface["tie"] = TIE * np.sqrt(_dot(diff, diff).max()) + 1e-300
    tol = surface["tie"]
    chunks = _chunks(len(pt))

    if kind.name == "T3":
        xi = np.concatenate([closest_on_triangles(points[pt[c]], *np.moveaxis(
            x[facets[fc[c]]], 1, 0)) for c in chunks])
    else:
        pt, fc, xi = _project_curved(kind, x, facets, points, pt, fc, tol)
        chunks = _chunks(len(pt))
    dist = np.concatenate([_distance(points[pt[c]],
                                     _evaluate(kind, x[facets[fc[c]]], xi[c])[0])
                           for c in chunks])
    nearest = np.full(m, np.inf)
    np.minimum.at(nearest, pt, dist)
    tied = np.flatnonzero(dist <= nearest[pt] + tol)

    # the tie rules, among the tied candidates: facing, then over the facet, then facet number
    pt, fc, xi, dist = pt[tied], fc[tied], xi[tied], dist[tied]
    p = points[pt]
    pos, J, _ = _evaluate(kind, x[facets[fc]], xi)
    normal = _unit(np.cross(J[:, :, 0], J[:, :, 1]))
    xi_free = xi + _gauss_newton_step(J, p - pos)
    beyond = outside(kind, xi_free).any(axis=1)
    facing = np.zeros(len(pt))
    if point_normals is not None:
        pn = np.asarray(point_normals, dtype=float).reshape(-1, 3)
        facing = np.round(_dot(pn[pt], normal), 9)
    order = np.lexsort((fc, beyond, facing, pt))
    first = order[np.r_[0, np.flatnonzero(np.diff(pt[order])) + 1]]
    who = pt[first]
    out.facet[who] = fc[first]
    out.xi[who] = xi[first]
    out.point[who] = pos[first]
    out.distance[who] = dist[first]
    out.normal[who] = normal[first]
    out.xi_free[who] = xi_free[first]
    return out


def _gauss_newton_step(J: np.ndarray, r: np.ndarray) -> np.ndarray:
    """(JᵀJ)⁻¹ Jᵀ r for J (n, 3, 2), r (n, 3)."""
    g = (r[:, None, :] @ J)[:, 0]
    G = np.swapaxes(J, 1, 2) @ J
    det = G[:, 0, 0] * G[:, 1, 1] - G[:, 0, 1] ** 2
    return np.column_stack([G[:, 1, 1] * g[:, 0] - G[:, 0, 1] * g[:, 1],
                            G[:, 0, 0] * g[:, 1] - G[:, 0, 1] * g[:, 0]]) / det[:, None]
