"""A body's section: what its out-of-plane assumption decides, in one object.

A 2D body stands for a 3D one by an assumption about the third direction: a slice of a long
body (plane strain: no strain across it), a thin plate (plane stress: no stress across it), or
a body of revolution (issue 42) (axisymmetric: the hoop strain u_r / r, and a
measure 2πr). A 3D body has none. Every integral of a small-kinematics body reads its section
rather than the material's ``plane`` or the mesh's dimension (the plane-stress λ is the
material's :meth:`~vfem.materials.LinearElastic.lame`; a Newton body of :mod:`vfem.nonlinear`
(large kinematics, or a law with state) is told only whether it turns about an axis):

* :meth:`Section.weight` — the measure per unit of the mesh's own length, area or volume at given
  points: 1 here (2πr, or r per radian, for a body of revolution). The body's tractions
  (:func:`vfem.bodies.loads.traction_vector`), the contact surface's mass matrix N*
  (:mod:`vfem.contact.geometry.measure`), the transfer's overlap quadrature
  (:meth:`Segment.overlap_quadrature
  <vfem.contact.geometry.facets.Segment.overlap_quadrature>`), the thesis variant's opposing
  traction (:mod:`vfem.contact.formulations.algorithm`) and the invariants' consistent tension
  measure (:meth:`Section.facet_mass`) multiply by it;
* the stiffness (:meth:`Section.stiffness`), the element-average strains and stresses
  (:meth:`Section.average_strain_operator`, :meth:`Section.stress`: the out-of-plane stress)
  and the strain the solver's warning reads (:meth:`Section.max_strain`);
* the rigid-body motions the supports must hold (:meth:`Section.rigid_modes`);
* the modulus of Hertz's E* (:meth:`Section.contact_modulus`), and whether large kinematics
  (:mod:`vfem.nonlinear`) has the section (:attr:`Section.takes_large`);
* :attr:`Section.space`: the bodies of one model share it (:meth:`vfem.model.Model.validate`).

A section is chosen per body by :func:`section_of` from its mesh's dimension and its material's
``plane``, from the registry :data:`SECTIONS` (by the ``plane`` name, for 2D bodies) and
:data:`SOLID` (3D); a new section is a class here and an entry in :data:`SECTIONS`
(``docs/dev/walkthrough.md``, section 1).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementVector, asm
from skfem.models.elasticity import linear_elasticity

from ..errors import InputError
from .assembly import elasticity_stiffness
from .stresses import (
    axisymmetric_average_strain_operator,
    axisymmetric_max_strain,
    axisymmetric_small_strain_stress,
    plane_average_strain_operator,
    plane_max_strain,
    plane_small_strain_stress,
    solid_average_strain_operator,
    solid_max_strain,
    solid_small_strain_stress,
)

#: The consistent mass ∫φφᵀ of a straight facet per unit length: 2-node (ends), 3-node (ends,
#: midpoint)
_FACET_MASS = {2: np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0,
               3: np.array([[4.0, -1.0, 2.0], [-1.0, 4.0, 2.0], [2.0, 2.0, 16.0]]) / 30.0}


class Section(Protocol):
    """What a body's out-of-plane assumption decides (the module's docstring)."""

    #: ``"plane strain"``, ``"plane stress"``, ``"3D"``: in messages
    name: str
    #: the bodies of one model share it (issue 42: all plane strain, all plane stress, all
    #: axisymmetric or all 3D): ``"plane strain"``, ``"plane stress"``, ``"axisymmetric"``,
    #: ``"3D"``
    space: str
    #: whether large kinematics (:mod:`vfem.nonlinear`) has this section
    takes_large: bool
    #: the force components whose sum over a body's nodes is a resultant the body must balance
    #: (None: all; a body of revolution's axial one alone, its radial forces cancelling round
    #: the ring)
    resultant: tuple[int, ...] | None
    #: whether its small strain is sym(∇u) alone (a body of revolution's also has u_r / r):
    #: what the strain warning's screen bounds (:func:`~.stresses.strain_beyond`)
    strain_is_gradient: bool

    def weight(self, x: np.ndarray) -> np.ndarray | float:
        """The measure per unit of the mesh's length, area or volume at the points ``x``
        (coordinates first: (dim, ...)): 1, or an array of the points' shape."""
        ...

    def facet_mass(self, x: np.ndarray, facets: np.ndarray) -> np.ndarray:
        """(nf, k, k): ∫φφᵀ times the weight over each straight facet of ``k`` nodes of a 2D
        boundary (positions ``x`` (n, 2))."""
        ...

    def not_surface(self, mesh, facets: np.ndarray) -> np.ndarray:
        """(len(facets),) which of the mesh's boundary ``facets`` are not the body's surface,
        and so can touch nothing (a body of revolution's axis); none elsewhere."""
        ...

    def basis(self, body) -> Basis | None:
        """The body's vector basis, kept for its strains (None: none kept, :attr:`Body.basis
        <vfem.bodies.Body.basis>`)."""
        ...

    def stiffness(self, body, lam: float, mu: float, elements: np.ndarray | None = None
                  ) -> sp.csr_matrix:
        """The body's small-strain stiffness for the Lamé constants (lam, mu); with
        ``elements`` (sorted element numbers) only theirs, same size and numbering (a
        subdomain's Neumann matrix, :mod:`vfem.bodies.subdomains`)."""
        ...

    def average_strain_operator(self, body) -> sp.csr_matrix:
        """The sparse operator from a displacement to each element's average strain."""
        ...

    def stress(self, body, u: np.ndarray) -> dict[str, np.ndarray]:
        """Element-average linear-elastic stresses at ``u``, with von Mises."""
        ...

    def max_strain(self, body, u: np.ndarray) -> tuple[float, int]:
        """The largest absolute principal small strain and its element."""
        ...

    def rigid_modes(self, points: np.ndarray) -> dict[str, np.ndarray]:
        """The rigid-body motions by name, each (npoints, dim), of the points (dim, npoints)."""
        ...

    def contact_modulus(self, material) -> float:
        """The modulus of Hertz's E* for the material (E / (1 - nu^2), or E in plane stress)."""
        ...


