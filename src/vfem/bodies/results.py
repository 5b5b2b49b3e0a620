"""One body's results at the end of a converged step (full-mesh fields) and its support
reactions from them.

Below contact (issue 38): the formulations build them (the classical baselines their whole
steps), the independent checks read them, and the step and run results
(:mod:`vfem.result_types`) hold them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from . import Body


@dataclass
class BodyStepResult:
    """The state of one body at the end of a converged step (full mesh fields)."""

    displacement: np.ndarray  # (npoints, dim), at the body's points (Body.points)
    contact_force: np.ndarray  # (npoints, dim) nodal force applied by the other bodies
    #: (npoints,) nominal normal pressure: normal nodal contact force / undeformed tributary
    #: length, i.e. the traction averaged with the node's shape function (int phi q / int phi)
    contact_pressure: np.ndarray
    contact_status: np.ndarray  # (npoints,) 0 free, 1 in contact
    penetration: np.ndarray  # (npoints,) signed penetration at candidate nodes (0 elsewhere)
    #: (npoints,) the formulation's nominal normal traction at the node (paired variant: the
    #: unknowns q on the compatibility side, that field read at the other side's nodes); where a
    #: formulation has none, the nodal reading ``contact_pressure``
    contact_traction: np.ndarray | None = None
    #: (npoints, dim) nodal force the supports, prescribed displacements and platen apply to the
    #: body (:meth:`Body.nodal_reaction`): zero on unconstrained dofs. With the contact force and
    #: the applied loads it balances the body (:func:`add_reactions`)
    reaction: np.ndarray | None = None
    #: per boundary carrying a support, a prescribed displacement or the platen, the total (x, y)
    #: (3D: (x, y, z)) of ``reaction`` over the dofs that boundary's own conditions constrain
    #: (:meth:`Body.boundary_reactions`: a shared corner dof counts in each boundary constraining
    #: it; the body's total, ``reaction.sum(axis=0)``, counts it once)
    reactions: dict[str, tuple[float, ...]] = field(default_factory=dict)
    #: the components of the forces whose sums are the body's resultants (its section's
    #: :attr:`~vfem.bodies.section.Section.resultant`; None: all): what ``reaction_imbalance``
    #: reads (a body of revolution's radial forces cancel round the ring)
    resultant_components: tuple[int, ...] | None = None
    #: (dim,) resultant (x, y[, z]) of the body's applied loads (its tractions) at the step's
    #: load factor
    applied_load: np.ndarray | None = None
    # -- with friction (vfem.contact.formulations.friction; None without): at the nodes that carry a
    # contact pair's compatibility (where its traction values live), zero at the others
    #: (npoints, dim) the tangential traction on the body (x, y[, z]), the part of the pair's
    #: traction field along the contact surface
    contact_shear: np.ndarray | None = None
    #: (npoints,) the relative tangential displacement against the virtual node in this step
    #: (2D: signed along the pair's tangent, the opposing surface's outward normal turned by
    #: +90°; 3D: its length, the direction being the opposite of a slipping node's traction)
    slip_increment: np.ndarray | None = None
    #: (npoints,) the slip accumulated over the converged steps so far (length)
    accumulated_slip: np.ndarray | None = None
    #: (npoints,) 0 free, 1 sticking, 2 slipping; -1 at the nodes that carry no pair's
    #: compatibility (the other side of a pair reads the traction field its partner defines)
    friction_status: np.ndarray | None = None
    #: (npoints, dim) the part of ``contact_force`` that the tangential traction makes (on both
    #: sides of a pair): what the friction's work is measured with
    friction_force: np.ndarray | None = None

    def __post_init__(self):
        if self.contact_traction is None:
            self.contact_traction = self.contact_pressure

    @property
    def reaction_total(self) -> np.ndarray:
        """(dim,) the body's total support reaction (x, y[, z]): ``reaction`` summed over the
        nodes, each constrained dof once; zeros where reactions were not computed."""
        if self.reaction is None:
            shape = np.shape(self.displacement)
            return np.zeros(shape[1] if len(shape) == 2 else 2)
        return self.reaction.sum(axis=0)


def add_reactions(body: Body, r: BodyStepResult, load_factor: float) -> BodyStepResult:
    """Fill ``r``'s support reactions (``reaction``, ``reactions``, ``applied_load``) from its
    displacement and contact force at ``load_factor``: one evaluation of the body's stiffness
    (internal force under large kinematics) per converged step, so every output reads the same
    numbers. Returns ``r``."""
    nodal = body.nodal_reaction(np.asarray(r.displacement).ravel(), load_factor,
                                np.asarray(r.contact_force).ravel())
    dim = body.mesh.p.shape[0]
    r.reaction = nodal.reshape(-1, dim)
    r.reactions = body.boundary_reactions(nodal)
    r.applied_load = body.applied_load(load_factor).reshape(-1, dim).sum(axis=0)
    r.resultant_components = body.section.resultant
    return r
