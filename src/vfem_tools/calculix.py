"""The same model in CalculiX: write a vfem model as a ``ccx`` input deck, run it, read it back.

For comparing vfem with a general-purpose code on the *same mesh* (docs/benchmarks.md, *Hertz in
CalculiX*):

* :func:`write_deck` writes a two-body, linear-element :class:`~vfem.model.Model`
  (the Hertz example's, or any like it) as a CalculiX deck: the same nodes and elements (3-node
  triangles as CPE3, 4-node quadrilaterals as CPE4; CPS3/CPS4 for plane stress), each counter-
  clockwise in the x-y plane as ccx requires, unit thickness; one linear elastic material per
  body; supports and prescribed displacements as ``*BOUNDARY``; a force-controlled platen as
  ``*EQUATION`` ties of its nodes' platen component to one reference node that carries the
  ``*CLOAD``; frictionless surface-to-surface penalty contact (``*CONTACT PAIR, TYPE=SURFACE TO
  SURFACE``) between the bodies' contact candidate facets, the softer body the slave (a
  contact pair's side that names boundaries, ``"ring:outer"``, the surface of those boundaries'
  element faces; a pair of two boundaries of one body, self-contact in 2D or r-z, a ``*CONTACT
  PAIR`` of its two surfaces, the side named first the slave: ``Deck.pairs``); a J2
  plastic material (:class:`vfem.materials.J2Plastic`, isotropic hardening) as ``*PLASTIC``. With
  ``friction``, Coulomb friction (``*FRICTION``: mu and ccx's stick slope); with
  ``steps="curves"``, loads on load curves (prescribed displacements and a platen force with
  amplitudes: the Cattaneo example's press, then shear) as one ccx step per stretch of linear
  loading, its increments at the model's load factors. In 3D (the sphere example's kind of
  model): 8-node hexahedra as C3D8 (scikit-fem's corners in ccx's order,
  :data:`C3D8_FROM_SKFEM`) and 4-node tetrahedra as C3D4, each of positive volume (a mirrored
  element's node order reversed), supports on x, y and z, the platen's ties on its component,
  the contact surfaces as the elements' faces S1-S6 (S1-S4). A body of revolution (material
  ``plane = "axisymmetric"``) as CAX4 (CAX3): ccx expands them into a wedge of 2 degrees and
  reports its forces (RF, CF) on the wedge, which the readers multiply by 180
  (``Deck.force_scale``) to give vfem's, per full circle (its loads, like vfem's, are per full
  circle: ccx's manual, *Eight-node axisymmetric element*). A large-kinematics body (``kinematics
  = "total"`` or ``"updated"``) puts NLGEOM on every step; its law ``"neo-hookean-isochoric"``
  is written as ``*HYPERELASTIC, NEO HOOKE`` (the same law), ``"neo-hookean"`` as the same card
  with the same small-strain constants (not the same law at finite strain: :func:`_elastic`),
  Saint Venant-Kirchhoff as ``*ELASTIC`` (ccx's under NLGEOM); the held boundaries' total
  reactions are then written at every increment.
* :func:`run` runs ``ccx`` in a temporary folder, times it, and reads the results: ccx's own
  nodal contact pressure on the slave surface (CPRESS of ``*CONTACT FILE, CSTR``: "raw"), the
  total contact force ccx reports, and the slave body's nodal contact forces recomputed as
  ``K u`` (its stiffness, the same elements as ccx's, times ccx's displacements) per undeformed
  tributary length (3D: area), the reading :func:`vfem_examples.hertz.evaluate` (and
  :func:`vfem_examples.sphere.evaluate`) makes of vfem's results;
  and per increment (``history``) the slave nodes' contact stresses and slips (CPRESS, CSHEAR1,
  CSHEAR2, COPEN, CSLIP1, CSLIP2), their ``K u`` forces, the reactions of the held boundaries
  and ccx's total contact force: what benchmarks/cattaneo_calculix.py compares with vfem's
  friction.

The core never imports this module.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from skfem import Basis, ElementVector, FacetBasis, LinearForm, MeshHex, MeshTri, asm
from skfem.io.meshio import HEX_MAPPING
from skfem.models.elasticity import linear_elasticity

from vfem.contact.search import project_points
from vfem.errors import InputError, VfemError

if TYPE_CHECKING:
    from vfem.solver import Model

DOF = {"x": 1, "y": 2, "z": 3}

#: scikit-fem's MeshHex1 corners in ccx's C3D8 order (VTK's and Abaqus's: the face z = 0
#: counter-clockwise seen from +z, then the face above it)
C3D8_FROM_SKFEM = tuple(int(k) for k in HEX_MAPPING[:8])
#: ccx's faces S1..S6 of a C3D8 and S1..S4 of a C3D4 (local nodes, from 0)
C3D8_FACES = ((0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0))
C3D4_FACES = ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0))


@dataclass
class BodyDeck:
    """Where one body's nodes and elements went in the deck (ccx numbers from 1)."""

    name: str
    node_offset: int  # ccx node = node_offset + point + 1
    element_offset: int  # ccx element = element_offset + element + 1
    element_type: str
    contact_facets: np.ndarray  # facet ids (into mesh.facets) in the body's contact surface
    flipped: int  # elements whose node order was reversed (counter-clockwise; 3D: volume > 0)


@dataclass
class Deck:
    """A written CalculiX deck and what :func:`run` needs to read its results."""

    path: Path
    model: Model
    bodies: list[BodyDeck]
    slave: str
    master: str
    reference_node: int | None  # ccx node carrying the platen force (None: no platen)
    penalty: float | None
    tension: float
    approach: float | None  # the platen's displacement in the first, contact-making step
    steps: list[float] = field(default_factory=list)  # load factor at the end of each load step
    friction: float | None = None  # Coulomb's mu of *FRICTION (None: frictionless)
    stick_slope: float | None = None  # *FRICTION's tangential stiffness
    # steps="curves": per load step, the model's load factors it ends its increments at
    increments: list[list[float]] = field(default_factory=list)
    # boundary node sets whose total reaction is printed per increment: set -> (body, boundary)
    reaction_sets: dict[str, tuple[str, str]] = field(default_factory=dict)
    #: what ccx's forces (RF, CF) are multiplied by to be vfem's: 1, or 180 for an
    #: axisymmetric model (ccx expands CAX elements into a wedge of 2 degrees and reports the
    #: forces on it; vfem's, like the loads of both, are per full circle)
    force_scale: float = 1.0
    #: every ``*CONTACT PAIR`` as (slave surface, master surface), in the deck's order: the two
    #: bodies' pair first (if the model pairs them), then each pair of two sides of one body
    #: (self-contact)
    pairs: list[tuple[str, str]] = field(default_factory=list)

    def body(self, name: str) -> BodyDeck:
        return next(b for b in self.bodies if b.name == name)


# -- writing -------------------------------------------------------------------------------------


