"""What an analysis gives back: per converged step the full-mesh fields of every body, and the
run as a whole (its steps, the model, timings); and what a run needs to continue after a step.

Their own module (issue 18): the solver fills them and the writers turn them into files, so
neither needs the other. One body's results (:class:`BodyStepResult`, :func:`add_reactions`) are
below contact, in :mod:`vfem.bodies.results` (issue 38), since the formulations build them and
the independent checks read them; they are here too for those who import them from here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .bodies.results import BodyStepResult, add_reactions  # noqa: F401 - here too
from .contact.state import ContactState, IterationRecord

if TYPE_CHECKING:
    from .contact.geometry import ContactPairs, ContactSurface
    from .model import Model


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
    #: per body of a plastic material, its quadrature points with plastic strain once the step
    #: converged (:func:`vfem.bodies.mechanics.yielded_points`); empty where none is plastic
    yielded: dict[str, int] = field(default_factory=dict)


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
    #: the pairs of surface sides that might touch, their zones read on ``surfaces``
    #: (:meth:`Model.contact_surfaces`); None: every two bodies on their whole surfaces
    pairs: ContactPairs | None = None


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


def largest_penetrations(result: AnalysisResult, step: StepResult | None = None
                         ) -> dict[str, dict]:
    """Per body: the largest penetration of its candidate nodes into another body (the older
    check of the contact candidates' linearised gaps; the invariants are
    :mod:`vfem.contact.invariants.check`'s).

    The paired variant enforces compatibility at one surface of each pair (docs/method.md §6);
    the other surface's nodes are free to indent it where its facets are longer or its geometry
    sharper. This measures that, for every candidate node of every side of a pair that may
    touch (``result.pairs``) against the other side's candidate surface, with the same linear
    kinematics as the analysis: the node's closest point on the other undeformed surface, the
    outward normal there, and the gap ``g0 + n . (u_node - u_other(closest point))``; where the
    closest point is a vertex (a corner), n is the direction from it to the node. Nodes whose
    closest point is an end of the other surface (beyond its edge) are left out. When any body
    is analysed under large displacements the same measure is taken on the deformed surfaces:
    each node's current position against the other surface as it now lies.

    Returns ``{body: {"penetration": value (> 0 overlap, <= 0 none), "node": point number,
    "into": other body}}`` for the given step (default: the last).
    """
    from .contact.geometry import ContactPairs, zone_nodes

    step = step or result.steps[-1]
    surfaces = result.surfaces
    pairs = result.pairs if result.pairs is not None else ContactPairs.every(len(surfaces))
    large = any(b.large for b in result.model.bodies)
    out = {s.body.name: {"penetration": -np.inf, "node": -1, "into": ""} for s in surfaces}
    for side, other in pairs.oriented():  # each side's nodes against the other side's facets
        s, so = surfaces[side.body], surfaces[other.body]
        if s.nc == 0 or so.nc == 0:
            continue
        local = zone_nodes(s, side.facets)
        if not len(local) or (other.facets is not None and not len(other.facets)):
            continue  # (a side with no candidate facet)
        u = step.bodies[s.body.name].displacement[s.nodes[local]]
        x = s.X[local] + u if large else s.X[local]
        xo = so.X + step.bodies[so.body.name].displacement[so.nodes] if large else so.X
        seg, t, dist, n = so.closest(x, xo, other.facets)[:4]
        pos, _ = so.curve(seg, t, xo)
        # closest to a vertex (a corner of the other surface): measure along the line from
        # that vertex to the node, not along a facet normal that does not reach it
        at_vertex = ((t <= 0) | (t >= 1)) & (dist > 1e-12 * max(so.lengths.max(), 1e-300))
        n = np.where(at_vertex[:, None],
                     (x - pos) / np.maximum(dist, 1e-300)[:, None], n)
        if large:
            pen = -np.einsum("ij,ij->i", x - pos, n)
        else:
            uo = step.bodies[so.body.name].displacement[so.nodes[: so.nc]]
            uv = np.einsum("nk,nkd->nd", so.shape(t), uo[so.facets[seg]])
            pen = -(np.einsum("ij,ij->i", x - pos, n)
                    + np.einsum("ij,ij->i", u - uv, n))
        ends = so.facets[seg]
        off = (((t <= 0) & so.surface_ends[ends[:, 0]])
               | ((t >= 1) & so.surface_ends[ends[:, 1]]))
        pen = np.where(off, -np.inf, pen)
        k = int(np.argmax(pen))
        if pen[k] > out[s.body.name]["penetration"]:
            out[s.body.name] = {"penetration": float(pen[k]), "node": int(s.nodes[local[k]]),
                                "into": so.body.name}
    return out
