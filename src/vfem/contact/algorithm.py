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
from dataclasses import dataclass, field

import numpy as np

from ..errors import RindViolation
from .corrections import compatibility_displacement, equilibrium_force
from .search import outward_normals, project_points
from .settings import ContactSettings
from .surface import ContactSurface

log = logging.getLogger(__name__)


@dataclass
class Pairing:
    """The pairs (own node, virtual node) of one body; arrays over its candidate nodes (nc).

    Forces are normal components in the pair's frame (see ``corrections``): positive is
    compressive. ``normal`` is the outward normal of the opposing facet at the virtual node.
    """

    other: np.ndarray  # (nc,) opposing body, -1 where none
    facet: np.ndarray  # (nc,) facet of the opposing body holding the virtual node
    t: np.ndarray  # (nc,) local coordinate of the virtual node on that facet
    normal: np.ndarray  # (nc, 2)
    penetration: np.ndarray  # (nc,) > 0 inside the other body
    embedded: np.ndarray  # (nc,) bool, located in the other body's rind
    stiffness: np.ndarray  # (nc,) own Castigliano normal stiffness
    virtual_stiffness: np.ndarray  # (nc,) opposing stiffness interpolated at the virtual node
    force: np.ndarray  # (nc,) own compressive normal force
    virtual_force: np.ndarray  # (nc,) opposing compressive force re-integrated on own elements
    participating: np.ndarray  # (nc,) bool: embedded or carrying compressive force
    #: (nc,) the formulation's normal traction at the node (nominal), where it has one; None:
    #: the results read nodal force over tributary length
    pressure: np.ndarray | None = None

    @property
    def equilibrium_error(self) -> np.ndarray:
        return self.force - self.virtual_force


@dataclass
class ContactState:
    """What the contact algorithm changes: the nodal contact forces on each body's candidates."""

    load_factor: float
    platen_displacement: float
    forces: list[np.ndarray]  # per body (nc, 2), the force the other bodies apply on it
    released: list[np.ndarray] = field(default_factory=list)  # nodes released last iteration
    platen_force: float = 0.0  # the force the platen must apply (Platen.force_at)
    multipliers: dict = field(default_factory=dict)  # per-pair traction values (paired)

    def copy(self) -> ContactState:
        return ContactState(self.load_factor, self.platen_displacement,
                            [f.copy() for f in self.forces], [r.copy() for r in self.released],
                            self.platen_force,
                            {k: v.copy() for k, v in self.multipliers.items()})


@dataclass
class IterationRecord:
    """The errors seen by one check and the corrections that followed (history of a solve)."""

    iteration: int
    max_penetration: float
    max_equilibrium_error: float
    contact_nodes: int
    tension_nodes: int
    force_correction: float = 0.0
    displacement_correction: float = 0.0
    platen_error: float = 0.0  # platen reaction minus its scheduled force


@dataclass
class SolveResult:
    converged: bool
    iterations: int
    history: list[IterationRecord]
    pairings: list[Pairing]
    message: str = ""
    fixed_point: bool = False  # stopped where corrections cancel, errors above tolerance