def _basis_on(body, elements: np.ndarray | None) -> Basis:
    """A 2D body's vector basis: its own, or (``elements``) one on those elements alone, the
    same element and quadrature (a subdomain's, :mod:`vfem.bodies.subdomains`)."""
    if elements is None:
        return body.basis
    return Basis(body.mesh, ElementVector(body.element()), elements=np.asarray(elements))


class _Plane:
    """A 2D section of measure 1 (plane strain or plane stress): what they share."""

    resultant = None

    strain_is_gradient = True

    def __repr__(self) -> str:
        return f"<section {self.name}>"

    def weight(self, x):
        return 1.0

    def not_surface(self, mesh, facets):
        return np.zeros(len(facets), dtype=bool)

    def facet_mass(self, x, facets):
        L = np.linalg.norm(x[facets[:, 1]] - x[facets[:, 0]], axis=1)
        return L[:, None, None] * _FACET_MASS[facets.shape[1]][None]

    def basis(self, body):
        return Basis(body.mesh, ElementVector(body.element()))

    def stiffness(self, body, lam, mu, elements=None):
        return asm(linear_elasticity(lam, mu), _basis_on(body, elements)).tocsr()

    def average_strain_operator(self, body):
        return plane_average_strain_operator(body)

    def stress(self, body, u):
        return plane_small_strain_stress(body, u, self.out_of_plane)

    def max_strain(self, body, u):
        return plane_max_strain(body, u)

    def rigid_modes(self, points):
        x, y = points
        return {"translation in x": np.column_stack([np.ones_like(x), 0 * y]),
                "translation in y": np.column_stack([0 * x, np.ones_like(y)]),
                "rotation": np.column_stack([-(y - y.mean()), x - x.mean()])}


class PlaneStrain(_Plane):
    """A slice of a long body: no strain across it, szz = nu (sxx + syy)."""

    name = "plane strain"
    plane = "strain"
    space = "plane strain"
    takes_large = True

    @staticmethod
    def out_of_plane(avg, nu):
        return nu * (avg["sxx"] + avg["syy"])

    def contact_modulus(self, material):
        return material.plane_strain_modulus()  # E / (1 - nu^2)


