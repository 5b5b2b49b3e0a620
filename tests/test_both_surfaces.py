"""Both surfaces enforced (issue 37): a stiff, coarse body's corner lands on a softer, finer one.

The paired variant puts compatibility on the surface that gives way more (the soft block) and
reads it at that surface's nodes. Before issue 37 the other surface was free between them: a
stiff square turned 10 degrees, pushed corner first 0.02 into a block 2000 times softer,
"converged" with its corner 6.5e-3 below the block's deformed surface (a third of the push),
every invariant passing; pushed 0.002 (here) it stopped at its first step, invariant (b). Its
nodes are now held by point forces where they would penetrate
(``vfem.contact.geometry.held.held_nodes``).

Each check here is read from the full-mesh results alone: the depth of every node of the
square below the block's deformed top (the polyline through its nodes at X + u), each body's
forces in balance, and the same answer with the bodies listed the other way round.
"""

from __future__ import annotations

import numpy as np
import pytest

import vfem
from vfem.contact.solvers.complementarity import DenseSystem, linear_complementarity
from vfem.mesh import rectangle

PUSH = 0.002


def tilted_square_on_block(nb: int = 36, swap: bool = False) -> vfem.Model:
    c, s = np.cos(np.radians(10.0)), np.sin(np.radians(10.0))
    sq = rectangle(x0=-0.25, y0=0.0, width=0.5, height=0.5, nx=2, ny=2)
    A = np.array([[c, -s], [s, c]])
    sq = type(sq)(A @ sq.p, sq.t, _boundaries=sq.boundaries)
    sq = sq.translated((0.0, -sq.p[1].min()))  # its lowest corner on the block's top
    square = vfem.Body(name="square", mesh=sq, material=vfem.LinearElastic(2e11, 0.3),
                       supports=(vfem.Support("top", ("x",)),),
                       prescribed=(vfem.PrescribedDisplacement("top", "y", -PUSH),))
    block = vfem.Body(name="block", mesh=rectangle(x0=-0.6, y0=-0.6, width=1.2, height=0.6,
                                                   nx=nb, ny=nb // 2),
                      material=vfem.LinearElastic(1e8, 0.3),
                      supports=(vfem.Support("bottom", ("x", "y")),),
                      contact_boundaries=("top",))
    return vfem.Model(name="tilted square", bodies=[block, square] if swap else [square, block],
                      load_factors=(0.25, 0.5, 0.75, 1.0))


def depth_below_block(result, model) -> float:
    """The deepest node of the square below the block's deformed top (> 0 inside)."""
    last = result.steps[-1]
    bodies = {b.name: b for b in model.bodies}
    block = bodies["block"]
    X = block.mesh.p.T
    top = np.flatnonzero(np.isclose(X[:, 1], 0.0))
    top = top[np.argsort(X[top, 0])]
    xb = X[top] + last.bodies["block"].displacement[top]
    xs = bodies["square"].mesh.p.T + last.bodies["square"].displacement
    y_surface = np.interp(xs[:, 0], xb[:, 0], xb[:, 1], left=-np.inf, right=-np.inf)
    return float((y_surface - xs[:, 1]).max())


@pytest.fixture(scope="module")
def solved():
    out = {}
    for swap in (False, True):
        model = tilted_square_on_block(swap=swap)
        out[swap] = (model, vfem.solve(model))
    return out


def test_the_stiff_corner_does_not_sink_into_the_soft_block(solved):
    model, result = solved[False]
    assert result.converged, result.message
    # small kinematics holds the linearised gap; the deformed positions differ from it by
    # second-order terms (strain 0.5 % here, times the slip): 1 % of the push bounds them
    # (measured -1.4e-6 on 36 block facets, 4.3e-6 on 72; before issue 37 no answer, and
    # pushed 0.02 a third of the push)
    assert depth_below_block(result, model) <= 0.01 * PUSH


def test_forces_balance_and_do_not_depend_on_the_order_of_the_bodies(solved):
    (_, a), (_, b) = solved[False], solved[True]
    assert a.converged and b.converged
    fa = {n: f.contact_force.sum(axis=0) for n, f in a.steps[-1].bodies.items()}
    fb = {n: f.contact_force.sum(axis=0) for n, f in b.steps[-1].bodies.items()}
    scale = np.abs(fa["square"]).max()
    assert np.abs(fa["square"] + fa["block"]).max() <= 1e-12 * scale
    for name in fa:
        np.testing.assert_allclose(fb[name], fa[name], rtol=0, atol=1e-8 * scale)
    for name, fields in a.steps[-1].bodies.items():
        np.testing.assert_allclose(b.steps[-1].bodies[name].displacement, fields.displacement,
                                   rtol=0, atol=1e-8 * PUSH)


def test_a_held_node_joins_only_where_it_would_penetrate():
    """Two nodes: node 0 of the compatibility side, node 1 held (reserve), guarded by node 0.
    W = identity: each closes its own penetration."""
    W = np.eye(2)
    q0 = np.zeros(2)
    reserve = np.array([False, True])
    # node 1 penetrates, node 0 not: node 1 is held
    q, _ = linear_complementarity(W, q0, np.array([-1.0, 2.0]), 1e-12, reserve=reserve,
                                  guard=np.array([[-1], [0]]))
    np.testing.assert_allclose(q, [0.0, 2.0])
    # both penetrate: node 0 touches, and node 1, whose guard is in contact, is left to the
    # faceting of the compatibility side
    q, _ = linear_complementarity(W, q0, np.array([1.0, 2.0]), 1e-12, reserve=reserve,
                                  guard=np.array([[-1], [0]]))
    np.testing.assert_allclose(q, [1.0, 0.0])
    # without a guard it is held too
    q, _ = linear_complementarity(W, q0, np.array([1.0, 2.0]), 1e-12, reserve=reserve)
    np.testing.assert_allclose(q, [1.0, 2.0])



def test_one_at_a_time_pivoting_that_cycles_ends_at_the_cycle():
    """Murty's rule (one violation at a time, the lowest index first) is finite only for a
    P-matrix; with held nodes W need not be one (a held node's force and gap directions
    differ), and the rule can cycle. Its next set is a function of the current one, so a set
    met again is a cycle: the search ends there instead of running to ``max_pivots`` (the
    16-plate 3D stack of ``benchmarks/stack.py``: a join of two held nodes cycled with period 2
    for 4,273 solves, twice; 34 solves in all since, the same answer). Here a 3-node W whose
    minor on {0, 1} is zero and whose full set gives a negative value: the rule cycles although
    {1, 2} is complementary (checked by enumeration); the block phase and the single phase each
    visit a set at most once before they stop, so at most 2 (2^n + 1) solves, where the search
    before took all 10 n + 10 = 40."""
    W = np.array([[0.0, 1.0, 3.0], [2.0, 1.0, 0.0], [0.0, 3.0, -2.0]])
    p = np.array([2.0, 1.0, -3.0])
    solves = []

    class Counted(DenseSystem):
        def solve(self, *args, **kwargs):
            solves.append(1)
            return super().solve(*args, **kwargs)

    n = len(p)
    q, _ = linear_complementarity(Counted(W), np.zeros(n), p, 1e-12)
    assert len(solves) <= 2 * (2**n + 1) < 10 * n + 10
    # what the search returns is no complementary set: a clipped, non-negative value
    assert (q >= 0).all()
    pen = p - W @ q
    assert not ((pen <= 1e-12).all() and (q * pen == 0).all())
    # the complementary set the rule missed exists (the cycle is the rule's, not the data's)
    q_set = np.zeros(n)
    q_set[1:] = np.linalg.solve(W[1:, 1:], p[1:])
    assert (q_set >= 0).all() and (p - W @ q_set <= 1e-12).all()

# -- a stiff block's corner under a soft body's face whose nodes lie far off ---------------------

CORNER_PUSH = 0.002


def soft_square_over_block_corner(swap: bool = False) -> tuple[vfem.Model, float]:
    """A soft one-element square turned 10 degrees, its lowest corner 0.05 left of a stiff
    block's corner, so that its bottom face passes over that corner with its other node 0.44
    to the right and 0.08 up: no node of the square touches; the block's corner lands on its
    face. Pushed down by the gap over the corner plus CORNER_PUSH. Returns the model and the
    gap (vertical, over the corner)."""
    c, s = np.cos(np.radians(10.0)), np.sin(np.radians(10.0))
    sq = rectangle(x0=0.0, y0=0.0, width=0.5, height=0.5, nx=1, ny=1)
    sq = type(sq)(np.array([[c, -s], [s, c]]) @ sq.p, sq.t, _boundaries=sq.boundaries)
    low = np.argmin(sq.p[1])
    sq = sq.translated((-0.65 - sq.p[0, low], 0.01 - sq.p[1, low]))
    # the bottom face's height over the block's corner (x = -0.6)
    right = np.argmin(np.where(np.arange(sq.p.shape[1]) == low, np.inf, sq.p[1]))
    (x0, y0), (x1, y1) = sq.p[:, low], sq.p[:, right]
    gap = y0 + (y1 - y0) * (-0.6 - x0) / (x1 - x0)
    square = vfem.Body(name="square", mesh=sq, material=vfem.LinearElastic(1e8, 0.3),
                       supports=(vfem.Support("top", ("x",)),),
                       prescribed=(vfem.PrescribedDisplacement("top", "y",
                                                               -(gap + CORNER_PUSH)),))
    block = vfem.Body(name="block", mesh=rectangle(x0=-0.6, y0=-0.6, width=1.2, height=0.6,
                                                   nx=24, ny=12),
                      material=vfem.LinearElastic(2e11, 0.3),
                      supports=(vfem.Support("bottom", ("x", "y")),),
                      contact_boundaries=("top",))
    return vfem.Model(name="corner under a face",
                      bodies=[block, square] if swap else [square, block],
                      load_factors=(0.5, 1.0)), gap


def corner_depth(result, model) -> float:
    """How far the block's corner (-0.6, 0) lies inside the square (> 0 inside): below the
    line through the square's two deformed bottom nodes."""
    last = result.steps[-1]
    bodies = {b.name: b for b in model.bodies}
    X = bodies["block"].mesh.p.T
    k = int(np.argmin(np.hypot(X[:, 0] + 0.6, X[:, 1])))
    corner = X[k] + last.bodies["block"].displacement[k]
    P = bodies["square"].mesh.p.T
    x = P + last.bodies["square"].displacement
    a, b = np.argsort(P[:, 1])[:2]
    t = (x[b] - x[a]) / np.linalg.norm(x[b] - x[a])
    n = np.array([t[1], -t[0]])
    n = n if n[1] < 0 else -n  # out of the square, downwards
    return float(-n @ (corner - x[a]))


@pytest.mark.parametrize("swap", [False, True])
def test_a_stiff_corner_under_a_soft_face_is_held(swap):
    """Before, no pair was made (the square's only node over the block lies 0.08 up) and the
    corner went through the face by all of the push, "converged" with no force; read along
    the facet's normal interpolated between its nodes, it still went through."""
    model, gap = soft_square_over_block_corner(swap)
    result = vfem.solve(model)
    assert result.converged, result.message
    fy = result.steps[-1].bodies["square"].contact_force[:, 1].sum()
    assert fy > 0  # the block pushes the square up
    # the linearised gap of a point against a straight facet is its distance to first order;
    # what is left is second order (the face's turn, strain ~ 1e-3, times the slide along it,
    # about gap sin 10 deg): 2 % of the push bounds it
    assert corner_depth(result, model) <= 0.02 * CORNER_PUSH


@pytest.mark.slow
def test_the_16_plate_stack_finds_its_sets_without_cycling(monkeypatch):
    """The 16-plate 3D stack (10 x 10 x 2 plates, each 1/32 narrower, W dense): a join of two
    held nodes cycled with period 2 under one-at-a-time pivoting until its limit, twice:
    8,563 set solves in its one step (248 s of the LCP). A set met again under that rule
    now ends the search: 34. Counted here (not timed): the set solves of the whole run stay
    far below one cycle's limit (20 + m, m = 4,253 unknowns), and the run converges with
    every invariant."""
    from vfem.contact.solvers import complementarity
    from vfem.solver import Analysis
    from vfem_examples import stack

    solves = []
    original = complementarity.DenseSystem.solve

    def counted(self, *args, **kwargs):
        solves.append(1)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(complementarity.DenseSystem, "solve", counted)
    model = stack.build(stack.Parameters(blocks=16, divisions=10, layers=2, shrink=1 / 32,
                                         flexibility="dense"))
    result = Analysis(model).run()
    assert result.converged and all(s.invariants["passed"] for s in result.steps)
    assert len(solves) < 1_000
