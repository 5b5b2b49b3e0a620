"""How much memory an analysis needs, estimated before anything is factorized.

A model too large for the machine should stop at once with a message saying so, not after
minutes of swapping or with the operating system's out-of-memory killer. :func:`check_memory`
estimates the peak memory of setting the bodies up (:meth:`vfem.solver.Analysis.setup`: assembly,
SuperLU factorization, the flexibility on the contact surfaces) from the meshes and the contact
surfaces alone, logs it, and raises :class:`~vfem.errors.AnalysisError` when it exceeds the
memory available (:func:`available_memory`). :func:`memory_guard` turns a ``MemoryError`` that
gets through anyway into the same kind of message.

The model (bytes), per body, summed over the bodies:

    FACTOR_BYTES * entries(factor)  +  DENSE_BYTES * m**2  +  STIFFNESS_BYTES * nnz(K)

(``PARDISO_DENSE_BYTES`` for ``DENSE_BYTES`` under PARDISO)

plus ``BASE_BYTES``, plus ``PAIR_BYTES * nc_i * nc_j`` per pair of contact surfaces that may
touch (matrix-free: ``SPARSE_PAIR_BYTES * (nc_i + nc_j)``, nothing dense), plus
``LARGE_BYTES * ndofs * 2 nc`` per large-kinematics body (fitted when its tangent flexibility
for the candidate dofs was built dense, ndofs x 2 nc, in each Newton iteration; since issue 19
it comes from the Schur complement, or from back-substitutions in blocks of columns, so the
term is an upper bound: total-Lagrangian Hertz at 119k dofs, estimate 2,642
MiB, peak 1,281 MiB). Here

* ``nnz(K)`` is its structural count, from the mesh: 4 (points + 2 pairs of points sharing an
  element), the pairs being C(k, 2) per element of k points less those counted twice on shared
  edges;
* ``m`` is the number of condensed dofs (``ContactSurface.condensed_dofs``: the candidate
  nodes', and the rind's too for the thesis variant), ordered last in the factorization; the
  dense inverse on them is what grows fastest when a contact surface is long;
* ``entries(factor)`` is the backend's fill (:func:`factor_entries`), per backend: SuperLU's
  nnz(L + U) with vfem's ordering (minimum degree on the node graph, the condensed dofs last),
  modelled as ``ndofs * max(20, 22 log2(ndofs) - 140) + 0.6 m**2``; PARDISO's nnz(L) (nested
  dissection, Cholesky; the count PARDISO reports), ``ndofs * max(10, 8.4 log2(ndofs) - 48) +
  0.5 m**2``. Other backends take SuperLU's, the larger.

The constants were fitted (``benchmarks/memory_model.py [--solver pardiso]`` repeats the
measurements) to the peak resident memory of ``Analysis.setup`` and the backends' fill on two
rectangular bodies in contact, linear and quadratic triangles and quadrilaterals, 460 to 103,000
dofs a body, and on two long thin strips whose whole faces are candidates (up to 4,000 tracked
dofs a body): SuperLU's fill model gives 1.0 to 1.5 times its nnz(L + U), and the whole
estimate 1.05 to 1.85 times the measured peak (1.05 to 1.5 above 100 MiB); PARDISO's gives 0.91
to 1.11 times its count above 20,000 dofs (0.82 to 1.14 at all sizes), the whole estimate 0.85
to 1.24 times the peak above 100 MiB. Far more irregular meshes fill differently; the estimate
is a guide, not a bound.

In 3D (issue 21) a solid's fill grows as ndofs^(4/3), not as ndofs log ndofs: the fill per dof
is ``a ndofs^(1/3) + b`` (:data:`PARDISO_3D`, :data:`SUPERLU_3D`, fitted on the sphere
example's hexahedral bodies), the stiffness's structural count is exact (the distinct pairs of
points sharing an element, nine entries each) and a body has three dofs a point. Under PARDISO
a 3D body's factors take :data:`PARDISO_3D_FACTOR_BYTES` per entry (PARDISO's own count) and
its stiffness :data:`PARDISO_3D_STIFFNESS_BYTES`. Against the set-up's peaks on the sphere
example (``benchmarks/memory_model.py --solver pardiso sphere 1 N``, 2026-11-28; the fill
model 0.97 to 1.05 times PARDISO's count from 92k dofs up):

| facets across a | dofs | peak MiB | estimate MiB |
|---:|---:|---:|---:|
| 12 | 92,172 | 1,106 | 966 |
| 22 | 315,825 | 4,730 | 4,909 |
| 29 | 568,008 | 10,293 | 10,721 |
| 36 | 928,191 | 19,532 | 20,626 |

(the peaks before the bodies stopped keeping scikit-fem's basis, 147 KB a hexahedron, were 2.8
times these, and the model fitted to them refused the 928k-dof sphere with 52 GiB; it now
runs on the 24 GB machine, ``vfem bench sphere``).
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .errors import AnalysisError

log = logging.getLogger(__name__)

#: Bytes per entry of SuperLU's factors: values and indices, and the transient copies of L and U
#: the trailing block is read from.
FACTOR_BYTES = 28
#: Bytes per entry of the square of the tracked dofs: the dense Schur complement, its inverse,
#: the flexibility kept by the body and by its contact surface.
DENSE_BYTES = 28
#: Bytes per stiffness entry: the assembled matrix, its free block, the reordered copy that is
#: factorized, and scikit-fem's element-by-element assembly arrays.
STIFFNESS_BYTES = 64
#: The same under PARDISO, whose Schur complement vfem inverts in PARDISO's own output array
#: (:func:`vfem.linalg.common.spd_inverse_in_place`; its factor's dense block is in the fill)
PARDISO_DENSE_BYTES = 12
#: Bytes per product of two contact surfaces' candidate counts (the paired variant's transfer
#: and mass matrices and its condensed flexibility; fitted while N and T were dense: since
#: issue 40 they are sparse, and on the dense route the term is an upper bound).
PAIR_BYTES = 32
#: The matrix-free route forms no pair matrix, and a pair's N, T and virtual-node weights are
#: sparse (issue 40): per candidate node of either surface at most this many bytes (16 an
#: entry, values and indices; at most 32 entries a node over the three matrices: a node's
#: column of N reaches the nodes of the facets around it, nine on a quadrilateral surface,
#: T's the nodes of the facets it overlaps, the weights four a row).
SPARSE_PAIR_BYTES = 16 * 32
#: Bytes per entry of a large-kinematics body's dense tangent flexibility (ndofs x 2 nc) and its
#: right-hand sides.
LARGE_BYTES = 24
#: PARDISO's fill per dof, ``max(MIN, SLOPE log2(ndofs) - OFFSET)``
PARDISO_MIN, PARDISO_SLOPE, PARDISO_OFFSET = 10.0, 8.4, 48.0
#: 3D: fill per dof ``a ndofs^(1/3) + b`` (nested dissection of a 3D grid: nnz(L) ~ n^(4/3)),
#: fitted 2026-11-28 to the sphere example's two bodies (trilinear hexahedra, 5,000 to 47,000
#: free dofs a body, condensed dofs last): PARDISO's nnz(L) within 0.96 to 1.02 times the fit,
#: SuperLU's nnz(L + U) within 0.98 to 1.02 (5,000 to 21,000). The 2D log-law put 3D bodies'
#: factors 5 to 7 times too low.
PARDISO_3D = (25.5, -143.0)
SUPERLU_3D = (65.6, -446.0)
#: Bytes per entry of PARDISO's factors of a 3D body: its values and indices, the Schur
#: complement's block included (PARDISO's own count of its memory, ``iparm[15] + iparm[16]``,
#: over its nnz(L): 9.0 to 9.6 on the sphere's bodies from 41k to 889k dofs, 2026-11-28).
#: :data:`FACTOR_BYTES` is SuperLU's, whose copies of L and U at the trailing block cost more;
#: 2D keeps it for PARDISO too, where the whole 2D estimate was fitted with it.
PARDISO_3D_FACTOR_BYTES = 10
#: Bytes per stiffness entry of a 3D body under PARDISO: the matrix kept, PARDISO's copy of its
#: upper triangle and what the assembly and the contact set-up leave (fitted: 27 to 35 bytes
#: beside the factors and the dense blocks from 316k to 928k dofs). A 3D body keeps no basis
#: and no free block (:attr:`vfem.bodies.Body.basis`): :data:`STIFFNESS_BYTES` counts both.
PARDISO_3D_STIFFNESS_BYTES = 32
#: What Python, NumPy and scikit-fem hold besides (measured: about 15 MB).
BASE_BYTES = 16 * 2**20


def factor_entries(ndofs: int, condensed: int, backend: str | None = None, dim: int = 2
                   ) -> float:
    """Estimated entries of a body's factors with ``condensed`` dofs ordered last: SuperLU's
    nnz(L + U), or with ``backend`` ``"pardiso"`` its nnz(L) (nested dissection, Cholesky).
    ``dim`` 3: a solid's fill grows as ndofs^(4/3) (:data:`PARDISO_3D`, :data:`SUPERLU_3D`)."""
    if ndofs <= 0:
        return 0.0
    if dim == 3:
        a, b = PARDISO_3D if backend == "pardiso" else SUPERLU_3D
        per_dof = max(PARDISO_MIN, a * float(ndofs) ** (1.0 / 3.0) + b)
        return ndofs * per_dof + (0.5 if backend == "pardiso" else 0.6) * float(condensed) ** 2
    if backend == "pardiso":
        per_dof = max(PARDISO_MIN, PARDISO_SLOPE * math.log2(max(ndofs, 2)) - PARDISO_OFFSET)
        return ndofs * per_dof + 0.5 * float(condensed) ** 2
    per_dof = max(20.0, 22.0 * math.log2(max(ndofs, 2)) - 140.0)
    return ndofs * per_dof + 0.6 * float(condensed) ** 2


