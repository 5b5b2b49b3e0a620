"""Contact under large displacements: the paired variant in the current configuration.

With small displacements (:class:`~vfem.contact.paired.PairedContact`) the bodies are paired once,
on the undeformed geometry, and each body's response to its contact forces is linear. Here the
bodies may slide far and deform much (thesis Chapters 2-3; the method's claim is "any amount of
sliding of the touching surfaces without requiring rediscretization"), so every contact iteration

1. **equilibrates** every large-kinematics body on its own under the contact forces it carries
   (Newton's method in :class:`~vfem.nonlinear.NonlinearBody`, warm-started from the previous
   iteration's state, so a small change of the forces costs one or two corrections): the
   nonlinearity of each body is resolved inside the body, the contact at the global level
   (vfem-method §3.1);
2. **re-pairs** the surfaces on the deformed geometry: every compatibility-side node finds its
   virtual node on the opposing surface as it now lies, with that facet's current normal; the
   transfer of the traction to the opposing nodes is re-integrated over the current overlap of
   the two surfaces. Tractions stay nominal (per undeformed length of the compatibility side), so
   the two sides' forces remain equal and opposite in total;
3. **corrects** the traction values exactly as the small-displacement variant does, with each
   body's *tangent* flexibility: the inverse of its tangent stiffness (material + geometric) at
   the current state, condensed to its contact dofs. It is recomputed when the body's shape has
   changed enough to change its tangent (an element edge changed by more than
   :data:`REFRESH_STRAIN` of its length since the last one) and reused otherwise; an out-of-date
   flexibility only slows the iteration, it never changes where it converges, because the
   penetrations are always measured on the equilibrated, deformed bodies.

Which surface of a pair carries compatibility is decided once, on the undeformed geometry (the
softer one), and the rind check guards every step as with small displacements. A body with
``kinematics = "small"`` may take part: it is paired in the current configuration too, with its
constant flexibility.
"""

from __future__ import annotations

import logging

import numpy as np

from ..errors import InputError
from .algorithm import ContactState
from .paired import PairedContact
from .search import outward_normals, project_points
from .surface import ContactSurface

log = logging.getLogger(__name__)

#: An element edge that has changed by more than this fraction of its length since a body's
#: tangent flexibility was computed makes it be computed again.
REFRESH_STRAIN = 1e-3


