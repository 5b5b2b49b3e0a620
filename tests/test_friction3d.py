"""Coulomb friction in 3D (issue 21, C13): the paired variant, small kinematics, linear
elements, two tangents per contact node and the cone (a disk) for |s| <= mu q.

The 3D friction patch test is the 2D one's (tests/test_friction.py) with a third dimension: two
stacked unit boxes (:func:`vfem.mesh.solids.box`, nu = 0, non-matching interface meshes) are
pressed (the upper top moved down by 2 p / E: a uniform pressure p), then sheared by moving the
upper top along a direction 30 degrees off the x axis, with the lower bottom fixed and the four
side faces of both boxes loaded by the tractions the uniform shear state has there (no rollers:
a roller on a side face would hold the shear's component across it). Sticking (shear tau =
mu p / 2, the motion 2 tau / G, G = E / 2): every interface node sticks and the tangential
traction is the applied shear; slipping (the motion three times that for mu p, the sides at
mu p): every node slips and |s| = mu p, along the applied shear.
"""

import numpy as np
import pytest

from vfem.bodies import Body, PrescribedDisplacement, Support, Traction
from vfem.contact.formulations.friction import tangents
from vfem.contact.settings import ContactSettings, PairFriction
from vfem.io.results import frictional_work
from vfem.materials import LinearElastic
from vfem.mesh.solids import box
from vfem.solver import Analysis, Model

E, MU, P = 1.0e6, 0.3, 100.0
G = E / 2.0  # nu = 0
PRESS = ((0.0, 0.0), (0.5, 1.0), (1.0, 1.0))  # pressed over the first half
SHOVE = ((0.0, 0.0), (0.5, 0.0), (1.0, 1.0))  # then sheared
ANGLE = np.radians(30.0)
OBLIQUE = np.array([np.cos(ANGLE), np.sin(ANGLE), 0.0])
# (cells, divisions across) of the lower and the upper box
CASES = [(("hex", 4), ("tet", 7)), (("tet", 5), ("hex", 3)), (("hex", 3), ("hex", 5))]
STICK = (0.5 * MU * P, 2 * 0.5 * MU * P / G)  # (side shear, top motion)
SLIP = (MU * P, 3 * 2 * MU * P / G)


def sides(tau: float, direction: np.ndarray, faces=("left", "right", "front", "back")):
    """The side faces' tractions of the uniform shear state sigma_xz, sigma_yz = tau d."""
    tx, ty = tau * direction[:2]
    loads = {"left": (0.0, 0.0, -tx), "right": (0.0, 0.0, tx), "front": (0.0, 0.0, -ty),
             "back": (0.0, 0.0, ty)}
    return tuple(Traction(f, loads[f], amplitude=SHOVE) for f in faces)


def stacked(lower, upper, tau, shift, direction=OBLIQUE, swap=False, rollers=False,
            large=False, **pair) -> Model:
    mat = LinearElastic(E, 0.0)
    (cl, nl), (cu, nu) = lower, upper
    # rollers: both boxes held along x at x = 0 (a symmetry plane through the contact)
    faces = ("front", "back") if rollers else ("left", "right", "front", "back")
    roller = (Support("left", ("x",)),) if rollers else ()
    kinematics = "total" if large else "small"
    low = Body("lower", box(0.0, 0.0, -1.0, 1.0, 1.0, 1.0, nl, nl, 2, tetrahedra=cl == "tet"),
               mat, supports=(Support("bottom"), *roller), tractions=sides(tau, direction, faces),
               contact_boundaries=("top",), kinematics=kinematics)
    top = [PrescribedDisplacement("top", "z", -2 * P / E, amplitude=PRESS)]
    top += [PrescribedDisplacement("top", c, shift * direction[i], amplitude=SHOVE)
            for i, c in enumerate("xy") if not (rollers and c == "x")]
    up = Body("upper", box(0.0, 0.0, 0.0, 1.0, 1.0, 1.0, nu, nu, 2, tetrahedra=cu == "tet"),
              mat, supports=roller, prescribed=tuple(top), tractions=sides(tau, direction, faces),
              contact_boundaries=("bottom",), kinematics=kinematics)
    bodies = [up, low] if swap else [low, up]
    pairs = (PairFriction(("lower", "upper"), **pair),) if pair else ()
    return Model("friction patch 3d", bodies, ContactSettings(friction=MU, pairs=pairs),
                 (0.5, 1.0))


def carrying(step):
    """(body name, its compatibility-side nodes) of the interface: one side carries them."""
    out = [(name, np.flatnonzero(r.friction_status > 0)) for name, r in step.bodies.items()
           if (r.friction_status > 0).any()]
    assert len(out) == 1
    return out[0]


