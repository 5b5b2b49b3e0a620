"""Redistribution (N* q = Q, thesis §4.4) and virtual elements (§4.5.1) on a uniform traction."""

import numpy as np
import pytest
from skfem import MeshQuad, MeshTri

from vfem.bodies import Body, Support
from vfem.contact.formulations.algorithm import VirtualElementContact
from vfem.contact.geometry.surface import ContactSurface
from vfem.contact.geometry.transfer import traction_from_forces
from vfem.contact.settings import ContactSettings
from vfem.materials import LinearElastic


def block(cls, y0, y1, nx, name):
    m = cls.init_tensor(np.linspace(0, 1, nx + 1), np.linspace(y0, y1, 3))
    t = 1e-9
    m = m.with_boundaries({"top": lambda x: x[1] > y1 - t, "bottom": lambda x: x[1] < y0 + t})
    support = "bottom" if y0 < 0 else "top"
    # stiff enough that the test forces leave the surfaces unstretched (to ~1e-9)
    return Body(name, m, LinearElastic(1e9, 0.3), supports=(Support(support),))


@pytest.mark.parametrize(("n_lower", "n_upper"), [(2, 10), (10, 2), (3, 7)])
def test_uniform_traction_crosses_non_matching_meshes_exactly(n_lower, n_upper):
    lower = block(MeshQuad, -0.5, 0.0, n_lower, "lower")
    upper = block(MeshTri, 0.0, 0.5, n_upper, "upper")
    surfaces = []
    for b, name in ((lower, "top"), (upper, "bottom")):
        b.setup()
        s = ContactSurface.build(b, b.mesh.boundaries[name])
        s.compute_flexibility()
        surfaces.append(s)
    contact = VirtualElementContact(surfaces, {frozenset((0, 1))}, ContactSettings())
    state = contact.new_state()
    # the upper body carries a uniform pressure 1 from the lower one: consistent nodal loads
    su = surfaces[1]
    F = np.zeros((su.nc, 2))
    F[:, 1] = su.tributary
    state.forces[1] = F
    x = contact.positions(state)
    tractions = [traction_from_forces(s, f) for s, f in zip(surfaces, state.forces)]
    np.testing.assert_allclose(tractions[1][:, 1], 1.0, rtol=1e-12)  # N* q = Q recovers it
    virtual = contact._virtual_forces(0, x, tractions)  # on the lower body's virtual elements
    sl = surfaces[0]
    np.testing.assert_allclose(virtual[:, 1], sl.tributary, rtol=1e-8)
    assert virtual[:, 1].sum() == pytest.approx(F[:, 1].sum(), rel=1e-8)  # force conserved
