"""The incremental driver (thesis Fig. 4.2): steps, the contact solve, platens, step cutting.

For each step (an increment of the load factor):

1. **predict** — every body is solved on its own with the new loads and the contact forces it
   already carries (for linear bodies this is a change of the load factor in the superposition
   ``u = load_factor * u_load + platen * u_platen + K^-1 f_contact``);
2. **resolve contact** — the variant chosen by ``ContactSettings.variant``
   (:class:`~vfem.contact.paired.PairedContact` by default, or the thesis's
   :class:`~vfem.contact.algorithm.VirtualElementContact`) iterates check -> correct until
   converged, moving a force-controlled platen as it goes;
3. a step that fails (no convergence, a cycling contact set, a node pushed past the rind of
   another body) is cut in half and retried from exactly the last converged state, and the
   increment grows back after easy steps (vfem-method §3.2, *Reading*; docs/method.md §7).

Results of converged steps are kept in :class:`AnalysisResult` and handed to a callback as soon
as each step converges, so a later failure never loses them; :meth:`Analysis.checkpoint` is the
complete state after a step, from which :meth:`Analysis.run` can continue (``--resume``).
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
from .errors import AnalysisError, InputError, RindViolation
from .linalg import resolve as resolve_backend
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
        if any(b.large for b in self.bodies):
            if self.contact.variant != "paired":
                raise InputError(f"model {self.name!r}: large kinematics needs the paired "
                                 "contact variant")
            quadratic = [b.name for b in self.bodies if b.order != 1]
            if quadratic:
                raise InputError(f"model {self.name!r}, body {quadratic[0]!r}: contact with a "
                                 "large-kinematics body needs linear elements (order 1) on every "
                                 "body")
        if self.contact.method != "vfem":
            for b in self.bodies:
                if b.large or b.order != 1:
                    raise InputError(f"model {self.name!r}, body {b.name!r}: the classical "
                                     f"contact methods (contact.method = "
                                     f"{self.contact.method!r}) need linear elements (order 1) "
                                     "and small kinematics; use contact.method = 'vfem'")
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
    backend: str = ""  # the linear-algebra backend that factorized the bodies (vfem.linalg)


#: steps in a row that must converge easily before a cut increment doubles again
EASY_STEPS = 2


def easy_iterations(settings: ContactSettings) -> int:
    """A step converged "easily" in at most this many contact iterations."""
    return max(3, settings.max_iterations // 10)


def diagnosis(step: int, start: float, target: float, cuts: int, exc: Exception,
              settings: ContactSettings) -> str:
    """The message of an analysis that stops: which step, what failed (the error names the
    bodies and nodes), and what the user can change."""
    text = str(exc)
    if isinstance(exc, RindViolation):
        remedy = ("take smaller steps ([steps] count), or give the bodies deeper surface "
                  "elements so a step's overlap stays inside them")
    elif "cycles" in text:
        remedy = ("the nodes named switch between contact states: refine the mesh there, take "
                  "smaller steps, or check for a sharp corner meeting the other surface")
    elif "inside out" in text:
        remedy = "take smaller steps, or refine the mesh where the elements distort"
    elif "Newton did not converge" in text:
        remedy = (f"take smaller steps or allow more cuts (contact.max_step_cuts = "
                  f"{settings.max_step_cuts}); check the body's supports and material")
    else:
        remedy = (f"allow more iterations (contact.max_iterations = {settings.max_iterations}), "
                  f"more cuts (contact.max_step_cuts = {settings.max_step_cuts}) or smaller "
                  "steps; check that every body is held the way you expect")
    times = "once" if cuts == 1 else f"{cuts} times"
    return (f"step {step} (load factor {start:.6g} -> {target:.6g}) failed with the increment "
            f"cut {times}: {text}. What to change: {remedy}")


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


class Analysis:
    """Set up the bodies and their contact surfaces, then run the steps of a :class:`Model`."""

    def __init__(self, model: Model, backend: str | None = None):
        model.validate()
        self.model = model
        self.backend = resolve_backend(backend)  # None: the one chosen (--solver), else auto
        self.timings: dict[str, float] = {}

    def setup(self) -> None:
        """Find each body's contact candidates, then assemble and factorize every body.

        Candidates come first (they depend on the meshes only), so that each body's single
        factorization can also deliver its flexibility on them. Bodies that start deeply
        interpenetrated are refused (:class:`InputError`) and the memory the set-up needs is
        estimated before anything is factorized (:mod:`vfem.memory`): a model that cannot fit
        is refused, and running out of memory anyway is an :class:`AnalysisError` that says so.
        """
        if self.model.contact.method != "vfem":  # a classical baseline: one global system
            from .contact.baselines import GlobalContact

            self.contact = GlobalContact(self.model, self.backend)
            self.surfaces = self.contact.surfaces
            self.timings.update(self.contact.timings)
            return
        t0 = time.perf_counter()
        log.info("linear solver: %s", self.backend)
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

    def run(self, on_step: Callable[[StepResult], None] | None = None,
            start: Checkpoint | None = None) -> AnalysisResult:
        """Run the steps; ``on_step(step)`` after each converged one. If ``on_step`` also has
        an ``iteration`` attribute, it is called with every contact iteration's record (a
        progress display shows the current errors with it).

        ``start``: a :class:`Checkpoint` (from :meth:`checkpoint` of an earlier run of the same
        model, e.g. read back by ``--resume``) to continue from instead of the unloaded state.

        Step control: a step that fails (no convergence within ``max_iterations``, a contact
        set that cycles, a node pushed past a rind, an element turned inside out) is discarded
        — every body goes back to the last converged state exactly — and retried with half the
        increment, down to 1 / 2**``max_step_cuts`` of the scheduled one; after
        :data:`EASY_STEPS` steps in a row that converge in at most :func:`easy_iterations`
        iterations the increment doubles again, up to the scheduled one. Scheduled load factors
        are always reached exactly.
        """
        if not hasattr(self, "contact"):
            self.setup()
        if self.model.contact.method != "vfem":
            return self.contact.run(self, on_step, start)
        self.contact.on_iteration = getattr(on_step, "iteration", None)
        t_setup = time.perf_counter()
        settings = self.model.contact
        easy_limit = easy_iterations(settings)
        if start is None:
            state = self.contact.new_state()
            steps: list[StepResult] = []
            self.target, self.level, self.easy = 1, 0, 0
        else:
            state, steps = start.state.copy(), list(start.steps)
            self.target, self.level, self.easy = start.target, start.level, start.easy
            for b in self.model.bodies:
                b.restore_state(start.bodies.get(b.name, {}))
        self.state, self.steps = state, steps
        schedule = [0.0, *self.model.load_factors]
        message = ""
        converged = True
        while self.target < len(schedule):
            k = self.target
            target, full = schedule[k], schedule[k] - schedule[k - 1]
            increment = full / 2**self.level
            remaining = target - state.load_factor
            lf = target if abs(remaining) <= abs(increment) * (1 + 1e-9) else (
                state.load_factor + increment)
            history: list[IterationRecord] = []
            try:
                new, res = self.solve_step(state, lf, history)
            except AnalysisError as exc:
                for b in self.model.bodies:
                    b.discard_step()
                self.easy = 0
                if self.level >= settings.max_step_cuts:
                    converged = False
                    message = diagnosis(len(steps) + 1, state.load_factor, lf, self.level, exc,
                                        settings)
                    log.info(message)  # the caller reports it (AnalysisResult.message)
                    break
                self.level += 1
                log.warning("step to load factor %.6g failed (%s); cutting the increment to "
                            "%.6g", lf, exc, full / 2**self.level)
                continue
            for b in self.model.bodies:
                b.commit_step()
            state = self.state = new
            iterations = sum(1 for h in history if h.iteration > 0) or 0
            step = StepResult(step=len(steps) + 1, load_factor=lf, iterations=iterations,
                              converged=True, history=history,
                              platen_displacement=state.platen_displacement, cuts=self.level,
                              fixed_point=res.fixed_point)
            step.bodies = self._fields(state, res.pairings)
            steps.append(step)
            log.info("step %d (load factor %.4g) converged in %d iterations", step.step, lf,
                     iterations)
            if lf == target:
                self.target += 1
            self.easy = self.easy + 1 if iterations <= easy_limit else 0
            if self.level > 0 and self.easy >= EASY_STEPS:
                self.level -= 1
                self.easy = 0
                log.info("the increment grows back to %.6g", full / 2**self.level)
            if on_step is not None:
                on_step(step)
        self.timings["steps_s"] = time.perf_counter() - t_setup
        self.timings["total_s"] = sum(self.timings[key] for key in
                                      ("search_s", "assemble_factorize_s", "flexibility_s",
                                       "steps_s"))
        return AnalysisResult(self.model, converged, steps, dict(self.timings), message,
                              self.surfaces, self.contact.penetration_tolerance, self.backend)

    def checkpoint(self) -> Checkpoint:
        """The last converged state, complete, with the steps so far: what :meth:`run` needs
        to continue from it (and what step cutting goes back to)."""
        return Checkpoint(list(self.steps), self.state.copy(),
                          {b.name: b.saved_state() for b in self.model.bodies},
                          self.target, self.level, self.easy)

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
