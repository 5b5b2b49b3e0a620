"""Redistribution (N* q = Q, thesis §4.4) and virtual elements (§4.5.1) on a uniform traction."""

import numpy as np
import pytest

from models import strip_surfaces
from vfem.contact.formulations.algorithm import VirtualElementContact
from vfem.contact.geometry import ContactPairs
from vfem.contact.geometry.transfer import traction_from_forces
from vfem.contact.settings import ContactSettings


@pytest.mark.parametrize(("n_lower", "n_upper"), [(2, 10), (10, 2), (3, 7)])
def test_uniform_traction_crosses_non_matching_meshes_exactly(n_lower, n_upper):
    # stiff (E = 1e9) enough that the test forces leave the surfaces unstretched (to ~1e-9)
    surfaces = strip_surfaces(n_lower, n_upper)
    contact = VirtualElementContact(surfaces, ContactPairs.every(2), ContactSettings())
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
