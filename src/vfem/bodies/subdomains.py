"""A body split into subdomains (issue 43): its elements partitioned by METIS, each subdomain's
stiffness assembled on its own elements, and the split solve (:class:`vfem.linalg.bddc.BDDCSolve`)
that stands in for the body's factorization (``subdomains`` > 1, :func:`.condensation.setup`).

**Partition.** The graph is the elements' dual graph: one vertex per element, an edge between
two elements that share a facet (scikit-fem's ``mesh.f2t``), so a subdomain is a set of
elements glued face to face and the cut runs along facets. METIS's k-way partition (pymetis)
balances the *element counts*: every element of a body is the same kind and order, so each
carries the same number of dofs and equal element counts are equal work (a subdomain's
factorization) to within the interface's share; a node weight per element would be that
same constant. Contiguous parts are asked for (a subdomain in two pieces would float), and
the seed is fixed, so the same mesh and K give the same partition on every run and machine
(METIS is deterministic for a fixed seed and input).

**Primal dofs** (the coarse problem's): the free dofs of every point shared by three or more
subdomains (corners in 2D, edges in 3D) or on the body's exterior boundary and shared by two.
With them held, every subdomain's Neumann matrix is nonsingular: a cut between two
subdomains ends on the exterior boundary, so even K = 2 has primal points on the cut's ends.
A subdomain whose primal points could still turn it as a rigid body (fewer than two in 2D,
collinear ones in 3D, e.g. an island whose cut touches neither the boundary nor a third
subdomain) gets the interface points farthest from the ones it has, until they span.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from ..errors import InputError

log = logging.getLogger(__name__)

#: METIS's random seed: fixed, so that a partition is the same on every run
SEED = 1


def element_graph(mesh) -> tuple[np.ndarray, np.ndarray]:
    """The elements' dual graph in CSR form (``xadj``, ``adjncy``): elements adjacent through a
    shared facet (``mesh.f2t``; a boundary facet has one element)."""
    f2t = mesh.f2t
    inner = f2t[1] >= 0
    a, b = f2t[0, inner], f2t[1, inner]
    src = np.concatenate([a, b])
    dst = np.concatenate([b, a])
    order = np.lexsort((dst, src))
    src, dst = src[order], dst[order]
    xadj = np.zeros(mesh.nelements + 1, dtype=np.int64)
    np.add.at(xadj, src + 1, 1)
    return np.cumsum(xadj), dst.astype(np.int64)


def partition(mesh, k: int) -> np.ndarray:
    """(nelements,) each element's subdomain, 0..k-1: METIS's k-way partition of the element
    dual graph (see the module docstring), every part non-empty; all zeros for k = 1."""
    n = mesh.nelements
    if k == 1:
        return np.zeros(n, dtype=int)
    if k > n:
        raise ValueError(f"more subdomains than elements ({k} > {n})")
    import pymetis

    graph = pymetis.CSRAdjacency(*element_graph(mesh))
    try:
        _, parts = pymetis.part_graph(k, graph, options=pymetis.Options(seed=SEED, contig=1))
    except Exception:  # noqa: BLE001 (a mesh in pieces cannot be split into contiguous parts)
        _, parts = pymetis.part_graph(k, graph, options=pymetis.Options(seed=SEED))
    parts = np.asarray(parts, dtype=int)
    if len(np.unique(parts)) != k:
        raise ValueError(f"METIS left a part empty ({len(np.unique(parts))} of {k})")
    return parts


def body_partition(body) -> np.ndarray:
    """The body's element -> subdomain map for its ``subdomains``, computed once per mesh."""
    kept = body.__dict__.get("_partition")
    if kept is None or kept[0] is not body.mesh or kept[1] != body.subdomains:
        try:
            parts = partition(body.mesh, body.subdomains)
        except ValueError as exc:
            raise InputError(f"body {body.name!r}: cannot split it into {body.subdomains} "
                             f"subdomains: {exc}") from None
        kept = body._partition = (body.mesh, body.subdomains, parts)
    return kept[2]


def subdomain_points(body, parts: np.ndarray) -> list[np.ndarray]:
    """Each subdomain's points (sorted): those of its elements' dofs."""
    point_of = body.dof_map.element_dofs[:: body.dim] // body.dim  # (points per element, ne)
    return [np.unique(point_of[:, parts == i]) for i in range(int(parts.max()) + 1)]


