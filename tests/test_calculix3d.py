"""vfem_tools.calculix in 3D: the sphere example as a CalculiX deck of C3D8/C3D4 elements (always
checked), and run in ccx when it is installed (the total contact force against the applied one)."""

import numpy as np
import pytest
from skfem import MeshHex, MeshTet

from test_calculix import blocks as cards  # the deck's cards, as the 2D tests read them
from test_calculix import needs_ccx
from vfem_examples import sphere
from vfem_tools.calculix import (
    C3D4_FACES,
    C3D8_FACES,
    _positive_solids,
    corner_jacobians,
    run,
    write_deck,
)

#: the sphere example at its smallest: 2 facets across a, the bulk's elements 4 times larger
TINY = {"facets_per_radius": 2, "max_element_size": 4.0, "steps": 1}




@pytest.fixture(scope="module", params=["hex", "tet"])
def tiny(request, tmp_path_factory):
    p = sphere.SphereParameters(**TINY, sphere_cells=request.param)
    model = sphere.build(p)
    deck = write_deck(model, tmp_path_factory.mktemp("ccx3d") / "sphere.inp")
    return p, model, deck


def test_solid_node_order_gives_positive_volumes():
    for mesh in (MeshHex().refined(1), MeshTet().refined(1)):
        t, flipped = _positive_solids(mesh)
        assert flipped == 0 or isinstance(mesh, MeshTet)
        assert np.all(corner_jacobians(mesh.p, t) > 0)
        mirrored = type(mesh)(mesh.p * np.array([[-1.0], [1.0], [1.0]]), mesh.t)
        t, flipped = _positive_solids(mirrored)
        assert np.all(corner_jacobians(mirrored.p, t) > 0)
        assert flipped > 0
        # the same elements, as node sets
        assert (sorted(map(sorted, t.T.tolist()))
                == sorted(map(sorted, mirrored.t.T.tolist())))
    # ccx's faces (its manual, nodes from 1): C3D8 S1 1-2-3-4, S2 5-8-7-6, S3 1-5-6-2,
    # S4 2-6-7-3, S5 3-7-8-4, S6 4-8-5-1; C3D4 S1 1-2-3, S2 1-4-2, S3 2-4-3, S4 3-4-1
    assert [set(f) for f in C3D8_FACES] == [{k - 1 for k in f} for f in (
        (1, 2, 3, 4), (5, 8, 7, 6), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 8, 4), (4, 8, 5, 1))]
    assert [set(f) for f in C3D4_FACES] == [{k - 1 for k in f} for f in (
        (1, 2, 3), (1, 4, 2), (2, 4, 3), (3, 4, 1))]
    # on the unit cube, each C3D8 face is a face of the cube: one coordinate constant
    x = MeshHex().p[:, _positive_solids(MeshHex())[0][:, 0]]
    for face in C3D8_FACES:
        assert np.any(np.ptp(x[:, list(face)], axis=1) == 0)


def test_deck_has_the_3d_model(tiny):
    p, model, deck = tiny
    blocks = cards(deck.path.read_text())
    keys = [k for k, _ in blocks]
    nodes, elements = {}, {}
    for key, data in blocks:
        if key.startswith("*NODE,"):
            nodes[key.split("NSET=")[1]] = np.array([[float(v) for v in d.split(",")]
                                                     for d in data])
        elif key.startswith("*ELEMENT"):
            kind = key.split("TYPE=")[1].split(",")[0]
            elements[key.split("ELSET=")[1]] = (kind, np.array(
                [[int(v) for v in d.split(",")] for d in data]))
    for body in model.bodies:
        tag = body.name.upper()
        bd = deck.body(body.name)
        assert np.allclose(nodes[f"N_{tag}"][:, 1:].T, body.mesh.p, rtol=1e-13, atol=1e-15)
        kind, conn = elements[f"E_{tag}"]
        assert kind == ("C3D8" if isinstance(body.mesh, MeshHex) else "C3D4")
        assert kind == bd.element_type
        assert conn.shape == (body.mesh.t.shape[1], body.mesh.t.shape[0] + 1)
        local = conn[:, 1:].T - bd.node_offset - 1
        assert sorted(map(sorted, local.T.tolist())) == sorted(map(sorted, body.mesh.t.T.tolist()))
        assert np.all(corner_jacobians(body.mesh.p, local) > 0)
        # the contact surface: element faces whose nodes are the contact facets' nodes
        faces = dict(blocks)[f"*SURFACE, NAME=S_{tag}, TYPE=ELEMENT"]
        assert len(faces) == len(bd.contact_facets) > 0
        table = C3D8_FACES if kind == "C3D8" else C3D4_FACES
        got = set()
        for line in faces:
            e, label = (v.strip() for v in line.split(","))
            got.add(frozenset(local[list(table[int(label[1:]) - 1]),
                                    int(e) - bd.element_offset - 1].tolist()))
        assert got == {frozenset(f) for f in body.mesh.facets[:, bd.contact_facets].T.tolist()}
        assert f"*SOLID SECTION, ELSET=E_{tag}, MATERIAL=M_{tag}" in keys
    pair = keys.index("*CONTACT PAIR, INTERACTION=CONTACT, TYPE=SURFACE TO SURFACE")
    assert blocks[pair][1] == ["S_SPHERE, S_FLAT"]  # the finer sphere is the slave
    assert "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR" in keys
    assert not any("NLGEOM" in k for k in keys)
    # the platen: the top face's z dofs tied to one node, which carries a quarter of the force
    sph = model.bodies[0]
    top = np.unique(sph.mesh.facets[:, sph.mesh.boundaries["top"]])
    assert len(blocks[keys.index("*EQUATION")][1]) == 2 * (len(top) - 1)
    assert blocks[keys.index("*CLOAD")][1] == [f"{deck.reference_node}, 3, -3750.0"]
    supports = blocks[keys.index("*BOUNDARY")][1]
    assert "B_SPHERE_LEFT, 1, 1" in supports and "B_SPHERE_FRONT, 2, 2" in supports
    assert {"B_FLAT_BOTTOM, 1, 1", "B_FLAT_BOTTOM, 2, 2", "B_FLAT_BOTTOM, 3, 3"} <= set(supports)


@needs_ccx
def test_ccx_carries_the_applied_force(tmp_path):
    """Tetrahedra (C3D4) on hexahedra (C3D8): ccx's total contact force is the platen's, and
    K u of its displacements vanishes off the contact surface (its elements are vfem's)."""
    p = sphere.SphereParameters(**TINY, sphere_cells="tet")
    model = sphere.build(p)
    deck = write_deck(model, tmp_path / "sphere.inp")
    r = run(deck, p0=sphere.theory(p)["p0_theory"])
    quarter = p.force / 4
    # measured (ccx 2.20, penalty 1e11): 3750.0 and 3749.996; p_max (nodal) -5.7 % on this
    # coarse mesh (2 facets across a)
    assert r["total_contact_force"][2] == pytest.approx(quarter, rel=1e-4)
    assert r["total_contact_force_nodal"][2] == pytest.approx(quarter, rel=1e-3)
    assert r["nodal_residual"] < 1e-3
    assert abs(r["p_max_error_nodal"]) < 0.15
    assert r["dofs"] == sum(b.mesh.p.size for b in model.bodies)
    assert r["increments"] >= 1 and r["iterations"] > 0
