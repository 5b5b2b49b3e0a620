"""Where the bodies lie, before contact and between steps: whether two bodies overlap before the
first step, how far a platen's body travels before it touches, and which facets may come into
contact at all (the candidates every later stage reads; thesis §4.3's search, bounded by the
motion the loads can give).
"""

from __future__ import annotations

import numpy as np

from ...bodies import COMPONENTS, Body
from ...errors import InputError
from ...executor import SERIAL
from ..search import project_points
from .bodymesh import (
    exterior_facets,
    forget_simplex_sets,
    locate_in_simplices,
    mesh_simplices,
)
from .closest3d import closest_on_facets
from .sides import ContactPairs, zone_nodes
from .surface import ContactSurface


def check_initial_overlap(surfaces: list[ContactSurface], pairs: ContactPairs,
                          executor=SERIAL) -> None:
    """Refuse bodies that start deeper into each other than the outer layer of elements.

    The contact iteration finds a node's partner on the other surface only while the node is
    within that body's rind (thesis §5.6): :class:`~vfem.contact.formulations.paired.PairedContact`
    stops a step whose penetration passes the depth of the element behind the facet it is measured
    against (``rind_depth``), and cuts it; an overlap that deep at the start cannot be cut away,
    so every step would fail. The same rule is applied here to the undeformed bodies: for each
    pair of sides that may touch (:class:`~.sides.ContactPairs`, their zones read on these
    surfaces), each candidate node of one side is projected onto the other side's facets; a
    node behind it by more than the ``rind_depth`` of the facet there, and inside that body's
    elements (not behind a thin body, beyond its far side), is refused. An overlap within the
    rind is allowed: the first step resolves it.

    ``executor``: where each oriented pair is looked at (:mod:`vfem.executor`: spread over
    MPI ranks, what each found to every rank).

    Raises:
        InputError: naming both bodies, the node, its position and depth, and the rind there.
    """
    oriented = list(pairs.oriented())

    def deepest(k: int):
        """The oriented pair k's nodes too deep: (how many, depth, rind, the side's body,
        the facing body, position, node) of the deepest, or None."""
        side, facing = oriented[k]
        si, sj = surfaces[side.body], surfaces[facing.body]
        own, other = side.facets, facing.facets
        if si.nc == 0 or len(sj.facets) == 0 or (other is not None and not len(other)):
            return None
        # the nodes of one side, against the other's facets (their zones: :mod:`.sides`)
        local = zone_nodes(si, own)
        x, node = si.X[local], si.nodes[local]
        seg, t, _, n, tf = sj.closest(x, None, other)
        pos, _ = sj.curve(seg, t)
        depth = -np.einsum("ij,ij->i", x - pos, n)
        rind = sj.rind_depth[seg]
        deep = np.flatnonzero(depth > rind)
        if deep.size and si is sj:
            # two sides of one body: its own nodes lie in its elements, so that test says
            # nothing; a node counts where it lies over the other side, not past its end
            ends = sj.patch_boundary(np.arange(len(sj.facets)) if other is None else other)
            deep = deep[~sj.beyond(seg[deep], tf[deep], ends)]
        elif deep.size:
            mesh = sj.body.mesh
            deep = deep[locate_in_simplices(mesh.p[:, : mesh.nvertices].T,
                                            mesh_simplices(mesh), x[deep]) >= 0]
        if not deep.size:
            return None
        k = int(deep[np.argmax(depth[deep])])
        return (int(deep.size), float(depth[k]), float(rind[k]), side.body, facing.body, x[k],
                int(node[k]))

    found = executor.map(range(len(oriented)), deepest,
                         owners=[facing.body % executor.size for _, facing in oriented])
    worst, count = None, 0
    for k in range(len(oriented)):  # (in order: the first of equal depths, as before)
        if found[k] is None:
            continue
        count += found[k][0]
        if worst is None or found[k][1] > worst[0]:
            worst = found[k][1:]
    if worst is not None:
        depth, rind, i, j, x_k, k = worst
        si, sj = surfaces[i], surfaces[j]
        a, b = si.body.name, sj.body.name
        where = ", ".join(f"{v:.6g}" for v in x_k)  # (x, y) or (x, y, z)
        raise InputError(
            (f"bodies {a!r} and {b!r}" if si is not sj else f"two sides of body {a!r}")
            + f" start deeply interpenetrated: node {k} of "
            f"{a!r}, at ({where}), lies {depth:.3g} inside {b!r}, deeper than "
            f"its outer layer of elements there ({rind:.3g}; {count} such node(s) in all); "
            "contact cannot resolve an overlap that deep. Move the bodies apart (an input file's "
            "mesh.translate; a built-in example's own parameters, e.g. hertz's initial_gap >= 0) "
            "so that they start touching, and apply the overlap as a prescribed displacement or "
            "a platen force")


