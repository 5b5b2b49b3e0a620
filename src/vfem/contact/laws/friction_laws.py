"""The friction laws of a contact pair, node by node (thesis §1.10: friction is "modular", a law
of its own beside the contact formulation; docs/method.md §11).

A law answers, per node, from the slip the node has accumulated over the converged steps:

* ``static(slip)``: the coefficient of the cone a sticking node's tangential traction lies
  within, which it must reach to start slipping;
* ``dynamic(slip)``: the coefficient of a slipping node's traction, ``|s| = dynamic q``;
* ``compliance``: the slip per unit tangential traction that a sticking node takes up
  elastically (0: it sticks rigidly);
* ``acts``: whether it has friction at all (a frictionless pair has no tangential unknowns).

The frictional formulations (small and large kinematics, 2D and 3D, and the ``lagrange``
baseline) read a pair's law through these alone, so that a new law is one class here, its
parameters' fields in :class:`~vfem.contact.settings.PairFriction` (if it has parameters of its
own); which formulations take it follows from what it asks them to read (``reads``, against
``Capabilities.friction``). :func:`friction_law` builds a pair's law from its settings and checks
them; :func:`slip_onset` and :func:`reaches_cone` are the one rule of when a node at rest or
sliding is on the cone. What a law records of itself
(:func:`law_record`) is what ``summary.json`` keeps, and :func:`law_text` and :func:`law_bounds`
read that record back, for the screen and the figures, without the model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Protocol

import numpy as np

from ...errors import InputError
from .coulomb import CONE_TOLERANCE


class FrictionLaw(Protocol):
    """What the frictional formulations ask of a pair's law (the module docstring)."""

    name: ClassVar[str]
    #: the optional fields of :class:`~vfem.contact.settings.PairFriction` the law reads
    parameters: ClassVar[tuple[str, ...]]
    #: what a formulation must read of it (``Capabilities.friction``): ``"coefficients"``, and
    #: ``"slip"`` where they depend on the accumulated slip, ``"compliance"`` where it has one
    reads: ClassVar[tuple[str, ...]]
    compliance: float

    @property
    def acts(self) -> bool:
        """Whether the pair has friction at all."""

    def static(self, slip: np.ndarray) -> np.ndarray:
        """Per node: the coefficient of the cone a sticking node lies within."""

    def dynamic(self, slip: np.ndarray) -> np.ndarray:
        """Per node: the coefficient of a slipping node's traction."""

    def record(self) -> dict:
        """The law and its coefficients by name (``summary.json``)."""

    @classmethod
    def of(cls, pair, where: str) -> FrictionLaw:
        """The law of one pair's settings, its own parameters checked (:func:`friction_law`)."""

    @staticmethod
    def text(record: dict) -> str:
        """A record of the law (:meth:`record`) in words, for the screen and the figures
        (optional: :func:`law_text` words any record)."""

    @staticmethod
    def bounds(record: dict) -> list[tuple[str, float]]:
        """The bounds of the tangential traction over the normal one its record puts on a
        node, each (what it is, its coefficient), for the friction figure (optional: none)."""


def _check_static_dynamic(pair, where: str) -> None:
    static = pair.static_friction
    if static is None:
        raise InputError(f"{where} {list(pair.bodies)!r}: the static_dynamic law needs "
                         f"static_friction (>= friction, {pair.friction:g})")
    if not (math.isfinite(static) and static >= pair.friction):
        raise InputError(f"{where} {list(pair.bodies)!r}: the static_dynamic law needs "
                         f"static_friction >= friction ({pair.friction:g}), got {static!r}")


def _check_elastoplastic(pair, where: str) -> None:
    stiffness = pair.slip_stiffness
    if stiffness is None:
        raise InputError(f"{where} {list(pair.bodies)!r}: the elastoplastic law needs "
                         "slip_stiffness (> 0), the tangential traction per unit elastic slip")
    if not (math.isfinite(stiffness) and stiffness > 0):
        raise InputError(f"{where} {list(pair.bodies)!r}: the elastoplastic law needs "
                         f"slip_stiffness > 0, got {stiffness!r}")


