"""Which surfaces may touch: contact pairs of surface *sides*, not of whole bodies.

A pair joins two sides. A side is a body and, optionally, the named boundaries of its mesh
that take part in this pair (``contact_pairs = [["punch", "block:top"]]``: the punch's whole
contact surface against the block's boundary ``top``); without names it is the body's whole
contact surface. This is how CalculiX's ``*CONTACT PAIR`` and Abaqus pair *surfaces*: a body
touching two others on two faces says which face meets which, and a side's facets (its
**zone**) are all that the pair's search, pairing, transfer and placement read.

Every stage that reads "which facets of one side may meet the other" reads the pair's sides,
not two body indices: the candidates and the placement check (:mod:`.placement`, through
:meth:`ContactPairs.oriented`), the facing patches (:func:`~.pairing.facing`,
:func:`~.pairing.overlap`, a side's ``facets``), the compliance densities, the side choice and
the nodes a side keeps (:mod:`vfem.contact.formulations.pairmaking`: :meth:`ContactPairs.sorted`,
:meth:`ContactPairs.facing`), and the large-kinematics re-pairing (each pair keeps its zones).
What reads bodies only (the memory estimate, the unreachable pairs' note, the thesis variant
and the baselines, which refuse named sides) reads :meth:`ContactPairs.keys` and
:meth:`ContactPairs.opponents`. A pair of two sides of one body (self-contact, issue 42) is a
pair like any other to those that read sides: its two sides are two named boundaries of the
body that share no facet (:func:`_check_own_sides`), so a node never meets its own facets; the
invariants check the body against itself (:meth:`vfem.contact.invariants.check.InvariantCheck
._own_sides_apart`), in 2D, r-z and 3D. A surface that finds its own two sides (single-surface
contact: a body's ``self_contact``, or one side named twice, ``["ring:bore", "ring:bore"]``)
is split once, at rest (:func:`~.own_sides.split`), into two sides that hold their facets
(``Side.found``) and are read as named ones are.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...errors import InputError
from . import own_sides
from .bodymesh import exterior_facets

#: what separates a body's name from its boundaries' in a ``contact_pairs`` entry
#: (``"block:top"``, ``"block:top,left"``)
SEPARATOR = ":"


@dataclass(frozen=True, eq=False)
class Side:
    """One side of a contact pair: body ``body`` (its index), on its named ``boundaries`` only,
    or (None) on its whole contact surface. ``facets``: its **zone**, the facets of the body's
    contact surface it holds (indices into ``surface.facets``; :meth:`ContactPairs.on`), None
    for all of them. A side is itself and no other (compared by identity): the two sides of
    one body in a self-contact pair are two sides.

    A side of a surface that found its own two sides (single-surface self-contact,
    :func:`~.own_sides.split`) holds its mesh facets in ``found`` and which of the two it is
    in ``part`` (1 or 2); ``boundaries`` then names the surface split (None: the body's whole
    contact surface)."""

    body: int
    boundaries: tuple[str, ...] | None = None
    facets: np.ndarray | None = None
    #: (k,) the mesh facets of a side found by a split (sorted); None: named by ``boundaries``
    found: np.ndarray | None = None
    #: 1 or 2: which side of a split surface; 0: a named side
    part: int = 0

    def mesh_facets(self, body) -> np.ndarray | None:
        """(k,) the side's facets as indices into its ``body``'s mesh's facets, or None for
        all."""
        if self.found is not None:
            return self.found
        if self.boundaries is None:
            return None
        mesh = body.mesh
        return np.unique(np.concatenate([np.zeros(0, dtype=np.int64)] + [
            np.asarray(mesh.boundaries[b], dtype=np.int64) for b in self.boundaries]))

    def zone(self, body) -> np.ndarray:
        """(k,) the side's mesh facets, the body's whole contact surface's for None."""
        facets = self.mesh_facets(body)
        return exterior_facets(body) if facets is None else facets

    def text(self, bodies) -> str:
        """The side as an input names it (``block:top``), a found side with which of its
        surface's two it is (``ring:bore (side 1 of 2)``)."""
        name = bodies[self.body].name
        named = name if self.boundaries is None else (
            f"{name}{SEPARATOR}{','.join(self.boundaries)}")
        return f"{named} (side {self.part} of 2)" if self.part else named

    def on(self, surface) -> Side:
        """This side with its zone read on its body's contact ``surface``."""
        facets = self.mesh_facets(surface.body)
        return replace(self, facets=None if facets is None else
                       np.flatnonzero(np.isin(surface.facet_ids, facets)))


