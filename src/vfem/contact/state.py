"""What the contact formulations share with the solver: the state a step starts from and
ends in, the record of each iteration, a solve's result, and the cycle watch.

Every formulation (:mod:`vfem.contact.formulations.formulation`) keeps its contact forces in a
:class:`ContactState`, or in a subclass with its own unknowns: the paired variant's traction
values (:class:`TractionState`), a baseline's active set and pressures
(:class:`BaselineState`); reports per body a :class:`Pairing` for the output fields, one
:class:`IterationRecord` per iteration and a :class:`SolveResult` per solve; a failed solve names
its failure kind (an :class:`~vfem.errors.AnalysisError` subclass) for the step cutter and the
stop diagnosis.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np

from ..errors import AnalysisError


@dataclass
class Pairing:
    """The pairs (own node, virtual node) of one body; arrays over its candidate nodes (nc).

    Forces are normal components in the pair's frame (see ``corrections``): positive is
    compressive. ``normal`` is the outward normal of the opposing facet at the virtual node.
    """

    other: np.ndarray  # (nc,) opposing body, -1 where none
    facet: np.ndarray  # (nc,) facet of the opposing body holding the virtual node
    t: np.ndarray  # (nc,) local coordinate of the virtual node on that facet
    normal: np.ndarray  # (nc, 2)
    penetration: np.ndarray  # (nc,) > 0 inside the other body
    embedded: np.ndarray  # (nc,) bool, located in the other body's rind
    stiffness: np.ndarray  # (nc,) own Castigliano normal stiffness
    virtual_stiffness: np.ndarray  # (nc,) opposing stiffness interpolated at the virtual node
    force: np.ndarray  # (nc,) own compressive normal force
    virtual_force: np.ndarray  # (nc,) opposing compressive force re-integrated on own elements
    participating: np.ndarray  # (nc,) bool: embedded or carrying compressive force
    #: (nc,) the formulation's normal traction at the node (nominal), where it has one; None:
    #: the results read nodal force over tributary length
    pressure: np.ndarray | None = None

    @property
    def equilibrium_error(self) -> np.ndarray:
        return self.force - self.virtual_force


@dataclass
class ContactState:
    """What every formulation's contact solve changes: the nodal contact forces on each body's
    candidates, the platen's motion and force. A formulation with unknowns of its own keeps
    them in a subclass (:class:`TractionState`, :class:`BaselineState`), which names them for
    checkpoints (:meth:`unknowns`, :meth:`with_unknowns`)."""

    load_factor: float
    platen_displacement: float
    forces: list[np.ndarray]  # per body (nc, dim), the force the other bodies apply on it
    released: list[np.ndarray] = field(default_factory=list)  # nodes released last iteration
    platen_force: float = 0.0  # the force the platen must apply (Platen.force_at)

    def copy(self) -> ContactState:
        """A deep copy (every array copied), of the same type."""
        out = copy.copy(self)
        out.forces = [f.copy() for f in self.forces]
        out.released = [r.copy() for r in self.released]
        return out.with_unknowns({k: v.copy() for k, v in self.unknowns().items()})

    def unknowns(self) -> dict[str, np.ndarray]:
        """The formulation's own unknowns, by name (none here)."""
        return {}

    def with_unknowns(self, arrays: dict[str, np.ndarray]) -> ContactState:
        """This state with its own unknowns set from ``arrays`` (:meth:`unknowns`'s names);
        returns it."""
        return self


@dataclass
class TractionState(ContactState):
    """The paired variant's state: per contact pair (its index), the normal traction values at
    its compatibility-side nodes, the unknowns of its iteration (thesis §4.4)."""

    tractions: dict[int, np.ndarray] = field(default_factory=dict)

    def unknowns(self) -> dict[str, np.ndarray]:
        return _named("traction", self.tractions)

    def with_unknowns(self, arrays: dict[str, np.ndarray]) -> TractionState:
        self.tractions = _by_pair("traction", arrays)
        return self


