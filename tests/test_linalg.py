"""The linear-algebra backends (vfem.linalg): every installed backend solves, gives the
flexibility on trailing dofs, and gives the same contact answer; choosing one by name.

SuperLU is always installed; PARDISO, CHOLMOD and MUMPS are tested where installed (their
parametrized cases are then absent, not skipped silently: ``test_superlu_is_always_there``
checks the list)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.sparse as sp

from vfem import linalg
from vfem.cli import main
from vfem.errors import AnalysisError, InputError
from vfem.mesh import rectangle
from vfem.solver import Analysis
from vfem_examples.hertz import HertzParameters, build

INSTALLED = linalg.available()


def stiffness() -> sp.csc_matrix:
    """A small plane-strain stiffness, held on one side: symmetric positive definite."""
    from skfem import Basis, ElementQuad1, ElementVector, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    mesh = rectangle(0.0, 0.0, 2.0, 1.0, nx=12, ny=6)
    basis = Basis(mesh, ElementVector(ElementQuad1()))
    K = asm(linear_elasticity(*lame_parameters(1000.0, 0.3)), basis).tocsr()
    fixed = basis.get_dofs(mesh.boundaries["left"]).all()
    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    return K[free][:, free].tocsc()


def test_superlu_is_always_there():
    assert "superlu" in INSTALLED
    assert linalg.resolve("superlu") == "superlu"
    assert linalg.resolve("auto") == INSTALLED[0]


@pytest.mark.parametrize("backend", INSTALLED)
def test_every_backend_solves_and_gives_the_flexibility(backend):
    K = stiffness()
    dense = np.linalg.inv(K.toarray())
    rng = np.random.default_rng(0)
    b = rng.standard_normal((K.shape[0], 3))
    trailing = rng.choice(K.shape[0], size=20, replace=False)  # unsorted, like contact dofs
    for tr in (None, trailing):
        f = linalg.factorize(K, backend, trailing=tr, groups=np.arange(K.shape[0]) // 2)
        x = f.solve(b)
        assert np.linalg.norm(K @ x - b) <= 1e-10 * np.linalg.norm(b)
        assert np.allclose(f.solve(b[:, 1]), x[:, 1], rtol=1e-12, atol=1e-14)
    G = f.trailing_inverse
    ref = dense[np.ix_(trailing, trailing)]
    assert np.abs(G - ref).max() <= 1e-10 * np.abs(ref).max()
    assert np.array_equal(G, G.T)


@pytest.mark.parametrize("backend", INSTALLED)
def test_every_dof_trailing_gives_the_whole_inverse(backend):
    """A body whose every free dof is a contact dof (one layer of elements touched on both
    faces): the flexibility is the whole inverse (PARDISO takes it dense, its Schur mode on
    the whole matrix read outside its arrays), in the order of the dofs given, and the
    factorization still solves. Round-off: the inverse's condition times machine epsilon."""
    K = stiffness()
    dense = np.linalg.inv(K.toarray())
    n = K.shape[0]
    trailing = np.random.default_rng(2).permutation(n)  # every dof, unsorted
    f = linalg.factorize(K, backend, trailing=trailing)
    G = f.trailing_inverse
    ref = dense[np.ix_(trailing, trailing)]
    assert G.shape == (n, n)
    assert np.abs(G - ref).max() <= 1e-10 * np.abs(ref).max()
    b = np.arange(n, dtype=float)
    assert np.linalg.norm(K @ f.solve(b) - b) <= 1e-10 * np.linalg.norm(b)


