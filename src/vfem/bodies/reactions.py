"""The forces a body's constraints apply to it: nodal reactions, per boundary and per component,
from the out-of-balance force on the constrained dofs."""

from __future__ import annotations

import numpy as np

from .loads import boundary_dofs, superpose


def applied_load(body, load_factor: float) -> np.ndarray:
    """The body's applied nodal loads (ndofs: its tractions' load vector) at
    ``load_factor``, each traction at its load curve's multiplier; the one place reactions,
    force balances and the large-kinematics loads read the loads from."""
    return superpose(load_factor, ((c.amplitude, c.force) for c in body.load_cases))


def nodal_reaction(body, u: np.ndarray, load_factor: float = 1.0,
               contact_force: np.ndarray | None = None) -> np.ndarray:
    """The nodal forces (ndofs) the constraints (supports, prescribed displacements, the
    platen) apply to the body, for displacement ``u`` (ndofs) under the loads at
    ``load_factor`` and the nodal ``contact_force`` (ndofs): the out-of-balance force
    ``K u - applied_load(load_factor) - f_contact`` (the internal force in place of ``K u``
    under large kinematics) on the constrained dofs (``fixed_dofs``), zero on the free
    ones, where it is only the solver's residual. Adding it to the loads and contact
    forces balances the body, so its sum is the body's total support reaction, each
    constrained dof counted once."""
    Ku = body.mechanics.internal_force(u)
    r = Ku - body.applied_load(load_factor)
    if contact_force is not None:
        r = r - contact_force
    out = np.zeros(body.ndofs)
    out[body.fixed_dofs] = r[body.fixed_dofs]
    return out


def reaction_dofs(body) -> dict[str, np.ndarray]:
    """Per boundary that carries a support, a prescribed displacement or the platen (in
    that order of first mention), the dofs its own conditions constrain: a support's
    components, a prescribed component, the platen's component. A node shared by two such
    boundaries (a corner) is in both where both constrain the same component."""
    parts: dict[str, list[np.ndarray]] = {}
    for s in body.supports:
        for c in body.support_components(s):
            parts.setdefault(s.boundary, []).append(boundary_dofs(body, s.boundary, c))
    for pd in body.prescribed:
        parts.setdefault(pd.boundary, []).append(boundary_dofs(body, pd.boundary,
                                                                     pd.component))
    if body.platen is not None:
        parts.setdefault(body.platen.boundary, []).append(body.platen_dofs)
    return {name: np.unique(np.concatenate(d)) for name, d in parts.items()}


def boundary_reactions(body, nodal_reaction: np.ndarray) -> dict[str, tuple[float, ...]]:
    """Per constrained boundary (:func:`reaction_dofs`), the total (x, y), or (x, y, z) in
    3D, of
    ``nodal_reaction`` (ndofs, from :func:`nodal_reaction`) over the dofs it constrains.
    A shared corner dof counts in each boundary that constrains it, so the boundaries'
    totals add up to the body's total only where no dof is shared."""
    r = np.asarray(nodal_reaction, dtype=float).ravel()
    out = {}
    for name, dofs in reaction_dofs(body).items():
        dim = body.dim
        out[name] = tuple(float(r[dofs[dofs % dim == c]].sum()) for c in range(dim))
    return out


def reaction(body, u: np.ndarray, boundary: str, component: str, load_factor: float = 1.0,
         contact_force: np.ndarray | None = None) -> float:
    """Total force the supports (or prescribed displacements) on ``boundary`` apply to the
    body along ``component``, for displacement ``u`` (ndofs) under the body's loads at
    ``load_factor`` and the nodal ``contact_force`` (ndofs): :func:`nodal_reaction` summed
    over the boundary's dofs of that component (zero where none of them is constrained)."""
    r = nodal_reaction(body, u, load_factor, contact_force)
    return float(r[boundary_dofs(body, boundary, component)].sum())


def reaction_of(body, result, boundary: str, component: str) -> float:
    """What :func:`reaction` gives for a converged step, read from its results
    (``result``: the body's :class:`~vfem.bodies.results.BodyStepResult`, whose nodal
    reactions were computed once, where the body's stiffness is: on the MPI rank that owns
    it, :mod:`vfem.parallel`), the same number without the stiffness."""
    r = np.asarray(result.reaction, dtype=float).ravel()
    return float(r[boundary_dofs(body, boundary, component)].sum())
