"""Which surfaces may touch: contact pairs of surface *sides*, not of whole bodies.

A pair joins two sides. A side is a body and, optionally, the named boundaries of its mesh
that take part in this pair (``contact_pairs = [["punch", "block:top"]]``: the punch's whole
contact surface against the block's boundary ``top``); without names it is the body's whole
contact surface. This is how CalculiX's ``*CONTACT PAIR`` and Abaqus pair *surfaces*: a body
touching two others on two faces says which face meets which, and a side's facets (its
**zone**) are all that the pair's search, pairing, transfer and placement read.

Every stage that reads "which facets of body i may meet body j" takes it from here
(:meth:`ContactPairs.zones`): the candidates (:mod:`.placement`), the facing patches
(:func:`~.pairing.facing`, :func:`~.pairing.overlap`), the compliance densities and the side
choice (:mod:`vfem.contact.formulations.pairmaking`), and the pairs the formulations and the
solver iterate (:meth:`ContactPairs.keys`, :meth:`ContactPairs.opponents`). A pair of two
sides of one body (self-contact, issue 42) is a pair like any other here; what it adds is the
split of one boundary into two sides (each node's own neighbourhood left out), which is not
built yet (:meth:`ContactPairs.parse` refuses a body named twice).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError

#: what separates a body's name from its boundaries' in a ``contact_pairs`` entry
#: (``"block:top"``, ``"block:top,left"``)
SEPARATOR = ":"


@dataclass(frozen=True)
class Side:
    """One side of a contact pair: body ``body`` (its index), on its named ``boundaries`` only,
    or (None) on its whole contact surface."""

    body: int
    boundaries: tuple[str, ...] | None = None

    def mesh_facets(self, bodies) -> np.ndarray | None:
        """(k,) the side's facets as indices into its mesh's facets, or None for all."""
        if self.boundaries is None:
            return None
        mesh = bodies[self.body].mesh
        return np.unique(np.concatenate([np.zeros(0, dtype=np.int64)] + [
            np.asarray(mesh.boundaries[b], dtype=np.int64) for b in self.boundaries]))

    def text(self, bodies) -> str:
        name = bodies[self.body].name
        return name if self.boundaries is None else (
            f"{name}{SEPARATOR}{','.join(self.boundaries)}")


@dataclass(frozen=True)
class SurfacePair:
    """Two sides that may touch, in the order the input names them."""

    a: Side
    b: Side

    @property
    def bodies(self) -> tuple[int, int]:
        return self.a.body, self.b.body

    def side(self, body: int) -> Side:
        return self.a if body == self.a.body else self.b


@dataclass(frozen=True)
class ContactPairs:
    """The pairs of surface sides that may touch, one pair at most per two bodies.

    ``zones``: per pair (i, j) and body, its side's facets as indices into that body's
    contact surface (:meth:`on`), or None where the side is the whole surface. Membership
    (``frozenset((i, j)) in pairs``) and iteration (:meth:`keys`) read the bodies only.
    """

    pairs: tuple[SurfacePair, ...]
    zones: dict = field(default_factory=dict, compare=False)

    @classmethod
    def every(cls, n: int) -> ContactPairs:
        """Every two of ``n`` bodies, on their whole contact surfaces."""
        return cls(tuple(SurfacePair(Side(i), Side(j)) for i in range(n) for j in range(i + 1, n)))

    @classmethod
    def parse(cls, entries, bodies, where: str = "contact pair") -> ContactPairs:
        """The pairs an input names (``contact_pairs``; None: :meth:`every`). A side is a body's
        name, or its name, :data:`SEPARATOR` and boundary names separated by commas.

        Raises:
            InputError: an unknown body or boundary (naming the entry and what there is), a
                body named twice in one entry, or two entries for the same two bodies.
        """
        if entries is None:
            return cls.every(len(bodies))
        names = {b.name: i for i, b in enumerate(bodies)}
        made: dict[tuple[int, int], SurfacePair] = {}
        for entry in entries:
            if len(entry) != 2:
                raise InputError(f"{where} {list(entry)!r}: name two surfaces, e.g. "
                                 "['punch', 'block:top']")
            sides = [_side(text, names, bodies, entry, where) for text in entry]
            if sides[0].body == sides[1].body:
                raise InputError(f"{where} {list(entry)!r} names one body twice: contact of "
                                 "a body with itself is not supported")
            key = tuple(sorted((sides[0].body, sides[1].body)))
            if key in made:
                first = made[key]
                raise InputError(
                    f"{where} {list(entry)!r}: bodies {bodies[key[0]].name!r} and "
                    f"{bodies[key[1]].name!r} are already paired "
                    f"({[first.a.text(bodies), first.b.text(bodies)]!r}); name all the "
                    "boundaries of a side in one entry, separated by commas "
                    f"('{bodies[key[1]].name}{SEPARATOR}top,left')")
            made[key] = SurfacePair(*sides)
        return cls(tuple(made.values()))

    def keys(self) -> list[tuple[int, int]]:
        """(i, j), i < j, of every pair, in order."""
        return sorted(tuple(sorted(p.bodies)) for p in self.pairs)

    def names(self, bodies) -> list[tuple[str, str]]:
        """Each pair's two bodies' names, in the order the input gives them."""
        return [(bodies[p.a.body].name, bodies[p.b.body].name) for p in self.pairs]

    def __iter__(self):
        return iter(self.pairs)

    def __len__(self) -> int:
        return len(self.pairs)

    def __contains__(self, bodies) -> bool:
        return self.between(*sorted(bodies)) is not None if len(bodies) == 2 else False

    def between(self, i: int, j: int) -> SurfacePair | None:
        for p in self.pairs:
            if set(p.bodies) == {i, j}:
                return p
        return None

    def opponents(self, i: int) -> list[int]:
        """The bodies body ``i`` may touch, in order."""
        return sorted(j for p in self.pairs for j in p.bodies if i in p.bodies and j != i)

    @property
    def named(self) -> bool:
        """Whether a side names boundaries (a formulation that reads whole surfaces refuses
        it: :attr:`~vfem.contact.capabilities.Capabilities.surface_pairs`)."""
        return any(s.boundaries is not None for p in self.pairs for s in (p.a, p.b))

    def mesh_zone(self, bodies, i: int, j: int) -> np.ndarray | None:
        """Body i's side of its pair with j as mesh facet indices (None: all)."""
        return self.between(i, j).side(i).mesh_facets(bodies)

    def on(self, surfaces) -> ContactPairs:
        """These pairs with their zones read on the bodies' contact ``surfaces``."""
        bodies = [s.body for s in surfaces]
        zones = {}
        for p in self.pairs:
            for own, other in (p.bodies, p.bodies[::-1]):
                facets = self.mesh_zone(bodies, own, other)
                zones[own, other] = None if facets is None else np.flatnonzero(
                    np.isin(surfaces[own].facet_ids, facets))
        return ContactPairs(self.pairs, zones)

    def zone(self, i: int, j: int) -> np.ndarray | None:
        """Body i's facets (indices into its contact surface) on its side of the pair with
        body j, or None for its whole surface."""
        if (i, j) in self.zones:
            return self.zones[i, j]
        if self.between(i, j).side(i).boundaries is not None:
            raise ValueError("a side's zone is read on the contact surfaces (ContactPairs.on) "
                             "before it is used")
        return None


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
    wanted = tuple(dict.fromkeys(b.strip() for b in rest.split(",")))
    known = sorted(body.mesh.boundaries or {})
    for b in wanted:
        if b not in known:
            raise InputError(f"{where} {list(entry)!r}: body {name!r} has no boundary {b!r}; "
                             f"its mesh's boundaries: {', '.join(known) or 'none'}")
        if body.contact_boundaries is not None and b not in body.contact_boundaries:
            raise InputError(f"{where} {list(entry)!r}: boundary {b!r} of body {name!r} is not "
                             f"one of its contact_boundaries ({', '.join(body.contact_boundaries)})"
                             "; add it there, or leave contact_boundaries out")
    return Side(names[name], wanted)
