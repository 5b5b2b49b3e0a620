"""A model as data: the typed, frozen description that input files and the examples share.

An input file (``examples/*.toml``, see ``docs/input.md``) is read into a :class:`ModelConfig`;
every built-in example builds the same objects, so ``vfem run examples/hertz.toml`` and
``vfem run hertz`` solve the very same model. These classes are the single source of truth for the
names, types, defaults and help text of every key: the loader (:mod:`vfem.io.input`) checks input
against them and the key reference in ``docs/input.md`` is generated from them (a test keeps the
two equal).

Classes that describe a body's physics are the solver's own: the material tables
(:data:`~vfem.materials.MATERIALS`: :class:`~vfem.materials.LinearElastic`),
:class:`~vfem.bodies.Support`, :class:`~vfem.bodies.PrescribedDisplacement`,
:class:`~vfem.bodies.Traction`, :class:`~vfem.bodies.Platen` and
:class:`~vfem.contact.settings.ContactSettings`. What only a description needs (how to make the
mesh, the steps, where results go) is defined here. :meth:`ModelConfig.build` turns the
description into a :class:`~vfem.model.Model`.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path, PureWindowsPath
from typing import Any

import numpy as np

from .bodies import Body, Platen, PrescribedDisplacement, Support, Traction
from .contact.settings import ContactSettings
from .errors import InputError
from .materials import MaterialTable
from .mesh import parametric, shapes, solids
from .schema import check_parameters
from .solver import Model

#: The built-in parametric meshes an input file may name as ``mesh.shape``: each is a function
#: of ``vfem.mesh`` whose keyword parameters are the keys of the mesh table.
SHAPES = {
    "rectangle": shapes.rectangle,
    "block": shapes.block,
    "graded_quarter_disk": parametric.graded_quarter_disk,
    "graded_half_disk": parametric.graded_half_disk,
    "graded_layer": parametric.graded_layer,
    "wedge": shapes.wedge,
    "wedge_plate": shapes.wedge_plate,
    "wedge_grid": shapes.wedge_grid,
    "wedge_plate_grid": shapes.wedge_plate_grid,
    "gasket": shapes.gasket,
    "rounded_punch": shapes.rounded_punch,
    "filleted_punch": shapes.filleted_punch,
    "disk": shapes.disk,
    "annulus": shapes.annulus,
    "box": solids.box,
    "cylinder": solids.cylinder,
    "cylinder_section": solids.cylinder_section,
    "ring": solids.ring,
}
#: The shapes of :data:`SHAPES` that make 3D meshes (tetrahedra, hexahedra).
SOLID_SHAPES = ("box", "cylinder", "ring")


@dataclass(frozen=True)
class Curve:
    """Quadratic geometry on a circular boundary (bodies with ``order = 2``), or in 3D on a
    spherical one (tetrahedra).

    Attributes:
        boundary: the boundary whose facet midpoints are moved onto the circle (its vertices
            must already lie on it), e.g. a cylinder's arc; in 3D the midpoints of the edges
            of its triangles, onto the sphere (a sphere's cap).
        centre: the circle's centre (x, y); the sphere's (x, y, z).
        radius: the circle's (sphere's) radius.
    """

    boundary: str
    centre: tuple[float, ...]
    radius: float


@dataclass(frozen=True)
class MeshSpec:
    """Where a body's mesh comes from: a built-in shape or a mesh file.

    Attributes:
        shape: a built-in parametric mesh (see *Mesh shapes* below); its parameters are the
            other keys of the same table.
        file: a mesh file read through meshio: Gmsh ``.msh`` (format 4) or Abaqus ``.inp``;
            relative paths are taken from the input file's folder. Physical curves (Gmsh) or
            node sets (Abaqus) become the body's named boundaries; in a file with 3D elements
            (tetrahedra, hexahedra), physical surfaces or element sets of faces and node sets.
        cells: the group of ``file`` holding this body's elements: a Gmsh physical surface
            (physical volume in 3D) or an Abaqus element set. Default: every 2D element of the
            file (every 3D element, if it has any).
        translate: moves the mesh by (dx, dy) after it is made; (dx, dy, dz) for a 3D mesh.
        curve: puts the facet midpoints of a circular boundary on the circle (quadratic
            elements only); of a tetrahedral mesh, the triangles' edge midpoints of a
            spherical boundary on the sphere.
        parameters: the shape's parameters (in an input file: the other keys of the mesh
            table, not a key of its own).
    """

    shape: str | None = None
    file: str | None = None
    cells: str | None = None
    translate: tuple[float, ...] = (0.0, 0.0)
    curve: Curve | None = None
    parameters: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self):
        # one order for the same parameters, so equal descriptions compare (and cache) equal
        object.__setattr__(self, "parameters", tuple(sorted(self.parameters)))

    def make(self, base: Path | None = None):
        """The scikit-fem mesh, with its named boundaries."""
        if (self.shape is None) == (self.file is None):
            raise InputError("mesh: give exactly one of 'shape' (a built-in mesh) and 'file'")
        if self.shape is not None:
            mesh = _shape_mesh(self.shape, self.parameters)
        else:
            from .mesh.imports import read_mesh

            path = Path(self.file)
            if base is not None and not path.is_absolute():
                path = Path(base) / path
            mesh = read_mesh(path, self.cells)
        dim = mesh.p.shape[0]
        what = (f"the {dim}D shape {self.shape!r}" if self.shape is not None
                else f"the {dim}D mesh of file {self.file!r}")
        if len(self.translate) != dim and tuple(self.translate) != (0.0, 0.0):
            raise InputError(f"mesh.translate: expected {dim} values "
                             f"({', '.join('d' + a for a in 'xyz'[:dim])}) for {what}, got "
                             f"{len(self.translate)}")
        if any(self.translate):
            mesh = mesh.translated(tuple(float(v) for v in self.translate))
        if self.curve is not None:
            from .mesh.quadratic import curved

            if dim == 3 and mesh.t.shape[0] != 4:
                raise InputError(f"mesh.curve: curved facets in 3D are for tetrahedra (on a "
                                 f"sphere); {what} is of hexahedra (remove mesh.curve)")
            if len(self.curve.centre) != dim:
                raise InputError(f"mesh.curve.centre: expected {dim} values for {what}, got "
                                 f"{len(self.curve.centre)}")
            if self.curve.boundary not in (mesh.boundaries or {}):
                raise InputError(f"mesh.curve: no boundary named {self.curve.boundary!r}; the "
                                 f"mesh has {', '.join(sorted(mesh.boundaries or {}))}")
            mesh = curved(mesh, self.curve.boundary, self.curve.centre, self.curve.radius)
        return mesh


@lru_cache(maxsize=8)
def _shape_mesh(shape: str, parameters: tuple[tuple[str, Any], ...]):
    """A built-in mesh (cached: several models of one example often share their meshes;
    meshes are never modified in place)."""
    if shape not in SHAPES:
        raise InputError(f"mesh: unknown shape {shape!r}; built-in shapes: "
                         f"{', '.join(SHAPES)}")
    check_parameters(SHAPES[shape], parameters, f"mesh shape {shape!r}")  # as a file's
    try:
        return SHAPES[shape](**dict(parameters))
    except (ValueError, TypeError, ArithmeticError) as exc:
        # a shape refuses parameters it cannot mesh with a ValueError; numbers out of range
        # may also surface as TypeError (a count that is a float) or OverflowError
        raise InputError(f"mesh shape {shape!r}: {exc}") from None


@dataclass(frozen=True)
class BodyConfig:
    """One deformable body.

    Attributes:
        name: unique name, used in messages and output file names.
        mesh: how its mesh is made.
        material: its material.
        order: 1 for linear elements, 2 for quadratic ones (6-node triangles, 9-node
            quadrilaterals) on the same mesh.
        supports: fixed displacement components on named boundaries.
        prescribed: displacements prescribed on named boundaries (value at load factor 1).
        tractions: distributed loads on named boundaries (at load factor 1).
        platen: a rigid, force-controlled platen on a named boundary.
        contact_boundaries: the boundaries that may touch other bodies. Default: every
            exterior facet on which no displacement is prescribed.
        kinematics: ``"small"`` (small displacements, linear elasticity or small-strain
            plasticity), or large displacements and strains by the ``"total"`` or
            ``"updated"`` Lagrangian formulation (plane strain or 3D, linear elements; a
            plastic material at finite strain).
        law: under large kinematics, the hyperelastic law whose small-strain constants are the
            material's: ``"saint-venant-kirchhoff"``, ``"neo-hookean"`` (Ciarlet–Simo) or
            ``"neo-hookean-isochoric"`` (CalculiX's and Abaqus's NEO HOOKE) (a plastic
            material has its own law: Hencky elasticity in the logarithmic strain).
        self_contact: whether its contact surface (``contact_boundaries``, or its whole free
            surface) may touch itself (a slot closing, a seal folding): its two sides are
            found at rest, where a ray along each facet's normal meets a facet facing it
            (docs/method.md §15). A surface whose sides cannot be told apart at rest (a round
            bore) is refused: name its two sides in ``contact_pairs`` instead.
        subdomains: 1 (default): the body's stiffness is factorized whole. K > 1: its elements
            are split into K subdomains (METIS, balanced by element count) whose interface
            problem is solved by BDDC, each subdomain factorized on its own: the same answers
            to 1e-8 of the largest, for a body too large to factorize whole (issue 43; serial
            for now). Linear bodies only: small kinematics, elastic material.
    """

    name: str
    mesh: MeshSpec
    material: MaterialTable
    order: int = 1
    supports: tuple[Support, ...] = ()
    prescribed: tuple[PrescribedDisplacement, ...] = ()
    tractions: tuple[Traction, ...] = ()
    platen: Platen | None = None
    contact_boundaries: tuple[str, ...] | None = None
    kinematics: str = "small"
    law: str = "saint-venant-kirchhoff"
    self_contact: bool = False
    subdomains: int = 1

    def build(self, base: Path | None = None) -> Body:
        try:
            mesh = self.mesh.make(base)
        except InputError as exc:
            raise InputError(f"body {self.name!r}: {exc}") from None
        if mesh.t.shape[1] == 0:
            raise InputError(f"body {self.name!r}: its mesh has no elements")
        return Body(self.name, mesh, self.material, supports=self.supports,
                    prescribed=self.prescribed, tractions=self.tractions, platen=self.platen,
                    contact_boundaries=self.contact_boundaries, order=self.order,
                    kinematics=self.kinematics, law=self.law,
                    self_contact=self.self_contact, subdomains=self.subdomains)


#: The most equal steps ``steps.count`` may ask for: each step is a contact solve, so more is a
#: slip of the keyboard, not a plan.
MAX_STEPS = 1_000_000


@dataclass(frozen=True)
class Steps:
    """The load history. Every load, prescribed displacement and platen force is scaled by the
    load factor (proportional loading), or by its load curve's multiplier where it has an
    ``amplitude``; each step ends at the next load factor.

    Attributes:
        count: that many equal steps from 0 to 1 (used when ``load_factors`` is not given; at
            most 1,000,000).
        load_factors: the load factor at the end of each step, e.g. ``[0.5, 1.0, 0.5, 0.0]``
            to load and unload; each differs from the one before, the first from 0.
    """

    count: int = 1
    load_factors: tuple[float, ...] | None = None

    def factors(self) -> tuple[float, ...]:
        if self.load_factors is not None:
            return tuple(float(f) for f in self.load_factors)
        if self.count < 1:
            raise InputError(f"steps.count must be at least 1, got {self.count}")
        if self.count > MAX_STEPS:  # (a count of 2**63 would fill the memory)
            raise InputError(f"steps.count must be at most {MAX_STEPS:,}, got {self.count}")
        return tuple((k + 1) / self.count for k in range(self.count))


@dataclass(frozen=True)
class Output:
    """What a run writes.

    Attributes:
        directory: the results folder, a relative path inside the folder where vfem runs
            (no absolute path, drive or ``..`` that climbs out). Default: ``results/<name>``
            (with the command line's ``--set`` changes in the name). The command line's
            ``--out`` overrides it and may be any folder.
        figures: draw the figures at the end (deformed shape, contact pressure, history, von
            Mises stress; ``vfem plot`` redraws them from the files).
    """

    directory: str | None = None
    figures: bool = True

    def __post_init__(self):
        if self.directory is not None:
            check_inside(self.directory, "output.directory")


def check_inside(directory: str, key: str) -> None:
    """Refuse a results folder named in an input file that is not a relative path staying
    inside the working directory: absolute, with a drive, climbing out with ``..``, or empty.
    An input file from someone else must not make vfem write elsewhere; the command line's
    ``--out`` is the user's own choice and is not checked. Backslashes count as separators
    (a file written on Windows). Symbolic links inside the working directory are not followed
    here."""
    text = os.fspath(directory) if isinstance(directory, (str, os.PathLike)) else None
    if not isinstance(text, str):
        raise InputError(f"{key}: expected a folder name, got {directory!r}")
    depth, climbs = 0, False
    for part in text.replace("\\", "/").split("/"):
        if part not in ("", "."):
            depth += -1 if part == ".." else 1
            climbs |= depth < 0
    if (not text.strip() or "\0" in text or text.startswith(("/", "\\"))
            or PureWindowsPath(text).drive or climbs):
        raise InputError(f"{key}: {text!r} is not a folder inside the working directory; give "
                         "a relative path such as 'results/model' (no leading '/', drive or "
                         "'..' that climbs out), or choose any folder with --out")


@dataclass(frozen=True)
class ModelConfig:
    """A whole contact analysis.

    Attributes:
        name: the model's name (messages, the default results folder).
        bodies: the bodies, two or more for contact (each one ``[[bodies]]`` table).
        contact: settings of the contact algorithm.
        steps: the load history.
        contact_pairs: which surfaces may touch, in pairs, e.g. ``[["cylinder", "flat"]]``.
            A surface is a body's name (its whole contact surface), or its name, a colon and
            boundaries of its mesh separated by commas (``"block:top"``, ``"block:top,left"``):
            that pair reads those facets alone. Two bodies are paired once. Default: every
            two bodies. A body with itself: two of its boundaries that share no facet
            (``[["u:slot_top", "u:slot_bottom"]]``), or one surface named twice, which finds
            its own two sides (``[["u", "u"]]``; as a body's ``self_contact``).
        output: what a run writes.
    """

    name: str
    bodies: tuple[BodyConfig, ...]
    contact: ContactSettings = field(default_factory=ContactSettings)
    steps: Steps = field(default_factory=Steps)
    contact_pairs: tuple[tuple[str, str], ...] | None = None
    output: Output = field(default_factory=Output)

    def build(self, base: Path | None = None) -> Model:
        """The solver's model; mesh files are looked up relative to ``base``. Raises
        :class:`InputError` naming the body and key of anything that cannot be analysed."""
        names = [b.name for b in self.bodies]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise InputError(f"two bodies are named {dup[0]!r}: body names must be unique")
        t0 = time.perf_counter()
        model = Model(self.name, [b.build(base) for b in self.bodies], self.contact,
                      self.steps.factors(), self.contact_pairs)
        model.validate()
        model.build_s = time.perf_counter() - t0
        return model


def check(config: ModelConfig, base: Path | None = None) -> Model:
    """Everything that can be checked without solving: build the model (meshes checked by
    :func:`vfem.mesh.checks.check_mesh`), each body's constraints (a body that could move freely
    is named with its free motion) and the contact surfaces (bodies that start deeper into each
    other than the outer layer of elements are refused)."""
    model = config.build(base)
    for body in model.bodies:
        body.check_supports()
    from .parallel import current

    model.contact_surfaces(current())  # (the pairs' search spread over MPI ranks: kept)
    return model


def as_parameters(**kwargs) -> tuple[tuple[str, Any], ...]:
    """Shape parameters as the frozen, hashable tuple :class:`MeshSpec` keeps (lists and
    arrays become tuples; NumPy scalars become Python numbers, so they print exactly)."""
    def plain(v):
        if isinstance(v, (list, tuple, np.ndarray)):
            return tuple(plain(x) for x in v)
        if isinstance(v, np.generic):
            return v.item()
        return v
    return tuple((k, plain(v)) for k, v in kwargs.items())
