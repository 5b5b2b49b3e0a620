"""The invariants of vfem.contact.invariants.check on 3D bodies (issue 21, C9 of the 3D plan):
hand-made states of two boxes (hexahedra and tetrahedra) touching at a flat interface, z = 0.

A consistent state (equal and opposite forces from one pressure field, the lower box's share
by ``transfer_matrices``, no penetration) passes; a node moved 10x the penetration tolerance
into the other box fails (b) naming it; unbalanced forces fail (a); a tensile force fails (c).
"""

from types import SimpleNamespace

import numpy as np
import pytest

from vfem.bodies import Body, Support
from vfem.contact.geometry.surface import ContactSurface
from vfem.contact.geometry.transfer import transfer_matrices
from vfem.contact.invariants.check import InvariantCheck
from vfem.materials import LinearElastic
from vfem.mesh.solids import box

MAT = LinearElastic(1000.0, 0.3)
TOL = 1e-8
PRESSURE = 10.0


def boxes(lower_cells, upper_cells):
    """A box 0.2 <= x, y <= 0.8, 0 <= z <= 0.5 resting on a wider one, 0 <= x, y <= 1,
    -0.5 <= z <= 0; the meshes do not match."""
    lower = Body("lower", box(0, 0, -0.5, 1, 1, 0.5, nx=5, ny=5, nz=1,
                              tetrahedra=lower_cells == "tet"), MAT,
                 supports=(Support("bottom"),))
    upper = Body("upper", box(0.2, 0.2, 0, 0.6, 0.6, 0.5, nx=4, ny=4, nz=1,
                              tetrahedra=upper_cells == "tet"), MAT,
                 supports=(Support("top"),))
    return lower, upper


def state(lower, upper, pressure=PRESSURE):
    """Zero displacements; a uniform ``pressure`` between the boxes: the upper box's
    consistent nodal forces (N q) and the lower box's (-T q) from one transfer."""
    out = {b.name: SimpleNamespace(displacement=np.zeros((b.npoints, 3)),
                                   contact_force=np.zeros((b.npoints, 3)))
           for b in (lower, upper)}
    sf = ContactSurface.build(upper, upper.mesh.boundaries["bottom"])
    sc = ContactSurface.build(lower, lower.mesh.boundaries["top"])
    fpatch, cpatch = np.arange(len(sf.facets)), np.arange(len(sc.facets))
    N, T = transfer_matrices(sf, sc, fpatch, cpatch, sc.node_normals(sc.X, cpatch),
                             sc.patch_boundary(cpatch), 0.0, sf.X, sc.X)
    q = np.full(sf.nc, pressure)
    out["upper"].contact_force[sf.nodes[: sf.nc], 2] += N @ q  # pushed up, into the box
    out["lower"].contact_force[sc.nodes[: sc.nc], 2] -= T @ q
    return out


CELLS = [("hex", "tet"), ("tet", "hex"), ("hex", "hex"), ("tet", "tet")]


@pytest.fixture(params=CELLS, ids=[f"{a}-{b}" for a, b in CELLS])
def model(request):
    lower, upper = boxes(*request.param)
    return lower, upper, InvariantCheck([lower, upper], [("lower", "upper")], TOL)


def test_a_consistent_state_passes(model):
    lower, upper, check = model
    fields = state(lower, upper)
    inv = check(fields)
    assert inv.ok, inv.message()
    assert inv.force_balance < 1e-12
    assert len(inv.resultant) == 3
    assert inv.totals["upper"][2] == pytest.approx(PRESSURE * 0.36, rel=1e-10)
    assert inv.tension == 0.0
    assert inv.max_penetration <= TOL
    record = inv.record()
    assert record["passed"] and record["failed"] == []


def test_the_whole_box_pressed_in_fails_b(model):
    lower, upper, check = model
    fields = state(lower, upper)
    fields["upper"].displacement[:, 2] = -10 * TOL
    inv = check(fields)
    assert inv.failed() == ["interpenetration"]
    assert inv.penetration == pytest.approx(10 * TOL, rel=1e-6)
    assert {inv.where["body"], inv.where["into"]} == {"upper", "lower"}
    assert inv.where["z"] == pytest.approx(-10 * TOL if inv.where["body"] == "upper" else 0)
    assert inv.where["linearised_depth"] == pytest.approx(10 * TOL, rel=1e-6)
    assert "invariant (b) no interpenetration violated" in inv.message()


def test_a_node_moved_in_fails_b_naming_it(model):
    lower, upper, check = model
    fields = {b.name: SimpleNamespace(displacement=np.zeros((b.npoints, 3)),
                                      contact_force=np.zeros((b.npoints, 3)))
              for b in (lower, upper)}
    X = upper.points
    node = int(np.flatnonzero((np.abs(X[0] - 0.5) < 1e-9) & (np.abs(X[1] - 0.5) < 1e-9)
                              & (np.abs(X[2]) < 1e-9))[0])
    fields["upper"].displacement[node, 2] = -10 * TOL
    inv = check(fields)
    assert inv.failed() == ["interpenetration"]
    assert inv.where["node"] == node and inv.where["body"] == "upper"
    assert (inv.where["x"], inv.where["y"]) == pytest.approx((0.5, 0.5))
    assert inv.penetration == pytest.approx(10 * TOL, rel=1e-6)
    assert f"node {node} of body 'upper', at (0.5, 0.5, -1e-07)" in inv.message()
    # moved away instead: nothing inside
    fields["upper"].displacement[node, 2] = 10 * TOL
    assert check(fields).ok


