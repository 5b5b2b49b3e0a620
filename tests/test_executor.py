"""Who runs each body's work (issue 38, ``vfem.executor``): the contact formulations are handed
an executor (the solver hands them the run's MPI ranks) and, built without one, run serially
with the same answers."""

import numpy as np

from models import strip_surfaces
from vfem import parallel
from vfem.contact.formulations.paired import PairedContact
from vfem.contact.geometry import ContactPairs
from vfem.contact.settings import ContactSettings
from vfem.executor import SERIAL


def surfaces():
    return strip_surfaces(4, 7, E=1e3, names=("top", "bottom"))


def test_a_formulation_built_without_an_executor_runs_serially_and_alike():
    pairs = ContactPairs.every(2)
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