class LargeDeformationContact(PairedContact):
    """Frictionless contact with large displacements and sliding (see the module docstring)."""

    def __init__(self, surfaces: list[ContactSurface], pairs: set[frozenset[int]], settings,
                 backend: str = "superlu"):
        for s in surfaces:
            if s.order != 1:
                raise InputError(f"body {s.body.name!r}: large-displacement contact needs "
                                 "linear elements (order 1)")
        super().__init__(surfaces, pairs, settings)
        self.backend = backend
        self.flexibility_updates = 0
        # per body: the element edges and their vectors where the flexibility was last computed
        self._edges = []
        for s in surfaces:
            t = s.body.mesh.t
            e = np.vstack([t, t[:1]])
            self._edges.append(np.column_stack([e[:-1].ravel(), e[1:].ravel()]))
        self._flex_shape: list[np.ndarray | None] = [self._edge_vectors(i, None)
                                                     for i in range(len(surfaces))]
        self._eq_key: tuple | None = None
        self._x: list[np.ndarray] = []
        # the platen body's state at its last equilibrium: (reaction, forces, platen motion)
        self._platen_eq: tuple[float, np.ndarray, float] | None = None

    # -- the bodies at the contact forces -------------------------------------------------------

    def _full_force(self, i: int, F: np.ndarray) -> np.ndarray:
        s = self.surfaces[i]
        f = np.zeros(s.body.ndofs)
        f[s.candidate_dofs] = F.ravel()
        return f

    def _edge_vectors(self, i: int, u: np.ndarray | None) -> np.ndarray:
        b = self.surfaces[i].body
        x = b.points.T if u is None else b.points.T + u.reshape(-1, 2)
        e = self._edges[i]
        return x[e[:, 1]] - x[e[:, 0]]

    def equilibrate(self, state: ContactState) -> list[np.ndarray]:
        """Every body at the state's contact forces: the tracked nodes' current positions."""
        key = (state.load_factor, state.platen_displacement,
               b"".join(F.tobytes() for F in state.forces))
        if key == self._eq_key:
            return self._x
        x = super().positions(state)  # small-kinematics bodies: their linear response
        for i, (s, F) in enumerate(zip(self.surfaces, state.forces)):
            b = s.body
            if not b.large:
                continue
            u = b.equilibrate(state.load_factor, state.platen_displacement,
                              self._full_force(i, F))
            x[i] = s.X + u[s.tracked_dofs].reshape(-1, 2)
            self._refresh_flexibility(i, u)
            if i == self.platen_body:
                self._platen_eq = (b.platen_reaction_now(), F.copy(), state.platen_displacement)
        self._eq_key, self._x = key, x
        return x

    def _refresh_flexibility(self, i: int, u: np.ndarray) -> None:
        """Recompute body i's tangent flexibility if its shape has changed enough since."""
        s = self.surfaces[i]
        e0 = self._flex_shape[i]
        e = self._edge_vectors(i, u)
        change = float(np.max(np.linalg.norm(e - e0, axis=1) / np.linalg.norm(e0, axis=1)))
        if change <= REFRESH_STRAIN:
            return
        G, motion, stiffness = s.body.tangent_flexibility(s.tracked_dofs, s.candidate_dofs,
                                                          self.backend)
        s.G = G
        self.platen_motion[i] = motion[: 2 * s.nc].reshape(-1, 2)
        s.platen_row = -motion[: 2 * s.nc]
        s.body.platen_stiffness = stiffness
        self._flex_shape[i] = e
        self.flexibility_updates += 1
        log.debug("body %s: tangent flexibility recomputed (edges changed by %.3g)",
                  s.body.name, change)

    def positions(self, state: ContactState) -> list[np.ndarray]:
        return self.equilibrate(state)

    def platen_reaction(self, state: ContactState) -> float:
        """The platen's reaction: exact at the last equilibrium, linearised (tangent) about it
        for forces and platen motion changed since (within one correction)."""
        if self.platen_body is None or not self.surfaces[self.platen_body].body.large:
            return super().platen_reaction(state)
        if self._platen_eq is None:
            self.equilibrate(state)
        R, F0, d0 = self._platen_eq
        s = self.surfaces[self.platen_body]
        dF = state.forces[self.platen_body] - F0
        return (R + float(s.platen_row @ dF.ravel())
                + (state.platen_displacement - d0) * s.body.platen_stiffness)

    # -- pairing in the current configuration ---------------------------------------------------

    @staticmethod
    def _smooth_normals(sc: ContactSurface, A: np.ndarray, B: np.ndarray, seg: np.ndarray,
                        t: np.ndarray) -> np.ndarray:
        """The opposing surface's normal at the virtual nodes, continuous along the surface.

        Facet normals jump at every vertex of a faceted curved surface, so a node sliding past
        a vertex would turn its force abruptly (by the angle between the facets) and a node
        right under a vertex would take one facet's normal or the other's. The normal here is
        interpolated between the nodal normals (the mean of the adjacent facets' normals) with
        the facet's shape functions: continuous, and the facet normal itself on a flat surface.
        """
        fn = outward_normals(A, B)
        nodal = np.zeros((sc.nc, 2))
        for col in sc.facets.T:
            np.add.at(nodal, col, fn)
        nodal /= np.maximum(np.linalg.norm(nodal, axis=1), 1e-300)[:, None]
        ends = sc.facets[seg]
        n = (1 - t)[:, None] * nodal[ends[:, 0]] + t[:, None] * nodal[ends[:, 1]]
        return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]

    def penetrations(self, state: ContactState) -> list[np.ndarray]:
        """Equilibrate the bodies, re-pair every contact pair on the deformed geometry and
        return the penetrations (> 0 overlap) of the pairs' compatibility-side nodes."""
        x = self.equilibrate(state)
        out = []
        for pair in self.contact_pairs:
            sf, sc = self.surfaces[pair.fine], self.surfaces[pair.coarse]
            pts = x[pair.fine][pair.nodes]
            A, B = sc.segments(x[pair.coarse])
            seg, t, _ = project_points(pts, A, B)
            normal = self._smooth_normals(sc, A, B, seg, t)
            closest = A[seg] + t[:, None] * (B[seg] - A[seg])
            gap = np.einsum("ij,ij->i", pts - closest, normal)
            interp = np.zeros((len(pair.nodes), sc.nc))
            rows = np.arange(len(pair.nodes))
            for col, phi in zip(sc.facets[seg].T, sc.shape(t).T):
                interp[rows, col] += phi
            pair.normal, pair.interp, pair.rind_depth = normal, interp, sc.rind_depth[seg]
            pair.transfer = self._transfer(sf, sc, 0.0, x[pair.fine], x[pair.coarse])
            v = self.platen_motion
            pair.platen_rate = np.einsum("id,id->i", normal, interp @ v[pair.coarse]
                                         - v[pair.fine][pair.nodes])
            # the linear reading p = -(gap0 + n.(u_f - u_c)) holds with gap0 the current gap
            # less the current relative motion: keeps PairedContact's formulas valid
            uf = x[pair.fine][pair.nodes] - sf.X[pair.nodes]
            uc = interp @ (x[pair.coarse][: sc.nc] - sc.X[: sc.nc])
            pair.gap0 = gap - np.einsum("ij,ij->i", uf - uc, normal)
            out.append(-gap)
        return out


__all__ = ["LargeDeformationContact", "REFRESH_STRAIN"]
