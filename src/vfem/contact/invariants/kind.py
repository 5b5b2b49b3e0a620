"""What the invariants read of the bodies of one dimension: the dimension lives here and in the
surfaces each kind builds (issue 38: one checker, :class:`~vfem.contact.invariants.check.
InvariantCheck`, for 2D and 3D; the kinds: :data:`.plane.PLANE`, :data:`.check3d.SOLID`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class SurfaceKind:
    """The dimension-specific parts of the invariants.

    Attributes:
        name: "2D" or "3D", for messages.
        boundary: a body -> its boundary, from its undeformed mesh (once).
        surface: (boundary, (nb, dim) positions) -> the boundary at those positions, which
            answers invariant (b)'s questions (box, inside, depth, turning_within, adjacent)
            and carries the normals (c) reads.
        linearised_depth: (reference surfaces, i, j, body i's local nodes, current surfaces)
            -> the depth of those nodes into body j as linear theory reads it, and the
            allowance for its second-order terms (small kinematics).
        tension: (bodies, tolerance of a body, least tolerance, boundary contact forces, the
            bodies' own surfaces[, measure]) -> (value, tolerance, where) of invariant (c).
        tension_measures: the measures ``tension`` takes.
        skips_untouched: whether a model in which nothing may touch and no force acts is
            answered without building its surfaces (3D: their set-up is the costly part).
    """

    name: str
    boundary: Callable
    surface: Callable
    linearised_depth: Callable
    tension: Callable
    tension_measures: tuple[str, ...]
    skips_untouched: bool