class PlaneStress(_Plane):
    """A thin plate: no stress across it (the material's lambda modified,
    :meth:`~vfem.materials.LinearElastic.lame`)."""

    name = "plane stress"
    plane = "stress"
    space = "plane stress"
    takes_large = False

    @staticmethod
    def out_of_plane(avg, nu):
        return np.zeros_like(avg["sxx"])

    def contact_modulus(self, material):
        return material.youngs_modulus


class Solid:
    """A 3D body: no assumption, measure 1."""

    name = "3D"
    space = "3D"
    resultant = None
    takes_large = True
    strain_is_gradient = True

    def __repr__(self) -> str:
        return "<section 3D>"

    def weight(self, x):
        return 1.0

    def not_surface(self, mesh, facets):
        return np.zeros(len(facets), dtype=bool)

    def facet_mass(self, x, facets):
        raise NotImplementedError("a 3D body's boundary is a surface: no facet mass of lines")

    def basis(self, body):
        # scikit-fem's per-pair loop takes minutes at 3D sizes (assembly.py), and its basis,
        # 147 KB a hexahedron, is not kept (:attr:`Body.basis`)
        return None

    def stiffness(self, body, lam, mu, elements=None):
        if elements is not None:  # a subdomain's share: no gradient bound kept
            return elasticity_stiffness(body.mesh, body.element(), lam, mu,
                                        body.dof_map.element_dofs, which=elements)
        # the strain screen's gradient bound from the assembly's own gradients (no pass of its
        # own: :func:`~vfem.bodies.stresses.strain_beyond`)
        bound = np.empty(body.mesh.nelements)
        K = elasticity_stiffness(body.mesh, body.element(), lam, mu,
                                 body.dof_map.element_dofs, gradient_bound=bound)
        body.__dict__["_gradient_bound"] = (body.mesh, bound)
        return K

    def average_strain_operator(self, body):
        return solid_average_strain_operator(body)

    def stress(self, body, u):
        return solid_small_strain_stress(body, u)

    def max_strain(self, body, u):
        return solid_max_strain(body, u)

    def rigid_modes(self, points):
        X = points - points.mean(axis=1, keepdims=True)
        zero, one = np.zeros(X.shape[1]), np.ones(X.shape[1])
        x, y, z = X
        return {"translation in x": np.column_stack([one, zero, zero]),
                "translation in y": np.column_stack([zero, one, zero]),
                "translation in z": np.column_stack([zero, zero, one]),
                "rotation about x": np.column_stack([zero, -z, y]),
                "rotation about y": np.column_stack([z, zero, -x]),
                "rotation about z": np.column_stack([-y, x, zero])}

    def contact_modulus(self, material):
        return material.plane_strain_modulus()  # E / (1 - nu^2)


