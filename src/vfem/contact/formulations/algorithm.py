"""The contact iteration of the virtual finite element method (thesis §4.3–4.5, §5.6).

Given the bodies' contact surfaces and a state (load factor, platen displacement, the contact
forces each body carries), one iteration is

    detect  -> pair every candidate node with its virtual node on the opposing surface
               (current configuration): penetration, normal, own and virtual stiffness,
               own and virtual (re-integrated) contact force;
    check   -> largest penetration, largest equilibrium error, nodes in tension;
    correct -> tension release; equilibrium correction (eq. 4.2.7); compatibility correction
               (eq. 4.2.4, turned into forces by prescribing the normal displacements through the
               flexibility, §4.5.2); relaxation;

and the corrections of all bodies are applied at once (the 1D shares assume both sides move
together). Every body is treated alike: each computes corrections for its own nodes only, from its
pairing with the others' virtual nodes.

A force-controlled platen (a rigid boundary whose total force is scheduled, used to load a body
that only contact holds, like the Hertz cylinder) is one more unknown of the compatibility stage
of its body: the platen displacement is solved together with the nodal forces that realise the
prescribed normal displacements, so that the platen's reaction meets its force in every iteration.
The platen never moves ahead of the contact, so no node is driven through another body's rind.
"""

from __future__ import annotations

import logging

import numpy as np

from ...errors import RindViolation
from ..capabilities import Capabilities
from ..geometry import ContactPairs, traction_from_forces
from ..laws import (
    compatibility_displacement,
    equilibrium_force,
    relaxation,
    release_tension,
)
from ..search import outward_normals, project_points
from ..solvers import Check, bordered_solve, iterate
from ..state import (
    ContactState,
    IterationRecord,
    Pairing,
    SolveResult,
    closing_motion,
)
from .group import SurfaceGroup

log = logging.getLogger(__name__)


