"""A stiff flat punch with rounded corners on a softer block (issue 16, item 8).

The punch (``filleted_punch``: 1 wide, corner radius a/5 = 0.1, E = 2e11) is pressed 0.01 into a
block 200 times softer (E = 1e9). The contact zone ends on the arcs, a little beyond the
flat-to-arc tangent points x = -+0.4, where the pressure peaks — finite, unlike a sharp corner's.
Its peak is narrow: the zone extends only about 0.014 past the tangent points (the rigid punch on a
half-plane at the same load: 0.0127, the peak 5.3e7 at |x| = 0.404), so the example's mesh (block
spacing 0.05) holds it in one node, and the comparison with the Lagrange baseline is made on fine
meshes that resolve it. There the block's top nodes are the punch face nodes' x where the zone
ends: matching meshes, so that the baseline's slave nodes (the block's) are not finer than its
master facets (node-to-segment multipliers oscillate then).
"""

import dataclasses
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from skfem import MeshQuad

import vfem
from vfem.mesh.shapes import filleted_punch, graded_nodes
from vfem_tools.calculix import write_deck

EXAMPLE = Path(__file__).parent.parent / "examples" / "punch" / "rounded_punch.toml"
TANGENT = 0.4  # x of the right tangent point


@pytest.mark.parametrize("parameters", [
    {}, {"n_arc": 2, "rows": 3}, {"n_arc": 5, "rows": 9, "grading": 0.9},
    {"x0": 3.0, "y0": -1.0, "width": 2.0, "height": 4.0, "radius": 0.3, "n_flat": 7},
    {"n_flat": 80, "n_arc": 24, "rows": 30, "grading": 1.15, "h_tangent": 0.001}])
def test_the_shape(parameters):
    """filleted_punch: a valid mesh (no inverted or degenerate element, counter-clockwise), its
    face the flat part and two arcs, nodes exactly at the tangent points and on the arcs,
    mirror-symmetric about x = x0."""
    from vfem.mesh.checks import check_mesh

    p = {"x0": 0.0, "y0": 0.0, "width": 1.0, "height": 0.5, "radius": 0.1, "n_flat": 16,
         "n_arc": 4, "rows": 8, **parameters}
    mesh = filleted_punch(**p)
    check_mesh(mesh, "filleted_punch")
    x, y = mesh.p
    corners = mesh.p[:, mesh.t]
    area = 0.5 * np.sum(corners[0] * np.roll(corners[1], -1, axis=0)
                        - np.roll(corners[0], -1, axis=0) * corners[1], axis=0)
    assert (area > 0).all()
    a, r, x0, y0 = 0.5 * p["width"], p["radius"], p["x0"], p["y0"]
    face = np.unique(mesh.facets[:, mesh.boundaries["face"]])
    assert len(mesh.boundaries["face"]) == p["n_flat"] + 2 * p["n_arc"]
    flat = face[y[face] == y0]
    assert len(flat) == p["n_flat"] + 1
    assert {x0 - (a - r), x0 + (a - r)} <= set(x[flat])
    arcs = face[y[face] != y0]
    centre = np.where(x[arcs] < x0, x0 - a + r, x0 + a - r)
    assert np.allclose(np.hypot(x[arcs] - centre, y[arcs] - y0 - r), r, rtol=0, atol=1e-14)
    assert np.isclose(y[arcs].max(), y0 + r) and np.isclose(np.ptp(x[face]), 2 * a)
    for name, on in (("left", x0 - a), ("right", x0 + a), ("top", None)):
        nodes = np.unique(mesh.facets[:, mesh.boundaries[name]])
        if on is None:
            assert np.allclose(y[nodes], y0 + p["height"])
        else:
            assert np.allclose(x[nodes], on) and y[nodes].min() == pytest.approx(y0 + r)
    mirrored = np.vstack([2 * x0 - x, y])
    order = np.lexsort(np.round(mesh.p / 1e-9)), np.lexsort(np.round(mirrored / 1e-9))
    assert np.allclose(mesh.p[:, order[0]], mirrored[:, order[1]], rtol=0, atol=1e-12)


@pytest.mark.parametrize("parameters, message", [
    ({"radius": 0.5}, "0 < radius < width / 2"), ({"height": 0.1}, "height > radius"),
    ({"n_arc": 1}, "n_arc >= 2"), ({"rows": 4}, "rows > n_arc"),
    ({"h_tangent": 0.1}, "h_tangent must lie in")])
