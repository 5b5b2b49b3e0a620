"""What every virtual-element formulation knows of the bodies: their contact surfaces, where the
tracked nodes are, and the force-controlled platen.

:class:`SurfaceGroup` is the shared part of the thesis variant
(:class:`~vfem.contact.formulations.algorithm.VirtualElementContact`) and the paired variant (small
and large displacements, :mod:`vfem.contact.formulations.paired`,
:mod:`vfem.contact.formulations.large`); the platen's bordered system that each of them solves in
its compatibility correction is the solvers'
(:func:`~vfem.contact.solvers.bordered.bordered_solve`).
"""

from __future__ import annotations

import numpy as np

from ...bodies.results import BodyStepResult, add_reactions
from ...executor import SERIAL, Executor
from ..geometry import ContactPairs, ContactSurface
from ..settings import ContactSettings
from ..state import ContactState, SolveResult


def weightless_corners(s) -> bool:
    """Whether the facets of ``s`` (it has candidate facets) have corners whose shape
    functions integrate to zero (:attr:`~vfem.contact.geometry.facets.FacetKind.weightless_corners`:
    quadratic triangles, T6)."""
    return s.kind is not None and bool(s.kind.weightless_corners) and len(s.facets) > 0


def quadratic_status(s, participating: np.ndarray) -> np.ndarray:
    """In contact, where corners weigh nothing (quadratic triangles, T6): a node the
    formulation counts in (the compatibility side's positive tractions, the other side's
    compressive forces), and a corner both of whose edge midpoints in one of its facets are: a
    corner's force is zero under a uniform pressure and of either sign under a varying one, so
    it cannot tell."""
    on = np.asarray(participating, dtype=bool).copy()
    f = s.facets
    for corner, m1, m2 in s.kind.weightless_corners:
        both = on[f[:, m1]] & on[f[:, m2]]
        on[f[both, corner]] = True
    return on


def consistent_pressure(s, force: np.ndarray) -> np.ndarray:
    """The nodal pressure of normal nodal forces ``force`` (nc,) on surface ``s``: force over
    tributary (the traction averaged with each node's shape function, ``BodyStepResult.
    contact_pressure``); on quadratic triangles (3D, T6), whose corners' shape functions
    integrate to zero (a uniform pressure puts no force on them), the consistent pressure
    instead, the nodal values p with N p = force (N the surface's mass matrix, ∫ phi phi^T):
    exact for any pressure the facets can represent (the 3D patch test's to round-off). So too
    wherever a node's tributary (nearly) vanishes, under 1e-6 of the largest, and force over
    tributary is no reading: a body of revolution's node on the axis at the end of a quadratic
    facet (∫ phi 2 pi r ds = 0 on a straight one, of the order of the facet's curvature on a
    curved one: 6e-10 of the largest tributary on the Hertz sphere's axis; issue 42)."""
    trib = s.tributary
    weightless = len(s.facets) > 0 and trib.size > 0 and bool(
        (trib <= 1e-6 * np.abs(trib).max()).any())
    if weightless_corners(s) or weightless:
        from scipy.sparse.linalg import spsolve

        N = s.mass_matrix(np.ones(len(s.facets))).tocsc()
        return np.asarray(spsolve(N, force), dtype=float).ravel()
    return force / s.tributary