class VirtualElementContact:
    """Frictionless contact between any number of linear bodies by the virtual element method:
    the thesis's plain reading (every node of both bodies checked for both conditions)."""

    capabilities = Capabilities(
        name="thesis", orders=(1,), kinematics=("small",), dimensions=(2,),
        invariants="recorded", reads_rind=True)

    def __init__(self, surfaces, pairs: ContactPairs, settings, backend: str | None = None,
                 executor=None):
        #: the bodies' surfaces, the platen and the full-mesh fields (its data by name too)
        self.group = SurfaceGroup(surfaces, pairs, settings, backend, executor=executor)
        self.group.adopt(self)

    def new_state(self, load_factor: float = 0.0, platen_displacement: float = 0.0
                  ) -> ContactState:
        """No contact force on any body."""
        return self.group.new_state(ContactState, load_factor, platen_displacement)

    def positions(self, state: ContactState) -> list[np.ndarray]:
        """Current coordinates of every body's condensed nodes (the bodies' linear response)."""
        return self.group.positions(state)

    def fields(self, state: ContactState, result: SolveResult) -> dict:
        """Full-mesh results of a converged state, per body."""
        return self.group.fields(state, result)

    def _platen_motion(self, nodes: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """Normal displacement of candidate nodes of the platen body per unit platen motion."""
        return np.einsum("ij,ij->i", self.platen_motion[self.platen_body][nodes], normal)

    # -- detect ---------------------------------------------------------------------------------

    def detect(self, state: ContactState) -> list[Pairing]:
        """Pair every candidate node with its virtual node in the current configuration."""
        x = self.positions(state)
        tractions = [traction_from_forces(s, F) for s, F in zip(self.surfaces, state.forces)]
        return [self._pair(i, x, state, tractions) for i in range(len(self.surfaces))]

    def _opposing(self, i: int, x: list[np.ndarray]):
        """The candidate facets of all bodies body i may touch, in current position."""
        owners, local, A, B = [], [], [], []
        for j in self.group.opponents(i):
            a, b = self.surfaces[j].segments(x[j])
            owners.append(np.full(len(a), j))
            local.append(np.arange(len(a)))
            A.append(a)
            B.append(b)
        if not A:
            return None
        return (np.concatenate(owners), np.concatenate(local), np.concatenate(A),
                np.concatenate(B))

    def _pair(self, i: int, x: list[np.ndarray], state: ContactState,
              tractions: list[np.ndarray]) -> Pairing:
        """Virtual node, penetration, stiffnesses and forces of every candidate node of body i."""
        s = self.surfaces[i]
        nc = s.nc
        F = state.forces[i]
        opp = self._opposing(i, x)
        if opp is None or nc == 0:  # nothing this body may touch
            return Pairing(other=np.full(nc, -1), facet=np.zeros(nc, int), t=np.zeros(nc),
                           normal=np.zeros((nc, 2)), penetration=np.full(nc, -np.inf),
                           embedded=np.zeros(nc, bool), stiffness=np.zeros(nc),
                           virtual_stiffness=np.zeros(nc), force=np.zeros(nc),
                           virtual_force=np.zeros(nc), participating=np.zeros(nc, bool))
        owners, local, A, B = opp
        pts = x[i][:nc]
        seg, t, _ = project_points(pts, A, B)
        normals = outward_normals(A, B)[seg]
        closest = A[seg] + t[:, None] * (B[seg] - A[seg])
        penetration = np.einsum("ij,ij->i", closest - pts, normals)
        other = owners[seg]
        facet = local[seg]

        # Point location in the opposing rind, for the nodes that may be inside at all.
        embedded = np.zeros(nc, dtype=bool)
        maybe = penetration > -self.penetration_tolerance
        for j in np.unique(other[maybe]):
            sel = np.flatnonzero(maybe & (other == j))
            embedded[sel] = self.surfaces[j].locate(x[j], pts[sel]) >= 0
        interior = (t > 1e-9) & (t < 1 - 1e-9)
        deep = (penetration > self.penetration_tolerance) & interior & ~embedded
        if deep.any():
            k = int(np.flatnonzero(deep)[0])
            j = int(other[k])
            raise RindViolation(
                f"node {int(s.nodes[k])} of body {s.body.name!r} went {penetration[k]:.3g} deep "
                f"into body {self.surfaces[j].body.name!r}, past its outer layer of elements: "
                "the step is too large")

        stiffness = s.normal_stiffness(np.arange(nc), normals)
        virtual_stiffness = np.zeros(nc)
        for j in np.unique(other):
            sel = np.flatnonzero(other == j)
            sj = self.surfaces[j]
            ends = sj.facets[facet[sel]]
            k0 = sj.normal_stiffness(ends[:, 0], normals[sel])
            k1 = sj.normal_stiffness(ends[:, 1], normals[sel])
            virtual_stiffness[sel] = (1 - t[sel]) * k0 + t[sel] * k1
        Fv = self._virtual_forces(i, x, tractions)
        force = np.einsum("ij,ij->i", F, normals)
        virtual_force = -np.einsum("ij,ij->i", Fv, normals)
        # A node in contact (§4.3.2): embedded in another body, or carrying compressive force.
        participating = embedded | (force > 0)
        return Pairing(other=other, facet=facet, t=t, normal=normals, penetration=penetration,
                       embedded=embedded, stiffness=stiffness,
                       virtual_stiffness=virtual_stiffness, force=force,
                       virtual_force=virtual_force, participating=participating)

    def _virtual_forces(self, i: int, x: list[np.ndarray], tractions: list[np.ndarray]
                        ) -> np.ndarray:
        """Opposing tractions integrated over body i's virtual elements (§4.5.1).

        The virtual element opposite a facet of body i has the facet's own shape functions and
        quadrature; each quadrature point is projected onto the opposing surface to read the
        opposing traction there. Returns, per candidate node of i, the force the opposing body
        carries there (as a force on the opposing body).
        """
        s = self.surfaces[i]
        out = np.zeros((s.nc, 2))
        opp = self._opposing(i, x)
        if opp is None or len(s.facets) == 0:
            return out
        owners, local, A, B = opp
        xa, xb = s.segments(x[i])
        # Raise the order where own facets are much longer than the opposing ones (§5.6).
        mid = 0.5 * (xa + xb)
        seg, _, _ = project_points(mid, A, B)
        opp_len = np.linalg.norm(B - A, axis=1)
        ratio = float(np.max(s.lengths / np.maximum(opp_len[seg], 1e-300)))
        order = self.settings.quadrature_order
        if ratio > self.settings.size_ratio_limit:
            order = int(np.ceil(order * ratio / self.settings.size_ratio_limit))
        xi, phi, w = s.quadrature(order)
        nq = len(xi)
        pts = (xa[:, None, :] * (1 - xi)[None, :, None]
               + xb[:, None, :] * xi[None, :, None]).reshape(-1, 2)
        seg, t, dist = project_points(pts, A, B)
        own_len = np.repeat(s.lengths, nq)
        near = dist <= np.maximum(own_len, opp_len[seg])
        # A point whose closest opposing point is an end of the opposing contact surface lies
        # beyond that surface: no opposing traction reaches it.
        for j in np.unique(owners[seg]):
            sel = np.flatnonzero(owners[seg] == j)
            ends = self.surfaces[j].facets[local[seg[sel]]]
            free_end = self.surfaces[j].surface_ends
            beyond = (((t[sel] <= 0.0) & free_end[ends[:, 0]])
                      | ((t[sel] >= 1.0) & free_end[ends[:, 1]]))
            near[sel[beyond]] = False
        # Tractions are nominal (per undeformed length of the body that carries them). The same
        # current-configuration stretch of surface is ds/stretch_own of own undeformed length and
        # ds/stretch_opp of the opposing one, so the opposing traction is weighted by
        # stretch_own/stretch_opp: the virtual forces then add up to the opposing total.
        stretch_own = np.repeat(np.linalg.norm(xb - xa, axis=1) / s.lengths, nq)
        trac = np.zeros((len(pts), 2))
        for j in np.unique(owners[seg]):
            sel = np.flatnonzero((owners[seg] == j) & near)
            sj = self.surfaces[j]
            g = local[seg[sel]]
            ends = sj.facets[g]
            qj = tractions[j]
            jac = stretch_own[sel] * sj.lengths[g] / opp_len[seg[sel]]
            # and the opposing body's section's measure at its undeformed point (1, or 2πr on
            # a body of revolution): the opposing force per own undeformed length
            opp0 = (1 - t[sel, None]) * sj.X[ends[:, 0]] + t[sel, None] * sj.X[ends[:, 1]]
            jac = jac * sj.weight(opp0)
            trac[sel] = jac[:, None] * ((1 - t[sel, None]) * qj[ends[:, 0]]
                                        + t[sel, None] * qj[ends[:, 1]])
        trac = trac.reshape(len(s.facets), nq, 2)
        for a in range(2):
            contrib = np.einsum("fq,q,fqk->fk", w, phi[a], trac)
            np.add.at(out, s.facets[:, a], contrib)
        return out

    # -- check ----------------------------------------------------------------------------------

    def errors(self, pairings: list[Pairing]) -> tuple[float, float, float, int, int]:
        """(largest penetration, largest equilibrium error, its tolerance, contact, tension)."""
        pen = eq = 0.0
        scale = 0.0
        contact = tension = 0
        for p in pairings:
            m = p.participating
            scale = max(scale, float(p.force.max(initial=0.0)))
            tension += int((p.force < 0).sum())
            if m.any():
                pen = max(pen, float(np.abs(p.penetration[m]).max()))
                eq = max(eq, float(np.abs(p.equilibrium_error[m]).max()))
                contact += int((p.force[m] > 0).sum())
        return pen, eq, self.settings.equilibrium_tolerance * scale, contact, tension

    # -- correct --------------------------------------------------------------------------------

    def corrections(self, state: ContactState, pairings: list[Pairing], iteration: int
                    ) -> tuple[list[np.ndarray], float]:
        """Corrective nodal forces for every body (and the platen's motion), from one state."""
        cfg = self.settings
        _, _, eq_tol, _, _ = self.errors(pairings)
        omega = relaxation(cfg, iteration)
        out = []
        d_platen = 0.0
        for i, (s, p) in enumerate(zip(self.surfaces, pairings)):
            F = state.forces[i]
            part = p.participating
            # Tension release over several iterations (§5.6). Every node that carries a tensile
            # force is released, whether or not it still touches the other body.
            tension = p.force < 0
            dF, state.released[i] = release_tension(F, tension, state.released[i],
                                                    cfg.release_iterations)
            active = part & ~tension & np.isfinite(p.stiffness)
            n = p.normal
            # Equilibrium (eq. 4.2.7) where the error exceeds its tolerance.
            err = p.equilibrium_error
            eq_on = active & (np.abs(err) > eq_tol)
            d_lam = np.zeros(s.nc)
            d_lam[eq_on] = omega * equilibrium_force(p.stiffness[eq_on],
                                                     p.virtual_stiffness[eq_on], err[eq_on])
            dF += d_lam[:, None] * n
            # Compatibility (eq. 4.2.4): the own share of the penetration as a displacement,
            # turned into forces by prescribing it along the normals with every other candidate
            # dof free (§4.5.2, stage 2): d_lam = (n^T C n)^-1 du over the corrected nodes.
            comp = active & (np.abs(p.penetration) > self.penetration_tolerance)
            if i == self.platen_body:
                dF_comp, d_platen = self._platen_compatibility(state, p, comp, dF, omega)
            else:
                dF_comp = np.zeros_like(F)
                idx = np.flatnonzero(comp)
                if len(idx):
                    du = omega * compatibility_displacement(
                        p.stiffness[idx], p.virtual_stiffness[idx], p.penetration[idx])
                    mu = np.linalg.solve(s.normal_flexibility(idx, n[idx]), du)
                    dF_comp[idx] = mu[:, None] * n[idx]
            out.append(dF + dF_comp)
        return out, d_platen

    def _platen_compatibility(self, state: ContactState, p: Pairing, comp: np.ndarray,
                              dF_other: np.ndarray, omega: float) -> tuple[np.ndarray, float]:
        """Compatibility stage 2 of the platen's body, with the platen force as one more condition.

        Unknowns: the normal forces mu at the corrected nodes and the platen motion d. Conditions:
        each corrected node moves by its share du along its normal,
        ``sum_t (n_s^T C_st n_t) mu_t + a_s d = du_s``, and the platen's reaction reaches its
        force, ``sum_t b_t mu_t + r d = target - R - h.dF_other``, where ``a_s`` is the node's
        normal motion per unit platen motion, ``b_t`` the platen reaction per unit normal force at
        node t and ``r`` the platen's own stiffness (zero for a body only contact holds). While
        the platen is off its force, nodes touching within tolerance are held on the surface too.
        """
        s = self.surfaces[self.platen_body]
        n = p.normal
        dF = np.zeros((s.nc, s.dim))
        b = s.body
        r_platen = b.platen_stiffness
        need = (state.platen_force - self.group.platen_reaction(state)
                - float(s.platen_row @ dF_other.ravel()))
        off = abs(need) > self.group.platen_allowance(state)  # (a zero force: issue 37)
        sel = comp.copy()
        if off:
            sel |= p.participating & (p.force >= 0) & (p.penetration > -self.penetration_tolerance)
        idx = np.flatnonzero(sel)
        if len(idx) == 0:
            if not off:
                return dF, 0.0
            if r_platen != 0.0:
                return dF, need / r_platen
            # Nothing touches: a node's penetration changes by -a per unit platen motion.
            a = self._platen_motion(np.arange(s.nc), n)
            return dF, closing_motion(p.penetration, -a, need)
        du = omega * compatibility_displacement(p.stiffness[idx], p.virtual_stiffness[idx],
                                                p.penetration[idx])
        a = self._platen_motion(idx, n[idx])
        row = s.platen_row.reshape(-1, s.dim)[idx]
        bvec = np.einsum("ij,ij->i", row, n[idx])
        # when the force is already met, keep it met while correcting compatibility
        mu, d = bordered_solve(s.normal_flexibility(idx, n[idx]), a, bvec, r_platen, du,
                               need if off else 0.0)
        dF[idx] = mu[:, None] * n[idx]
        return dF, d

    # -- solve ----------------------------------------------------------------------------------

    def solve(self, state: ContactState, on_iteration=None) -> SolveResult:
        """Iterate from ``state`` (modified in place) until the contact state has converged
        (:func:`~vfem.contact.solvers.iteration.iterate`); ``on_iteration`` gets every record.

        Stopping rules (``ContactSettings.convergence``):

        * always: the physical errors are within tolerance — largest penetration <=
          penetration tolerance, largest equilibrium error <= equilibrium tolerance, no node in
          tension;
        * ``"stationary"`` (default): or the iteration has reached its fixed point — the net
          corrective force on every node is within the equilibrium tolerance and the largest
          displacement it causes within the penetration tolerance, with no node in tension. The
          thesis's reading checks both bodies against both conditions, which can leave the two
          corrections cancelling each other (vfem-method §6); the residual errors are reported
          in the history;
        * ``"thesis"``: or the corrective forces of an iteration are below ``thesis_fraction``
          of the largest of the solve, or the displacements they cause below that fraction of
          the largest (thesis §5.6); that last increment is not applied.
        """
        cfg = self.settings
        tol = self.penetration_tolerance
        largest = {"df": 0.0, "du": 0.0}  # the largest corrections of the solve so far

        def check(k: int) -> Check:
            pairings = self.detect(state)
            pen, eq, eq_tol, contact, tension = self.errors(pairings)
            platen_ok = self.group.platen_met(state)
            rec = IterationRecord(k, pen, eq, contact, tension,
                                  platen_error=self.group.platen_error(state))
            return Check(
                rec, pen <= tol and eq <= eq_tol and tension == 0 and platen_ok,
                lambda: [(s.body.name, s.nodes[: s.nc], p.participating & (p.force > 0))
                         for s, p in zip(self.surfaces, pairings)],
                max(pen, eq), lambda: pairings,
                lambda: (f"no convergence in {cfg.max_iterations} iterations "
                         f"(penetration {pen:.3g}, equilibrium error {eq:.3g})"),
                extra=(pairings, eq_tol, platen_ok))

        def correct(k: int, c: Check):
            pairings, eq_tol, platen_ok = c.extra
            rec = c.record
            pen, eq, tension = rec.max_penetration, rec.max_equilibrium_error, rec.tension_nodes
            dF, d_platen = self.corrections(state, pairings, k)
            dU = [(s.C @ d.ravel()).reshape(-1, s.dim) for s, d in zip(self.surfaces, dF)]
            if d_platen:
                dU[self.platen_body] += d_platen * self.platen_motion[self.platen_body]
            df = float(np.sqrt(sum((d**2).sum() for d in dF)))
            du = float(np.sqrt(sum((d**2).sum() for d in dU)))
            rec.force_correction, rec.displacement_correction = df, du
            if cfg.convergence == "stationary" and tension == 0 and platen_ok:
                node_df = max(float(np.linalg.norm(d, axis=1).max(initial=0.0)) for d in dF)
                node_du = max(float(np.linalg.norm(d, axis=1).max(initial=0.0)) for d in dU)
                if node_df <= eq_tol and node_du <= tol:
                    residual = pen > tol or eq > eq_tol
                    if residual:
                        log.info(
                            "contact stopped at a fixed point of the iteration with residual "
                            "penetration %.3g (tolerance %.3g) and equilibrium error %.3g "
                            "(tolerance %.3g): the corrections cancel each other there "
                            "(docs/method.md §5)", pen, tol, eq, eq_tol)
                    return True, residual
            if cfg.convergence == "thesis" and k > 0 and platen_ok and (
                    df <= cfg.thesis_fraction * largest["df"]
                    or du <= cfg.thesis_fraction * largest["du"]):
                return True, False
            largest["df"], largest["du"] = max(largest["df"], df), max(largest["du"], du)
            for F, d in zip(state.forces, dF):
                F += d
            state.platen_displacement += d_platen
            log.debug("iteration %d: penetration %.3g, equilibrium error %.3g (tol %.3g), "
                      "%d in contact, %d in tension", k, pen, eq, eq_tol, rec.contact_nodes,
                      tension)
            return None

        return iterate(cfg, check, correct, on_iteration)