def test_the_shape_refuses(parameters, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        filleted_punch(**parameters)


def model(method: str = "vfem"):
    m = vfem.load(EXAMPLE).build()
    m.contact = dataclasses.replace(m.contact, method=method)
    return m


def block_top(result):
    """x and contact pressure of the block's top nodes, by x."""
    body = result.model.bodies[[b.name for b in result.model.bodies].index("block")]
    x, y = body.points
    top = np.flatnonzero(np.abs(y) < 1e-12)
    top = top[np.argsort(x[top])]
    return x[top], result.steps[-1].bodies["block"].contact_pressure[top]


def check_symmetric(result):
    """Balance, no sideways force and a mirror-symmetric pressure, all to round-off; returns the
    load and the two sides' p_max."""
    assert result.converged, result.message
    totals = {k: v.contact_force.sum(axis=0) for k, v in result.steps[-1].bodies.items()}
    load = abs(totals["block"][1])
    assert np.abs(totals["block"] + totals["punch"]).max() <= 1e-8 * load
    for t in totals.values():
        assert abs(t[0]) <= 1e-8 * load
    x, p = block_top(result)
    assert np.allclose(x, -x[::-1], rtol=0, atol=1e-12)
    assert np.allclose(p, p[::-1], rtol=1e-8, atol=1e-8 * p.max())
    left, right = p[x < 0].max(), p[x > 0].max()
    assert left == pytest.approx(right, rel=1e-8)
    return load, left, right


@pytest.mark.parametrize("method", ["vfem", "lagrange"])
def test_the_example_is_symmetric_and_balanced(method):
    """The issue's tie: the tangent points on block nodes gave p_max 5.06e7 on the left and 4.53e7
    on the right, and a sideways force of 0.8 % of the load (vfem and the baseline alike).
    Measured now: p_max left and right 2.32e7 (vfem), 2.51e7 (Lagrange), equal to 1e-13; the
    sideways force 1e-15 of the load."""
    result = vfem.solve(model(method))
    load, left, right = check_symmetric(result)
    for step in result.steps:
        assert step.invariants["force_balance"] <= 1e-8
    x, p = block_top(result)
    assert (p >= 0).all()
    # nothing beyond the punch carries pressure; the zone reaches past the tangent points
    assert not (p[np.abs(x) > 0.5 + 1e-12] > 0).any()
    assert p[np.isclose(np.abs(x), TANGENT)].min() > 0
    # the peak on the tangent nodes (the narrow peak beyond them falls between this mesh's nodes)
    assert np.isclose(np.abs(x[np.argmax(p)]), TANGENT)
    # the fine meshes' 9.47e6 (below): vfem 1.7 % above it on this mesh, the baseline 0.03 %
    assert load == pytest.approx(9.47e6, rel=0.025)


def fine_model(method: str, n_flat: int, n_arc: int, rows: int, grading: float,
               h_tangent: float, reach: float = 0.43):
    """The example on fine meshes: the punch's facets ``h_tangent`` long at the tangent points,
    growing away from them; the block's top grid lines on the punch face nodes' x for |x| <=
    ``reach`` (past the zone's end), its columns beyond and its rows below graded from
    ``h_tangent`` (growth 0.25 per unit distance, at most 0.2)."""
    m = model(method)
    punch = filleted_punch(width=1.0, height=0.5, radius=0.1, n_flat=n_flat, n_arc=n_arc,
                           rows=rows, grading=grading, h_tangent=h_tangent)
    face = np.unique(punch.facets[:, punch.boundaries["face"]])
    xs = np.unique(punch.p[0, face])
    xs = xs[np.abs(xs) <= reach]
    size = lambda d: np.minimum(h_tangent + 0.25 * np.abs(d), 0.2)  # noqa: E731
    x = np.concatenate([graded_nodes(-2.0, xs[0], lambda s: size(s - xs[0]))[:-1], xs,
                        -graded_nodes(-2.0, xs[0], lambda s: size(s - xs[0]))[-2::-1]])
    y = graded_nodes(-2.0, 0.0, size)
    grid = MeshQuad.init_tensor(x, y)
    block = MeshQuad(grid.p, grid.t[::-1].copy()).with_boundaries({  # counter-clockwise
        "top": lambda p: p[1] > -1e-9, "bottom": lambda p: p[1] < -2 + 1e-9,
        "left": lambda p: p[0] < -2 + 1e-9, "right": lambda p: p[0] > 2 - 1e-9})
    names = [b.name for b in m.bodies]
    m.bodies[names.index("block")] = dataclasses.replace(m.bodies[names.index("block")],
                                                         mesh=block)
    m.bodies[names.index("punch")] = dataclasses.replace(m.bodies[names.index("punch")],
                                                         mesh=punch)
    return m


#: uniform rows below the arcs' centres (0.1 / n_arc): a thinner first row than the 0.0025 a
#: step moves makes the solver cut steps for the rind, with the same answer
FINE = dict(n_flat=80, n_arc=24, rows=30, grading=1.0, h_tangent=0.001)
FINER = dict(n_flat=100, n_arc=32, rows=40, grading=1.0, h_tangent=0.0005)


def check_finite_and_smooth(result):
    """Each side's pressure rises from the middle to one peak just beyond the tangent point and
    falls from it to zero at the zone's end (no second peak, no oscillation); at the tangent
    point, where the punch's curvature jumps, no spike (the node within 10 % of its neighbours'
    mean; on the example's mesh it reads 2.6 times). Returns the peak and its x."""
    x, p = block_top(result)
    right = x >= 0
    xr, pr = x[right], p[right]
    k = int(np.argmax(pr))
    assert TANGENT < xr[k] < TANGENT + 0.01
    assert (np.diff(pr[: k + 1]) > 0).all(), "the pressure dips between the middle and the peak"
    assert (np.diff(pr[k:]) <= 0).all(), "the pressure rises again beyond the peak"
    assert 0.41 < xr[pr > 0].max() < 0.42  # the zone's end
    i = int(np.flatnonzero(np.isclose(xr, TANGENT))[0])
    assert pr[i] == pytest.approx(0.5 * (pr[i - 1] + pr[i + 1]), rel=0.1)
    return pr[k], xr[k]


def against_lagrange(mesh: dict):
    """vfem and the Lagrange baseline on the same fine meshes: each symmetric and balanced,
    total force and peak pressure within 1 % of each other. Returns both results."""
    vfem_result = vfem.solve(fine_model("vfem", **mesh))
    lagrange = vfem.solve(fine_model("lagrange", **mesh))
    load, peak, _ = check_symmetric(vfem_result)
    load_l, peak_l, _ = check_symmetric(lagrange)
    assert load == pytest.approx(load_l, rel=0.01)
    assert peak == pytest.approx(peak_l, rel=0.01)
    return vfem_result, lagrange


@pytest.mark.slow
def test_fine_mesh_against_the_lagrange_baseline():
    """Acceptance: total force and peak pressure within 1 % of the Lagrange baseline on a fine
    mesh (17k dofs; 0.001 at the tangent points). Measured: 9.4726e6 against 9.4684e6 (+0.045 %),
    p_max 5.230e7 against 5.205e7 (+0.47 %), both at |x| = 0.4049; balanced and symmetric to
    round-off both ways."""
    vfem_result, lagrange = against_lagrange(FINE)
    p, x = check_finite_and_smooth(vfem_result)
    p_l, x_l = check_finite_and_smooth(lagrange)
    assert x == x_l


@pytest.mark.slow
def test_finer_mesh_the_peak_is_finite():
    """Halving the facets at the tangent points (26k dofs, 0.0005) moves the peak by 0.36 %
    (5.230e7 to 5.248e7; the nodal pressure at a sharp corner grows like h^-1/2, 41 % per halving)
    and keeps the baseline within 1 %: force +0.027 %, p_max +0.34 %."""
    fine_peak = check_finite_and_smooth(vfem.solve(fine_model("vfem", **FINE)))[0]
    result, lagrange = against_lagrange(FINER)
    _, peak, _ = check_symmetric(result)
    check_finite_and_smooth(result)
    check_finite_and_smooth(lagrange)
    assert peak == pytest.approx(fine_peak, rel=0.01)


def test_the_fine_model_writes_as_a_calculix_deck(tmp_path):
    """The fine model as a CalculiX deck (checked whether or not ccx is installed): the block,
    the softer, is the slave; the penalty stiff enough that its overclosure at p_max is 1e-5 of
    the indentation (the writer's default, 1e11, chosen for Hertz, would give 5 %)."""
    deck = write_deck(fine_model("vfem", **FINE), tmp_path / "rounded_punch.inp", penalty=1e14)
    assert (deck.slave, deck.master) == ("block", "punch")
    text = deck.path.read_text()
    assert "*CONTACT PAIR, INTERACTION=CONTACT, TYPE=SURFACE TO SURFACE" in text
    assert "S_BLOCK, S_PUNCH" in text


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed")
def test_calculix_on_the_fine_mesh(tmp_path):
    """Issue 16, item 8: "and with CalculiX when installed". Not yet run here (no ccx on the
    machine that wrote it): total force within 1 %, the nodal p_max (K u per tributary length,
    as vfem's) within 2 % of vfem's on the same meshes."""
    from vfem_tools.calculix import run

    load, peak, _ = check_symmetric(vfem.solve(fine_model("vfem", **FINE)))
    deck = write_deck(fine_model("vfem", **FINE), tmp_path / "rounded_punch.inp", penalty=1e14)
    r = run(deck, keep=tmp_path / "out")
    assert abs(r["total_contact_force_nodal"][1]) == pytest.approx(load, rel=0.01)
    assert r["p_max_nodal"] == pytest.approx(peak, rel=0.02)