def _named(name: str, table: dict[int, np.ndarray]) -> dict[str, np.ndarray]:
    """A state's per-pair arrays ``table`` by their names in a checkpoint: ``<name>_<pair>``."""
    return {f"{name}_{k}": v for k, v in table.items()}


def _by_pair(name: str, arrays: dict[str, np.ndarray]) -> dict[int, np.ndarray]:
    """The per-pair arrays named ``<name>_<pair>`` among ``arrays`` (:func:`_named`), by pair."""
    return {int(k.removeprefix(f"{name}_")): v for k, v in arrays.items()
            if k.startswith(f"{name}_")}


@dataclass
class FrictionState(ContactState):
    """The frictional paired variant's state (:mod:`vfem.contact.formulations.friction`): as
    :class:`TractionState`, the normal traction values (``tractions``), and per contact pair
    (its index) at its compatibility-side nodes the tangential traction values (``shear``), the
    relative tangential displacement against the virtual node at the last converged step
    (``anchor``: a node that sticks keeps it within the step), the slip accumulated since the
    start (``slip``) and the penetration at the last converged step (``penetration``: where a
    node that comes into contact within a step first touched) and which nodes slip
    (``sliding``). All are path-dependent history: saved in checkpoints and restored exactly
    when a step is cut."""

    tractions: dict[int, np.ndarray] = field(default_factory=dict)
    shear: dict[int, np.ndarray] = field(default_factory=dict)
    anchor: dict[int, np.ndarray] = field(default_factory=dict)
    slip: dict[int, np.ndarray] = field(default_factory=dict)
    penetration: dict[int, np.ndarray] = field(default_factory=dict)
    #: per node, whether it slipped in the last correction (a static coefficient holds a node
    #: at rest until its traction reaches it; a sliding one slips at the dynamic coefficient)
    sliding: dict[int, np.ndarray] = field(default_factory=dict)

    #: the history arrays, by their names in :meth:`unknowns`
    HISTORY = ("shear", "anchor", "slip", "penetration", "sliding")

    def unknowns(self) -> dict[str, np.ndarray]:
        out = _named("traction", self.tractions)
        for name in self.HISTORY:
            out.update(_named(name, getattr(self, name)))
        return out

    def with_unknowns(self, arrays: dict[str, np.ndarray]) -> FrictionState:
        self.tractions = _by_pair("traction", arrays)
        for name in self.HISTORY:
            setattr(self, name, _by_pair(name, arrays))
        return self


@dataclass
class BaselineState(ContactState):
    """A classical baseline's state: per constraint row, whether it is active and the
    multiplier (pressure) the next step starts from (the augmented Lagrangian's)."""

    pressures: np.ndarray = field(default_factory=lambda: np.zeros(0))
    active: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    #: Coulomb friction (lagrange): per row the tangential force, the relative tangential
    #: displacement at the last converged step (a sticking node keeps it), the accumulated
    #: slip and whether the node slides; empty without friction
    shear: np.ndarray = field(default_factory=lambda: np.zeros(0))
    anchor: np.ndarray = field(default_factory=lambda: np.zeros(0))
    slip: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sliding: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))

    FRICTION = ("shear", "anchor", "slip", "sliding")

    def unknowns(self) -> dict[str, np.ndarray]:
        out = {"pressures": self.pressures, "active": self.active}
        out.update({name: getattr(self, name) for name in self.FRICTION
                    if len(getattr(self, name))})
        return out

    def with_unknowns(self, arrays: dict[str, np.ndarray]) -> BaselineState:
        self.pressures = arrays.get("pressures", np.zeros(0))
        self.active = np.asarray(arrays.get("active", np.zeros(0)), dtype=bool)
        for name in self.FRICTION:
            value = np.asarray(arrays.get(name, np.zeros(0)))
            setattr(self, name, value.astype(bool) if name == "sliding" else value)
        return self


