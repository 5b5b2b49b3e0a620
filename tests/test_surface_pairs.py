"""Contact pairs of surface sides (``contact_pairs = [["punch", "block:top"]]``;
:mod:`vfem.contact.geometry.sides`): a side that names boundaries of its body takes part with
those facets only, in the candidates, the facing patches, the pairing and the placement checks.

The references are models whose answer a side's zone must not change and the same model with
the zone made by other means: a side named by its boundary is the body with that boundary as
its contact surface (``contact_boundaries``), to round-off, in 2D and 3D, with small and large
kinematics and with friction; a stack whose middle plates name their top and bottom is the
stack whose pairs name bodies. And a zone that leaves out the facets that would touch leaves
the pair without them: the candidates lie on the named boundary alone.
"""

from __future__ import annotations

import numpy as np
import pytest

from models import (
    box_mesh,
    built,
    input_file,
    rectangle_mesh,
    support,
    toml_body,
)
from vfem.cli import main
from vfem.contact.geometry import ContactPairs, facing, overlap
from vfem.errors import InputError
from vfem.solver import Analysis

#: the displacements and contact forces of two runs of one model that differ in how a side's
#: facets were chosen: the same facets in the same order, so the same arithmetic; a tolerance
#: of round-off on the condensed flexibility's inverse (a few thousand contact dofs' dense
#: solve, condition ~1e6 at these stiffness ratios, times 1e-16)
ROUND_OFF = 1e-9


def punch_on_block(dim: int, pairs: str | None = None, block_boundaries=None, friction=None,
                   kinematics=None, contact: dict | None = None) -> str:
    """A stiff coarse punch pressed (and, with friction, pushed sideways) onto a softer, finer
    block held at its bottom."""
    if dim == 2:
        block = rectangle_mesh(-1.0, -1.0, 2.0, 1.0, 16, 8)
        punch = rectangle_mesh(-0.4, 0.0, 0.8, 0.4, 5, 3)
        down, across = "y", "x"
    else:
        block = box_mesh(-1.0, -1.0, -1.0, 2.0, 2.0, 1.0, 6, 6, 3)
        punch = box_mesh(-0.4, -0.4, 0.0, 0.8, 0.8, 0.4, 3, 3, 2)
        down, across = "z", "x"
    loads = [f'[[bodies.prescribed]]\nboundary = "top"\ncomponent = "{down}"\nvalue = -0.01']
    if friction is not None:
        loads.append(f'[[bodies.prescribed]]\nboundary = "top"\ncomponent = "{across}"\n'
                     "value = 0.002")
    others = [c for c in ("x", "y", "z")[:dim] if c != down and (friction is None or c != across)]
    if others:
        loads.insert(0, support("top", others))
    text = input_file(
        "named sides",
        toml_body("block", block, support("bottom"), contact_boundaries=block_boundaries,
                  kinematics=kinematics),
        toml_body("punch", punch, *loads, E=2e5, kinematics=kinematics),
        contact={**({} if friction is None else {"friction": friction}), **(contact or {})}
        or None,
        load_factors=[0.5, 1.0])
    if pairs is not None:
        text = text.replace('name = "named sides"',
                            f'name = "named sides"\ncontact_pairs = {pairs}', 1)
    return text


def solved(text: str):
    result = Analysis(built(text)).run()
    assert result.converged, result.message
    return result


def assert_same(a, b) -> None:
    for sa, sb in zip(a.steps, b.steps, strict=True):
        for name, ra in sa.bodies.items():
            rb = sb.bodies[name]
            for field in ("displacement", "contact_force"):
                x, y = getattr(ra, field), getattr(rb, field)
                assert np.abs(x - y).max() <= ROUND_OFF * np.abs(x).max(), (name, field)


@pytest.mark.parametrize("dim, friction, kinematics", [
    (2, None, None), (2, 0.3, None), pytest.param(2, None, "total", marks=pytest.mark.slow),
    (3, None, None)])
