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


def test_a_total_is_the_sum_in_order_and_its_time_is_counted_once():
    """``total`` (a body's part of a shared matrix on its owner, issue 40): in serial the sum
    in order, as one rank's; the work inside is timed into ``Ranks.busy``, a share within a
    share once."""
    parts = {i: np.full((2, 3), 10.0**i) for i in range(4)}
    expected = parts[0] + parts[1] + parts[2] + parts[3]
    np.testing.assert_array_equal(SERIAL.total(range(4), parts.get, (2, 3)), expected)
    ranks = parallel.Ranks()

    def nested(i):
        return ranks.own(parts.get, i)

    np.testing.assert_array_equal(ranks.total(range(4), nested, (2, 3)), expected)
    assert ranks.busy >= 0.0 and ranks._depth == 0
    before = ranks.busy
    ranks.own(lambda: sum(range(200000)))
    assert ranks.busy > before


def test_the_pair_matrix_is_the_bodies_parts_summed():
    """W (eq. 4.2.4 in matrix form), now the sum over bodies of read_b C_b dF_b each on its
    owner (issue 40), against W formed unknown by unknown as before: each body's motion under
    the unit traction values, read at every pair node (fine side) and its virtual node
    (``interp`` of the coarse side's motion) along the unknown's direction. Round-off only."""
    from vfem.contact.solvers.pair_flexibility import force_rows

    pc = PairedContact(surfaces(), ContactPairs.every(2), ContactSettings())
    W, _, _, offsets = pc._full_flexibility()
    directions = [pc.directions(k) for k in range(len(pc.contact_pairs))]
    _, dF = force_rows(pc.surfaces, pc.contact_pairs, directions)
    m = int(offsets[-1])
    du = [np.asarray(s.C @ dF[b].toarray()).reshape(s.nc, s.dim, m)
          for b, s in enumerate(pc.surfaces)]
    reference = np.zeros((m, m))
    for k, pair in enumerate(pc.contact_pairs):
        n = len(pair.nodes)
        uf = pair.fine_read(du[pair.fine])
        uc = np.einsum("ij,jdm->idm", pair.interp.toarray(), du[pair.coarse])
        for j, direction in enumerate(directions[k]):
            rows = slice(offsets[k] + j * n, offsets[k] + (j + 1) * n)
            reference[rows] = np.einsum("id,idm->im", pair.reading(j, direction), uf - uc)
    assert m > 0 and np.abs(reference).max() > 0
    # a few products and sums of numbers of W's size: round-off of 1e-15 times a handful
    np.testing.assert_allclose(W, reference, rtol=0, atol=1e-13 * np.abs(reference).max())


def test_a_stiffness_not_assembled_on_this_rank_says_so():
    """A rank that does not own a body assembles all of it but its stiffness (issue 40); a
    read of it there is a clear error naming the body, and the reactions of a converged step
    are read from its results instead (``Body.reaction_of``, the same number)."""
    import pytest

    from vfem.solver import Analysis
    from vfem_examples import block

    model = block.build(block.Parameters())
    result = Analysis(model).run()
    last = result.steps[-1]
    b = model.bodies[0]
    r = last.bodies[b.name]
    f = np.zeros(b.ndofs)
    s = result.surfaces[0]
    f[s.candidate_dofs] = r.contact_force[s.nodes[: s.nc]].ravel()
    boundary = next(iter(r.reactions))
    assert b.reaction_of(r, boundary, "y") == b.reaction(r.displacement.ravel(), boundary, "y",
                                                         last.load_factor, f)
    ndofs = b.ndofs
    b.assemble(stiffness=False)
    assert b.ndofs == ndofs
    with pytest.raises(RuntimeError, match=f"body {b.name!r}: its stiffness is assembled on "
                       "the MPI rank that owns it only"):
        b.K @ np.zeros(ndofs)
    with pytest.raises(RuntimeError, match="owns it only"):
        _ = b.K.shape
