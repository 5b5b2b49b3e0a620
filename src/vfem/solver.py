"""The incremental driver (thesis Fig. 4.2): steps, the contact solve, platens, step cutting.

For each step (an increment of the load factor):

1. **predict** — every body is solved on its own with the new loads and the contact forces it
   already carries (for linear bodies this is a change of the load factor in the superposition
   ``u = load_factor * u_load + platen * u_platen + K^-1 f_contact``, the first term summed
   over the body's load curves, :meth:`~vfem.bodies.Body.load_displacement`);
2. **resolve contact** — the formulation of the model's settings and kinematics
   (:func:`~vfem.contact.formulations.formulation.formulation_class`: the paired variant by default,
   small or large displacements, the thesis's plain reading, or a classical baseline) solves the
   step from the last converged state
   (:class:`~vfem.contact.formulations.formulation.ContactFormulation`), moving a force-controlled
   platen as it goes; what it supports it declares as data (``capabilities``), which the model's
   checks and the step loop read;
3. **check** — three invariants of the converged state's full-mesh results, checked
   independently of the contact formulation (:mod:`vfem.contact.invariants.check`): the contact
   forces of all bodies balance, no boundary node lies inside another body, no node carries tension.
   All three are recorded per step; those in :data:`ENFORCED` (all three, for the paired
   variant) fail the step;
4. a step that fails (no convergence, a cycling contact set, a node pushed past the rind of
   another body, a broken enforced invariant) is cut in half and retried from exactly the last
   converged state, and the increment grows back after easy steps (vfem-method §3.2, *Reading*;
   docs/method.md §7).

Results of converged steps are kept in :class:`AnalysisResult` and handed to a callback as soon
as each step converges, so a later failure never loses them; :meth:`Analysis.checkpoint` is the
complete state after a step, from which :meth:`Analysis.run` can continue (``--resume``).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

import numpy as np

from .bodies import multiplier
from .bodies.mechanics import yielded_points
from .bodies.stresses import strain_beyond
from .contact.formulations import formulation_class
from .contact.geometry import ContactPairs, exterior_facets
from .contact.invariants import InvariantCheck, Invariants
from .contact.search import project_points
from .contact.settings import ContactSettings
from .contact.solvers import matrix_free_refusal, predicted_seconds
from .contact.state import ContactState, IterationRecord, SolveResult
from .errors import (
    ActiveSetNotSettled,
    AnalysisError,
    ContactCycling,
    ContactNotConverged,
    ElementInverted,
    InputError,
    InvariantViolation,
    NewtonNotConverged,
    PlatenOffForce,
    PlatenUnheld,
    PlatenUnpaired,
    RindViolation,
    SingularSystem,
)
from .linalg import resolve as resolve_backend
from .memory import available_memory, check_memory, estimate, memory_guard
from .model import Model
from .parallel import current as current_ranks
from .parallel import set_up_bodies
from .result_types import (  # the result types, here too for those who import them from here
    AnalysisResult,
    BodyStepResult,
    Checkpoint,
    StepResult,
)
from .threads import ensure as ensure_threads

log = logging.getLogger(__name__)


#: The invariants whose violation fails a step (cut, then stop); all are recorded in every step
#: (summary.json, the closing screen's "VIOLATED"). The thesis variant and the baselines record
#: them without failing a step (:meth:`Analysis.check_invariants`).
ENFORCED = ("force balance", "interpenetration", "tension")

#: steps in a row that must converge easily before a cut increment doubles again
EASY_STEPS = 2
#: at most this many nodes a step that broke invariant (b) has the formulation hold before it
#: is cut (:meth:`Analysis._enforce`)
ENFORCED_NODES = 10

#: a small-kinematics body whose largest principal strain (:meth:`Body.max_strain`) exceeds
#: this after a step is warned about, once per run (small strain pushed too far, issue 16)
SMALL_STRAIN_LIMIT = 0.05


def easy_iterations(settings: ContactSettings) -> int:
    """A step converged "easily" in at most this many contact iterations."""
    return max(3, settings.max_iterations // 10)


def unreachable_pairs(model: Model, pairs: ContactPairs, surfaces: list) -> list[str]:
    """A note for every pair of bodies that may touch but has no contact candidate on either
    body: how far apart they are, against the search distance (``contact.search_distance``).
    Such bodies cannot touch in the analysis; a body that only contact would hold (pushed by
    a platen) then has nothing to push against, and the stop diagnosis says so."""
    notes = []
    for i, j in pairs.keys():
        if surfaces[i].nc or surfaces[j].nc:
            continue
        ends = []
        for b in (model.bodies[i], model.bodies[j]):
            f = b.mesh.facets[:, exterior_facets(b)]
            ends.append((b.mesh.p[:, f[0]].T, b.mesh.p[:, f[1]].T))
        gap = float(project_points(np.vstack(ends[0]), *ends[1])[2].min()) if len(
            ends[0][0]) and len(ends[1][0]) else np.inf
        distance = model.contact.search_distance
        said = (f"{distance:.3g}" if distance is not None else
                "2 % of the smaller body's size, the default")
        notes.append(f"bodies {model.bodies[i].name!r} and {model.bodies[j].name!r} are "
                     f"{gap:.3g} apart and no load is predicted to bring them within the contact "
                     f"search distance ({said}; contact.search_distance): no facet of theirs is "
                     "a contact candidate, so they cannot touch in this analysis")
    return notes


def idle_load_curves(model: Model) -> list[str]:
    """A note for every load whose curve (``amplitude``) is zero at every load factor of the
    steps, so that it is never applied: most likely a curve written for other load factors
    (``[[1, 0], [2, 1]]`` with steps ending at 1)."""
    factors = [0.0, *model.load_factors]
    notes = []
    for b in model.bodies:
        loads = [(f"prescribed displacement on {x.boundary!r}", x) for x in b.prescribed]
        loads += [(f"traction on {x.boundary!r}", x) for x in b.tractions]
        loads += [(f"platen on {b.platen.boundary!r}", b.platen)] if b.platen else []
        for what, load in loads:
            if load.amplitude is not None and all(
                    multiplier(load.amplitude, lf) == 0.0 for lf in factors):
                notes.append(f"body {b.name!r}: the load curve of its {what} is 0 at every load "
                             f"factor of the steps (0 to {max(factors):g}): that load is never "
                             "applied; check the curve's load factors")
    return notes


#: what to change where a platen's reaction stays off its force (measured, docs/errors.md)
PLATEN_REMEDY = (
    "a body that only the platen and contact hold along the platen's direction is free there "
    "where the platen's force is zero, or where the contact cannot push along it (frictionless, "
    "sideways): end the platen's load curve at a small force instead of zero, or hold the body "
    "with a support; where other loads press the bodies together before the platen's body "
    "touches, start the platen's force first (a load curve on the other loads)")

#: what to change where the thesis variant stopped at its fixed point outside its tolerance
#: (measured: the paired variant solves every model that showed it, docs/errors.md)
FIXED_POINT_REMEDY = (
    "analyse the model with the paired variant (contact.variant = \"paired\", the default), "
    "whose exact discrete state is the fixed point of its iteration; smaller steps, more "
    "iterations or a looser contact.equilibrium_tolerance do not move the thesis variant's "
    "fixed point (docs/method.md §5)")


def fixed_point_message(steps: list[StepResult], penetration_tolerance: float) -> str:
    """The message of an analysis of the thesis variant that ran every step but stopped some
    at the fixed point of its iteration with errors above its tolerance (``fixed_point``): how
    many, the first and the worst, and what to change (:data:`FIXED_POINT_REMEDY`)."""
    outside = [s for s in steps if s.fixed_point]

    def errors(s: StepResult) -> str:
        last = s.history[-1]
        return (f"step {s.step} (load factor {s.load_factor:.6g}): penetration "
                f"{last.max_penetration:.3g} against a tolerance of {penetration_tolerance:.3g}, "
                f"equilibrium error {last.max_equilibrium_error:.3g}")

    first = outside[0]
    worst = max(outside, key=lambda s: s.history[-1].max_penetration)
    where = errors(first) + ("" if worst is first else f"; the deepest, {errors(worst)}")
    return (f"{len(outside)} of {len(steps)} steps stopped at the thesis variant's fixed point "
            f"OUTSIDE its tolerance, where its compatibility and equilibrium corrections cancel "
            f"({where}); every step's results are written, its residuals in summary.json "
            f"(steps[].max_penetration, max_equilibrium_error). What to change: "
            f"{FIXED_POINT_REMEDY}")


def diagnosis(step: int, start: float, target: float, cuts: int, exc: Exception,
              settings: ContactSettings, unreachable: list[str] = (),
              tried: str = "") -> str:
    """The message of an analysis that stops: which step, what failed (the error names the
    bodies and nodes), and what the user can change. ``unreachable``: notes of
    :func:`unreachable_pairs`, the likely cause when there are any; ``tried``: what the
    solver's switch of the pair's compatibility side came to (:meth:`Analysis._switch_side`):
    "" where it was not tried."""
    text = str(exc)
    if unreachable:
        return (f"step {step} (load factor {start:.6g} -> {target:.6g}) failed: no contact was "
                f"found: {'; '.join(unreachable)}. What to change: set contact.search_distance "
                "above the gap, or start the bodies closer; a body held only by contact (a "
                "platen) has nothing to push against until it touches")
    if isinstance(exc, InvariantViolation):
        bodies = getattr(exc, "bodies", None)
        # (measured: benchmarks/random_models.py --remedies, seed 0, 2026-11-30, seventh
        # session: of its 2 stopped models the other compatibility side solved both, four
        # times the steps none, large kinematics the 1 it applies to; the fifth session, 3 of
        # 3, none, 2 of 2; at the state with 20 stops, 13 of 20, none, none)
        first = tried or ("" if not bodies else (
            f"try the other body of the two on the compatibility side (contact."
            f"compatibility_side = \"{bodies[0]}\" or \"{bodies[1]}\": the side whose nodes "
            "are held by tractions; measured on the random models that stopped "
            "(benchmarks/random_models.py --remedies), it solved 2 of 2, and 13 of 20 "
            "before the last changes, where four times the steps solved none; the solver "
            "switches it itself where the side was not set and without friction); else "))
        remedy = (f"the contact iteration met its own stopping rule but the state it reached "
                  f"breaks an invariant checked from the full-mesh results; {first}refine the "
                  "mesh where the nodes named are, or take smaller steps ([steps] count); "
                  "where the bodies slide or turn by more than a facet, analyse them with "
                  "large kinematics (kinematics = \"total\": small kinematics pairs the "
                  "surfaces once, undeformed; it does not help where they do not: on the same "
                  "models it solved 2 of the 2 it applies to); if it persists report it with "
                  "the input (a contact formulation error)")
    elif isinstance(exc, RindViolation):
        remedy = (f"{tried}take smaller steps ([steps] count), or give the bodies deeper "
                  "surface elements so a step's overlap stays inside them")
    elif isinstance(exc, PlatenOffForce):
        remedy = (f"{PLATEN_REMEDY}; else allow more iterations (contact.max_iterations = "
                  f"{settings.max_iterations}) or smaller steps")
    elif isinstance(exc, PlatenUnpaired):
        # (measured: random model 3d-17 of benchmarks/random_models.py, a tilted box over a
        # block's corner, stopped so with the box on the compatibility side; the block there
        # solves it, and by default a side that pairs no node gives way to the other)
        remedy = ("where contact.compatibility_side is set, set it to the other body of the "
                  "pair (its nodes, or the other's held against it, may then hold the platen; "
                  "by default a side that pairs no node gives way to the other); else hold "
                  "the body otherwise, or start it touching; no step size or iteration count "
                  "can help")
    elif isinstance(exc, PlatenUnheld):
        remedy = ("give the platen's force the sign that pushes the body onto the other (or "
                  "hold the body otherwise); no step size or iteration count can help")
    elif isinstance(exc, ContactCycling):
        remedy = ("the nodes named switch between contact states: refine the mesh there, take "
                  "smaller steps, or check for a sharp corner meeting the other surface")
    elif isinstance(exc, ElementInverted):
        remedy = "take smaller steps, or refine the mesh where the elements distort"
    elif isinstance(exc, SingularSystem):
        remedy = ("bring the bodies within contact.search_distance of each other, or support "
                  "the body")
    elif isinstance(exc, ActiveSetNotSettled):
        remedy = (f"allow more linear solves (contact.max_iterations = "
                  f"{settings.max_iterations}) or take smaller steps; check that every body is "
                  "held the way you expect")
    elif isinstance(exc, NewtonNotConverged):
        remedy = (f"take smaller steps or allow more cuts (contact.max_step_cuts = "
                  f"{settings.max_step_cuts}); check the body's supports and material")
    else:
        remedy = (f"allow more iterations (contact.max_iterations = {settings.max_iterations}), "
                  f"more cuts (contact.max_step_cuts = {settings.max_step_cuts}) or smaller "
                  "steps; check that every body is held the way you expect")
    if cuts == 0:  # a formulation whose steps are not cut (a baseline)
        return (f"step {step} (load factor {start:.6g} -> {target:.6g}) failed: {text}. What "
                f"to change: {remedy}")
    times = "once" if cuts == 1 else f"{cuts} times"
    return (f"step {step} (load factor {start:.6g} -> {target:.6g}) failed with the increment "
            f"cut {times}: {text}. What to change: {remedy}")


class Analysis:
    """Set up the bodies and their contact surfaces, then run the steps of a :class:`Model`."""

    def __init__(self, model: Model, backend: str | None = None):
        model.validate()
        self.model = model
        self.backend = resolve_backend(backend)  # None: the one chosen (--solver), else auto
        self.timings: dict[str, float] = {}
        self.strain_warned: set[str] = set()  # bodies already warned about (warn_large_strain)
        self.unreachable: list[str] = []  # pairs that cannot touch (unreachable_pairs)
        self.pairs: ContactPairs | None = None  # the pairs of sides that may touch (setup)
        #: per pair (i, j), i < j, whose compatibility side was switched (:meth:`_switch_side`),
        #: the body that carries it; and per pair whose other side was tried and not kept,
        #: what the stop message says of it
        self.sides: dict[tuple[int, int], int] = {}
        self.side_notes: dict[tuple[int, int], str] = {}

    def setup(self) -> None:
        """Find each body's contact candidates, then assemble and factorize every body.

        Candidates come first (they depend on the meshes only), so that each body's single
        factorization can also deliver its flexibility on them. Bodies that start deeply
        interpenetrated are refused (:class:`InputError`) and the memory the set-up needs is
        estimated before anything is factorized (:mod:`vfem.memory`): a model that cannot fit
        is refused, and running out of memory anyway is an :class:`AnalysisError` that says so.
        """
        ensure_threads()  # the thread pools sized once, unless the caller did (vfem.threads)
        self.matrix_free = False  # the contact flexibility formed (issue 22: or applied)
        if self.model.contact.method != "vfem":  # a classical baseline: one global system
            from .contact.formulations import GlobalContact

            self.contact = GlobalContact(self.model, self.backend)
            self.surfaces, self.pairs = self.contact.surfaces, self.contact.pairs
            self.timings.update(self.contact.timings, flexibility_s=0.0,
                                assemble_factorize_s=self.contact.timings["assemble_s"])
            # recorded per step, not enforced (its capabilities)
            self.invariant_check = self._invariant_check()
            return
        t0 = time.perf_counter()
        log.info("linear solver: %s", self.backend)
        bodies = self.model.bodies
        # (each pair's search on one rank under MPI, vfem.parallel)
        pairs, self.surfaces = self.model.contact_surfaces(current_ranks())
        self.pairs = pairs
        # condensed to the candidate dofs alone unless the formulation reads the rind (issue 19)
        reads_rind = self._formulation().capabilities.reads_rind
        for s in self.surfaces:
            s.rind_rows = reads_rind
        self.unreachable = unreachable_pairs(self.model, pairs, self.surfaces)
        for note in self.unreachable + idle_load_curves(self.model):
            log.warning("%s", note)
        t1 = time.perf_counter()
        self.matrix_free = self._matrix_free(pairs)
        check_memory(self.surfaces, pairs, self.backend, matrix_free=self.matrix_free)
        with memory_guard("factorizing the bodies and computing their flexibility"):
            ranks = current_ranks()
            # the thesis variant reads every body's flexibility on every rank, and so does
            # the Newton formulation (a model with a body that iterates: the linear bodies'
            # beside the others' tangent ones, vfem.contact.formulations.large); the paired
            # variant of small kinematics on its owner only (vfem.parallel)
            shared = (self.model.contact.variant != "paired"
                      or any(b.iterates for b in bodies))
            if ranks.parallel:  # each body on its own rank (vfem.parallel, issue 22)
                set_up_bodies(ranks, bodies, lambda i: bodies[i].setup(
                    self.backend, condensed_dofs=None if self.matrix_free
                    else self.surfaces[i].condensed_dofs), shared)
            else:
                # every body assembled before any is factorized: the assemblies' temporaries
                # then take memory before the factors hold it (measured at 104k dofs: the
                # bodies' assembly 2.8-3.5 s this way, 4.3-5.2 s assembling the second body
                # beside the first one's factors; issue 40), as a plain run assembles its
                # whole model first
                assembled = [ranks.own(b.assemble) for b in bodies]
                for b, s, a in zip(bodies, self.surfaces, assembled):
                    ranks.own(b.setup, self.backend,
                              None if self.matrix_free else s.condensed_dofs, a)
            t2 = time.perf_counter()
            # the bodies' unloaded state (a switch of a compatibility side under large
            # kinematics goes through the steps again from it: :meth:`_replay`)
            self._unloaded = {b.name: b.saved_state() for b in bodies}
            for i, s in enumerate(self.surfaces):
                s.compute_flexibility(matrix_free=self.matrix_free,
                                      remote=not (shared or ranks.mine(i)))
                log.info("body %s: %d contact candidate nodes", s.body.name, s.nc)
            self.contact = self._contact(pairs)
        self.invariant_check = self._invariant_check()
        t3 = time.perf_counter()
        self.timings.update(search_s=t1 - t0, assemble_factorize_s=t2 - t1,
                            flexibility_s=t3 - t2)
        for key in ("assemble_s", "factorize_s"):
            self.timings[key] = sum(b.timings[key] for b in bodies)

    def _matrix_free(self, pairs: ContactPairs) -> bool:
        """Whether the contact correction applies the bodies' flexibility instead of forming
        it (``contact.flexibility``, issue 22): asked for, or ``"auto"`` and either the dense
        blocks would exceed ``contact.dense_limit_mib`` (default half the memory available)
        or the matrix-free route is predicted to take less time
        (:func:`~vfem.contact.solvers.routes.predicted_seconds`, issue 40). The matrix-free
        route serves the paired variant under small kinematics without friction; asked for
        elsewhere, it is refused with the reason."""
        cfg = self.model.contact
        if cfg.flexibility == "dense" or not any(s.nc for s in self.surfaces):
            return False
        why = matrix_free_refusal(cfg, self.model.bodies)
        if cfg.flexibility == "matrix_free":
            if why:
                raise InputError(f"contact.flexibility = \"matrix_free\": {why}; use "
                                 "\"dense\" or \"auto\"")
            return True
        if why:
            return False
        dense = estimate(self.surfaces, pairs, self.backend)["dense"]
        if cfg.dense_limit_mib is not None:
            limit = cfg.dense_limit_mib * 2**20
        else:
            available = available_memory()
            limit = None if available is None else 0.5 * available
        seconds = predicted_seconds(self.surfaces, len(self.model.load_factors), self.backend)
        faster = seconds["matrix_free"] < seconds["dense"]
        # one choice for every MPI rank (the memory available differs from rank to rank)
        chosen = current_ranks().agree((limit is not None and dense > limit) or faster)
        log.info("contact flexibility: %s (dense blocks about %.0f MiB, limit %s; predicted "
                 "%.3g s dense, %.3g s matrix-free)", "matrix-free" if chosen else "dense",
                 dense / 2**20, "none" if limit is None else f"{limit / 2**20:.0f} MiB",
                 seconds["dense"], seconds["matrix_free"])
        return chosen

    def _contact(self, pairs: ContactPairs):
        """The contact formulation of the model's settings and kinematics
        (:func:`~vfem.contact.formulations.formulation.formulation_class`)."""
        extra = {"sides": dict(self.sides)} if self.sides else {}
        return self._formulation()(self.surfaces, pairs, self.model.contact,
                                   backend=self.backend, executor=current_ranks(), **extra)

    def _formulation(self):
        """The formulation class (or composition) of the model's contact settings and
        kinematics."""
        return formulation_class(self.model.contact, self.model.iterates)

    def _invariant_check(self) -> InvariantCheck:
        """The invariants every converged step must satisfy (:mod:`vfem.contact.invariants.check`),
        to the contact's penetration tolerance; each pair's (b) read on one MPI rank."""
        check = InvariantCheck(self.model, None, self.contact.penetration_tolerance)
        check.executor = current_ranks()
        return check

    def check_invariants(self, fields: dict[str, BodyStepResult],
                         history: list[IterationRecord]) -> Invariants:
        """The invariants of a converged step's full-mesh ``fields``.

        The thesis variant leaves errors by design (docs/method.md §5). Its allowed depth
        includes the penetration it stopped with beyond its tolerance. Its force balance is
        recorded, not enforced: each body's forces act along the *other* body's facet normals,
        so where the two surfaces' normals differ the forces leave a tangential resultant
        (measured: 6 % at the first step of wedge case 1, whose flanks slope 3.4°; 0.5 to
        1.3 % on Hertz), far beyond what its ``equilibrium_tolerance`` bounds (the normal
        components, node by node). Its tolerance is recorded as that bound on the sum: the
        nodes in contact times the larger of ``equilibrium_tolerance`` times the largest nodal
        force and the residual error it stopped with, relative to the largest body's total.
        None of the three fails a thesis-variant step: it is the plain reading, kept to be
        compared (its tension release leaves tensile nodes of 0.5 % of the largest force on
        the wedge, half-released by design, thesis §5.6).
        """
        settings = self.model.contact
        extra, force_tolerance, enforced = 0.0, None, None
        if self.contact.capabilities.invariants == "recorded" and history:  # the thesis's
            last = history[-1]
            extra = max(0.0, last.max_penetration - self.contact.penetration_tolerance)
            forces = [np.asarray(r.contact_force) for r in fields.values()]
            largest = max(float(np.linalg.norm(f, axis=1).max(initial=0.0)) for f in forces)
            scale = max(float(np.linalg.norm(f.sum(axis=0))) for f in forces)
            per_node = max(settings.equilibrium_tolerance * largest, last.max_equilibrium_error)
            force_tolerance = settings.equilibrium_tolerance
            if scale > 0:
                force_tolerance = max(force_tolerance,
                                      max(last.contact_nodes, 1) * per_node / scale)
            enforced = ()  # the plain reading: recorded, compared, never a failed step
        if enforced is None:
            enforced = ENFORCED
        else:
            enforced = tuple(e for e in enforced if e in ENFORCED)
        inv = self.invariant_check(fields, extra, force_tolerance, enforced)
        self.timings["invariants_s"] = self.timings.get("invariants_s", 0.0) + inv.seconds
        return inv

    def warn_large_strain(self, step: StepResult) -> None:
        """After a converged step: warn (log, not fail) about each small-kinematics body whose
        largest principal strain (:meth:`Body.max_strain`) exceeds :data:`SMALL_STRAIN_LIMIT`,
        naming the body, the strain, the step and where, once per body per run. A screen per
        small body and step (:func:`~vfem.bodies.stresses.strain_beyond`: the strain exactly
        only in elements that could exceed the limit), none once every such body has been
        named."""
        bodies = self.model.bodies
        screened = [i for i, b in enumerate(bodies) if not (
            b.large or b.name in self.strain_warned or b.name not in step.bodies)]
        # each body on the rank that owns it (the bound comes from its assembly, vfem.parallel)
        found = current_ranks().map(screened, lambda i: strain_beyond(
            bodies[i], step.bodies[bodies[i].name].displacement.ravel(), SMALL_STRAIN_LIMIT))
        for i in screened:
            b, beyond = bodies[i], found[i]
            if beyond is not None:
                strain, element = beyond
                self.strain_warned.add(b.name)
                where = ", ".join(f"{c:.4g}" for c in
                                  b.mesh.p[:, b.mesh.t[:, element]].mean(axis=1))
                log.warning("body %r: strain %.3g %% at step %d (load factor %.6g), element %d "
                            "at (%s), beyond the %g %% small kinematics is meant for: "
                            "its answer may be far off; analyse it with kinematics = \"total\"",
                            b.name, 100 * strain, step.step, step.load_factor, element, where,
                            100 * SMALL_STRAIN_LIMIT)

    def warn_second_order(self, steps: list[StepResult]) -> None:
        """After the steps, under small kinematics: warn (log, not fail) where a node lies
        deeper inside another body on the deformed geometry than invariant (b) allows for
        faceting and linear theory's second-order terms while linear theory's own reading
        holds it within (``Invariants.second_order``), naming the step and node furthest
        beyond: the answer holds as linear theory reads it, and its deformed geometry is off
        by about that depth (issue 37: random model 2d-50 of seed 4, a soft quadratic quarter
        disk flattened 3.6 % by a platen, its facets at the edge of contact turning 0.09 rad
        as they slip a quarter facet over the block; large kinematics reads the same model
        with linear elements 0.004 % of the push inside)."""
        found = [(s, s.invariants["second_order"]) for s in steps
                 if s.invariants and s.invariants.get("second_order")]
        if not found:
            return
        step, so = max(found, key=lambda f: f[1]["beyond"])
        quadratic = any(b.order > 1 for b in self.model.bodies
                        if b.name in (so["body"], so["into"]))
        remedy = 'kinematics = "total"' + (" (with linear elements)" if quadratic else "")
        settings = self.model.contact
        if settings.method != "vfem" or settings.variant != "paired":
            # the thesis variant and the baselines: small kinematics only (the record exists
            # only under small kinematics, so the running formulation cannot tell)
            remedy = f"the paired variant (the default contact method) with {remedy}"
        log.warning("step %d (load factor %.6g): node %d of body %r lies %.3g inside body %r on "
                    "the deformed geometry, beyond the %.3g allowed for faceting and linear "
                    "theory's second-order terms, while small kinematics reads it %.3g %s: the "
                    "answer holds as linear theory reads it, its deformed geometry is off by "
                    "about that depth; %s reads the deformed geometry",
                    step.step, step.load_factor, so["node"], so["body"], so["deformed_depth"],
                    so["into"], so["allowed"], abs(so["linearised_depth"]),
                    "inside" if so["linearised_depth"] > 0 else "outside", remedy)

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
        state.platen_force = platen.force_at(load_factor) if platen is not None else 0.0
        res = self.contact.solve(state, self.on_iteration)
        history_out.extend(res.history)
        if not res.converged:
            failure, message = res.failure, res.message
            off = self._platen_off(state, res) if failure is ContactNotConverged else ""
            if off:
                message = f"{message}; {off}"
                last = res.history[-1]
                if (last.max_penetration <= self.contact.penetration_tolerance
                        and last.tension_nodes == 0):
                    failure = PlatenOffForce  # what is left: the platen (its own remedy)
            raise failure(message)  # its kind: what the diagnosis reads
        return state, res

    def _platen_off(self, state: ContactState, res: SolveResult) -> str:
        """Where a solve ended with a force-controlled platen's reaction off its force (the
        last iteration's ``platen_error`` beyond the formulation's allowance, issue 37), what
        the message adds: by how much, and the force; "" otherwise."""
        group = getattr(self.contact, "group", None)  # the virtual-element formulations'
        if group is None or group.platen_body is None or not res.history:
            return ""  # (a baseline's global system: its own failure kinds)
        error = res.history[-1].platen_error
        allowed = group.platen_allowance(state)
        if abs(error) <= allowed:
            return ""
        name = group.surfaces[group.platen_body].body.name
        return (f"the platen on body {name!r} is {abs(error):.3g} off its force "
                f"{state.platen_force + 0.0:.6g} (allowed {allowed:.3g})")

    # -- the steps ------------------------------------------------------------------------------

    def run(self, on_step: Callable[[StepResult], None] | None = None,
            start: Checkpoint | None = None) -> AnalysisResult:
        """Run the steps; ``on_step(step)`` after each converged one. If ``on_step`` also has
        an ``iteration`` attribute, it is called with every contact iteration's record (a
        progress display shows the current errors with it).

        ``start``: a :class:`Checkpoint` (from :meth:`checkpoint` of an earlier run of the same
        model, e.g. read back by ``--resume``) to continue from instead of the unloaded state.

        Step control: a step that fails (no convergence within ``max_iterations``, a contact
        set that cycles, a node pushed past a rind, an element turned inside out, a converged state
        that breaks an enforced invariant of :mod:`vfem.contact.invariants.check`) is discarded
        — every body goes back to the last converged state exactly — and retried with half the
        increment, down to 1 / 2**``max_step_cuts`` of the scheduled one; after
        :data:`EASY_STEPS` steps in a row that converge in at most :func:`easy_iterations`
        iterations the increment doubles again, up to the scheduled one. Scheduled load factors
        are always reached exactly. A step that breaks invariant (b) or meets the rind at every
        cut may have its pair's compatibility side switched (:meth:`_switch_side`) and is then
        solved again from the full increment.
        """
        if not hasattr(self, "contact"):
            self.setup()
        #: called with every contact iteration's record (progress displays)
        self.on_iteration = getattr(on_step, "iteration", None)
        t_setup = time.perf_counter()
        settings = self.model.contact
        caps = self.contact.capabilities
        # a formulation whose failed step is final (a baseline's) is not cut
        max_cuts = settings.max_step_cuts if caps.cuts_steps else 0
        easy_limit = easy_iterations(settings)
        if start is None:
            if self.sides:  # (a run before on this analysis switched some: the rules' again)
                self.sides.clear()
                self.contact = self._contact(self.pairs)
            self.side_notes.clear()
            state = self.contact.new_state()
            steps: list[StepResult] = []
            self.target, self.level, self.easy = 1, 0, 0
        else:
            sides = {(int(i), int(j)): int(c) for i, j, c in start.sides}
            if sides != self.sides:  # the sides the run had switched by then
                self.sides = sides
                self.contact = self._contact(self.pairs)
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
                t0 = time.perf_counter()
                new, res = self.solve_step(state, lf, history)
                t1 = time.perf_counter()
                # full-mesh results and the invariants before the bodies commit the step, so
                # that a state that breaks one is discarded like any failed step
                fields = self._fields(new, res)
                self._add_time("contact_s", t1 - t0)
                self._add_time("fields_s", time.perf_counter() - t1)
                invariants = self.check_invariants(fields, history)
                # (a baseline's answer is its own: recorded against vfem's invariants, compared,
                # never a failed step)
                if not invariants.ok and caps.invariants == "enforced":
                    exc = InvariantViolation(
                        "the converged contact state breaks an invariant checked independently "
                        f"of the contact formulation: {invariants.message()}")
                    where = invariants.where or {}
                    exc.bodies = None if invariants.separated or "into" not in where else (
                        where["body"], where["into"])
                    exc.where = (dict(where) if "interpenetration" in invariants.failed()
                                 and not invariants.separated else None)
                    raise exc
                if invariants.failed() and caps.invariants == "recorded":
                    log.warning("step to load factor %.6g: recorded, not enforced: %s violated "
                                "(summary.json, steps[].invariants)", lf,
                                ", ".join(invariants.failed()))
            except AnalysisError as exc:
                for b in self.model.bodies:
                    b.discard_step()
                if self._enforce(exc):
                    continue  # the same step again, the node held (not a cut)
                self.easy = 0
                switched = self._switch_side(exc, lf, steps) if self.level >= max_cuts \
                    else None
                if switched is not None:
                    # the step again from the last converged load factor and the full
                    # increment, the pair's other side carrying compatibility
                    state = self.state = switched
                    self.level = 0
                    continue
                if self.level >= max_cuts:
                    converged = False
                    message = diagnosis(len(steps) + 1, state.load_factor, lf, self.level, exc,
                                        settings, self.unreachable, self._tried(exc))
                    log.info(message)  # the caller reports it (AnalysisResult.message)
                    break
                self.level += 1
                # step control at work, not a failure: the progress line counts the cuts
                log.info("step to load factor %.6g not reached (%s); cutting the increment to "
                         "%.6g", lf, exc, full / 2**self.level)
                continue
            for b in self.model.bodies:
                b.commit_step()
            if hasattr(self.contact, "enforce"):
                self.contact.enforce(None)  # each step finds its own (resumed runs alike)
            state = self.state = new
            iterations = sum(1 for h in history if h.iteration > 0) or 0
            if res.fixed_point:  # the thesis variant's: not converged (issue 37)
                last = history[-1]
                log.warning("step to load factor %.6g: stopped at the thesis variant's fixed "
                            "point OUTSIDE its tolerance (penetration %.3g, tolerance %.3g; "
                            "equilibrium error %.3g): not converged", lf, last.max_penetration,
                            self.contact.penetration_tolerance, last.max_equilibrium_error)
            step = StepResult(step=len(steps) + 1, load_factor=lf, iterations=iterations,
                              converged=not res.fixed_point, history=history,
                              platen_displacement=state.platen_displacement, cuts=self.level,
                              fixed_point=res.fixed_point, invariants=invariants.record(),
                              compatibility_switched=self._sides())
            step.bodies = fields
            step.yielded = {b.name: n for b in self.model.bodies
                            if (n := yielded_points(b.mechanics)) is not None}
            self.warn_large_strain(step)
            steps.append(step)
            log.info("step %d (load factor %.4g) converged in %d iterations", step.step, lf,
                     iterations)
            if self.model.iterates and len(history) > 1:
                # Newton's bodies: the order of convergence (quadratic near the solution with
                # the consistent tangent: r_k+1 / r_k^2 bounded; "-" after a round-off start)
                r = [h.max_equilibrium_error for h in history]
                log.info("step %d: relative body residuals %s; r_k+1/r_k^2 %s", step.step,
                         ", ".join(f"{x:.2e}" for x in r),
                         ", ".join(f"{b / a**2:.3g}" if a > 1e-10 else "-"
                                   for a, b in zip(r[:-1], r[1:])))
            if lf == target:
                self.target += 1
            self.easy = self.easy + 1 if iterations <= easy_limit else 0
            if self.level > 0 and self.easy >= EASY_STEPS:
                self.level -= 1
                self.easy = 0
                log.info("the increment grows back to %.6g", full / 2**self.level)
            if on_step is not None:
                t0 = time.perf_counter()
                on_step(step)  # (the results of the step written, by the caller)
                self._add_time("output_s", time.perf_counter() - t0)
        self.warn_second_order(steps)
        complete = self.target >= len(schedule)  # every scheduled load factor reached
        if converged and any(s.fixed_point for s in steps):
            # the thesis variant ran every step, but stopped some outside its tolerance: not
            # converged (the CLI's exit status 1), its results written for comparison
            converged = False
            message = fixed_point_message(steps, self.contact.penetration_tolerance)
            log.info(message)
        # a formulation's own timings (a baseline's factorizations and solves)
        self.timings.update(getattr(self.contact, "timings", {}))
        self.timings["steps_s"] = time.perf_counter() - t_setup
        self.timings["build_s"] = self.model.build_s
        self.timings["total_s"] = sum(self.timings[key] for key in
                                      ("search_s", "assemble_factorize_s", "flexibility_s",
                                       "steps_s"))
        return AnalysisResult(self.model, converged, steps, dict(self.timings), message,
                              self.surfaces, self.contact.penetration_tolerance, self.backend,
                              "matrix_free" if getattr(self, "matrix_free", False) else "dense",
                              complete, self.pairs)

    def _enforce(self, exc: AnalysisError) -> bool:
        """A step stopped at invariant (b) at a node the formulation left out on purpose (a
        held node its guard excused): whether the formulation now holds it
        (:meth:`~vfem.contact.formulations.paired.PairedContact.enforce`), at most
        :data:`ENFORCED_NODES` times a step; the step is then solved again at the same load factor.
        Each step starts without such nodes (a run resumed from a checkpoint finds the same
        ones)."""
        where = getattr(exc, "where", None)
        if (not isinstance(exc, InvariantViolation) or not where
                or not hasattr(self.contact, "enforce")):
            return False
        count = getattr(self, "_enforced_step", (None, 0))
        n = count[1] if count[0] == len(self.steps) else 0
        if n >= ENFORCED_NODES or not self.contact.enforce(where):
            return False
        self._enforced_step = (len(self.steps), n + 1)
        return True

    def _pair_of(self, exc: AnalysisError) -> tuple[int, int] | None:
        """The pair (i, j), i < j, of the two bodies an error names (``exc.bodies``), or None."""
        bodies = getattr(exc, "bodies", None)
        names = [b.name for b in self.model.bodies]
        if not bodies or any(n not in names for n in bodies) or bodies[0] == bodies[1]:
            return None
        i, j = sorted(names.index(n) for n in bodies)
        return i, j

    def _tried(self, exc: AnalysisError) -> str:
        """What the stop message says of the pair an error names where the solver tried its
        other compatibility side (:meth:`_switch_side`), "" where it did not."""
        key = self._pair_of(exc)
        if key in self.sides:
            return ("the solver switched the pair's compatibility side to the other body "
                    f"({self.model.bodies[self.sides[key]].name!r}) already, and it failed "
                    "too; ")
        return self.side_notes.get(key, "")

    def _switch_side(self, exc: AnalysisError, load_factor: float, steps: list[StepResult]
                     ) -> ContactState | None:
        """A step that broke invariant (b), or pushed a node past the rind, at every cut: where
        the rules chose the pair's compatibility side (``contact.compatibility_side`` unset),
        the contact is frictionless (its answer at a load factor owes nothing to which side
        carried compatibility on the way: no slip history) and the pair has not been switched
        before, the other body carries it from now on. Returns the contact state of the
        switched formulation at the last converged load factor (reached through the load
        factors of ``steps``), or None: no switch (the other side pairs no node, or it did
        not reach those load factors again: the rules' side is kept, and the stop message says
        what was tried).

        **Why**: where one side's mesh cannot resolve the contact (a soft rectangle's corner
        sliding along a block turned by the load, random model 2d-75; a stiff round face
        coarsely met, 2d-215), no step size helps (four times the steps solved neither) and
        the other side solves both (``benchmarks/random_models.py --remedies``); the
        large-kinematics gasket of docs/examples.md, stopped at step 11, runs through. The
        invariants judge the switched side as they judged the first (their tolerance is the
        surfaces', not the side's: the check stands); a forced coarser side's warning
        (:data:`~vfem.contact.formulations.pairmaking.FORCED_COARSER`) is given for it too."""
        from .contact.formulations import LargeDeformationContact, PairedContact

        if not (isinstance(exc, RindViolation)
                or (isinstance(exc, InvariantViolation) and getattr(exc, "where", None))):
            return None  # ((b) failed: ``where`` is set only then)
        key = self._pair_of(exc)
        if (key is None or key in self.sides or key in self.side_notes
                or self.model.contact.compatibility_side is not None
                or type(self.contact) not in (PairedContact, LargeDeformationContact)
                or self.contact.friction is not None  # (friction: its slip history)
                or key not in self.contact.carriers):
            return None
        carrier, _ = self.contact.carriers[key]
        other = key[1] if carrier == key[0] else key[0]
        a, b = (self.model.bodies[k].name for k in key)
        name = self.model.bodies[other].name
        kept = self.contact
        self.sides[key] = other
        self.contact = self._contact(self.pairs)
        why = ""
        if self.contact.carriers.get(key, (other, 0))[1] == 0:
            why = f"with {name!r} on the compatibility side no node of the two is paired"
        else:
            state = self._replay(steps)
            if state is not None:
                self._enforced_step = (None, 0)  # (the switched formulation's own count)
                log.warning(
                    "step to load factor %.6g %s at every cut with the compatibility side the "
                    "rules chose for bodies %r and %r: %r carries it from here (summary.json: "
                    "steps[].compatibility_switched)", load_factor,
                    "broke invariant (b)" if isinstance(exc, InvariantViolation) else
                    "pushed a node past the other body's outer layer of elements", a, b, name)
                return state
            why = (f"with {name!r} on the compatibility side the steps before did not "
                   "converge again")
        del self.sides[key]
        self.contact = kept
        self.side_notes[key] = (f"the solver tried the other body of the two on the "
                                f"compatibility side and kept the rules' ({why}); ")
        log.info("compatibility side of bodies %r and %r not switched: %s", a, b, why)
        return None

    def _replay(self, steps: list[StepResult]) -> ContactState | None:
        """The switched formulation's contact state at the last converged load factor, reached
        through the load factors of ``steps`` as the run reached them (each a step of the
        same size as it was, so that no node goes past the rind for want of a path; the
        steps' results stand as they were found, and the progress display is not told);
        None where one of them fails. Large-kinematics bodies go through them too, from their
        unloaded state, committing each (and back to the state they had where one fails;
        a linear body's state is empty, :class:`~vfem.bodies.mechanics.LinearMechanics`)."""
        bodies = self.model.bodies
        kept = {b.name: b.saved_state() for b in bodies}
        for b in bodies:
            b.restore_state(self._unloaded[b.name])
        state = self.contact.new_state()
        shown, self.on_iteration = self.on_iteration, None
        t0 = time.perf_counter()
        try:
            for s in steps:
                state, _ = self.solve_step(state, s.load_factor, [])
                for b in bodies:
                    b.commit_step()
        except AnalysisError as exc:
            log.info("with the switched compatibility side, the load factor %.6g of step %d "
                     "was not reached again (%s)", s.load_factor, s.step, exc)
            for b in bodies:
                b.discard_step()
                b.restore_state(kept[b.name])
            return None
        finally:
            self.on_iteration = shown
            self._add_time("contact_s", time.perf_counter() - t0)
        return state

    def _sides(self) -> dict[str, str]:
        """Per switched pair ("a/b"), the body that carries its compatibility now."""
        return {f"{self.model.bodies[i].name}/{self.model.bodies[j].name}":
                self.model.bodies[c].name for (i, j), c in sorted(self.sides.items())}

    def _add_time(self, key: str, seconds: float) -> None:
        self.timings[key] = self.timings.get(key, 0.0) + seconds

    def checkpoint(self) -> Checkpoint:
        """The last converged state, complete, with the steps so far: what :meth:`run` needs
        to continue from it (and what step cutting goes back to)."""
        return Checkpoint(list(self.steps), self.state.copy(),
                          {b.name: b.saved_state() for b in self.model.bodies},
                          self.target, self.level, self.easy,
                          [[i, j, c] for (i, j), c in sorted(self.sides.items())])

    def _fields(self, state: ContactState, result: SolveResult) -> dict[str, BodyStepResult]:
        """Full-mesh results of a converged state (the formulation's
        :meth:`~vfem.contact.formulations.formulation.ContactFormulation.fields`)."""
        return self.contact.fields(state, result)
