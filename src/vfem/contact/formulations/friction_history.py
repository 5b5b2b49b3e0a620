"""What the frictional formulations share (:class:`FrictionHistory`, small and large kinematics
alike): each pair's friction law (thesis §1.10, :class:`vfem.contact.laws.FrictionLaw`), the
history carried in the state (tangential tractions, anchors, accumulated slip, which nodes
slide), the friction's errors and its output fields.
"""

from __future__ import annotations

import numpy as np

from ..laws import (
    friction_law,
    magnitudes,
    slip_onset,
    tangent_by_tangent,
)
from ..state import ContactState, FrictionState


class FrictionHistory:
    """What the friction parts of the paired formulations (small and large kinematics) share:
    each pair's law, the history in the state (tangential tractions, anchors, accumulated slip,
    which nodes slide), the friction's errors and its output fields.

    A friction part is held by the formulation it serves (``formulation.friction``, built with
    it: ``form``), which asks it for what friction adds at each of its steps; it reads the
    formulation's pairs and traction values."""

    #: the state with the friction's history
    state_type = FrictionState

    def __init__(self, form, settings) -> None:
        """Each pair's friction law (:class:`~vfem.contact.laws.FrictionLaw`: its static and
        dynamic coefficients node by node, its compliance); the last step's slip increments."""
        self.form = form
        self.laws = [friction_law(settings.pair_friction(self.form.surfaces[p.fine].body.name,
                                                         self.form.surfaces[p.coarse].body.name))
                     for p in self.form.contact_pairs]
        #: per pair, the slip increments of the last converged step (for :meth:`add_fields`)
        self._increments = [self._zeros(k) for k in range(len(self.form.contact_pairs))]

    def _zeros(self, k: int) -> np.ndarray:
        """Zeros for pair k's tangential array, (n, ntan): one column per tangent of its
        normals' space (checkpoints written before 2026-11-30 kept 2D's as (n,):
        :func:`vfem.io.checkpoint.read` turns them into columns)."""
        pair = self.form.contact_pairs[k]
        return np.zeros((len(pair.nodes), pair.normal.shape[1] - 1))

    def _values(self, state: FrictionState, name: str, k: int, dtype=float) -> np.ndarray:
        """Pair k's array ``name`` of the state's history, zeros until first set."""
        table = getattr(state, name)
        if k not in table:
            table[k] = np.zeros(len(self.form.contact_pairs[k].nodes), dtype=dtype)
        return table[k]

    def shear(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's tangential traction values at its compatibility-side nodes, one column per
        tangent: (n, ntan)."""
        table = state.shear
        if k not in table:
            table[k] = self._zeros(k)
        return table[k]

    def anchor(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's anchors at the last converged step: under small kinematics its relative
        tangential displacements, (n, ntan) as :meth:`shear`; under large kinematics the
        material points of the other surface its nodes faced
        (:meth:`~vfem.contact.formulations.large_friction.LargeFriction._virtual_points`)."""
        table = state.anchor
        if k not in table:
            table[k] = self._zeros(k)
        return table[k]

    def tangential_traction(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's tangential traction vectors (n, dim) at its nodes: sum of s_j t_j."""
        s = self.shear(state, k)
        return sum(s[:, j, None] * t for j, t in enumerate(self.tangent_basis(k)))

    def accumulated_slip(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's slip accumulated over the converged steps (length, per node)."""
        return self._values(state, "slip", k)

    def sliding(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's nodes that slipped in the last correction."""
        return self._values(state, "sliding", k, bool)

    def static(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's static coefficient at its nodes (the cone a sticking node lies within), by
        its law from the slip each has accumulated."""
        return self.laws[k].static(self.accumulated_slip(state, k))

    def dynamic(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's dynamic coefficient at its nodes (a slipping node's traction over its
        normal one), by its law from the slip each has accumulated."""
        return self.laws[k].dynamic(self.accumulated_slip(state, k))

    def onset(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's coefficient at its nodes that a traction must reach to slip: the dynamic
        one where the node slid in the last correction, else the static one
        (:func:`~vfem.contact.laws.slip_onset`)."""
        return slip_onset(self.laws[k], self.sliding(state, k), self.accumulated_slip(state, k))

    def status(self, state: FrictionState, k: int) -> np.ndarray:
        """Pair k's nodes: 0 free (no normal traction), 1 sticking, 2 slipping."""
        on = self.form.tractions(state, k) > 0
        return np.where(on, np.where(self.sliding(state, k), 2, 1), 0)

    def friction_errors(self, state: FrictionState, slips: list[np.ndarray]
                        ) -> tuple[float, float, int, int]:
        """The largest tangential compatibility error (a sticking node's slip within the step,
        or a slipping node's slip against the direction its traction opposes), the largest
        excess of a tangential traction over its cone (relative to the largest mu q), and the
        nodes sticking and slipping."""
        err, excess, stick, slip = 0.0, 0.0, 0, 0
        # per pair, each node's cone mu_s q (no cone where the node pulls)
        cones = [self.static(state, k) * np.maximum(self.form.tractions(state, k), 0.0)
                 for k in range(len(self.form.contact_pairs))]
        scale = max((float(c.max(initial=0.0)) for c in cones), default=0.0)
        for k, dw in enumerate(slips):
            s = self.shear(state, k)
            status = self.status(state, k)
            held = self._held_components(k)
            if held is not None and held.any():  # 3D: a sticking node's slip along a held
                dw = dw.copy()  # tangent is the supports', as the solve has it
                dw[held & (status == 1)[:, None]] = 0.0
            stick += int((status == 1).sum())
            slip += int((status == 2).sum())
            if (status == 1).any():
                err = max(err, float(magnitudes(dw[status == 1]).max()))
            # a slipping node: its slip along sigma, the direction its traction opposes, and
            # none across it (with one tangent, sigma = -sign(s) and nothing is across). A node
            # that slips with no traction (a frictionless pair's) has no direction to measure its
            # slip against: it is free; dividing by its |s| = 0 made NaN errors (issue 37)
            on = (status == 2) & (magnitudes(s) > 0)
            if on.any():
                sigma = -s[on] / magnitudes(s[on])[:, None]
                along = np.einsum("ij,ij->i", sigma, dw[on])
                across = magnitudes(dw[on] - along[:, None] * sigma)
                err = max(err, float(np.maximum(-along, 0.0).max()), float(across.max()))
            outside = magnitudes(s) - cones[k]
            if len(outside) and scale > 0:
                excess = max(excess, float(outside.max()) / scale)
            elif np.any(s != 0):
                excess = np.inf  # a tangential traction without a normal one
        return err, excess, stick, slip

    def _held_components(self, k: int) -> np.ndarray | None:
        """3D: pair k's (n, ntan) tangential components whose relative motion no traction moves
        (:data:`~vfem.contact.formulations.friction.HELD`: supports on both bodies along that
        tangent); None in 2D (a held node there has no tangential unknown at all, and its slip is
        round-off) or before the first correction has set up the pair matrix. A sticking node's slip
        along a held tangent is the supports' (a prescribed motion, as the press fit's pushed end
        faces), not an error the iteration could correct."""
        if getattr(self.form, "_full", None) is None or not hasattr(self, "_held"):
            return None  # (before the first correction; or the large-kinematics part)
        n, base = len(self.form.contact_pairs[k].nodes), self.form._full[3][k]
        return self._held[base + n: base + (1 + self._ntan) * n].reshape(self._ntan, n).T

    def _unknowns(self, state: FrictionState) -> np.ndarray:
        """Every pair's normal then tangential traction values, in the pair matrix's order."""
        return np.concatenate([np.concatenate([self.form.tractions(state, k),
                                               tangent_by_tangent(self.shear(state, k))])
                               for k in range(len(self.form.contact_pairs))] or [np.zeros(0)])

    def _sets(self, state: FrictionState) -> list[tuple[str, np.ndarray, np.ndarray]]:
        """The contact set, the slipping nodes and their directions, for the cycle watch."""
        out = []
        for k, pair in enumerate(self.form.contact_pairs):
            sf = self.form.surfaces[pair.fine]
            status = self.status(state, k)
            nodes = sf.nodes[pair.nodes]
            out += [(sf.body.name, nodes, status > 0), (sf.body.name, nodes, status == 2)]
            out += [(sf.body.name, nodes, c < 0) for c in self.shear(state, k).T]
        return out

    def add_fields(self, out: dict, state: ContactState) -> dict:
        """To the frictionless fields ``out``, the friction's at each pair's compatibility-side
        nodes (:class:`~vfem.bodies.results.BodyStepResult`: tangential traction, slip
        increment, accumulated slip, stick or slip)."""
        increments = self._increments
        for s in self.form.surfaces:
            r = out[s.body.name]
            n = s.body.npoints
            r.contact_shear, r.slip_increment = np.zeros((n, s.dim)), np.zeros(n)
            r.accumulated_slip = np.zeros(n)
            r.friction_force = np.zeros((n, s.dim))
            r.friction_status = np.full(n, -1)  # not a compatibility-side node of a pair
        for k, pair in enumerate(self.form.contact_pairs):
            sf = self.form.surfaces[pair.fine]
            r = out[sf.body.name]
            points = sf.nodes[pair.nodes]
            traction = self.tangential_traction(state, k)
            r.contact_shear[points] = traction
            # with one tangent (2D): signed along it; with two (3D): the increment's length
            inc = increments[k]
            r.slip_increment[points] = inc[:, 0] if inc.shape[1] == 1 else magnitudes(inc)
            r.accumulated_slip[points] = self.accumulated_slip(state, k)
            r.friction_status[points] = self.status(state, k)
            # the nodal forces of the tangential traction alone, on both sides (as
            # assemble_forces makes them)
            sc = self.form.surfaces[pair.coarse]
            out[sf.body.name].friction_force[sf.nodes[: sf.nc]] += \
                pair.mass[:, pair.nodes] @ traction
            out[sc.body.name].friction_force[sc.nodes[: sc.nc]] -= \
                pair.transfer[:, pair.nodes] @ traction
        return out