@dataclass(frozen=True)
class SurfacePair:
    """Two sides that may touch, in the order the input names them."""

    a: Side
    b: Side

    @property
    def bodies(self) -> tuple[int, int]:
        return self.a.body, self.b.body

    def ordered(self) -> SurfacePair:
        """The pair with the lower body's side first (a pair's key order, :meth:`keys`)."""
        return self if self.a.body <= self.b.body else SurfacePair(self.b, self.a)


@dataclass(frozen=True)
class ContactPairs:
    """The pairs of surface sides that may touch, one pair at most per two bodies, in the order
    the input names them. What reads a pair's geometry reads its sides (:meth:`sorted`,
    :meth:`oriented`, a side's ``facets``, after :meth:`on`); membership
    (``frozenset((i, j)) in pairs``), :meth:`keys` and :meth:`opponents` read the bodies only.
    """

    pairs: tuple[SurfacePair, ...]

    @classmethod
    def every(cls, n: int) -> ContactPairs:
        """Every two of ``n`` bodies, on their whole contact surfaces."""
        return cls(tuple(SurfacePair(Side(i), Side(j)) for i in range(n) for j in range(i + 1, n)))

    @classmethod
    def parse(cls, entries, bodies, where: str = "contact pair") -> ContactPairs:
        """The pairs an input names (``contact_pairs``; None: :meth:`every`), and a pair of
        each body with ``self_contact`` with itself. A side is a body's name, or its name,
        :data:`SEPARATOR` and boundary names separated by commas. An entry naming one side
        twice (``["ring:bore", "ring:bore"]``, ``["u", "u"]``), or a body's
        ``self_contact`` (its whole contact surface), is a surface that finds its own two
        sides (:func:`~.own_sides.split`): the pair of those two, or none where it finds
        nothing.

        Raises:
            InputError: an unknown body or boundary (naming the entry and what there is), two
                different sides of one body that share facets, two entries for the same two
                bodies, a body with ``self_contact`` that an entry pairs with itself too, or a
                surface whose two sides cannot be told apart (:func:`~.own_sides.split`).
        """
        made: dict[tuple[int, int], SurfacePair | None] = {}
        named: dict[tuple[int, int], list] = {}
        if entries is None:
            made = {p.bodies: p for p in cls.every(len(bodies)).pairs}
        names = {b.name: i for i, b in enumerate(bodies)}
        for entry in entries or ():
            if len(entry) != 2:
                raise InputError(f"{where} {list(entry)!r}: name two surfaces, e.g. "
                                 "['punch', 'block:top']")
            sides = [_side(text, names, bodies, entry, where) for text in entry]
            key = tuple(sorted((sides[0].body, sides[1].body)))
            if key in named:
                first = named[key]
                raise InputError(
                    f"{where} {list(entry)!r}: bodies {bodies[key[0]].name!r} and "
                    f"{bodies[key[1]].name!r} are already paired ({first!r}); name all the "
                    "boundaries of a side in one entry, separated by commas (e.g. "
                    f"'{bodies[key[1]].name}{SEPARATOR}top,left')")
            named[key] = list(entry)
            if sides[0].body == sides[1].body and _check_own_sides(sides, bodies, entry,
                                                                    where):
                made[key] = _found(sides[0], bodies, f"{where} {list(entry)!r}")
            else:
                made[key] = SurfacePair(*sides)
        for i, body in enumerate(bodies):
            if getattr(body, "self_contact", False) is False:
                continue
            body.validate()  # (a self_contact that is not a boolean: said by the body)
            if (i, i) in named:
                raise InputError(f"{where} {named[(i, i)]!r} pairs body {body.name!r} with "
                                 "itself, and the body has self_contact = true too: give one "
                                 "(self_contact finds the two sides of its whole contact "
                                 "surface; the entry names them, or one side to split)")
            made[(i, i)] = _found(Side(i), bodies,
                                  f"{where} of body {body.name!r} with itself "
                                  "(self_contact = true)")
        return cls(tuple(p for p in made.values() if p is not None))

    def keys(self) -> list[tuple[int, int]]:
        """(i, j), i <= j (equal: two sides of one body), of every pair, in order."""
        return [p.bodies for p in self.sorted()]

    def sorted(self) -> list[SurfacePair]:
        """The pairs in the order of their bodies, the lower body's side first."""
        return sorted((p.ordered() for p in self.pairs), key=lambda p: p.bodies)

    def oriented(self) -> list[tuple[Side, Side]]:
        """Every pair both ways, (own side, other side), in the order of (own body, other
        body): what the placement and the side choice read of each side against the other."""
        both = [(s, o) for p in self.pairs for s, o in ((p.a, p.b), (p.b, p.a))]
        return sorted(both, key=lambda so: (so[0].body, so[1].body))

    def names(self, bodies) -> list[tuple[str, str]]:
        """Each pair's two bodies' names, in the order the input gives them."""
        return [(bodies[p.a.body].name, bodies[p.b.body].name) for p in self.pairs]

    def __iter__(self):
        return iter(self.pairs)

    def __len__(self) -> int:
        return len(self.pairs)

    def __contains__(self, bodies) -> bool:
        """Whether a pair joins the bodies of the set ``bodies`` (two, or one: a pair of one
        body's sides)."""
        b = sorted(bodies)
        return len(b) in (1, 2) and self.between(b[0], b[-1]) is not None

    def between(self, i: int, j: int) -> SurfacePair | None:
        for p in self.pairs:
            if set(p.bodies) == {i, j}:
                return p
        return None

    def opponents(self, i: int) -> list[int]:
        """The bodies body ``i`` may touch, in order."""
        return sorted(j for p in self.pairs for j in p.bodies if i in p.bodies and j != i)

    def facing(self, side: Side) -> list[tuple[Side, Side]]:
        """What the nodes of ``side``'s body may meet: (own side, other side) of every pair
        with a side on its body, but ``side`` itself as the other (in the order of
        :meth:`oriented`). A node meets the other side of a pair whose own side holds it."""
        return [(s, o) for s, o in self.oriented() if s.body == side.body and o is not side]

    @property
    def sided(self) -> bool:
        """Whether a pair is not two whole bodies: a side names boundaries, or both sides are
        one body's. A formulation that reads whole surfaces refuses it
        (:attr:`~vfem.contact.capabilities.Capabilities.sides`)."""
        return any(s.boundaries is not None for p in self.pairs for s in (p.a, p.b)) or any(
            p.a.body == p.b.body for p in self.pairs)

    def on(self, surfaces) -> ContactPairs:
        """These pairs with their sides' zones read on the bodies' contact ``surfaces``."""
        return ContactPairs(tuple(SurfacePair(p.a.on(surfaces[p.a.body]),
                                              p.b.on(surfaces[p.b.body])) for p in self.pairs))