def predicted_translation(body: Body, load_factor: float) -> np.ndarray:
    """(dim,) the body's motion at ``load_factor`` as its prescribed displacements predict it, a
    rigid translation (the mean prescribed value of each component; zero for a component that
    nothing prescribes). What candidate selection needs to see bodies that start apart."""
    out = np.zeros(body.dim)
    for c in range(body.dim):
        values = [pd.at(load_factor) for pd in body.prescribed
                  if COMPONENTS[pd.component] == c]
        if values:
            out[c] = float(np.mean(values))
    return out


def platen_approach(moving: tuple[np.ndarray, np.ndarray], fixed: tuple[np.ndarray, np.ndarray],
                    direction: np.ndarray, chunk: int = 2_000_000) -> float:
    """How far the facets ``moving`` (ends (s, 2) and (s, 2); in 3D triangles, corners (s, 3)
    three times) travel along the unit ``direction`` before they first meet the facets
    ``fixed`` (inf if never): the smallest ray hit of one set's facet corners on the other's
    facets (``moving``'s corners along ``direction``, ``fixed``'s along its opposite; in 3D a
    ray-triangle intersection, Moeller-Trumbore; edges crossing edges are not looked at).
    Where a force-controlled body (a platen) that starts apart from another will touch it; the
    platen's own motion is not known before the solve, so candidate selection looks there
    (:func:`select_candidate_facets`)."""
    best = np.inf
    for points, facets, e in ((np.unique(np.vstack(moving), axis=0), fixed, direction),
                              (np.unique(np.vstack(fixed), axis=0), moving, -direction)):
        if len(points) == 0 or len(facets[0]) == 0:
            continue
        if len(facets) == 3:
            best = min(best, _ray_triangles(points, *facets, e, chunk))
            continue
        a, b = facets
        d = b - a
        denom = d[:, 0] * e[1] - d[:, 1] * e[0]  # cross(d, e): zero for facets along the ray
        step = max(1, chunk // len(a))
        for k in range(0, len(points), step):
            w = a[None, :, :] - points[k:k + step, None, :]  # (points, facets, 2)
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (w[..., 0] * d[:, 1] - w[..., 1] * d[:, 0]) / -denom  # along the ray
                s = (w[..., 0] * e[1] - w[..., 1] * e[0]) / -denom  # along the facet
            hit = (denom != 0) & (t >= 0) & (s >= 0) & (s <= 1)
            if hit.any():
                best = min(best, float(t[hit].min()))
    return best


def _ray_triangles(points: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray,
                   e: np.ndarray, chunk: int) -> float:
    """The shortest distance along the unit ``e`` from any of ``points`` (m, 3) to any of the
    triangles (corners ``a``, ``b``, ``c``, (s, 3) each), inf if no ray hits one
    (Moeller-Trumbore; a hit on an edge or a corner counts).

    Only the (point, triangle) pairs that can hit are tried: a ray along ``e`` meets a
    triangle only where the point's projection on the plane normal to ``e`` lies in the
    triangle's, so within the circle about its projected centroid through its farthest
    projected corner (a KD-tree of the projected points answers each circle, with a margin
    of 1e-9 of the model's size for round-off). All pairs were tried before: quadratic in
    the surface, 0.5 s of the sphere's 100k-dof set-up and the most of its search at 1M
    (issue 40)."""
    from scipy.spatial import cKDTree

    if len(points) == 0 or len(a) == 0:
        return np.inf
    # an orthonormal basis (u, v) of the plane normal to e
    helper = np.eye(3)[int(np.argmin(np.abs(e)))]
    u = np.cross(e, helper)
    u /= np.linalg.norm(u)
    v = np.cross(e, u)
    plane = np.column_stack([u, v])
    corners = np.stack([a, b, c])  # (3, s, 3)
    centre = corners.mean(axis=0) @ plane  # (s, 2)
    reach = np.max(np.linalg.norm(corners @ plane - centre[None], axis=2), axis=0)
    size = float(np.ptp(np.vstack([points, a, b, c]), axis=0).max())
    tree = cKDTree(points @ plane)
    near = tree.query_ball_point(centre, reach * (1 + 1e-9) + 1e-9 * size + 1e-300)
    counts = np.fromiter((len(q) for q in near), dtype=np.int64, count=len(near))
    if not counts.sum():
        return np.inf
    tri = np.repeat(np.arange(len(a)), counts)
    pt = np.fromiter((i for q in near for i in q), dtype=np.int64, count=int(counts.sum()))
    best = np.inf
    e1, e2 = b - a, c - a
    pvec = np.cross(e, e2)  # (s, 3)
    det = np.einsum("ij,ij->i", e1, pvec)  # zero for triangles parallel to the ray
    for k in range(0, len(pt), chunk):
        j, i = tri[k:k + chunk], pt[k:k + chunk]
        w = points[i] - a[j]  # (pairs, 3)
        qvec = np.cross(w, e1[j])
        with np.errstate(divide="ignore", invalid="ignore"):
            uu = np.einsum("ij,ij->i", w, pvec[j]) / det[j]
            vv = (qvec @ e) / det[j]
            t = np.einsum("ij,ij->i", qvec, e2[j]) / det[j]
            hit = (det[j] != 0) & (uu >= 0) & (vv >= 0) & (uu + vv <= 1) & (t >= 0)
        if hit.any():
            best = min(best, float(t[hit].min()))
    return best


def _facet_geometry(body: Body, f: np.ndarray):
    """(facets, mids, half) of a body's exterior facets ``f`` (their vertices, straight): 2D
    the ends ``(a, b)``, 3D triangles ``(a, b, c)`` (quadrilaterals split in two); their
    centres; the largest distance from a centre to a corner (half a 2D facet's length)."""
    mesh = body.mesh
    if body.dim == 2:
        a, c = mesh.p[:, mesh.facets[0, f]].T, mesh.p[:, mesh.facets[1, f]].T
        return (a, c), 0.5 * (a + c), 0.5 * np.linalg.norm(c - a, axis=1)
    corners = mesh.p[:, mesh.facets[:, f]].transpose(2, 1, 0)  # (nf, k, 3)
    mids = corners.mean(axis=1)
    half = np.linalg.norm(corners - mids[:, None], axis=2).max(axis=1)
    split = [(0, 1, 2)] if corners.shape[1] == 3 else [(0, 1, 2), (0, 2, 3)]
    tri = tuple(np.vstack([corners[:, s[k]] for s in split]) for k in range(3))
    return tri, mids, half


def _some(facets: tuple[np.ndarray, ...], which: np.ndarray, nf: int
          ) -> tuple[np.ndarray, ...]:
    """The facets ``which`` (of ``nf``) of :func:`_facet_geometry`'s ``facets``: in 3D each
    facet's triangles (a quadrilateral's two, the second ``nf`` later)."""
    per = len(facets[0]) // nf if nf else 1
    rows = np.concatenate([which + k * nf for k in range(per)]) if per > 1 else which
    return tuple(f[rows] for f in facets)


def _distance_to_facets(points: np.ndarray, facets: tuple[np.ndarray, ...]) -> np.ndarray:
    """(m,) each point's distance to the nearest of the facets (:func:`_facet_geometry`)."""
    if len(facets) == 2:
        return project_points(points, *facets)[2]
    a, b, c = facets
    if len(a) == 0:
        return np.full(len(points), np.inf)
    x = np.vstack([a, b, c])
    tri = np.arange(len(x)).reshape(3, -1).T
    return closest_on_facets(points, x, tri).distance  # nearest by bounding spheres


#: the most load factors :func:`select_candidate_facets` samples to follow a long path
MAX_PATH_SAMPLES = 4097


def _path_samples(bodies: list[Body], samples: np.ndarray, search_distance: float
                  ) -> np.ndarray:
    """``samples`` refined until no body's predicted translation moves more than half the
    search distance between two of them (at most :data:`MAX_PATH_SAMPLES`): a body that
    slides far is looked at all along its way, not only at the schedule's points."""
    if not np.isfinite(search_distance) or len(samples) < 2:
        return samples
    fine = np.linspace(samples.min(), samples.max(), 257)
    path = max(float(np.linalg.norm(np.diff([predicted_translation(b, x) for x in fine],
                                            axis=0), axis=1).sum()) for b in bodies)
    n = min(MAX_PATH_SAMPLES, int(np.ceil(2.0 * path / search_distance)) + 1)
    if n <= len(samples):
        return samples
    return np.unique(np.concatenate([samples, np.linspace(samples.min(), samples.max(), n)]))


def select_candidate_facets(bodies: list[Body], pairs: ContactPairs,
                            search_distance: float,
                            load_factors: tuple[float, ...] = (),
                            follow_path: bool = False, executor=SERIAL) -> list[np.ndarray]:
    """Per body, the exterior facets within ``search_distance`` of a body it may touch, at any
    load factor of the schedule: of each pair's sides (:class:`~.sides.ContactPairs`), the
    facets of one side near the other side's.

    Bodies that start apart and are driven together must find each other: each body's facets
    are moved by the body's :func:`predicted_translation` at load factors sampled over the
    schedule (its values and 16 between its smallest and largest), and a facet is a candidate
    when, at one of them, its midpoint is within ``search_distance`` plus its half length (3D:
    its centre, plus the distance from there to its farthest corner) of another body's
    surface (the exact distance to that body's facets, so that one long facet elsewhere does
    not widen the search) or inside that body (bodies that start overlapping).
    A body moved by a platen (force control) is also looked at where its platen would first
    bring it within reach of the other body (:func:`platen_approach`): a cylinder pressed onto
    a flat from a small gap finds the flat. ``follow_path`` (large kinematics, where a body may
    slide far): the samples are refined so that no body moves more than half the search
    distance between two of them (:func:`_path_samples`). ``executor``: where each oriented
    pair's search runs (:mod:`vfem.executor`: spread over MPI ranks, every result to all).
    """
    try:
        return _select_candidate_facets(bodies, pairs, search_distance, load_factors,
                                        follow_path, executor)
    finally:
        forget_simplex_sets()  # the body meshes' simplices, searched at every sample


def _select_candidate_facets(bodies: list[Body], pairs: ContactPairs, search_distance: float,
                             load_factors: tuple[float, ...], follow_path: bool,
                             executor=SERIAL) -> list[np.ndarray]:
    """:func:`select_candidate_facets`."""
    ext = [exterior_facets(b) for b in bodies]
    lf = np.concatenate([[0.0], np.asarray(load_factors, dtype=float)])
    samples = np.unique(np.concatenate([lf, np.linspace(lf.min(), lf.max(), 17)]))
    if follow_path:
        samples = _path_samples(bodies, samples, search_distance)
    moves = [np.array([predicted_translation(b, x) for x in samples]) for b in bodies]
    ends, mids, half = [], [], []
    for b, f in zip(bodies, ext):
        facets, mid, h = _facet_geometry(b, f)
        ends.append(facets)
        mids.append(mid)
        half.append(h)
    oriented = list(pairs.oriented())

    def near(k: int) -> np.ndarray | None:
        """The oriented pair k's side's facets near the facing side, as a mask of the side
        body's exterior facets (None: none looked at)."""
        side, facing = oriented[k]
        i, j = side.body, facing.body
        keep = np.zeros(len(ext[i]), dtype=bool)
        # each side's facets (all of the body's, or its zone's)
        own, oth = (np.arange(len(ext[s.body])) if z is None else
                    np.flatnonzero(np.isin(ext[s.body], z))
                    for s, z in ((side, side.mesh_facets(bodies[i])),
                                 (facing, facing.mesh_facets(bodies[j]))))
        if len(oth) == 0 or len(own) == 0:
            return None
        relative = moves[i] - moves[j]
        for mover, other, sign, moving, fixed in ((i, j, 1.0, own, oth), (j, i, -1.0, oth, own)):
            platen = bodies[mover].platen
            if platen is None:
                continue
            # the directions the platen pushes in over the schedule (its load curve may
            # change sign)
            for direction in np.unique(np.sign([platen.force_at(x) for x in samples])):
                if direction == 0.0:
                    continue
                e = np.zeros(bodies[mover].dim)
                e[COMPONENTS[platen.component]] = direction
                t = platen_approach(_some(ends[mover], moving, len(ext[mover])),
                                    _some(ends[other], fixed, len(ext[other])), e)
                if np.isfinite(t) and t > search_distance:  # else the schedule's reach
                    relative = np.vstack([relative, relative[:1] + sign * t * e])
        mesh = bodies[j].mesh
        lo, hi = mesh.p.min(axis=1), mesh.p.max(axis=1)
        tri = None  # body j's triangles, made only if a facet may start inside it
        scale = float(np.ptp(np.vstack([mids[i][own], mids[j][oth]]), axis=0).max())
        for r in np.unique(relative, axis=0):
            if not np.all(np.abs(r) <= 1e6 * max(scale, 1e-300)):
                continue  # a motion no step of a contact analysis can follow
            x = mids[i][own] + r
            d = _distance_to_facets(x, _some(ends[j], oth, len(ext[j])))
            keep[own] |= d <= search_distance + half[i][own]
            # facets that start inside the other body (an initial overlap; not for two sides of
            # one body, whose own facets lie on it)
            box = np.flatnonzero(~keep[own] & np.all((x >= lo) & (x <= hi), axis=1))
            if len(box) and i != j:
                tri = mesh_simplices(mesh) if tri is None else tri
                inside = locate_in_simplices(mesh.p[:, : mesh.nvertices].T, tri,
                                             x[box], keep=True) >= 0
                keep[own[box[inside]]] = True
        return keep

    # the oriented pairs spread over the ranks by the body they face (vfem.parallel, issue
    # 40: the search structures of a body's facets are then made on one rank), every mask to
    # every rank
    found = executor.map(range(len(oriented)), near,
                         owners=[facing.body % executor.size for _, facing in oriented])
    keeps = [np.zeros(len(f), dtype=bool) for f in ext]
    for k, (side, _) in enumerate(oriented):
        if found[k] is not None:
            keeps[side.body] |= found[k]
    return [f[keep] for f, keep in zip(ext, keeps)]
