"""A body's supports and loads, and what they make of its dofs.

The boundary conditions a body takes (:class:`Support`, :class:`PrescribedDisplacement`,
:class:`Traction`, a force-controlled :class:`Platen`), load curves (an ``amplitude``,
:func:`multiplier`), and the functions that turn them into the body's constrained dofs
(:func:`constraints`), its load vectors grouped by curve (:func:`load_cases`, one solve each) and
their superposition at a load factor (:func:`superpose`): loads that follow a curve are not
proportional to the load factor, so the loads are grouped by curve into :class:`LoadCase` s and
the response is ``sum_k m_k(load_factor) u_k`` (the loads without a curve share the proportional
case, ``m = load_factor``). Frictionless small-strain contact is path independent, so this
superposition stays exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import ElementVector, FacetBasis, LinearForm, asm

from ..errors import InputError
from ..mesh.topology import centred
from .discretisation import COMPONENTS


class AllComponents(tuple):
    """The default of :attr:`Support.components`: every displacement component of the body it
    holds (x and y in 2D, x, y and z in 3D). It is the tuple ``("x", "y")`` itself, so that
    whatever reads a support's components without knowing the body's dimension reads the 2D
    default as before; :meth:`Body.support_components` gives the body's own."""

    __slots__ = ()


#: Every component of the body (:class:`AllComponents`).
ALL_COMPONENTS = AllComponents(("x", "y"))

#: A load curve: ``((load_factor, multiplier), ...)`` points, load factors strictly increasing.
Amplitude = tuple[tuple[float, float], ...]


def check_amplitude(amplitude, where: str) -> None:
    """Raise :class:`InputError` (``where`` names the body, the load and its boundary) unless
    ``amplitude`` is a load curve: [load factor, multiplier] pairs, finite numbers, load factors
    strictly increasing. The one check of every load's ``amplitude`` (:meth:`Body.validate`)."""
    try:
        pts = np.asarray(amplitude, dtype=float)
    except (TypeError, ValueError):
        pts = None
    if pts is None or pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 1:
        raise InputError(f"{where}: the amplitude must be [load factor, multiplier] pairs, "
                         f"e.g. [[0.0, 0.0], [1.0, 1.0]]; got {_shown(amplitude)}")
    if not np.all(np.isfinite(pts)):
        raise InputError(f"{where}: the amplitude must hold finite numbers, got "
                         f"{_shown(amplitude)}")
    bad = np.flatnonzero(np.diff(pts[:, 0]) <= 0)
    if len(bad):
        k = int(bad[0])
        raise InputError(f"{where}: the amplitude must have strictly increasing load factors; "
                         f"{pts[k, 0]:g} is followed by {pts[k + 1, 0]:g}")


def _shown(value) -> str:
    """A value as the input file writes it (tuples as TOML arrays: ``[]``, not ``()``)."""
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    return repr(value)


def multiplier(amplitude: Amplitude | None, load_factor: float) -> float:
    """What a load's value is multiplied by at ``load_factor``: the load factor itself without an
    ``amplitude`` (proportional loading), else the curve interpolated linearly (constant beyond
    its ends). The one interpolation of every load curve."""
    if amplitude is None:
        return load_factor
    lf, mult = np.asarray(amplitude, dtype=float).T
    return float(np.interp(load_factor, lf, mult))


def curve_key(amplitude) -> Amplitude | None:
    """``amplitude`` as a hashable tuple of float pairs (None stays None): loads with equal
    curves share one :class:`LoadCase`."""
    if amplitude is None:
        return None
    return tuple((float(t), float(m)) for t, m in amplitude)


def superpose(load_factor: float, terms):
    """``sum m(load_factor) * value`` over ``terms``, pairs (amplitude, value) with a value an
    array or a number (:func:`multiplier`). With the one proportional term of a body without
    load curves it is ``load_factor * value`` exactly, as before load curves existed."""
    out = None
    for amplitude, value in terms:
        term = multiplier(amplitude, load_factor) * value
        out = term if out is None else out + term
    return out


@dataclass
class LoadCase:
    """The loads of a small-kinematics body that follow one load curve.

    Attributes:
        amplitude: the curve (:func:`curve_key`), None for the loads proportional to the load
            factor.
        force: (ndofs) the nodal load vector of its tractions at multiplier 1.
        prescribed: (ndofs) its prescribed displacements' values at multiplier 1 on their dofs,
            zero on every other dof.
        displacement: (ndofs) the body's response to them, supports kept (after
            :meth:`Body.setup`).
        platen_reaction: the platen's reaction to them (after :meth:`Body.setup`).
    """

    amplitude: Amplitude | None
    force: np.ndarray
    prescribed: np.ndarray
    displacement: np.ndarray | None = None
    platen_reaction: float = 0.0


@dataclass(frozen=True)
class Support:
    """Fixed displacement components on a named boundary.

    Attributes:
        boundary: the boundary's name.
        components: the fixed components, ``"x"``, ``"y"`` (and ``"z"`` in 3D); by default
            all of the body's.
    """

    boundary: str
    components: tuple[str, ...] = ALL_COMPONENTS


