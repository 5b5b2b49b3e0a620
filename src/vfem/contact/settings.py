"""Contact settings: every number the algorithm uses, with its default and meaning."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import InputError

CONVERGENCE_CRITERIA = ("stationary", "physical", "thesis")
VARIANTS = ("thesis", "paired")


@dataclass(frozen=True)
class ContactSettings:
    """Settings of the virtual finite element contact algorithm.

    Attributes:
        variant: ``"thesis"`` — the plain reading: every node of both bodies checked for both
            compatibility and equilibrium (docs/method.md); ``"paired"`` — per contact pair one
            surface (the softer, or of equals the finer) carries compatibility and the other
            equilibrium, so the exact discrete contact state is the fixed point
            (``vfem/contact/paired.py``).
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
            penetration tolerance (the fixed point of the iteration); ``"physical"`` — only on
            the physical errors; ``"thesis"`` — also when the corrective forces of an iteration
            fall below ``thesis_fraction`` of the largest of the solve, or the displacements they
            cause below that fraction of the largest (thesis §5.6).
        thesis_fraction: the fraction of the thesis criterion (1 %).
        search_distance: facets farther than this from another body in the undeformed
            configuration are not contact candidates. Default (None): 2 % of the smaller of the
            two bodies' bounding-box diagonals.
        quadrature_order: polynomial order integrated exactly on the virtual elements.
        size_ratio_limit: when a facet is longer than this many times the opposing facets, the
            quadrature order is raised in proportion (thesis §5.6: 3:1 is easily tolerated).
        max_step_cuts: how many times a step is halved after a failure before the analysis stops.
        platen_tolerance: relative mismatch allowed between a platen's reaction and its force.
    """

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

    def validate(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and not math.isfinite(v):
                raise InputError(f"contact.{f.name} must be a finite number, got {v!r}")
        positive = ("equilibrium_tolerance", "relaxation", "first_relaxation", "thesis_fraction",
                    "size_ratio_limit", "platen_tolerance")
        for name in positive:
            if getattr(self, name) <= 0:
                raise InputError(f"contact.{name} must be > 0, got {getattr(self, name)!r}")
        for name in ("penetration_tolerance", "search_distance"):
            v = getattr(self, name)
            if v is not None and v <= 0:
                raise InputError(f"contact.{name} must be > 0, got {v!r}")
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
    def release_iterations(self) -> int:
        """``tension_release_iterations`` with its variant-dependent default applied."""
        if self.tension_release_iterations is not None:
            return int(self.tension_release_iterations)
        return 1 if self.variant == "paired" else 2
