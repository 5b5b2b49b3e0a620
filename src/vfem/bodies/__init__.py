"""A deformable body: mesh, material, supports and loads, with its own stiffness and factorization.

Bodies never share a matrix. Contact reaches a body only as nodal forces on its contact surface,
so for a linear body the whole response the contact algorithm needs is

    u = load_factor * u_load + platen_displacement * u_platen + K^-1 f_contact

where ``u_load`` is the solution under the body's loads and prescribed displacements at load factor
1, ``u_platen`` the solution for a unit motion of its force-controlled platen (if any), and
``K^-1`` is applied with the body's own factorization, supports kept.

Loads that follow a load curve (an ``amplitude``, :func:`multiplier`) are not proportional to the
load factor: the loads are grouped by curve into :class:`LoadCase` s, one solve each, and the
first term becomes ``sum_k m_k(load_factor) u_k`` (:func:`superpose`; the loads without a curve
share the proportional case, ``m = load_factor``). Frictionless small-strain contact is path
independent, so this superposition stays exact.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from skfem import (
    Basis,
    ElementHex1,
    ElementHex2,
    ElementQuad1,
    ElementQuad2,
    ElementTetP1,
    ElementTetP2,
    ElementTriP1,
    ElementTriP2,
    ElementVector,
    FacetBasis,
    LinearForm,
    MeshHex,
    MeshQuad,
    MeshTet,
    MeshTri,
    asm,
)
from skfem.assembly import Dofs
from skfem.io.meshio import HEX_MAPPING
from skfem.mesh.mesh_2d_2 import Mesh2D2
from skfem.models.elasticity import linear_elasticity

from ..errors import InputError
from ..linalg import factorize
from ..materials import LinearElastic
from ..mesh.checks import check_mesh
from .assembly import cell_mapping, elasticity_stiffness
from .mechanics import (
    BodyMechanics,
    LargeMechanics,
    Linearization,
    LinearMechanics,
    _platen_stiffness,
)

log = logging.getLogger(__name__)

#: The displacement components by name; a body has the first ``dim`` of them (``Body.dim``).
COMPONENTS = {"x": 0, "y": 1, "z": 2}
AXES = tuple(COMPONENTS)

#: The meshes a body accepts (scikit-fem's classes by name): 2D triangles and quadrilaterals,
#: 3D tetrahedra and hexahedra, each with straight (1) or curved (2: quadratic geometry) sides.
MESHES = ("MeshTri1", "MeshQuad1", "MeshTri2", "MeshQuad2",
          "MeshTet1", "MeshHex1", "MeshTet2", "MeshHex2")
#: The meshes whose own nodes are the quadratic element's points (curved geometry).
_QUADRATIC_GEOMETRY = ("MeshTet2", "MeshHex2")

#: Node permutations that mirror a VTK cell (turn a negative volume positive): a tetrahedron's
#: nodes 1 and 2 swapped, a hexahedron's bottom and top faces swapped, with their edge and face
#: nodes.
_VTK_MIRROR = {
    "tetra": [0, 2, 1, 3],
    "tetra10": [0, 2, 1, 3, 6, 5, 4, 7, 9, 8],
    "hexahedron": [4, 5, 6, 7, 0, 1, 2, 3],
    "hexahedron27": [4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11, 16, 17, 18, 19,
                     20, 21, 22, 23, 25, 24, 26],
}


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
        component: ``"x"`` or ``"y"``.
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
    """A distributed load on a named boundary.

    Attributes:
        boundary: the boundary's name.
        value: the traction (tx, ty), force per unit undeformed length, at load factor 1;
            (tx, ty, tz), force per unit undeformed area, on a 3D body.
        amplitude: a load curve, ``[[load_factor, multiplier], ...]`` points (load factors
            strictly increasing): the traction is ``value`` times the multiplier interpolated
            linearly at the load factor (constant beyond the ends), instead of ``value`` times
            the load factor.
    """

    boundary: str
    value: tuple[float, ...]
    amplitude: tuple[tuple[float, float], ...] | None = None


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
        component: the direction it moves in, ``"x"`` or ``"y"``.
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


def _named_first(null: np.ndarray) -> np.ndarray:
    """The rows of ``null`` (an orthonormal basis of free rigid-body motions, as coefficients
    of the named modes) rewritten as the named modes that are free by themselves (unit rows),
    then an orthonormal basis of the rest: a roller-supported box is free to "translate in x"
    and "rotate about z", not in combinations of them."""
    n = null.shape[1]
    pure = [i for i in range(n) if np.linalg.norm(null[:, i]) > 1 - 1e-8]
    named = np.eye(n)[pure]
    if len(pure) == len(null):
        return named
    rest = null - (null @ named.T) @ named  # the part orthogonal to the named modes
    _, _, vt = np.linalg.svd(rest)
    return np.vstack([named, vt[: len(null) - len(pure)]])


@dataclass
class Body:
    """One deformable body of a contact model.

    Args:
        name: unique name, used in messages and output files.
        mesh: a scikit-fem ``MeshTri`` or ``MeshQuad`` with named boundaries; ``MeshTri2`` or
            ``MeshQuad2`` for curved (quadratic) facets, e.g. a cylinder's arc
            (:func:`vfem.mesh.quadratic.curved`). In 3D a ``MeshTet`` or ``MeshHex``
            (``MeshTet2``, ``MeshHex2`` curved), e.g. :func:`vfem.mesh.solids.box`: linear
            elasticity under small kinematics.
        material: its material.
        supports, prescribed, tractions: boundary conditions on named boundaries.
        platen: an optional force-controlled rigid platen.
        contact_boundaries: boundaries that may touch other bodies; default: every exterior facet
            on which no displacement is prescribed (symmetry planes and supports cannot touch).
        order: 1 for linear elements (3-node triangles, 4-node quadrilaterals; 4-node
            tetrahedra, 8-node hexahedra), 2 for quadratic ones (6-node triangles, 9-node
            quadrilaterals; 10-node tetrahedra, 27-node hexahedra) on the same mesh.
        kinematics: ``"small"`` (default: small displacements and strains, linear elasticity)
            or large displacements and strains, by the ``"total"`` or ``"updated"`` Lagrangian
            formulation (thesis Chapters 2-3; plane strain or 3D, linear elements).
        law: under large kinematics, the hyperelastic law whose small-strain constants are the
            material's: ``"saint-venant-kirchhoff"`` (default) or ``"neo-hookean"``.

    Points: the nodes of the elements. For linear elements they are the mesh vertices; quadratic
    elements add one point at the middle of each facet (numbered after the vertices, in facet
    order) and, for quadrilaterals, one at each element's centre. Point k carries dofs 2k (x) and
    2k + 1 (y), as scikit-fem numbers them. In 3D, quadratic elements add the middle of each
    edge (in ``mesh.edges`` order) and, for hexahedra, each facet's centre (``mesh.facets``
    order) and each element's; point k carries dofs 3k (x), 3k + 1 (y) and 3k + 2 (z).
    """

    name: str
    mesh: MeshTri | MeshQuad | MeshTet | MeshHex
    material: LinearElastic
    supports: tuple[Support, ...] = ()
    prescribed: tuple[PrescribedDisplacement, ...] = ()
    tractions: tuple[Traction, ...] = ()
    platen: Platen | None = None
    contact_boundaries: tuple[str, ...] | None = None
    order: int = 1
    kinematics: str = "small"
    law: str = "saint-venant-kirchhoff"

    @property
    def dim(self) -> int:
        """The body's dimension, 2 or 3: its mesh's number of coordinates."""
        return int(self.mesh.p.shape[0])

    @property
    def components(self) -> tuple[str, ...]:
        """The body's displacement components: ``("x", "y")``, or ``("x", "y", "z")`` in 3D."""
        return AXES[: self.dim]

    def symmetry_planes(self) -> list[tuple[np.ndarray, int]]:
        """The body's symmetry planes, as (boundary facets, axis) per roller ``Support`` (held
        along one axis only, :meth:`support_components`) whose facets are all flat, normal to
        that axis and on one plane (x, y, or z in 3D). The model continues across them as
        their mirror image: no surface that contact sees (the invariants,
        :func:`vfem.contact.invariants.polygon._symmetry_facets`), no edge of a contact patch
        (:meth:`vfem.contact.geometry.surface.ContactSurface.patch_boundary`), a tangent plane for
        friction (:func:`vfem.contact.formulations.friction.plane_normals`)."""
        mesh = self.mesh
        out = []
        for sup in self.supports:
            components = self.support_components(sup)
            if len(components) != 1 or sup.boundary not in (mesh.boundaries or {}):
                continue
            facets = np.asarray(mesh.boundaries[sup.boundary])
            if not len(facets):
                continue
            axis = self.components.index(components[0])  # x 0, y 1, z 2
            ends = mesh.p[:, mesh.facets[:, facets]]  # (dim, nodes of a facet, nf)
            along = np.ptp(ends[axis], axis=0)  # 2D: |the two ends' difference|
            size = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=0)
            coord = ends[axis].ravel()
            if np.all(along <= 1e-9 * size) and np.ptp(coord) <= 1e-9 * max(size.max(), 1e-300):
                out.append((facets, axis))
        return out

    def support_components(self, support: Support) -> tuple[str, ...]:
        """The components ``support`` fixes on this body: its own, or by default
        (:class:`AllComponents`) all of the body's."""
        if isinstance(support.components, AllComponents):
            return self.components
        return tuple(support.components)

    @property
    def large(self) -> bool:
        """Whether the body is analysed under large displacements (see ``kinematics``)."""
        return self.kinematics != "small"

    # -- set-up ---------------------------------------------------------------------------------

    def assemble(self) -> dict[int, float]:
        """Validate and assemble, without factorizing anything: the basis, the stiffness ``K``
        (all dofs), the constrained dofs (``fixed_dofs``, ``platen_dofs``, ``free_dofs``), the
        load vector ``f_load`` and ``u_prescribed`` (the constrained dofs' values, 0 on supports
        and the platen's dofs), both with every load at its full value (load factor 1, or
        multiplier 1 on a load curve), and the same split by load curve (``load_cases``, the
        proportional case first). Refuses a body free to move as a rigid body. Returns the
        prescribed value of every supported or prescribed dof.

        :meth:`setup` starts with it; the classical baselines
        (:mod:`vfem.contact.formulations.baselines`), which solve every body in one global system,
        need only this part.
        """
        self.validate()
        t0 = time.perf_counter()
        lam, mu = self.material.lame()
        if self.dim == 3:  # scikit-fem's per-pair loop takes minutes at 3D sizes (assembly.py),
            # and its basis, 147 KB a hexahedron, is not kept (:attr:`basis`)
            self.K = elasticity_stiffness(self.mesh, self.element(), lam, mu,
                                          self.dof_map.element_dofs)
        else:
            self.basis = Basis(self.mesh, ElementVector(self.element()))
            self.K = asm(linear_elasticity(lam, mu), self.basis).tocsr()
        self.ndofs = self.K.shape[0]
        t1 = time.perf_counter()
        fixed = self._constraints()
        self._check_supported()
        self.free_dofs = np.setdiff1d(np.arange(self.ndofs), self.fixed_dofs)
        self.load_cases = self._load_cases(fixed)
        if len(self.load_cases) == 1:  # proportional loading: as before load curves existed
            self.f_load = self.load_cases[0].force
            self.u_prescribed = self.load_cases[0].prescribed
        else:
            self.f_load = sum(c.force for c in self.load_cases)
            self.u_prescribed = sum(c.prescribed for c in self.load_cases)
        self.timings = {"assemble_s": t1 - t0, "constraints_s": time.perf_counter() - t1}
        return fixed

    def setup(self, backend: str | None = None, condensed_dofs: np.ndarray | None = None) -> None:
        """Validate, assemble the stiffness (:meth:`assemble`), factorize it and solve the unit
        load cases.

        With ``condensed_dofs`` (the dofs contact follows), the factorization also yields the
        inverse stiffness among them (``condensed_flexibility``, supports kept: zero on fixed dofs).
        """
        fixed = self.assemble()
        t1 = time.perf_counter()
        platen_dofs = self.platen_dofs
        K_ff = self.K_ff
        trailing = None
        if condensed_dofs is not None:
            condensed_dofs = np.asarray(condensed_dofs, dtype=int)
            pos, free = self.free_positions(condensed_dofs)
            trailing = pos[free]
        t2 = time.perf_counter()
        self.factor = factorize(K_ff, backend, trailing=trailing,
                                groups=self.free_dofs // self.dim, what=f"body {self.name!r}")
        t3 = time.perf_counter()
        del K_ff  # the factorization has its own copy (a million-dof 3D model: 1 GB each)
        self.condensed_flexibility = None
        if condensed_dofs is not None:
            if free.all():  # the factor's block is the flexibility: no copy
                G = self.factor.trailing_inverse
            else:
                G = np.zeros((len(condensed_dofs), len(condensed_dofs)))
                ix = np.flatnonzero(free)
                G[np.ix_(ix, ix)] = self.factor.trailing_inverse
            self.condensed_flexibility = G
            # the factor's dense copy is not needed for its solves: freed (issue 19, item 4:
            # three dense copies per body were kept)
            self.factor.trailing_inverse = None

        for case in self.load_cases:
            case.displacement = self._solve_with(case.force, case.prescribed)
        self.u_load = (self.load_cases[0].displacement if len(self.load_cases) == 1
                       else sum(c.displacement for c in self.load_cases))
        # The platen's reaction (the force it applies to the body, along its component) is
        # linear in the state: sum_k m_k(load_factor) * (case k's reaction) + platen_displacement
        # * platen_stiffness + (reaction per unit contact force) . contact forces.
        self.u_platen = np.zeros(self.ndofs)
        self.platen_load_reaction = self.platen_stiffness = 0.0
        if self.platen is not None:
            u_unit = np.zeros(self.ndofs)
            u_unit[platen_dofs] = 1.0
            self.u_platen = self._solve_with(np.zeros(self.ndofs), u_unit)
            for case in self.load_cases:
                case.platen_reaction = float((self.K @ case.displacement
                                              - case.force)[platen_dofs].sum())
            self.platen_load_reaction = sum(c.platen_reaction for c in self.load_cases)
            self.platen_stiffness = _platen_stiffness(self.K, self.u_platen, platen_dofs)
        # how the body answers its contact forces: linearly, or under large kinematics
        self.mechanics = LargeMechanics(self, fixed) if self.large else LinearMechanics(self)
        self.timings.update(constraints_s=self.timings["constraints_s"] + t2 - t1,
                            factorize_s=t3 - t2, load_cases_s=time.perf_counter() - t3)
        log.info("body %s: %d points, %d dofs (%d fixed)", self.name, self.ndofs // self.dim,
                 self.ndofs, len(self.fixed_dofs))

    # -- the body's mechanics (vfem.bodies.mechanics) ---------------------------------------

    @property
    def mechanics(self) -> BodyMechanics:
        """How the body answers its contact forces (:mod:`vfem.bodies.mechanics`): set by
        :meth:`setup`; linear for a body that was only assembled (a baseline's)."""
        if "_mechanics" not in self.__dict__:
            self._mechanics = LinearMechanics(self)
        return self._mechanics

    @mechanics.setter
    def mechanics(self, value: BodyMechanics) -> None:
        self._mechanics = value

    @property
    def nonlinear(self):
        """The hyperelastic body behind a large-kinematics body (:mod:`vfem.nonlinear`)."""
        return self.mechanics.nonlinear

    def equilibrate(self, load_factor: float, platen_displacement: float,
                    contact_force: np.ndarray) -> np.ndarray:
        """Large kinematics: :meth:`LargeMechanics.equilibrate`."""
        return self.mechanics.equilibrate(load_factor, platen_displacement, contact_force)

    def linearize(self, load_factor: float, platen_displacement: float,
                  contact_force: np.ndarray, condensed_dofs: np.ndarray,
                  candidate_dofs: np.ndarray, backend: str | None = None) -> Linearization:
        """Large kinematics: :meth:`LargeMechanics.linearize`."""
        return self.mechanics.linearize(load_factor, platen_displacement, contact_force,
                                        condensed_dofs, candidate_dofs, backend)

    def move(self, correction: np.ndarray) -> None:
        """Large kinematics: :meth:`LargeMechanics.move`."""
        self.mechanics.move(correction)

    def commit_step(self) -> None:
        """A step converged: keep its state (large kinematics; nothing for small)."""
        self.mechanics.commit()

    def discard_step(self) -> None:
        """A step failed: go back to the last converged state (large kinematics)."""
        self.mechanics.discard()

    def saved_state(self) -> dict[str, np.ndarray]:
        """The converged state as arrays (empty for small kinematics: a linear body's state is
        the contact forces, platen and load factor, which the contact state holds)."""
        return self.mechanics.saved_state()

    def restore_state(self, state: dict[str, np.ndarray]) -> None:
        """Put back a state from :meth:`saved_state` exactly (step cutting, ``--resume``)."""
        self.mechanics.restore_state(state)

    def check_supports(self) -> None:
        """Without assembling anything: raise :class:`InputError` if the body is invalid or
        its supports leave it free to move as a rigid body (``vfem check``)."""
        self.validate()
        self._constraints()
        self._check_supported()

    def _constraints(self) -> dict[int, float]:
        """The constrained dofs: sets ``platen_dofs`` and ``fixed_dofs``, returns the
        prescribed value at load factor 1 of every supported or prescribed dof."""
        fixed: dict[int, float] = {}  # dof -> prescribed value at factor 1
        for s in self.supports:
            for c in self.support_components(s):
                fixed.update(dict.fromkeys(self._boundary_dofs(s.boundary, c).tolist(), 0.0))
        for pd in self.prescribed:
            fixed.update(dict.fromkeys(self._boundary_dofs(pd.boundary, pd.component).tolist(),
                                       float(pd.value)))
        self.platen_dofs = np.array([], dtype=int)
        if self.platen is not None:
            self.platen_dofs = self._boundary_dofs(self.platen.boundary, self.platen.component)
        self.fixed_dofs = np.array(sorted(set(fixed) | set(self.platen_dofs.tolist())),
                                   dtype=int)
        return fixed

    def _load_cases(self, fixed: dict[int, float]) -> list[LoadCase]:
        """The body's loads grouped by load curve: the proportional case (also holding the
        supports' zeros) first, then one per distinct ``amplitude`` of its tractions and
        prescribed displacements, in order of first mention. A dof that several conditions
        prescribe belongs to the last prescribed displacement on it, as in :meth:`_constraints`.
        ``fixed``: the prescribed value of every constrained dof (from :meth:`_constraints`)."""
        keys = [None]
        for load in (*self.tractions, *self.prescribed):
            key = curve_key(load.amplitude)
            if key not in keys:
                keys.append(key)
        cases = [LoadCase(k, np.zeros(self.ndofs), np.zeros(self.ndofs)) for k in keys]
        for tr in self.tractions:
            cases[keys.index(curve_key(tr.amplitude))].force += self._traction_vector(tr)
        owner = dict.fromkeys(fixed, 0)
        for pd in self.prescribed:  # later ones win, as in _constraints
            owner.update(dict.fromkeys(self._boundary_dofs(pd.boundary, pd.component).tolist(),
                                       keys.index(curve_key(pd.amplitude))))
        for dof, value in fixed.items():
            cases[owner[dof]].prescribed[dof] = value
        return cases

    def load_displacement(self, load_factor: float, dofs: np.ndarray | None = None
                          ) -> np.ndarray:
        """Small kinematics: the displacement (ndofs, or of ``dofs``) due to the loads and
        prescribed displacements at ``load_factor``, each case at its curve's multiplier
        (``load_factor * u_load`` without load curves); after :meth:`setup`."""
        if dofs is None:
            return superpose(load_factor, ((c.amplitude, c.displacement)
                                           for c in self.load_cases))
        return superpose(load_factor, ((c.amplitude, c.displacement[dofs])
                                       for c in self.load_cases))

    def platen_load_reaction_at(self, load_factor: float) -> float:
        """Small kinematics: the platen's reaction to the loads and prescribed displacements at
        ``load_factor`` (``load_factor * platen_load_reaction`` without load curves)."""
        return superpose(load_factor, ((c.amplitude, c.platen_reaction)
                                       for c in self.load_cases))

    def prescribed_at(self, load_factor: float) -> np.ndarray:
        """(ndofs) the constrained dofs' prescribed values at ``load_factor`` (zero on supports,
        the platen's dofs and the free dofs; after :meth:`assemble`)."""
        return superpose(load_factor, ((c.amplitude, c.prescribed) for c in self.load_cases))

    def element(self):
        """The scalar scikit-fem element of each displacement component."""
        if isinstance(self.mesh, MeshTet):
            return ElementTetP2() if self.order == 2 else ElementTetP1()
        if isinstance(self.mesh, MeshHex):
            return ElementHex2() if self.order == 2 else ElementHex1()
        tri = isinstance(self.mesh, MeshTri)
        if self.order == 2:
            return ElementTriP2() if tri else ElementQuad2()
        return ElementTriP1() if tri else ElementQuad1()

    @cached_property
    def points(self) -> np.ndarray:
        """(dim, npoints) coordinates of the element nodes (see the class docstring)."""
        mesh = self.mesh
        if self.order == 1:
            return mesh.p[:, : mesh.nvertices]
        if isinstance(mesh, Mesh2D2) or type(mesh).__name__ in _QUADRATIC_GEOMETRY:
            return mesh.doflocs  # curved (quadratic) geometry: its nodes are the points
        if self.dim == 3:  # scikit-fem's dofs: vertices, edges, (hexahedra) facets, elements
            parts = [mesh.p, mesh.p[:, mesh.edges].mean(axis=1)]
            if isinstance(mesh, MeshHex):
                parts += [mesh.p[:, mesh.facets].mean(axis=1), mesh.p[:, mesh.t].mean(axis=1)]
            return np.hstack(parts)
        parts = [mesh.p, mesh.p[:, mesh.facets].mean(axis=1)]
        if not isinstance(mesh, MeshTri):
            parts.append(mesh.p[:, mesh.t].mean(axis=1))
        return np.hstack(parts)

    @property
    def npoints(self) -> int:
        return self.points.shape[1]

    def facet_points(self, facets: np.ndarray) -> np.ndarray:
        """(nf, k) points of the given facets: the two vertices, then (order 2) the midpoint.
        In 3D the facet's 3 or 4 vertices (``mesh.facets``), then (order 2) its edges' middles
        (in the order of ``mesh.f2e``: the facet's edges 0-1, 1-2, then 0-2 of a triangle,
        2-3 and 0-3 of a quadrilateral) and a quadrilateral's centre."""
        mesh = self.mesh
        fp = mesh.facets[:, facets].T
        if self.order == 2:
            if self.dim == 3:
                facets = np.asarray(facets)
                cols = [fp, mesh.nvertices + mesh.f2e[:, facets].T]
                if isinstance(mesh, MeshHex):
                    cols.append(mesh.nvertices + mesh.edges.shape[1] + facets)
                return np.column_stack(cols)
            fp = np.column_stack([fp, self.mesh.nvertices + np.asarray(facets)])
        return fp

    def boundary_points(self, boundary: str) -> np.ndarray:
        """Sorted points on a named boundary."""
        return np.unique(self.facet_points(self.mesh.boundaries[boundary]))

    def cells(self) -> tuple[str, np.ndarray]:
        """VTK cell type and (nelements, k) point connectivity, in VTK's node order (after
        :meth:`setup`). In 3D: ``tetra``, ``hexahedron``, ``tetra10`` or ``hexahedron27``
        (scikit-fem's hexahedron nodes reordered by ``skfem.io.meshio.HEX_MAPPING``), each cell
        with a positive volume in VTK's convention (a mirrored element's nodes listed
        mirrored)."""
        if self.dim == 3:
            return self._cells_3d()
        tri = isinstance(self.mesh, MeshTri)
        if self.order == 1:
            return ("triangle" if tri else "quad"), self.mesh.t.T
        # scikit-fem's element dofs (x of point k is dof 2k): vertices, then facets in VTK's edge
        # order, then the centre
        conn = self.dof_map.element_dofs[::2].T // 2
        return ("triangle6" if tri else "quad9"), conn

    def _cells_3d(self) -> tuple[str, np.ndarray]:
        """:meth:`cells` of a 3D body."""
        mesh, tet = self.mesh, isinstance(self.mesh, MeshTet)
        if self.order == 1:
            kind = "tetra" if tet else "hexahedron"
            conn = mesh.t if tet else mesh.t[HEX_MAPPING[:8]]
        else:  # scikit-fem's element dofs (x of point k is dof 3k): vertices, edges, ...
            kind = "tetra10" if tet else "hexahedron27"
            conn = self.dof_map.element_dofs[::3] // 3
            conn = conn if tet else conn[HEX_MAPPING]
        conn = np.ascontiguousarray(conn.T)
        x = self.points[:, conn[:, :8 if not tet else 4]]  # (3, ne, corners)
        if tet:
            a, b, c = x[:, :, 1] - x[:, :, 0], x[:, :, 2] - x[:, :, 0], x[:, :, 3] - x[:, :, 0]
        else:  # the trilinear map's Jacobian at the centre, VTK's corner order
            a = (x[:, :, [1, 2, 5, 6]] - x[:, :, [0, 3, 4, 7]]).sum(axis=2)
            b = (x[:, :, [2, 3, 6, 7]] - x[:, :, [1, 0, 5, 4]]).sum(axis=2)
            c = (x[:, :, [4, 5, 6, 7]] - x[:, :, [0, 1, 2, 3]]).sum(axis=2)
        volume = np.einsum("ie,ie->e", np.cross(a, b, axis=0), c)
        mirrored = volume < 0
        if mirrored.any():
            conn[mirrored] = conn[mirrored][:, _VTK_MIRROR[kind]]
        return kind, conn

    def validate(self) -> None:
        """Raise :class:`InputError` naming the body if its definition cannot be analysed."""
        where = f"body {self.name!r}"
        if not isinstance(self.mesh, (MeshTri, MeshQuad, MeshTet, MeshHex)) or (
                type(self.mesh).__name__ not in MESHES):
            raise InputError(f"{where}: mesh must be triangles or quadrilaterals (2D), "
                             f"tetrahedra or hexahedra (3D), got {type(self.mesh).__name__}")
        # validate runs before every use of the body; the mesh is checked once
        if getattr(self, "_checked_mesh", None) is not self.mesh:
            check_mesh(self.mesh, where)
            self._checked_mesh = self.mesh
        if self.order not in (1, 2):
            raise InputError(f"{where}: order must be 1 (linear) or 2 (quadratic elements), "
                             f"got {self.order!r}")
        self.material.validate(f"{where}, material")
        if self.kinematics not in ("small", "total", "updated"):
            raise InputError(f"{where}: kinematics must be 'small', 'total' or 'updated', "
                             f"got {self.kinematics!r}")
        if self.law not in ("saint-venant-kirchhoff", "neo-hookean"):
            raise InputError(f"{where}: law must be 'saint-venant-kirchhoff' or 'neo-hookean', "
                             f"got {self.law!r}")
        if self.dim == 3 and self.material.plane != "strain":
            raise InputError(f"{where}: plane = {self.material.plane!r} is an assumption of 2D "
                             "bodies; a 3D body (tetrahedra or hexahedra) has none: leave "
                             "the material's plane out")
        if self.dim == 3 and self.large and self.order != 1:
            raise InputError(f"{where}: large kinematics ({self.kinematics!r}) needs linear "
                             "elements (order 1)")
        if self.large and (self.order != 1 or self.material.plane != "strain"):
            raise InputError(f"{where}: large kinematics ({self.kinematics!r}) needs linear "
                             "elements (order 1) and plane strain")
        names = set((self.mesh.boundaries or {}).keys())
        for bc in (*self.supports, *self.prescribed, *self.tractions,
                   *((self.platen,) if self.platen else ()), *(self.contact_boundaries or ())):
            name = bc if isinstance(bc, str) else bc.boundary
            if name not in names:
                raise InputError(f"{where}: no boundary named {name!r}; the mesh has "
                                 f"{', '.join(sorted(names)) or 'no named boundaries'}")
            if len(self.mesh.boundaries[name]) == 0:
                raise InputError(f"{where}: boundary {name!r} holds no facet of the mesh's "
                                 "outline; check how it is defined (a shape's parameters, or "
                                 "the mesh file's group)")
        comps = [("support", s.boundary, c) for s in self.supports
                 for c in self.support_components(s)]
        comps += [("prescribed displacement", pd.boundary, pd.component)
                  for pd in self.prescribed]
        comps += [("platen", self.platen.boundary, self.platen.component)] if self.platen else []
        allowed = self.components
        for kind, boundary, c in comps:
            if c not in allowed:
                names = " or ".join((", ".join(repr(a) for a in allowed[:-1]),
                                     repr(allowed[-1])))
                raise InputError(f"{where}: {kind} on {boundary!r}: component must be {names}"
                                 + ("" if c not in COMPONENTS else
                                    f" (the body's mesh is {self.dim}D)") + f", got {c!r}")
        for tr in self.tractions:
            if not isinstance(tr.value, (tuple, list)) or len(tr.value) != self.dim:
                raise InputError(
                    f"{where}: traction on {tr.boundary!r}: value must have {self.dim} "
                    f"components ({', '.join('t' + a for a in allowed)}) on a {self.dim}D "
                    f"body, got {_shown(tr.value)}")
        for kind, loads in (("prescribed displacement", self.prescribed),
                            ("traction", self.tractions),
                            ("platen", (self.platen,) if self.platen else ())):
            for load in loads:
                if load.amplitude is not None:
                    check_amplitude(load.amplitude, f"{where}: {kind} on {load.boundary!r}")
        values = [pd.value for pd in self.prescribed] + [v for t in self.tractions for v in t.value]
        values += [self.platen.force] if self.platen else []
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
            raise InputError(f"{where}: loads and prescribed displacements must be finite numbers")

    def _boundary_dofs(self, boundary: str, component: str) -> np.ndarray:
        """The dofs of ``component`` on the named boundary, numbered as the body's basis
        numbers them (scikit-fem's :class:`~skfem.assembly.Dofs` of the vector element: the
        numbering without a basis's values at every quadrature point, which ``vfem check`` of a
        170k-dof hexahedral body took 1.6 s and gigabytes of address space to build)."""
        facets = self.mesh.boundaries[boundary]
        return self.dof_map.get_facet_dofs(facets).all(f"u^{COMPONENTS[component] + 1}")

    @property
    def K_ff(self):
        """The stiffness's block of the free dofs (``free_dofs``), CSC: what :meth:`setup`
        factorizes; formed when asked, not kept."""
        return self.K[self.free_dofs][:, self.free_dofs].tocsc()

    @property
    def basis(self) -> Basis:
        """scikit-fem's ``CellBasis`` of the body's vector element. A 2D body builds it in
        :meth:`assemble` and keeps it; a 3D body's assembly and strains work a chunk of
        elements at a time (:func:`~vfem.bodies.assembly.cell_gradients`) and keep none, since
        the whole basis takes more memory than the factorization (147 KB per trilinear
        hexahedron: the million-dof sphere was killed building it), so here it is built on
        first use, for callers that want scikit-fem's view of the body."""
        basis = self.__dict__.get("_basis")
        if basis is None:
            mapping = cell_mapping(self.mesh) if self.dim == 3 else None
            basis = self._basis = Basis(self.mesh, ElementVector(self.element()),
                                        mapping=mapping)
        return basis

    @basis.setter
    def basis(self, value: Basis) -> None:
        self._basis = value

    @property
    def dof_map(self) -> Dofs:
        """scikit-fem's numbering of the body's dofs (the vector element's), as its basis has
        it, without the basis."""
        if not hasattr(self, "_dof_map"):
            self._dof_map = Dofs(self.mesh, ElementVector(self.element()))
        return self._dof_map

    def _rigid_modes(self) -> dict[str, np.ndarray]:
        """The body's rigid-body motions by name, each (npoints, dim): in 2D the translations
        in x and y and the rotation; in 3D the translations in x, y and z and the rotations
        about the axes x, y and z through the points' centroid."""
        if self.dim == 2:
            x, y = self.points
            return {"translation in x": np.column_stack([np.ones_like(x), 0 * y]),
                    "translation in y": np.column_stack([0 * x, np.ones_like(y)]),
                    "rotation": np.column_stack([-(y - y.mean()), x - x.mean()])}
        X = self.points - self.points.mean(axis=1, keepdims=True)
        zero, one = np.zeros(X.shape[1]), np.ones(X.shape[1])
        x, y, z = X
        return {"translation in x": np.column_stack([one, zero, zero]),
                "translation in y": np.column_stack([zero, one, zero]),
                "translation in z": np.column_stack([zero, zero, one]),
                "rotation about x": np.column_stack([zero, -z, y]),
                "rotation about y": np.column_stack([z, zero, -x]),
                "rotation about z": np.column_stack([-y, x, zero])}

    def _check_supported(self) -> None:
        """Refuse a body that can move as a rigid body: its stiffness would be singular. The
        message names the free motions (2D: the translations in x and y, the rotation; 3D:
        the translations in x, y and z, the rotations about x, y and z)."""
        modes = self._rigid_modes()
        R = np.column_stack([m.ravel() for m in modes.values()])  # interleaved dofs
        Rc = R[self.fixed_dofs]
        names = list(modes)
        n = len(names)
        # (rows of zeros up to n: vt is then n x n without the full, fixed dofs squared, U)
        A = Rc if len(Rc) >= n else np.vstack([Rc, np.zeros((n - len(Rc), n))])
        _, sv, vt = np.linalg.svd(A, full_matrices=False)
        tol = 1e-10 * max(1.0, float(np.abs(R).max())) * max(1, len(Rc))
        rank = int((sv > tol).sum())
        if rank < n:
            null = vt[rank:]  # the free motions' coefficients, an orthonormal basis
            if self.dim == 3:
                null = _named_first(null)
            free = []
            for v in null:
                parts = [names[i] for i in np.flatnonzero(np.abs(v) > 1e-6 * np.abs(v).max())]
                free.append(parts[0] if len(parts) == 1
                            else "a combination of " + " and ".join(parts))
            raise InputError(
                f"body {self.name!r} is not supported: it can move freely as a rigid body "
                f"({'; '.join(free)}), so its stiffness is singular; add supports or a platen"
            )

    def _traction_vector(self, tr: Traction) -> np.ndarray:
        fb = FacetBasis(self.mesh, ElementVector(self.element()),
                        facets=self.mesh.boundaries[tr.boundary])
        t = np.asarray(tr.value, dtype=float)

        @LinearForm
        def load(v, w):
            out = t[0] * v[0] + t[1] * v[1]
            for d in range(2, len(t)):  # 3D: + t[2] * v[2]
                out = out + t[d] * v[d]
            return out

        return asm(load, fb)

    def _solve_with(self, f: np.ndarray, u_fixed: np.ndarray) -> np.ndarray:
        """Displacement for load ``f`` with the fixed dofs at ``u_fixed``."""
        u = u_fixed.copy()
        rhs = f - self.K @ u_fixed
        u[self.free_dofs] = self.factor.solve(rhs[self.free_dofs])
        return u

    # -- what the contact algorithm uses ---------------------------------------------------------

    def response(self, nodal_force: np.ndarray) -> np.ndarray:
        """Displacement due to nodal forces (ndofs), supports kept at zero: K^-1 f."""
        return self._solve_with(np.asarray(nodal_force, dtype=float), np.zeros(self.ndofs))

    def free_positions(self, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where body dofs ``dofs`` stand among the free dofs (the rows of the factorized
        block), and which of them are free at all (a constrained dof has no row)."""
        dofs = np.asarray(dofs, dtype=int)
        pos = np.searchsorted(self.free_dofs, dofs)
        is_free = (pos < len(self.free_dofs)) & (
            self.free_dofs[np.minimum(pos, len(self.free_dofs) - 1)] == dofs)
        return pos, is_free

    def flexibility_columns(self, dofs: np.ndarray, chunk: int = 256) -> np.ndarray:
        """Columns of K^-1 (supports kept) for the given dofs, shape (ndofs, len(dofs)).

        One back-substitution per dof; constrained dofs give zero columns.
        """
        dofs = np.asarray(dofs, dtype=int)
        out = np.zeros((self.ndofs, len(dofs)))
        pos, is_free = self.free_positions(dofs)
        cols = np.flatnonzero(is_free)
        for start in range(0, len(cols), chunk):
            c = cols[start:start + chunk]
            rhs = np.zeros((len(self.free_dofs), len(c)))
            rhs[pos[c], np.arange(len(c))] = 1.0
            out[np.ix_(self.free_dofs, c)] = self.factor.solve(rhs)
        return out

    def displacement(self, load_factor: float, platen_displacement: float,
                     contact_force: np.ndarray) -> np.ndarray:
        """Full displacement vector (ndofs) for the given state (:attr:`mechanics`)."""
        return self.mechanics.displacement(load_factor, platen_displacement, contact_force)

    def applied_load(self, load_factor: float) -> np.ndarray:
        """The body's applied nodal loads (ndofs: its tractions' load vector) at
        ``load_factor``, each traction at its load curve's multiplier; the one place reactions,
        force balances and the large-kinematics loads read the loads from."""
        return superpose(load_factor, ((c.amplitude, c.force) for c in self.load_cases))

    def nodal_reaction(self, u: np.ndarray, load_factor: float = 1.0,
                       contact_force: np.ndarray | None = None) -> np.ndarray:
        """The nodal forces (ndofs) the constraints (supports, prescribed displacements, the
        platen) apply to the body, for displacement ``u`` (ndofs) under the loads at
        ``load_factor`` and the nodal ``contact_force`` (ndofs): the out-of-balance force
        ``K u - applied_load(load_factor) - f_contact`` (the internal force in place of ``K u``
        under large kinematics) on the constrained dofs (``fixed_dofs``), zero on the free
        ones, where it is only the solver's residual. Adding it to the loads and contact
        forces balances the body, so its sum is the body's total support reaction, each
        constrained dof counted once."""
        Ku = self.mechanics.internal_force(u)
        r = Ku - self.applied_load(load_factor)
        if contact_force is not None:
            r = r - contact_force
        out = np.zeros(self.ndofs)
        out[self.fixed_dofs] = r[self.fixed_dofs]
        return out

    def reaction_dofs(self) -> dict[str, np.ndarray]:
        """Per boundary that carries a support, a prescribed displacement or the platen (in
        that order of first mention), the dofs its own conditions constrain: a support's
        components, a prescribed component, the platen's component. A node shared by two such
        boundaries (a corner) is in both where both constrain the same component."""
        parts: dict[str, list[np.ndarray]] = {}
        for s in self.supports:
            for c in self.support_components(s):
                parts.setdefault(s.boundary, []).append(self._boundary_dofs(s.boundary, c))
        for pd in self.prescribed:
            parts.setdefault(pd.boundary, []).append(self._boundary_dofs(pd.boundary,
                                                                         pd.component))
        if self.platen is not None:
            parts.setdefault(self.platen.boundary, []).append(self.platen_dofs)
        return {name: np.unique(np.concatenate(d)) for name, d in parts.items()}

    def boundary_reactions(self, nodal_reaction: np.ndarray) -> dict[str, tuple[float, ...]]:
        """Per constrained boundary (:meth:`reaction_dofs`), the total (x, y), or (x, y, z) in
        3D, of
        ``nodal_reaction`` (ndofs, from :meth:`nodal_reaction`) over the dofs it constrains.
        A shared corner dof counts in each boundary that constrains it, so the boundaries'
        totals add up to the body's total only where no dof is shared."""
        r = np.asarray(nodal_reaction, dtype=float).ravel()
        out = {}
        for name, dofs in self.reaction_dofs().items():
            dim = self.dim
            out[name] = tuple(float(r[dofs[dofs % dim == c]].sum()) for c in range(dim))
        return out

    def reaction(self, u: np.ndarray, boundary: str, component: str, load_factor: float = 1.0,
                 contact_force: np.ndarray | None = None) -> float:
        """Total force the supports (or prescribed displacements) on ``boundary`` apply to the
        body along ``component``, for displacement ``u`` (ndofs) under the body's loads at
        ``load_factor`` and the nodal ``contact_force`` (ndofs): :meth:`nodal_reaction` summed
        over the boundary's dofs of that component (zero where none of them is constrained)."""
        r = self.nodal_reaction(u, load_factor, contact_force)
        return float(r[self._boundary_dofs(boundary, component)].sum())


__all__ = ["Body", "Support", "PrescribedDisplacement", "Traction", "Platen", "Linearization",
           "LoadCase", "check_amplitude", "multiplier", "superpose"]
