"""The lighter dense route (issue 19, item 4): bodies condensed to the dofs the formulation reads,
the inverse computed in place, the pair matrix's factors reused, the memory model per backend."""

from __future__ import annotations

import numpy as np
import pytest

from vfem import linalg
from vfem.contact.solvers.bordered import ReusedFactor
from vfem.linalg.common import mirror, spd_inverse, spd_inverse_in_place
from vfem.memory import factor_entries
from vfem.solver import Analysis
from vfem_examples.hertz import HertzParameters, build


def _setup(rind_rows: bool, backend: str | None = None):
    """The Hertz example set up with its bodies condensed to the tracked dofs (``rind_rows``)
    or to the candidates alone."""
    analysis = Analysis(build(HertzParameters()), backend)
    pairs, surfaces = analysis.model.contact_surfaces()
    for s in surfaces:
        s.rind_rows = rind_rows
        s.body.setup(analysis.backend, condensed_dofs=s.condensed_dofs)
        s.compute_flexibility()
    return surfaces


@pytest.mark.parametrize("backend", linalg.available())
def test_candidates_alone_give_the_candidate_rows_of_the_tracked_flexibility(backend):
    """Condensing to the candidate dofs (what the paired variant reads) gives the same
    flexibility on them as condensing to every tracked dof and keeping their rows: the
    inverse stiffness among the candidates does not depend on which other dofs are condensed
    with them (round-off aside)."""
    tracked, candidates = _setup(True, backend), _setup(False, backend)
    for t, c in zip(tracked, candidates):
        assert t.G.shape == (2 * len(t.nodes), 2 * t.nc)
        assert c.G.shape == (2 * c.nc, 2 * c.nc)
        scale = np.abs(t.C).max()
        assert np.abs(c.C - t.C).max() <= 1e-10 * scale
        assert np.array_equal(c.C, c.C.T) and c.exactly_symmetric


def test_paired_variant_condenses_to_candidates_and_thesis_variant_to_the_rind():
    """The analysis condenses each body to what its formulation reads: the thesis variant
    locates nodes in the rind (its rows kept), the paired variant reads the candidates only."""
    for variant, rind in (("paired", False), ("thesis", True)):
        analysis = Analysis(build(HertzParameters(variant=variant)))
        analysis.setup()
        for s in analysis.surfaces:
            assert s.rind_rows is rind
            rows = len(s.nodes) if rind else s.nc
            assert s.G.shape == (2 * rows, 2 * s.nc)
            assert len(analysis.contact.positions(analysis.contact.new_state())[0]) > 0


@pytest.mark.parametrize("m", [1, 7, 1030, pytest.param(2100, marks=pytest.mark.slow)])
def test_in_place_inverse_is_the_inverse_to_the_bit(m):
    """The in-place inverse reads the upper triangle only (the lower may hold anything, as
    PARDISO's output does), returns the very bits of :func:`spd_inverse` of the symmetric
    matrix, in the memory it was given."""
    rng = np.random.default_rng(m)
    A = rng.standard_normal((m, m))
    S = A @ A.T + m * np.eye(m)
    work = S.copy()
    work[np.tril_indices(m, -1)] = np.nan
    out = spd_inverse_in_place(work)
    assert np.shares_memory(out, work)
    assert np.array_equal(out, spd_inverse(S))
    assert np.allclose(out @ S, np.eye(m), atol=1e-9)


def test_mirror_copies_one_triangle_onto_the_other():
    A = np.arange(49.0).reshape(7, 7)
    up = A.copy()
    mirror(up, from_upper=True, block=3)
    assert np.array_equal(up, np.triu(A) + np.triu(A, 1).T)
    low = A.copy()
    mirror(low, from_upper=False, block=3)
    assert np.array_equal(low, np.tril(A) + np.tril(A, -1).T)


def test_reused_factor_solves_as_numpy_and_factorizes_once_per_matrix():
    rng = np.random.default_rng(1)
    W = rng.standard_normal((40, 40)) + 40 * np.eye(40)
    calls = []

    def matrix():
        calls.append(1)
        return W.copy()

    cache = ReusedFactor()
    for _ in range(3):
        b = rng.standard_normal(40)
        x = cache.solve(("same",), matrix, b)
        assert np.allclose(x, np.linalg.solve(W, b), rtol=1e-12, atol=1e-14)
    assert len(calls) == 1
    cache.solve(("other",), matrix, b)
    assert len(calls) == 2
    assert cache.solve(("singular",), lambda: np.zeros((3, 3)), np.ones(3)) is None


