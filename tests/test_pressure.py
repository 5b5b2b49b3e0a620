"""A pressure on a boundary (``[[bodies.tractions]]`` with ``pressure``): the traction -p n
along the facets' outward normals. On a flat face it is the traction it stands for, to the
bit's round-off; on a curved bore it gives Lame's thick cylinder to the mesh's accuracy; a
traction given both ways, or neither, is named."""

from __future__ import annotations

import math

import numpy as np
import pytest

import vfem
from vfem.bodies import Body, Support, Traction
from vfem.errors import InputError
from vfem.mesh.shapes import annulus, rectangle
from vfem.mesh.solids import box

E, NU = 1000.0, 0.3


def block(tractions, dim=2):
    mesh = rectangle(nx=4, ny=3) if dim == 2 else box(h=0.5)
    return Body("block", mesh, vfem.LinearElastic(E, NU),
                supports=(Support("bottom"),), tractions=tractions)


@pytest.mark.parametrize("dim", [2, 3])
def test_a_pressure_on_a_flat_face_is_the_traction_it_stands_for(dim):
    """The top's outward normal is +y (+z in 3D): pressure p is the traction (0, -p)."""
    from vfem.bodies.loads import traction_vector

    pressed = block((Traction("top", pressure=2.5),), dim)
    down = (0.0,) * (dim - 1) + (-2.5,)
    pulled = block((Traction("top", down),), dim)
    pressed.validate()
    a = traction_vector(pressed, pressed.tractions[0])
    b = traction_vector(pulled, pulled.tractions[0])
    assert np.abs(a - b).max() <= 1e-14 * np.abs(b).max()
    assert a.sum() == pytest.approx(-2.5 * (1.0 if dim == 3 else 1.0), rel=1e-12)


def test_a_bore_under_pressure_is_lames_thick_cylinder():
    """A quarter of a plane-strain cylinder, a = 1, b = 2, pressure p in the bore, symmetry
    planes: the radial displacement of the bore and of the outer surface against Lame's
    u(r) = p a^2 / (E (b^2 - a^2)) ((1 + nu)(1 - 2 nu) r + (1 + nu) b^2 / r), to the mesh's
    accuracy: bilinear quadrilaterals, 32 x 16, measured -0.083 % at the bore and -0.065 %
    outside, -0.021 % and -0.016 % at 64 x 32 (as h^2); allowed 0.3 %."""
    a, b, p = 1.0, 2.0, 10.0
    mesh = annulus(a, b, around=32, radial=16)
    body = Body("cylinder", mesh, vfem.LinearElastic(E, NU),
                supports=(Support("left", ("x",)), Support("bottom", ("y",))),
                tractions=(Traction("inner", pressure=p),))
    model = vfem.Model("lame", [body])
    result = vfem.solve(model)
    u = result.steps[-1].bodies["cylinder"].displacement
    x = body.points.T
    r = np.hypot(x[:, 0], x[:, 1])
    radial = (u[:, 0] * x[:, 0] + u[:, 1] * x[:, 1]) / r

    def lame(rr):
        return p * a * a / (E * (b * b - a * a)) * ((1 + NU) * (1 - 2 * NU) * rr
                                                  + (1 + NU) * b * b / rr)

    for at in (a, b):
        on = np.abs(r - at) < 1e-9
        assert radial[on] == pytest.approx(lame(at), rel=3e-3)
    assert math.isclose(float(np.ptp(radial[np.abs(r - a) < 1e-9])), 0.0,
                        abs_tol=1e-3 * lame(a))  # the same all round


@pytest.mark.parametrize(("traction", "words"), [
    (Traction("top", (0.0, -1.0), pressure=1.0), "give value .* or pressure, not both"),
    (Traction("top"), "value must have 2 components.*or give pressure"),
    (Traction("top", pressure=math.inf), "pressure must be a finite number"),
])
def test_a_traction_given_both_ways_or_neither_is_named(traction, words):
    with pytest.raises(InputError, match=words):
        block((traction,)).validate()
