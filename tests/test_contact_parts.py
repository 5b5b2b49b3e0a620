"""The contact core's shared parts, each tested on its own (issue 18): the iteration loop, the
platen's bordered solve, the traction transfer of the paired variant on a uniform traction, the
surface's normal flexibility, its dofs, "beyond the end of the surface", the formulations'
capabilities and the contract they implement."""

from types import SimpleNamespace

import numpy as np
import pytest

from models import strip_surfaces
from vfem.contact.formulations.algorithm import VirtualElementContact
from vfem.contact.formulations.baselines import GlobalContact
from vfem.contact.formulations.formulation import check_capabilities, formulation_class
from vfem.contact.formulations.large import LargeDeformationContact
from vfem.contact.formulations.paired import PairedContact
from vfem.contact.geometry import ContactPairs
from vfem.contact.geometry.pairing import overlap
from vfem.contact.geometry.surface import beyond, patch_ends
from vfem.contact.settings import ContactSettings
from vfem.contact.solvers import bordered_solve
from vfem.contact.solvers.iteration import Check, iterate
from vfem.contact.state import IterationRecord
from vfem.errors import ContactCycling, ContactNotConverged, InputError

# -- the iteration loop ----------------------------------------------------------------------------


def fake_check(errors, masks, finished=None):
    """A check whose error and contact set follow the given sequences."""

    def check(it):
        e = errors[min(it, len(errors) - 1)]
        m = masks[min(it, len(masks) - 1)]
        return Check(IterationRecord(it, e, 0.0, int(m.sum()), 0), e <= 1e-9,
                     lambda: [("body", np.arange(len(m)), m)], e, lambda: [],
                     lambda: f"no convergence in the test (error {e:g})",
                     finish=(lambda: finished.append(it)) if finished is not None else None)

    return check


def test_the_loop_converges_records_reports_and_finishes_once():
    seen, finished, corrected = [], [], []
    errors = [1.0, 0.1, 0.01, 0.0]
    masks = [np.array([True, False])] * 4
    res = iterate(ContactSettings(max_iterations=10), fake_check(errors, masks, finished),
                  lambda it, c: corrected.append(it), seen.append)
    assert res.converged and res.iterations == 3 and len(res.history) == 4
    assert [r.iteration for r in seen] == [0, 1, 2, 3]  # every record, as it is made
    assert corrected == [0, 1, 2] and finished == [3]


def test_a_contact_set_that_keeps_coming_back_is_a_cycling_failure():
    a, b = np.array([True, False]), np.array([False, True])
    res = iterate(ContactSettings(max_iterations=50), fake_check([1.0], [a, b] * 30),
                  lambda it, c: None)
    assert not res.converged and res.failure is ContactCycling
    assert "cycles" in res.message and res.iterations < 50


def test_the_iteration_limit_is_a_no_convergence_failure_with_the_checks_message():
    res = iterate(ContactSettings(max_iterations=5), fake_check([1.0], [np.array([True])]),
                  lambda it, c: None)
    assert not res.converged and res.failure is ContactNotConverged
    assert res.iterations == 5 and len(res.history) == 6
    assert res.message == "no convergence in the test (error 1)"


def test_a_formulations_own_stopping_rule_ends_the_solve():
    res = iterate(ContactSettings(), fake_check([1.0], [np.array([True])]),
                  lambda it, c: (True, True) if it == 2 else None)
    assert res.converged and res.fixed_point and res.iterations == 2


# -- the platen's bordered system ------------------------------------------------------------------


def test_the_bordered_solve_meets_both_blocks_of_equations():
    rng = np.random.default_rng(3)
    m = 6
    B = rng.normal(size=(m, m))
    W = B @ B.T + m * np.eye(m)
    column, row, rhs = rng.normal(size=m), rng.normal(size=m), rng.normal(size=m)
    for lu_first in (False, True):
        x, d = bordered_solve(W, column, row, 2.5, rhs, 0.7, lu_first=lu_first)
        np.testing.assert_allclose(W @ x + column * d, rhs, atol=1e-12)
        assert row @ x + 2.5 * d == pytest.approx(0.7, abs=1e-12)


