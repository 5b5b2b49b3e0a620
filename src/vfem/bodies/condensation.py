"""A body's stiffness, its factorization and its flexibility: what contact reads of a linear
body.

Bodies never share a matrix. Contact reaches a body only as nodal forces on its contact surface,
so for a linear body the whole response the contact algorithm needs is

    u = load_factor * u_load + platen_displacement * u_platen + K^-1 f_contact

where ``u_load`` is the solution under the body's loads and prescribed displacements at load factor
1 (by load curve, :mod:`.loads`), ``u_platen`` the solution for a unit motion of its
force-controlled platen (if any), and ``K^-1`` is applied with the body's own factorization,
supports kept (:func:`response`, :func:`flexibility_columns`); with the contact dofs ordered last
the factorization also yields the flexibility among them (the condensation of vfem-method §3.1).
"""

from __future__ import annotations

import logging
import time

import numpy as np

from ..linalg import factorize
from .loads import constraints, load_cases
from .mechanics import _platen_stiffness, mechanics_for
from .validation import check_supported, validate

log = logging.getLogger(__name__)


def assemble(body, stiffness: bool = True) -> dict[int, float]:
    """Validate and assemble, without factorizing anything: the basis, the stiffness ``K``
    (all dofs), the constrained dofs (``fixed_dofs``, ``platen_dofs``, ``free_dofs``), the
    load vector ``f_load`` and ``u_prescribed`` (the constrained dofs' values, 0 on supports
    and the platen's dofs), both with every load at its full value (load factor 1, or
    multiplier 1 on a load curve), and the same split by load curve (``load_cases``, the
    proportional case first). Refuses a body free to move as a rigid body. Returns the
    prescribed value of every supported or prescribed dof.

    :func:`setup` starts with it; the classical baselines
    (:mod:`vfem.contact.formulations.baselines`), which solve every body in one global system,
    need only this part. ``stiffness`` False: all but ``K`` (an :class:`Elsewhere` in its
    place), for a rank that does not own the body (:mod:`vfem.parallel`, issue 40: its owner
    alone computes what reads the stiffness).
    """
    validate(body)
    t0 = time.perf_counter()
    lam, mu = body.material.lame()
    section = body.section  # its measure, strains and basis (:mod:`.section`)
    basis = section.basis(body)
    if basis is not None:
        body.basis = basis
    if stiffness:
        body.K = section.stiffness(body, lam, mu)
        body.ndofs = body.K.shape[0]
    else:
        body.K = Elsewhere(body.name)
        body.ndofs = body.dim * body.npoints
    t1 = time.perf_counter()
    fixed = constraints(body)
    check_supported(body)
    body.free_dofs = np.setdiff1d(np.arange(body.ndofs), body.fixed_dofs)
    body.load_cases = load_cases(body, fixed)
    if len(body.load_cases) == 1:  # proportional loading: as before load curves existed
        body.f_load = body.load_cases[0].force
        body.u_prescribed = body.load_cases[0].prescribed
    else:
        body.f_load = sum(c.force for c in body.load_cases)
        body.u_prescribed = sum(c.prescribed for c in body.load_cases)
    body.timings = {"assemble_s": t1 - t0, "constraints_s": time.perf_counter() - t1}
    return fixed


class Elsewhere:
    """A body's stiffness on an MPI rank that does not own the body (:mod:`vfem.parallel`):
    it was not assembled there, and what reads it runs on the owner. Any use is a bug, said
    as one (not a numpy error about an object array)."""

    def __init__(self, name: str):
        self.name = name

    def _refuse(self, *args, **kwargs):
        raise RuntimeError(f"body {self.name!r}: its stiffness is assembled on the MPI rank that "
                           "owns it only (vfem.parallel), and was read on another")

    __matmul__ = __rmatmul__ = __getitem__ = __array__ = _refuse

    def __getattr__(self, attr: str):
        if attr.startswith("__"):
            raise AttributeError(attr)
        self._refuse()


