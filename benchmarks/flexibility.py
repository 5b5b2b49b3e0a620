"""Routes to the flexibility on the contact dofs (the inverse stiffness among them), timed.

    python benchmarks/flexibility.py [DOFS [BACKEND ...]]   # default 300k, every backend
    python benchmarks/flexibility.py --sphere 30k 100k 300k  # 3D: each body of the sphere

``--sphere``: each body of the ``sphere`` example (Hertz's sphere on a flat, hexahedra) at
about the dofs given, PARDISO: the plain factorization of its free block (what a linear run
pays), the factorization with its contact candidates' dofs last and their Schur complement
(vfem's route), and the back-substitution route on the plain factor, timed on its first
``--columns`` columns (512) and scaled to all of them (said so in its row). Printed per body:
dofs, contact dofs, seconds and the factor's nonzeros of each route, and each route's cost in
plain factorizations. Then, once each: the factor entries of PARDISO's partial solve (its
sparse right-hand sides, ``iparm[30] = 3``: it orders the marked dofs last as the Schur
complement does), and the Schur complement with the factors out of core (``iparm[59] = 2``,
files in ``MKL_PARDISO_OOC_PATH`` or the working folder): its time and PARDISO's own count of the
memory it keeps, against the in-core one's. Issue 40, item 1.

For the Hertz example's cylinder (the body with all the dofs) and its tracked contact dofs, with
every installed backend:

* ``back-substitution``: factorize, then one solve per contact dof (blocks of 256 columns):
  what vfem did first;
* ``contact dofs last``: the route vfem takes, ``factorize(trailing=...)``: SuperLU and CHOLMOD
  order the contact dofs last and read the Schur complement off the factor's trailing block,
  PARDISO and MUMPS return it from their Schur-complement feature;
* ``sparse right-hand sides`` (PARDISO only): factorize, then one solve with the unit vectors of
  the contact dofs as sparse right-hand sides, only the contact dofs of the solution computed
  (``iparm[30] = 3``).

Printed: seconds for the factorization and for the flexibility, and the largest difference
from the first route's flexibility (relative).
"""

import sys
import time

import numpy as np

from vfem import linalg
from vfem.linalg.pardiso import PardisoFactorization
from vfem_examples.hertz import build
from vfem_tools.bench import hertz_parameters, parse_size

#: the out-of-core route's memory for PARDISO, MB (unless MKL_PARDISO_OOC_MAX_CORE_SIZE is set)
OOC_CORE_MB = 256


class Marked(PardisoFactorization):
    """PARDISO's positive definite factorization of ``A``, the dofs ``marked`` in ``perm``,
    with the ``iparm`` entries given besides vfem's own (its values, METIS, the factor's
    entries counted, zero-based indices): the routes vfem does not take, measured here."""

    def __init__(self, A, marked, settings: dict[int, int]):
        import scipy.sparse as sp

        self.shape = A.shape
        U = sp.triu(A, format="csr")
        U.sort_indices()
        self.n = U.shape[0]
        self._a = np.ascontiguousarray(U.data, dtype=float)
        self._ia, self._ja = U.indptr.astype(np.int32), U.indices.astype(np.int32)
        self._pt = np.zeros(64, dtype=np.int64)
        self._mtype = 2
        self._iparm = np.zeros(64, dtype=np.int32)
        self._iparm[[0, 1, 17, 34]] = [1, 2, -1, 1]
        for k, v in settings.items():
            self._iparm[k] = v
        self._perm = np.zeros(self.n, dtype=np.int32)
        self._perm[marked] = 1
        m = len(marked) if settings.get(35) else 0
        self._call(12, np.zeros(self.n), np.zeros(max(self.n, m * m)), 1)
        self.factor_entries = int(self._iparm[17])
        self.factor_bytes = 1024 * (int(self._iparm[15]) + int(self._iparm[16]))


def partial_solve(A, marked) -> Marked:
    """PARDISO with its sparse right-hand-side, partial-solution solve (``iparm[30] = 3``)."""
    return Marked(A, marked, {9: 8, 30: 3})


def out_of_core(A, marked) -> Marked:
    """PARDISO's Schur complement on ``marked`` with its factors out of core (``iparm[59] =
    2``: kept in files, ``MKL_PARDISO_OOC_PATH``, default the working folder; in memory at
    most ``MKL_PARDISO_OOC_MAX_CORE_SIZE`` MB, :data:`OOC_CORE_MB` unless set, else MKL's 2,000
    would hold these factors whole): its own count of the memory it keeps (``factor_bytes``)
    against the in-core factorization's."""
    import os

    os.environ.setdefault("MKL_PARDISO_OOC_MAX_CORE_SIZE", str(OOC_CORE_MB))
    return Marked(A, marked, {35: 2, 59: 2})


