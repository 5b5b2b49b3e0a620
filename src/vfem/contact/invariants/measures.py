"""The three invariants of one converged state as measured (:class:`Invariants`): force balance,
interpenetration and tension, where each is worst, whether each holds, the message a violation
stops with, and the record ``summary.json`` keeps per step (``steps[].invariants``). The
checks themselves are :mod:`vfem.contact.invariants.check`'s.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

#: (a): the resultant of all contact forces, relative to the largest body's total contact force
FORCE_BALANCE_TOLERANCE = 1e-8
#: (c): a tensile nodal force F·n, relative to the model's largest nodal contact force
TENSION_TOLERANCE = 1e-8
#: (c) on a body with quadratic elements (see :mod:`vfem.contact.invariants.check`)
QUADRATIC_TENSION_TOLERANCE = 5e-2
TENSION_MEASURES = ("nodal", "consistent")


@dataclass
class Invariants:
    """The three invariants of one state (see :mod:`vfem.contact.invariants.check`) and where they
    are worst.

    ``force_balance``: |sum of every body's contact forces| / the largest body's |total|
    (0 when no body carries force); ``resultant``: that sum (x, y; x, y, z in 3D); ``totals``:
    each body's.
    ``max_penetration``: the deepest boundary node inside another body (0 when none);
    ``penetration``, ``allowed`` and ``where``: the decisive node — the one that exceeds its
    allowed depth by most, or else the deepest — its depth, its allowed depth and
    ``{"body", "node", "into", "x", "y", "deformed_depth", "linearised_depth"}`` (None when no
    node is inside another body; ``linearised_depth`` None under large kinematics).
    ``second_order``: small kinematics only, the node deepest beyond its allowed depth on the
    deformed geometry that linear theory reads within it (``{"body", "node", "into", "x", "y",
    "deformed_depth", "linearised_depth", "allowed", "beyond"}``, None when there is none):
    recorded, not enforced
    (:meth:`~vfem.contact.invariants.check.InvariantCheck._beyond_second_order`). ``tension``: the
    largest tensile measure relative to the model's largest (0 when none), ``tension_where``:
    ``{"body", "node", "value"}`` of it (value: F·n, or the recovered pressure for the consistent
    measure), against ``tension_tolerance`` (that body's).
    """

    force_balance: float = 0.0
    force_tolerance: float = FORCE_BALANCE_TOLERANCE
    resultant: tuple[float, ...] = (0.0, 0.0)  # (x, y), (x, y, z) in 3D
    totals: dict[str, tuple[float, ...]] = field(default_factory=dict)
    max_penetration: float = 0.0
    penetration: float = 0.0
    allowed: float = 0.0
    where: dict | None = None
    second_order: dict | None = None
    tension: float = 0.0
    tension_tolerance: float = TENSION_TOLERANCE
    tension_where: dict | None = None
    tension_measure: str = "nodal"
    seconds: float = 0.0
    #: the invariants whose violation makes the state fail (``ok``); the others are recorded
    enforced: tuple[str, ...] = ("force balance", "interpenetration", "tension")

    @property
    def balanced(self) -> bool:
        return self.force_balance <= self.force_tolerance

    @property
    def separated(self) -> bool:
        return self.where is None or self.penetration <= self.allowed

    @property
    def compressive(self) -> bool:
        return self.tension <= self.tension_tolerance

    @property
    def ok(self) -> bool:
        """No enforced invariant is violated."""
        return not any(name in self.enforced for name in self.failed())

    def failed(self) -> list[str]:
        """The names of the invariants violated (enforced or not): "force balance",
        "interpenetration", "tension"."""
        return [name for name, good in (("force balance", self.balanced),
                                        ("interpenetration", self.separated),
                                        ("tension", self.compressive)) if not good]

    def message(self) -> str:
        """What is violated of the enforced invariants, between which bodies and at which
        nodes ("" when nothing)."""
        parts = []
        if not self.balanced and "force balance" in self.enforced:
            body = max(self.totals, key=lambda k: math.hypot(*self.totals[k]), default="")
            resultant = ", ".join(f"{v:.6g}" for v in self.resultant)
            parts.append(
                f"invariant (a) force balance violated: the contact forces of all bodies sum "
                f"to ({resultant}), {self.force_balance:.3g} of the largest body's total "
                f"contact force (body {body!r}; tolerance {self.force_tolerance:.3g})")
        if not self.separated and "interpenetration" in self.enforced:
            w = self.where
            at = ", ".join(f"{w[c]:.6g}" for c in ("x", "y", "z") if c in w)
            parts.append(
                f"invariant (b) no interpenetration violated: node {w['node']} of body "
                f"{w['body']!r}, at ({at}) deformed, lies "
                f"{self.penetration:.3g} inside body {w['into']!r} (allowed {self.allowed:.3g}: "
                "penetration tolerance and faceting allowance)")
        if not self.compressive and "tension" in self.enforced:
            w = self.tension_where
            what = ("a tensile contact force (F.n = " if self.tension_measure == "nodal"
                    else "a tensile recovered contact pressure (")
            parts.append(
                f"invariant (c) no tension violated: node {w['node']} of body {w['body']!r} "
                f"carries {what}{w['value']:.6g}, {self.tension:.3g} of the model's largest; "
                f"tolerance {self.tension_tolerance:.3g})")
        return "; ".join(parts)

    def record(self) -> dict:
        """The measures as plain JSON values (``StepResult.invariants``, summary.json)."""
        return {"force_balance": float(self.force_balance),
                "force_balance_tolerance": float(self.force_tolerance),
                "max_penetration_any_body": float(self.max_penetration),
                "penetration": float(self.penetration),
                "allowed": float(self.allowed),
                "where": dict(self.where) if self.where else None,
                "second_order": dict(self.second_order) if self.second_order else None,
                "tension": float(self.tension),
                "tension_tolerance": float(self.tension_tolerance),
                "tension_where": dict(self.tension_where) if self.tension_where else None,
                "tension_measure": self.tension_measure,
                "passed": bool(self.ok),
                "failed": self.failed(),
                "enforced": list(self.enforced),
                "seconds": float(self.seconds)}


def nodal_tension(bodies: list, tolerance: Callable, least: float, F: list[np.ndarray],
                  own: list, measure: Callable[[object, np.ndarray], np.ndarray]
                  ) -> tuple[float, float, dict | None]:
    """Invariant (c), the nodal measure, for any dimension: ``measure(surface, forces)`` is a
    body's tensile reading per boundary node (F·n, a quadratic facet's corner read with its
    midpoints: the surface kind's, :mod:`.plane`, :mod:`.check3d`). Returns the largest over
    the largest nodal force (0 where none), its body's tolerance (``tolerance(body)``; the
    least of the bodies', or ``least`` where there are none, when nothing is tensile) and where
    it is (``{"body", "node", "value"}``, or None)."""
    scale = max((float(np.linalg.norm(f, axis=1).max(initial=0.0)) for f in F), default=0.0)
    least = min((tolerance(b) for b in bodies), default=least)
    if scale == 0:
        return 0.0, least, None
    worst = None  # (value / scale / tolerance, value, body, point number)
    for b, f, g in zip(bodies, F, own):
        if not len(f):
            continue
        fn = measure(g, f)
        k = int(np.argmax(fn))
        ratio = fn[k] / scale / tolerance(b)
        if fn[k] > 0 and (worst is None or ratio > worst[0]):
            worst = (ratio, float(fn[k]), b, int(g.b.nodes[k]))
    if worst is None:
        return 0.0, least, None
    _, value, b, node = worst
    return value / scale, tolerance(b), {"body": b.name, "node": node, "value": value}