def zone_nodes(surface, facets: np.ndarray | None) -> np.ndarray:
    """(k,) the candidate nodes of ``surface`` (its local numbers) on a zone's ``facets``, all of
    them for None (a whole surface)."""
    return np.arange(surface.nc) if facets is None else np.unique(surface.facets[facets])


def zone_mask(surface, facets: np.ndarray | None) -> np.ndarray:
    """(nc,) True at the candidate nodes of ``surface`` on a zone's ``facets``
    (:func:`zone_nodes`)."""
    mask = np.zeros(surface.nc, dtype=bool)
    mask[zone_nodes(surface, facets)] = True
    return mask


def _check_own_sides(sides: list[Side], bodies, entry, where: str) -> bool:
    """Two sides of one body (self-contact, issue 42): one side named twice (the same facets:
    a surface that finds its own two sides, returns True), or two sides that share no facet,
    so a node never meets its own facets (False). Next to the line where two named sides
    meet, the pairing reads only the other side's facets that face this one
    (:func:`~.pairing.facing`: a straight boundary split in two pairs nothing), and the
    invariants leave out a node of both sides (``docs/method.md`` §15)."""
    body = bodies[sides[0].body]
    a, b = (set(s.zone(body).tolist()) for s in sides)
    if a == b:
        return True
    if a & b:
        shared = sorted(set(sides[0].boundaries or ()) & set(sides[1].boundaries or ()))
        whole = [s.text(bodies) for s in sides if s.boundaries is None]
        raise InputError(f"{where} {list(entry)!r}: the two sides of body {body.name!r} share "
                         f"{len(a & b)} facets" + (f" (boundary {shared[0]!r} is named on both)"
                                                   if shared else "")
                         + (f" ({whole[0]!r} is its whole contact surface)" if whole else "")
                         + "; a body's two sides in contact with each other must be apart (or "
                         "name one side twice for a surface that finds its own two sides)")
    return False


