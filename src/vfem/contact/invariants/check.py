"""Independent checks of a converged state: invariants every contact solution must satisfy.

:func:`step_invariants` (and :class:`InvariantCheck`, which keeps each body's boundary between
steps) takes only the full-mesh results of a step — each body's displacement and contact force
at every point (:class:`vfem.bodies.results.BodyStepResult`) — and the bodies' meshes and supports;
nothing of the contact formulation's own state (pairings, virtual nodes, multipliers, which side
carries compatibility). It checks

(a) **force balance**: the contact forces of all bodies sum to zero, within ``force_tolerance``
    (1e-8) of the largest body's total contact force.
(b) **no interpenetration**: for each pair of bodies that may touch, no boundary node of one, at
    its deformed position X + u, lies inside the other's deformed boundary deeper (distance to
    that boundary, symmetry planes left out) than the penetration tolerance plus a *faceting
    allowance*. Inside is decided by the node's closest point on the other body's deformed
    boundary polygon (the sign of the distance along the facet's normal there, or along the mean
    of the two facets' normals at a vertex: exact for any polygon, holes included); for an
    untangled mesh that is the same as lying in one of its deformed elements, and it costs
    O(boundary) where locating in the elements costs O(elements) per step. Of a node in the
    other body's box, only one that may have entered it since the undeformed state is asked
    (an exact bound on how far the two have moved, :meth:`InvariantCheck._may_enter`):
    O(contact) per step.
    The allowance: a convex part of one piecewise-linear surface (turning through α) can
    protrude between two nodes of the other surface that lie on it (a facet of length L) by at
    most (L/2)·tan(α/2) (the isosceles case; (L/2)·sin(α/2) would miss it by 1/cos(α/2)). α is
    the convex turning of the node's own boundary within L of it (the stretch such a facet can
    span; the node's own angle alone misses a finer surface curving under a coarser facet, and
    the concave bottom of an indentation does not lower what its convex shoulder protrudes), at
    most 90°, and the allowance at most the longer of L/2 and the node's own facets. A node on
    a symmetry plane (a straight boundary held normal to itself, a roller ``Support``) turns as
    the mirrored model does.
    Between two bodies analysed under small kinematics the contact condition is the linearised
    one (the gap g0 + n·(u_node − u_other) on the undeformed surfaces, as in small-strain
    contact theory) and the deformed positions differ from it by second-order terms (a facet's
    rotation times the slip along it; on the wedge examples, driven 0.3 into the plate, the
    linearised reading is the one that is off). There a node counts as penetrating by the
    smaller of its depth into the deformed boundary and its linearised depth, so only a
    penetration both readings see fails. Where any body of the model iterates (large
    kinematics, or a plastic material under small: issue 41), the model's contact is solved
    on the deformed geometry (the Newton formulation pairs every surface as it now lies), and
    the deformed reading alone is judged, for every pair (a flat punch driven past a plastic
    block's limit load, the block flowing up its side: 0.0187 deep, 19 times the nominal
    push, where the linearised reading saw nothing; random model 2d-41 ``--plastic``).
(c) **no tension**: no node carries a tensile contact force — the nodal test: F·n > ``1e-8``
    times the largest nodal contact force of the model is tension, with n the body's own outward
    nodal normal (the mean of its boundary facets' normals; deformed under large kinematics,
    undeformed under small, as linear theory reads it: a force tangential to a face that has
    rotated a little is not tension). With linear facets a compressive traction gives every
    node a compressive force (φ >= 0), so the test is exact. A quadratic facet's end node gets
    -L/30 of its far end's traction, so there F·n is summed over each vertex and the midpoints
    of its facets (weights 1 - φ_far end >= 0 on each facet; a midpoint alone, 4t(1 - t) >= 0);
    and a quadratic interpolation of non-negative nodal tractions is itself negative near the
    edge of contact (down to -1/8 of a nodal value), so the other side's nodes there carry
    small tensile forces: ``quadratic_tension_tolerance`` (5e-2) is the tolerance for bodies
    with quadratic elements (measured: 1.4e-2 on Hertz with order 2, 1.3e-2 on the gasket).
    The consistent recovery of a pressure, p = M⁻¹(−F·n) with M the boundary mass matrix over
    the facets whose nodes all carry force, was measured too and rejected: it recovers the
    traction exactly where F = M q, but on the other surface of a pair (forces re-integrated
    from the first) it undershoots at every edge of contact — negative pressures of 3.6 % of
    the largest on Hertz, 0.4 % on wedge case 1, 29 % next to the block's corner, 23 % on the
    gasket (``tension_measure="consistent"`` keeps it for comparison).

The solver (:meth:`vfem.solver.Analysis.run`) evaluates them after every converged contact
step and treats a violation as a failed step (:class:`vfem.errors.InvariantViolation`).

"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...executor import SERIAL
from .check3d import SOLID
from .kind import SurfaceKind
from .measures import (
    FORCE_BALANCE_TOLERANCE,
    QUADRATIC_TENSION_TOLERANCE,
    TENSION_MEASURES,
    TENSION_TOLERANCE,
    Invariants,
)
from .plane import PLANE

if TYPE_CHECKING:
    from ...bodies import Body


@dataclass
class _Undeformed:
    """Per boundary node of body i, undeformed, what the pre-filter of the pair (i, j) reads
    (:meth:`InvariantCheck._may_enter`): its distance to body j's closed undeformed boundary
    (every facet) and whether it lies inside it, computed for a node when first needed (a
    node far from j is never asked), and whether it was in j's box at an earlier state."""

    surfaces: tuple  # (body i's undeformed surface, body j's): what it was computed on
    distance: np.ndarray  # (nb,) NaN where not computed
    inside: np.ndarray  # (nb,) bool
    known: np.ndarray  # (nb,) bool: distance and inside computed
    seen: np.ndarray  # (nb,) bool

    @classmethod
    def of(cls, ri, rj) -> _Undeformed:
        n = len(ri.x)
        return cls((ri, rj), np.full(n, np.nan), np.zeros(n, dtype=bool),
                   np.zeros(n, dtype=bool), np.zeros(n, dtype=bool))

    def side(self, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The distance and inside of ``nodes`` (local numbers of body i), computed where not
        yet known."""
        todo = nodes[~self.known[nodes]]
        if todo.size:
            ri, rj = self.surfaces
            self.inside[todo], self.distance[todo] = rj.side(ri.x[todo])
            self.known[todo] = True
        return self.distance[nodes], self.inside[nodes]


class InvariantCheck:
    """The invariants of the states of one model (:func:`step_invariants` for one state).

    Args:
        bodies: the bodies, or a model (its ``bodies`` and ``contact_pairs``).
        pairs: the pairs of bodies that may touch: names ``(a, b)``, or sets of two body
            indices; None means the model's ``contact_pairs``, and then every pair.
        penetration_tolerance: the analysis' penetration tolerance (length).
        force_tolerance: (a)'s relative tolerance.
        tension_tolerance: (c)'s relative tolerance (bodies with linear elements).
        quadratic_tension_tolerance: (c)'s relative tolerance on bodies with quadratic ones.
        tension_measure: ``"nodal"`` (default) or ``"consistent"`` (module docstring).

    Each body's boundary polygon, oriented, is taken from its undeformed mesh once. A call
    costs O(boundary nodes): the bodies' interiors are never visited, apart from summing
    their contact forces.
    """

    def __init__(self, bodies, pairs=None, penetration_tolerance: float = 0.0,
                 force_tolerance: float = FORCE_BALANCE_TOLERANCE,
                 tension_tolerance: float = TENSION_TOLERANCE,
                 quadratic_tension_tolerance: float = QUADRATIC_TENSION_TOLERANCE,
                 tension_measure: str = "nodal"):
        #: a body's two sides that may touch each other (self-contact, issue 42): (body,
        #: mesh facets of one side, of the other), from the model's pairs
        self.own_sides: list[tuple[int, np.ndarray, np.ndarray]] = []
        if hasattr(bodies, "bodies"):  # a model
            model_pairs = bodies.pairs()
            if pairs is None:  # its pairs' bodies (a side's boundaries do not matter here)
                pairs = model_pairs.keys()
            bodies = bodies.bodies
            self.own_sides = [(p.a.body, p.a.mesh_facets(bodies[p.a.body]),
                               p.b.mesh_facets(bodies[p.b.body]))
                              for p in model_pairs if p.a.body == p.b.body]
        self.bodies = list(bodies)
        names = [b.name for b in self.bodies]
        if pairs is None:
            pairs = [(i, j) for i in range(len(names)) for j in range(i)]
        ordered = []
        for pair in pairs:
            i, j = (names.index(k) if isinstance(k, str) else int(k) for k in pair)
            if i != j:
                ordered += [(i, j), (j, i)]
        self.pairs = sorted(set(ordered))
        if tension_measure not in TENSION_MEASURES:
            raise ValueError(f"tension_measure must be one of {TENSION_MEASURES}, got "
                             f"{tension_measure!r}")
        self.penetration_tolerance = float(penetration_tolerance)
        self.force_tolerance = float(force_tolerance)
        self.tension_tolerance = float(tension_tolerance)
        self.quadratic_tension_tolerance = float(quadratic_tension_tolerance)
        self.tension_measure = tension_measure
        self._kind: SurfaceKind | None = None
        self._boundaries: list | None = None
        self._reference: list | None = None
        #: (i, j) -> the pre-filter's reading of the pair (:meth:`_may_enter`)
        self._undeformed: dict[tuple[int, int], _Undeformed] = {}
        #: where each pair's (b) is read (:mod:`vfem.executor`; the solver's MPI ranks)
        self.executor = SERIAL

    @property
    def kind(self) -> SurfaceKind:
        """What the invariants read of these bodies (:mod:`.kind`): 3D surfaces if any body
        is 3D, 2D polygons otherwise; the one place the checker asks the dimension."""
        if self._kind is None:
            self._kind = SOLID if any(b.dim == 3 for b in self.bodies) else PLANE
        return self._kind

    @property
    def boundaries(self) -> list:
        """Each body's boundary, from its undeformed mesh (``kind.boundary``)."""
        if self._boundaries is None:
            self._boundaries = [self.kind.boundary(b) for b in self.bodies]
            if any(getattr(b, "iterates", False) for b in self.bodies):
                # a body that iterates (large kinematics, a plastic material) has the model's
                # contact solved on the deformed geometry, every pair of it (the Newton
                # formulation, docs/method.md §10): (b) and (c) read it so
                for g in self._boundaries:
                    g.large = True
        return self._boundaries

    @property
    def reference(self) -> list:
        """Each body's boundary undeformed (``kind.surface``)."""
        if self._reference is None:
            self._reference = [self.kind.surface(g, b.points[:, g.nodes].T)
                               for b, g in zip(self.bodies, self.boundaries)]
        return self._reference

    def __call__(self, fields: dict, extra_allowance: float = 0.0,
                 force_tolerance: float | None = None,
                 enforced: tuple[str, ...] | None = None) -> Invariants:
        """The invariants of a state: ``fields[body name]`` has ``displacement`` and
        ``contact_force`` ((npoints, dim) each, at ``Body.points``). ``extra_allowance`` is
        added to every allowed depth, ``force_tolerance`` replaces (a)'s and ``enforced`` names
        the invariants that decide ``ok`` (default all three; the thesis variant's residual
        errors). One reading for 2D and 3D: the dimension's parts are the kind's."""
        t0 = time.perf_counter()
        kind = self.kind
        out = Invariants(force_tolerance=self.force_tolerance if force_tolerance is None
                         else float(force_tolerance),
                         tension_measure=self.tension_measure)
        if enforced is not None:
            out.enforced = tuple(enforced)
        F = [np.asarray(fields[b.name].contact_force, dtype=float) for b in self.bodies]
        self._force_balance(F, out)
        if kind.skips_untouched and not self.pairs and not self.own_sides and \
                not any(np.any(f) for f in F):
            # nothing may touch and no force acts: (a) balances, (b) and (c) hold
            out.allowed = self.penetration_tolerance + extra_allowance
            out.tension_tolerance = min((self._tolerance(b) for b in self.bodies),
                                        default=self.tension_tolerance)
            out.seconds = time.perf_counter() - t0
            return out
        if self.tension_measure not in kind.tension_measures:
            raise NotImplementedError(f"the {self.tension_measure} tension measure in "
                                      f"{kind.name} is not implemented (tension_measure="
                                      f"{' or '.join(repr(m) for m in kind.tension_measures)} "
                                      "is)")
        ref = self.reference
        u = [np.asarray(fields[b.name].displacement)[g.nodes]
             for b, g in zip(self.bodies, self.boundaries)]
        cur = [r if not np.any(ui) else kind.surface(r.b, r.x + ui) for r, ui in zip(ref, u)]
        Fb = [f[g.nodes] for f, g in zip(F, self.boundaries)]
        self._interpenetration(cur, out, extra_allowance, Fb, ref)
        if self.own_sides:
            self._own_sides_apart(cur, out, extra_allowance, Fb)
        # (c)'s normals: the deformed ones under large kinematics, the undeformed ones (linear
        # theory's) under small
        own = [c if b.large else r for b, c, r in zip(self.bodies, cur, ref)]
        out.tension, out.tension_tolerance, out.tension_where = kind.tension(
            self.bodies, self._tolerance, self.tension_tolerance, Fb, own, self.tension_measure)
        out.seconds = time.perf_counter() - t0
        return out

    # -- (a) ------------------------------------------------------------------------------------

    def _force_balance(self, F: list[np.ndarray], out: Invariants) -> None:
        # per component: a column sum is several times faster than sum(axis=0) on (n, 2)
        dim = F[0].shape[1] if F else 2
        totals = np.array([[f[:, c].sum() for c in range(dim)] for f in F]).reshape(-1, dim)
        out.totals = {b.name: tuple(float(v) for v in t) for b, t in zip(self.bodies, totals)}
        resultant = totals.sum(axis=0)
        out.resultant = tuple(float(v) for v in resultant)
        scale = float(np.linalg.norm(totals, axis=1).max(initial=0.0))
        # a body touching itself carries equal and opposite forces on its two sides, which its
        # own total does not show: each side's total counts as a body's would
        for i, nodes in self._own_side_nodes:
            scale = max(scale, float(np.linalg.norm(F[i][nodes].sum(axis=0))))
        out.force_balance = float(np.linalg.norm(resultant)) / scale if scale > 0 else 0.0

    # -- (b) ------------------------------------------------------------------------------------

    def _interpenetration(self, cur: list, out: Invariants, extra: float,
                          forces: list[np.ndarray] | None = None, ref: list | None = None
                          ) -> None:
        """(b) on the current surfaces ``cur`` (2D :class:`~.polygon._Polygon` s, or 3D
        :class:`~vfem.contact.invariants.check3d.Surface3` s, which answer the same questions: box,
        inside, depth, turning_within, adjacent); small kinematics' reading of a depth is the
        kind's (``kind.linearised_depth``, from the undeformed surfaces ``ref``, by default
        :attr:`reference`)."""
        ref = self.reference if ref is None else ref
        linearised_depth = self.kind.linearised_depth
        tol = self.penetration_tolerance + extra
        # per body: its boundary nodes that carry contact force or neighbour one that does
        touched = None if forces is None else [_loaded_or_next(g.b.segments, f)
                                               for g, f in zip(cur, forces)]

        def one(k: int):
            """Pair k's reading (i's nodes into j): the node furthest beyond its allowed depth
            (excess, depth, allowed, i, local node, j, deformed, linearised), the deepest
            depth and the second-order record (:meth:`_beyond_second_order`); None where no
            node of i is inside j."""
            i, j = self.pairs[k]
            gi, gj = cur[i], cur[j]
            if len(gi.x) == 0 or len(gj.b.segments) == 0:
                return None
            lo, hi = gj.box
            pad = 1e-9 * max(float(np.linalg.norm(hi - lo)), 1e-300)
            near = np.flatnonzero(np.all((gi.x >= lo - pad) & (gi.x <= hi + pad), axis=1))
            if not near.size:
                return None
            near = self._may_enter(i, j, near, cur, ref)
            node = near[gj.inside(gi.x[near])]
            if not node.size:
                return None
            depth, L, ends = gj.depth(gi.x[node])
            if touched is not None:
                # the faceting allowance is for a node between two nodes of the other surface
                # that lie on this one: where the facet is not in or next to a contact zone,
                # a node inside it is contact missed (a curved body's first touch between the
                # other's nodes), not faceting
                L = np.where(touched[j][ends].any(axis=1), L, 0.0)
            deformed, linearised, second = depth, None, 0.0
            if not (gi.b.large or gj.b.large):
                linearised, second = linearised_depth(ref, i, j, node, cur)
                depth = np.minimum(depth, linearised)
            alpha = np.minimum(gi.turning_within(node, L), 0.5 * np.pi)
            allowed = tol + second + np.minimum(0.5 * L * np.tan(0.5 * alpha),
                                                np.maximum(gi.adjacent[node], 0.5 * L))
            second_order = Invariants()  # (this pair's alone)
            if linearised is not None:
                self._beyond_second_order(second_order, i, j, node, deformed, linearised,
                                          allowed, cur)
            n = int(np.argmax(depth - allowed))
            cand = (float(depth[n] - allowed[n]), float(depth[n]), float(allowed[n]), i,
                    int(node[n]), j, float(deformed[n]),
                    None if linearised is None else float(linearised[n]))
            return cand, float(depth.max()), second_order.second_order

        # each pair on one rank (vfem.parallel, issue 40: by the body entered), its reading to
        # every rank; then taken in the pairs' order, as one loop over them would
        found = self.executor.map(range(len(self.pairs)), one,
                                  owners=[j % self.executor.size for _, j in self.pairs])
        best = None  # (excess, depth, allowed, i, local node, j, deformed, linearised)
        deepest = 0.0
        for k in range(len(self.pairs)):
            if found[k] is None:
                continue
            cand, depth_max, second = found[k]
            if second is not None and (out.second_order is None
                                       or second["beyond"] > out.second_order["beyond"]):
                out.second_order = second
            deepest = max(deepest, depth_max)
            if best is None or (cand[0] > 0 and cand[0] > best[0]) or (
                    best[0] <= 0 and cand[0] <= 0 and cand[1] > best[1]):
                best = cand
        out.max_penetration = max(deepest, 0.0)
        if best is None:
            out.allowed = tol
            return
        _, out.penetration, out.allowed, i, k, j, deformed, linearised = best
        pos = cur[i].x[k]
        out.where = {"body": self.bodies[i].name, "node": int(cur[i].b.nodes[k]),
                     "into": self.bodies[j].name,
                     **{c: float(v) for c, v in zip(("x", "y", "z"), pos)},
                     "deformed_depth": deformed, "linearised_depth": linearised}

    @functools.cached_property
    def _own_side_nodes(self) -> list[tuple[int, np.ndarray]]:
        """Per side of a body's own pair, (body, its nodes' point numbers): what (a) sums."""
        return [(i, np.unique(self.bodies[i].facet_points(f)))
                for i, a, b in self.own_sides for f in (a, b)]

    @functools.cached_property
    def _own_side_masks(self) -> list[tuple[int, np.ndarray, np.ndarray]]:
        """Per pair of a body's own sides, (body, its boundary's pieces on one side, on the
        other): masks over the pieces (segments, triangles) that (b) reads, once."""
        return [(i, np.isin(self.boundaries[i].facet_of, a),
                 np.isin(self.boundaries[i].facet_of, b)) for i, a, b in self.own_sides]

    def _own_sides_apart(self, cur: list, out: Invariants, extra: float,
                         forces: list[np.ndarray]) -> None:
        """(b) between the two sides of a body in contact with itself (issue 42): no node of
        one side behind the other side's deformed facets deeper than the tolerance and the
        faceting allowance, as between two bodies. A body's own boundary cannot say it (a
        node lies on it, so "inside"); so a node of each side is read against the other
        side's facets alone, behind them and over them (the kind's ``behind``:
        :meth:`~vfem.contact.invariants.polygon._Polygon.behind`,
        :meth:`~vfem.contact.invariants.check3d.Surface3.behind`), not a node of both (the
        sides' common corner), both ways: O(side) a step. Under small kinematics too the
        deformed reading alone is judged (the linearised one of two bodies reads the other's
        undeformed boundary, which here holds the node)."""
        tol = self.penetration_tolerance + extra
        for i, on_a, on_b in self._own_side_masks:
            g = cur[i]
            touched = _loaded_or_next(g.b.segments, forces[i])
            for own, other in ((on_a, on_b), (on_b, on_a)):
                found = g.behind(own, other)
                if found is None:
                    continue
                node, depth, L, ends = found
                # (the faceting allowance where the facet is in or next to contact, as (b)'s)
                L = np.where(touched[ends].any(axis=1), L, 0.0)
                alpha = np.minimum(g.turning_within(node, L), 0.5 * np.pi)
                allowed = tol + np.minimum(0.5 * L * np.tan(0.5 * alpha),
                                           np.maximum(g.adjacent[node], 0.5 * L))
                out.max_penetration = max(out.max_penetration, float(depth.max()))
                k = int(np.argmax(depth - allowed))
                excess = float(depth[k] - allowed[k])
                recorded = (None if out.where is None else out.penetration - out.allowed)
                if recorded is None or (excess > 0 and excess > recorded) or (
                        recorded <= 0 and excess <= 0 and depth[k] > out.penetration):
                    out.penetration, out.allowed = float(depth[k]), float(allowed[k])
                    pos = g.x[node[k]]
                    out.where = {"body": self.bodies[i].name, "node": int(g.b.nodes[node[k]]),
                                 "into": self.bodies[i].name + " (its other side)",
                                 **{c_: float(v) for c_, v in zip(("x", "y", "z"), pos)},
                                 "deformed_depth": float(depth[k]), "linearised_depth": None}

    def _may_enter(self, i: int, j: int, near: np.ndarray, cur: list, ref: list
                   ) -> np.ndarray:
        """Of body i's boundary nodes ``near`` (local numbers, ascending: those in j's box),
        those that may lie inside body j's boundary ``cur[j]``: the others are outside it, so
        asking ``cur[j].inside`` of these alone finds the same nodes, in O(contact) where
        asking of every node in j's box costs O(surface) per step (a sphere's whole lower
        half in a block's box). A node in j's box for the first time is kept: its undeformed
        side would cost what asking it costs (a one-state check spends nothing more); so are
        all when they are fewer than j's surface's ``bound_from`` (2D: asking is cheap).

        Exact, not a heuristic. With X the undeformed positions (``ref``), D = x − X the
        displacements to the current ones and c any common translation (the centre of the
        box of j's displacements: a rigid translation of j costs nothing), a node p of i
        outside j undeformed, at a distance d0(p) from j's closed boundary (every facet,
        symmetry planes included, as ``inside`` reads it; :class:`_Undeformed`), with
        |D_p − c| + max_q |D_q − c| < d0(p) (q over j's boundary nodes) is outside j now:

        1. each facet ``inside`` reads is linear in its nodes (a triangle, a quadrilateral's
           two, a quadratic triangle's four corner-and-midpoint pieces; a segment, a
           quadratic facet's two chords), so on the straight path X + t D, t from 0 to 1, a
           point y = sum_a λ_a x_a of it (λ_a >= 0, summing to 1) moves by t sum_a λ_a D_a:
           relative to t c, by at most t max_q |D_q − c|, a convex combination (a quadratic
           facet's own shape functions, negative in places, would need the sum of their
           magnitudes, 5/3 on a 6-node triangle; no facet is read so here);
        2. p, moving by t (D_p − c) relative to it, stays farther than
           d0(p) − |D_p − c| − max_q |D_q − c| > 0 from j's boundary all along the path;
        3. so its winding number about j's closed boundary, an integer continuous in the
           positions wherever the point is off the boundary, is the same now as undeformed:
           0, outside. ``inside``'s sign of the closest point's offset along the feature's
           pseudonormal is that winding number for a closed boundary that does not cross
           itself (Bærentzen & Aanæs 2005), the premise its own answers rest on (the path's
           intermediate boundaries may cross themselves).

        Nodes inside j undeformed (an initial overlap, an interference fit) are always asked.
        1e-9 of the coordinates' and displacements' magnitude is kept to spare for rounding
        in the distances (O(ε) of those). ``inside`` answers each point alone, so its
        answers for the nodes kept are those it gave among all of ``near``."""
        gi, gj, ri, rj = cur[i], cur[j], ref[i], ref[j]
        if len(near) < gj.bound_from or gi.b is not ri.b or gj.b is not rj.b or \
                len(gi.x) != len(ri.x) or len(gj.x) != len(rj.x):
            return near
        pair = self._undeformed.get((i, j))
        if pair is None or pair.surfaces[0] is not ri or pair.surfaces[1] is not rj:
            pair = self._undeformed[(i, j)] = _Undeformed.of(ri, rj)
        # a node in j's box for the first time is asked as it stands (a one-state check, or a
        # node that passes by once, spends nothing on its undeformed side); from its second
        # time on, the bound
        again = pair.seen[near]
        pair.seen[near] = True
        bound = near[again]
        if not bound.size:
            return near
        d0, inside0 = pair.side(bound)
        Dj = gj.x - rj.x
        Di = gi.x[bound] - ri.x[bound]
        c = 0.5 * (Dj.min(axis=0) + Dj.max(axis=0))
        spread = float(np.linalg.norm(Dj - c, axis=1).max(initial=0.0))
        size = max(float(np.abs(a).max(initial=0.0)) for a in (ri.x, rj.x, Di, Dj))
        reach = np.linalg.norm(Di - c, axis=1) + spread + 1e-9 * size
        # (a distance that is not a number leaves its node asked)
        outside = np.zeros(len(near), dtype=bool)
        outside[again] = ~inside0 & (reach < d0)
        return near[~outside]

    def _beyond_second_order(self, out: Invariants, i: int, j: int, node: np.ndarray,
                             deformed: np.ndarray, linearised: np.ndarray, allowed: np.ndarray,
                             cur: list) -> None:
        """Small kinematics: keep in ``out.second_order`` the node of body i deepest beyond its
        ``allowed`` depth into body j on the deformed geometry alone, which (b) passes because
        linear theory reads it within (the smaller of the two readings is judged). ``allowed``
        already holds linear theory's estimated second-order terms (slip times rotation, a
        quadratic facet's sag), so such a node is further off than those explain: the answer's
        deformed geometry, not a failure of the formulation's own condition. Recorded, not
        enforced (a stricter (b) that judged the deformed depth alone against this allowance
        was measured and not kept: on seed 0 of ``benchmarks/random_models.py`` it stopped one
        model and turned one wrong through the other compatibility side, to mend one of seed
        4); the solver warns about it."""
        over = np.where(np.asarray(linearised) <= allowed,
                        np.asarray(deformed, dtype=float) - allowed, -np.inf)
        k = int(np.argmax(over))
        if over[k] <= 0 or (out.second_order is not None
                            and over[k] <= out.second_order["beyond"]):
            return
        pos = cur[i].x[node[k]]
        out.second_order = {
            "body": self.bodies[i].name, "node": int(cur[i].b.nodes[node[k]]),
            "into": self.bodies[j].name,
            **{c: float(v) for c, v in zip(("x", "y", "z"), pos)},
            "deformed_depth": float(deformed[k]), "linearised_depth": float(linearised[k]),
            "allowed": float(allowed[k]), "beyond": float(over[k])}

    # -- (c) ------------------------------------------------------------------------------------

    def _tolerance(self, body: Body) -> float:
        return self.quadratic_tension_tolerance if body.order != 1 else self.tension_tolerance

def _loaded_or_next(segments: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """(nb,) the boundary nodes that carry a contact force (``forces``, (nb, dim)) or share a
    boundary segment with one that does."""
    loaded = np.abs(forces).sum(axis=1) > 0
    out = loaded.copy()
    for a, b in ((0, 1), (1, 0)):
        np.logical_or.at(out, segments[:, a], loaded[segments[:, b]])
    return out


def step_invariants(model_or_bodies, pairs, fields: dict, penetration_tolerance: float,
                    **options) -> Invariants:
    """The three invariants of one state (see :class:`InvariantCheck` for the arguments;
    ``fields``: body name -> its :class:`~vfem.bodies.results.BodyStepResult`, or anything with
    ``displacement`` and ``contact_force``)."""
    return InvariantCheck(model_or_bodies, pairs, penetration_tolerance, **options)(fields)