def check_every_step(result, model):
    """Every step: the invariants passed, the cone |s| <= mu q at every node, the tangential
    (friction) forces of the two bodies balanced to round-off."""
    for step in result.steps:
        assert step.invariants["passed"], step.invariants
        for r in step.bodies.values():
            on = r.friction_status >= 0  # the nodes that carry a pair's traction values
            size = np.linalg.norm(r.contact_shear[on], axis=1)
            assert np.all(size <= MU * np.maximum(r.contact_traction[on], 0.0) * (1 + 1e-9))
        forces = [r.friction_force.sum(axis=0) for r in step.bodies.values()]
        largest = max(np.abs(r.friction_force).sum() for r in step.bodies.values())
        assert np.abs(sum(forces)).max() <= 1e-12 * max(largest, 1.0)


@pytest.fixture(scope="module", params=[
    (c, swap) if k == 0 and not swap else pytest.param((c, swap), marks=pytest.mark.slow)
    for k, c in enumerate(CASES) for swap in (False, True)],
                ids=lambda p: f"{p[0][0][0]}{p[0][0][1]}-{p[0][1][0]}{p[0][1][1]}"
                              f"{'-upper-first' if p[1] else ''}")
def patch(request):
    """The stick and the slip runs of one case and body order (module docstring)."""
    (lower, upper), swap = request.param
    out = {}
    for name, (tau, shift) in (("stick", STICK), ("slip", SLIP)):
        model = stacked(lower, upper, tau, shift, swap=swap)
        result = Analysis(model).run()
        assert result.converged, result.message
        out[name] = (model, result, tau)
    return out


def last_carrying(run):
    """A patch run checked at every step: its result, shear, the carrying body's last step,
    its carrying nodes, and the sign of the applied shear's traction on that body."""
    model, result, tau = run
    check_every_step(result, model)
    name, nodes = carrying(result.steps[-1])
    sign = -1.0 if name == "upper" else 1.0  # the traction on the carrying body
    return result, tau, result.steps[-1].bodies[name], nodes, sign


def test_3d_friction_patch_sticks_with_the_applied_shear(patch):
    result, tau, r, nodes, sign = last_carrying(patch["stick"])
    assert np.all(r.friction_status[nodes] == 1)
    error = np.abs(r.contact_shear[nodes] - sign * tau * OBLIQUE).max() / tau
    assert error < 1e-8
    np.testing.assert_allclose(r.contact_traction[nodes], P, rtol=1e-8)
    np.testing.assert_allclose(r.slip_increment[nodes], 0.0, atol=1e-8 * tau / G)


def test_3d_friction_patch_slips_on_the_cone_along_the_shear(patch):
    result, tau, r, nodes, sign = last_carrying(patch["slip"])
    assert np.all(r.friction_status[nodes] == 2)
    s = r.contact_shear[nodes]
    size = np.linalg.norm(s, axis=1)
    assert np.abs(size / (MU * P) - 1).max() < 1e-8  # |s| = mu p
    across = np.linalg.norm(np.cross(s / size[:, None], sign * OBLIQUE), axis=1)
    assert across.max() < 1e-8  # s along the applied shear
    assert np.all(sign * s @ OBLIQUE > 0)
    np.testing.assert_allclose(r.contact_traction[nodes], P, rtol=1e-8)
    assert np.all(r.slip_increment[nodes] > 0) and np.all(r.accumulated_slip[nodes] > 0)
    # the work: mu p over the unit area times the slip of the step, the top's motion less the
    # two blocks' elastic shear 2 mu p / G (measured to 1e-12)
    work = frictional_work(result.steps)
    assert work[-1] > 0
    assert work[-1] == pytest.approx(MU * P * (SLIP[1] - 2 * MU * P / G), rel=1e-8)