@dataclass(frozen=True)
class Coulomb:
    """Coulomb's law: stick while ``|s| < mu q``, slip at ``|s| = mu q``."""

    mu: float
    name: ClassVar[str] = "coulomb"
    parameters: ClassVar[tuple[str, ...]] = ()
    reads: ClassVar[tuple[str, ...]] = ("coefficients",)
    compliance: ClassVar[float] = 0.0

    @classmethod
    def of(cls, pair, where: str) -> Coulomb:
        return cls(float(pair.friction))

    @property
    def acts(self) -> bool:
        return self.mu > 0

    def static(self, slip: np.ndarray) -> np.ndarray:
        return np.full(len(slip), self.mu)

    def dynamic(self, slip: np.ndarray) -> np.ndarray:
        return np.full(len(slip), self.mu)

    def record(self) -> dict:
        return {"law": self.name, "mu": self.mu}

    @staticmethod
    def text(record: dict) -> str:
        return f"Coulomb, mu = {record.get('mu', 0.0):g}"

    @staticmethod
    def bounds(record: dict) -> list[tuple[str, float]]:
        return [("mu q, Coulomb limit", float(record["mu"]))] if record.get("mu") else []


@dataclass(frozen=True)
class StaticDynamic:
    """A node that sticks starts slipping at ``mu_static q`` and slips at ``mu q``
    (``static_friction`` and ``friction``)."""

    mu: float
    mu_static: float
    name: ClassVar[str] = "static_dynamic"
    parameters: ClassVar[tuple[str, ...]] = ("static_friction",)
    reads: ClassVar[tuple[str, ...]] = ("coefficients",)
    compliance: ClassVar[float] = 0.0

    @classmethod
    def of(cls, pair, where: str) -> StaticDynamic:
        _check_static_dynamic(pair, where)
        return cls(float(pair.friction), float(pair.static_friction))

    @property
    def acts(self) -> bool:
        return self.mu_static > 0

    def static(self, slip: np.ndarray) -> np.ndarray:
        return np.full(len(slip), self.mu_static)

    def dynamic(self, slip: np.ndarray) -> np.ndarray:
        return np.full(len(slip), self.mu)

    def record(self) -> dict:
        return {"law": self.name, "mu_static": self.mu_static, "mu_dynamic": self.mu}

    @staticmethod
    def text(record: dict) -> str:
        return f"static mu = {record['mu_static']:g}, dynamic mu = {record['mu_dynamic']:g}"

    @staticmethod
    def bounds(record: dict) -> list[tuple[str, float]]:
        return [("mu_s q, stick limit", float(record["mu_static"])),
                ("mu_d q, slip", float(record["mu_dynamic"]))]


@dataclass(frozen=True)
class Elastoplastic(Coulomb):
    """The thesis's friction-slippage law (§1.10), a regularised Coulomb law: below the cone the
    tangential traction is ``slip_stiffness`` times an elastic slip, on it the node slips at
    ``mu q`` (Coulomb's coefficients, with a compliance)."""

    slip_stiffness: float
    name: ClassVar[str] = "elastoplastic"
    parameters: ClassVar[tuple[str, ...]] = ("slip_stiffness",)
    reads: ClassVar[tuple[str, ...]] = ("coefficients", "compliance")

    @classmethod
    def of(cls, pair, where: str) -> Elastoplastic:
        _check_elastoplastic(pair, where)
        return cls(float(pair.friction), float(pair.slip_stiffness))

    @property
    def compliance(self) -> float:
        return 1.0 / self.slip_stiffness

    def record(self) -> dict:
        return {"law": self.name, "mu": self.mu, "slip_stiffness": self.slip_stiffness}

    @staticmethod
    def text(record: dict) -> str:
        return (f"elasto-plastic, mu = {record['mu']:g}, slip stiffness "
                f"{record['slip_stiffness']:g}")