#: every state type, by name: how a checkpoint reads a state back
STATE_TYPES = {cls.__name__: cls for cls in (ContactState, TractionState, FrictionState,
                                             BaselineState)}


@dataclass
class IterationRecord:
    """The errors seen by one check and the corrections that followed (history of a solve)."""

    iteration: int
    max_penetration: float
    max_equilibrium_error: float
    contact_nodes: int
    tension_nodes: int
    force_correction: float = 0.0
    displacement_correction: float = 0.0
    platen_error: float = 0.0  # platen reaction minus its scheduled force


@dataclass
class SolveResult:
    converged: bool
    iterations: int
    history: list[IterationRecord]
    pairings: list[Pairing]
    message: str = ""
    fixed_point: bool = False  # stopped where corrections cancel, errors above tolerance
    #: the failure kind of an unconverged solve (what the solver raises with ``message``)
    failure: type[AnalysisError] = AnalysisError
    #: the full-mesh results, where the solve has them itself (a baseline's global solution)
    fields: dict | None = None


class CycleWatch:
    """Notices a contact iteration that cycles, so the step is cut instead of iterated to its
    limit: the same contact set coming back after others (not merely staying the same, which is
    how an iteration converges) without the error having fallen since it was last seen there.

    Call once per iteration with the in-contact masks; returns a message naming the nodes that
    keep switching once that has happened ``limit`` times, else None.
    """

    def __init__(self, limit: int = 3):
        self.limit = limit
        self.seen: dict[bytes, float] = {}  # contact set -> the smallest error seen with it
        self.last: bytes | None = None
        self.last_sets: list[np.ndarray] | None = None
        self.flipping: list[set[int]] = []
        self.count = 0

    def __call__(self, sets: list[tuple[str, np.ndarray, np.ndarray]], error: float,
                 iteration: int) -> str | None:
        """``sets``: per side (body name, its node numbers, bool in-contact mask)."""
        masks = [np.asarray(m, dtype=bool) for _, _, m in sets]
        key = b"|".join(np.packbits(m).tobytes() + len(m).to_bytes(4, "little") for m in masks)
        if self.last_sets is not None and key != self.last:
            if not self.flipping:
                self.flipping = [set() for _ in sets]
            for k, (m0, m1) in enumerate(zip(self.last_sets, masks)):
                self.flipping[k].update(np.flatnonzero(m0 != m1).tolist())
            if key in self.seen and error >= self.seen[key]:
                self.count += 1
        self.seen[key] = min(error, self.seen.get(key, np.inf))
        self.last, self.last_sets = key, masks
        if self.count < self.limit:
            return None
        names = []
        for (body, nodes, _), flips in zip(sets, self.flipping):
            if flips:
                listed = ", ".join(str(int(nodes[i])) for i in sorted(flips)[:8])
                more = f" and {len(flips) - 8} more" if len(flips) > 8 else ""
                names.append(f"node{'s' if len(flips) > 1 else ''} {listed}{more} of body "
                             f"{body!r}")
        return (f"the contact iteration cycles: {'; '.join(names) or 'some nodes'} keep "
                f"switching in and out of contact while the error stays at {error:.3g} "
                f"(iteration {iteration})")


def closing_motion(penetration: np.ndarray, rate: np.ndarray, need: float) -> float:
    """The platen motion that just closes the smallest gap when nothing touches yet.

    ``rate`` is each node's change of penetration per unit platen motion; the platen moves the
    way its missing force points (the sign of ``need``). Zero when no gap can be closed so.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(np.isfinite(penetration) & (rate != 0), -penetration / rate, np.nan)
    ok = np.isfinite(d) & (np.sign(d) == np.sign(need))
    return float(d[ok][np.argmin(np.abs(d[ok]))]) if ok.any() else 0.0


__all__ = ["BaselineState", "ContactState", "CycleWatch", "FrictionState", "IterationRecord",
           "Pairing", "STATE_TYPES", "SolveResult", "TractionState", "closing_motion"]
