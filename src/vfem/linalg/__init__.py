"""Sparse factorization behind one small interface.

``factorize(A, backend)`` returns an object with ``solve(b)`` for a vector or a block of columns.
Every body is factorized once (per tangent, under large kinematics) and the factorization is
reused for every solve after that.

``factorize(A, trailing=dofs, groups=node_of_dof)`` also returns the inverse of ``A`` restricted to
``dofs`` (``trailing_inverse``): what contact needs, the flexibility on the contact dofs. Each
backend gets it from one factorization with those dofs eliminated last, as the dense inverse of
the Schur complement on them — never one back-substitution per contact dof.

Backends (docs/benchmarks.md compares them):

* ``superlu`` — SciPy's SuperLU, always there (:mod:`.superlu`);
* ``pardiso`` — MKL PARDISO, from the ``pypardiso`` package (:mod:`.pardiso`);
* ``cholmod`` — SuiteSparse CHOLMOD, from ``scikit-sparse`` (:mod:`.cholmod`);
* ``mumps`` — MUMPS, from ``python-mumps`` (:mod:`.mumps`).

``"auto"`` (the default) picks the first installed in :data:`PREFERENCE`, the order measured
fastest on the Hertz benchmark. ``vfem run --solver NAME`` (or :func:`use`) chooses one.
"""

from __future__ import annotations

import importlib
import logging

import numpy as np
import scipy.sparse as sp

log = logging.getLogger(__name__)

#: backend name -> (module, class)
BACKENDS = {
    "superlu": ("superlu", "SuperLUFactorization"),
    "pardiso": ("pardiso", "PardisoFactorization"),
    "cholmod": ("cholmod", "CholmodFactorization"),
    "mumps": ("mumps", "MumpsFactorization"),
}

#: what "auto" tries, fastest first (measured: docs/benchmarks.md, "Linear-algebra backends")
PREFERENCE = ("pardiso", "cholmod", "mumps", "superlu")

_chosen: str | None = None
_available: dict[str, bool] = {}


def is_available(name: str) -> bool:
    """Whether the backend's package (and the library under it) loads here."""
    if name not in _available:
        if name == "superlu":
            _available[name] = True
        else:
            module = importlib.import_module(f".{BACKENDS[name][0]}", __name__)
            _available[name] = bool(module.available())
    return _available[name]


def available() -> list[str]:
    """The installed backends, in order of preference."""
    return [name for name in PREFERENCE if is_available(name)]


def resolve(name: str | None = None) -> str:
    """The backend a name stands for: ``None`` -> the one chosen with :func:`use`, else
    ``"auto"``; ``"auto"`` -> the fastest installed. Raises InputError for an unknown or
    uninstalled backend, naming the ones there are."""
    from ..errors import InputError

    name = name or _chosen or "auto"
    if name == "auto":
        return available()[0]
    if name not in BACKENDS:
        raise InputError(f"unknown linear solver {name!r}; choose auto or one of: "
                         f"{', '.join(BACKENDS)} (installed here: {', '.join(available())})")
    if not is_available(name):
        hint = {"pardiso": "pip install pypardiso",
                "cholmod": "apt install libsuitesparse-dev, then pip install "
                           "scikit-sparse==0.4.16",
                "mumps": "apt install libmumps-seq-dev, then pip install python-mumps"}[name]
        raise InputError(f"linear solver {name!r} is not installed ({hint}); installed here: "
                         f"{', '.join(available())}")
    return name


def use(name: str) -> str:
    """Make ``name`` (or ``"auto"``) the backend of every later factorization in this process
    that does not name its own; returns the backend it resolves to."""
    global _chosen
    resolved = resolve(name)
    _chosen = name
    return resolved


def factorize(A: sp.spmatrix, backend: str | None = None, trailing: np.ndarray | None = None,
              groups: np.ndarray | None = None, spd: bool = True, what: str = "a matrix",
              analysis=None, symmetric: bool = True):
    """Factorize the sparse matrix ``A`` with the named backend (see the module docstring).

    ``spd=False``: ``A`` is symmetric but indefinite (a saddle-point system of Lagrange
    multipliers); ``trailing`` is then not supported, and a backend that factorizes positive
    definite matrices only (CHOLMOD) hands the matrix to SuperLU.

    A backend that fails (a singular matrix, a library error) raises AnalysisError naming
    ``what`` (e.g. ``"body 'flat'"``), the backend and its reason.

    ``analysis``: an earlier factorization by the same backend of a matrix with the same
    sparsity (and ``trailing``), e.g. a large body's tangent of the last iteration; a backend
    that can (PARDISO) takes over its ordering and symbolic analysis, and the earlier one can no
    longer solve. Others ignore it.

    ``symmetric=False`` (with ``spd=False``): ``A`` is not symmetric (the Lagrange baseline's
    saddle point with Coulomb friction's ties); PARDISO factorizes it by LU, MUMPS and SuperLU
    always do, and CHOLMOD hands it to SuperLU."""
    from ..errors import AnalysisError

    name = resolve(backend)
    if not spd and name == "cholmod":
        log.info("cholmod factorizes positive definite matrices only: superlu for this one")
        name = "superlu"
    module, cls = BACKENDS[name]
    factory = getattr(importlib.import_module(f".{module}", __name__), cls)
    extra = {} if symmetric or name != "pardiso" else {"symmetric": False}
    try:
        if analysis is not None and getattr(factory, "reuses_analysis", False):
            return factory(A, trailing=trailing, groups=groups, spd=spd, analysis=analysis,
                           **extra)
        return factory(A, trailing=trailing, groups=groups, spd=spd, **extra)
    except (np.linalg.LinAlgError, RuntimeError, ValueError) as exc:
        raise AnalysisError(f"{what}: factorizing its stiffness ({A.shape[0]} dofs) with {name} "
                            f"failed: {exc}; check that it is held against every rigid-body "
                            "motion, or try --solver superlu") from exc