class SurfaceGroup:
    """The contact surfaces of all bodies, the pairs of bodies that may touch, the settings, the
    penetration tolerance and the platen (see the module docstring): a part each virtual-element
    formulation holds (``formulation.group``), not a class it derives from."""

    def __init__(self, surfaces: list[ContactSurface], pairs: ContactPairs,
                 settings: ContactSettings, backend: str | None = None,
                 executor: Executor | None = None):
        self.surfaces = surfaces
        self.backend = backend  # the linear solver of the bodies' tangents (large kinematics)
        #: where each body's work runs (each on the MPI rank that owns it, :mod:`vfem.parallel`,
        #: handed in by the solver; serially without one)
        self.executor = executor if executor is not None else SERIAL
        self.pairs = pairs
        self.settings = settings
        lengths = np.concatenate([s.lengths for s in surfaces if len(s.lengths)] or [[1.0]])
        self.penetration_tolerance = (settings.penetration_tolerance
                                      if settings.penetration_tolerance is not None
                                      else 1e-5 * float(lengths.min()))
        platens = [i for i, s in enumerate(surfaces) if s.body.platen is not None]
        self.platen_body = platens[0] if platens else None
        # each body's candidate-node motion per unit platen motion (zero but for the platen's)
        self.platen_motion = [s.body.u_platen[s.candidate_dofs].reshape(-1, s.dim)
                              for s in surfaces]

    def new_state(self, state_type: type[ContactState] = ContactState,
                  load_factor: float = 0.0, platen_displacement: float = 0.0) -> ContactState:
        """No contact force on any body (a ``state_type``: the formulation's, with its own
        unknowns, empty at first)."""
        return state_type(load_factor, platen_displacement,
                          [np.zeros((s.nc, s.dim)) for s in self.surfaces],
                          [np.zeros(s.nc, dtype=bool) for s in self.surfaces])

    def adopt(self, formulation) -> None:
        """Give ``formulation`` the group's data by name (the surfaces, pairs of bodies,
        settings, backend, executor, penetration tolerance and platen), which its stages read
        throughout."""
        for name in ("surfaces", "pairs", "settings", "backend", "executor",
                     "penetration_tolerance", "platen_body", "platen_motion"):
            setattr(formulation, name, getattr(self, name))

    def positions(self, state: ContactState) -> list[np.ndarray]:
        """Current coordinates of every body's condensed nodes (the rows of its flexibility:
        the tracked nodes, or the candidates alone, :attr:`ContactSurface.rind_rows`):
        X + u(load, platen, forces), the bodies' linear response (superposition)."""
        # the contact forces' share: each body on the rank that owns it (vfem.parallel)
        moved = self.executor.map(range(len(self.surfaces)), lambda i: self.surfaces[
            i].motion(state.forces[i].ravel()))
        out = []
        for i, s in enumerate(self.surfaces):
            b = s.body
            dofs = s.condensed_dofs
            u = (b.load_displacement(state.load_factor, dofs) + state.platen_displacement
                 * b.u_platen[dofs] + moved[i])
            out.append(s.X[: len(dofs) // s.dim] + u.reshape(-1, s.dim))
        return out

    def platen_reaction(self, state: ContactState) -> float:
        """Reaction of the platen (force it applies to its body), linear in the state."""
        if self.platen_body is None:
            return 0.0
        s = self.surfaces[self.platen_body]
        b = s.body
        return (b.platen_load_reaction_at(state.load_factor)
                + state.platen_displacement * b.platen_stiffness
                + float(s.platen_row @ state.forces[self.platen_body].ravel()))

    def platen_error(self, state: ContactState) -> float:
        """The platen's reaction less its scheduled force (0 without a platen: both zero)."""
        return self.platen_reaction(state) - state.platen_force

    def platen_met(self, state: ContactState) -> bool:
        """Whether the platen's reaction is on its scheduled force (always, without a platen)."""
        if self.platen_body is None:
            return True
        error = self.platen_reaction(state) - state.platen_force
        return abs(error) <= self.platen_allowance(state)

    def platen_allowance(self, state: ContactState) -> float:
        """How far the platen's reaction may be from its force and count as on it:
        ``platen_tolerance`` times the force; where the force is zero (a load curve at zero, a
        platen that holds a body sideways while it is pressed), times the force scale of the
        reaction instead (issue 37, :meth:`platen_force_scale`). Relative to the zero force
        itself only an exactly zero reaction would do: a model whose every error was 1e-17
        stopped after ``max_iterations``."""
        cfg = self.settings
        if state.platen_force != 0.0:
            return cfg.platen_tolerance * abs(state.platen_force)
        return cfg.platen_tolerance * self.platen_force_scale(state)

    def platen_force_scale(self, state: ContactState) -> float:
        """The forces the platen's reaction sums (:meth:`platen_reaction`), in magnitude: the
        loads' share, the platen's motion times its stiffness, and every contact force of its
        body (the whole force, not its component along the platen: the round-off of a sideways
        reaction is the normal forces') times the reaction it makes per unit force. Zero only
        where every one of them is, the reaction then exactly zero."""
        if self.platen_body is None:
            return 0.0
        s = self.surfaces[self.platen_body]
        b = s.body
        row = np.linalg.norm(s.platen_row.reshape(-1, s.dim), axis=1)
        force = np.linalg.norm(state.forces[self.platen_body], axis=1)
        return (abs(b.platen_load_reaction_at(state.load_factor))
                + abs(state.platen_displacement * b.platen_stiffness) + float(row @ force))

    def fields(self, state: ContactState, result: SolveResult) -> dict[str, BodyStepResult]:
        """Full-mesh results of a converged state, per body (one back-substitution each): the
        displacements under the state's loads, platen motion and contact forces, the contact
        forces, pressure (nodal force over tributary length), the formulation's traction where
        it has one, contact status and penetration (``result.pairings``), and the reactions."""
        def body_result(i: int) -> BodyStepResult:
            s, F, p = self.surfaces[i], state.forces[i], result.pairings[i]
            b = s.body
            f = np.zeros(b.ndofs)
            f[s.candidate_dofs] = F.ravel()
            u = b.displacement(state.load_factor, state.platen_displacement, f)
            nv = b.npoints
            cand = s.nodes[: s.nc]
            force = np.zeros((nv, s.dim))
            force[cand] = F
            pressure = np.zeros(nv)
            pressure[cand] = consistent_pressure(s, np.where(p.other >= 0, p.force, 0.0))
            traction = None
            if p.pressure is not None:  # the formulation's traction field (paired)
                traction = np.zeros(nv)
                traction[cand] = p.pressure
            status = np.zeros(nv, dtype=int)
            if weightless_corners(s):
                status[cand] = quadratic_status(s, p.participating)
            else:
                status[cand] = p.participating & (p.force > 0)
            pen = np.zeros(nv)
            pen[cand] = np.where(np.isfinite(p.penetration), p.penetration, 0.0)
            return add_reactions(
                b, BodyStepResult(u.reshape(-1, s.dim), force, pressure, status, pen, traction),
                state.load_factor)

        # each body's back-substitution and reactions on the rank that owns it
        # (vfem.parallel: the others hold neither its factorization nor its stiffness)
        results = self.executor.map(range(len(self.surfaces)), body_result)
        return {s.body.name: results[i] for i, s in enumerate(self.surfaces)}

    def opponents(self, i: int) -> list[int]:
        """The bodies body ``i`` may touch that have candidate facets."""
        return [j for j in self.pairs.opponents(i) if len(self.surfaces[j].facets)]
