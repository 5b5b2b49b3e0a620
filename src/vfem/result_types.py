"""What an analysis gives back: per converged step the full-mesh fields of every body, and the
run as a whole (its steps, the model, timings); and what a run needs to continue after a step.

Their own module (issue 18): the solver fills them, the contact formulations (the classical
baselines build their own steps) and the independent checks read them, and the writers turn them
into files, so none of those needs to import the solver.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .contact.state import ContactState, IterationRecord

if TYPE_CHECKING:
    from .bodies import Body
    from .contact.surface import ContactSurface
    from .solver import Model


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
    #: (dim,) resultant (x, y[, z]) of the body's applied loads (its tractions) at the step's
    #: load factor
    applied_load: np.ndarray | None = None
    # -- with friction (vfem.contact.friction; None without): at the nodes that carry a contact
    # pair's compatibility (where its traction values live), zero at the others
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
    return r


@dataclass
class StepResult:
    step: int
    load_factor: float
    iterations: int
    converged: bool
    history: list[IterationRecord]
    platen_displacement: float = 0.0
    cuts: int = 0
    fixed_point: bool = False  # stopped where the corrections cancel, with residual errors
    bodies: dict[str, BodyStepResult] = field(default_factory=dict)
    #: the invariants of the converged state (``Invariants.record()``: force_balance,
    #: max_penetration_any_body, allowed, where, tension, ...); empty when not checked
    invariants: dict = field(default_factory=dict)
    #: per pair ("a/b") whose compatibility side the solver switched in this run by this step
    #: (:meth:`vfem.solver.Analysis._switch_side`), the body that carries it; empty where none
    compatibility_switched: dict[str, str] = field(default_factory=dict)


@dataclass
class AnalysisResult:
    model: Model
    converged: bool
    steps: list[StepResult]
    timings: dict[str, float]
    message: str = ""
    surfaces: list[ContactSurface] = field(default_factory=list)
    penetration_tolerance: float = 0.0  # the one the contact iteration used
    backend: str = ""  # the linear-algebra backend that factorized the bodies (vfem.linalg)
    #: how the contact correction read the flexibility: "dense" or "matrix_free" (issue 22)
    flexibility: str = "dense"
    #: every scheduled load factor was reached: true where ``converged`` is, and where the
    #: thesis variant ran every step but stopped some at its fixed point outside its tolerance
    #: (``StepResult.fixed_point``; not converged, its answers there for comparison)
    complete: bool = False


@dataclass
class Checkpoint:
    """Everything a run needs to continue after a converged step: the steps so far, the
    contact state, each body's saved state (:meth:`Body.saved_state`) and the step control."""

    steps: list[StepResult]
    state: ContactState
    bodies: dict[str, dict[str, np.ndarray]]
    target: int = 1  # the next scheduled load factor: model.load_factors[target - 1]
    level: int = 0  # halvings of the scheduled increment now in use
    easy: int = 0  # easy steps in a row at that level
    #: [i, j, body] per pair of bodies i < j whose compatibility side the run had switched,
    #: and the body that carries it (``Analysis.sides``)
    sides: list = field(default_factory=list)


#: The phases of a run (issue 19): what each takes, from the timings an analysis records
#: (``AnalysisResult.timings``) and the figures' drawing; label -> the timing keys it sums.
PHASES = (
    ("model: meshes, bodies, checks", ("build_s",)),
    ("contact search", ("search_s",)),
    ("assembly", ("assemble_s",)),
    ("factorization and condensation", ("factorize_s", "flexibility_s")),
    ("contact iterations", ("contact_s",)),
    ("back-substitution: full-mesh fields", ("fields_s",)),
    ("invariants", ("invariants_s",)),
    ("output: VTU, CSV, checkpoints", ("output_s",)),
    ("figures", ("figures_s",)),
)


def phase_table(timings: dict[str, float]) -> dict[str, float]:
    """Seconds per phase of a run (:data:`PHASES`), those the run had, in order; "other" is
    what the timed phases leave of the run's wall time (``run_s``, where the run recorded it,
    else the analysis's ``total_s`` plus its output and figures)."""
    out = {}
    for label, keys in PHASES:
        if any(k in timings for k in keys):
            out[label] = float(sum(timings.get(k, 0.0) for k in keys))
    wall = timings.get("run_s")
    if wall is None:
        wall = (timings.get("total_s", 0.0) + timings.get("build_s", 0.0)
                + timings.get("figures_s", 0.0))
    out["other"] = max(0.0, float(wall) - sum(out.values()))
    return out

