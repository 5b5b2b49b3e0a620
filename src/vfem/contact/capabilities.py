"""What a contact formulation supports, declared as data
(:mod:`vfem.contact.formulations.formulation`)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Capabilities:
    """What a formulation supports, as data.

    ``invariants``: what a broken invariant of :mod:`vfem.contact.invariants.check` does to a step —
    ``"enforced"`` (the step fails and is cut), ``"recorded"`` (recorded and warned about: the
    thesis's plain reading leaves errors by design) or ``"compared"`` (recorded silently: a
    baseline's answer is its own, compared with vfem's). ``cuts_steps``: whether a failed step
    is retried with a smaller increment (a baseline's linear frictionless answer does not depend
    on the path, so its failure is final). ``reads_rind``: whether the formulation needs the
    current positions of the rind's nodes from the bodies' flexibility (the thesis variant
    locates nodes in the opposing rind as it iterates); the others read only the candidate
    nodes, so each body is condensed to its candidate dofs alone (issue 19, item 4: the dense
    block, its inversion and its memory shrink by about 2, 8 and 4 times on a long surface).
    ``orders_3d``: the element orders of ``orders`` it supports on 3D bodies that may touch
    (the 3D overlap quadrature is for linear facets only: issue 21, C10). ``friction``: what its
    friction reads of a pair's law (:class:`vfem.contact.laws.FrictionLaw`): ``"coefficients"``
    (the static and dynamic ones), ``"slip"`` (coefficients that depend on the slip a node has
    accumulated), ``"compliance"`` (an elastic slip below the cone); it takes every law whose
    ``reads`` are among them, and none (empty) for frictionless contact only. ``sides``:
    whether it reads a pair's sides (:class:`vfem.contact.geometry.sides.ContactPairs`: a side
    that names boundaries, ``["punch", "block:top"]``); one that reads whole surfaces refuses
    such a pair.
    """

    name: str
    orders: tuple[int, ...]
    kinematics: tuple[str, ...]
    dimensions: tuple[int, ...]
    #: what its friction reads of a law (see above); empty: frictionless contact only
    friction: tuple[str, ...] = ()
    invariants: str = "enforced"
    cuts_steps: bool = True
    reads_rind: bool = False
    orders_3d: tuple[int, ...] = ()
    sides: bool = False