def stiffness_entries(body) -> int:
    """Structural nnz of a body's stiffness, from its mesh (nothing assembled). 3D: counted
    exactly, the distinct pairs of points sharing an element (nine entries each)."""
    mesh = body.mesh
    if body.dim == 3:
        import scipy.sparse as sp

        t = mesh.t if body.order == 1 else body.dof_map.element_dofs[::3] // 3
        k = t.shape[0]
        rows, cols = np.repeat(t, k, axis=0).ravel(), np.tile(t, (k, 1)).ravel()
        pattern = sp.coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)),
                                shape=(body.npoints, body.npoints)).tocsr()
        return 9 * int(pattern.nnz)
    k = body.element().doflocs.shape[0]  # points per element
    per_facet = 1 if body.order == 1 else 3  # pairs of points on a shared edge
    interior = int((mesh.f2t[1] >= 0).sum())
    pairs = k * (k - 1) // 2 * mesh.nelements - per_facet * interior
    return 4 * (body.npoints + 2 * pairs)


def estimate(surfaces, pairs=(), backend: str | None = None, matrix_free: bool = False
             ) -> dict[str, float]:
    """Estimated peak bytes of the set-up with ``backend`` (SuperLU's model for any other),
    by part: ``{"total", "factors", "dense", "stiffness", "pairs", "large"}`` (see the module
    docstring for the model). ``matrix_free`` (issue 22): no body is condensed, so no dense
    block and no condensed block in the factors."""
    parts = dict.fromkeys(("factors", "dense", "stiffness", "pairs", "large"), 0.0)
    for s in surfaces:
        body = s.body
        ndofs = body.dim * body.npoints
        m = 0 if matrix_free else len(s.condensed_dofs)
        per_entry = PARDISO_3D_FACTOR_BYTES if backend == "pardiso" and body.dim == 3 \
            else FACTOR_BYTES
        parts["factors"] += per_entry * factor_entries(ndofs, m, backend, body.dim)
        parts["dense"] += (PARDISO_DENSE_BYTES if backend == "pardiso" else DENSE_BYTES) \
            * float(m) ** 2
        parts["stiffness"] += (PARDISO_3D_STIFFNESS_BYTES if backend == "pardiso"
                               and body.dim == 3 else STIFFNESS_BYTES) * stiffness_entries(body)
        if body.iterates:  # its tangent's factor and flexibility, each iteration
            parts["large"] += LARGE_BYTES * ndofs * 2.0 * s.nc
    for i, j in pairs.keys():
        parts["pairs"] += (SPARSE_PAIR_BYTES * float(surfaces[i].nc + surfaces[j].nc)
                           if matrix_free else PAIR_BYTES * float(surfaces[i].nc) * surfaces[j].nc)
    parts["total"] = BASE_BYTES + sum(parts.values())
    return parts