@pytest.mark.skipif(not linalg.is_available("pardiso"), reason="PARDISO is not installed")
def test_pardiso_fill_model_is_near_what_pardiso_reports():
    """The memory model's PARDISO fill (vfem.memory) against PARDISO's own count of its
    factor's entries, on both Hertz bodies: within a factor of two either way (fitted on
    benchmarks/memory_model.py's cases to 0.8 to 1.1)."""
    for s in _setup(False, "pardiso"):
        reported = s.body.factor.factor_entries
        model = factor_entries(s.body.ndofs, len(s.condensed_dofs), "pardiso")
        assert reported > 0
        assert 0.5 * reported <= model <= 2.0 * reported


def test_large_kinematics_honours_a_search_distance_along_the_whole_path():
    """Under large kinematics every facet of the contact boundaries is a candidate by default
    (bodies may slide anywhere); a search distance given is honoured, with the sliding body
    followed all along its prescribed path (issue 19, item 7): the block's top facets under
    the punch's path are candidates, those well beyond either end of it are not."""
    import dataclasses

    from vfem_examples import sliding

    p = sliding.Parameters()
    config = sliding.config(p)
    default = config.build()
    _, everything = default.contact_surfaces()
    distance = 0.05
    limited = dataclasses.replace(config, contact=dataclasses.replace(
        config.contact, search_distance=distance)).build()
    _, surfaces = limited.contact_surfaces()
    block_all, block = everything[0], surfaces[0]
    assert block.body.name == "block"
    assert block.nc < block_all.nc  # fewer candidates
    x = block.X[: block.nc, 0]
    # the punch's lowest point travels from ``start`` to ``start + slide``; its face reaches
    # at most half its width either side of it
    lo, hi = p.start, p.start + p.slide
    reach = 0.5 * p.punch_width + distance + 2 * p.block_length / p.block_columns
    path = block_all.X[: block_all.nc, 0]
    under = path[(path >= lo) & (path <= hi)]
    assert np.isin(np.round(under, 12), np.round(x, 12)).all()  # the whole path is covered
    assert x.min() > lo - reach and x.max() < hi + reach
    assert block_all.X[: block_all.nc, 0].min() < lo - reach  # (the default reaches beyond)


def test_large_dense_operations_get_the_threads_within_the_safe_range():
    """vfem.threads.dense_threads gives the policy's threads to a dense operation only between
    DENSE_THREADS_FROM and DENSE_THREADS_UPTO (above it SciPy's OpenBLAS crashes in threaded
    Cholesky); one thread before and after."""
    from threadpoolctl import threadpool_info

    from vfem import threads

    threads.apply(2)

    def blas() -> set[int]:
        return {i["num_threads"] for i in threadpool_info() if i["internal_api"] == "openblas"}

    try:
        assert blas() == {1}
        with threads.dense_threads(threads.DENSE_THREADS_FROM):
            assert blas() == {2}
        assert blas() == {1}
        for order in (threads.DENSE_THREADS_FROM - 1, threads.DENSE_THREADS_UPTO + 1):
            with threads.dense_threads(order):
                assert blas() == {1}
    finally:
        threads.apply()


def test_max_strain_of_linear_triangles_from_the_average_strain_equals_the_quadrature():
    """Linear triangles have a constant strain: the fast reading (one sparse product) gives the
    largest principal strain and its element as the quadrature-point reading does."""
    from vfem.bodies import stresses

    model = build(HertzParameters(refinement=1))
    rng = np.random.default_rng(3)
    for body in model.bodies:
        body.assemble()
        u = rng.normal(size=body.ndofs) * 1e-3
        fast = stresses.max_strain(body, u)
        slow = stresses._max_strain_at_quadrature(body, u)
        assert fast[1] == slow[1]
        assert fast[0] == pytest.approx(slow[0], rel=1e-12)