@pytest.mark.parametrize("backend", INSTALLED)
def test_a_factorization_of_the_same_pattern_takes_over_the_analysis(backend):
    """A large body's next tangent (same sparsity, same Schur set, new values): given the last
    factorization as ``analysis``, PARDISO skips its ordering and gives the same solution and
    Schur inverse as a fresh factorization, bit for bit; the one handed on refuses to solve. A
    different pattern is factorized afresh; other backends ignore the argument."""
    K = stiffness()
    rng = np.random.default_rng(1)
    trailing = rng.choice(K.shape[0], size=20, replace=False)
    b = rng.standard_normal(K.shape[0])
    first = linalg.factorize(K, backend, trailing=trailing)
    d = 1.0 + 0.1 * rng.random(K.shape[0])
    K2 = K.copy()  # D K D: new values, the same stored entries, still positive definite
    K2.data *= d[K2.indices] * np.repeat(d, np.diff(K2.indptr))
    fresh = linalg.factorize(K2, backend, trailing=trailing)
    reused = linalg.factorize(K2, backend, trailing=trailing, analysis=first)
    assert np.array_equal(reused.solve(b), fresh.solve(b))
    assert np.array_equal(reused.trailing_inverse, fresh.trailing_inverse)
    if backend == "pardiso":
        with pytest.raises(RuntimeError, match="handed on"):
            first.solve(b)
        other = linalg.factorize(K2, backend, trailing=trailing[:10], analysis=reused)
        assert np.abs(K2 @ other.solve(b) - b).max() <= 1e-10 * np.abs(b).max()
        assert np.array_equal(reused.solve(b), fresh.solve(b))  # not taken: still solves
    else:
        again = linalg.factorize(K, backend, trailing=trailing)
        assert np.array_equal(first.solve(b), again.solve(b))  # ignored: still solves


@pytest.mark.parametrize("backend", INSTALLED)
def test_every_backend_solves_a_saddle_point(backend):
    """``spd=False``: symmetric indefinite (a stiffness bordered by a constraint row)."""
    K = stiffness()
    n = K.shape[0]
    B = sp.csr_matrix((np.ones(2), ([0, 0], [n - 1, n - 3])), shape=(1, n))
    A = sp.bmat([[K, B.T], [B, None]]).tocsc()
    b = np.r_[np.ones(n), 0.5]
    x = linalg.factorize(A, backend, spd=False).solve(b)
    assert np.linalg.norm(A @ x - b) <= 1e-9 * np.linalg.norm(b)


@pytest.mark.parametrize("backend", INSTALLED)
def test_the_contact_answer_does_not_depend_on_the_backend(backend):
    p = HertzParameters(steps=1)
    reference = Analysis(build(p), "superlu").run()
    result = Analysis(build(p), backend).run()
    assert result.backend == backend and result.converged
    for name, r in reference.steps[-1].bodies.items():
        other = result.steps[-1].bodies[name]
        scale = np.abs(r.contact_force).max()
        assert np.abs(other.contact_force - r.contact_force).max() <= 1e-8 * scale
        assert np.abs(other.displacement - r.displacement).max() <= (
            1e-8 * np.abs(r.displacement).max())


def test_a_singular_stiffness_is_named_not_a_traceback():
    K = stiffness().tolil()
    K[0, :] = 0.0
    K[:, 0] = 0.0
    K = K.tocsc()
    for backend in INSTALLED:
        with pytest.raises(AnalysisError, match=f"body 'block': factorizing its stiffness "
                                                f"\\({K.shape[0]} dofs\\) with {backend} failed"):
            linalg.factorize(K, backend, what="body 'block'")


def test_unknown_and_missing_solvers_are_input_errors(tmp_path, capsys):
    with pytest.raises(InputError, match="unknown linear solver 'fastest'"):
        linalg.resolve("fastest")
    missing = [name for name in linalg.BACKENDS if name not in INSTALLED]
    for name in missing:
        with pytest.raises(InputError, match=f"linear solver '{name}' is not installed"):
            linalg.resolve(name)
    assert main(["run", "hertz", "--solver", "fastest", "--out", str(tmp_path)]) == 2
    assert "unknown linear solver" in capsys.readouterr().err


def test_the_solver_is_chosen_on_the_command_line_and_recorded(tmp_path):
    try:
        assert main(["-q", "run", "hertz", "--solver", "superlu", "--set", "steps=1",
                     "--out", str(tmp_path)]) == 0
    finally:
        linalg.use("auto")
    assert json.loads((tmp_path / "summary.json").read_text())["linear_solver"] == "superlu"