def available_memory() -> int | None:
    """Bytes this process may still use, or None if it cannot be told.

    The kernel's ``MemAvailable`` (free memory plus the caches it can drop; Linux), capped by
    the memory limit of the process's control group (containers, batch schedulers) where there
    is one; else free physical pages (``sysconf``).
    """
    available = None
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                available = int(line.split()[1]) * 1024
                break
    except (OSError, ValueError, IndexError):
        pass
    if available is None:
        try:
            available = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_AVPHYS_PAGES")
        except (AttributeError, ValueError, OSError):
            return None
    for limit_file, usage_file in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                                   ("/sys/fs/cgroup/memory/memory.limit_in_bytes",
                                    "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        try:
            limit = Path(limit_file).read_text().strip()
            usage = int(Path(usage_file).read_text().strip())
        except (OSError, ValueError):
            continue
        if limit.isdigit() and int(limit) < 2**60:  # "max" or a huge number: no limit
            available = min(available, max(0, int(limit) - usage))
        break
    return available


def _size(n: float) -> str:
    return f"{n / 2**30:.2f} GiB" if n >= 2**30 else f"{n / 2**20:.0f} MiB"


def _advice(parts: dict[str, float]) -> str:
    """What to change, from the part of the estimate that dominates."""
    if parts["dense"] + parts["pairs"] + parts["large"] > parts["factors"] + parts["stiffness"]:
        return ("the contact surfaces dominate: fewer contact candidates (contact_boundaries, "
                "a smaller contact.search_distance) or coarser elements along them")
    return "the bodies' meshes dominate: coarser meshes away from the contact"


def check_memory(surfaces, pairs=(), backend: str | None = None, matrix_free: bool = False
                 ) -> dict[str, float]:
    """Log the estimated memory of the set-up and refuse a model that cannot fit.

    Raises:
        AnalysisError: the estimate exceeds :func:`available_memory`; the message gives both
            and what to change.
    """
    parts = estimate(surfaces, pairs, backend, matrix_free)
    available = available_memory()
    log.info("estimated memory for the set-up: %s (factors %s, dense contact matrices %s, "
             "stiffness %s); available: %s", _size(parts["total"]), _size(parts["factors"]),
             _size(parts["dense"] + parts["pairs"] + parts["large"]), _size(parts["stiffness"]),
             "unknown" if available is None else _size(available))
    if available is not None and parts["total"] > available:
        raise AnalysisError(
            f"the analysis needs about {_size(parts['total'])} of memory (estimated before "
            f"factorizing: factors {_size(parts['factors'])}, dense contact matrices "
            f"{_size(parts['dense'] + parts['pairs'] + parts['large'])}, stiffness "
            f"{_size(parts['stiffness'])}) but only {_size(available)} is available; "
            f"{_advice(parts)}")
    return parts


@contextmanager
def memory_guard(what: str) -> Iterator[None]:
    """Turn a ``MemoryError`` raised while doing ``what`` into an :class:`AnalysisError`."""
    try:
        yield
    except MemoryError:
        available = available_memory()
        raise AnalysisError(
            f"out of memory while {what}"
            + ("" if available is None else f" ({_size(available)} available now)")
            + "; use coarser meshes or fewer contact candidates (contact_boundaries, a smaller "
            "contact.search_distance)") from None