def test_a_side_named_by_its_boundary_is_the_body_with_that_boundary_as_its_contact_surface(
        dim, friction, kinematics):
    named = solved(punch_on_block(dim, '[["punch", "block:top"]]', friction=friction,
                                  kinematics=kinematics))
    bounded = solved(punch_on_block(dim, block_boundaries=["top"], friction=friction,
                                    kinematics=kinematics))
    everywhere = solved(punch_on_block(dim, friction=friction, kinematics=kinematics))
    assert_same(named, bounded)
    # the whole surface gives the same contact too (here the candidates are the same facets:
    # the block's top near the punch; a zone strictly smaller than its body's candidates is
    # the stack's, below)
    assert_same(named, everywhere)
    force = named.steps[-1].bodies["punch"].contact_force.sum(axis=0)
    assert abs(force[dim - 1]) > 0  # the punch pressed the block


def test_a_zone_that_leaves_out_the_touching_facets_is_read_as_the_pair_says():
    """The punch's side named by its left face, which meets the block's top at a right angle
    (the face's lower end lies on it): the punch's candidates are on its left face alone, and
    the start check reads the pair's sides, so the block's nodes under the punch, which lie on
    its bottom and behind its left face by most of its width, are refused as deep inside it
    (the same model with whole bodies starts touching, and is taken)."""
    from vfem.contact.geometry import select_candidate_facets

    model = built(punch_on_block(2, '[["punch:left", "block"]]'))
    candidates = select_candidate_facets(model.bodies, model.pairs(), 0.05)
    on_left = model.bodies[1].mesh.boundaries["left"]
    assert len(candidates[1]) and np.isin(candidates[1], on_left).all()
    with pytest.raises(InputError, match="bodies 'block' and 'punch' start deeply "
                                         "interpenetrated: node"):
        model.contact_surfaces()
    bottom = model.bodies[1].mesh.boundaries["bottom"]
    assert not np.isin(candidates[1], bottom).any()
    _, everywhere = built(punch_on_block(2)).contact_surfaces()
    assert np.isin(everywhere[1].facet_ids, bottom).any()  # the bottom's too, by default


def stack(pairs: str) -> str:
    """Three plates pressed together, the middle one touching the others on its top and
    bottom (each plate's whole exterior a candidate otherwise)."""
    plates = []
    for k, (y0, nx) in enumerate(((0.0, 12), (0.25, 9), (0.5, 7))):
        loads = ([support("bottom", ["y"]), support("left", ["x"])] if k == 0 else
                 [support("left", ["x"]), support("right", ["y"])])  # (as the stack example)
        if k == 2:
            loads = [support("left", ["x"]), '[[bodies.prescribed]]\nboundary = "top"\n'
                     'component = "y"\nvalue = -0.004']
        plates.append(toml_body(f"plate{k}", rectangle_mesh(0.0, y0, 1.0 - 0.1 * k, 0.25, nx, 3),
                                *loads, E=7e4))
    text = input_file("stack of three", *plates, load_factors=[1.0])
    return text.replace('name = "stack of three"',
                        f'name = "stack of three"\ncontact_pairs = {pairs}', 1)


def test_a_stack_whose_middle_plate_names_its_top_and_bottom_is_the_stack_of_bodies():
    sides = solved(stack('[["plate0:top", "plate1:bottom"], ["plate1:top", "plate2:bottom"]]'))
    bodies = solved(stack('[["plate0", "plate1"], ["plate1", "plate2"]]'))
    assert_same(sides, bodies)
    model = built(stack('[["plate0", "plate1:bottom"], ["plate1:top", "plate2"]]'))
    pairs, surfaces = model.contact_surfaces()
    middle, mesh = surfaces[1], model.bodies[1].mesh
    # each pair's zone on the middle plate is its named boundary's candidates
    below, above = pairs.sorted()
    low, high = below.b.facets, above.a.facets
    assert len(low) and len(high) and not np.intersect1d(low, high).size
    assert len(low) < len(middle.facets) and len(high) < len(middle.facets)
    assert np.isin(middle.facet_ids[low], mesh.boundaries["bottom"]).all()
    assert np.isin(middle.facet_ids[high], mesh.boundaries["top"]).all()
    assert below.a.facets is None and above.b.facets is None


