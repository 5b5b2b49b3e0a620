"""Contact under large displacements (``vfem.contact.formulations.large``): the linearised
complementarity problem, and the gasket crushed by backs moving 0.5 each, loaded and unloaded, by
the total and the updated Lagrangian formulations."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

from vfem.contact.solvers import linear_complementarity
from vfem.solver import Analysis
from vfem_examples import gasket


def test_linear_complementarity_finds_the_touching_set():
    """Against every candidate set: the one with q >= 0 that leaves no node penetrating."""
    rng = np.random.default_rng(3)
    n = 7
    L = rng.normal(size=(n, n))
    W = L @ L.T + n * np.eye(n) + 0.2 * rng.normal(size=(n, n))  # nonsymmetric, P-matrix
    q0 = np.abs(rng.normal(size=n)) * (rng.random(n) < 0.5)
    p = rng.normal(size=n)
    q, d = linear_complementarity(W, q0, p, 1e-12)
    pen = p - W @ (q - q0)
    assert d == 0.0
    assert np.all(q >= 0) and np.all(pen <= 1e-10) and np.allclose(q * pen, 0.0, atol=1e-10)
    for bits in itertools.product([False, True], repeat=n):  # the solution is unique
        a = np.flatnonzero(bits)
        z = np.zeros(n)
        z[a] = np.linalg.solve(W[np.ix_(a, a)], p[a] + (W @ q0)[a]) if len(a) else []
        if np.all(z >= -1e-12) and np.all(p - W @ (z - q0) <= 1e-10):
            assert np.allclose(z, q, atol=1e-9)


@pytest.fixture(scope="module")
def crushed():
    """Backs moving 0.5 each (the soft half ring crushed into an S), ten steps each way."""
    p = gasket.Parameters(order=1, n_through=2, n_around=40, back_motion=0.5, steps=10)
    cfg = gasket.config(p)
    out = {}
    for kin in ("total", "updated"):
        bodies = tuple(dataclasses.replace(b, kinematics=kin) for b in cfg.bodies)
        out[kin] = Analysis(dataclasses.replace(cfg, bodies=bodies).build()).run()
    return out


@pytest.mark.slow
def test_large_kinematics_gasket_is_crushed_and_released(crushed):
    """Every scheduled load factor reached, loading and unloading; the two gaskets' forces
    balance; the unloading retraces the loading at the scheduled load factors, and every node
    is back at its start. (Since the held nodes, issue 41, the first unloading steps of this
    coarse model are cut, twice at most: at full crush four of the stiff ring's vertices carry
    the contact, and the tangent prediction of a whole unloading step releases them all, the
    S-shaped ring then springing 0.46 into the other; without held nodes it took no cut.)"""
    schedule = np.round(np.concatenate([np.arange(1, 11), np.arange(9, -1, -1)]) / 10, 12)
    for result in crushed.values():
        assert result.converged, result.message
        assert max(s.cuts for s in result.steps) <= 2
        lf = np.round([s.load_factor for s in result.steps], 12)
        at = [int(np.flatnonzero(lf == f)[0 if k < 10 else -1]) for k, f in enumerate(schedule)]
        assert all(a < b for a, b in zip(at, at[1:]))  # in order: each reached, none skipped
        forces = [np.linalg.norm(s.bodies["soft"].contact_force.sum(axis=0))
                  for s in result.steps]
        assert max(forces) > 1000.0  # the contact carries the whole crushing
        # the two gaskets' forces balance, and the unloading retraces the loading
        for s in result.steps:
            total = s.bodies["soft"].contact_force.sum(axis=0)
            assert np.allclose(total, -s.bodies["stiff"].contact_force.sum(axis=0),
                               atol=1e-9 * max(forces))
        loading = [forces[at[k]] for k in range(9)]
        unloading = [forces[at[18 - k]] for k in range(9)]
        assert np.allclose(loading, unloading, rtol=1e-8)
        assert max(np.abs(r.displacement).max() for r in result.steps[-1].bodies.values()) < 1e-10


@pytest.mark.slow
def test_total_and_updated_lagrangian_agree(crushed):
    for a, b in zip(crushed["total"].steps, crushed["updated"].steps):
        assert a.load_factor == b.load_factor
        for name in a.bodies:
            u, v = a.bodies[name].displacement, b.bodies[name].displacement
            assert np.abs(u - v).max() <= 1e-8 * max(np.abs(u).max(), 1e-3)


@pytest.mark.parametrize("model", ["sliding", "gasket"])
@pytest.mark.slow
def test_follower_stiffness_coloured_equals_one_coordinate_at_a_time(model, monkeypatch):
    """Perturbing together the coordinates that move the normals of disjoint sets of loaded
    nodes (``follower.follower_moves``) gives the follower stiffness of one
    perturbation per coordinate, to the round-off of the latter's difference of whole force
    vectors: in every iteration of a slide (the punch's corner region passing over the block's
    facets) and of the crushed gasket (curved against curved, the contact zone growing). A
    coordinate whose reach were drawn too small would miss entries of the size of the matrix."""
    from vfem.contact.formulations.large import LargeDeformationContact
    from vfem_examples import sliding

    if model == "sliding":
        p = sliding.Parameters(block_columns=60, block_rows=8, punch_columns=24, punch_rows=6,
                               slide=0.5, press_steps=2, slide_steps=3, start=-0.5)
        model_ = sliding.build(p)
    else:
        cfg = gasket.config(gasket.Parameters(order=1, n_through=2, n_around=40,
                                              back_motion=0.5, steps=5))
        bodies = tuple(dataclasses.replace(b, kinematics="total") for b in cfg.bodies)
        model_ = dataclasses.replace(cfg, bodies=bodies).build()
    original = LargeDeformationContact._follower_stiffness
    worst = []

    def both(self, state, coloured=True):
        J, B = original(self, state, coloured=True)
        J1, B1 = original(self, state, coloured=False)
        assert np.array_equal(J, J1)
        if len(J):
            worst.append(np.abs(B - B1).max() / np.abs(B1).max())
        return J, B

    monkeypatch.setattr(LargeDeformationContact, "_follower_stiffness", both)
    result = Analysis(model_).run()
    assert result.converged, result.message
    assert len(worst) > 10 and max(worst) < 1e-6, max(worst)