def primal_points(body, points: list[np.ndarray]) -> np.ndarray:
    """(npoints,) bool: the coarse problem's points (see the module docstring)."""
    npts = body.npoints
    count = np.zeros(npts, dtype=int)
    for p in points:
        count[p] += 1
    exterior = np.zeros(npts, dtype=bool)
    exterior[np.unique(body.facet_points(body.mesh.boundary_facets()))] = True
    primal = (count >= 3) | (exterior & (count >= 2))
    x = body.points
    for p in points:
        chosen = list(p[primal[p]])
        shared = p[count[p] >= 2]
        while not _spans(x[:, chosen], body.dim) and len(chosen) < len(shared):
            if chosen:
                d = np.min(np.linalg.norm(x[:, shared, None] - x[:, None, chosen], axis=0),
                           axis=1)
            else:
                d = np.linalg.norm(x[:, shared] - x[:, shared].mean(axis=1, keepdims=True),
                                   axis=0)
            far = shared[int(np.argmax(d))]
            chosen.append(far)
            primal[far] = True
    return primal


def _spans(x: np.ndarray, dim: int) -> bool:
    """Whether points (dim, n) hold a body against rigid motion: two distinct ones in 2D,
    three not on one line in 3D."""
    if x.shape[1] < dim:
        return False
    c = x - x.mean(axis=1, keepdims=True)
    s = np.linalg.svd(c, compute_uv=False)
    return bool(s[dim - 2] > 1e-9 * max(s[0], 1e-300))


def subdomain_matrices(body, parts: np.ndarray) -> tuple[list, list[np.ndarray]]:
    """Each subdomain's stiffness (its elements' alone, on the free dofs of its points, in the
    numbering of ``body.free_dofs``) and those dofs: ``K_ff = sum_i R_i^T K_i R_i``."""
    lam, mu = body.material.lame()
    free_no = -np.ones(body.ndofs, dtype=int)
    free_no[body.free_dofs] = np.arange(len(body.free_dofs))
    matrices, dofs = [], []
    for i, pts in enumerate(subdomain_points(body, parts)):
        d = (body.dim * pts[:, None] + np.arange(body.dim)).ravel()
        d = d[free_no[d] >= 0]
        K_i = body.section.stiffness(body, lam, mu, elements=np.flatnonzero(parts == i))
        matrices.append(K_i[d][:, d].tocsc())
        dofs.append(free_no[d])
    return matrices, dofs


def split_solve(body, backend: str | None = None, trailing: np.ndarray | None = None):
    """The body's split solve (:class:`~vfem.linalg.bddc.BDDCSolve`) on its free dofs, over
    ``body.subdomains`` subdomains; keeps the partition's sizes in ``body.subdomain_sizes``."""
    from ..linalg.bddc import BDDCSolve

    t0 = time.perf_counter()
    parts = body_partition(body)
    points = subdomain_points(body, parts)
    primal = primal_points(body, points)
    matrices, dofs = subdomain_matrices(body, parts)
    free_no = -np.ones(body.ndofs, dtype=int)
    free_no[body.free_dofs] = np.arange(len(body.free_dofs))
    primal_dofs = (body.dim * np.flatnonzero(primal)[:, None] + np.arange(body.dim)).ravel()
    is_primal = np.zeros(len(body.free_dofs), dtype=bool)
    is_primal[free_no[primal_dofs][free_no[primal_dofs] >= 0]] = True
    t1 = time.perf_counter()
    solve = BDDCSolve(len(body.free_dofs), matrices, dofs, is_primal, backend, trailing,
                      what=f"body {body.name!r}")
    body.subdomain_sizes = {
        "count": int(body.subdomains),
        "elements": [int((parts == i).sum()) for i in range(body.subdomains)],
        "dofs": [int(len(d)) for d in dofs],
        "interface_dofs": int(len(solve.interface)),
        "primal_dofs": int(solve.n_primal),
        "assemble_s": t1 - t0,
        "setup_s": solve.setup_s,
    }
    log.info("body %s: %d subdomains of %s dofs", body.name, body.subdomains,
             "/".join(map(str, body.subdomain_sizes["dofs"])))
    return solve
