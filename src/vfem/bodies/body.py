"""The body itself: what the user defines (mesh, material, supports, loads, order, kinematics)
and the state its set-up computes (stiffness, factorization, load cases), with the operations
contact and the solver call on it. Each operation lives with its responsibility, in a module of
its own: the element and dof numbering (:mod:`.discretisation`), supports and loads
(:mod:`.loads`), checks (:mod:`.validation`), stiffness, factorization and flexibility
(:mod:`.condensation`), reactions (:mod:`.reactions`), the response to contact forces
(:mod:`.mechanics`); ``Body`` is their one entry point."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from skfem import Basis, MeshHex, MeshQuad, MeshTet, MeshTri
from skfem.assembly import Dofs

from ..materials import LinearElastic
from . import condensation, discretisation, loads, reactions, validation
from .discretisation import AXES
from .loads import AllComponents, Platen, PrescribedDisplacement, Support, Traction
from .mechanics import BodyMechanics, Linearization, LinearMechanics
from .section import Section, section_of


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
        kinematics: ``"small"`` (default: small displacements and strains, linear elasticity
            or small-strain plasticity) or large displacements and strains, by the ``"total"``
            or ``"updated"`` Lagrangian formulation (thesis Chapters 2-3; plane strain or 3D,
            linear elements; a plastic material at finite strain).
        law: under large kinematics, the hyperelastic law whose small-strain constants are the
            material's: ``"saint-venant-kirchhoff"`` (default), ``"neo-hookean"``
            (Ciarlet–Simo) or ``"neo-hookean-isochoric"`` (CalculiX's and Abaqus's NEO HOOKE)
            (a plastic material has its own law: Hencky elasticity in the logarithmic strain).
        self_contact: whether its contact surface (``contact_boundaries``, or its whole free
            surface) may touch itself: one self-contact pair of two sides found on the
            undeformed geometry (:func:`vfem.contact.geometry.own_sides.split`).
        subdomains: 1 (default) to factorize the body whole; K > 1 to split its elements into
            K subdomains (METIS) glued on their interfaces and solved by BDDC
            (:mod:`.subdomains`, issue 43): the same answers to 1e-8. Linear bodies only
            (small kinematics, elastic).

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
    self_contact: bool = False
    subdomains: int = 1

    @property
    def dim(self) -> int:
        """The body's dimension, 2 or 3: its mesh's number of coordinates."""
        return int(self.mesh.p.shape[0])

    @property
    def section(self) -> Section:
        """The body's section: what its out-of-plane assumption decides (plane strain, plane
        stress, 3D; :mod:`.section`), from its mesh and its material's ``plane``."""
        return section_of(self)

    @property
    def components(self) -> tuple[str, ...]:
        """The body's displacement components: ``("x", "y")``, or ``("x", "y", "z")`` in 3D."""
        return AXES[: self.dim]

    def symmetry_planes(self) -> list[tuple[np.ndarray, int]]:
        """The body's symmetry planes (:func:`.loads.symmetry_planes`)."""
        return loads.symmetry_planes(self)

    def support_components(self, support: Support) -> tuple[str, ...]:
        """The components ``support`` fixes on this body: its own, or by default
        (:class:`AllComponents`) all of the body's."""
        if isinstance(support.components, AllComponents):
            return self.components
        return tuple(support.components)

    @property
    def large(self) -> bool:
        """Whether the body is analysed under large displacements (see ``kinematics``): its
        geometry is the deformed one (where contact pairs it, how the invariants read it)."""
        return self.kinematics != "small"

    @property
    def iterates(self) -> bool:
        """Whether the body's response to its contact forces is nonlinear, so that contact
        corrects it by Newton's method (:meth:`.mechanics.BodyMechanics.linearize`) instead of
        through its constant flexibility: under large kinematics, or where its material carries
        a state from step to step (``carries_state``: a plastic one, issue 41), under small
        kinematics too. Where the code asks how a body responds it reads this; where it asks
        which geometry, :attr:`large`."""
        return self.large or self.material.carries_state

    # -- set-up (vfem.bodies.condensation) --------------------------------------------------------

    def assemble(self, stiffness: bool = True) -> dict[int, float]:
        """Validate and assemble without factorizing (:func:`.condensation.assemble`; without
        the stiffness on an MPI rank that does not own the body); returns the prescribed value
        of every supported or prescribed dof."""
        return condensation.assemble(self, stiffness)

    def setup(self, backend: str | None = None, condensed_dofs: np.ndarray | None = None,
              assembled: dict[int, float] | None = None) -> None:
        """Validate, assemble, factorize and solve the load cases
        (:func:`.condensation.setup`); with ``condensed_dofs``, keep the flexibility among
        them (``condensed_flexibility``); ``assembled``: what :meth:`assemble` returned, if
        it was called already (then not again)."""
        condensation.setup(self, backend, condensed_dofs, assembled)

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
        validation.check_supports(self)

    def validate(self) -> None:
        """Raise :class:`InputError` naming the body if its definition cannot be analysed
        (:func:`.validation.validate`)."""
        validation.validate(self)

    # -- loads (vfem.bodies.loads) ------------------------------------------------------------

    def load_displacement(self, load_factor: float, dofs: np.ndarray | None = None
                          ) -> np.ndarray:
        """Small kinematics: the displacement due to the loads at ``load_factor``
        (:func:`.loads.load_displacement`)."""
        return loads.load_displacement(self, load_factor, dofs)

    def platen_load_reaction_at(self, load_factor: float) -> float:
        """Small kinematics: the platen's reaction to the loads at ``load_factor``
        (:func:`.loads.platen_load_reaction_at`)."""
        return loads.platen_load_reaction_at(self, load_factor)

    def prescribed_at(self, load_factor: float) -> np.ndarray:
        """(ndofs) the constrained dofs' prescribed values at ``load_factor``
        (:func:`.loads.prescribed_at`)."""
        return loads.prescribed_at(self, load_factor)

    def applied_load(self, load_factor: float) -> np.ndarray:
        """The body's applied nodal loads (ndofs) at ``load_factor``
        (:func:`.reactions.applied_load`)."""
        return reactions.applied_load(self, load_factor)

    # -- elements and dofs (vfem.bodies.discretisation) ---------------------------------------

    def element(self):
        """The scalar scikit-fem element of each displacement component."""
        return discretisation.element(self)

    @cached_property
    def points(self) -> np.ndarray:
        """(dim, npoints) coordinates of the element nodes (see the class docstring)."""
        return discretisation.points(self)

    @property
    def npoints(self) -> int:
        return self.points.shape[1]

    def facet_points(self, facets: np.ndarray) -> np.ndarray:
        """(nf, k) points of the given facets (:func:`.discretisation.facet_points`)."""
        return discretisation.facet_points(self, facets)

    def boundary_points(self, boundary: str) -> np.ndarray:
        """Sorted points on a named boundary."""
        return np.unique(self.facet_points(self.mesh.boundaries[boundary]))

    def cells(self) -> tuple[str, np.ndarray]:
        """VTK cell type and (nelements, k) point connectivity in VTK's node order
        (:func:`.discretisation.cells`)."""
        return discretisation.cells(self)

    @property
    def basis(self) -> Basis:
        """scikit-fem's ``CellBasis`` of the body's vector element
        (:func:`.discretisation.basis`)."""
        return discretisation.basis(self)

    @basis.setter
    def basis(self, value: Basis) -> None:
        self._basis = value

    @property
    def dof_map(self) -> Dofs:
        """scikit-fem's numbering of the body's dofs (the vector element's), as its basis has
        it, without the basis."""
        return discretisation.dof_map(self)

    @property
    def K_ff(self):
        """The stiffness's block of the free dofs (``free_dofs``), CSC: what :meth:`setup`
        factorizes; formed when asked, not kept."""
        return self.K[self.free_dofs][:, self.free_dofs].tocsc()

    # -- what the contact algorithm uses (vfem.bodies.condensation) -----------------------------

    def response(self, nodal_force: np.ndarray) -> np.ndarray:
        """Displacement due to nodal forces (ndofs), supports kept at zero: K^-1 f."""
        return condensation.response(self, nodal_force)

    def free_positions(self, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where body dofs ``dofs`` stand among the free dofs, and which of them are free
        (:func:`.condensation.free_positions`)."""
        return condensation.free_positions(self, dofs)

    def flexibility_columns(self, dofs: np.ndarray, chunk: int = 256) -> np.ndarray:
        """Columns of K^-1 (supports kept) for the given dofs, shape (ndofs, len(dofs))
        (:func:`.condensation.flexibility_columns`)."""
        return condensation.flexibility_columns(self, dofs, chunk)

    def displacement(self, load_factor: float, platen_displacement: float,
                     contact_force: np.ndarray) -> np.ndarray:
        """Full displacement vector (ndofs) for the given state (:attr:`mechanics`)."""
        return self.mechanics.displacement(load_factor, platen_displacement, contact_force)

    # -- reactions (vfem.bodies.reactions) -----------------------------------------------------

    def nodal_reaction(self, u: np.ndarray, load_factor: float = 1.0,
                       contact_force: np.ndarray | None = None) -> np.ndarray:
        """The nodal forces (ndofs) the constraints apply to the body
        (:func:`.reactions.nodal_reaction`)."""
        return reactions.nodal_reaction(self, u, load_factor, contact_force)

    def reaction_dofs(self) -> dict[str, np.ndarray]:
        """Per constrained boundary, the dofs its own conditions constrain
        (:func:`.reactions.reaction_dofs`)."""
        return reactions.reaction_dofs(self)

    def boundary_reactions(self, nodal_reaction: np.ndarray) -> dict[str, tuple[float, ...]]:
        """Per constrained boundary, the total of ``nodal_reaction`` by component
        (:func:`.reactions.boundary_reactions`)."""
        return reactions.boundary_reactions(self, nodal_reaction)

    def reaction_of(self, result, boundary: str, component: str) -> float:
        """Total force the supports on ``boundary`` apply to the body along ``component`` in a
        converged step's results ``result`` (:func:`.reactions.reaction_of`: no stiffness
        read, so on any MPI rank)."""
        return reactions.reaction_of(self, result, boundary, component)

    def reaction(self, u: np.ndarray, boundary: str, component: str, load_factor: float = 1.0,
                 contact_force: np.ndarray | None = None) -> float:
        """Total force the supports on ``boundary`` apply to the body along ``component``
        (:func:`.reactions.reaction`)."""
        return reactions.reaction(self, u, boundary, component, load_factor, contact_force)