class Axisymmetric(_Plane):
    """A body of revolution about the y axis (issue 42): its mesh is the r-z half-plane,
    x = r >= 0 and y = z, every field independent of the angle and without twist. The strain
    has the hoop component u_r / r beside sym(grad u), and every integral the measure 2 pi r
    (the weight: per **full circle**, as Abaqus's and CalculiX's axisymmetric elements read
    their concentrated loads: a platen's force, a reaction, a contact force is the ring's
    whole force). Stresses: sxx = s_rr, syy = s_zz, sxy = s_rz and szz the hoop stress
    s_tt (the third direction's, as plane strain's szz is). The only rigid motion is along the
    axis; the material's Lamé constants are its 3D ones, and Hertz's modulus E / (1 - nu^2)."""

    name = "axisymmetric"
    plane = "axisymmetric"
    space = "axisymmetric"
    resultant = (1,)  # along the axis: the radial forces of a ring cancel round it
    takes_large = True  # (vfem.nonlinear's 3x3 tensors about the axis)
    strain_is_gradient = False  # the hoop strain u_r / r too

    def weight(self, x):
        return 2.0 * np.pi * np.asarray(x)[0]

    def not_surface(self, mesh, facets):
        # a facet on the axis (both ends at r = 0, to round-off of the mesh's size) bounds the
        # r-z section but not the body: it has no area (2 pi r = 0) and touches nothing
        span = float(np.ptp(mesh.p, axis=1).max())
        return np.all(np.abs(mesh.p[0, mesh.facets[:, facets]]) <= 1e-12 * span, axis=0)

    def facet_mass(self, x, facets):
        # ∫ φ_a φ_b 2πr ds over each straight facet: r is linear along it, so three Gauss
        # points are exact for the 2-node (cubic) and the 3-node (quintic) facets
        t, wt = np.polynomial.legendre.leggauss(3)
        t, wt = 0.5 * (t + 1.0), 0.5 * wt
        if facets.shape[1] == 2:
            phi = np.stack([1.0 - t, t])
        else:
            phi = np.stack([(1 - t) * (1 - 2 * t), t * (2 * t - 1), 4 * t * (1 - t)])
        ends = x[facets[:, :2]]  # (nf, 2, 2)
        L = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
        at = ends[:, 0, :, None] * (1 - t) + ends[:, 1, :, None] * t  # (nf, 2, q)
        w = self.weight(np.moveaxis(at, 1, 0)) * wt[None] * L[:, None]  # (nf, q)
        return np.einsum("aq,bq,fq->fab", phi, phi, w)

    def stiffness(self, body, lam, mu, elements=None):
        return asm(_axisymmetric_elasticity(lam, mu), _basis_on(body, elements)).tocsr()

    def average_strain_operator(self, body):
        return axisymmetric_average_strain_operator(body)

    def stress(self, body, u):
        return axisymmetric_small_strain_stress(body, u)

    def max_strain(self, body, u):
        return axisymmetric_max_strain(body, u)

    def rigid_modes(self, points):
        x, y = points
        return {"translation along the axis (y)": np.column_stack([0 * x, np.ones_like(y)])}

    def contact_modulus(self, material):
        return material.plane_strain_modulus()  # E / (1 - nu^2)


def _axisymmetric_elasticity(lam: float, mu: float):
    """The bilinear form of isotropic linear elasticity on a body of revolution: ∫ (lam
    tr e(u) tr e(v) + 2 mu e(u) : e(v)) 2 pi r dA, e = (du_r/dr, du_z/dz, u_r / r and the
    shear (du_r/dz + du_z/dr) / 2, which counts twice in e : e)."""
    from skfem import BilinearForm

    def strains(f, r):
        g = f.grad
        return g[0, 0], g[1, 1], f[0] / r, 0.5 * (g[0, 1] + g[1, 0])

    @BilinearForm
    def form(u, v, w):
        r = w.x[0]
        a, b = strains(u, r), strains(v, r)
        tra, trb = a[0] + a[1] + a[2], b[0] + b[1] + b[2]
        return 2.0 * np.pi * r * (lam * tra * trb + 2.0 * mu * (
            a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2.0 * a[3] * b[3]))

    return form


#: The 2D sections by the material's ``plane`` name
SECTIONS: dict[str, Section] = {s.plane: s for s in (PlaneStrain(), PlaneStress(),
                                                      Axisymmetric())}
#: A 3D body's section
SOLID: Section = Solid()
#: The spaces a model's bodies may share, in the order messages name them
SPACES = tuple(dict.fromkeys([*(s.space for s in SECTIONS.values()), SOLID.space]))


def check_plane(plane: str, where: str) -> None:
    """Raise :class:`InputError` naming ``where`` unless ``plane`` names a 2D section."""
    if plane not in SECTIONS:
        names = " or ".join(repr(name) for name in SECTIONS)
        raise InputError(f"{where}: plane must be {names}, got {plane!r}")


def section_of(body) -> Section:
    """The section of ``body`` from its mesh's dimension and its material's ``plane``; raises
    :class:`InputError` naming the body for a plane that is not a section's name, or a plane
    given to a 3D body (whose default, ``"strain"``, says nothing)."""
    where = f"body {body.name!r}"
    plane = body.material.plane
    check_plane(plane, f"{where}, material")
    if body.dim == 3:
        if plane != PlaneStrain.plane:
            raise InputError(f"{where}: plane = {plane!r} is an assumption of 2D bodies; a 3D "
                             "body (tetrahedra or hexahedra) has none: leave the material's "
                             "plane out")
        return SOLID
    return SECTIONS[plane]


__all__ = ["SECTIONS", "SOLID", "SPACES", "Axisymmetric", "PlaneStrain", "PlaneStress",
           "Section", "Solid", "check_plane", "section_of"]