@pytest.mark.parametrize("pairs, message", [
    ('[["punch", "block:tpo"]]', "body 'block' has no boundary 'tpo'; its mesh's boundaries: "),
    ('[["punch", "blok:top"]]', "names unknown body 'blok:top'"),
    ('[["punch", "block:top"], ["block:left", "punch"]]', "are already paired"),
    ('[["punch", "punch:bottom"]]', "share .* facets .'punch' is its whole contact surface."),
    ('[["punch:bottom", "punch:bottom,left"]]', "the two sides of body 'punch' share"),
    ('[["punch", "block:top,"]]', "names an empty boundary"),
    ('[["punch", "block:bottom"]]', "boundary 'bottom' of body 'block' cannot touch: a "
                                    "displacement is prescribed on it"),
])
def test_a_side_that_names_what_is_not_there_is_one_message(pairs, message):
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace("[", r"\[")):
        built(punch_on_block(2, pairs))


def test_a_side_must_name_a_contact_boundary_where_the_body_lists_them():
    with pytest.raises(InputError, match="boundary 'left' of body 'block' is not one of its "
                                         "contact_boundaries"):
        built(punch_on_block(2, '[["punch", "block:left"]]', block_boundaries=["top"]))


def test_a_formulation_that_reads_whole_surfaces_refuses_named_sides(tmp_path, capsys):
    path = tmp_path / "thesis.toml"
    path.write_text(punch_on_block(2, '[["punch", "block:top"]]', contact={"variant": "thesis"}))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "names boundaries of a body" in err and "contact.variant = 'thesis'" in err
    assert "Traceback" not in err


@pytest.mark.parametrize("entry", ['[["block:top", "punch"]]', '[["punch", "block:top"]]'])
def test_the_pairs_read_bodies_alike_whatever_order_the_input_names_them(entry):
    model = built(punch_on_block(2, entry))
    pairs = model.pairs()
    assert pairs.keys() == [(0, 1)] and pairs.opponents(0) == [1] and pairs.opponents(1) == [0]
    assert frozenset((0, 1)) in pairs and frozenset((0,)) not in pairs
    (pair,) = pairs.sorted()
    assert pair.a.body == 0 and pair.a.boundaries == ("top",) and pair.b.boundaries is None
    # the names as the input gives them (the friction record's order)
    assert pairs.names(model.bodies) == [tuple(n.split(":")[0] for n in eval_pair(entry))]
    assert ContactPairs.every(3).keys() == [(0, 1), (0, 2), (1, 2)]


def eval_pair(entry: str) -> list[str]:
    import json

    return json.loads(entry)[0]


def test_a_zone_splits_a_surface_the_pairing_reads_its_part_alone():
    """What self-contact's two sides of one boundary need (issue 42): of the block's top, the
    facets left of x = 0 as one side against the punch: the facing patch is the whole top's
    within the zone, and every node paired lies on it."""
    model = built(punch_on_block(2))
    _, (block, punch) = model.contact_surfaces()
    left = np.flatnonzero(block.X[block.facets].mean(axis=1)[:, 0] < 0.0)
    whole = facing(block, block.X, punch, punch.X)
    part = facing(block, block.X, punch, punch.X, left)
    assert len(part) and np.array_equal(part, np.intersect1d(whole, left))
    geo = overlap(block, punch, zones=(left, None))
    assert len(geo.nodes) and np.isin(geo.nodes, block.facets[left]).all()
    assert (block.X[geo.nodes, 0] <= 1e-12).all()
    assert np.array_equal(geo.fpatch, part)
    everywhere = overlap(block, punch)
    assert len(everywhere.nodes) > len(geo.nodes)  # the zone left the right half out


def two_parts(gap: float = 1e-3):
    """A block (quadrilaterals, y in [-1, 0]) and a narrower pad over it (y in [gap, 0.4 + gap]),
    their boundaries named (``base`` and ``base_top`` below, ``pad_bottom`` and ``pad_top``
    above): the two meshes, and the one mesh of both (the block's nodes first)."""
    from skfem import MeshQuad

    eps = 1e-9
    marks = {"base": lambda x: x[1] < -1 + eps, "base_top": lambda x: np.abs(x[1]) < eps,
             "pad_bottom": lambda x: np.abs(x[1] - gap) < eps,
             "pad_top": lambda x: x[1] > 0.4 + gap - eps}
    lower = MeshQuad.init_tensor(np.linspace(-1, 1, 17), np.linspace(-1, 0, 9))
    upper = MeshQuad.init_tensor(np.linspace(-0.4, 0.4, 6), np.linspace(gap, 0.4 + gap, 4))
    both = MeshQuad(np.hstack([lower.p, upper.p]),
                    np.hstack([lower.t, upper.t + lower.p.shape[1]]))
    return (lower.with_boundaries({k: marks[k] for k in ("base", "base_top")}),
            upper.with_boundaries({k: marks[k] for k in ("pad_bottom", "pad_top")}),
            both.with_boundaries(marks))