def test_tangents_in_3d():
    """t1 = unit projection of the global axis least aligned with n (ties: the lowest axis),
    t2 = n x t1: orthonormal, right-handed with n; a normal within the plane x = 0 (a symmetry
    plane) gets t1 = x."""
    rng = np.random.default_rng(3)
    n = rng.normal(size=(50, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    n = np.vstack([n, [[0, 0, 1.0], [0, 0, -1.0], [0, 0.6, -0.8], [1.0, 0, 0], [0.6, 0.8, 0]]])
    t1, t2 = tangents(n)
    for a, b in ((t1, n), (t2, n), (t1, t2)):
        np.testing.assert_allclose(np.einsum("ij,ij->i", a, b), 0.0, atol=1e-15)
    for t in (t1, t2):
        np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, rtol=1e-15)
    np.testing.assert_allclose(np.einsum("ij,ij->i", np.cross(t1, t2), n), 1.0, rtol=1e-15)
    np.testing.assert_array_equal(t1[-5:-2], [[1.0, 0, 0]] * 3)  # x (ties: x before y)
    np.testing.assert_array_equal(t1[-2:], [[0, 1.0, 0], [0, 0, 1.0]])


@pytest.mark.parametrize("tau, shift, status", [(*STICK, 1), (*SLIP, 2)],
                         ids=["stick", "slip"])
def test_a_node_on_a_roller_plane_keeps_its_held_component(tau, shift, status):
    """Both boxes on rollers at x = 0 (held along x there), sheared along y: the interface
    nodes on the plane have their tangent t1 = x held by the supports (no tangential unknown
    along it: no traction and no motion across the plane), and stick or slip along y with the
    others, the shear uniform."""
    model = stacked(("hex", 4), ("tet", 7), tau, shift, direction=np.array([0.0, 1.0, 0.0]),
                    rollers=True)
    result = Analysis(model).run()
    assert result.converged, result.message
    check_every_step(result, model)
    name, nodes = carrying(result.steps[-1])
    r = result.steps[-1].bodies[name]
    body = next(b for b in model.bodies if b.name == name)
    plane = nodes[body.points[0, nodes] == 0.0]
    assert len(plane) >= 5
    assert np.all(r.friction_status[nodes] == status)
    sign = -1.0 if name == "upper" else 1.0
    assert np.all(r.contact_shear[plane, 0] == 0.0)  # the held component
    assert np.all(r.displacement[plane, 0] == 0.0)  # no motion across the plane
    expected = sign * tau * np.array([0.0, 1.0, 0.0])
    assert np.abs(r.contact_shear[nodes] - expected).max() < 1e-8 * tau


def test_the_elastoplastic_law_in_3d():
    """The thesis's friction-slippage law (§1.10, slip stiffness k_t) in 3D: below the cone
    the interface slips elastically by tau / k_t in series with the blocks (the uniform shear
    delta / (2 / G + 1 / k_t) along the motion); driven far, it slips at mu p along it."""
    k_t, delta = 2.5e5, 1e-4
    tau = delta / (2 / G + 1 / k_t)
    pair = dict(friction=MU, law="elastoplastic", slip_stiffness=k_t)
    for shear, motion, status in ((tau, delta, 1),
                                  (MU * P, 10 * MU * P * (2 / G + 1 / k_t), 2)):
        model = stacked(("hex", 3), ("tet", 4), shear, motion, **pair)
        result = Analysis(model).run()
        assert result.converged, result.message
        check_every_step(result, model)
        name, nodes = carrying(result.steps[-1])
        r = result.steps[-1].bodies[name]
        assert np.all(r.friction_status[nodes] == status)
        sign = -1.0 if name == "upper" else 1.0
        # (as in 2D, to 1e-8 of p: measured 2.8e-12 of the shear sticking, 6.6e-9 slipping)
        assert np.abs(r.contact_shear[nodes] - sign * shear * OBLIQUE).max() < 1e-8 * P


@pytest.mark.parametrize("rollers", [False, True], ids=["free", "rollers"])
@pytest.mark.slow
def test_the_3d_friction_patch_sticks_under_large_kinematics(rollers):
    """The sticking patch with both boxes under total Lagrangian kinematics
    (vfem.contact.formulations.large_friction; tests/test_large_friction3d.py slides): two
    iterations a step, every node sticks and carries the applied shear but for the geometric
    nonlinearity's share (the pressure 1.5e-4 below p: measured 1.4e-4 of tau); with a roller
    plane through the contact the held tangent carries nothing."""
    model = stacked(("hex", 4), ("tet", 7), *STICK, rollers=rollers, large=True)
    result = Analysis(model).run()
    assert result.converged, result.message
    assert all(s.iterations <= 2 for s in result.steps)
    result_, tau, r, nodes, sign = last_carrying((model, result, STICK[0]))
    assert np.all(r.friction_status[nodes] == 1)
    applied = sign * tau * OBLIQUE
    if rollers:
        applied[0] = 0.0
    assert np.abs(r.contact_shear[nodes] - applied).max() < 3e-4 * tau
    np.testing.assert_allclose(r.contact_traction[nodes], P, rtol=3e-4)


def test_the_3d_friction_outputs(tmp_path):
    """A 3D run's friction fields in the files (the results writer, checkpoints included):
    contact.csv with shear_x, shear_y, shear_z, slip_increment (the slip's length in 3D),
    accumulated_slip and the stick/slip column; the VTU's three-component contact_shear."""
    import csv

    import meshio

    from vfem.io.results import contact_columns, run_writing

    model = stacked(("hex", 3), ("hex", 5), *SLIP)
    _, result = run_writing(model, tmp_path)
    assert result.converged, result.message
    with open(tmp_path / "contact.csv") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == contact_columns(3, friction=True)
    assert {"shear_x", "shear_y", "shear_z"} <= set(rows[0])
    last = [r for r in rows if r["step"] == rows[-1]["step"] and r["friction"]]
    assert last and all(r["friction"] == "slip" for r in last)
    shear = np.array([[float(r[f"shear_{a}"]) for a in "xyz"] for r in last])
    np.testing.assert_allclose(np.linalg.norm(shear, axis=1), MU * P, rtol=1e-8)
    assert all(float(r["slip_increment"]) > 0 for r in last)
    vtu = meshio.read(sorted(tmp_path.glob("*upper*.vtu"))[-1])
    assert vtu.point_data["contact_shear"].shape == (len(vtu.points), 3)
