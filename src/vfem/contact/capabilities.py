"""What a contact formulation supports, declared as data (:mod:`vfem.contact.formulation`)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Capabilities:
    """What a formulation supports, as data.

    ``invariants``: what a broken invariant of :mod:`vfem.contact.check` does to a step —
    ``"enforced"`` (the step fails and is cut), ``"recorded"`` (recorded and warned about: the
    thesis's plain reading leaves errors by design) or ``"compared"`` (recorded silently: a
    baseline's answer is its own, compared with vfem's). ``cuts_steps``: whether a failed step
    is retried with a smaller increment (a baseline's linear frictionless answer does not depend
    on the path, so its failure is final).
    """

    name: str
    orders: tuple[int, ...]
    kinematics: tuple[str, ...]
    dimensions: tuple[int, ...]
    friction: tuple[str, ...]
    invariants: str = "enforced"
    cuts_steps: bool = True
