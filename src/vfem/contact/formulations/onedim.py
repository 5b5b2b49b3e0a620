"""The one-dimensional analogy of thesis §4.2: two bodies touching end to end.

Each body is reduced to its contact end: a displacement along the line of contact, the reaction
the body develops there, and a stiffness. The iteration is the same as in two dimensions
(predict, check compatibility and equilibrium, correct with eqs. 4.2.4 and 4.2.7 from
:mod:`vfem.contact.laws.corrections`, re-solve), which makes this module the clearest statement of
the method and a check of the shared formulas against the thesis's worked example (§4.2.1).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Protocol

from ..laws import compatibility_displacement, equilibrium_force

log = logging.getLogger(__name__)


class EndBody(Protocol):
    """A body seen from its contact end: its reaction and (secant) stiffness at a compression.

    The compression is the displacement of the contact end into the body, the only motion that
    contact produces in 1D; a positive reaction is compressive (see ``corrections``).
    """

    def reaction(self, compression: float) -> float: ...

    def stiffness(self, compression: float) -> float: ...


@dataclass(frozen=True)
class SecantSpring:
    """A nonlinear spring whose force is ``K(c) * d``: a *secant* stiffness of the compression d.

    ``K(c) = k0 * (1 + a*c + b*c**2)`` with ``c = d / length`` the fractional compression
    (thesis §4.2.1: spring A has k0 = 1000, a = 10; spring B has k0 = 2000, b = 20).
    """

    length: float
    k0: float
    a: float = 0.0
    b: float = 0.0

    def stiffness(self, compression: float) -> float:
        c = compression / self.length
        return self.k0 * (1.0 + self.a * c + self.b * c * c)

    def reaction(self, compression: float) -> float:
        return self.stiffness(compression) * compression


@dataclass
class Iteration1D:
    """One pass of the 1D contact iteration, in the quantities the thesis reports."""

    penetration: float
    equilibrium_error: float
    compatibility_force: float
    equilibrium_force_a: float
    equilibrium_force_b: float
    reaction_a: float
    reaction_b: float


@dataclass
class Step1D:
    step: int
    position: float | None  # where the springs meet; None while they are apart
    contact_force: float
    converged: bool
    iterations: list[Iteration1D] = field(default_factory=list)
    gap: float = 0.0


def solve_step(
    body_a: EndBody,
    body_b: EndBody,
    compression_a: float,
    compression_b: float,
    penetration: float,
    *,
    penetration_tolerance: float,
    equilibrium_tolerance: float,
    max_iterations: int = 50,
) -> tuple[float, float, list[Iteration1D], bool]:
    """Resolve the contact after a linear prediction that left ``penetration`` (>0: overlap).

    Returns the converged compressions of A and B, the iteration history and whether it
    converged. A contact force is applied to each end; its displacement follows from the body's
    current (secant) stiffness, and the check uses the body's true reaction, exactly as a
    nonlinear finite element code applies corrective forces and then evaluates internal forces.
    """
    history: list[Iteration1D] = []
    da, db = compression_a, compression_b
    for _ in range(max_iterations):
        ra, rb = body_a.reaction(da), body_b.reaction(db)
        in_contact = penetration > 0.0 or ra > 0.0 or rb > 0.0
        error = ra - rb  # own compressive force minus the opposing one, seen from A
        if not in_contact or (
            abs(penetration) <= penetration_tolerance and abs(error) <= equilibrium_tolerance
        ):
            return da, db, history, True
        ka, kb = body_a.stiffness(da), body_b.stiffness(db)
        seen_penetration = penetration
        # Compatibility (eq. 4.2.4): each end takes its share of the overlap; the force that
        # produces it is K_own * share (equal for A and B).
        comp_force = 0.0
        if abs(penetration) > penetration_tolerance:
            ua = compatibility_displacement(ka, kb, penetration)
            ub = compatibility_displacement(kb, ka, penetration)
            comp_force = float(ka * ua)
            da, db = da + float(ua), db + float(ub)
            penetration -= float(ua + ub)
        # Equilibrium (eq. 4.2.7), from the reactions at the state the check saw: each body's
        # own error is its reaction minus the other's.
        fa = fb = 0.0
        if abs(error) > equilibrium_tolerance:
            fa = float(equilibrium_force(ka, kb, error))
            fb = float(equilibrium_force(kb, ka, -error))
            ua, ub = fa / ka, fb / kb
            da, db = da + ua, db + ub
            penetration -= ua + ub
        history.append(Iteration1D(penetration=float(seen_penetration), equilibrium_error=error,
                                   compatibility_force=comp_force, equilibrium_force_a=fa,
                                   equilibrium_force_b=fb, reaction_a=ra, reaction_b=rb))
        log.debug("1D iteration %d: %s", len(history), history[-1])
    return da, db, history, False
