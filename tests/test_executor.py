"""Who runs each body's work (issue 38, ``vfem.executor``): the contact formulations are handed
an executor (the solver hands them the run's MPI ranks) and, built without one, run serially
with the same answers."""

import numpy as np
from skfem import MeshQuad, MeshTri

from vfem import parallel
from vfem.bodies import Body, Support
from vfem.contact.formulations.paired import PairedContact
from vfem.contact.geometry.surface import ContactSurface
from vfem.contact.settings import ContactSettings
from vfem.executor import SERIAL
from vfem.materials import LinearElastic


def surfaces():
    out = []
    for cls, y0, y1, n, face, held in ((MeshQuad, -0.5, 0.0, 4, "top", "bottom"),
                                       (MeshTri, 0.0, 0.5, 7, "bottom", "top")):
        m = cls.init_tensor(np.linspace(0, 1, n + 1), np.linspace(y0, y1, 3)).with_boundaries(
            {"top": lambda x, y1=y1: x[1] > y1 - 1e-9, "bottom": lambda x, y0=y0: x[1] < y0 + 1e-9})
        b = Body(face, m, LinearElastic(1e3, 0.3), supports=(Support(held),))
        b.setup()
        s = ContactSurface.build(b, m.boundaries[face])
        s.compute_flexibility()
        out.append(s)
    return out


def test_a_formulation_built_without_an_executor_runs_serially_and_alike():
    pairs = {frozenset((0, 1))}
    alone = PairedContact(surfaces(), pairs, ContactSettings())
    ranks = PairedContact(surfaces(), pairs, ContactSettings(), executor=parallel.Ranks())
    assert alone.executor is SERIAL and alone.executor.size == 1
    assert len(alone.contact_pairs) == len(ranks.contact_pairs) >= 1
    for a, b in zip(alone.contact_pairs, ranks.contact_pairs):
        assert (a.fine, a.coarse) == (b.fine, b.coarse)
        np.testing.assert_array_equal(a.nodes, b.nodes)
        np.testing.assert_array_equal(a.gap0, b.gap0)


def test_serial_maps_in_order_as_one_rank_does():
    calls = []

    def work(i):
        calls.append(i)
        return i * i

    assert SERIAL.map([2, 0, 1], work) == parallel.Ranks().map([2, 0, 1], lambda i: i * i)
    assert calls == [2, 0, 1]
