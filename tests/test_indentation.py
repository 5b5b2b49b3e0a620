"""The indentation example (issue 41, ``vfem_examples.indentation``): its theory and its
parameters. Its run is checked by its own verification (``summary.json``) in the slow set
(``tests/test_examples_invariants.py`` runs ``examples/indentation.toml``;
``tests/test_doc_numbers.py`` keeps ``docs/examples.md``'s numbers of it current)."""

from __future__ import annotations

import dataclasses
import math

import pytest

from vfem.errors import InputError
from vfem_examples import hertz, indentation


def test_the_onset_is_mcewens_and_the_yield_stress_puts_it_at_the_onset_force():
    """p0 / Y = 1.794 at 0.704 a for nu = 0.3 (Johnson, Contact Mechanics, §6.2: the line
    contact's first yield, von Mises); the onset force's Hertz half-width is the parameter's."""
    p = indentation.IndentationParameters()
    ratio, depth = indentation.onset(0.3)
    assert ratio == pytest.approx(1.794, abs=5e-4)
    assert depth == pytest.approx(0.704, abs=5e-4)
    th = indentation.theory(p)
    h = hertz.theory(indentation._hertz(p, th["onset_force"]))
    assert h["a_theory"] == pytest.approx(p.onset_half_width * p.radius, rel=1e-12)
    assert h["p0_theory"] / th["yield_stress"] == pytest.approx(ratio, rel=1e-12)
    config = indentation.config(p)
    cylinder = next(b for b in config.bodies if b.name == "cylinder")
    assert cylinder.material.yield_stress == pytest.approx(th["yield_stress"], rel=1e-12)
    # the platen's force: up and down through the onset, steps 1 % apart around it
    forces = [p.overload * (lf if lf <= 1 else 2 - lf) for lf in config.steps.load_factors]
    assert max(forces) == pytest.approx(p.overload)
    assert [round(f, 6) for f in forces[2:10]] == [0.96, 0.97, 0.98, 0.99, 1.0, 1.01, 1.02,
                                                   1.03]
    assert forces[-1] == pytest.approx(0.01) and math.isclose(forces[-2], 0.2)


@pytest.mark.parametrize("change, words", [
    ({"overload": 1.0}, "overload must exceed 1.03"),
    ({"overload": 1e300}, "overload must be at most 20"),
    ({"onset_half_width": 0.2}, "onset_half_width must be at most 0.05"),
    ({"onset_half_width": -1.0}, "onset_half_width must be a finite number > 0"),
    ({"hardening_modulus": -1.0}, "hardening_modulus must be a finite number >= 0"),
    ({"facets_per_half_width": 0}, "facets_per_half_width must be at least 1"),
])
def test_bad_parameters_are_named(change, words):
    p = dataclasses.replace(indentation.IndentationParameters(), **change)
    with pytest.raises(InputError, match=words):
        indentation.validate(p)