def test_a_node_of_the_lower_box_moved_up_fails_b(model):
    lower, upper, check = model
    fields = state(lower, upper)
    X = lower.points
    node = int(np.flatnonzero((np.abs(X[0] - 0.6) < 1e-9) & (np.abs(X[1] - 0.4) < 1e-9)
                              & (np.abs(X[2]) < 1e-9))[0])
    fields["lower"].displacement[node, 2] = 1e-3  # far beyond any faceting allowance
    inv = check(fields)
    assert "interpenetration" in inv.failed()
    assert inv.where["node"] == node and inv.where["into"] == "upper"


def test_unbalanced_forces_fail_a(model):
    lower, upper, check = model
    fields = state(lower, upper)
    fields["lower"].contact_force *= 0.99
    inv = check(fields)
    assert inv.failed() == ["force balance"]
    assert inv.force_balance == pytest.approx(0.01, rel=1e-6)
    assert inv.resultant[2] == pytest.approx(0.01 * PRESSURE * 0.36, rel=1e-6)
    assert "invariant (a) force balance violated" in inv.message()


def test_a_tensile_force_fails_c(model):
    lower, upper, check = model
    fields = state(lower, upper)
    f = fields["upper"].contact_force
    X = upper.points
    node = int(np.flatnonzero((np.abs(X[0] - 0.5) < 1e-9) & (np.abs(X[1] - 0.5) < 1e-9)
                              & (np.abs(X[2]) < 1e-9))[0])
    f[node, 2] = -1.0  # pulls the upper box's bottom down: tension (balance broken too)
    inv = check(fields)
    assert "tension" in inv.failed()
    assert inv.tension_where == {"body": "upper", "node": node, "value": pytest.approx(1.0)}
    # a tangential force is no tension
    fields = state(lower, upper)
    fields["upper"].contact_force[node] += [0.5, -0.3, 0.0]
    assert "tension" not in check(fields).failed()


def test_symmetry_planes_are_no_surface():
    """A quarter model: the lower box held by rollers on x = 0 and y = 0 (symmetry planes); a
    node of the upper box on the plane x = 0 pressed into the lower box's top is measured
    against the top, not against the plane."""
    lower = Body("lower", box(0, 0, -0.5, 1, 1, 0.5, nx=3, ny=3, nz=1), MAT,
                 supports=(Support("bottom"), Support("left", "x"), Support("front", "y")))
    upper = Body("upper", box(0, 0, 0, 0.5, 0.5, 0.5, nx=2, ny=2, nz=1, tetrahedra=True),
                 MAT, supports=(Support("left", "x"), Support("front", "y")))
    check = InvariantCheck([lower, upper], [("lower", "upper")], TOL)
    fields = {b.name: SimpleNamespace(displacement=np.zeros((b.npoints, 3)),
                                      contact_force=np.zeros((b.npoints, 3)))
              for b in (lower, upper)}
    assert check(fields).ok
    X = upper.points
    node = int(np.flatnonzero((np.abs(X[0]) < 1e-9) & (np.abs(X[1] - 0.25) < 1e-9)
                              & (np.abs(X[2]) < 1e-9))[0])
    fields["upper"].displacement[node, 2] = -10 * TOL
    inv = check(fields)
    assert inv.failed() == ["interpenetration"] and inv.where["node"] == node
    assert inv.penetration == pytest.approx(10 * TOL, rel=1e-6)
    # the normal on the plane lies in it
    n = check.reference[0].normals
    x = check.reference[0].x
    top = np.flatnonzero((np.abs(x[:, 2]) < 1e-9) & (x[:, 0] < 1 - 1e-9) & (x[:, 1] < 1 - 1e-9))
    assert np.allclose(n[top], [0, 0, 1])


def test_3d_contact_without_pairs_or_forces_is_not_visited():
    lower, upper = boxes("hex", "tet")
    fields = {b.name: SimpleNamespace(displacement=np.zeros((b.npoints, 3)),
                                      contact_force=np.zeros((b.npoints, 3)))
              for b in (lower, upper)}
    check = InvariantCheck([lower, upper], [], TOL)
    assert check(fields).ok and check._reference is None


def test_the_consistent_measure_is_refused_in_3d():
    lower, upper = boxes("hex", "hex")
    check = InvariantCheck([lower, upper], [("lower", "upper")], TOL,
                           tension_measure="consistent")
    with pytest.raises(NotImplementedError, match="consistent tension measure in 3D"):
        check(state(lower, upper))
