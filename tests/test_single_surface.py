"""A surface that finds its own two sides (single-surface self-contact, issue 42): a body's
``self_contact = true``, or a ``contact_pairs`` entry naming one side twice, split at rest
into two sides (:func:`vfem.contact.geometry.own_sides.split`). Checked against the same
models with the two sides named by hand (the U of ``test_self_contact``, an E closing on both
slots), on a straight boundary (nothing faces anything), and on round bores, whose two sides
cannot be told apart at rest (refused)."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from skfem import MeshQuad

from test_self_contact import (
    AXIS,
    BACK,
    GAP,
    NU,
    SIZE,
    STEPS,
    E,
    L,
    P,
    T,
    closing_u,
    kept_elements,
    material,
    u_mesh,
    u_mesh_3d,
)
from vfem.bodies import Body, Support, Traction
from vfem.cli import main
from vfem.contact.geometry.own_sides import two_colours
from vfem.errors import InputError
from vfem.io.input import loads
from vfem.materials import LinearElastic
from vfem.mesh.shapes import block
from vfem.mesh.topology import named_boundaries
from vfem.solver import Analysis, Model

#: the forms of a U that finds its own sides: self_contact on the body, or one side named twice
FORMS = {"self_contact": None, "whole twice": (("u", "u"),),
         "boundaries twice": (("u:slot_top,slot_bottom", "u:slot_top,slot_bottom"),)}


def single(model: Model, pairs) -> Model:
    """``model`` (its one body's sides named) with the body finding its own sides instead:
    ``pairs`` None, the body's ``self_contact``; else those ``contact_pairs``."""
    model.contact_pairs = pairs
    model.bodies[0].self_contact = pairs is None
    return model


def same_run(a, b, name: str) -> int:
    """Assert two runs of one mesh agree at every node and step to 1e-10 of the largest
    contact force and displacement (one pairing: round-off); the steps compared."""
    assert a.converged, a.message
    assert b.converged, b.message
    assert [s.load_factor for s in a.steps] == [s.load_factor for s in b.steps]
    for s, t in zip(a.steps, b.steps):
        f, g = s.bodies[name].contact_force, t.bodies[name].contact_force
        assert np.abs(f - g).max() <= 1e-10 * max(np.abs(f).max(), 1e-300)
        d, e = s.bodies[name].displacement, t.bodies[name].displacement
        assert np.abs(d - e).max() <= 1e-10 * np.abs(d).max()
    assert all(s.invariants["passed"] for s in b.steps)
    assert np.abs(b.steps[-1].bodies[name].contact_force).max() > 0
    return len(a.steps)


def found_sides(model: Model):
    """The one pair of ``model``'s sides, as (side 1, side 2) mesh facet sets."""
    (pair,) = model.pairs()
    body = model.bodies[pair.a.body]
    assert (pair.a.part, pair.b.part) == (1, 2)
    return (set(pair.a.mesh_facets(body).tolist()), set(pair.b.mesh_facets(body).tolist()))


def faces(mesh, *names) -> set:
    return set(np.concatenate([mesh.boundaries[n] for n in names]).tolist())


@pytest.mark.parametrize("form", list(FORMS))
def test_a_u_that_finds_its_own_sides_is_the_u_with_them_named(form):
    """Plane strain, small kinematics: the U whose slot faces are found (self_contact, or its
    contact surface named twice) splits into exactly the slot's two faces (side 1 the lower,
    whose facets are numbered first) and gives the named-sides model's contact forces and
    displacements at every node and step to 1e-10 of the largest (one pairing: round-off;
    measured 0)."""
    model = single(closing_u(), FORMS[form])
    mesh = model.bodies[0].mesh
    assert found_sides(model) == (faces(mesh, "slot_bottom"), faces(mesh, "slot_top"))
    assert model.pairs().pairs[0].a.text(model.bodies) == (
        "u (side 1 of 2)" if form != "boundaries twice"
        else "u:slot_top,slot_bottom (side 1 of 2)")
    same_run(Analysis(closing_u()).run(), Analysis(model).run(), "u")


@pytest.mark.parametrize("change", [{"order": 2}, {"kinematics": "total"}],
                         ids=["quadratic", "finite strain"])
def test_a_quadratic_or_finite_strain_u_that_finds_its_own_sides(change):
    """The same with quadratic elements (3-node facets: the ray from each facet's midpoint
    along its normal there), and at finite strain (total Lagrangian: the found sides'
    zones re-paired at every iteration as named ones are): the slot's two faces, and the
    named-sides run to 1e-10 (measured 0)."""
    def u() -> Model:
        model = closing_u()
        for key, value in change.items():
            setattr(model.bodies[0], key, value)
        return model

    model = single(u(), None)
    mesh = model.bodies[0].mesh
    assert found_sides(model) == (faces(mesh, "slot_bottom"), faces(mesh, "slot_top"))
    same_run(Analysis(u()).run(), Analysis(model).run(), "u")


def test_the_whole_free_surface_of_the_u_finds_the_slot():
    """Without contact_boundaries (every free facet: the outside, the arms' ends, the slot's
    closed end) the sides found are the slot's two faces alone: nothing else faces another
    part of the surface."""
    u = Body("u", u_mesh(), material({}), supports=[Support("back")], self_contact=True)
    model = Model("u", [u])
    assert found_sides(model) == (faces(u.mesh, "slot_bottom"), faces(u.mesh, "slot_top"))


def test_a_u_of_revolution_that_finds_its_own_sides():
    """Axisymmetric (a groove round a disk's rim closing): the same, forces per full
    circle, to 1e-10."""
    model = single(closing_u(section=AXIS), None)
    mesh = model.bodies[0].mesh
    assert found_sides(model) == (faces(mesh, "slot_bottom"), faces(mesh, "slot_top"))
    same_run(Analysis(closing_u(section=AXIS)).run(), Analysis(model).run(), "u")


def test_a_3d_u_that_finds_its_own_sides():
    """3D (hexahedra, held in plane strain by its front and rear faces): the sides found are
    the slot's two faces and the run is the named one's to 1e-10."""
    def u3(self_contact: bool) -> Model:
        walls = [Support("front", ("y",)), Support("rear", ("y",))]
        u = Body("u", u_mesh_3d(), LinearElastic(E, NU), supports=[Support("back"), *walls],
                 tractions=[Traction("upper_end", (0.0, 0.0, -P)),
                            Traction("lower_end", (0.0, 0.0, P))],
                 contact_boundaries=["slot_top", "slot_bottom"], self_contact=self_contact)
        return Model("u3", [u], load_factors=STEPS, contact_pairs=None if self_contact else
                     (("u:slot_top", "u:slot_bottom"),))

    model = u3(True)
    mesh = model.bodies[0].mesh
    assert found_sides(model) == (faces(mesh, "slot_bottom"), faces(mesh, "slot_top"))
    same_run(Analysis(u3(False)).run(), Analysis(model).run(), "u")


# -- an E: two slots -------------------------------------------------------------------------

#: the E's arms (from the bottom) and slots: T, GAP, T, GAP, T
E_HEIGHT = 3 * T + 2 * GAP


def e_mesh() -> MeshQuad:
    """The E on its back (three arms T thick, two slots GAP wide cut from x = BACK to L) in
    quadrilaterals of SIZE. Boundaries: ``back``, the outer arms' ends ``lower_end`` and
    ``upper_end``, the slots' faces ``slot1_bottom``, ``slot1_top`` (the lower slot) and
    ``slot2_bottom``, ``slot2_top``."""
    levels = np.cumsum([0.0, T, GAP, T, GAP, T])
    up = np.unique(np.concatenate([np.linspace(a, b, 10 if b - a > GAP else 3)
                                   for a, b in zip(levels[:-1], levels[1:])]))
    mesh = MeshQuad.init_tensor(np.linspace(0.0, L, int(round(L / SIZE)) + 1), up)
    x, y = mesh.p[:, mesh.t].mean(axis=1)
    slots = [(levels[1], levels[2]), (levels[3], levels[4])]
    keep = ~((x > BACK) & np.any([(y > a) & (y < b) for a, b in slots], axis=0))
    mesh = kept_elements(mesh, keep)
    tol = 1e-9

    def at(level):
        return lambda p: (np.abs(p[1] - level) < tol) & (p[0] > BACK)

    return named_boundaries(mesh, {
        "back": lambda p: p[0] < tol,
        "lower_end": lambda p: (p[0] > L - tol) & (p[1] < T + tol),
        "upper_end": lambda p: (p[0] > L - tol) & (p[1] > E_HEIGHT - T - tol),
        "slot1_bottom": at(levels[1]), "slot1_top": at(levels[2]),
        "slot2_bottom": at(levels[3]), "slot2_top": at(levels[4])})


SLOTS = ("slot1_bottom", "slot1_top", "slot2_bottom", "slot2_top")


def closing_e(named: bool) -> Model:
    """The E's outer arms pressed towards the middle one by equal and opposite tractions on
    their ends: both slots close. ``named``: the sides named by hand (the slots' lower faces
    against their upper ones), else found (``self_contact``)."""
    e = Body("e", e_mesh(), LinearElastic(E, NU), supports=[Support("back")],
             tractions=[Traction("upper_end", (0.0, -P)), Traction("lower_end", (0.0, P))],
             contact_boundaries=list(SLOTS), self_contact=not named)
    return Model("e", [e], load_factors=STEPS, contact_pairs=(
        ("e:slot1_bottom,slot2_bottom", "e:slot1_top,slot2_top"),) if named else None)


def test_an_e_finds_four_runs_in_two_sides_and_closes_both_slots(caplog):
    """self_contact on an E: the four slot faces are four runs, each slot's two faces seeing
    each other, coloured into the slots' lower faces (side 1, the run of each slot numbered
    first) and their upper ones (side 2). The run equals the model with those sides named by
    hand to 1e-10 at every node and step; both slots close, each carrying equal and opposite
    forces on its two faces (to 1e-12 of their magnitude, round-off), and the invariants pass
    at every step."""
    model = closing_e(named=False)
    mesh = model.bodies[0].mesh
    assert found_sides(model) == (faces(mesh, "slot1_bottom", "slot2_bottom"),
                                  faces(mesh, "slot1_top", "slot2_top"))
    found = Analysis(model).run()
    same_run(Analysis(closing_e(named=True)).run(), found, "e")
    f = found.steps[-1].bodies["e"].contact_force
    for slot in ("slot1", "slot2"):
        lower, upper = (np.unique(mesh.facets[:, mesh.boundaries[f"{slot}_{k}"]])
                        for k in ("bottom", "top"))
        below, above = f[lower].sum(axis=0), f[upper].sum(axis=0)
        assert below[1] < 0 < above[1]  # (the upper face pushes the lower one down)
        assert np.abs(below + above).max() <= 1e-12 * (np.abs(f[lower]).sum()
                                                      + np.abs(f[upper]).sum())


# -- nothing found ---------------------------------------------------------------------------

@pytest.mark.parametrize("order", [1, 2])
def test_a_straight_boundary_finds_nothing(order, caplog):
    """The cantilever of ``test_self_contact`` with self_contact on its whole free surface
    (top, bottom, free end): no facet's ray meets a facet facing it, so no pair is made (a
    warning says so), and bent up (its top concave) it carries no contact force."""
    beam = Body("beam", block(0.0, 0.0, 4.0, 0.4, 0.1), LinearElastic(E, NU),
                supports=[Support("left")], tractions=[Traction("right", (0.0, 0.2))],
                order=order, self_contact=True)
    model = Model("bend", [beam], load_factors=(0.5, 1.0))
    with caplog.at_level(logging.WARNING, logger="vfem.contact.geometry.own_sides"):
        assert len(model.pairs()) == 0
    assert "no facet of the surface of body 'beam' faces another part of it" in caplog.text
    result = Analysis(model).run()
    assert result.converged, result.message
    last = result.steps[-1].bodies["beam"]
    assert np.abs(last.displacement[:, 1]).max() > 0.25
    assert not np.any(last.contact_force)


# -- refused ---------------------------------------------------------------------------------

def test_runs_seeing_each_other_in_an_odd_cycle_have_no_two_sides():
    """The colouring: runs seeing each other in a chain take alternate sides, the run with the
    lowest facet number of each connected part side 1 (whatever the order of the links);
    three runs each seeing the next have no two sides, and the clash is said."""
    colour, clash = two_colours(4, np.array([0, 2]), np.array([1, 3]), np.array([7, 3, 5, 1]))
    assert clash is None and colour.tolist() == [1, 0, 1, 0]
    again, _ = two_colours(4, np.array([3, 1]), np.array([2, 0]), np.array([7, 3, 5, 1]))
    assert again.tolist() == colour.tolist()
    _, clash = two_colours(3, np.array([0, 1, 2]), np.array([1, 2, 0]), np.array([0, 1, 2]))
    assert clash is not None and len(set(clash)) == 2


def ring_mesh(inner: float = 0.7, outer: float = 1.0, around: int = 64,
              radial: int = 4) -> MeshQuad:
    """The ring crush's annulus whole (a = 0.7, b = 1): quadrilaterals on a polar grid, the
    seam's nodes merged. Boundaries: ``bore`` and ``outer``, ``foot`` (the outer facets
    below y = -0.9)."""
    grid = MeshQuad.init_tensor(np.linspace(inner, outer, radial + 1),
                                np.linspace(0.0, 2 * np.pi, around + 1))
    r, th = grid.p
    p = np.vstack([r * np.cos(th), r * np.sin(th)])
    key = np.rint(p.T / 1e-9).astype(np.int64)
    _, first, index = np.unique(key, axis=0, return_index=True, return_inverse=True)
    index = index.ravel()
    order = np.argsort(first)
    renumber = np.empty_like(order)
    renumber[order] = np.arange(len(order))
    mesh = MeshQuad(np.ascontiguousarray(p[:, np.sort(first)]),
                    np.ascontiguousarray(renumber[index[grid.t]]))
    mid = 0.5 * (inner + outer)  # (the tests read the boundary facets' midpoints)
    return named_boundaries(mesh, {
        "bore": lambda q: np.hypot(*q) < mid,
        "outer": lambda q: np.hypot(*q) > mid,
        "foot": lambda q: (np.hypot(*q) > mid) & (q[1] < -0.9)})


def ring(**keys) -> Model:
    body = Body("ring", ring_mesh(), LinearElastic(E, NU), supports=[Support("foot")],
                **keys)
    return Model("ring", [body])


@pytest.mark.parametrize("keys, pairs", [({"self_contact": True}, None),
                                         ({}, (("ring:bore", "ring:bore"),))],
                         ids=["self_contact", "bore twice"])
def test_a_round_bore_is_refused(keys, pairs):
    """The ring crush's bore whole: every facet faces its antipode across the bore, one
    closed run that sees itself; its two sides are not told apart at rest, and the model is
    refused, naming the body and the boundary and saying how to name the sides."""
    model = ring(**keys)
    model.contact_pairs = pairs
    with pytest.raises(InputError, match=(
            r"the surface of body 'ring' \(boundary 'bore'\) faces itself across one closed "
            r"stretch .* name them as the pair's two sides, e\.g\. "
            r"\['ring:upper', 'ring:lower'\]")):
        model.validate()


TUBE = """
name = "tube"
[[bodies]]
name = "tube"
self_contact = true
[bodies.mesh]
shape = "ring"
inner_radius = 0.7
outer_radius = 1.0
height = 0.2
quarter = false
around = 4
radial = 1
layers = 1
[bodies.material]
youngs_modulus = 1000.0
poissons_ratio = 0.3
[[bodies.supports]]
boundary = "bottom"
"""


def test_a_round_bore_in_3d_is_refused_through_the_cli(tmp_path, capsys):
    """A tube (the 3D ring, whole) with self_contact: its bore faces itself; vfem check
    stops with exit status 2 and the message, no traceback."""
    path = tmp_path / "tube.toml"
    path.write_text(TUBE)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "the surface of body 'tube' (boundary 'inner')" in err
    assert "faces itself across one closed stretch" in err
    assert "Traceback" not in err


def test_self_contact_must_be_a_boolean():
    """``self_contact = "yes"`` in an input file is refused by its type, as every key is; a
    Python body's by its check."""
    with pytest.raises(InputError, match=r"bodies\[0\] \(tube\)\.self_contact: expected true "
                                         r"or false, got the string 'yes'"):
        loads(TUBE.replace("self_contact = true", 'self_contact = "yes"'))
    model = closing_u()
    model.bodies[0].self_contact = "yes"
    with pytest.raises(InputError, match="self_contact must be true or false, got 'yes'"):
        model.validate()


def test_self_contact_and_an_own_pair_are_refused_together():
    """A body with self_contact that contact_pairs also pairs with itself: one or the other."""
    model = closing_u()
    model.bodies[0].self_contact = True
    with pytest.raises(InputError, match=r"\['u:slot_top', 'u:slot_bottom'\] pairs body 'u' "
                                         "with itself, and the body has self_contact = true "
                                         "too: give one"):
        model.validate()


def test_a_whole_side_and_a_boundary_of_one_body_are_refused():
    """Two different sides of one body that share facets (its whole contact surface and one
    of its boundaries) are refused, as two named boundaries sharing facets are."""
    model = closing_u()
    model.contact_pairs = (("u", "u:slot_top"),)
    with pytest.raises(InputError, match=r"share \d+ facets \('u' is its whole contact "
                                         "surface\\)"):
        model.validate()