#: the friction laws by the name ``[[contact.pairs]] law`` gives
FRICTION_LAWS: dict[str, type] = {law.name: law for law in (Coulomb, StaticDynamic, Elastoplastic)}


def friction_law(pair, where: str = "contact.pairs") -> FrictionLaw:
    """The law of one pair's friction settings (a :class:`~vfem.contact.settings.PairFriction`),
    its parameters checked: an unknown law, a parameter it needs missing or out of range, or one
    it does not read, raise :class:`InputError` naming the pair (``where``)."""
    pair.validate(where)  # the entry's own checks first (its bodies, friction >= 0)
    law = FRICTION_LAWS.get(pair.law)
    if law is None:
        raise InputError(f"{where} {list(pair.bodies)!r}: law must be one of "
                         f"{tuple(FRICTION_LAWS)}, got {pair.law!r}")
    out = law.of(pair, where)  # its own parameters, then those it does not read
    for other in FRICTION_LAWS.values():
        for field in other.parameters:
            if field not in law.parameters and getattr(pair, field) is not None:
                raise InputError(f"{where} {list(pair.bodies)!r}: {field} is for the "
                                 f"{other.name} law, not {pair.law!r}")
    return out


def law_record(law: FrictionLaw) -> dict:
    """What ``summary.json`` keeps of a pair's law: ``law`` and its coefficients by name, or
    ``{"law": "frictionless"}`` where it has no friction."""
    return law.record() if law.acts else {"law": "frictionless"}


def law_text(record: dict) -> str:
    """A recorded law (:func:`law_record`) in words: "Coulomb, mu = 0.3", "frictionless"; a
    law without its own ``text``, by its name and coefficients ("weakening, mu = 0.3"); a
    record of no law known (a folder written before the law was recorded), as Coulomb's."""
    name = record.get("law")
    if name == "frictionless":
        return "frictionless"
    law = FRICTION_LAWS.get(name)
    if law is None:
        return Coulomb.text(record)
    if hasattr(law, "text"):
        return law.text(record)
    return ", ".join([str(name)] + [f"{k} = {v:g}" for k, v in record.items()
                                    if k != "law" and isinstance(v, (int, float))])


def law_bounds(record: dict) -> list[tuple[str, float]]:
    """The bounds of the tangential traction over the normal one a recorded law puts on a node,
    each (what it is, its coefficient): [] for none known (nor for a law that gives none)."""
    law = FRICTION_LAWS.get(record.get("law"))
    return law.bounds(record) if hasattr(law, "bounds") else []


def slip_onset(law: FrictionLaw, was_sliding: np.ndarray, slip: np.ndarray) -> np.ndarray:
    """Per node, the coefficient its tangential traction must reach to count as on the cone (and
    slip): the dynamic one for a node that slid in the last correction, the static one for a node
    at rest."""
    return np.where(was_sliding, law.dynamic(slip), law.static(slip))


def reaches_cone(size: np.ndarray, q: np.ndarray, coefficient: np.ndarray) -> np.ndarray:
    """Per node, whether a tangential traction of magnitude ``size`` is on the cone
    ``coefficient q``, within :data:`CONE_TOLERANCE` (round-off only: the correction meets the
    cone exactly)."""
    return size >= (1.0 - CONE_TOLERANCE) * coefficient * q


def beyond_cone(size: np.ndarray, q: np.ndarray, coefficient: np.ndarray) -> np.ndarray:
    """Per node, whether a sticking node's tangential traction of magnitude ``size`` lies
    outside its cone ``coefficient q`` by more than :data:`CONE_TOLERANCE` (it must slip)."""
    return size > (1.0 + CONE_TOLERANCE) * coefficient * q
