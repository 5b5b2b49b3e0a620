"""The two correction formulas of thesis §4.2 (eqs. 4.2.4 and 4.2.7) and their invariants."""

import numpy as np
import pytest

from vfem.contact.laws.corrections import (
    compatibility_displacement,
    compatibility_force,
    equilibrium_force,
)

rng = np.random.default_rng(0)
KA = rng.uniform(1, 1e4, 50)
KB = rng.uniform(1, 1e4, 50)
P = rng.uniform(-1, 1, 50)


def test_compatibility_shares_close_the_gap_without_unbalancing():
    ua = compatibility_displacement(KA, KB, P)
    ub = compatibility_displacement(KB, KA, P)
    np.testing.assert_allclose(ua + ub, P, rtol=1e-13)  # eq. 4.2.1
    np.testing.assert_allclose(KA * ua, KB * ub, rtol=1e-12)  # eq. 4.2.3: dF_A + dF_B = 0
    np.testing.assert_allclose(compatibility_force(KA, KB, P), KA * ua, rtol=1e-13)


def test_equilibrium_corrections_remove_the_error_without_moving_apart():
    E = rng.uniform(-100, 100, 50)
    fa = equilibrium_force(KA, KB, E)
    fb = equilibrium_force(KB, KA, -E)  # B's own error is the opposite of A's
    np.testing.assert_allclose(fa - fb, -E, rtol=1e-12)  # eq. 4.2.6 in the pair's frame
    np.testing.assert_allclose(fa / KA, -fb / KB, rtol=1e-12)  # eq. 4.2.5: same motion


def test_thesis_numbers_of_section_4_2_1():
    # step 5: 0.5 in overlap, K_A = 1000, K_B = 2000 -> 333 lb, A 0.333 in, B 0.167 in
    assert compatibility_force(1000.0, 2000.0, 0.5) == pytest.approx(333.33, abs=0.01)
    assert compatibility_displacement(1000.0, 2000.0, 0.5) == pytest.approx(0.3333, abs=1e-4)
    assert compatibility_displacement(2000.0, 1000.0, 0.5) == pytest.approx(0.1667, abs=1e-4)
