"""The friction laws behind one protocol (issue 38: a new law is a class in the laws stage and
its settings, not a change to every frictional formulation).

A law defined here, outside the library, and registered by name runs in the frictional
formulations through :class:`vfem.contact.laws.FrictionLaw` alone, taken by those whose
capabilities read what it asks (``reads``): a copy of Coulomb's law under another name gives
Coulomb's answers bit for bit, and a law whose coefficient weakens with the slip a node has
accumulated makes a block dragged far carry the weakened coefficient times its normal force; the
``lagrange`` baseline, which keeps no slip per node, refuses it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from models import built
from test_friction import BLOCKS, forces
from vfem.contact.laws import (
    FRICTION_LAWS,
    beyond_cone,
    friction_law,
    law_bounds,
    law_record,
    law_text,
    reaches_cone,
    slip_onset,
)
from vfem.contact.settings import PairFriction
from vfem.errors import InputError

#: the pair entry that names the test's law
ENTRY = '[[contact.pairs]]\nbodies = ["lower", "upper"]\nfriction = 0.3\nlaw = "{law}"\n'


@dataclass(frozen=True)
class CoulombCopy:
    """Coulomb's law under another name (what a law registered from outside runs through)."""

    mu: float
    name: ClassVar[str] = "coulomb_copy"
    parameters: ClassVar[tuple[str, ...]] = ()
    reads: ClassVar[tuple[str, ...]] = ("coefficients",)
    compliance: ClassVar[float] = 0.0

    @classmethod
    def of(cls, pair, where):
        return cls(float(pair.friction))

    @property
    def acts(self) -> bool:
        return self.mu > 0

    def static(self, slip):
        return np.full(len(slip), self.mu)

    def dynamic(self, slip):
        return np.full(len(slip), self.mu)

    def record(self) -> dict:
        return {"law": self.name, "mu": self.mu}


@dataclass(frozen=True)
class Weakening(CoulombCopy):
    """mu (``friction``) until a node has slipped ``CRITICAL`` over the converged steps, then
    ``WEAK``: a slip-weakening law, static and dynamic alike."""

    name: ClassVar[str] = "weakening"
    reads: ClassVar[tuple[str, ...]] = ("coefficients", "slip")
    CRITICAL: ClassVar[float] = 0.02
    WEAK: ClassVar[float] = 0.2

    def static(self, slip):
        return np.where(slip < self.CRITICAL, self.mu, self.WEAK)

    def dynamic(self, slip):
        return self.static(slip)


@pytest.fixture
def registered(monkeypatch):
    """The test's laws registered by name (nothing else: the formulations take them by what
    they read)."""
    for law in (CoulombCopy, Weakening):
        monkeypatch.setitem(FRICTION_LAWS, law.name, law)


def dragged(law: str | None, method: str = "vfem"):
    """The sliding block of ``test_friction`` (pressed, then dragged 0.1 in four steps of
    0.025, mu 0.3), with its pair following ``law`` (None: the model's Coulomb law), by the
    contact ``method``."""
    text = BLOCKS.format(mu=0.3, shift=0.1).replace(
        "[contact]\n", f'[contact]\nmethod = "{method}"\n', 1)
    if law is not None:
        text = text.replace("[[bodies]]", ENTRY.format(law=law) + "[[bodies]]", 1)
    return forces(built(text))


def test_a_law_registered_from_outside_runs_as_the_built_in_one(registered):
    """Coulomb's law under another name: every contact force of every step bit for bit."""
    _, plain = dragged(None)
    _, copy = dragged(CoulombCopy.name)
    for name in ("lower", "upper"):
        np.testing.assert_array_equal(copy[name], plain[name])


def test_a_slip_weakening_law_carries_its_weakened_coefficient_once_slipped(registered):
    """Dragged 0.05 before the last step (less the blocks' elastic shear, about 1e-3), every
    node has slipped past 0.02: in the last step the block slides at the weak coefficient,
    0.2 times its normal force exactly (1e-12, a traction field of nodes all on the cone); a
    step in which nodes have not slipped that far yet carries more."""
    result, f = dragged(Weakening.name)
    lower, upper = f["lower"], f["upper"]
    np.testing.assert_allclose(lower, -upper, rtol=0, atol=1e-12 * np.abs(lower).max())
    last = lower[-1]
    assert abs(abs(last[0]) / abs(last[1]) - Weakening.WEAK) < 1e-12
    first_slide = lower[2]  # load factor 0.625: the first step of the drag
    assert abs(first_slide[0]) / abs(first_slide[1]) > Weakening.WEAK + 0.05
    status = result.steps[-1].bodies["upper"].friction_status
    assert np.all(status[status > 0] == 2)
    # the closing screen and the figures word a law that brings no text or bounds of its own
    assert law_text(law_record(Weakening(0.3))) == "weakening, mu = 0.3"
    assert law_bounds(law_record(Weakening(0.3))) == []


def test_a_law_asking_what_a_formulation_does_not_read_is_refused_naming_it(registered):
    """The lagrange baseline keeps no accumulated slip: the slip-weakening law is refused, in
    one message naming the pair, the law, what it reads and the laws the baseline takes."""
    with pytest.raises(InputError, match="the weakening friction law reads its slip, which the "
                                         "classical formulation does not: not yet with "
                                         "contact.method = 'lagrange'; use law = 'coulomb' or "
                                         "'static_dynamic' or 'coulomb_copy'"):
        dragged(Weakening.name, "lagrange")


def test_the_rule_and_the_records():
    """The one rule of the cone (a node at rest reaches the static coefficient, a sliding one
    the dynamic), and what a law records of itself read back as text and bounds."""
    pair = PairFriction(("a", "b"), 0.3, "static_dynamic", static_friction=0.4)
    law = friction_law(pair)
    onset = slip_onset(law, np.array([False, True]), np.zeros(2))
    np.testing.assert_array_equal(onset, [0.4, 0.3])
    q = np.array([10.0, 10.0])
    np.testing.assert_array_equal(reaches_cone(np.array([4.0, 2.9]), q, onset), [True, False])
    np.testing.assert_array_equal(beyond_cone(np.array([4.0 * (1 + 1e-6), 3.0]), q, onset),
                                  [True, False])
    rec = law_record(law)
    assert rec == {"law": "static_dynamic", "mu_static": 0.4, "mu_dynamic": 0.3}
    assert law_text(rec) == "static mu = 0.4, dynamic mu = 0.3"
    assert law_bounds(rec) == [("mu_s q, stick limit", 0.4), ("mu_d q, slip", 0.3)]
    assert law_record(friction_law(PairFriction(("a", "b"), 0.0))) == {"law": "frictionless"}
    elastic = friction_law(PairFriction(("a", "b"), 0.3, "elastoplastic", slip_stiffness=4.0))
    assert elastic.compliance == 0.25 and law_text(law_record(elastic)).startswith("elasto")
