"""The block-indentation example (issue 41, ``vfem_examples.block_indentation``): its theory,
its mesh and its parameters. Its run is checked by its own verification (``summary.json``) in
the slow set (``tests/test_examples_invariants.py`` runs ``examples/block_indentation.toml``;
``tests/test_doc_numbers.py`` keeps ``docs/examples.md``'s numbers of it current)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vfem.errors import InputError
from vfem_examples import block_indentation as bi
from vfem_examples import hertz, indentation


def test_the_onset_is_mcewens_in_the_block_and_the_mesh_resolves_it():
    """p0 / Y = 1.794 at 0.704 a for the block's nu = 0.3; the onset force's Hertz half-width
    is the parameter's; the block's elements at the contact are a_peak / facets along its top
    and as deep (graded in depth), and it is block_size R wide and deep."""
    p = bi.BlockIndentationParameters()
    th = bi.theory(p)
    assert (th["p0_over_Y"], th["depth_over_a"]) == indentation.onset(0.3)
    h = hertz.theory(bi._hertz(p, th["onset_force"]))
    assert h["a_theory"] == pytest.approx(p.onset_half_width * p.radius, rel=1e-12)
    assert h["p0_theory"] / th["yield_stress"] == pytest.approx(th["p0_over_Y"], rel=1e-12)
    model = bi.build(p)
    block = next(b for b in model.bodies if b.name == "block")
    x, y = block.mesh.p
    h_fine = th["a_peak"] / p.facets_per_half_width
    xs, ys = np.unique(np.round(x, 12)), np.unique(np.round(y, 12))
    under = xs[xs <= th["a_peak"]]
    # (the nodes fit a whole number of elements: a size within a few % of h_fine, not above)
    assert 0.95 * h_fine <= np.diff(under).max() <= h_fine * (1 + 1e-9)
    deep = ys[ys >= -th["depth_over_a"] * th["a_onset"] * 2]
    assert 0.95 * h_fine <= np.diff(deep).max() <= h_fine * (1 + 1e-9)
    assert x.max() == pytest.approx(p.block_size) and y.min() == pytest.approx(-p.block_size)
    assert isinstance(block.material, type(bi.config(p).bodies[1].material))
    assert block.material.yield_stress == pytest.approx(th["yield_stress"], rel=1e-12)


@pytest.mark.parametrize("change, words", [
    ({"overload": 1.0}, "overload must exceed 1.03"),
    ({"overload": 1e300}, "overload must be at most 20"),
    ({"onset_half_width": 0.2}, "onset_half_width must be at most 0.05"),
    ({"block_size": 0.05}, "block_size must be at least 20 times"),
    ({"growth": -1.0}, "growth must be a finite number > 0"),
    ({"hardening_modulus": -1.0}, "hardening_modulus must be a finite number >= 0"),
    ({"kinematics": "updated"}, "kinematics must be 'small' or 'total'"),
    ({"facets_per_half_width": 0}, "facets_per_half_width must be at least 1"),
    ({"facets_per_half_width": 400}, "more than"),
])
def test_bad_parameters_are_named(change, words):
    p = dataclasses.replace(bi.BlockIndentationParameters(), **change)
    with pytest.raises(InputError, match=words):
        bi.validate(p)


def test_the_loading_passes_the_onset_in_steps_of_a_hundredth():
    p = bi.BlockIndentationParameters()
    factors = bi.config(p).steps.load_factors
    forces = [p.overload * (lf if lf <= 1 else 2 - lf) for lf in factors]
    assert max(forces) == pytest.approx(p.overload)
    assert [round(f, 6) for f in forces[2:10]] == [0.96, 0.97, 0.98, 0.99, 1.0, 1.01, 1.02,
                                                   1.03]
    assert forces[-1] == pytest.approx(0.01) and math.isclose(forces[-2], 0.2)
