"""A body in contact with itself (issue 42, item 2): two named boundaries of one body as the two
sides of a contact pair (``contact_pairs = [["u:slot_top", "u:slot_bottom"]]``). Checked against
the same problem halved by its symmetry (one arm against a stiff plane: two bodies, the
formulation's ordinary path), on a straight boundary bent both ways (no contact may appear
where its two sides meet), and the invariants' reading of a body against itself."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree
from skfem import MeshHex, MeshQuad

from vfem.bodies import Body, Support, Traction
from vfem.contact.invariants.check import InvariantCheck
from vfem.errors import InputError
from vfem.materials import LinearElastic
from vfem.mesh.shapes import block
from vfem.mesh.solids import box
from vfem.mesh.topology import named_boundaries
from vfem.solver import Analysis, Model

E, NU = 1000.0, 0.3
#: the U's height, arms' thickness, slot's width, length, the slot's closed end and element size
H, T, GAP, L, BACK, SIZE = 1.0, 0.45, 0.1, 4.0, 1.0, 0.05
#: the traction on each arm's end: the free arms would close the slot at about a fifth of it
P = 0.5
STEPS = tuple(np.linspace(0.1, 1.0, 10))


def kept_elements(mesh, keep: np.ndarray):
    """``mesh`` (its class kept) with the elements where ``keep`` alone, its nodes renumbered
    to those they use."""
    t = mesh.t[:, keep]
    used = np.unique(t)
    number = np.full(mesh.p.shape[1], -1)
    number[used] = np.arange(len(used))
    return type(mesh)(mesh.p[:, used], number[t])


def slotted(mesh_cls, half: bool, *across):
    """The U's mesh of ``mesh_cls`` on the grid of ``across`` (x, then z in 3D) by its
    height's last coordinate, the slot's elements left out: a block H high, a slot GAP wide
    cut from x = BACK to its end at mid-height, two arms T thick (``half``: its lower half,
    cut at mid-height). Boundaries: the ``back`` (x = 0), the arms' ends, the slot's two
    faces, the cut (``mid``); in 3D also ``front`` and ``rear``."""
    up = np.unique(np.r_[np.linspace(0.0, T, 10 if mesh_cls is MeshQuad else 5),
                         np.linspace(T, T + GAP, 3),
                         np.linspace(T + GAP, H, 10 if mesh_cls is MeshQuad else 5)])
    if half:
        up = up[up <= 0.5 * H + 1e-12]
    mesh = mesh_cls.init_tensor(*across, up)
    z = mesh.p.shape[0] - 1  # the height's coordinate
    centre = mesh.p[:, mesh.t].mean(axis=1)
    keep = ~((centre[0] > BACK) & (centre[z] > T) & (centre[z] < T + GAP))
    mesh = kept_elements(mesh, keep)
    tol = 1e-9
    names = {
        "back": lambda x: x[0] < tol,
        "upper_end": lambda x: (x[0] > L - tol) & (x[z] > T + 0.5 * GAP),
        "lower_end": lambda x: (x[0] > L - tol) & (x[z] < T + 0.5 * GAP),
        "slot_top": lambda x: (np.abs(x[z] - T - GAP) < tol) & (x[0] > BACK),
        "slot_bottom": lambda x: (np.abs(x[z] - T) < tol) & (x[0] > BACK),
        "mid": lambda x: (np.abs(x[z] - 0.5 * H) < tol) & (x[0] < BACK)}
    if z == 2:
        depth = float(across[1][-1])
        names.update(front=lambda x: x[1] < tol, rear=lambda x: x[1] > depth - tol)
    return named_boundaries(mesh, names)


def u_mesh(half: bool = False) -> MeshQuad:
    """The U on its side in quadrilaterals of SIZE (:func:`slotted`)."""
    return slotted(MeshQuad, half, np.linspace(0.0, L, int(round(L / SIZE)) + 1))


#: a U of revolution (``plane = "axisymmetric"``): moved out to r = 1 ... 5, a groove round a
#: disk's rim closing (a bellows' convolution)
AXIS = {"plane": "axisymmetric"}


def material(section: dict) -> LinearElastic:
    return LinearElastic(E, NU, **section)


def moved(mesh, section: dict):
    return mesh.translated((1.0, 0.0)) if section else mesh


def closing_u(kinematics: str = "small", section: dict | None = None) -> Model:
    """The U's arms pressed together by equal and opposite tractions on their ends: they meet
    at their tips, on the plane of symmetry y = H/2."""
    section = section or {}
    u = Body("u", moved(u_mesh(), section), material(section), supports=[Support("back")],
             tractions=[Traction("upper_end", (0.0, -P)), Traction("lower_end", (0.0, P))],
             contact_boundaries=["slot_top", "slot_bottom"], kinematics=kinematics)
    return Model("u", [u], load_factors=STEPS, contact_pairs=(("u:slot_top", "u:slot_bottom"),))


def halved_u(kinematics: str = "small", section: dict | None = None) -> Model:
    """The same, halved by its symmetry: the lower arm against a plane a million times
    stiffer on y = H/2 (the upper arm's mirror image), the cut held along y."""
    section = section or {}
    half = Body("u", moved(u_mesh(half=True), section), material(section),
                supports=[Support("back"), Support("mid", ("y",))],
                tractions=[Traction("lower_end", (0.0, P))], contact_boundaries=["slot_bottom"],
                kinematics=kinematics)
    plane = Body("plane", moved(block(BACK, 0.5 * H, L - BACK, 0.1, SIZE), section),
                 LinearElastic(1e6 * E, NU, **section), supports=[Support("top")],
                 contact_boundaries=["bottom"])
    return Model("half", [half, plane], load_factors=STEPS)


def by_load_factor(result) -> dict:
    return {round(s.load_factor, 9): s for s in result.steps}


@pytest.mark.parametrize("section", [{}, AXIS], ids=["plane strain", "axisymmetric"])
def test_a_u_closing_on_itself_is_its_half_against_the_plane_of_symmetry(section):
    """Small kinematics: the U's arms meeting tip to tip (self-contact) carry, at every node
    of the lower arm and at every step both runs reach, the contact forces and displacements of
    the halved model against a stiff plane to 1e-6 of the largest (the plane's compliance, a
    millionth of the arm's, is the one difference); the invariants pass at every step. In
    plane strain, and as a body of revolution (the U moved out to r = 1 ... 5: a groove round a
    disk's rim, its two faces closing on each other, forces per full circle)."""
    whole, half = Analysis(closing_u(section=section)).run(), \
        Analysis(halved_u(section=section)).run()
    assert whole.converged, whole.message
    assert half.converged, half.message
    assert all(s.invariants["passed"] for s in whole.steps)
    u = whole.model.bodies[0]
    lower = half.model.bodies[0]
    distance, match = cKDTree(u.points.T).query(lower.points.T)
    assert distance.max() < 1e-12
    steps = by_load_factor(half)
    compared = 0
    for step in whole.steps:
        other = steps.get(round(step.load_factor, 9))
        if other is None:  # (a step the other run cut)
            continue
        mine, theirs = step.bodies["u"], other.bodies["u"]
        f, g = mine.contact_force[match], theirs.contact_force
        assert np.abs(f - g).max() <= 1e-6 * max(np.abs(g).max(), 1e-300) + 1e-300
        d, e = mine.displacement[match], theirs.displacement
        assert np.abs(d - e).max() <= 1e-6 * np.abs(e).max()
        compared += 1
    assert compared >= 8
    last = whole.steps[-1].bodies["u"]
    assert np.abs(last.contact_force).max() > 0
    # equal and opposite on the two sides: the body's own total vanishes
    assert np.abs(last.contact_force.sum(axis=0)).max() <= 1e-12 * np.abs(
        last.contact_force).sum()


def test_a_u_closing_on_itself_at_finite_strain():
    """Large kinematics (total Lagrangian): the same two runs converge with the invariants
    passed at every step, and the arms' total contact force is the halved model's to 1e-3
    (measured 5e-5: the tips meet corner to corner, each on the other's facet rotated by the
    bending, where the halved model's corner meets a flat plane: the nodal split differs by
    2 %, at the level of the discretisation)."""
    whole, half = Analysis(closing_u("total")).run(), Analysis(halved_u("total")).run()
    assert whole.converged, whole.message
    assert half.converged, half.message
    assert all(s.invariants["passed"] for s in whole.steps)
    u, lower = whole.model.bodies[0], half.model.bodies[0]
    _, match = cKDTree(u.points.T).query(lower.points.T)
    f = whole.steps[-1].bodies["u"].contact_force[match][:, 1].sum()
    g = half.steps[-1].bodies["u"].contact_force[:, 1].sum()
    assert g < 0 and f == pytest.approx(g, rel=1e-3)  # (the plane pushes the arm down)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("load", [-0.2, 0.2])
def test_a_straight_boundary_bent_either_way_stays_free(order, load):
    """A cantilever whose top is split at mid-length into two sides that may touch each
    other, bent down (the top convex) and up (concave, its two halves turning towards each
    other): no node meets the other side where the two sides meet, nor its own facets: no
    contact force anywhere, the invariants passed."""
    mesh = named_boundaries(block(0.0, 0.0, 4.0, 0.4, 0.1), {
        "top_left": lambda x: (x[1] > 0.4 - 1e-9) & (x[0] < 2.0),
        "top_right": lambda x: (x[1] > 0.4 - 1e-9) & (x[0] > 2.0)})
    beam = Body("beam", mesh, LinearElastic(E, NU), supports=[Support("left")],
                tractions=[Traction("right", (0.0, load))],
                contact_boundaries=["top_left", "top_right"], order=order)
    model = Model("bend", [beam], load_factors=(0.5, 1.0),
                  contact_pairs=(("beam:top_left", "beam:top_right"),))
    result = Analysis(model).run()
    assert result.converged, result.message
    last = result.steps[-1].bodies["beam"]
    assert np.abs(last.displacement[:, 1]).max() > 0.25  # bent well past the element size
    assert not np.any(last.contact_force)
    assert not np.any(last.contact_status > 0)
    assert all(s.invariants["passed"] for s in result.steps)


def test_the_invariants_read_a_body_against_itself():
    """Invariant (b) between a body's two sides: the upper arm's tip pushed 0.02 through the
    lower arm's face (a state made by hand) is interpenetration into the body's other side;
    the same arm 0.02 short of it is not. Invariant (a): equal and opposite forces on the two
    sides balance; 1e-3 of a side's force left over fails (measured against the side's
    total, which the body's own total, zero, does not show)."""
    model = closing_u()
    u = model.bodies[0]
    check = InvariantCheck(model, penetration_tolerance=1e-9)
    x, y = u.points
    tip = (y > T + GAP - 1e-9) & (x > L - BACK)  # the upper arm's last metre
    shift = (x - (L - BACK)) / BACK

    class Fields:
        def __init__(self, drop, forces):
            d = np.zeros((u.npoints, 2))
            d[tip, 1] = -drop * shift[tip]
            self.displacement, self.contact_force = d, forces

    none = np.zeros((u.npoints, 2))
    through = check({"u": Fields(GAP + 0.02, none)})
    assert not through.separated
    assert "its other side" in through.where["into"]
    assert through.max_penetration == pytest.approx(0.02, rel=1e-9)
    assert through.penetration > through.allowed
    assert check({"u": Fields(GAP - 0.02, none)}).separated
    # two nodes facing each other across the slot's end, equal and opposite forces
    a = int(np.flatnonzero((np.abs(y - T - GAP) < 1e-9) & (np.abs(x - L) < 1e-9))[0])
    b = int(np.flatnonzero((np.abs(y - T) < 1e-9) & (np.abs(x - L) < 1e-9))[0])
    forces = np.zeros((u.npoints, 2))
    forces[a, 1], forces[b, 1] = 1.0, -1.0
    assert check({"u": Fields(GAP, forces)}).balanced
    forces[b, 1] = -1.0 + 1e-3
    assert not check({"u": Fields(GAP, forces)}).balanced


@pytest.mark.parametrize(("pair", "words"), [
    (("u", "u:slot_top"), "share .* facets \\('u' is its whole contact surface\\)"),
    (("u:slot_top", "u:slot_top,slot_bottom"), "share .* facets .*'slot_top' is named on both"),
])
def test_a_body_named_twice_needs_two_apart_sides(pair, words):
    """A body paired with itself must name two different sides sharing no facet (or one side
    twice: a surface that finds its own sides, tests/test_single_surface.py): said, with the
    entry and the body."""
    model = closing_u()
    model.contact_pairs = (pair,)
    with pytest.raises(InputError, match=words):
        model.validate()


def u_mesh_3d(half: bool = False) -> MeshHex:
    """:func:`u_mesh` extruded 0.4 deep along y in two elements (z up, elements of 0.2 along
    x): its faces ``front`` and ``rear`` (y = 0, 0.4) beside the 2D boundaries."""
    return slotted(MeshHex, half, np.linspace(0.0, L, 21), np.linspace(0.0, 0.4, 3))


def test_a_u_closing_on_itself_in_3d_is_its_half_against_the_plane_of_symmetry():
    """3D (hexahedra; the U extruded and held in plane strain by its front and rear faces):
    the arms meeting tip to tip carry the halved model's contact forces and displacements
    against a plane a million times stiffer to 1e-6 of the largest at every step (measured
    2.4e-8 and 3.3e-9), with the invariants passed at every step."""
    walls = [Support("front", ("y",)), Support("rear", ("y",))]
    u = Body("u", u_mesh_3d(), LinearElastic(E, NU), supports=[Support("back"), *walls],
             tractions=[Traction("upper_end", (0.0, 0.0, -P)),
                        Traction("lower_end", (0.0, 0.0, P))],
             contact_boundaries=["slot_top", "slot_bottom"])
    whole = Analysis(Model("u3", [u], load_factors=STEPS,
                           contact_pairs=(("u:slot_top", "u:slot_bottom"),))).run()
    half = Body("u", u_mesh_3d(half=True), LinearElastic(E, NU),
                supports=[Support("back"), Support("mid", ("z",)), *walls],
                tractions=[Traction("lower_end", (0.0, 0.0, P))],
                contact_boundaries=["slot_bottom"])
    plane = Body("plane", box(BACK, 0.0, 0.5 * H, L - BACK, 0.4, 0.1, nx=15, ny=2, nz=1),
                 LinearElastic(1e6 * E, NU), supports=[Support("top")],
                 contact_boundaries=["bottom"])
    halved = Analysis(Model("half", [half, plane], load_factors=STEPS)).run()
    assert whole.converged, whole.message
    assert halved.converged, halved.message
    assert all(s.invariants["passed"] for s in whole.steps)
    distance, match = cKDTree(u.points.T).query(half.points.T)
    assert distance.max() < 1e-12
    steps = by_load_factor(halved)
    compared = 0
    for step in whole.steps:
        other = steps.get(round(step.load_factor, 9))
        if other is None:
            continue
        f, g = step.bodies["u"].contact_force[match], other.bodies["u"].contact_force
        assert np.abs(f - g).max() <= 1e-6 * max(np.abs(g).max(), 1e-300) + 1e-300
        d, e = step.bodies["u"].displacement[match], other.bodies["u"].displacement
        assert np.abs(d - e).max() <= 1e-6 * np.abs(e).max()
        compared += 1
    assert compared >= 8 and np.abs(whole.steps[-1].bodies["u"].contact_force).max() > 0


def test_the_invariants_read_a_3d_body_against_itself():
    """Invariant (b) in 3D between a body's two sides: the upper arm's tip pushed 0.02 through
    the lower arm's face is interpenetration into its other side, 0.02 deep; 0.02 short of it
    is not."""
    u = Body("u", u_mesh_3d(), LinearElastic(E, NU), supports=[Support("back")],
             contact_boundaries=["slot_top", "slot_bottom"])
    model = Model("u3", [u], contact_pairs=(("u:slot_top", "u:slot_bottom"),))
    check = InvariantCheck(model, penetration_tolerance=1e-9)
    x, _, z = u.points
    tip = (z > T + GAP - 1e-9) & (x > L - BACK)
    shift = (x - (L - BACK)) / BACK

    class Fields:
        def __init__(self, drop):
            d = np.zeros((u.npoints, 3))
            d[tip, 2] = -drop * shift[tip]
            self.displacement, self.contact_force = d, np.zeros((u.npoints, 3))

    through = check({"u": Fields(GAP + 0.02)})
    assert not through.separated
    assert "its other side" in through.where["into"]
    assert through.max_penetration == pytest.approx(0.02, rel=1e-9)
    assert check({"u": Fields(GAP - 0.02)}).separated