def _found(side: Side, bodies, where: str) -> SurfacePair | None:
    """The pair of the two sides the surface of ``side`` finds of itself
    (:func:`~.own_sides.split`), None where it finds none."""
    body = bodies[side.body]
    body.validate()  # (the split reads its mesh, boundaries and section)
    found = own_sides.split(body, side.zone(body), where, side.boundaries)
    if found is None:
        return None
    return SurfacePair(*(Side(side.body, side.boundaries, found=f, part=k + 1)
                         for k, f in enumerate(found)))


def _side(text, names: dict, bodies, entry, where: str) -> Side:
    if not isinstance(text, str):
        raise InputError(f"{where} {list(entry)!r}: {text!r} is not a name")
    if text in names:
        return Side(names[text])
    name, sep, rest = text.rpartition(SEPARATOR)
    if not sep or name not in names:
        raise InputError(f"{where} {list(entry)!r} names unknown body {text!r}; the bodies: "
                         f"{', '.join(names)} (a side may name boundaries as "
                         f"'body{SEPARATOR}boundary')")
    body = bodies[names[name]]
    wanted = tuple(dict.fromkeys(b.strip() for b in rest.split(",")))  # (spaces ignored)
    if "" in wanted:
        raise InputError(f"{where} {list(entry)!r}: {text!r} names an empty boundary; give "
                         f"'{name}{SEPARATOR}boundary' or boundaries separated by commas")
    known = sorted(body.mesh.boundaries or {})
    exterior = exterior_facets(body)
    for b in wanted:
        if b not in known:
            raise InputError(f"{where} {list(entry)!r}: body {name!r} has no boundary {b!r}; "
                             f"its mesh's boundaries: {', '.join(known) or 'none'}")
        if body.contact_boundaries is not None and b not in body.contact_boundaries:
            raise InputError(f"{where} {list(entry)!r}: boundary {b!r} of body {name!r} is not "
                             f"one of its contact_boundaries ({', '.join(body.contact_boundaries)})"
                             "; add it there, or leave contact_boundaries out")
        if not np.isin(body.mesh.boundaries[b], exterior).any():
            raise InputError(f"{where} {list(entry)!r}: boundary {b!r} of body {name!r} cannot "
                             "touch: a displacement is prescribed on it (a support, a prescribed "
                             "displacement or the platen); name it in contact_boundaries if it "
                             "is meant to")
    return Side(names[name], wanted)