class CycleWatch:
    """Notices a contact iteration that cycles, so the step is cut instead of iterated to its
    limit: the same contact set coming back after others (not merely staying the same, which is
    how an iteration converges) without the error having fallen since it was last seen there.

    Call once per iteration with the in-contact masks; returns a message naming the nodes that
    keep switching once that has happened ``limit`` times, else None.
    """

    def __init__(self, limit: int = 3):
        self.limit = limit
        self.seen: dict[bytes, float] = {}  # contact set -> the smallest error seen with it
        self.last: bytes | None = None
        self.last_sets: list[np.ndarray] | None = None
        self.flipping: list[set[int]] = []
        self.count = 0

    def __call__(self, sets: list[tuple[str, np.ndarray, np.ndarray]], error: float,
                 iteration: int) -> str | None:
        """``sets``: per side (body name, its node numbers, bool in-contact mask)."""
        masks = [np.asarray(m, dtype=bool) for _, _, m in sets]
        key = b"|".join(np.packbits(m).tobytes() + len(m).to_bytes(4, "little") for m in masks)
        if self.last_sets is not None and key != self.last:
            if not self.flipping:
                self.flipping = [set() for _ in sets]
            for k, (m0, m1) in enumerate(zip(self.last_sets, masks)):
                self.flipping[k].update(np.flatnonzero(m0 != m1).tolist())
            if key in self.seen and error >= self.seen[key]:
                self.count += 1
        self.seen[key] = min(error, self.seen.get(key, np.inf))
        self.last, self.last_sets = key, masks
        if self.count < self.limit:
            return None
        names = []
        for (body, nodes, _), flips in zip(sets, self.flipping):
            if flips:
                listed = ", ".join(str(int(nodes[i])) for i in sorted(flips)[:8])
                more = f" and {len(flips) - 8} more" if len(flips) > 8 else ""
                names.append(f"node{'s' if len(flips) > 1 else ''} {listed}{more} of body "
                             f"{body!r}")
        return (f"the contact iteration cycles: {'; '.join(names) or 'some nodes'} keep "
                f"switching in and out of contact while the error stays at {error:.3g} "
                f"(iteration {iteration})")