@dataclass(frozen=True)
class PrescribedDisplacement:
    """A displacement component prescribed on a named boundary.

    Attributes:
        boundary: the boundary's name.
        component: ``"x"``, ``"y"`` or (3D) ``"z"``.
        value: the displacement at load factor 1.
        amplitude: a load curve, ``[[load_factor, multiplier], ...]`` points (load factors
            strictly increasing): the displacement is ``value`` times the multiplier
            interpolated linearly at the load factor (constant beyond the ends), instead of
            ``value`` times the load factor. For loads that are not proportional, e.g. press
            then slide, or load, hold and unload; small or large kinematics.
    """

    boundary: str
    component: str
    value: float
    amplitude: tuple[tuple[float, float], ...] | None = None

    def at(self, load_factor: float) -> float:
        """The prescribed displacement at ``load_factor``."""
        return self.value * multiplier(self.amplitude, load_factor)


@dataclass(frozen=True)
class Traction:
    """A distributed load on a named boundary: a traction vector, or a pressure along the
    boundary's normal.

    Attributes:
        boundary: the boundary's name.
        value: the traction (tx, ty), force per unit undeformed length, at load factor 1;
            (tx, ty, tz), force per unit undeformed area, on a 3D body. Give it or
            ``pressure``.
        amplitude: a load curve, ``[[load_factor, multiplier], ...]`` points (load factors
            strictly increasing): the traction is ``value`` times the multiplier interpolated
            linearly at the load factor (constant beyond the ends), instead of ``value`` times
            the load factor.
        pressure: in place of ``value``, a pressure p at load factor 1 (force per unit
            undeformed length or area), pushing into the body (negative: pulling) along each
            facet's undeformed outward normal n: the traction -p n (a bore's internal pressure,
            a seal's fluid). Under large kinematics it stays a dead load on the undeformed
            normals.
    """

    boundary: str
    value: tuple[float, ...] = ()
    amplitude: tuple[tuple[float, float], ...] | None = None
    pressure: float | None = None


@dataclass(frozen=True)
class Platen:
    """A rigid, force-controlled platen on a named boundary.

    Every node of the boundary moves by the same (unknown) displacement along ``component``; the
    solver finds it so that the platen's reaction equals ``force`` times the load factor (or
    times its load curve's multiplier). This is how a body held only by the load (the Hertz
    cylinder) is loaded without a singular stiffness. ``force`` is the total force on the platen
    along ``component`` (negative: towards -x or -y).

    Attributes:
        boundary: the boundary the platen holds.
        component: the direction it moves in, ``"x"``, ``"y"`` or (3D) ``"z"``.
        force: its total force at load factor 1 (negative: towards -x or -y).
        amplitude: a load curve, ``[[load_factor, multiplier], ...]`` points (load factors
            strictly increasing): the force is ``force`` times the multiplier interpolated
            linearly at the load factor (constant beyond the ends), instead of ``force`` times
            the load factor.
    """

    boundary: str
    component: str
    force: float
    amplitude: tuple[tuple[float, float], ...] | None = None

    def force_at(self, load_factor: float) -> float:
        """The force the platen must apply at ``load_factor``."""
        return self.force * multiplier(self.amplitude, load_factor)


def constraints(body) -> dict[int, float]:
    """The constrained dofs: sets ``platen_dofs`` and ``fixed_dofs``, returns the
    prescribed value at load factor 1 of every supported or prescribed dof."""
    fixed: dict[int, float] = {}  # dof -> prescribed value at factor 1
    for s in body.supports:
        for c in body.support_components(s):
            fixed.update(dict.fromkeys(boundary_dofs(body, s.boundary, c).tolist(), 0.0))
    for pd in body.prescribed:
        fixed.update(dict.fromkeys(boundary_dofs(body, pd.boundary, pd.component).tolist(),
                                   float(pd.value)))
    body.platen_dofs = np.array([], dtype=int)
    if body.platen is not None:
        body.platen_dofs = boundary_dofs(body, body.platen.boundary, body.platen.component)
    body.fixed_dofs = np.array(sorted(set(fixed) | set(body.platen_dofs.tolist())),
                               dtype=int)
    return fixed


def load_cases(body, fixed: dict[int, float]) -> list[LoadCase]:
    """The body's loads grouped by load curve: the proportional case (also holding the
    supports' zeros) first, then one per distinct ``amplitude`` of its tractions and
    prescribed displacements, in order of first mention. A dof that several conditions
    prescribe belongs to the last prescribed displacement on it, as in :func:`constraints`.
    ``fixed``: the prescribed value of every constrained dof (from :func:`constraints`)."""
    keys = [None]
    for load in (*body.tractions, *body.prescribed):
        key = curve_key(load.amplitude)
        if key not in keys:
            keys.append(key)
    cases = [LoadCase(k, np.zeros(body.ndofs), np.zeros(body.ndofs)) for k in keys]
    for tr in body.tractions:
        cases[keys.index(curve_key(tr.amplitude))].force += traction_vector(body, tr)
    owner = dict.fromkeys(fixed, 0)
    for pd in body.prescribed:  # later ones win, as in constraints
        owner.update(dict.fromkeys(boundary_dofs(body, pd.boundary, pd.component).tolist(),
                                   keys.index(curve_key(pd.amplitude))))
    for dof, value in fixed.items():
        cases[owner[dof]].prescribed[dof] = value
    return cases


