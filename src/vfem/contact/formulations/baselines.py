"""The classical contact methods vfem is measured against (``contact.method``): penalty,
Lagrange multipliers and the augmented Lagrangian, on one global system of every body.

This is contact the way most finite element codes do it, on the same :class:`~vfem.model.Model`
as the virtual finite element method (bodies, meshes, supports, loads, platen, load factors):

* **one global system**: the stiffness of every body, block diagonal, reduced to the free dofs
  by a sparse transformation ``U = T q + load_factor * U_prescribed`` (``K_red = T^T K T``). A
  force-controlled rigid platen is one more unknown, the platen displacement, to which all its
  dofs are tied; its equation carries the platen force (scaled by the load factor). Loads on
  load curves (``amplitude``) are kept apart, one load vector per curve, each scaled by its
  curve's multiplier.
* **node-to-segment, single pass** (:mod:`vfem.contact.formulations.node_to_segment`): per pair
  of bodies, each node of the finer (*slave*) surface is a constraint on its closest segment of
  the other (*master*), its gap linearised once, ``g = g0 + B U >= 0``; the contact forces are
  ``B^T Lambda``, in balance between the bodies by construction.
* the **active set** (nodes in contact) is iterated until it no longer changes, and the global
  matrix refactorized each time it changes (the classical cost):

  - ``penalty``: ``(K + B_A^T E W B_A) q = f - B_A^T E W g0`` over the active (penetrating)
    nodes, ``E`` the penalty and ``W`` the slave nodes' tributary lengths: contact pressure =
    penalty x penetration, so the answer depends on the penalty;
  - ``lagrange``: the saddle point ``[K B_A^T; B_A 0]``, the gaps of the active nodes exactly
    closed; a node whose multiplier is tensile leaves the set, a node whose gap closes enters;
  - ``augmented``: augmented Lagrangian (Uzawa): the penalty system with the multipliers
    ``lambda`` (pressures) as loads, ``lambda <- max(0, lambda - penalty g)`` until every active
    node's gap and every other node's penetration is within ``augmented_tolerance`` of the
    shortest slave facet; refactorized only when the active set changes.

* the steps follow ``model.load_factors``, each from the previous step's active set (and
  multipliers); a step counts its linear solves as its iterations.

A body held only by contact and its platen (the Hertz cylinder) makes the system singular while
no node touches it: then its closest node is put in the active set, as a seed.

The results are the :class:`~vfem.result_types.AnalysisResult` of vfem: nodal contact forces on both
bodies, the nominal pressure read as vfem reads it (a node's normal contact force over its
undeformed tributary length on its :class:`~vfem.contact.geometry.surface.ContactSurface`; on a
master node the normal is the master's own node normal), the slave nodes' gaps as ``penetration`` (0
on master nodes, where none is measured). See ``docs/baselines.md``.
"""

from __future__ import annotations

import logging
import time

import numpy as np
import scipy.sparse as sp

from ...bodies import COMPONENTS, curve_key, superpose
from ...errors import ActiveSetNotSettled, AnalysisError, SingularSystem
from ...linalg import factorize
from ...memory import memory_guard
from ..capabilities import Capabilities
from ..geometry import ContactSurface
from ..laws import friction_law
from ..state import BaselineState, IterationRecord, SolveResult
from .node_to_segment import (
    node_to_segment,
)

log = logging.getLogger(__name__)

#: a node enters the active set when its gap is below minus this fraction of the shortest
#: slave facet (round-off, not physics: the gaps Lagrange closes are exact; penalty and
#: augmented nodes stay in while they penetrate at all)
GAP_ROUNDOFF = 1e-10
#: ... and leaves it when its force is tensile by more than this fraction of the largest force
FORCE_ROUNDOFF = 1e-10