def test_a_singular_bordered_system_gets_its_least_squares_answer():
    # a platen body with no node in contact and nothing else holding it: zero row and corner
    W = np.eye(2)
    x, d = bordered_solve(W, np.zeros(2), np.zeros(2), 0.0, np.array([1.0, 2.0]), 0.0,
                          lu_first=True)
    np.testing.assert_allclose(x, [1.0, 2.0])
    assert d == pytest.approx(0.0)


# -- surfaces: two non-matching blocks, the lower one's top against the upper one's bottom ---------


@pytest.fixture(scope="module")
def surfaces():
    return strip_surfaces(3, 7)


@pytest.mark.parametrize("fine", [0, 1])
def test_the_paired_transfer_carries_a_uniform_traction_exactly(surfaces, fine):
    """F_fine = N q and F_coarse = -T q (eq. 4.4.11): a uniform traction 1 over the whole
    interface gives each side its consistent nodal loads (the tributary lengths), the two
    totals equal and opposite to round-off, whichever side carries compatibility."""
    sf, sc = surfaces[fine], surfaces[1 - fine]
    geo = overlap(sf, sc)
    q = np.zeros(sf.nc)
    q[geo.nodes] = 1.0
    f_fine, f_coarse = geo.mass @ q, geo.transfer @ q
    np.testing.assert_allclose(f_fine, sf.tributary, rtol=1e-12)
    np.testing.assert_allclose(f_coarse, sc.tributary, rtol=1e-12)
    assert f_fine.sum() == pytest.approx(f_coarse.sum(), rel=1e-14)
    np.testing.assert_allclose(geo.gap, 0.0, atol=1e-15)  # the blocks touch along y = 0


def test_the_normal_flexibility_is_symmetric_and_its_diagonal_the_castigliano_stiffness(
        surfaces):
    s = surfaces[1]
    nodes = np.arange(s.nc)
    n = np.tile([0.6, -0.8], (s.nc, 1))
    F = s.normal_flexibility(nodes, n)
    np.testing.assert_allclose(F, F.T, rtol=1e-12, atol=0)
    np.testing.assert_allclose(1.0 / np.diag(F), s.normal_stiffness(nodes, n), rtol=1e-12)
    # the normal motion of each node under unit normal forces, from the flexibility itself
    f = np.zeros(s.dim * s.nc)
    f[s.dofs_of(nodes)] = (n * np.arange(1, s.nc + 1)[:, None]).ravel()
    u = (s.C @ f).reshape(-1, s.dim)
    np.testing.assert_allclose(np.einsum("ij,ij->i", u, n), F @ np.arange(1, s.nc + 1),
                               rtol=1e-12)


def test_the_dofs_of_a_node_are_its_components_in_turn(surfaces):
    s = surfaces[0]
    assert s.dim == 2
    np.testing.assert_array_equal(s.dofs_of(np.array([0, 3])), [0, 1, 6, 7])
    np.testing.assert_array_equal(s.candidate_dofs, s.dofs_of(s.nodes[: s.nc]))


def test_beyond_the_end_of_a_surface_only_past_its_end_facets(surfaces):
    s = surfaces[0]  # the lower block's top: 3 facets from x = 0 to 1
    ends = patch_ends(s, np.arange(len(s.facets)))
    assert ends.sum() == 2
    points = np.array([[-0.2, 0.1], [0.5, 0.1], [1.3, 0.1]])
    seg, _, _, _, t_free = s.closest(points)
    np.testing.assert_array_equal(beyond(s, seg, t_free, ends), [True, False, True])
    np.testing.assert_array_equal(beyond(s, seg, t_free, s.surface_ends), [True, False, True])


