"""The incremental driver (thesis Fig. 4.2): steps, the contact solve, platens, step cutting.

For each step (an increment of the load factor):

1. **predict** — every body is solved on its own with the new loads and the contact forces it
   already carries (for linear bodies this is a change of the load factor in the superposition
   ``u = load_factor * u_load + platen * u_platen + K^-1 f_contact``);
2. **resolve contact** — the variant chosen by ``ContactSettings.variant``
   (:class:`~vfem.contact.paired.PairedContact` by default, or the thesis's
   :class:`~vfem.contact.algorithm.VirtualElementContact`) iterates check -> correct until
   converged, moving a force-controlled platen as it goes;
3. a step that fails (no convergence, or a node pushed past the rind of another body) is cut in
   half and retried from the last converged state (vfem-method §3.2, *Reading*).

Results of converged steps are kept in :class:`AnalysisResult` and handed to a callback as soon
as each step converges, so a later failure never loses them.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .bodies import Body
from .contact.algorithm import (
    ContactState,
    IterationRecord,
    Pairing,
    SolveResult,
    VirtualElementContact,
)
from .contact.settings import ContactSettings
from .contact.surface import ContactSurface, check_initial_overlap, select_candidate_facets
from .errors import AnalysisError, InputError
from .memory import check_memory, memory_guard

log = logging.getLogger(__name__)


@dataclass
class Model:
    """Bodies, the contact settings and the load schedule.

    ``load_factors``: the load factor at the end of each step, starting from 0. They may go down
    as well as up (unloading, thesis §5.5); loads and prescribed displacements scale with them.
    """

    name: str
    bodies: list[Body]
    contact: ContactSettings = field(default_factory=ContactSettings)
    load_factors: tuple[float, ...] = (1.0,)
    contact_pairs: tuple[tuple[str, str], ...] | None = None  # default: every pair may touch

    def validate(self) -> None:
        names = [b.name for b in self.bodies]
        if not self.bodies:
            raise InputError(f"model {self.name!r} has no bodies")
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise InputError(f"model {self.name!r}: body names must be unique, repeated: "
                             f"{', '.join(sorted(dup))}")
        lf = np.asarray(self.load_factors, dtype=float)
        if lf.size == 0 or not np.all(np.isfinite(lf)) or np.any(np.diff(np.r_[0.0, lf]) == 0):
            raise InputError(f"model {self.name!r}: load_factors must be finite numbers, each "
                             f"different from the one before (and the first not 0), got "
                             f"{list(self.load_factors)}")
        for a, b in self.contact_pairs or ():
            for n in (a, b):
                if n not in names:
                    raise InputError(f"model {self.name!r}: contact pair names unknown body {n!r}")
        for b in self.bodies:
            b.validate()
            if b.order != 1 and self.contact.variant == "thesis":
                raise InputError(f"model {self.name!r}, body {b.name!r}: the thesis variant "
                                 "supports linear elements only (order 1); use the paired "
                                 "variant for quadratic elements")
        if any(b.large for b in self.bodies) and self.contact.variant != "paired":
            raise InputError(f"model {self.name!r}: large kinematics needs the paired contact "
                             "variant")
        if sum(b.platen is not None for b in self.bodies) > 1:
            raise InputError(f"model {self.name!r}: at most one force-controlled platen")
        self.contact.validate()

    def contact_surfaces(self) -> tuple[set[frozenset[int]], list[ContactSurface]]:
        """The pairs of bodies (by index) that may touch (``contact_pairs``, or every pair) and
        each body's contact surface: candidate facets within ``contact.search_distance`` of a
        body it may touch (every facet that may touch under large kinematics, where bodies may
        slide far).

        Depends on the meshes only, so it is also part of ``vfem check``: bodies that start
        deeper into each other than the outer layer of elements are refused here
        (:func:`~vfem.contact.surface.check_initial_overlap`).
        """
        index = {b.name: i for i, b in enumerate(self.bodies)}
        if self.contact_pairs is None:
            pairs = {frozenset((i, j)) for i in range(len(self.bodies)) for j in range(i)}
        else:
            pairs = {frozenset((index[a], index[b])) for a, b in self.contact_pairs}
        distance = self.contact.search_distance
        if distance is None:
            diag = [float(np.linalg.norm(np.ptp(b.mesh.p, axis=1))) for b in self.bodies]
            distance = 0.02 * min(diag)
        if any(b.large for b in self.bodies):
            distance = np.inf
        facets = select_candidate_facets(self.bodies, pairs, distance)
        surfaces = [ContactSurface.build(b, f) for b, f in zip(self.bodies, facets)]
        check_initial_overlap(surfaces, pairs)
        return pairs, surfaces


@dataclass
class BodyStepResult:
    """The state of one body at the end of a converged step (full mesh fields)."""

    displacement: np.ndarray  # (npoints, 2), at the body's points (Body.points)
    contact_force: np.ndarray  # (npoints, 2) nodal force applied by the other bodies
    contact_pressure: np.ndarray  # (npoints,) nominal normal pressure (force / undeformed length)
    contact_status: np.ndarray  # (npoints,) 0 free, 1 in contact
    penetration: np.ndarray  # (npoints,) signed penetration at candidate nodes (0 elsewhere)


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


@dataclass
class AnalysisResult:
    model: Model
    converged: bool
    steps: list[StepResult]
    timings: dict[str, float]
    message: str = ""
    surfaces: list[ContactSurface] = field(default_factory=list)
    penetration_tolerance: float = 0.0  # the one the contact iteration used


class Analysis:
    """Set up the bodies and their contact surfaces, then run the steps of a :class:`Model`."""

    def __init__(self, model: Model, backend: str = "superlu"):
        model.validate()
        self.model = model
        self.backend = backend
        self.timings: dict[str, float] = {}

    def setup(self) -> None:
        """Find each body's contact candidates, then assemble and factorize every body.

        Candidates come first (they depend on the meshes only), so that each body's single
        factorization can also deliver its flexibility on them. Bodies that start deeply
        interpenetrated are refused (:class:`InputError`) and the memory the set-up needs is
        estimated before anything is factorized (:mod:`vfem.memory`): a model that cannot fit
        is refused, and running out of memory anyway is an :class:`AnalysisError` that says so.
        """
        t0 = time.perf_counter()
        bodies = self.model.bodies
        pairs, self.surfaces = self.model.contact_surfaces()
        t1 = time.perf_counter()
        check_memory(self.surfaces, pairs)
        with memory_guard("factorizing the bodies and computing their flexibility"):
            for b, s in zip(bodies, self.surfaces):
                b.setup(self.backend, tracked_dofs=s.tracked_dofs)
            t2 = time.perf_counter()
            for s in self.surfaces:
                s.compute_flexibility()
                log.info("body %s: %d contact candidate nodes", s.body.name, s.nc)
            self.contact = self._contact(pairs)
        t3 = time.perf_counter()
        self.timings.update(search_s=t1 - t0, assemble_factorize_s=t2 - t1,
                            flexibility_s=t3 - t2)
        for key in ("assemble_s", "factorize_s"):
            self.timings[key] = sum(b.timings[key] for b in bodies)

    def _contact(self, pairs: set[frozenset[int]]):
        """The contact iteration for the model's variant and kinematics."""
        if any(b.large for b in self.model.bodies):
            from .contact.large import LargeDeformationContact

            return LargeDeformationContact(self.surfaces, pairs, self.model.contact,
                                           self.backend)
        if self.model.contact.variant == "paired":
            from .contact.paired import PairedContact

            return PairedContact(self.surfaces, pairs, self.model.contact)
        return VirtualElementContact(self.surfaces, pairs, self.model.contact)

    def solve_step(self, start: ContactState, load_factor: float, history_out: list
                   ) -> tuple[ContactState, SolveResult]:
        """Resolve the contact at ``load_factor`` from the converged ``start`` state.

        The prediction is the start state at the new load factor (contact forces and platen held);
        a force-controlled platen gets its new force and is moved by the contact iteration.
        Raises :class:`AnalysisError` (or :class:`RindViolation`) when it cannot converge.
        """
        state = start.copy()
        state.load_factor = load_factor
        platen = next((b.platen for b in self.model.bodies if b.platen is not None), None)
        state.platen_force = load_factor * platen.force if platen is not None else 0.0
        res = self.contact.solve(state)
        history_out.extend(res.history)
        if not res.converged:
            raise AnalysisError(res.message)
        return state, res

    # -- the steps ------------------------------------------------------------------------------

    def run(self, on_step: Callable[[StepResult], None] | None = None) -> AnalysisResult:
        """Run the steps; ``on_step(step)`` after each converged one. If ``on_step`` also has
        an ``iteration`` attribute, it is called with every contact iteration's record (a
        progress display shows the current errors with it)."""
        if not hasattr(self, "contact"):
            self.setup()
        self.contact.on_iteration = getattr(on_step, "iteration", None)
        t_setup = time.perf_counter()
        state = self.contact.new_state()
        steps: list[StepResult] = []
        # (load factor, halvings of the scheduled increment that led to it): a step is never
        # cut below 1 / 2**max_step_cuts of its scheduled increment, so a load factor at which
        # the iteration cannot converge ends the analysis instead of being crept up on forever
        targets = [(lf, 0) for lf in self.model.load_factors]
        message = ""
        converged = True
        while targets:
            lf, cuts = targets[0]
            history: list[IterationRecord] = []
            try:
                new, res = self.solve_step(state, lf, history)
            except AnalysisError as exc:
                for b in self.model.bodies:
                    b.discard_step()
                prev = state.load_factor
                if cuts >= self.model.contact.max_step_cuts:
                    converged = False
                    message = f"step to load factor {lf:.6g} failed after {cuts} cuts: {exc}"
                    log.error(message)
                    break
                log.warning("step to load factor %.6g failed (%s); cutting it to %.6g", lf, exc,
                            0.5 * (prev + lf))
                targets[0] = (lf, cuts + 1)  # the rest of this increment, as deeply cut
                targets.insert(0, (0.5 * (prev + lf), cuts + 1))
                continue
            targets.pop(0)
            for b in self.model.bodies:
                b.commit_step()
            state = self.state = new
            iterations = sum(1 for h in history if h.iteration > 0) or 0
            step = StepResult(step=len(steps) + 1, load_factor=lf, iterations=iterations,
                              converged=True, history=history,
                              platen_displacement=state.platen_displacement, cuts=cuts,
                              fixed_point=res.fixed_point)
            step.bodies = self._fields(state, res.pairings)
            steps.append(step)
            log.info("step %d (load factor %.4g) converged in %d iterations", step.step, lf,
                     iterations)
            if on_step is not None:
                on_step(step)
        self.timings["steps_s"] = time.perf_counter() - t_setup
        self.timings["total_s"] = sum(self.timings[k] for k in
                                      ("search_s", "assemble_factorize_s", "flexibility_s",
                                       "steps_s"))
        return AnalysisResult(self.model, converged, steps, dict(self.timings), message,
                              self.surfaces, self.contact.penetration_tolerance)

    def _fields(self, state: ContactState, pairings: list[Pairing]) -> dict[str, BodyStepResult]:
        """Full-mesh results of a converged state (one back-substitution per body)."""
        out = {}
        for s, F, p in zip(self.surfaces, state.forces, pairings):
            b = s.body
            f = np.zeros(b.ndofs)
            f[s.candidate_dofs] = F.ravel()
            u = b.displacement(state.load_factor, state.platen_displacement, f)
            nv = b.npoints
            cand = s.nodes[: s.nc]
            force = np.zeros((nv, 2))
            force[cand] = F
            pressure = np.zeros(nv)
            pressure[cand] = np.where(p.other >= 0, p.force, 0.0) / s.tributary
            status = np.zeros(nv, dtype=int)
            status[cand] = p.participating & (p.force > 0)
            pen = np.zeros(nv)
            pen[cand] = np.where(np.isfinite(p.penetration), p.penetration, 0.0)
            out[b.name] = BodyStepResult(u.reshape(-1, 2), force, pressure, status, pen)
        return out