def setup(body, backend: str | None = None, condensed_dofs: np.ndarray | None = None,
          assembled: dict[int, float] | None = None) -> None:
    """Validate, assemble the stiffness (:func:`assemble`), factorize it and solve the unit
    load cases.

    With ``condensed_dofs`` (the dofs contact follows), the factorization also yields the
    inverse stiffness among them (``condensed_flexibility``, supports kept: zero on fixed dofs).

    A body with ``subdomains`` > 1 gets the split solve of :mod:`.subdomains` in place of the
    factorization (BDDC, the same ``solve`` and ``trailing_inverse``); its flexibility among
    the condensed dofs is then one PCG solve per condensed dof (a block of unit columns).
    """
    fixed = assemble(body) if assembled is None else assembled
    t1 = time.perf_counter()
    platen_dofs = body.platen_dofs
    K_ff = body.K_ff
    trailing = None
    if condensed_dofs is not None:
        condensed_dofs = np.asarray(condensed_dofs, dtype=int)
        pos, free = free_positions(body, condensed_dofs)
        trailing = pos[free]
    t2 = time.perf_counter()
    if body.subdomains > 1:  # split into subdomains, solved by BDDC (issue 43)
        from .subdomains import split_solve

        body.factor = split_solve(body, backend, trailing=trailing)
    else:
        body.factor = factorize(K_ff, backend, trailing=trailing,
                                groups=body.free_dofs // body.dim, what=f"body {body.name!r}")
    t3 = time.perf_counter()
    del K_ff  # the factorization has its own copy (a million-dof 3D model: 1 GB each)
    body.condensed_flexibility = None
    if condensed_dofs is not None:
        if free.all():  # the factor's block is the flexibility: no copy
            G = body.factor.trailing_inverse
        else:
            G = np.zeros((len(condensed_dofs), len(condensed_dofs)))
            ix = np.flatnonzero(free)
            G[np.ix_(ix, ix)] = body.factor.trailing_inverse
        body.condensed_flexibility = G
        # the factor's dense copy is not needed for its solves: freed (issue 19, item 4:
        # three dense copies per body were kept)
        body.factor.trailing_inverse = None

    for case in body.load_cases:
        case.displacement = solve_with(body, case.force, case.prescribed)
    body.u_load = (body.load_cases[0].displacement if len(body.load_cases) == 1
                   else sum(c.displacement for c in body.load_cases))
    # The platen's reaction (the force it applies to the body, along its component) is
    # linear in the state: sum_k m_k(load_factor) * (case k's reaction) + platen_displacement
    # * platen_stiffness + (reaction per unit contact force) . contact forces.
    body.u_platen = np.zeros(body.ndofs)
    body.platen_load_reaction = body.platen_stiffness = 0.0
    if body.platen is not None:
        u_unit = np.zeros(body.ndofs)
        u_unit[platen_dofs] = 1.0
        body.u_platen = solve_with(body, np.zeros(body.ndofs), u_unit)
        for case in body.load_cases:
            case.platen_reaction = float((body.K @ case.displacement
                                          - case.force)[platen_dofs].sum())
        body.platen_load_reaction = sum(c.platen_reaction for c in body.load_cases)
        body.platen_stiffness = _platen_stiffness(body.K, body.u_platen, platen_dofs)
    # how the body answers its contact forces: linearly, or under large kinematics
    body.mechanics = mechanics_for(body, fixed)
    body.timings.update(constraints_s=body.timings["constraints_s"] + t2 - t1,
                        factorize_s=t3 - t2, load_cases_s=time.perf_counter() - t3)
    log.info("body %s: %d points, %d dofs (%d fixed)", body.name, body.ndofs // body.dim,
             body.ndofs, len(body.fixed_dofs))


def solve_with(body, f: np.ndarray, u_fixed: np.ndarray) -> np.ndarray:
    """Displacement for load ``f`` with the fixed dofs at ``u_fixed``."""
    u = u_fixed.copy()
    rhs = f - body.K @ u_fixed
    u[body.free_dofs] = body.factor.solve(rhs[body.free_dofs])
    return u


def response(body, nodal_force: np.ndarray) -> np.ndarray:
    """Displacement due to nodal forces (ndofs), supports kept at zero: K^-1 f."""
    return solve_with(body, np.asarray(nodal_force, dtype=float), np.zeros(body.ndofs))


def free_positions(body, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where body dofs ``dofs`` stand among the free dofs (the rows of the factorized
    block), and which of them are free at all (a constrained dof has no row)."""
    dofs = np.asarray(dofs, dtype=int)
    pos = np.searchsorted(body.free_dofs, dofs)
    is_free = (pos < len(body.free_dofs)) & (
        body.free_dofs[np.minimum(pos, len(body.free_dofs) - 1)] == dofs)
    return pos, is_free


def flexibility_columns(body, dofs: np.ndarray, chunk: int = 256) -> np.ndarray:
    """Columns of K^-1 (supports kept) for the given dofs, shape (ndofs, len(dofs)).

    One back-substitution per dof; constrained dofs give zero columns.
    """
    dofs = np.asarray(dofs, dtype=int)
    out = np.zeros((body.ndofs, len(dofs)))
    pos, is_free = free_positions(body, dofs)
    cols = np.flatnonzero(is_free)
    for start in range(0, len(cols), chunk):
        c = cols[start:start + chunk]
        rhs = np.zeros((len(body.free_dofs), len(c)))
        rhs[pos[c], np.arange(len(c))] = 1.0
        out[np.ix_(body.free_dofs, c)] = body.factor.solve(rhs)
    return out