def test_a_2d_surface_reaches_its_facets_through_its_segment_kind(surfaces):
    """The facet-kind layer (vfem.contact.geometry.facets): a 2D surface's kind is Segment(order),
    and the surface's geometry goes through it (issue 21, C4)."""
    from vfem.contact.geometry.facets import FACET_READINGS, Segment
    from vfem.contact.search.closest import outward_normals

    s = surfaces[0]  # the lower block's top: 3 facets from x = 0 to 1
    assert s.kind == Segment(1) and s.kind.corners == 2 and s.kind.nodes == 2
    np.testing.assert_array_equal(s.kind.readings, FACET_READINGS)
    np.testing.assert_array_equal(s.facet_normals(), outward_normals(*s.segments(s.X)))
    seg, xi = np.array([0, 1, 2]), np.array([0.25, 0.5, 1.0])
    pos, jn = s.surface_map(seg, xi)
    cpos, tangent = s.curve(seg, xi)
    np.testing.assert_array_equal(pos, cpos)
    np.testing.assert_array_equal(np.linalg.norm(jn, axis=1), np.linalg.norm(tangent, axis=1))
    np.testing.assert_allclose(jn / np.linalg.norm(jn, axis=1)[:, None], [[0.0, 1.0]] * 3)
    boundary = s.patch_boundary(np.arange(len(s.facets)))
    np.testing.assert_array_equal(s.boundary_nodes(boundary), s.surface_ends)
    points = np.array([[0.0, 0.1], [0.5, 0.1], [1.3, 0.1]])
    seg, _, _, _, xi_free = s.closest(points)
    np.testing.assert_array_equal(s.on_boundary(seg, xi_free, boundary), [True, False, True])
    np.testing.assert_array_equal(s.beyond(seg, xi_free, boundary), [False, False, True])
    np.testing.assert_array_equal(s.kind.strictly_inside(np.array([0.0, 0.5, 1.0])),
                                  [False, True, False])
    t = np.array([0.0, 0.5])
    anchors = s.material_points(seg[:2], s.interpolation(seg[:2], t))
    np.testing.assert_array_equal(np.floor(anchors), seg[:2])
    np.testing.assert_allclose(s.material_positions(anchors, s.X), s.curve(seg[:2], t)[0],
                               atol=1e-15)


# -- the formulations' contract and capabilities ---------------------------------------------------


@pytest.mark.parametrize(("method", "variant", "large", "cls"), [
    ("vfem", "paired", False, PairedContact), ("vfem", "thesis", False, VirtualElementContact),
    ("vfem", "paired", True, LargeDeformationContact),
    ("penalty", "paired", False, GlobalContact), ("lagrange", "thesis", False, GlobalContact)])
def test_each_setting_picks_one_formulation_that_implements_the_contract(method, variant,
                                                                         large, cls):
    picked = formulation_class(ContactSettings(method=method, variant=variant), large)
    assert picked is cls
    for name in ("new_state", "solve", "fields"):
        assert callable(getattr(picked, name)), name
    caps = picked.capabilities
    # 3D contact: the paired variant's, linear elements (issue 21, C10), large kinematics too
    # (C16)
    paired = cls in (PairedContact, LargeDeformationContact)
    assert caps.dimensions == ((2, 3) if paired else (2,))
    assert caps.orders_3d == ({PairedContact: (1, 2), LargeDeformationContact: (1,)}
                              .get(cls, ()))  # quadratic: tetrahedra, small, frictionless
    # Coulomb friction: the frictional formulations' (vfem), the lagrange baseline's
    assert caps.friction == (("coefficients",) if cls is GlobalContact else ())
    assert ("large" in caps.kinematics) == (cls is LargeDeformationContact)
    assert caps.cuts_steps == (cls is not GlobalContact)


def fake_model(order=1, dim=2, large=False, corners=4, **settings):
    """Two alike bodies that may touch (``contact_pairs`` None: every pair): a body that may
    touch none is not the contact formulation's to refuse (``bodies_that_may_touch``).
    ``corners``: of an element (3D: 4 tetrahedra, 8 hexahedra)."""
    bodies = [SimpleNamespace(name=name, order=order, large=large, iterates=large, platen=None,
                              mesh=SimpleNamespace(p=np.zeros((dim, 3)),
                                                   t=np.zeros((corners, 1), dtype=int)))
              for name in "ab"]
    return SimpleNamespace(name="m", bodies=bodies, contact=ContactSettings(**settings),
                           contact_pairs=None, iterates=large,
                           pairs=lambda: ContactPairs.every(len(bodies)))


