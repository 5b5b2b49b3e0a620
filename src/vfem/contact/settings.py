"""Contact settings: every number the algorithm uses, with its default and meaning."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import InputError

CONVERGENCE_CRITERIA = ("stationary", "physical", "thesis")
VARIANTS = ("thesis", "paired")
METHODS = ("vfem", "penalty", "lagrange", "augmented")
#: how the contact correction reads the bodies' flexibility (issue 22)
FLEXIBILITY_ROUTES = ("auto", "dense", "matrix_free")


@dataclass(frozen=True)
class PairFriction:
    """The friction of one pair of bodies (``[[contact.pairs]]``), instead of the model's
    ``contact.friction``.

    Attributes:
        bodies: the two bodies' names.
        friction: Coulomb's coefficient mu (with ``static_dynamic``: the dynamic one, of a node
            that slips). 0: frictionless.
        law: ``"coulomb"`` — stick while the tangential traction is within mu times the normal
            one, slip at mu times it; ``"static_dynamic"`` — a node that sticks starts slipping
            at ``static_friction`` times its normal traction and slips at ``friction`` times
            it; ``"elastoplastic"`` — the thesis's friction-slippage law (§1.10), a regularised
            Coulomb law: below the cone the tangential traction is ``slip_stiffness`` times an
            elastic slip, on it the node slips at mu times its normal traction (it has a
            parameter to choose: for those who want the regularisation).
        static_friction: the static coefficient (``static_dynamic``), at least ``friction``.
        slip_stiffness: the tangential traction per unit elastic slip (``elastoplastic``).
    """

    bodies: tuple[str, str]
    friction: float = 0.0
    law: str = "coulomb"
    static_friction: float | None = None
    slip_stiffness: float | None = None

    def validate(self, where: str = "contact.pairs") -> None:
        if len(self.bodies) != 2:
            raise InputError(f"{where}: bodies must name two bodies, got {list(self.bodies)!r}")
        # (one body twice: its friction with itself, which needs a pair of its own sides in
        # contact_pairs: checked with the model's pairs, vfem.contact.formulations.formulation)
        if not (math.isfinite(self.friction) and self.friction >= 0):
            raise InputError(f"{where} {list(self.bodies)!r}: friction must be a number >= 0, "
                             f"got {self.friction!r}")
        # the law and its own parameters are the law's to check
        # (vfem.contact.laws.friction_law, with the formulation's capabilities)


@dataclass(frozen=True)
class ContactSettings:
    """Settings of the contact algorithm: the virtual finite element method, or one of the
    classical baselines it is measured against (``method``).

    Attributes:
        method: ``"vfem"`` (default) — the virtual finite element method; or a classical
            baseline it is measured against, one global system of every body with
            node-to-segment contact (docs/baselines.md): ``"penalty"`` — a penalty on each
            penetrating node, so the answer depends on ``penalty`` (contact pressure = penalty
            x penetration); ``"lagrange"`` — Lagrange multipliers, gaps closed exactly;
            ``"augmented"`` — augmented Lagrangian (Uzawa) with the same penalty, until the
            gaps are within ``augmented_tolerance``. Of the keys below the baselines use
            ``search_distance``, ``max_iterations`` (linear solves per step), ``penalty``,
            ``penalty_factor`` and ``augmented_tolerance``; they need linear elements (order 1)
            and small kinematics.
        variant: ``"thesis"`` — the plain reading: every node of both bodies checked for both
            compatibility and equilibrium (docs/method.md); ``"paired"`` — per contact pair one
            surface (the softer, or of equals the finer) carries compatibility and the other
            equilibrium, so the exact discrete contact state is the fixed point
            (``vfem/contact/formulations/paired.py``).
        penetration_tolerance: largest penetration (length) left uncorrected (thesis §5.6). Must
            be small against the thickness of the surface elements. Default (None): 1e-5 times the
            shortest candidate contact facet.
        equilibrium_tolerance: largest equilibrium error left uncorrected, relative to the largest
            nodal contact force (thesis §5.6: small compared with nodal loads).
        relaxation: factor on the corrective forces after the first ``relaxed_iterations``.
        first_relaxation: factor on the corrective forces of the first ``relaxed_iterations``
            iterations of a step (under-relaxation < 1 often helps, thesis §5.6).
        relaxed_iterations: how many iterations use ``first_relaxation``.
        tension_release_iterations: a node found in tension gives up its force over this many
            iterations. Default (None): 2 for the thesis variant (thesis §5.6: half in each of
            two, which softens the disturbance to its approximate corrections), 1 for the paired
            variant, whose correction re-closes every gap exactly after a release.
        max_iterations: contact iterations allowed per solve before the step is cut.
        convergence: when a contact solve stops. Always when the physical errors are within
            tolerance (largest penetration, largest equilibrium error, no node in tension).
            ``"stationary"`` (default) — also when the net corrective force on every node is
            within the equilibrium tolerance and the displacement it causes within the
            penetration tolerance (the fixed point of the iteration; a step that stops there
            with the physical errors above tolerance is not converged, and neither is the
            analysis, which still runs and writes every step); ``"physical"`` — only on
            the physical errors; ``"thesis"`` — also when the corrective forces of an iteration
            fall below ``thesis_fraction`` of the largest of the solve, or the displacements they
            cause below that fraction of the largest (thesis §5.6).
        thesis_fraction: the fraction of the thesis criterion (1 %).
        search_distance: facets farther than this from another body in the undeformed
            configuration (moved by the bodies' prescribed motions over the schedule) are not
            contact candidates. Default (None): 2 % of the smaller of the two bodies'
            bounding-box diagonals; under large kinematics, every facet of the contact
            boundaries (bodies may slide anywhere and deform towards each other). Given under
            large kinematics, it is honoured: it must then also cover how far the surfaces
            deform towards each other, and a facet it leaves out can never carry contact (the
            candidate surface's ends take one-sided normals: keep them clear of the contact).
        quadrature_order: polynomial order integrated exactly on the virtual elements.
        size_ratio_limit: when a facet is longer than this many times the opposing facets, the
            quadrature order is raised in proportion (thesis §5.6: 3:1 is easily tolerated).
        max_step_cuts: how many times a step is halved after a failure before the analysis stops.
        platen_tolerance: relative mismatch allowed between a platen's reaction and its force;
            where the force is zero, relative to the forces the reaction sums (its body's
            contact forces, the loads' share).
        penalty: the baselines' penalty stiffness per unit contact length (``method``
            ``"penalty"`` or ``"augmented"``): contact pressure per unit penetration (a slave
            node's force is penalty x penetration x its tributary length). Default (None):
            ``penalty_factor`` x the larger plane-strain modulus E / (1 - nu^2) of the pair's
            two bodies / the pair's shortest slave facet. The penalty method's answer
            (penetration, pressure, contact size) depends on it.
        penalty_factor: the multiple of E' / h that makes the default ``penalty``.
        augmented_tolerance: the augmented Lagrangian stops when every active node's gap and
            every other node's penetration is within this fraction of the shortest slave facet
            of the model (the same length scale as ``penetration_tolerance``'s default).
        compatibility_side: the paired variant: the name of a body that carries compatibility
            in every contact pair it belongs to, instead of the surface chosen by stiffness and
            facet size (for testing that the answer does not depend on the choice beyond
            discretisation error). Default (None): the softer surface, of equals the finer. A
            forced body whose facets over the other surface are 1.5 times the other's or more
            is warned about: it resolves the traction on its own facets, and a contact zone
            narrower than they are can read far off (docs/benchmarks.md, the tilted cube).
            Unset, a pair whose chosen side breaks invariant (b), or pushes a node past the
            other body's outer layer of elements, at every cut has its side switched to the
            other body for the rest of the run (frictionless contact: no slip history ties
            the answer to the side that carried it; ``steps[].compatibility_switched`` in
            summary.json says where); set, the side stays.
        friction: Coulomb's coefficient of friction μ of every contact pair: a node in contact
            sticks (no relative tangential motion against its virtual node within the step) while
            its tangential traction stays within μ times its normal traction, and slips with
            that traction opposing its slip otherwise (docs/method.md §11). 0 (the default):
            frictionless, the code path of every analysis before friction. The paired variant,
            small and large kinematics, and the lagrange baseline (docs/baselines.md).
        pairs: the friction of particular pairs of bodies (``[[contact.pairs]]`` tables:
            ``bodies``, ``friction``, ``law`` and its parameters), instead of ``friction``;
            different laws in different contact areas, as the thesis allows (§1.10).
        flexibility: how the contact correction reads the bodies' flexibility on their contact
            surfaces (issue 22, :mod:`vfem.contact.solvers.matrix_free`): ``"dense"`` — formed, each
            body condensed to its contact dofs (a dense block of (dim nc)^2 numbers, fastest for
            small zones); ``"matrix_free"`` — applied through each body's factorization, one
            back-substitution per body per iteration of a GMRES solve, nothing dense (large
            contact zones); ``"auto"`` (default) — matrix-free when the dense blocks would take
            more than ``dense_limit_mib``, or where it is predicted to take less time
            (:func:`vfem.contact.solvers.routes.predicted_seconds`, issue 40), else dense.
            The matrix-free route serves the paired
            variant, small kinematics, without friction; ``"auto"`` keeps the others dense.
        dense_limit_mib: the memory (MiB) the dense blocks may take before ``"auto"`` goes
            matrix-free. Default (None): half the memory available when the analysis starts.
    """

    method: str = "vfem"
    variant: str = "paired"
    penetration_tolerance: float | None = None
    equilibrium_tolerance: float = 1e-3
    relaxation: float = 1.0
    first_relaxation: float = 1.0
    relaxed_iterations: int = 0
    tension_release_iterations: int | None = None
    max_iterations: int = 100
    convergence: str = "stationary"
    thesis_fraction: float = 0.01
    search_distance: float | None = None
    quadrature_order: int = 7
    size_ratio_limit: float = 3.0
    max_step_cuts: int = 6
    platen_tolerance: float = 1e-5
    penalty: float | None = None
    penalty_factor: float = 1000.0
    augmented_tolerance: float = 1e-9
    compatibility_side: str | None = None
    friction: float = 0.0
    pairs: tuple[PairFriction, ...] = ()
    flexibility: str = "auto"
    dense_limit_mib: float | None = None

    def validate(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and not math.isfinite(v):
                raise InputError(f"contact.{f.name} must be a finite number, got {v!r}")
        positive = ("equilibrium_tolerance", "relaxation", "first_relaxation", "thesis_fraction",
                    "size_ratio_limit", "platen_tolerance", "penalty_factor",
                    "augmented_tolerance")
        for name in positive:
            if getattr(self, name) <= 0:
                raise InputError(f"contact.{name} must be > 0, got {getattr(self, name)!r}")
        if self.friction < 0:
            raise InputError(f"contact.friction (Coulomb's coefficient) must be >= 0, got "
                             f"{self.friction!r}")
        named = set()
        for pair in self.pairs:
            pair.validate()
            key = frozenset(pair.bodies)
            if key in named:
                raise InputError(f"contact.pairs: {sorted(pair.bodies)!r} given twice")
            named.add(key)
        if self.flexibility not in FLEXIBILITY_ROUTES:
            raise InputError(f"contact.flexibility must be one of {FLEXIBILITY_ROUTES}, got "
                             f"{self.flexibility!r}")
        for name in ("penetration_tolerance", "search_distance", "penalty", "dense_limit_mib"):
            v = getattr(self, name)
            if v is not None and v <= 0:
                raise InputError(f"contact.{name} must be > 0, got {v!r}")
        if self.method not in METHODS:
            raise InputError(f"contact.method must be one of {METHODS}, got {self.method!r}")
        if self.variant not in VARIANTS:
            raise InputError(f"contact.variant must be one of {VARIANTS}, got {self.variant!r}")
        if self.convergence not in CONVERGENCE_CRITERIA:
            raise InputError(f"contact.convergence must be one of {CONVERGENCE_CRITERIA}, "
                             f"got {self.convergence!r}")
        for name in ("tension_release_iterations", "max_iterations", "quadrature_order"):
            v = getattr(self, name)
            if v is not None and int(v) < 1:
                raise InputError(f"contact.{name} must be >= 1, got {v!r}")
        for name in ("max_step_cuts", "relaxed_iterations"):
            v = getattr(self, name)
            if int(v) < 0:
                raise InputError(f"contact.{name} must be >= 0, got {v!r}")

    @property
    def frictional(self) -> bool:
        """Whether any pair has friction (``friction`` or a ``pairs`` entry's)."""
        return self.friction > 0 or any(p.friction > 0 for p in self.pairs)

    def pair_friction(self, a: str, b: str) -> PairFriction:
        """The friction of the bodies named ``a`` and ``b``: their ``pairs`` entry, else
        Coulomb's law with ``friction``."""
        for pair in self.pairs:
            if set(pair.bodies) == {a, b}:
                return pair
        return PairFriction((a, b), self.friction)

    @property
    def release_iterations(self) -> int:
        """``tension_release_iterations`` with its variant-dependent default applied."""
        if self.tension_release_iterations is not None:
            return int(self.tension_release_iterations)
        return 1 if self.variant == "paired" else 2