def main(dofs: int, backends: list[str]) -> None:
    model = build(hertz_parameters(dofs=dofs))
    surfaces = model.contact_surfaces()[1]
    body, surface = model.bodies[0], surfaces[0]
    body.assemble()
    K = body.K[body.free_dofs][:, body.free_dofs].tocsc()
    pos = np.searchsorted(body.free_dofs, surface.tracked_dofs)
    dofs_ = pos[body.free_dofs[np.minimum(pos, len(body.free_dofs) - 1)]
                == surface.tracked_dofs]
    m = len(dofs_)
    print(f"body {body.name!r}: {K.shape[0]} dofs, {m} contact dofs")
    print(f"{'backend':>8} {'route':>24} {'factorize s':>12} {'flexibility s':>14} "
          f"{'difference':>11}")
    reference = None
    for name in backends or linalg.available():
        t0 = time.perf_counter()
        f = linalg.factorize(K, name)
        t1 = time.perf_counter()
        G = np.empty((m, m))
        for start in range(0, m, 256):
            cols = dofs_[start:start + 256]
            E = np.zeros((K.shape[0], len(cols)))
            E[cols, np.arange(len(cols))] = 1.0
            G[:, start:start + len(cols)] = f.solve(E)[dofs_]
        t2 = time.perf_counter()
        reference = G if reference is None else reference
        scale = np.abs(reference).max()
        print(f"{name:>8} {'back-substitution':>24} {t1 - t0:>12.2f} {t2 - t1:>14.2f} "
              f"{np.abs(G - reference).max() / scale:>11.1e}", flush=True)
        t0 = time.perf_counter()
        f = linalg.factorize(K, name, trailing=dofs_, groups=body.free_dofs // 2)
        t1 = time.perf_counter()
        print(f"{name:>8} {'contact dofs last':>24} {t1 - t0:>12.2f} {'(included)':>14} "
              f"{np.abs(f.trailing_inverse - reference).max() / scale:>11.1e}", flush=True)
        if name == "pardiso":
            t0 = time.perf_counter()
            f = partial_solve(K, dofs_)
            t1 = time.perf_counter()
            E = np.zeros((K.shape[0], m), order="F")
            E[dofs_, np.arange(m)] = 1.0
            G = f.solve(E)[dofs_]
            t2 = time.perf_counter()
            print(f"{name:>8} {'sparse right-hand sides':>24} {t1 - t0:>12.2f} {t2 - t1:>14.2f} "
                  f"{np.abs(G - reference).max() / scale:>11.1e}", flush=True)


def sphere(sizes: list[int], columns: int = 512, repeat: int = 2) -> list[dict]:
    """The 3D routes per body of the sphere example (the module docstring); the faster of
    ``repeat`` alternating runs of each factorization kept."""
    import gc

    from vfem.bodies.condensation import free_positions
    from vfem_examples.sphere import build as build_sphere
    from vfem_tools.bench import sphere_parameters

    rows = []
    print(f"{'dofs':>9} {'body':>7} {'body dofs':>9} {'contact':>7} {'plain s':>8} "
          f"{'schur s':>8} {'ratio':>6} {'nnz plain':>11} {'nnz schur':>11} "
          f"{'back-sub s':>11} {'ratio':>6} {'nnz partial':>11} {'ooc s':>7} "
          f"{'MiB kept':>8} {'ooc MiB':>8}")
    for size in sizes:
        model = build_sphere(sphere_parameters(size, None))
        surfaces = model.contact_surfaces()[1]
        total = 0
        for body in model.bodies:
            body.assemble()
            total += body.ndofs
        for body, surface in zip(model.bodies, surfaces):
            K = body.K_ff
            pos, free = free_positions(body, np.asarray(surface.candidate_dofs, dtype=int))
            trailing = pos[free]
            m = len(trailing)
            best = {"plain": np.inf, "schur": np.inf}
            entries = {}
            for _ in range(repeat):
                for route in ("plain", "schur"):
                    gc.collect()
                    t0 = time.perf_counter()
                    f = linalg.factorize(K, "pardiso",
                                         trailing=trailing if route == "schur" else None)
                    best[route] = min(best[route], time.perf_counter() - t0)
                    entries[route] = f.factor_entries
                    if route == "plain":
                        cols = trailing[:columns]
                        E = np.zeros((K.shape[0], len(cols)), order="F")
                        E[cols, np.arange(len(cols))] = 1.0
                        t0 = time.perf_counter()
                        for start in range(0, len(cols), 256):
                            f.solve(E[:, start:start + 256])
                        back = (time.perf_counter() - t0) * m / max(len(cols), 1)
                    del f
            # PARDISO's partial solve orders the marked dofs last too (its factor's entries)
            gc.collect()
            t0 = time.perf_counter()
            f = partial_solve(K, trailing)
            partial_s, entries["partial"] = time.perf_counter() - t0, f.factor_entries
            del f
            in_core = linalg.factorize(K, "pardiso", trailing=trailing).factor_bytes
            gc.collect()
            t0 = time.perf_counter()
            f = out_of_core(K, trailing)
            ooc_s, ooc_bytes = time.perf_counter() - t0, f.factor_bytes
            del f
            row = {"dofs": total, "body": body.name, "body_dofs": K.shape[0],
                   "contact_dofs": m, "plain_s": best["plain"], "schur_s": best["schur"],
                   "nnz_plain": entries["plain"], "nnz_schur": entries["schur"],
                   "back_substitution_s": best["plain"] + back, "sampled_columns":
                   min(columns, m), "partial_s": partial_s, "nnz_partial": entries["partial"],
                   "out_of_core_s": ooc_s, "in_core_mib": in_core / 2**20,
                   "out_of_core_mib": ooc_bytes / 2**20}
            rows.append(row)
            print(f"{total:>9} {body.name:>7} {K.shape[0]:>9} {m:>7} {best['plain']:>8.2f} "
                  f"{best['schur']:>8.2f} {best['schur'] / best['plain']:>6.2f} "
                  f"{entries['plain']:>11,} {entries['schur']:>11,} "
                  f"{best['plain'] + back:>11.2f} {(best['plain'] + back) / best['plain']:>6.2f} "
                  f"{entries['partial']:>11,} {ooc_s:>7.2f} {in_core / 2**20:>8,.0f} "
                  f"{ooc_bytes / 2**20:>8,.0f}", flush=True)
        del model, surfaces
        gc.collect()
    return rows


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--sphere":
        sphere([parse_size(a) for a in sys.argv[2:]] or [30_000, 100_000, 300_000])
    else:
        main(parse_size(sys.argv[1]) if len(sys.argv) > 1 else 300_000, sys.argv[2:])
