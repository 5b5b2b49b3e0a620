"""The 3D contact patch test (issue 21, C10): a uniform pressure across non-matching 3D meshes.

Two stacked boxes (:func:`vfem.mesh.solids.box`), the lower one on rollers at its bottom
(z = -1), the upper one pressed down by a prescribed displacement of its top (z = 1), both on
rollers at x = 0 and y = 0 (supports of single components), so the exact state is uniaxial:
sigma_zz = -E * D / 2 in both bodies, the contact pressure its opposite, sigma_xx = sigma_yy = 0.
The interface meshes do not match (hexahedra against tetrahedra, hexahedra or tetrahedra of
other sizes). The paired variant must reach it to round-off in one contact iteration, with
every invariant passed, whichever body comes first; so must quadratic tetrahedra (6-node
triangular facets, their contact pressure the consistent one); quadratic hexahedra are refused
with a message (``check_capabilities``). Friction in 3D: tests/test_friction3d.py.
"""

import numpy as np
import pytest

from models import Raw, box_mesh, input_file, prescribed, support, toml_body
from vfem.bodies import Body, PrescribedDisplacement, Support
from vfem.bodies.stresses import stress
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.materials import LinearElastic
from vfem.mesh.solids import box
from vfem.solver import Analysis, Model

E, NU, D = 200.0, 0.3, 0.01  # D: the upper top's downward displacement
EXACT = E * D / 2.0  # the pressure: uniaxial stress over the total height 2
ROLLERS = (Support("left", ("x",)), Support("front", ("y",)))
# (cells, divisions across) of the lower and the upper box
CASES = [(("hex", 4), ("tet", 7)), (("tet", 7), ("hex", 4)), (("hex", 3), ("hex", 5)),
         (("tet", 4), ("tet", 6)), (("tet", 5), ("hex", 2))]
# quadratic tetrahedra (6-node facets): against each other and against linear hexahedra
# (measured 2026-11-28: pressure and traction uniform to 5e-13, sigma_zz to 2e-14)
QUADRATIC = [(("tet", 4), ("tet", 6), 2), (("hex", 3), ("tet", 5), (1, 2)),
             (("tet", 5), ("hex", 2), (2, 1))]


def stacked(lower, upper, order=1, swap=False, variant="paired", **settings) -> Model:
    """``order``: both bodies', or (the lower's, the upper's)."""
    mat = LinearElastic(E, NU)
    (cl, nl), (cu, nu) = lower, upper
    order_low, order_up = (order, order) if isinstance(order, int) else order
    low = Body("lower", box(0.0, 0.0, -1.0, 1.0, 1.0, 1.0, nl, nl, 2, tetrahedra=cl == "tet"),
               mat, supports=(Support("bottom", ("z",)), *ROLLERS),
               contact_boundaries=("top",), order=order_low)
    up = Body("upper", box(0.0, 0.0, 0.0, 1.0, 1.0, 1.0, nu, nu, 2, tetrahedra=cu == "tet"),
              mat, supports=ROLLERS, prescribed=(PrescribedDisplacement("top", "z", -D),),
              contact_boundaries=("bottom",), order=order_up)
    bodies = [up, low] if swap else [low, up]
    return Model("patch3d", bodies, contact=ContactSettings(variant=variant, **settings))


@pytest.mark.parametrize("swap", [False, True], ids=["lower-first", "upper-first"])
@pytest.mark.parametrize("lower,upper,order", [(lo, up, 1) for lo, up in CASES] + QUADRATIC,
                         ids=lambda c: f"{c[0]}{c[1]}" if isinstance(c, tuple) else
                         f"order{c}")
def test_uniform_pressure_and_stress_across_non_matching_3d_meshes(lower, upper, order, swap):
    model = stacked(lower, upper, order=order, swap=swap)
    result = Analysis(model).run()
    assert result.converged, result.message
    assert [s.iterations for s in result.steps] == [1] * len(result.steps)
    for step in result.steps:
        assert step.invariants["passed"], step.invariants
    last = result.steps[-1]
    for body in model.bodies:
        r = last.bodies[body.name]
        on = r.contact_status > 0
        side = "top" if body.name == "lower" else "bottom"
        touching = np.unique(body.facet_points(body.mesh.boundaries[side]))
        assert np.array_equal(np.flatnonzero(on), touching)  # the whole interface, no more
        assert np.abs(r.contact_pressure[on] / EXACT - 1).max() < 1e-8
        assert np.abs(r.contact_traction[on] / EXACT - 1).max() < 1e-8
        s = stress(body, r.displacement.ravel())
        assert np.abs(-s["szz"] / EXACT - 1).max() < 1e-8
        assert np.abs(s["sxx"]).max() < 1e-8 * EXACT and np.abs(s["syy"]).max() < 1e-8 * EXACT


def test_quadratic_hexahedra_and_quadratic_friction_in_3d_contact_are_refused():
    with pytest.raises(InputError, match=r"body 'lower': 3D contact of quadratic hexahedra "
                                         r"\(9-node facets\) is not implemented"):
        stacked(("hex", 3), ("hex", 5), order=2).validate()
    with pytest.raises(InputError, match=r"3D contact with friction supports linear elements "
                                         r"only"):
        stacked(("tet", 3), ("tet", 5), order=2, friction=0.3).validate()


def test_friction_in_3d_is_accepted_with_small_kinematics():
    """Friction in 3D: the paired variant, small kinematics, linear elements (C13; its tests:
    tests/test_friction3d.py); with large kinematics it is refused (there)."""
    stacked(("hex", 3), ("hex", 5), friction=0.3).validate()


def test_the_thesis_variant_stays_2d():
    with pytest.raises(InputError, match="thesis contact supports 2D bodies, this one is 3D"):
        stacked(("hex", 3), ("hex", 5), variant="thesis").validate()


STIFF_PUNCH = input_file(
    "stiff_punch_3d",
    toml_body("base", box_mesh(-1.0, -1.0, -1.0, 2.0, 2.0, 1.0, Raw("{n}"), Raw("{n}"), 4),
              support("bottom")),
    toml_body("punch", box_mesh(-0.37, -0.29, 0.01, 0.6, 0.5, 0.4, 5, 4, 2, tetrahedra=True),
              support("top", ["x", "y"]), prescribed("top", "z", -0.03), E=100000.0),
    load_factors=[0.25, 0.5, 0.75, 1.0])


@pytest.mark.parametrize("n", [9, pytest.param(18, marks=pytest.mark.slow)])
def test_a_stiff_punch_with_corners_inside_the_contact_starting_apart(n):
    """Not in the issue: a tetrahedral punch 100 times stiffer than a hexahedral base, started
    0.01 above it, its corners and edges inside the contact, pressed 0.02 into it. On the
    coarse base (9 x 9 over 2: facets longer than the punch's) and on one twice as fine every
    step converges with the forces balanced to round-off and no tension; the punch's corners
    indent the base between its nodes (measured 9e-3 and 7e-3 deep on 0.22 and 0.11 facets),
    which the faceting allowance accepts, as in 2D (docs/method.md §6: the stiff side keeps
    equilibrium). The fine base stopped at first touch before a corner's own turning counted
    in the allowance (check3d.Surface3.own_turning: its neighbours lay farther than the base's
    facet)."""
    from vfem.io.input import loads

    model = loads(STIFF_PUNCH.format(n=n)).build()
    result = Analysis(model).run()
    assert result.converged, result.message
    for step in result.steps:
        assert step.invariants["passed"]
        assert step.invariants["force_balance"] < 1e-12
