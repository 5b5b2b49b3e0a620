"""An interference fit in 2D (issue 21, item 5): a shaft (a disk of radius b + delta) in a hub
(an annulus, bore b, outer radius c), of one material, overlapping by delta at the start; the
contact resolves the overlap in one step, with no load. Plane strain, quarter model. Lame (the
derivation: docs/examples.md, press fit): p = E delta (c^2 - b^2) / (2 b c^2 (1 - nu^2)).

Measured (2026-11-28): with the shaft's rim nodes at the hub bore's angles (24 facets per
quarter turn, 8 elements through the hub's wall), in one iteration with every invariant, the
hub's nodal pressure within 1.58 % of Lame's at every node (0.39 % off the symmetry planes;
mean +0.14 %), the shaft's within 1.37 % (mean -0.86 %) — the 3D press_fit's numbers, its
sections being in plane strain, until 3D stopped reading edges on symmetry planes as patch
boundaries (3D now 0.27 % and 0.82 %; 2D's symmetry-plane nodes still read low: its patch
ends are vertices, unchanged); 16 elements through the wall: 1.35 % and 1.46 %. The bodies
listed the other way round give the same pressures. With the shaft's facets at other angles
(32 per quarter turn against 24) the faceting sag, comparable with delta, scatters the nodal
pressure by up to 57 % about a mean within 0.4 %. Finer facets (48 per quarter turn) make the
shaft's outer elements thinner than delta, and the start is refused.
"""

import numpy as np

from vfem.bodies import Body, Support
from vfem.contact.settings import ContactSettings
from vfem.materials import LinearElastic
from vfem.mesh.shapes import annulus, disk
from vfem.solver import Analysis, Model

E, NU, B, C, DELTA = 200e3, 0.3, 1.0, 2.0, 0.01
LAME = E * DELTA * (C * C - B * B) / (2 * B * C * C * (1 - NU * NU))
ROLLERS = (Support("left", ("x",)), Support("bottom", ("y",)))


def fit(shaft_across: int = 12, around: int = 24, swap: bool = False):
    hub = Body("hub", annulus(B, C, around=around, radial=8), LinearElastic(E, NU),
               supports=ROLLERS, contact_boundaries=("inner",))
    shaft = Body("shaft", disk(B + DELTA, (B + DELTA) / shaft_across * (1 + 1e-9)),
                 LinearElastic(E, NU), supports=ROLLERS, contact_boundaries=("rim",))
    model = Model("fit2d", [hub, shaft] if swap else [shaft, hub])
    model.contact = ContactSettings()
    result = Analysis(model).run()
    assert result.converged, result.message
    out = {}
    for body, boundary in ((hub, "inner"), (shaft, "rim")):
        nodes = np.unique(body.mesh.facets[:, body.mesh.boundaries[boundary]])
        out[body.name] = result.steps[-1].bodies[body.name].contact_pressure[nodes] / LAME - 1
    return result, out


def test_pressure_within_2_percent_of_lame():
    result, err = fit()
    assert [s.iterations for s in result.steps] == [1]
    assert all(s.invariants["passed"] for s in result.steps)
    assert np.abs(err["hub"]).max() < 0.02 and np.abs(err["shaft"]).max() < 0.02
    assert abs(err["hub"].mean()) < 0.005 and abs(err["shaft"].mean()) < 0.01


def test_body_order():
    _, a = fit()
    _, b = fit(swap=True)
    for name in ("hub", "shaft"):
        assert np.abs(a[name] - b[name]).max() < 1e-8


def test_facets_at_other_angles_scatter_the_pressure():
    """Measured: 16 divisions across the shaft (32 facets per quarter turn) against the hub's
    24: the hub's nodal pressure scatters by up to 57 % about a mean within 0.4 % of Lame's."""
    result, err = fit(shaft_across=16)
    assert all(s.invariants["passed"] for s in result.steps)
    assert abs(err["hub"].mean()) < 0.01
    assert np.abs(err["hub"]).max() > 0.05  # the scatter is real: matching angles matter
