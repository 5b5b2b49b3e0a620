"""The contact iteration every virtual-element formulation runs: check, then correct, until the
check passes (thesis Fig. 4.2, the inner loop; §4.3-4.5).

A formulation gives :func:`iterate` two functions: ``check(it)`` measures the state (the errors of
its compatibility and equilibrium conditions, the contact set) and says whether it has converged;
``correct(it, check)`` applies one correction (thesis eq. 4.2.4 and 4.2.7, or the paired variant's
matrix form) and may end the solve by a stopping rule of its own (the thesis variant's fixed
point). The loop is written once: the history of records, the progress callback, the cycle watch
(a contact set that comes back without the error falling is a failed step, not an iteration to
the limit) and the failure kinds of a solve that does not converge.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...errors import ContactCycling, ContactNotConverged
from ..settings import ContactSettings
from ..state import CycleWatch, IterationRecord, Pairing, SolveResult


@dataclass
class Check:
    """What one check of a state found."""

    record: IterationRecord
    converged: bool
    #: the contact set, per side (body name, its node numbers, bool in-contact mask), and the
    #: error the cycle watch compares; called only when the solve goes on
    sets: Callable[[], list[tuple[str, np.ndarray, np.ndarray]]]
    error: float
    #: per body, the output fields' view of this state (called once the solve ends)
    pairings: Callable[[], list[Pairing]]
    #: the message of a solve that ends here without converging in ``max_iterations``
    unconverged: Callable[[], str]
    #: called once when the check has converged, before the result is returned
    finish: Callable[[], None] | None = None
    #: what the formulation's correction needs from its check (its own types)
    extra: object = None


#: ``correct(it, check)`` returns None to go on, or (converged, fixed_point) to end the solve
Correct = Callable[[int, Check], "tuple[bool, bool] | None"]


def iterate(settings: ContactSettings, check: Callable[[int], Check], correct: Correct,
            on_iteration: Callable[[IterationRecord], None] | None = None) -> SolveResult:
    """Check, correct, ... until a check converges (see the module docstring); at most
    ``settings.max_iterations`` corrections. ``on_iteration`` gets every record as it is made
    (progress displays)."""
    history: list[IterationRecord] = []
    watch = CycleWatch()
    for it in range(settings.max_iterations + 1):
        c = check(it)
        history.append(c.record)
        if on_iteration is not None:
            on_iteration(c.record)
        if c.converged:
            if c.finish is not None:
                c.finish()
            return SolveResult(True, it, history, c.pairings())
        if it == settings.max_iterations:
            break
        cycling = watch(c.sets(), c.error, it)
        if cycling:
            return SolveResult(False, it, history, c.pairings(), cycling,
                               failure=ContactCycling)
        stop = correct(it, c)
        if stop is not None:
            converged, fixed_point = stop
            return SolveResult(converged, it, history, c.pairings(), fixed_point=fixed_point)
    return SolveResult(False, settings.max_iterations, history, c.pairings(), c.unconverged(),
                       failure=ContactNotConverged)