def test_the_model_checks_read_the_declared_capabilities():
    check_capabilities(fake_model(order=2))  # the paired variant: quadratic elements too
    with pytest.raises(InputError, match="the thesis variant supports linear elements only"):
        check_capabilities(fake_model(order=2, variant="thesis"))
    with pytest.raises(InputError, match="contact with a large-kinematics body needs linear"):
        check_capabilities(fake_model(order=2, large=True))
    with pytest.raises(InputError, match="large kinematics needs the paired contact variant"):
        check_capabilities(fake_model(large=True, variant="thesis"))
    with pytest.raises(InputError, match="classical contact methods .* need linear elements"):
        check_capabilities(fake_model(large=True, method="penalty"))
    check_capabilities(fake_model(dim=3))  # the paired variant: linear 3D bodies too (C10)
    with pytest.raises(InputError, match="thesis contact supports 2D bodies, this one is 3D"):
        check_capabilities(fake_model(dim=3, variant="thesis"))
    check_capabilities(fake_model(dim=3, large=True))  # large kinematics in 3D (C16)
    check_capabilities(fake_model(order=2, dim=3))  # quadratic tetrahedra (2026-11-28)
    with pytest.raises(InputError, match="3D contact of quadratic hexahedra"):
        check_capabilities(fake_model(order=2, dim=3, corners=8))
    with pytest.raises(InputError, match="3D contact with friction supports linear elements"):
        check_capabilities(fake_model(order=2, dim=3, friction=0.3))
    check_capabilities(fake_model(dim=3, friction=0.3))  # friction in 3D, small (C13)
    # friction in 3D under large kinematics (2026-11-28; tests/test_large_friction3d.py)
    check_capabilities(fake_model(dim=3, large=True, friction=0.3))
    with pytest.raises(InputError, match="contact with a large-kinematics body needs linear"):
        check_capabilities(fake_model(order=2, dim=3, large=True, friction=0.3))


# -- each formulation's own typed state ------------------------------------------------------------


def test_a_state_copy_keeps_its_type_and_owns_its_arrays():
    from vfem.contact.state import STATE_TYPES, BaselineState, TractionState

    base = dict(load_factor=0.5, platen_displacement=0.1, forces=[np.ones((2, 2))],
                released=[np.zeros(2, dtype=bool)], platen_force=3.0)
    for state in (TractionState(**base, tractions={0: np.array([1.0, 2.0])}),
                  BaselineState(**base, pressures=np.array([4.0]), active=np.array([True]))):
        copied = state.copy()
        assert type(copied) is type(state) and STATE_TYPES[type(state).__name__] is type(state)
        for name, value in state.unknowns().items():
            np.testing.assert_array_equal(copied.unknowns()[name], value)
            assert copied.unknowns()[name] is not value
        copied.forces[0][0, 0] = 7.0
        assert state.forces[0][0, 0] == 1.0
        rebuilt = type(state)(**base).with_unknowns(state.unknowns())
        assert sorted(rebuilt.unknowns()) == sorted(state.unknowns())


@pytest.mark.parametrize(("method", "expected"), [("vfem", "TractionState"),
                                                  ("lagrange", "BaselineState")])
def test_a_checkpoint_written_before_the_states_were_typed_reads_back(method, expected):
    from vfem.io.checkpoint import _state

    meta = {"load_factor": 1.0, "platen_displacement": 0.0, "platen_force": 0.0,
            "multipliers": [0, 1]}
    arrays = {"force_0": np.zeros((2, 2)), "released_0": np.zeros(2, dtype=bool),
              "multiplier_0": np.array([0.5, 0.0]), "multiplier_1": np.array([1.0, 0.0])}
    model = SimpleNamespace(bodies=[None], contact=ContactSettings(method=method))
    state = _state(meta, arrays, model)
    assert type(state).__name__ == expected
    if expected == "BaselineState":
        np.testing.assert_array_equal(state.active, [True, False])
        np.testing.assert_array_equal(state.pressures, [0.5, 0.0])
    else:
        np.testing.assert_array_equal(state.tractions[1], [1.0, 0.0])
