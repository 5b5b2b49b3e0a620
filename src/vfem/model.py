"""The model: bodies, the contact settings and the load schedule (:class:`Model`), and the
contact surfaces its meshes give (:meth:`Model.contact_surfaces`).

Below the driver (:mod:`vfem.solver`) and the result types, which both read it; it depends on
the bodies and on contact's search and surfaces only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .bodies import Body
from .bodies.section import SPACES
from .contact.formulations import check_capabilities
from .contact.geometry import (
    ContactPairs,
    ContactSurface,
    check_initial_overlap,
    select_candidate_facets,
)
from .contact.settings import ContactSettings
from .errors import InputError
from .executor import SERIAL


@dataclass
class Model:
    """Bodies, the contact settings and the load schedule.

    ``load_factors``: the load factor at the end of each step, starting from 0. They may go down
    as well as up (unloading, thesis §5.5); loads and prescribed displacements scale with them,
    or follow their load curves (``amplitude``).
    """

    name: str
    bodies: list[Body]
    contact: ContactSettings = field(default_factory=ContactSettings)
    load_factors: tuple[float, ...] = (1.0,)
    contact_pairs: tuple[tuple[str, str], ...] | None = None  # default: every pair may touch
    #: seconds spent building it (meshes, bodies, checks: ModelConfig.build), for the phases
    build_s: float = field(default=0.0, compare=False)

    @property
    def iterates(self) -> bool:
        """Whether a body's response is corrected by Newton's method (:attr:`Body.iterates`):
        the contact then takes the large-kinematics formulation."""
        return any(b.iterates for b in self.bodies)

    def validate(self) -> None:
        names = [b.name for b in self.bodies]
        if not self.bodies:
            raise InputError(f"model {self.name!r} has no bodies")
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise InputError(f"model {self.name!r}: body names must be unique, repeated: "
                             f"{', '.join(sorted(dup))}")
        lf = np.asarray(self.load_factors, dtype=float)
        if lf.size == 0 or not np.all(np.isfinite(lf)) or np.any(np.diff(np.r_[0.0, lf]) == 0):
            raise InputError(f"model {self.name!r}: load_factors must be finite numbers, each "
                             f"different from the one before (and the first not 0), got "
                             f"{list(self.load_factors)}")
        self.pairs()  # its bodies and boundaries exist, one pair per two bodies
        for b in self.bodies:
            b.validate()
        spaces = {b.name: b.section.space for b in self.bodies}  # bodies.section
        if len(set(spaces.values())) > 1:
            raise InputError(f"model {self.name!r}: its bodies must all be "
                             + " or all ".join(SPACES) + ", got "
                             + ", ".join(f"{n!r} {d}" for n, d in spaces.items()))
        check_capabilities(self)  # what the formulation supports, as it declares it
        if sum(b.platen is not None for b in self.bodies) > 1:
            raise InputError(f"model {self.name!r}: at most one force-controlled platen")
        self.contact.validate()

    def pairs(self) -> ContactPairs:
        """The pairs of surface sides that may touch (``contact_pairs``, or every two bodies on
        their whole contact surfaces; :class:`~vfem.contact.geometry.sides.ContactPairs`)."""
        return ContactPairs.parse(self.contact_pairs, self.bodies,
                                  f"model {self.name!r}: contact pair")

    def contact_surfaces(self, executor=SERIAL) -> tuple[ContactPairs, list[ContactSurface]]:
        """The pairs of surface sides that may touch (:meth:`pairs`, their zones read on the
        surfaces) and each body's contact surface: candidate facets within
        ``contact.search_distance`` of a side it may touch (by default every facet that may
        touch under large kinematics, where bodies may slide far; a distance given is honoured
        there, along the whole path of the prescribed motions).

        Depends on the meshes only, so it is also part of ``vfem check``: bodies that start
        deeper into each other than the outer layer of elements are refused here
        (:func:`~vfem.contact.geometry.placement.check_initial_overlap`). ``executor``: where
        each pair's search runs (:mod:`vfem.executor`; over MPI ranks, spread).
        """
        pairs = self.pairs()
        distance = self.contact.search_distance
        large = any(b.large for b in self.bodies)
        if distance is None and large:  # bodies may slide anywhere: every facet (issue 19:
            distance = np.inf           # a distance given is honoured, with the path followed)
        elif distance is None:
            diag = [float(np.linalg.norm(np.ptp(b.mesh.p, axis=1))) for b in self.bodies]
            distance = 0.02 * min(diag)
        facets = self._candidate_facets(pairs, distance, large, executor)
        surfaces = [ContactSurface.build(b, f, tributary=False)
                    for b, f in zip(self.bodies, facets)]
        # the facets' mass matrices (the tributary areas) each body's on one rank
        # (vfem.parallel, issue 40), every one to every rank
        entries = executor.map(
            range(len(surfaces)), lambda i: surfaces[i]._facet_mass_entries()
            if len(surfaces[i].facets) else None,
            owners=[i % executor.size for i in range(len(surfaces))])
        for i, s in enumerate(surfaces):
            s.set_tributary(entries[i])
        pairs = pairs.on(surfaces)
        check_initial_overlap(surfaces, pairs, executor)
        return pairs, surfaces

    def _candidate_facets(self, pairs: ContactPairs, distance: float, large: bool,
                          executor=SERIAL) -> list:
        """Each body's candidate facets (:func:`select_candidate_facets`), searched once per
        model: an input file's run checks its model (``vfem.config.check``, which builds the
        contact surfaces) and then solves it (:meth:`vfem.solver.Analysis.setup`, again),
        and the search was 2.8 s of ``vfem run cattaneo3d``'s 21 (issue 40). Kept with what it
        read (the bodies and meshes by identity, their kinematics and prescribed motions, the
        pairs, the distance and the load factors), searched afresh if any of it changed.
        The arrays handed out are copies (the kept ones stay as searched)."""
        key = (tuple((id(b), id(b.mesh), b.large, repr(b.prescribed), repr(b.platen),
                      repr(b.contact_boundaries)) for b in self.bodies),
               repr(self.contact_pairs), repr(pairs), float(distance),
               tuple(float(f) for f in self.load_factors), large)
        kept = self.__dict__.get("_facets")
        if kept is None or kept[0] != key:
            facets = select_candidate_facets(self.bodies, pairs, distance, self.load_factors,
                                             follow_path=large, executor=executor)
            kept = self.__dict__["_facets"] = (key, facets)
        return [np.array(f, copy=True) for f in kept[1]]