def _check_supported(model, curves: bool = False) -> None:
    """Refuse what the deck writer cannot express (one message per kind of problem); load curves
    (amplitudes) only with ``curves`` (``steps="curves"``)."""
    model.validate()
    if len(model.bodies) != 2:
        raise InputError(f"CalculiX deck: the writer handles two bodies in contact, model "
                         f"{model.name!r} has {len(model.bodies)}")
    if model.bodies[0].mesh.p.shape[0] == 3 and any(p.a.body == p.b.body
                                                    for p in model.pairs()):
        raise InputError(f"CalculiX deck: model {model.name!r} pairs two sides of one body "
                         "in 3D (self-contact), which the writer does not translate")
    for b in model.bodies:
        if b.order != 1:
            raise InputError(f"CalculiX deck: body {b.name!r} must have linear elements (order "
                             f"1), got order {b.order}")
        if b.large and b.material.carries_state:
            raise InputError(f"CalculiX deck: body {b.name!r} is plastic under large kinematics "
                             f"({b.kinematics!r}), which the writer does not translate (ccx's "
                             "finite-strain plasticity is not vfem's Hencky law)")
        if b.tractions:
            raise InputError(f"CalculiX deck: body {b.name!r} has tractions, which the writer "
                             "does not translate")
        if curves:
            continue
        if any(pd.amplitude is not None for pd in b.prescribed):
            raise InputError(f"CalculiX deck: body {b.name!r} has a prescribed displacement "
                             "with an amplitude, which the writer does not translate")
        if b.platen is not None and b.platen.amplitude is not None:
            raise InputError(f"CalculiX deck: body {b.name!r} has a platen force with an "
                             "amplitude, which the writer does not translate")


def _plastic(body) -> list[str]:
    """``*PLASTIC`` of a J2 material (:class:`vfem.materials.J2Plastic`; none for an elastic
    one): ccx's isotropic hardening table, von Mises stress against equivalent plastic strain
    (its hardening curve, or Y and, with a hardening modulus H, Y + H at a plastic strain of 1;
    perfectly plastic: Y alone)."""
    m = body.material
    if getattr(m, "yield_stress", None) is None:
        return []
    if m.kinematic_modulus:
        raise InputError(f"CalculiX deck: body {body.name!r} has kinematic hardening, which the "
                         "writer does not translate (ccx's *PLASTIC here is isotropic)")
    if m.hardening_curve:
        table = [(float(v), float(a)) for a, v in m.hardening_curve]
    elif m.hardening_modulus:
        table = [(float(m.yield_stress), 0.0),
                 (float(m.yield_stress + m.hardening_modulus), 1.0)]
    else:
        table = [(float(m.yield_stress), 0.0)]
    return ["*PLASTIC", *(f"{_num(v)}, {_num(a)}" for v, a in table)]


def _elastic(body) -> list[str]:
    """The elastic law of a body's ``*MATERIAL``: ``*ELASTIC`` (E, nu), which under ``NLGEOM``
    ccx reads in the Green-Lagrange strain, i.e. Saint Venant-Kirchhoff, vfem's default law of a
    large body; a large body with ``law = "neo-hookean-isochoric"``
    (:class:`vfem.materials.hyperelastic.IsochoricNeoHookean`) as ``*HYPERELASTIC, NEO HOOKE``
    with ``C10 = mu / 2`` and ``D1 = 2 / K`` (K = lambda + 2 mu / 3): the same law. With ``law =
    "neo-hookean"`` (:class:`vfem.materials.NeoHookean`) the same card and constants, which are
    not the same law at finite strain: vfem's ``"neo-hookean"`` is Ciarlet-Simo's, ``W = mu/2
    (I1 - 3) - mu ln J + lambda/2 (ln J)^2``, ccx's the split ``W = C10 (I1bar - 3) + (J - 1)^2
    / D1`` (I1bar = J^(-2/3) I1); no form of ccx's ``*HYPERELASTIC`` or ``*HYPERFOAM`` equals
    the Ciarlet-Simo form (benchmarks/oring_calculix.py measures the difference at a material
    point)."""
    m = body.material
    if body.large and body.law in ("neo-hookean", "neo-hookean-isochoric"):
        lam, mu = m.law(body.law, body.kinematics).lame()  # (the law's 3D constants)
        bulk = lam + 2.0 * mu / 3.0
        return ["*HYPERELASTIC, NEO HOOKE", f"{_num(mu / 2.0)}, {_num(2.0 / bulk)}"]
    return ["*ELASTIC", f"{_num(m.youngs_modulus)}, {_num(m.poissons_ratio)}"]


def _counter_clockwise(mesh) -> tuple[np.ndarray, int]:
    """(nodes per element, nelements) connectivity with every element counter-clockwise (ccx
    expands plane elements into solids along +z and refuses a negative Jacobian)."""
    t = mesh.t.copy()
    x = mesh.p[:, t]
    area2 = ((x[0, 1] - x[0, 0]) * (x[1, 2] - x[1, 0])
             - (x[0, 2] - x[0, 0]) * (x[1, 1] - x[1, 0]))
    cw = area2 < 0
    order = [0, 2, 1] if t.shape[0] == 3 else [0, 3, 2, 1]
    t[:, cw] = t[order][:, cw]
    return t, int(cw.sum())


def _faces(mesh, t: np.ndarray, facets: np.ndarray) -> list[tuple[int, int]]:
    """(element, face label k) of each facet: ccx's edge Sk of a plane element joins its local
    nodes k and k + 1 (the last one to the first)."""
    out = []
    n = t.shape[0]
    for f in facets:
        e = int(mesh.f2t[0, f])
        ends = set(mesh.facets[:, f].tolist())
        for k in range(n):
            if {int(t[k, e]), int(t[(k + 1) % n, e])} == ends:
                out.append((e, k + 1))
                break
    return out