class _Refined:
    """A saddle point's factorization whose solves take one step of iterative refinement:
    general pivoting on a matrix mixing stiffnesses (E ~ 1e9) with unit constraint rows loses
    digits, and one residual solve brings the gaps of the active nodes back to round-off."""

    def __init__(self, M: sp.spmatrix, factor):
        self.M, self.factor = M, factor

    def solve(self, b: np.ndarray) -> np.ndarray:
        x = self.factor.solve(b)
        return x + self.factor.solve(b - self.M @ x)


class GlobalContact:
    """A classical baseline (``model.contact.method``: penalty, lagrange or augmented) on the
    global system of the model's bodies; see the module docstring. A contact formulation
    (:class:`~vfem.contact.formulations.formulation.ContactFormulation`) whose step is one global
    solve with its active set, run on the solver's own steps."""

    capabilities = Capabilities(
        name="classical", orders=(1,), kinematics=("small",), dimensions=(2,),
        friction=("coefficients",), invariants="compared", cuts_steps=False)

    #: the methods that solve Coulomb friction (the Lagrange multipliers' saddle point)
    FRICTIONAL_METHODS = ("lagrange",)

    def __init__(self, model, backend: str | None = None):
        self.model = model
        self.method = model.contact.method
        self.backend = backend
        settings = model.contact
        t0 = time.perf_counter()
        pairs, self.surfaces = model.contact_surfaces()
        self.pairs = pairs  # (the result's, as the paired variant's)
        t1 = time.perf_counter()
        bodies = model.bodies
        for b in bodies:
            b.assemble()
        sizes = np.array([b.ndofs for b in bodies])
        self.offsets = np.r_[0, np.cumsum(sizes)[:-1]]
        N = int(sizes.sum())
        K = sp.block_diag([b.K for b in bodies], format="csr")
        free = np.concatenate([o + b.free_dofs for o, b in zip(self.offsets, bodies)])
        rows, cols = [free], [np.arange(len(free))]
        self.platen_body = next((i for i, b in enumerate(bodies) if b.platen is not None), None)
        self.nq = len(free) + (self.platen_body is not None)
        # the loads by load curve (the proportional case first): every body's load cases and
        # the platen force, each at multiplier 1
        keys = [None]
        for b in bodies:
            keys += [cs.amplitude for cs in b.load_cases if cs.amplitude not in keys]
        if self.platen_body is not None:
            amplitude = curve_key(bodies[self.platen_body].platen.amplitude)
            keys += [amplitude] if amplitude not in keys else []
        f1 = [np.zeros(N) for _ in keys]
        U1 = [np.zeros(N) for _ in keys]
        for b, off in zip(bodies, self.offsets):
            for cs in b.load_cases:
                k = keys.index(cs.amplitude)
                f1[k][off:off + b.ndofs] = cs.force
                U1[k][off:off + b.ndofs] = cs.prescribed
        platen_force = [np.zeros(self.nq) for _ in keys]
        if self.platen_body is not None:
            b = bodies[self.platen_body]
            rows.append(self.offsets[self.platen_body] + b.platen_dofs)
            cols.append(np.full(len(b.platen_dofs), self.nq - 1))
            platen_force[keys.index(curve_key(b.platen.amplitude))][-1] = b.platen.force
        r, c = np.concatenate(rows), np.concatenate(cols)
        self.T = sp.csr_matrix((np.ones(len(r)), (r, c)), shape=(N, self.nq))
        self.K = (self.T.T @ K @ self.T).tocsc()
        self.curves = keys
        #: per load curve: the prescribed displacements (all dofs) and the reduced load (loads,
        #: prescribed displacements, platen force), at multiplier 1
        self.U_prescribed = U1
        self.f1 = [self.T.T @ (f - K @ U) + pf for f, U, pf in zip(f1, U1, platen_force)]
        t2 = time.perf_counter()
        c = node_to_segment(self.surfaces, pairs, self.offsets, N, settings.penalty,
                            settings.penalty_factor)
        Br = (c.B @ self.T).tocsr()
        Br.eliminate_zeros()
        # a row without a free dof (slave node and master segment both held) is no constraint
        live = np.diff(abs(Br).tocsr().indptr) > 0
        self.c = c.subset(live)
        self.Br = Br[live]
        self.g_prescribed = [self.c.B @ U for U in self.U_prescribed]  # per unit multiplier
        self.frictional = settings.frictional
        if self.frictional:
            self._setup_friction(settings)
        t3 = time.perf_counter()
        slave_lengths = [s.lengths.min() for i, s in enumerate(self.surfaces)
                         if len(s.lengths) and np.any(self.c.slave == i)]
        self.h_min = float(min(slave_lengths)) if slave_lengths else 1.0
        self.gap_tolerance = GAP_ROUNDOFF * self.h_min
        self.augmented_tolerance = settings.augmented_tolerance * self.h_min
        self.floating = self._floating_rows()
        self._factor_key: tuple | None = None
        self._factor = None
        self.factorizations = 0
        self.timings = {"search_s": (t1 - t0) + (t3 - t2), "assemble_s": t2 - t1,
                        "factorize_s": 0.0, "solve_s": 0.0}
        log.info("%s: global system of %d unknowns, %d node-to-segment constraints",
                 self.method, self.nq, len(self.c.node))

    def _setup_friction(self, settings) -> None:
        """Coulomb friction on the node-to-segment rows (``lagrange``): each row's law (the
        pair of its slave and master bodies), its relative tangential displacement's rows on
        the free dofs and their prescribed part. A row whose tangential motion no free dof
        moves (a symmetry plane through the contact), or of a frictionless pair, has no
        tangential unknown."""
        names = [b.name for b in self.model.bodies]
        # each row's pair's law (:class:`~vfem.contact.laws.FrictionLaw`), at no accumulated
        # slip: the baseline keeps none per row, and its capabilities read the coefficients
        # alone (a law that reads the slip is refused before, check_capabilities)
        laws = [friction_law(settings.pair_friction(names[a], names[b]))
                for a, b in zip(self.c.slave, self.c.master)]
        none = np.zeros(1)
        self.mu = np.array([law.dynamic(none)[0] for law in laws])
        self.mu_static = np.array([law.static(none)[0] for law in laws])
        Bt = (self.c.Bt @ self.T).tocsr()
        Bt.eliminate_zeros()
        self.Btr = Bt
        self.t_live = (np.diff(abs(Bt).tocsr().indptr) > 0) & (self.mu_static > 0)
        self.w_prescribed = [self.c.Bt @ U for U in self.U_prescribed]

    @property
    def penetration_tolerance(self) -> float:
        """The gap tolerance the method works to (0 for the penalty method, which has none)."""
        return {"lagrange": self.gap_tolerance, "augmented": self.augmented_tolerance}.get(
            self.method, 0.0)

    def _floating_rows(self) -> list[np.ndarray]:
        """For each body held along its platen's direction only by contact (the platen is its
        only support that way), the constraint rows that touch it: one of them must stay active
        or the global matrix is singular."""
        out = []
        self.unheld = []  # such bodies without any constraint row: the matrix is singular
        for i, b in enumerate(self.model.bodies):
            if b.platen is None:
                continue
            held = np.setdiff1d(b.fixed_dofs, b.platen_dofs)
            if np.any(held % 2 == COMPONENTS[b.platen.component]):
                continue
            rows = np.flatnonzero((self.c.slave == i) | (self.c.master == i))
            if len(rows):
                out.append(rows)
            else:
                self.unheld.append(b)
        return out

    def _seeded(self, active: np.ndarray, gap: np.ndarray) -> np.ndarray:
        """``active`` with the closest node of each body that only contact holds, where none
        of its nodes is active."""
        out = active.copy()
        for rows in self.floating:
            if not out[rows].any():
                out[rows[np.argmin(gap[rows])]] = True
        return out

    # -- the linear systems ----------------------------------------------------------------------

    def _factorized(self, active: np.ndarray):
        """The factorization of the method's matrix for ``active``, refactorized only when the
        active set changed."""
        key = (self.method, active.tobytes())
        if key == self._factor_key:
            return self._factor
        A = np.flatnonzero(active)
        Ba = self.Br[A]
        t0 = time.perf_counter()
        try:
            with memory_guard(f"factorizing the global system ({self.method})"):
                if self.method == "lagrange":
                    M = sp.bmat([[self.K, Ba.T], [Ba, None]], format="csc")
                    self._factor = _Refined(M, factorize(M, self.backend, spd=False,
                                                         what=f"the {self.method} global system"))
                else:
                    ew = self.c.penalty[A] * self.c.weight[A]
                    M = (self.K + Ba.T @ sp.diags(ew) @ Ba).tocsc()
                    self._factor = factorize(M, self.backend,
                                             what=f"the {self.method} global system")
        except RuntimeError as exc:  # SuperLU: a zero pivot
            if isinstance(exc, AnalysisError):
                raise SingularSystem(str(exc)) from None
            raise SingularSystem(
                f"the global matrix of the {self.method} method is singular with "
                f"{len(A)} nodes in contact ({exc}): a body is held by nothing but contact and "
                "no node of it can touch (no candidate facets near it?)") from None
        self.timings["factorize_s"] += time.perf_counter() - t0
        self.factorizations += 1
        self._factor_key = key
        return self._factor

    def at(self, load_factor: float, per_curve: list) -> np.ndarray:
        """``per_curve`` (one vector per load curve, :attr:`curves`, at multiplier 1) at
        ``load_factor``: ``load_factor`` times the one vector of a model without load curves."""
        return superpose(load_factor, zip(self.curves, per_curve))

    def solve_step(self, load_factor: float, active: np.ndarray, lam: np.ndarray):
        """Solve at ``load_factor`` from the active set and multipliers (pressures, augmented
        Lagrangian) of the previous step. Returns (q, Lambda, gap, active, lam, history):
        the reduced unknowns, each row's normal contact force, its gap, the final active set,
        the multipliers to start the next step from, and one record per linear solve.

        Raises:
            AnalysisError: the active set does not settle within ``max_iterations`` solves, or
                comes back to one it had left.
        """
        settings = self.model.contact
        if self.unheld:
            b = self.unheld[0]
            raise SingularSystem(
                f"body {b.name!r} is held along {b.platen.component} only by its platen and by "
                "contact, and none of its nodes can touch another body (no contact candidates "
                "within contact.search_distance), so the global matrix is singular")
        f = self.at(load_factor, self.f1)
        gp = self.c.g0 + self.at(load_factor, self.g_prescribed)  # with the loads' motion only
        c, Br = self.c, self.Br
        ew = c.penalty * c.weight
        active = self._seeded(active, gp)
        seen = {active.tobytes()}
        history: list[IterationRecord] = []
        for it in range(1, settings.max_iterations + 1):
            A = np.flatnonzero(active)
            factor = self._factorized(active)
            t0 = time.perf_counter()
            Lam = np.zeros(len(gp))
            tension = 0
            if self.method == "lagrange":
                sol = factor.solve(np.r_[f, -gp[A]])
                q = sol[: self.nq]
                Lam[A] = -sol[self.nq:]
                g = gp + Br @ q
                scale = float(np.abs(Lam).max(initial=0.0))
                leave = active & (Lam < -FORCE_ROUNDOFF * scale)
                tension = int(leave.sum())
                new = (active & ~leave) | (~active & (g < -self.gap_tolerance))
            elif self.method == "penalty":
                q = factor.solve(f - Br[A].T @ (ew[A] * gp[A]))
                g = gp + Br @ q
                Lam[A] = -ew[A] * g[A]
                # a node enters past round-off (two bodies' coincident nodes moving together
                # have gaps of +-1e-18 that would cycle), stays while it penetrates at all
                new = (active & (g < 0)) | (g < -self.gap_tolerance)
            else:  # augmented Lagrangian
                q = factor.solve(f + Br[A].T @ (c.weight[A] * lam[A] - ew[A] * gp[A]))
                g = gp + Br @ q
                trial = lam - c.penalty * g  # pressures
                Lam[A] = c.weight[A] * trial[A]
                new = (active & (trial > 0)) | (trial > c.penalty * self.gap_tolerance)
            self.timings["solve_s"] += time.perf_counter() - t0
            if not np.all(np.isfinite(q)):
                raise SingularSystem(
                    f"the {self.method} method's linear solve gave non-finite displacements "
                    f"with {len(A)} nodes in contact: the global matrix is singular (a body "
                    "held by nothing but contact, with no node of it in contact)")
            new = self._seeded(new, gp)
            penetration = float(np.maximum(-g, 0.0).max(initial=0.0))
            history.append(IterationRecord(it, penetration, 0.0, int((Lam > 0).sum()), tension))
            if np.array_equal(new, active):
                if self.method != "augmented":
                    return q, Lam, g, active, Lam / c.weight, history
                error = float(np.abs(np.where(active, g, np.minimum(g, 0.0))).max(initial=0.0))
                if error <= self.augmented_tolerance:
                    return q, Lam, g, active, np.maximum(trial, 0.0), history
                lam = np.maximum(trial, 0.0)  # Uzawa's update; the factorization is kept
                continue
            key = new.tobytes()
            if key in seen and self.method != "augmented":
                changed = np.flatnonzero(new != active)
                raise ActiveSetNotSettled(
                    f"the {self.method} method's active set cycles: it came back to a contact "
                    f"set it had left after {it} linear solves (nodes switching now: "
                    f"{self._name_rows(changed)})")
            seen.add(key)
            active = new
        raise ActiveSetNotSettled(
            f"the {self.method} method's active set did not settle in {settings.max_iterations} "
            f"linear solves (contact.max_iterations); largest penetration {penetration:.3g}")

    def _factorized_frictional(self, active: np.ndarray, stick: np.ndarray, slide: np.ndarray,
                               sigma: np.ndarray):
        """The saddle point of Lagrange multipliers with Coulomb friction for these sets:

            [ K      B_A^T + C   T_S^T ] [q  ]   [f              ]
            [ B_A    0           0     ] [y_n] = [-g_A           ]
            [ T_S    0           0     ] [y_t]   [w_anchor - w_p ]

        ``B_A`` the gaps of the nodes in contact, ``T_S`` the relative tangential
        displacements of the sticking ones (held at their anchors), and ``C`` the slipping
        nodes' tangential forces tied to their normal ones (``-mu sigma T_L^T`` in their
        columns): not symmetric, factorized by LU. Refactorized when a set changes."""
        key = ("coulomb", active.tobytes(), stick.tobytes(), slide.tobytes(),
               (sigma[slide] > 0).tobytes())
        if key == self._factor_key:
            return self._factor
        A, S, L = np.flatnonzero(active), np.flatnonzero(stick), np.flatnonzero(slide)
        Bn = self.Br[A]
        column = Bn.T.tocsr()
        if len(L):
            where = np.searchsorted(A, L)  # each slipping row's column among the contact ones
            pick = sp.csr_matrix((np.ones(len(L)), (np.arange(len(L)), where)),
                                 shape=(len(L), len(A)))
            column = column + self.Btr[L].T @ sp.diags(-self.mu[L] * sigma[L]) @ pick
        Bt = self.Btr[S]
        M = sp.bmat([[self.K, column, Bt.T], [Bn, None, None], [Bt, None, None]],
                    format="csc")
        t0 = time.perf_counter()
        try:
            with memory_guard("factorizing the global system (lagrange, friction)"):
                # not symmetric: LU (PARDISO's saddle-point mode reads one triangle of a
                # symmetric matrix: with slipping nodes its solves were off by 1e-3)
                self._factor = _Refined(M, factorize(
                    M, self.backend, spd=False, symmetric=False,
                    what="the lagrange global system with friction"))
        except RuntimeError as exc:
            if isinstance(exc, AnalysisError):
                raise SingularSystem(str(exc)) from None
            raise SingularSystem(
                f"the global matrix of the lagrange method with friction is singular with "
                f"{len(A)} nodes in contact, {len(S)} sticking ({exc})") from None
        self.timings["factorize_s"] += time.perf_counter() - t0
        self.factorizations += 1
        self._factor_key = key
        return self._factor

    def solve_frictional(self, load_factor: float, state: BaselineState):
        """One step of Lagrange multipliers with Coulomb friction (node-to-segment, small
        displacements): the contact, stick and slip sets iterated until none changes, each set
        one factorization of :meth:`_factorized_frictional`, the classical active-set strategy.
        A node in contact sticks (its relative tangential displacement held at its anchor,
        the value at the last converged step) until its tangential force exceeds mu_s times
        its normal one; it then slips with the force mu times the normal one opposing the
        slip, until its slip turns back. Returns (q, Lambda_n, Lambda_t, g, w, active,
        sliding, sigma, history)."""
        settings = self.model.contact
        f = self.at(load_factor, self.f1)
        gp = self.c.g0 + self.at(load_factor, self.g_prescribed)
        wp = self.at(load_factor, self.w_prescribed)
        live = self.t_live
        anchor = state.anchor
        active = self._seeded(state.active, gp)
        sliding = state.sliding & active & live
        sigma = np.where(state.shear != 0, -np.sign(state.shear), 1.0)
        seen = set()
        history: list[IterationRecord] = []
        nq = self.nq
        for it in range(1, settings.max_iterations + 1):
            stick, slide = active & live & ~sliding, active & live & sliding
            A, S, L = np.flatnonzero(active), np.flatnonzero(stick), np.flatnonzero(slide)
            factor = self._factorized_frictional(active, stick, slide, sigma)
            t0 = time.perf_counter()
            sol = factor.solve(np.r_[f, -gp[A], anchor[S] - wp[S]])
            self.timings["solve_s"] += time.perf_counter() - t0
            q = sol[:nq]
            if not np.all(np.isfinite(q)):
                raise SingularSystem("the lagrange method's linear solve with friction gave "
                                     "non-finite displacements: the global matrix is singular")
            Lam, Lt = np.zeros(len(gp)), np.zeros(len(gp))
            Lam[A] = -sol[nq:nq + len(A)]
            Lt[S] = -sol[nq + len(A):]
            Lt[L] = -self.mu[L] * sigma[L] * Lam[L]
            g = gp + self.Br @ q
            w = wp + self.Btr @ q
            dw = w - anchor
            scale = float(np.abs(Lam).max(initial=0.0))
            leave = active & (Lam < -FORCE_ROUNDOFF * scale)
            new_active = self._seeded((active & ~leave) | (~active & (g < -self.gap_tolerance)),
                                      gp)
            over = stick & (np.abs(Lt) > self.mu_static * Lam + FORCE_ROUNDOFF * scale)
            back = slide & (sigma * dw < -self.gap_tolerance)
            new_sigma = np.where(over, -np.sign(Lt), sigma)
            new_sliding = (sliding | over) & ~back & new_active
            penetration = float(np.maximum(-g, 0.0).max(initial=0.0))
            history.append(IterationRecord(it, penetration, 0.0, int((Lam > 0).sum()),
                                           int(leave.sum())))
            if (np.array_equal(new_active, active) and np.array_equal(new_sliding, sliding)
                    and np.array_equal(new_sigma[new_sliding], sigma[new_sliding])):
                return q, Lam, Lt, g, w, active, sliding & active, sigma, history
            key = (new_active.tobytes(), new_sliding.tobytes(), (new_sigma > 0).tobytes())
            if key in seen:
                changed = np.flatnonzero((new_active != active) | (new_sliding != sliding))
                raise ActiveSetNotSettled(
                    "the lagrange method's contact and stick/slip sets cycle: they came back to "
                    f"sets they had left after {it} linear solves (nodes switching now: "
                    f"{self._name_rows(changed)})")
            seen.add(key)
            active, sliding, sigma = new_active, new_sliding, new_sigma
        raise ActiveSetNotSettled(
            f"the lagrange method's contact and stick/slip sets did not settle in "
            f"{settings.max_iterations} linear solves (contact.max_iterations)")

    def _name_rows(self, rows: np.ndarray, limit: int = 8) -> str:
        """'cylinder 12, 13' for constraint rows (slave body, point number)."""
        names = [f"{self.model.bodies[self.c.slave[r]].name} "
                 f"{int(self.surfaces[self.c.slave[r]].nodes[self.c.node[r]])}"
                 for r in rows[:limit]]
        return ", ".join(names) + (f" and {len(rows) - limit} more" if len(rows) > limit else "")

    # -- results ----------------------------------------------------------------------------------

    def fields_of(self, load_factor: float, q: np.ndarray, Lam: np.ndarray, g: np.ndarray,
                  friction: dict | None = None):
        """Per body: the :class:`~vfem.bodies.results.BodyStepResult` and the contact forces on its
        candidate nodes (nc, 2). ``friction`` (frictional lagrange): per row the tangential
        force ``shear``, the step's slip ``increment``, the ``accumulated`` slip and the
        ``status`` (0 free, 1 stick, 2 slip), which add the friction's fields."""
        from ...bodies.results import BodyStepResult, add_reactions

        U = self.T @ q + self.at(load_factor, self.U_prescribed)
        f_slave = self.c.B_slave.T @ Lam
        f_master = self.c.B_master.T @ Lam
        if friction is not None:
            f_tangential = (self.c.T_slave.T @ friction["shear"]
                            + self.c.T_master.T @ friction["shear"])
            f_slave = f_slave + self.c.T_slave.T @ friction["shear"]
            f_master = f_master + self.c.T_master.T @ friction["shear"]
        out, forces = {}, []
        for i, (s, off) in enumerate(zip(self.surfaces, self.offsets)):
            b = s.body
            nv = b.npoints
            part = slice(off, off + b.ndofs)
            force = (f_slave[part] + f_master[part]).reshape(-1, s.dim)
            cand = s.nodes[: s.nc]
            mine = self.c.slave == i
            pressure = np.zeros(nv)
            # slave nodes: the normal force along the master's normal / tributary length
            pressure[cand] = (np.bincount(self.c.node[mine], Lam[mine], minlength=s.nc)
                              / s.tributary)
            # master nodes: the normal component of the forces spread on them / tributary
            fm = f_master[part].reshape(-1, s.dim)[cand]
            p_master = np.zeros(s.nc)
            if s.nc and len(s.facets):
                p_master = -np.einsum("ij,ij->i", fm, s.node_normals()) / s.tributary
            pressure[cand] += p_master
            status = np.zeros(nv, dtype=int)
            carried = np.bincount(self.c.node[mine], Lam[mine] > 0, minlength=s.nc) > 0
            status[cand] = carried | (np.abs(fm).sum(axis=1) > 0)
            pen = np.zeros(nv)
            if mine.any():
                depth = np.full(s.nc, -np.inf)
                np.maximum.at(depth, self.c.node[mine], -g[mine])
                pen[cand] = np.where(np.isfinite(depth), depth, 0.0)
            r = BodyStepResult(U[part].reshape(-1, s.dim), force, pressure, status, pen)
            if friction is not None:
                self._friction_fields(r, i, s, mine, friction, f_tangential[part])
            out[b.name] = add_reactions(b, r, load_factor)
            forces.append(force[cand])
        return out, forces

    def _friction_fields(self, r, i: int, s: ContactSurface, mine: np.ndarray, friction: dict,
                         f_tangential: np.ndarray) -> None:
        """The friction's fields of body i (its slave rows ``mine``): the tangential traction
        on it (force over tributary length, along the master's tangent), slip increment,
        accumulated slip and status at its slave nodes (-1 elsewhere), and the nodal forces
        of the tangential multipliers on every node."""
        nv = s.body.npoints
        r.contact_shear, r.slip_increment = np.zeros((nv, s.dim)), np.zeros(nv)
        r.accumulated_slip, r.friction_status = np.zeros(nv), np.full(nv, -1)
        r.friction_force = f_tangential.reshape(-1, s.dim).copy()
        if not mine.any():
            return
        rows = np.flatnonzero(mine)
        points = s.nodes[self.c.node[rows]]
        n = self.c.normal[rows]
        tangent = np.column_stack([-n[:, 1], n[:, 0]])
        r.contact_shear[points] = ((friction["shear"][rows] / s.tributary[self.c.node[rows]])
                                   [:, None] * tangent)
        r.slip_increment[points] = friction["increment"][rows]
        r.accumulated_slip[points] = friction["accumulated"][rows]
        r.friction_status[points] = friction["status"][rows]

    # -- the steps --------------------------------------------------------------------------------

    def new_state(self) -> BaselineState:
        m = len(self.c.node)
        return BaselineState(0.0, 0.0, [np.zeros((s.nc, s.dim)) for s in self.surfaces],
                             [np.zeros(s.nc, dtype=bool) for s in self.surfaces], 0.0,
                             np.zeros(m), np.zeros(m, dtype=bool))

    def solve(self, state: BaselineState, on_iteration=None) -> SolveResult:
        """One step: the global solve at ``state``'s load factor from its active set (and
        multipliers), which becomes the new state (modified in place); the result carries the
        full-mesh fields of the global solution. Raises :class:`~vfem.errors.SingularSystem`
        or :class:`~vfem.errors.ActiveSetNotSettled` when the step cannot be solved."""
        m = len(self.c.node)
        if len(state.pressures) != m or len(state.active) != m:  # not this model's rows
            state.pressures, state.active = np.zeros(m), np.zeros(m, dtype=bool)
        lf = state.load_factor
        before = self.factorizations
        if self.frictional:
            if len(state.anchor) != m:
                state.anchor, state.shear = np.zeros(m), np.zeros(m)
                state.slip, state.sliding = np.zeros(m), np.zeros(m, dtype=bool)
            q, Lam, Lt, g, w, active, sliding, _, history = self.solve_frictional(lf, state)
            increment = np.where(active, w - state.anchor, 0.0)
            state.slip = state.slip + np.abs(increment)
            state.anchor, state.shear, state.sliding = w, Lt, sliding
            status = np.where(active & (Lam > 0), np.where(sliding, 2, 1), 0)
            fields, forces = self.fields_of(lf, q, Lam, g, {
                "shear": Lt, "increment": increment, "accumulated": state.slip,
                "status": status})
            lam = Lam / self.c.weight
        else:
            q, Lam, g, active, lam, history = self.solve_step(lf, state.active,
                                                              state.pressures)
            fields, forces = self.fields_of(lf, q, Lam, g)
        state.platen_displacement = float(q[-1]) if self.platen_body is not None else 0.0
        state.forces[:] = forces
        state.pressures, state.active = lam, active.copy()
        log.info("load factor %.4g: %s converged in %d linear solves (%d factorizations), %d "
                 "nodes in contact, largest penetration %.3g", lf, self.method, len(history),
                 self.factorizations - before, int(active.sum()), history[-1].max_penetration)
        return SolveResult(True, len(history), history, [], fields=fields)

    def fields(self, state: BaselineState, result: SolveResult):
        """The full-mesh results of the step's global solution (:meth:`fields_of`)."""
        return result.fields
