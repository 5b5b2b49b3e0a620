"""The 3D contact patch test (issue 21, C10): a uniform pressure across non-matching 3D meshes.

Two stacked boxes (:func:`vfem.mesh.solids.box`), the lower one on rollers at its bottom
(z = -1), the upper one pressed down by a prescribed displacement of its top (z = 1), both on
rollers at x = 0 and y = 0 (supports of single components), so the exact state is uniaxial:
sigma_zz = -E * D / 2 in both bodies, the contact pressure its opposite, sigma_xx = sigma_yy = 0.
The interface meshes do not match (hexahedra against tetrahedra, hexahedra or tetrahedra of
other sizes). The paired variant must reach it to round-off in one contact iteration, with
every invariant passed, whichever body comes first; quadratic 3D bodies and friction in 3D are
refused with a message (``check_capabilities``).
"""

import numpy as np
import pytest

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


def stacked(lower, upper, order=1, swap=False, variant="paired", **settings) -> Model:
    mat = LinearElastic(E, NU)
    (cl, nl), (cu, nu) = lower, upper
    low = Body("lower", box(0.0, 0.0, -1.0, 1.0, 1.0, 1.0, nl, nl, 2, tetrahedra=cl == "tet"),
               mat, supports=(Support("bottom", ("z",)), *ROLLERS),
               contact_boundaries=("top",), order=order)
    up = Body("upper", box(0.0, 0.0, 0.0, 1.0, 1.0, 1.0, nu, nu, 2, tetrahedra=cu == "tet"),
              mat, supports=ROLLERS, prescribed=(PrescribedDisplacement("top", "z", -D),),
              contact_boundaries=("bottom",), order=order)
    bodies = [up, low] if swap else [low, up]
    return Model("patch3d", bodies, contact=ContactSettings(variant=variant, **settings))


@pytest.mark.parametrize("swap", [False, True], ids=["lower-first", "upper-first"])
@pytest.mark.parametrize("lower,upper", CASES, ids=lambda c: f"{c[0]}{c[1]}")
def test_uniform_pressure_and_stress_across_non_matching_3d_meshes(lower, upper, swap):
    model = stacked(lower, upper, swap=swap)
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
        touching = np.unique(body.mesh.facets[:, body.mesh.boundaries[side]])
        assert np.array_equal(np.flatnonzero(on), touching)  # the whole interface, no more
        assert np.abs(r.contact_pressure[on] / EXACT - 1).max() < 1e-8
        s = stress(body, r.displacement.ravel())
        assert np.abs(-s["szz"] / EXACT - 1).max() < 1e-8
        assert np.abs(s["sxx"]).max() < 1e-8 * EXACT and np.abs(s["syy"]).max() < 1e-8 * EXACT


def test_quadratic_3d_bodies_in_contact_are_refused():
    with pytest.raises(InputError, match=r"body 'lower': 3D contact supports linear elements "
                                         r"only \(order 1\); quadratic 3D contact is not "
                                         "implemented yet"):
        stacked(("hex", 3), ("hex", 5), order=2).validate()


def test_friction_in_3d_is_refused():
    with pytest.raises(InputError, match=r"body 'lower': friction in 3D contact is not "
                                         "implemented yet; set the friction to 0"):
        stacked(("hex", 3), ("hex", 5), friction=0.3).validate()


def test_the_thesis_variant_stays_2d():
    with pytest.raises(InputError, match="thesis contact supports 2D bodies, this one is 3D"):
        stacked(("hex", 3), ("hex", 5), variant="thesis").validate()