def corner_jacobians(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(ncorners, nelements) determinants of the edge vectors at each corner of 3D elements in
    ccx's node order (C3D8: at corner k its edges to the next corner of its face, to the
    previous one and to the corner across; C3D4: six times the volume): all positive for an
    element ccx accepts. ``x``: (3, npoints); ``t``: (4 or 8, nelements)."""
    def det(a, b, c):
        return np.einsum("i...,i...->...", a, np.cross(b, c, axis=0))

    if t.shape[0] == 4:
        x0 = x[:, t[0]]
        return det(x[:, t[1]] - x0, x[:, t[2]] - x0, x[:, t[3]] - x0)[None]
    out = []
    for k in range(8):
        base, ring = divmod(k, 4)
        ring0 = 4 * base
        nxt, prv = ring0 + (ring + 1) % 4, ring0 + (ring - 1) % 4
        other = (k + 4) % 8
        xk = x[:, t[k]]
        d = det(x[:, t[nxt]] - xk, x[:, t[prv]] - xk, x[:, t[other]] - xk)
        out.append(d if base == 0 else -d)  # the top face runs the same way, seen from below
    return np.array(out)


def _positive_solids(mesh) -> tuple[np.ndarray, int]:
    """(nodes per element, nelements) connectivity in ccx's order (C3D8 or C3D4), every element
    of positive volume (one whose Jacobian is negative mirrored: its two z faces swapped, or a
    tetrahedron's second and third nodes)."""
    hexes = isinstance(mesh, MeshHex)
    t = mesh.t[list(C3D8_FROM_SKFEM)] if hexes else mesh.t.copy()
    signs = corner_jacobians(mesh.p, t).sum(axis=0)
    bad = signs < 0
    order = [4, 5, 6, 7, 0, 1, 2, 3] if hexes else [0, 2, 1, 3]
    t[:, bad] = t[order][:, bad]
    return t, int(bad.sum())


def _faces3d(mesh, t: np.ndarray, facets: np.ndarray) -> list[tuple[int, int]]:
    """(element, face label k) of each boundary facet of a 3D mesh: ccx's face Sk of its
    element (``C3D8_FACES``, ``C3D4_FACES``)."""
    faces = C3D8_FACES if t.shape[0] == 8 else C3D4_FACES
    facets = np.asarray(facets, dtype=int)
    elems = mesh.f2t[0, facets]
    want = np.sort(mesh.facets[:, facets], axis=0)
    label = np.zeros(len(facets), dtype=int)
    for k, face in enumerate(faces):
        have = np.sort(t[list(face)][:, elems], axis=0)
        label[(label == 0) & np.all(have == want, axis=0)] = k + 1
    if np.any(label == 0):
        raise VfemError("CalculiX deck: a contact facet is no face of its element")
    return list(zip(elems.tolist(), label.tolist()))


def _num(v: float) -> str:
    """A real as ccx reads it: at most 20 characters (it reads numbers with a 20-character
    format), full precision where that fits, else 14 significant digits."""
    text = repr(float(v))
    return text if len(text) <= 20 else f"{v:.13e}"


def _tag(name: str) -> str:
    """A name as a ccx set or surface name (upper case, word characters)."""
    return re.sub(r"\W", "_", name.upper())


def _side_surface(model, surfaces, side) -> tuple[str, np.ndarray]:
    """A contact pair's side (:class:`vfem.contact.geometry.sides.Side`) as a ccx surface: its
    name, ``S_<BODY>`` for a body's whole contact surface (its candidate facets),
    ``S_<BODY>_<BOUNDARY>`` for named boundaries (their names joined by ``_``), and its facets
    (indices into the body's mesh's facets)."""
    body = model.bodies[side.body]
    if side.boundaries is None:
        return f"S_{_tag(body.name)}", np.asarray(surfaces[side.body].facet_ids)
    name = f"S_{_tag(body.name)}_{_tag('_'.join(side.boundaries))}"
    return name, np.asarray(side.mesh_facets(body))


def _lines(values, per_line: int = 8) -> list[str]:
    values = list(values)
    return [", ".join(str(v) for v in values[i:i + per_line])
            for i in range(0, len(values), per_line)]


def _initial_gap(s, m) -> float:
    """The smallest distance from a slave candidate node to the master's candidate facets; in
    3D the :data:`APPROACH_NODES`-th smallest (so that the slave facets around the first point
    of contact overlap the master after the approach step: ccx makes contact elements only
    where a slave face's integration point penetrates, and a single touching node makes
    none)."""
    pts = s.X[: s.nc]
    if pts.shape[1] == 3:
        from vfem.contact.geometry import closest_on_facets

        if not len(pts) or not len(m.facets):
            return 0.0
        dist = closest_on_facets(pts, m.X, m.facets).distance
        dist = np.sort(dist[np.isfinite(dist)])
        return float(dist[min(APPROACH_NODES, len(dist)) - 1]) if len(dist) else 0.0
    a, b = m.X[m.facets[:, 0]], m.X[m.facets[:, 1]]
    _, _, dist = project_points(pts, a, b)
    return float(dist.min()) if len(dist) else 0.0


#: 3D: the platen's approach step brings this many slave candidate nodes onto the master
APPROACH_NODES = 4


def write_deck(model, path, *, slave: str | None = None, penalty: float | None = 1e11,
               tension: float = 0.0, steps: str = "one", approach: float | None = None,
               max_increments: int = 1000, friction: float | None = None,
               stick_slope: float | None = None,
               first_increment: float | None = None) -> Deck:
    """Write ``model`` as a CalculiX input deck at ``path`` (see the module docstring).

    Args:
        model: a two-body :class:`~vfem.model.Model` with linear elements (plane, axisymmetric
            or 3D; elastic bodies under small or large kinematics, plastic ones under small),
            supports, prescribed displacements and at most one platen (with amplitudes, i.e.
            load curves, only with ``steps="curves"``). Its contact pairs
            (:meth:`~vfem.model.Model.pairs`) are written as ``*CONTACT PAIR`` of their sides'
            surfaces (:func:`_side_surface`: a body's whole contact surface, or its named
            boundaries): the two bodies' pair with the ``slave`` body's side the slave; a pair of
            two sides of one body (self-contact, in 2D and r-z), the side the input names first
            the slave and the second the master (ccx pairs two distinct surfaces of one body like
            those of two bodies).
        path: the ``.inp`` file to write.
        slave: the slave body's name; default the one with the smaller Young's modulus.
        penalty: the contact stiffness (pressure per unit overclosure) of ccx's linear
            pressure-overclosure law; ``None``: ``PRESSURE-OVERCLOSURE=HARD`` (ccx chooses its
            own stiffness, which on the Hertz problem is far too soft: p_max 9 % low). The
            default, 1e11, gives the Hertz problem a penetration of 3e-7 at p0, 1.7e-4 of the
            cylinder's indentation (docs/benchmarks.md has the measured choice).
        tension: the linear law's second constant, sigma_inf (its tension at large
            clearances), which ccx says is "only relevant for node-to-surface contact" (it
            replaces 0 by a default of its own): surface-to-surface contact makes contact
            elements only where a slave integration point penetrates (measured: the same
            results with 0, 1 and 1.4e5).
        steps: ``"one"``: one ccx step to the last load factor, ccx's automatic increments
            starting with the first load factor (load factors that do not rise steadily get one
            step each); ``"model"``: one ccx step per model step; ``"curves"``: for loads on
            load curves (press, then shear), one ccx step per stretch of the model's load
            factors over which every load changes linearly (a new step where a load's rate
            changes or the load factor turns back: the Cattaneo example's press and shear), its
            increments the model's steps (ccx's automatic increments, at most a model step
            long, so that they end at the model's load factors unless ccx cuts one back), the
            loads at each step's end from their curves, so that ccx follows the path vfem does; the
            prescribed displacements are held at their load factor 0 values during the
            platen's approach; the total reaction of every held boundary (``*NODE PRINT,
            TOTALS=ONLY``, RF) and the contact displacements (``CDIS``) are written at every
            increment besides what the other choices write.
        approach: with a platen, a first ccx step pushes the platen this far (towards its
            force) under displacement control, so that contact holds the body when force
            control starts (ccx starts with no contact elements, and a body that only contact
            holds is singular then); default the initial gap plus 1e-6 times the model's size.
        max_increments: ccx's limit on the increments of a step.
        friction: Coulomb's coefficient mu: ``*FRICTION`` in the surface interaction (ccx's
            penalty friction: a node sticks elastically, its tangential traction the stick
            slope times its relative tangential displacement, until that reaches mu times its
            pressure); ``None``: frictionless, as before.
        stick_slope: *FRICTION's stick slope lambda (shear traction per unit relative
            tangential displacement); default the normal ``penalty`` (on the Cattaneo example
            the stick zone is then within a contact facet of Cattaneo-Mindlin's and no longer
            moves with the slope: benchmarks/cattaneo_calculix.py measures it). The elastic slip
            of a sticking node is its shear over lambda, which must be small against the slips
            of the slip zone near its edge, else the stick zone shrinks.
        first_increment: ccx's first increment of each load step, as a fraction of the step
            (at most); default the first load factor's share (one increment for a one-step
            model: on the 3D sphere ccx then cycles through contact states at full load).
    """
    curves = steps == "curves"
    _check_supported(model, curves)
    if steps not in ("one", "model", "curves"):
        raise InputError(f"CalculiX deck: steps must be 'one' or 'model', got {steps!r} (or "
                         "'curves' for loads on load curves)")
    names = [b.name for b in model.bodies]
    if slave is None:
        slave = min(model.bodies, key=lambda b: b.material.youngs_modulus).name
    if slave not in names:
        raise InputError(f"CalculiX deck: no body named {slave!r} for the slave surface; the "
                         f"model has {', '.join(names)}")
    i_slave = names.index(slave)
    master = names[1 - i_slave]
    tags = {n: _tag(n) for n in names}
    pairs, surfaces = model.contact_surfaces()
    # every contact pair as (slave side, master side): the two bodies' first, then self pairs
    contact_pairs = []
    for p in pairs:
        if p.a.body != p.b.body:
            contact_pairs.insert(0, (p.a, p.b) if p.a.body == i_slave else (p.b, p.a))
        else:
            contact_pairs.append((p.a, p.b))
    sides = {id(side): _side_surface(model, surfaces, side)
             for pair in contact_pairs for side in pair}
    size = max(float(np.linalg.norm(np.ptp(b.mesh.p, axis=1))) for b in model.bodies)
    # large kinematics: every step NLGEOM (ccx's applies to the whole model; a small body in
    # it is then Saint Venant-Kirchhoff, which its small strains cannot tell from linear)
    large = any(b.large for b in model.bodies)
    axisymmetric = model.bodies[0].section.space == "axisymmetric"

    out = ["*HEADING", f"vfem model {model.name!r} written by vfem_tools.calculix"]
    decks: list[BodyDeck] = []
    node_off = elem_off = 0
    for ib, (b, s) in enumerate(zip(model.bodies, surfaces)):
        mesh, tag = b.mesh, tags[b.name]
        solid = mesh.p.shape[0] == 3
        if solid:
            t, flipped = _positive_solids(mesh)
            kind = "C3D8" if t.shape[0] == 8 else "C3D4"
        else:
            t, flipped = _counter_clockwise(mesh)
            family = {"plane strain": "CPE", "plane stress": "CPS",
                      "axisymmetric": "CAX"}[b.section.space]
            kind = family + ("3" if isinstance(mesh, MeshTri) else "4")
        out.append(f"** body {b.name}: nodes {node_off + 1}-{node_off + mesh.p.shape[1]}, "
                   f"elements {elem_off + 1}-{elem_off + t.shape[1]} ({kind})")
        out.append(f"*NODE, NSET=N_{tag}")
        out += [f"{node_off + i + 1}, " + ", ".join(_num(v) for v in x)
                for i, x in enumerate(mesh.p.T.tolist())]
        out.append(f"*ELEMENT, TYPE={kind}, ELSET=E_{tag}")
        out += [f"{elem_off + e + 1}, " + ", ".join(str(node_off + k + 1) for k in conn)
                for e, conn in enumerate(t.T.tolist())]
        held = {x.boundary for x in (*b.supports, *b.prescribed)}
        held |= {b.platen.boundary} if b.platen else set()
        for name in sorted(held):
            nodes = np.unique(mesh.facets[:, mesh.boundaries[name]]) + node_off + 1
            out.append(f"*NSET, NSET=B_{tag}_{_tag(name)}")
            out += _lines(nodes.tolist())
        written = set()
        for side in (side for pair in contact_pairs for side in pair):
            surface, facets = sides[id(side)]
            if side.body != ib or surface in written:
                continue
            written.add(surface)
            out.append(f"*SURFACE, NAME={surface}, TYPE=ELEMENT")
            out += [f"{elem_off + e + 1}, S{k}"
                    for e, k in (_faces3d if solid else _faces)(mesh, t, facets)]
        # a plane element's thickness, 1 (an axisymmetric one's is ccx's 2 degrees, whatever
        # the line says: none is written)
        out += [f"*MATERIAL, NAME=M_{tag}", *_elastic(b), *_plastic(b),
                f"*SOLID SECTION, ELSET=E_{tag}, MATERIAL=M_{tag}",
                *([] if solid or kind.startswith("CAX") else ["1."])]
        decks.append(BodyDeck(b.name, node_off, elem_off, kind, np.asarray(s.facet_ids),
                              flipped))
        node_off += mesh.p.shape[1]
        elem_off += t.shape[1]

    supports = [f"B_{tags[b.name]}_{_tag(sup.boundary)}, {DOF[c]}, {DOF[c]}"
                for b in model.bodies for sup in b.supports for c in b.support_components(sup)]
    out += ["*BOUNDARY", *supports]

    def prescribed(factor: float) -> list[str]:
        return [f"B_{tags[b.name]}_{_tag(pd.boundary)}, {DOF[pd.component]}, "
                f"{DOF[pd.component]}, {_num(pd.at(factor))}"
                for b in model.bodies for pd in b.prescribed]

    ref = None
    platen_body = next((b for b in model.bodies if b.platen is not None), None)
    if platen_body is not None:
        pl = platen_body.platen
        dof = DOF[pl.component]
        offset = decks[names.index(platen_body.name)].node_offset
        nodes = np.unique(platen_body.mesh.facets[:, platen_body.mesh.boundaries[pl.boundary]])
        nodes = nodes + offset + 1
        ref = int(nodes[0])
        out.append(f"** the platen: the {pl.component} displacement of every node of "
                   f"{platen_body.name}'s {pl.boundary!r} equals that of node {ref}")
        out.append("*EQUATION")
        for n in nodes[1:].tolist():
            out += ["2", f"{n}, {dof}, 1., {ref}, {dof}, -1."]

    out += ["*SURFACE INTERACTION, NAME=CONTACT"]
    if penalty is None:
        out += ["*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD"]
    else:
        out += ["*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
                f"{_num(penalty)}, {_num(tension)}"]
    if friction is not None:
        if stick_slope is None:
            stick_slope = penalty if penalty is not None else 1e11
        out += ["*FRICTION", f"{_num(friction)}, {_num(stick_slope)}"]
    deck_pairs = [(sides[id(a)][0], sides[id(b)][0]) for a, b in contact_pairs]
    for a, b in deck_pairs:
        out += ["*CONTACT PAIR, INTERACTION=CONTACT, TYPE=SURFACE TO SURFACE", f"{a}, {b}"]
    prints = [line for a, b in deck_pairs
              for line in (f"*CONTACT PRINT, SLAVE={a}, MASTER={b}", "CF")]

    factors = [float(f) for f in model.load_factors]
    stretches = _stretches(model) if curves else []
    if ref is not None:
        if approach is None:
            gap = _initial_gap(surfaces[i_slave], surfaces[1 - i_slave])
            approach = max(gap, 0.0) + 1e-6 * size
        towards = float(np.sign(pl.force)) or 1.0
        out += ["** step 1: the platen pushed under displacement control until contact holds "
                "the body", f"*STEP, {'NLGEOM, ' if large else ''}INC=100", "*STATIC",
                "1., 1., 1e-5, 1.", "*BOUNDARY",
                f"{ref}, {dof}, {dof}, {_num(towards * approach)}",
                *(prescribed(0.0) if curves else []), "*END STEP"]
    rising = all(np.diff(np.r_[0.0, factors]) > 0)
    if curves:
        plan = [(stretch[0], stretch[-1]) for stretch in stretches]
    elif steps == "one" and rising:
        plan = [(factors[0], factors[-1])]
    else:
        plan = [(f, f) for f in factors]
    reaction_sets = {}
    if curves or large:
        for b in model.bodies:
            for x in (*b.supports, *b.prescribed):
                reaction_sets[f"B_{tags[b.name]}_{_tag(x.boundary)}"] = (b.name, x.boundary)

    def output(k: int) -> list[str]:
        if not curves:  # (a large body's forces: its held boundaries' reactions, not K u)
            return [f"*NODE PRINT, NSET=N_{tags[slave]}", "U",
                    f"*NODE PRINT, NSET=N_{tags[master]}", "U",
                    *(line for name in reaction_sets
                      for line in (f"*NODE PRINT, NSET={name}, TOTALS=ONLY", "RF")),
                    *prints, "*CONTACT FILE", "CSTR"]
        # every increment (ccx's default frequency): *TIME POINTS would pin the increments to
        # the load factors, but ccx 2.20 then stalls on an increment of length 0 after landing
        # on one (measured on the Cattaneo example); the increments are the model's steps
        # unless ccx cuts one back, and the readers match increments to load factors by time
        return [f"*NODE PRINT, NSET=N_{tags[slave]}", "U",
                f"*NODE PRINT, NSET=N_{tags[master]}", "U",
                *(line for name in reaction_sets
                  for line in (f"*NODE PRINT, NSET={name}, TOTALS=ONLY", "RF")),
                *prints, "*CONTACT FILE", "CSTR, CDIS"]

    previous = 0.0
    for k, (first, factor) in enumerate(plan):
        span = abs(factor - previous)
        initial, largest = min(abs(first - previous), span), span
        if first_increment is not None:
            initial = min(initial, first_increment * span)
        if curves:  # increments no longer than the model's steps (rounded: 0.05, not 0.05 +
            # 4e-17): ccx lands on each of them
            largest = round(float(np.abs(np.diff([previous, *stretches[k]])).max()), 12)
            initial, span = round(initial, 12), round(span, 12)
        out += [f"*STEP, {'NLGEOM, ' if large else ''}INC={max_increments}", "*STATIC",
                f"{_num(initial)}, {_num(span)}, {_num(1e-5 * span)}, {_num(largest)}"]
        if ref is not None:
            # OP=NEW releases the platen's reference node: force control from here on
            out += ["*BOUNDARY, OP=NEW", *supports, *prescribed(factor),
                    "*CLOAD", f"{ref}, {dof}, {_num(pl.force_at(factor))}"]
        elif prescribed(factor):
            out += ["*BOUNDARY", *prescribed(factor)]
        out += [*output(k), "*END STEP"]
        previous = factor
    path = Path(path)
    path.write_text("\n".join(out) + "\n", encoding="ascii")
    return Deck(path, model, decks, slave, master, ref, penalty, tension, approach,
                [f for _, f in plan], friction, stick_slope if friction is not None else None,
                [list(s) for s in stretches], reaction_sets, 180.0 if axisymmetric else 1.0,
                deck_pairs)


def _stretches(model) -> list[list[float]]:
    """The model's load factors in stretches over which every prescribed displacement and
    platen force changes linearly with the load factor and the load factor runs one way: a new
    stretch where a load's rate changes (a load curve's corner at a load factor) or the load
    factor turns back. vfem applies the loads at the load factors only, so between two of them
    they change linearly, as in a ccx step."""
    factors = np.r_[0.0, np.asarray(model.load_factors, dtype=float)]
    loads = [pd.at for b in model.bodies for pd in b.prescribed]
    loads += [b.platen.force_at for b in model.bodies if b.platen is not None]
    values = np.array([[load(f) for load in loads] for f in factors]).reshape(len(factors), -1)
    scale = np.abs(values).max(axis=0) + 1e-300
    out: list[list[float]] = [[]]
    for k in range(1, len(factors)):
        out[-1].append(float(factors[k]))
        if k + 1 == len(factors):
            break
        d0, d1 = factors[k] - factors[k - 1], factors[k + 1] - factors[k]
        straight = d0 * d1 > 0 and np.all(np.abs(
            values[k] + (values[k] - values[k - 1]) * (d1 / d0) - values[k + 1])
            <= 1e-9 * scale)
        if not straight:
            out.append([])
    return out


# -- running and reading -------------------------------------------------------------------------


_FLOAT = r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?"


def _dat_blocks(text: str, title: str) -> list[np.ndarray]:
    """Every table of the ``.dat`` file whose heading starts with ``title``: rows of numbers."""
    return [rows for _, rows in _dat_timed_blocks(text, title)]


def _dat_timed_blocks(text: str, title: str) -> list[tuple[float, np.ndarray]]:
    """Every table of the ``.dat`` file whose heading starts with ``title``, with the total time
    its heading ends with (``... and time  0.1100000E+01``; nan if none)."""
    blocks = []
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.strip().startswith(title):
            rows = []
            j = i + 1
            while j < len(lines) and not lines[j].strip():
                j += 1
            while j < len(lines) and lines[j].strip():
                rows.append([float(v) for v in lines[j].split()])
                j += 1
            blocks.append((_heading_time(line), np.array(rows)))
    return blocks


def _heading_time(line: str) -> float:
    m = re.search(r"and time\s+(" + _FLOAT + ")", line)
    return float(m.group(1)) if m else float("nan")


def _contact_statistics(text: str) -> dict:
    """The last "statistics for slave set" block of the ``.dat`` file (``*CONTACT PRINT, CF``)."""
    start = text.rfind("statistics for slave set")
    if start < 0:
        return {}
    return _statistics_block(text[start:].splitlines())


def _contact_statistics_by_time(text: str) -> list[tuple[float, dict]]:
    """Every "statistics for slave set" block of the ``.dat`` file, with its total time; each
    block's ``pair`` is its (slave surface, master surface)."""
    pieces = text.split(" statistics for slave set")[1:]
    out = []
    for p in pieces:
        head = p.splitlines()[0]
        stats = _statistics_block(p.splitlines())
        names = re.match(r"\s*(\S+?),\s*master set\s+(\S+)", head)
        if names:
            stats["pair"] = (names.group(1), names.group(2))
        out.append((_heading_time(head), stats))
    return out


def _statistics_block(body: list[str]) -> dict:
    """Total force, contact area, normal and shear force of a statistics block's lines."""
    out = {}
    for i, line in enumerate(body):
        nums = None
        for j in range(i + 1, min(i + 4, len(body))):
            if body[j].strip():
                # (a pair without contact prints NaN for its normal and shear force)
                nums = [float(v) for v in re.findall(_FLOAT + r"|[-+]?nan", body[j], re.I)]
                break
        if line.strip().startswith("total surface force"):
            out["force"] = nums[:3]
        elif line.strip().startswith("area,  normal force"):
            out["area"], out["normal_force"], out["shear_force"] = nums[:3]
            break
    return out


def _frd_contact_pressure(path: Path) -> dict[int, float]:
    """CPRESS per node of the last CONTACT block of the ``.frd`` file (``*CONTACT FILE, CSTR``)."""
    blocks = _frd_contact(path)
    return {n: float(v[3]) for n, v in blocks[-1][1].items()} if blocks else {}


def _frd_contact(path: Path) -> list[tuple[float, dict[int, np.ndarray]]]:
    """Every CONTACT block of the ``.frd`` file (``*CONTACT FILE, CSTR`` and/or ``CDIS``): its
    total time and, per node with a value that is not zero, (COPEN, CSLIP1, CSLIP2, CPRESS,
    CSHEAR1, CSHEAR2).

    Fixed columns: ``-1``, the node in 10 characters, then 12 characters per value (6 significant
    digits: ratios of two values, such as shear over pressure, are known to about 1e-5). The
    time is the third field of the ``100CL`` line that heads the block."""
    blocks = []
    lines = path.read_text(errors="replace").splitlines()
    for i, line in enumerate(lines):
        if not line.startswith(" -4  CONTACT"):
            continue
        head = next((lines[k] for k in range(i - 1, -1, -1)
                     if lines[k].lstrip().startswith("100C")), "")
        fields = head.split()
        time = float(fields[2]) if len(fields) > 2 else float("nan")
        values: dict[int, np.ndarray] = {}
        for row in lines[i + 1:]:
            if row.startswith(" -3"):
                break
            if row.startswith(" -1"):
                v = np.zeros(6)
                for k in range(min(6, (len(row.rstrip()) - 13) // 12)):
                    v[k] = float(row[13 + 12 * k: 25 + 12 * k])
                if v.any():
                    values[int(row[3:13])] = v
        blocks.append((time, values))
    return blocks


def _sta(text: str) -> list[dict]:
    """The increments of the ``.sta`` file: step, increment, attempts, iterations."""
    rows = []
    for line in text.splitlines():
        parts = line.split()
        if len(parts) >= 7 and parts[0].isdigit() and parts[1].isdigit():
            rows.append({"step": int(parts[0]), "increment": int(parts[1]),
                         "attempts": int(parts[2].rstrip("U")), "iterations": int(parts[3])})
    return rows


def _stiffness(body):
    """The body's stiffness on its points (dof d k: x of point k, d the dimension), the
    elements ccx's are."""
    lam, mu = body.material.lame()
    if body.mesh.p.shape[0] == 3:  # as Body.assemble does (scikit-fem's loop is slow in 3D)
        from vfem.bodies.assembly import elasticity_stiffness

        return elasticity_stiffness(body.mesh, body.element(), lam, mu)
    basis = Basis(body.mesh, ElementVector(body.element()))
    return asm(linear_elasticity(lam, mu), basis).tocsr()


def _constrained(body) -> np.ndarray:
    """Dofs held by supports, prescribed displacements and the platen (not contact's)."""
    dofs = []
    comps = [(s.boundary, c) for s in body.supports for c in body.support_components(s)]
    comps += [(pd.boundary, pd.component) for pd in body.prescribed]
    if body.platen is not None:
        comps.append((body.platen.boundary, body.platen.component))
    for boundary, c in comps:
        nodes = np.unique(body.mesh.facets[:, body.mesh.boundaries[boundary]])
        dofs.append(body.mesh.p.shape[0] * nodes + DOF[c] - 1)
    return np.unique(np.concatenate(dofs)) if dofs else np.zeros(0, dtype=int)


def _reads_k_u(body) -> bool:
    """Whether ``K u`` (:func:`nodal_reading`: the body's linear plane stiffness times ccx's
    displacements) is the body's nodal force: not for a large body (its law is not linear) nor
    for a body of revolution (its stiffness is not the plane one)."""
    return not body.large and body.section.space != "axisymmetric"


def _unread(body, facets: np.ndarray) -> dict:
    """:func:`nodal_reading`'s keys, not a number, for a body whose ``K u`` is no reading
    (:func:`_reads_k_u`)."""
    nodes = np.unique(body.mesh.facets[:, facets])
    d = body.mesh.p.shape[0]
    return {"nodes": nodes, "force": np.full((len(nodes), d), np.nan),
            "pressure": np.full(len(nodes), np.nan), "tributary": np.full(len(nodes), np.nan),
            "total_force": np.full(d, np.nan), "residual": float("nan")}


def nodal_reading(body, facets: np.ndarray, u: np.ndarray, stiffness=None) -> dict:
    """The body's nodal contact forces ``K u`` on the nodes of ``facets`` and the nominal pressure.

    ``u``: (npoints, 2) displacements (3D: (npoints, 3)). On a contact node the only forces
    besides contact are the reactions of its constrained components, which are left out; the
    pressure is the size of what remains over the node's undeformed tributary length (half of
    each facet it ends), as :func:`vfem_examples.hertz.evaluate` reads vfem's; in 3D over its
    undeformed tributary area (the integral of its shape function over the facets, as vfem's
    nominal pressure, :func:`vfem_examples.sphere.evaluate`). ``residual`` is the largest
    ``|K u|`` on a free dof off the contact surface (zero in exact arithmetic: the check that the
    elements and the displacements read back are ccx's), relative to the largest nodal contact
    force.
    ``stiffness``: the body's, if already assembled (:func:`_stiffness`).
    """
    K = _stiffness(body) if stiffness is None else stiffness
    d = body.mesh.p.shape[0]
    f = (K @ np.asarray(u, dtype=float).ravel()).reshape(-1, d)
    held = np.zeros(d * body.npoints, dtype=bool)
    held[_constrained(body)] = True
    held = held.reshape(-1, d)
    ends = body.mesh.facets[:, facets]
    nodes = np.unique(ends)
    if d == 3:
        basis = FacetBasis(body.mesh, body.element(), facets=np.asarray(facets))
        tributary = np.asarray(asm(LinearForm(lambda v, w: v), basis))[: body.npoints]
    else:
        lengths = np.linalg.norm(np.diff(body.mesh.p[:, ends], axis=1)[:, 0], axis=0)
        tributary = np.zeros(body.npoints)
        np.add.at(tributary, ends[0], 0.5 * lengths)
        np.add.at(tributary, ends[1], 0.5 * lengths)
    force = np.where(held[nodes], 0.0, f[nodes])
    pressure = np.linalg.norm(force, axis=1) / tributary[nodes]
    off = np.ones(body.npoints, dtype=bool)
    off[nodes] = False
    free_off = np.where(held[off], 0.0, f[off])
    scale = float(np.abs(force).max()) or 1.0
    return {"nodes": nodes, "force": force, "pressure": pressure,
            "tributary": tributary[nodes], "total_force": force.sum(axis=0),
            "residual": float(np.abs(free_off).max(initial=0.0)) / scale}


def _load_factor(deck: Deck, total: float) -> float:
    """The model's load factor at ccx's total time ``total``: a step's time is the change of the
    load factor over it, after the platen's approach step (time 1) if there is one."""
    start = 1.0 if deck.reference_node is not None else 0.0
    ends = np.asarray(deck.steps, dtype=float)
    times = start + np.cumsum(np.abs(np.diff(np.r_[0.0, ends])))
    return float(np.interp(total, np.r_[start, times], np.r_[0.0, ends]))


def _at(blocks: list[tuple[float, np.ndarray]], total: float) -> np.ndarray | None:
    """The block of ``blocks`` (``(time, rows)``, :func:`_dat_timed_blocks`) written at
    total time ``total`` (the .dat file prints times to 7 digits, the .frd file to 10)."""
    return next((rows for t, rows in blocks if abs(t - total) <= 1e-6 * max(1.0, abs(total))),
                None)


def _history(deck: Deck, dat: str, contact: list) -> list[dict]:
    """Per increment with contact output (each CONTACT block of the .frd file), on the slave
    body's contact candidate nodes (sorted by x): ``time`` (ccx's total time),
    ``load_factor``, ``nodes`` (the body's point numbers), ``x`` (their undeformed
    coordinates), ccx's nodal ``cpress``, ``cshear``
    (CSHEAR1, CSHEAR2: along the master surface's tangent nearest to global x, and along z),
    ``copen`` and ``cslip`` (CSLIP1, CSLIP2; the total relative tangential displacement,
    written with friction only), ``u`` (the slave's displacements, (npoints, dim)) and, where
    ``K u`` reads the slave's forces (:func:`_reads_k_u`: small kinematics, plane or 3D),
    ``force_nodal`` (the contact forces ``K u`` of :func:`nodal_reading`) and ``tributary``
    (each node's undeformed tributary length), where the .dat file has the slave's
    displacements at that time; ``platen_displacement`` (the platen's reference node's,
    along its component), ``reactions`` (set -> the total (fx, fy) of ``*NODE PRINT,
    TOTALS=ONLY``, ``steps="curves"`` or a large body) and ``contact_force`` (ccx's total
    surface force (fx, fy) on the slave), ``contact_normal_force`` and
    ``contact_shear_force`` (its size) from ``*CONTACT PRINT, CF`` (of the deck's first
    contact pair, the two bodies'), ``pair_forces`` (every pair's, (slave surface, master
    surface) -> its total surface force on the slave; a self-contact pair's too); the forces
    of an axisymmetric model per full circle (``Deck.force_scale``)."""
    body = next(b for b in deck.model.bodies if b.name == deck.slave)
    bd = deck.body(deck.slave)
    nodes = np.unique(body.mesh.facets[:, bd.contact_facets])
    nodes = nodes[np.argsort(body.mesh.p[0, nodes], kind="stable")]
    ids = nodes + bd.node_offset + 1
    reactions = {name: _dat_timed_blocks(dat, f"total force (fx,fy,fz) for set {name}")
                 for name in deck.reaction_sets}
    statistics = _contact_statistics_by_time(dat)
    displacements = _dat_timed_blocks(dat, f"displacements (vx,vy,vz) for set "
                                           f"N_{_tag(deck.slave)}")
    # the platen's reference node (the body that carries it: the slave's or the master's set)
    platen_blocks = []
    if deck.reference_node is not None:
        carrier = next(b.name for b in deck.model.bodies if b.platen is not None)
        platen_blocks = _dat_timed_blocks(dat, f"displacements (vx,vy,vz) for set "
                                               f"N_{_tag(carrier)}")
        component = DOF[next(b for b in deck.model.bodies if b.platen is not None)
                        .platen.component] - 1
    stiffness = _stiffness(body) if displacements and _reads_k_u(body) else None
    scale = deck.force_scale
    out = []
    for total, values in contact:
        v = np.array([values.get(int(i), np.zeros(6)) for i in ids]).reshape(-1, 6)
        row = {"time": total, "load_factor": _load_factor(deck, total), "nodes": nodes,
               "x": body.mesh.p[:, nodes].T.copy(), "copen": v[:, 0], "cslip": v[:, 1:3],
               "cpress": v[:, 3], "cshear": v[:, 4:6]}
        rows = _at(displacements, total)
        if rows is not None:
            d = body.mesh.p.shape[0]
            u = np.zeros((body.npoints, d))
            u[rows[:, 0].astype(int) - bd.node_offset - 1] = rows[:, 1:1 + d]
            row["u"] = u
            if stiffness is not None:
                reading = nodal_reading(body, bd.contact_facets, u, stiffness)
                where = {int(n): k for k, n in enumerate(reading["nodes"])}
                order = [where[int(n)] for n in nodes]
                row["force_nodal"] = reading["force"][order]
                row["tributary"] = reading["tributary"][order]
        rows = _at(platen_blocks, total)
        if rows is not None:
            hit = rows[rows[:, 0].astype(int) == deck.reference_node]
            if len(hit):
                row["platen_displacement"] = float(hit[0, 1 + component])
        row["reactions"] = {}
        for name, blocks in reactions.items():
            r = _at(blocks, total)
            if r is not None:
                row["reactions"][name] = scale * r[0, :body.mesh.p.shape[0]]
        now = [st for t, st in statistics if abs(t - total) <= 1e-6 * max(1.0, abs(total))]
        stats = now[0] if now else {}  # the first pair's: the two bodies'
        row["pair_forces"] = {st["pair"]: scale * np.asarray(st["force"][:body.mesh.p.shape[0]])
                              for st in now if "pair" in st and "force" in st}
        if stats:
            row["contact_force"] = scale * np.asarray(
                stats.get("force", [np.nan] * 3)[:body.mesh.p.shape[0]])
            row["contact_normal_force"] = scale * abs(stats.get("normal_force", np.nan))
            row["contact_shear_force"] = scale * stats.get("shear_force", np.nan)
        out.append(row)
    return out


def sticking(row: dict, friction: float, tolerance: float = 1e-4) -> np.ndarray:
    """Which slave nodes of a ``history`` row (:func:`run`) stick: in contact (CPRESS > 0) with
    a shear below the Coulomb bound, ``|(CSHEAR1, CSHEAR2)| < mu CPRESS (1 - tolerance)``.

    ccx writes no stick/slip status; at a slipping node its extrapolated shear is mu times its
    pressure to the 6 digits the .frd file keeps (hence the default tolerance 1e-4, not 1e-6;
    next to the stick zone's edge, where its integration points differ, it can exceed the
    bound by a few % and counts as slipping)."""
    shear = np.linalg.norm(row["cshear"], axis=1)
    return (row["cpress"] > 0) & (shear < friction * row["cpress"] * (1 - tolerance))


def _solver(log: str) -> str:
    """The equation solver ccx names last (with friction its matrix is unsymmetric: the first,
    contact-free iteration still factors a symmetric one)."""
    found = re.findall(r"Factoring the system of equations using the (.+?) solver", log)
    return found[-1].strip() if found else "unknown"


def run_with_penalty_check(config, path: Path, penalty: float, *, check: bool = True,
                           keep=None, ccx: str = "ccx", timeout: float = 600.0, **deck_options):
    """Write ``config``'s model as a deck at ``path`` (:func:`write_deck`, ``steps="model"``,
    ``penalty`` and ``deck_options``) and run it (:func:`run`); with ``check``, write and run it
    again at a tenth of the penalty, the comparisons' check that the penalty does not decide the
    answer. Returns (deck, results, results at a tenth of the penalty or None)."""
    deck = write_deck(config.build(), path, steps="model", penalty=penalty, **deck_options)
    results = run(deck, ccx=ccx, timeout=timeout, keep=keep)
    other = None
    if check:
        tenth = write_deck(config.build(), path.with_name(f"{path.stem}_tenth{path.suffix}"),
                           steps="model", penalty=penalty / 10.0, **deck_options)
        other = run(tenth, ccx=ccx, timeout=timeout)
    return deck, results, other


def run(deck: Deck, ccx: str = "ccx", threads: int = 1, timeout: float = 600.0,
        p0: float | None = None, keep: str | Path | None = None) -> dict:
    """Run CalculiX on ``deck`` in a temporary folder and read its results.

    Args:
        deck: what :func:`write_deck` returned.
        ccx: the CalculiX executable.
        threads: ``OMP_NUM_THREADS`` and ccx's ``CCX_NPROC_*`` (stiffness, equation solver,
            results).
        timeout: seconds before ccx is stopped (a :class:`~vfem.errors.VfemError`).
        p0: a reference peak pressure (Hertz's p0): adds ``p_max_error_raw`` and
            ``p_max_error_nodal``.
        keep: a folder to copy ccx's files to (deck, log, .dat, .frd, .sta).

    Returns a dict: ``wall_s`` (the ccx process), ``ccx_total_s`` (ccx's own total),
    ``threads``, ``solver``, ``equations``, ``increments``/``iterations``/``cutbacks`` (the load
    steps; ``contact_step_iterations`` for the first, contact-making step), ``p_max_raw`` (ccx's
    CPRESS on the slave nodes), ``p_max_nodal`` (``K u`` per undeformed tributary length,
    :func:`nodal_reading`), ``p_max_master_nodal`` (the same reading on the master body),
    ``total_contact_force`` (ccx's, on the slave), ``total_contact_force_nodal``,
    ``nodal_residual``, ccx's own ``final_residual_force`` against its ``final_average_force``
    (its last iteration), per-node arrays under ``slave``, ``step_iterations`` (ccx step ->
    its iterations, the .sta file's) and ``history``, what ccx wrote at each increment
    (:func:`_history`: the contact stresses and slips, reactions, contact forces).
    """
    exe = shutil.which(ccx)
    if exe is None:
        raise VfemError(f"CalculiX executable {ccx!r} not found on the PATH; install it (Debian: "
                        "apt install calculix-ccx) or pass its path")
    model = deck.model
    env = dict(os.environ)
    for key in ("OMP_NUM_THREADS", "CCX_NPROC_STIFFNESS", "CCX_NPROC_EQUATION_SOLVER",
                "CCX_NPROC_RESULTS"):
        env[key] = str(int(threads))
    with tempfile.TemporaryDirectory(prefix="vfem-ccx-") as tmp:
        work = Path(tmp)
        shutil.copyfile(deck.path, work / "job.inp")
        t0 = time.perf_counter()
        try:
            proc = subprocess.run([exe, "-i", "job"], cwd=work, env=env, capture_output=True,
                                  text=True, timeout=timeout)
        except subprocess.TimeoutExpired as exc:
            raise VfemError(f"CalculiX did not finish within {timeout:g} s on {deck.path}") \
                from exc
        wall = time.perf_counter() - t0
        log = (proc.stdout or "") + (proc.stderr or "")
        if keep is not None:
            keep = Path(keep)
            keep.mkdir(parents=True, exist_ok=True)
            (keep / "ccx.log").write_text(log)
            for f in work.iterdir():
                if f.suffix in (".inp", ".dat", ".frd", ".sta", ".cvg"):
                    shutil.copyfile(f, keep / f.name)
        if proc.returncode != 0 or "*ERROR" in log or "Job finished" not in log:
            tail = "\n".join(line for line in log.splitlines() if line.strip())[-2000:]
            raise VfemError(f"CalculiX failed on {deck.path} (exit status {proc.returncode}); "
                            f"the end of its output:\n{tail}")
        dat = (work / "job.dat").read_text(errors="replace")
        sta = _sta((work / "job.sta").read_text(errors="replace"))
        contact = _frd_contact(work / "job.frd")
    cpress = {n: float(v[3]) for n, v in contact[-1][1].items()} if contact else {}

    total = re.search(r"Total CalculiX Time:\s*(" + _FLOAT + ")", log)
    residual = re.findall(r"largest residual force=\s*(" + _FLOAT + ")", log)
    average = re.findall(r"average force=\s*(" + _FLOAT + ")", log)
    eqs = re.findall(r"number of equations\s*\n\s*(\d+)", log)
    load_steps = [r for r in sta if r["step"] > (1 if deck.reference_node else 0)]
    first = [r for r in sta if deck.reference_node and r["step"] == 1]
    readings = {}
    for name in (deck.slave, deck.master):
        body = next(b for b in model.bodies if b.name == name)
        bd = deck.body(name)
        blocks = _dat_blocks(dat, f"displacements (vx,vy,vz) for set N_{name.upper()}")
        if not blocks:
            raise VfemError(f"CalculiX results: no displacements of body {name!r} in the .dat "
                            "file")
        rows = blocks[-1]
        d = body.mesh.p.shape[0]
        u = np.zeros((body.npoints, d))
        u[rows[:, 0].astype(int) - bd.node_offset - 1] = rows[:, 1:1 + d]
        readings[name] = (nodal_reading(body, bd.contact_facets, u) if _reads_k_u(body)
                          else _unread(body, bd.contact_facets))
    s = readings[deck.slave]
    bd = deck.body(deck.slave)
    raw = np.array([cpress.get(int(n) + bd.node_offset + 1, 0.0) for n in s["nodes"]])
    stats = _contact_statistics(dat)
    body = next(b for b in model.bodies if b.name == deck.slave)
    out = {
        "wall_s": wall,
        "ccx_total_s": float(total.group(1)) if total else float("nan"),
        "threads": int(threads),
        "cpus_reported": sorted({int(n) for n in re.findall(r"Using up to (\d+) cpu", log)}),
        "solver": _solver(log),
        "equations": int(eqs[-1]) if eqs else 0,
        "dofs": int(sum(b.mesh.p.shape[0] * b.mesh.p.shape[1] for b in model.bodies)),
        "increments": len(load_steps),
        "iterations": int(sum(r["iterations"] for r in load_steps)),
        "cutbacks": int(sum(r["attempts"] - 1 for r in load_steps)),
        "contact_step_iterations": int(sum(r["iterations"] for r in first)),
        "step_iterations": {k: int(sum(r["iterations"] for r in sta if r["step"] == k))
                            for k in sorted({r["step"] for r in sta})},
        "final_residual_force": float(residual[-1]) if residual else float("nan"),
        "final_average_force": float(average[-1]) if average else float("nan"),
        "penalty": deck.penalty,
        "p_max_raw": float(raw.max()),
        "p_max_nodal": float(s["pressure"].max()),
        "p_max_master_nodal": float(readings[deck.master]["pressure"].max()),
        "total_contact_force": [deck.force_scale * v for v in
                                stats.get("force", [float("nan")] * 3)[:body.mesh.p.shape[0]]],
        "contact_normal_force": deck.force_scale * abs(stats.get("normal_force", float("nan"))),
        "total_contact_force_nodal": [float(v) for v in s["total_force"]],
        "nodal_residual": s["residual"],
        "slave": {"x": body.mesh.p[:, s["nodes"]].T, "pressure_raw": raw,
                  "pressure_nodal": s["pressure"], "force": s["force"]},
        "history": _history(deck, dat, contact),
    }
    if p0:
        out["p0"] = p0
        out["p_max_error_raw"] = out["p_max_raw"] / p0 - 1.0
        out["p_max_error_nodal"] = out["p_max_nodal"] / p0 - 1.0
        out["p_max_master_error_nodal"] = out["p_max_master_nodal"] / p0 - 1.0
    return out