def test_two_sides_of_one_body_are_paired_as_two_bodies_are(monkeypatch):
    """What the pairs of sides carry for self-contact (issue 42; its split of one boundary and
    its invariants are not built): one body whose mesh is two parts, a block and a pad pressed
    onto it, its two sides paired (the block's top, the pad's bottom), gives the contact of the
    two parts as two bodies: one body's pair of its own sides goes through the candidates, the
    side choice, the pairing, the held nodes and the transfer, and its flexibility (both
    parts' in one factorization) carries both sides' forces. (A body of two pieces is refused
    by the mesh checks, which this test leaves out: each piece here is held.)"""
    from vfem.bodies import Body, PrescribedDisplacement, Support
    from vfem.contact.geometry import Side, SurfacePair
    from vfem.contact.invariants import InvariantCheck
    from vfem.materials import LinearElastic
    from vfem.mesh import checks
    from vfem.model import Model

    monkeypatch.setattr(checks, "_check_pieces", lambda p, t, where: None)
    n = two_parts()[0].p.shape[1]  # the block's nodes, then the pad's

    def parts_balance(self, F, out):
        """Invariant (a) of the two parts as the two bodies they are: a body's own sides'
        forces cancel in its total, which is (a)'s scale (self-contact's invariants, issue 42)."""
        if len(F) != 1:
            return balance(self, F, out)
        totals = np.array([F[0][:n].sum(axis=0), F[0][n:].sum(axis=0)])
        scale = float(np.linalg.norm(totals, axis=1).max())
        out.force_balance = float(np.linalg.norm(totals.sum(axis=0))) / scale if scale else 0.0

    balance = InvariantCheck._force_balance
    monkeypatch.setattr(InvariantCheck, "_force_balance", parts_balance)

    lower, upper, both = two_parts()
    press = (PrescribedDisplacement("pad_top", "y", -0.01),
             PrescribedDisplacement("pad_top", "x", 0.0))
    material = LinearElastic(1000.0, 0.3)
    one = Body("parts", both, material, supports=(Support("base"),), prescribed=press,
               contact_boundaries=("base_top", "pad_bottom"))
    own = ContactPairs((SurfacePair(Side(0, ("base_top",)), Side(0, ("pad_bottom",))),))
    monkeypatch.setattr(Model, "pairs", lambda self: own if self.name == "one" else
                        ContactPairs.every(len(self.bodies)))
    got = Analysis(Model("one", [one], load_factors=(0.5, 1.0))).run()
    assert got.converged, got.message
    two = Model("two", [Body("block", lower, material, supports=(Support("base"),),
                             contact_boundaries=("base_top",)),
                        Body("pad", upper, material, prescribed=press,
                             contact_boundaries=("pad_bottom",))], load_factors=(0.5, 1.0))
    two.validate()
    want = Analysis(two).run()
    assert want.converged, want.message
    for a, b in zip(got.steps, want.steps, strict=True):
        mine = a.bodies["parts"]
        for name, part in (("block", slice(0, n)), ("pad", slice(n, None))):
            theirs = b.bodies[name]
            for field in ("displacement", "contact_force", "contact_pressure", "contact_traction",
                          "penetration"):
                x, y = getattr(mine, field)[part], getattr(theirs, field)
                assert np.abs(x - y).max() <= ROUND_OFF * np.abs(y).max(), (name, field)
            assert np.array_equal(mine.contact_status[part], theirs.contact_status), name
    force = got.steps[-1].bodies["parts"].contact_force
    assert force[n:, 1].sum() > 0
    assert np.isclose(force[n:, 1].sum(), -force[:n, 1].sum(), rtol=1e-12)