def closing_motion(penetration: np.ndarray, rate: np.ndarray, need: float) -> float:
    """The platen motion that just closes the smallest gap when nothing touches yet.

    ``rate`` is each node's change of penetration per unit platen motion; the platen moves the
    way its missing force points (the sign of ``need``). Zero when no gap can be closed so.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(np.isfinite(penetration) & (rate != 0), -penetration / rate, np.nan)
    ok = np.isfinite(d) & (np.sign(d) == np.sign(need))
    return float(d[ok][np.argmin(np.abs(d[ok]))]) if ok.any() else 0.0


class VirtualElementContact:
    """Frictionless contact between any number of linear bodies by the virtual element method."""

    def __init__(self, surfaces: list[ContactSurface], pairs: set[frozenset[int]],
                 settings: ContactSettings):
        self.surfaces = surfaces
        self.pairs = pairs
        self.settings = settings
        lengths = np.concatenate([s.lengths for s in surfaces if len(s.lengths)] or [[1.0]])
        self.penetration_tolerance = (settings.penetration_tolerance
                                      if settings.penetration_tolerance is not None
                                      else 1e-5 * float(lengths.min()))
        platens = [i for i, s in enumerate(surfaces) if s.body.platen is not None]
        self.platen_body = platens[0] if platens else None
        # each body's candidate-node motion per unit platen motion (zero but for the platen's)
        self.platen_motion = [s.body.u_platen[s.candidate_dofs].reshape(-1, 2) for s in surfaces]

    # -- state ----------------------------------------------------------------------------------

    def new_state(self, load_factor: float = 0.0, platen_displacement: float = 0.0
                  ) -> ContactState:
        return ContactState(load_factor, platen_displacement,
                            [np.zeros((s.nc, 2)) for s in self.surfaces],
                            [np.zeros(s.nc, dtype=bool) for s in self.surfaces])

    def positions(self, state: ContactState) -> list[np.ndarray]:
        """Current coordinates of every body's tracked nodes: X + u(load, platen, forces)."""
        out = []
        for s, F in zip(self.surfaces, state.forces):
            b = s.body
            dofs = s.tracked_dofs
            u = (b.load_displacement(state.load_factor, dofs) + state.platen_displacement
                 * b.u_platen[dofs] + s.G @ F.ravel())
            out.append(s.X + u.reshape(-1, 2))
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

    def platen_met(self, state: ContactState) -> bool:
        """Whether the platen's reaction is on its scheduled force (always, without a platen)."""
        if self.platen_body is None:
            return True
        error = self.platen_reaction(state) - state.platen_force
        return abs(error) <= self.settings.platen_tolerance * max(abs(state.platen_force), 1e-300)

    def _platen_motion(self, nodes: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """Normal displacement of candidate nodes of the platen body per unit platen motion."""
        return np.einsum("ij,ij->i", self.platen_motion[self.platen_body][nodes], normal)

    def opponents(self, i: int) -> list[int]:
        return [j for j in range(len(self.surfaces))
                if j != i and frozenset((i, j)) in self.pairs and len(self.surfaces[j].facets)]

    # -- detect ---------------------------------------------------------------------------------

    def detect(self, state: ContactState) -> list[Pairing]:
        """Pair every candidate node with its virtual node in the current configuration."""
        x = self.positions(state)
        tractions = [self._traction(s, F) for s, F in zip(self.surfaces, state.forces)]
        return [self._pair(i, x, state, tractions) for i in range(len(self.surfaces))]

    def _opposing(self, i: int, x: list[np.ndarray]):
        """The candidate facets of all bodies body i may touch, in current position."""
        owners, local, A, B = [], [], [], []
        for j in self.opponents(i):
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

    def _traction(self, s: ContactSurface, F: np.ndarray) -> np.ndarray:
        """Redistribute nodal contact forces into a continuous traction: N* q = Q (§4.4).

        Facets none of whose nodes carry force are left out of N* (the thesis's N*), so the
        traction may jump at the edge of contact; nodes on no loaded facet get q = 0.
        """
        q = np.zeros_like(F)
        loaded = np.abs(F).sum(axis=1) > 0
        if not loaded.any():
            return q
        facet_on = loaded[s.facets].any(axis=1).astype(float)
        N = s.mass_matrix(facet_on)
        nodes = np.unique(s.facets[facet_on > 0])
        Nd = N[nodes][:, nodes].toarray()
        q[nodes] = np.linalg.solve(Nd, F[nodes])
        return q

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
        omega = cfg.first_relaxation if iteration < cfg.relaxed_iterations else cfg.relaxation
        out = []
        d_platen = 0.0
        for i, (s, p) in enumerate(zip(self.surfaces, pairings)):
            F = state.forces[i]
            dF = np.zeros_like(F)
            part = p.participating
            # Tension release over several iterations (§5.6); a node released in the previous
            # iteration and still in tension gives up the rest. Every node that carries a tensile
            # force is released, whether or not it still touches the other body.
            tension = p.force < 0
            frac = np.where(state.released[i], 1.0, 1.0 / cfg.release_iterations)
            dF[tension] -= frac[tension, None] * F[tension]
            state.released[i] = tension & (frac < 1.0)
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
                    mu = np.linalg.solve(self._normal_flexibility(s, idx, n[idx]), du)
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
        dF = np.zeros((s.nc, 2))
        b = s.body
        r_platen = b.platen_stiffness
        need = (state.platen_force - self.platen_reaction(state)
                - float(s.platen_row @ dF_other.ravel()))
        off = abs(need) > self.settings.platen_tolerance * max(abs(state.platen_force), 1e-300)
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
        row = s.platen_row.reshape(-1, 2)[idx]
        bvec = np.einsum("ij,ij->i", row, n[idx])
        m = len(idx)
        A = np.zeros((m + 1, m + 1))
        A[:m, :m] = self._normal_flexibility(s, idx, n[idx])
        A[:m, m] = a
        A[m, :m] = bvec
        A[m, m] = r_platen
        # when the force is already met, keep it met while correcting compatibility
        rhs = np.concatenate([du, [need if off else 0.0]])
        sol = np.linalg.lstsq(A, rhs, rcond=None)[0]
        dF[idx] = sol[:m, None] * n[idx]
        return dF, float(sol[m])

    @staticmethod
    def _normal_flexibility(s: ContactSurface, nodes: np.ndarray, n: np.ndarray) -> np.ndarray:
        """n_s^T C_st n_t over the given candidate nodes."""
        C = s.C
        ix, iy = 2 * nodes, 2 * nodes + 1
        return (n[:, 0, None] * C[np.ix_(ix, ix)] * n[None, :, 0]
                + n[:, 0, None] * C[np.ix_(ix, iy)] * n[None, :, 1]
                + n[:, 1, None] * C[np.ix_(iy, ix)] * n[None, :, 0]
                + n[:, 1, None] * C[np.ix_(iy, iy)] * n[None, :, 1])

    # -- solve ----------------------------------------------------------------------------------

    #: called with each iteration's record as it is made (progress displays)
    on_iteration = None

    def solve(self, state: ContactState) -> SolveResult:
        """Iterate from ``state`` (modified in place) until the contact state has converged.

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
        history: list[IterationRecord] = []
        max_df = max_du = 0.0
        pen = eq = 0.0
        watch = CycleWatch()
        for k in range(cfg.max_iterations + 1):
            pairings = self.detect(state)
            pen, eq, eq_tol, contact, tension = self.errors(pairings)
            platen_error = self.platen_reaction(state) - state.platen_force
            rec = IterationRecord(k, pen, eq, contact, tension, platen_error=platen_error)
            history.append(rec)
            if self.on_iteration is not None:
                self.on_iteration(rec)
            platen_ok = self.platen_met(state)
            if pen <= self.penetration_tolerance and eq <= eq_tol and tension == 0 and platen_ok:
                return SolveResult(True, k, history, pairings)
            if k == cfg.max_iterations:
                break
            sets = [(s.body.name, s.nodes[: s.nc], p.participating & (p.force > 0))
                    for s, p in zip(self.surfaces, pairings)]
            cycling = watch(sets, max(pen, eq), k)
            if cycling:
                return SolveResult(False, k, history, pairings, cycling)
            dF, d_platen = self.corrections(state, pairings, k)
            dU = [(s.C @ d.ravel()).reshape(-1, 2) for s, d in zip(self.surfaces, dF)]
            if d_platen:
                dU[self.platen_body] += d_platen * self.platen_motion[self.platen_body]
            df = float(np.sqrt(sum((d**2).sum() for d in dF)))
            du = float(np.sqrt(sum((d**2).sum() for d in dU)))
            rec.force_correction, rec.displacement_correction = df, du
            if cfg.convergence == "stationary" and tension == 0 and platen_ok:
                node_df = max(float(np.linalg.norm(d, axis=1).max(initial=0.0)) for d in dF)
                node_du = max(float(np.linalg.norm(d, axis=1).max(initial=0.0)) for d in dU)
                if node_df <= eq_tol and node_du <= self.penetration_tolerance:
                    residual = pen > self.penetration_tolerance or eq > eq_tol
                    if residual:
                        log.info(
                            "contact stopped at a fixed point of the iteration with residual "
                            "penetration %.3g (tolerance %.3g) and equilibrium error %.3g "
                            "(tolerance %.3g): the corrections cancel each other there "
                            "(docs/method.md §5)", pen, self.penetration_tolerance, eq, eq_tol)
                    return SolveResult(True, k, history, pairings, fixed_point=residual)
            if cfg.convergence == "thesis" and k > 0 and platen_ok and (
                    df <= cfg.thesis_fraction * max_df or du <= cfg.thesis_fraction * max_du):
                return SolveResult(True, k, history, pairings)
            max_df, max_du = max(max_df, df), max(max_du, du)
            for F, d in zip(state.forces, dF):
                F += d
            state.platen_displacement += d_platen
            log.debug("iteration %d: penetration %.3g, equilibrium error %.3g (tol %.3g), "
                      "%d in contact, %d in tension", k, pen, eq, eq_tol, contact, tension)
        return SolveResult(False, cfg.max_iterations, history, pairings,
                           f"no convergence in {cfg.max_iterations} iterations "
                           f"(penetration {pen:.3g}, equilibrium error {eq:.3g})")
