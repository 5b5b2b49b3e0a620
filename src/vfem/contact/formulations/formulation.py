"""The contract between the solver and a contact formulation.

The incremental driver (:class:`vfem.solver.Analysis`) runs the steps; a formulation resolves the
contact of one step. Every formulation — the paired variant with small
(:class:`~vfem.contact.formulations.paired.PairedContact`) or large displacements
(:class:`~vfem.contact.formulations.large.LargeDeformationContact`), the thesis's plain reading
(:class:`~vfem.contact.formulations.algorithm.VirtualElementContact`) and the classical baselines
(:class:`~vfem.contact.formulations.baselines.GlobalContact`) — implements
:class:`ContactFormulation`, and declares what it can do as data (:class:`Capabilities`), which the
model's checks read (:func:`check_capabilities`) instead of a hand-written rule per formulation.

:func:`formulation_class` picks the formulation of a model's settings and kinematics.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

from ...errors import InputError
from ..capabilities import Capabilities
from ..laws import FRICTION_LAWS, friction_law

if TYPE_CHECKING:
    from ...bodies.results import BodyStepResult
    from ..geometry import ContactSurface
    from ..state import ContactState, IterationRecord, SolveResult


class ContactFormulation(Protocol):
    """What the solver drives (see the module docstring)."""

    capabilities: Capabilities
    surfaces: list[ContactSurface]
    #: the penetration the formulation works to (the invariants' allowance)
    penetration_tolerance: float

    def new_state(self) -> ContactState:
        """The state before the first step: no contact force."""

    def solve(self, state: ContactState,
              on_iteration: Callable[[IterationRecord], None] | None = None) -> SolveResult:
        """Resolve the contact at ``state``'s load factor (and platen force), from ``state``
        (the last converged one, modified in place into the new one)."""

    def fields(self, state: ContactState, result: SolveResult) -> dict[str, BodyStepResult]:
        """The full-mesh results of a converged state, per body name."""


def formulation_class(settings, large: bool):
    """The formulation of the contact settings (``method``, ``variant``) and kinematics: a
    class, or a :class:`~vfem.contact.formulations.composed.Composed` (with friction); either
    declares its ``capabilities`` and builds the formulation when called."""
    if settings.method != "vfem":
        from .baselines import GlobalContact

        return GlobalContact
    if large:
        if settings.frictional:
            from .large_friction import FrictionalLargeContact

            return FrictionalLargeContact
        from .large import LargeDeformationContact

        return LargeDeformationContact
    if settings.variant == "paired":
        if settings.frictional:
            from .friction import FrictionalPairedContact

            return FrictionalPairedContact
        from .paired import PairedContact

        return PairedContact
    from .algorithm import VirtualElementContact

    return VirtualElementContact


def check_capabilities(model) -> None:
    """Raise :class:`InputError` for a body the model's formulation cannot analyse (its element
    order, kinematics or dimension), naming the body and what to choose instead."""
    settings = model.contact
    large = model.iterates  # a body corrected by Newton's method
    cls = formulation_class(settings, large)
    caps = cls.capabilities
    if settings.method != "vfem":
        for b in model.bodies:
            # (a body corrected by Newton's method under small kinematics, of a material that
            # carries state, is not linear either: the classical methods solve K u = f once)
            if ("large" if b.iterates else "small") not in caps.kinematics \
                    or b.order not in caps.orders:
                raise InputError(f"model {model.name!r}, body {b.name!r}: the classical "
                                 f"contact methods (contact.method = {settings.method!r}) need "
                                 f"{_orders(caps)} and small kinematics"
                                 + ("" if b.large or not b.iterates else
                                    " with a material that carries no state")
                                 + "; use contact.method = 'vfem'")
    elif large and settings.variant != "paired":
        raise InputError(f"model {model.name!r}: "
                         + ("large kinematics" if any(b.large for b in model.bodies) else
                            "a material that carries state (Newton's method)")
                         + " needs the paired contact variant")
    pairs = model.pairs()  # (parsed once here)
    if not caps.sides and pairs.sided:
        what, use = ((f"contact.method = {settings.method!r}", "contact.method = 'vfem'")
                     if settings.method != "vfem" else
                     (f"contact.variant = {settings.variant!r}", "the paired variant"))
        raise InputError(f"model {model.name!r}: contact_pairs names boundaries of a body "
                         f"(a pair's side), which the paired variant reads and {what} does "
                         f"not: name whole bodies, or use {use} (the default)")
    names = {b.name for b in model.bodies}
    index = {b.name: i for i, b in enumerate(model.bodies)}
    for pair in settings.pairs:
        unknown = [n for n in pair.bodies if n not in names]
        if unknown:
            raise InputError(f"model {model.name!r}: contact.pairs {list(pair.bodies)!r}: no "
                             f"body named {unknown[0]!r} (bodies: {', '.join(sorted(names))})")
        one = {index[n] for n in pair.bodies}
        if len(one) == 1 and frozenset(one) not in pairs:  # a body's own sides
            raise InputError(f"model {model.name!r}: contact.pairs {list(pair.bodies)!r} names "
                             "one body twice, and contact_pairs pairs no sides of it with "
                             "each other (a body's contact with itself is a pair of its two "
                             "sides: two of its boundaries named in contact_pairs, one side "
                             "named twice, or the body's self_contact = true)")
    # each pair's law and its parameters (the laws check their own), whether or not it acts
    laws = [(pair, friction_law(pair)) for pair in settings.pairs]
    if settings.frictional and (not caps.friction or (
            settings.method != "vfem"
            and settings.method not in getattr(cls, "FRICTIONAL_METHODS", ()))):
        what = (f"contact.method = {settings.method!r}" if settings.method != "vfem" else
                f"contact.variant = {settings.variant!r}")
        where = (f"contact.friction = {settings.friction:g}" if settings.friction > 0 else
                 "contact.pairs " + ", ".join(repr(list(p.bodies)) for p in settings.pairs
                                              if p.friction > 0))
        raise InputError(f"model {model.name!r}: friction ({where}) is available with the "
                         f"paired variant and the lagrange baseline only, not yet with {what}; "
                         "set it to 0 for frictionless contact")
    if settings.frictional:
        what = ("large kinematics" if large else f"contact.method = {settings.method!r}"
                if settings.method != "vfem" else f"the {caps.name} variant")
        for pair, law in laws:
            missing = [r for r in law.reads if r not in caps.friction]
            if law.acts and missing:
                taken = [name for name, other in FRICTION_LAWS.items()
                         if set(other.reads) <= set(caps.friction)]
                raise InputError(f"model {model.name!r}: contact.pairs {list(pair.bodies)!r}: "
                                 f"the {law.name} friction law reads its {' and '.join(missing)}, "
                                 f"which the {caps.name} formulation does not: not yet with "
                                 f"{what}; use law = " + " or ".join(repr(n) for n in taken))
        platen = next((b for b in model.bodies if b.platen is not None), None)
        if large and platen is not None:
            raise InputError(f"model {model.name!r}, body {platen.name!r}: a force-controlled "
                             "platen with friction is available with small kinematics only, not "
                             "yet with large kinematics; prescribe the body's motion instead "
                             "([[bodies.prescribed]]), or use small kinematics")
    touching = bodies_that_may_touch(model)
    for b in model.bodies:
        # (a body that touches no other takes any element: under large kinematics too, where
        # the Newton formulation needs linear facets of the bodies it pairs)
        if b.order not in caps.orders and not (large and b.name not in touching):
            if large:
                what = ("a large-kinematics body" if any(o.large for o in model.bodies) else
                        "a body of a material that carries state (Newton's method)")
                raise InputError(f"model {model.name!r}, body {b.name!r}: contact with "
                                 f"{what} needs {_orders(caps)} on every body that touches "
                                 "another")
            raise InputError(f"model {model.name!r}, body {b.name!r}: the {caps.name} variant "
                             f"supports {_orders(caps).replace(' (', ' only (', 1)}; use the "
                             "paired variant for quadratic elements")
        dim = b.mesh.p.shape[0]
        if b.name not in touching:
            continue
        if dim not in caps.dimensions:
            raise InputError(f"model {model.name!r}, body {b.name!r}: {caps.name} contact "
                             f"supports {' and '.join(f'{d}D' for d in caps.dimensions)} "
                             f"bodies, this one is {dim}D; 3D contact needs the paired "
                             "variant, small kinematics and linear elements (a 3D body that "
                             "touches no other runs without contact)")
        if dim == 3 and b.order not in caps.orders_3d:
            raise InputError(f"model {model.name!r}, body {b.name!r}: 3D contact "
                             + ("with friction " if settings.frictional else "")
                             + ("supports linear elements only (order 1)"
                                if caps.orders_3d == (1,) else "supports linear elements and "
                                "quadratic tetrahedra")
                             + "; use linear elements (a 3D body that touches no other may be "
                             "quadratic)")
        if dim == 3 and b.order == 2 and b.mesh.t.shape[0] == 8:
            raise InputError(f"model {model.name!r}, body {b.name!r}: 3D contact of quadratic "
                             "hexahedra (9-node facets) is not implemented; use quadratic "
                             "tetrahedra or linear hexahedra (a 3D body that touches no other "
                             "may be a quadratic hexahedron)")

def bodies_that_may_touch(model) -> set[str]:
    """The names of the bodies in a pair that may touch (``contact_pairs``, by default every
    pair of the model's bodies). A body in none (a model of one body, or one its
    ``contact_pairs`` leave out) is analysed without contact: its dimension is not the contact
    formulation's to refuse (a 3D body alone runs before 3D contact does, issue 21)."""
    return {n for pair in model.pairs().names(model.bodies) for n in pair}


def _orders(caps: Capabilities) -> str:
    """'linear elements (order 1)' or 'linear or quadratic elements (order 1 or 2)'."""
    names = {1: "linear", 2: "quadratic"}
    return (f"{' or '.join(names[o] for o in caps.orders)} elements "
            f"(order {' or '.join(str(o) for o in caps.orders)})")


__all__ = ["Capabilities", "ContactFormulation", "bodies_that_may_touch", "check_capabilities",
           "formulation_class"]