def traction_vector(body, tr: Traction) -> np.ndarray:
    """The nodal forces (ndofs) of a uniform traction on a named boundary: ∫ t·v times the
    section's measure (:meth:`~vfem.bodies.section.Section.weight`) over its facets; of a
    pressure, t = -p n with n the facets' outward normal."""
    # (on the mesh moved to its centre, :func:`~vfem.mesh.topology.centred`: the measure
    # reads the points where they are; the normals do not move)
    moved, centre = centred(body.mesh)
    fb = FacetBasis(moved, ElementVector(body.element()),
                    facets=body.mesh.boundaries[tr.boundary])
    at = centre.reshape(-1, 1, 1)
    section = body.section  # the measure of the body's boundary (:mod:`.section`)
    if tr.pressure is not None:
        p = float(tr.pressure)

        @LinearForm
        def pressed(v, w):
            out = w.n[0] * v[0] + w.n[1] * v[1]
            for d in range(2, body.dim):  # 3D: + n_z v_z
                out = out + w.n[d] * v[d]
            return -p * out * section.weight(np.asarray(w.x) + at)

        return asm(pressed, fb)
    t = np.asarray(tr.value, dtype=float)

    @LinearForm
    def load(v, w):
        out = t[0] * v[0] + t[1] * v[1]
        for d in range(2, len(t)):  # 3D: + t[2] * v[2]
            out = out + t[d] * v[d]
        return out * section.weight(np.asarray(w.x) + at)

    return asm(load, fb)


def boundary_dofs(body, boundary: str, component: str) -> np.ndarray:
    """The dofs of ``component`` on the named boundary, numbered as the body's basis
    numbers them (scikit-fem's :class:`~skfem.assembly.Dofs` of the vector element: the
    numbering without a basis's values at every quadrature point, which ``vfem check`` of a
    170k-dof hexahedral body took 1.6 s and gigabytes of address space to build)."""
    facets = body.mesh.boundaries[boundary]
    return body.dof_map.get_facet_dofs(facets).all(f"u^{COMPONENTS[component] + 1}")


def symmetry_planes(body) -> list[tuple[np.ndarray, int]]:
    """The body's symmetry planes, as (boundary facets, axis) per roller ``Support`` (held
    along one axis only, :meth:`Body.support_components`) whose facets are all flat, normal to
    that axis and on one plane (x, y, or z in 3D). The model continues across them as
    their mirror image: no surface that contact sees (the invariants,
    :func:`vfem.contact.invariants.polygon.symmetry_facets`), no edge of a contact patch
    (:meth:`vfem.contact.geometry.surface.ContactSurface.patch_boundary`), a tangent plane for
    friction (:func:`vfem.contact.formulations.friction.plane_normals`)."""
    mesh = body.mesh
    out = []
    for sup in body.supports:
        components = body.support_components(sup)
        if len(components) != 1 or sup.boundary not in (mesh.boundaries or {}):
            continue
        facets = np.asarray(mesh.boundaries[sup.boundary])
        if not len(facets):
            continue
        axis = body.components.index(components[0])  # x 0, y 1, z 2
        ends = mesh.p[:, mesh.facets[:, facets]]  # (dim, nodes of a facet, nf)
        along = np.ptp(ends[axis], axis=0)  # 2D: |the two ends' difference|
        size = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=0)
        coord = ends[axis].ravel()
        if np.all(along <= 1e-9 * size) and np.ptp(coord) <= 1e-9 * max(size.max(), 1e-300):
            out.append((facets, axis))
    return out


def load_displacement(body, load_factor: float, dofs: np.ndarray | None = None
                  ) -> np.ndarray:
    """Small kinematics: the displacement (ndofs, or of ``dofs``) due to the loads and
    prescribed displacements at ``load_factor``, each case at its curve's multiplier
    (``load_factor * u_load`` without load curves); after :func:`~.condensation.setup`."""
    if dofs is None:
        return superpose(load_factor, ((c.amplitude, c.displacement)
                                       for c in body.load_cases))
    return superpose(load_factor, ((c.amplitude, c.displacement[dofs])
                                   for c in body.load_cases))


def platen_load_reaction_at(body, load_factor: float) -> float:
    """Small kinematics: the platen's reaction to the loads and prescribed displacements at
    ``load_factor`` (``load_factor * platen_load_reaction`` without load curves)."""
    return superpose(load_factor, ((c.amplitude, c.platen_reaction)
                                   for c in body.load_cases))


def prescribed_at(body, load_factor: float) -> np.ndarray:
    """(ndofs) the constrained dofs' prescribed values at ``load_factor`` (zero on supports,
    the platen's dofs and the free dofs; after :func:`~.condensation.assemble`)."""
    return superpose(load_factor, ((c.amplitude, c.prescribed) for c in body.load_cases))