@pytest.mark.skipif("pardiso" not in INSTALLED, reason="PARDISO is not installed")
def test_small_pardiso_calls_run_on_one_thread_and_give_the_pool_back():
    """Under a policy of two threads, a small matrix's factorization and solves ask MKL for one
    thread for the calling thread only (``mkl_set_num_threads_local``) and restore its setting
    after each call, so the pool is the policy's again for a large one."""
    from vfem import threads
    from vfem.linalg import pardiso

    local = pardiso._local_threads()
    if local is None:
        pytest.skip("this MKL has no mkl_set_num_threads_local")
    seen = []
    original = pardiso.PardisoFactorization._pardiso

    def spy(self, *args):
        previous = local(0)  # what the call runs under (and give it back)
        local(previous)
        seen.append(previous)
        return original(self, *args)

    before = threads.sparse_threads()
    threads.apply(2)
    initial = local(0)  # the calling thread's setting (0: MKL's global one)
    local(initial)
    try:
        pardiso.PardisoFactorization._pardiso = spy
        K = stiffness()
        f = linalg.factorize(K, "pardiso", trailing=np.arange(10))
        f.solve(np.ones(K.shape[0]))
        after = local(initial)  # the setting from before, in force again
    finally:
        pardiso.PardisoFactorization._pardiso = original
        threads.apply(before or "off")
    assert seen[:2] == [1, 1]  # the factorization and the solve: one thread
    assert after == initial


@pytest.mark.skipif("pardiso" not in INSTALLED, reason="PARDISO is not installed")
def test_a_taken_over_analysis_factorizes_again_after_solves_at_its_size():
    """A large body's tangent between the two thread limits (20,000 to 200,000 dofs): factorized
    with a Schur complement, solved, then its analysis taken over by the next tangent and that
    one solved. MKL's PARDISO crashed (a segmentation fault in phase 22) when the solves of a
    handle ran on other threads than its factorizations: one thread count per matrix, however
    it is used (``vfem.linalg.pardiso``; found on total-Lagrangian Hertz at refinement 2)."""
    from skfem import Basis, ElementQuad1, ElementVector, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    from vfem import threads

    mesh = rectangle(0.0, 0.0, 4.0, 1.0, nx=180, ny=60)  # 21,960 dofs free
    basis = Basis(mesh, ElementVector(ElementQuad1()))
    K = asm(linear_elasticity(*lame_parameters(1000.0, 0.3)), basis).tocsr()
    fixed = basis.get_dofs(mesh.boundaries["left"]).all()
    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    K = K[free][:, free].tocsc()
    top = np.flatnonzero(np.isin(free, basis.get_dofs(mesh.boundaries["top"]).all()))
    b = np.ones(K.shape[0])
    before = threads.sparse_threads()
    threads.apply(2)
    try:
        first = linalg.factorize(K, "pardiso", trailing=top)
        first.solve(b)
        K2 = K.copy()
        K2.data *= 1.5
        second = linalg.factorize(K2, "pardiso", trailing=top, analysis=first)
        x = second.solve(b)
        fresh = linalg.factorize(K2, "pardiso", trailing=top).solve(b)
    finally:
        threads.apply(before or "off")
    assert np.array_equal(x, fresh)
    assert np.abs(K2 @ x - b).max() <= 1e-13 * np.abs(K2).max() * np.abs(x).max()


def test_the_default_install_brings_pardiso_where_its_wheel_exists():
    """Issue 39: `pip install -e .` installs PARDISO on x86-64 Linux and Windows (a platform
    marker on pypardiso, whose MKL has wheels there), nowhere else; `auto` then picks it."""
    import tomllib
    from pathlib import Path

    from packaging.markers import default_environment
    from packaging.requirements import Requirement

    project = tomllib.loads((Path(__file__).parent.parent / "pyproject.toml").read_text())
    (pardiso,) = [Requirement(r) for r in project["project"]["dependencies"]
                  if Requirement(r).name == "pypardiso"]
    env = default_environment()
    for machine, platform, wanted in (("x86_64", "linux", True), ("AMD64", "win32", True),
                                      ("aarch64", "linux", False), ("arm64", "darwin", False),
                                      ("x86_64", "darwin", False)):
        assert pardiso.marker.evaluate({**env, "platform_machine": machine,
                                        "sys_platform": platform}) is wanted, (machine, platform)
    assert linalg.PREFERENCE[0] == "pardiso"
    if linalg.is_available("pardiso"):
        assert linalg.resolve() == "pardiso"


def test_the_closing_line_names_the_linear_solver():
    from vfem.io.runner import solver_words

    assert solver_words({"linear_solver": "pardiso"}) == ", linear solver pardiso"
    assert solver_words({"linear_solver": "superlu"}).startswith(
        ", linear solver superlu (the slowest: ")
    assert solver_words({}) == ""  # (a summary written before the key existed)
