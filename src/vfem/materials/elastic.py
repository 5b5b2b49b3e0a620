"""Isotropic linear elasticity in plane strain, plane stress, axisymmetry or 3D."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from .constants import check_elastic_constants
from .hyperelastic import LAWS

if TYPE_CHECKING:
    from .protocol import Material

PLANE_STRAIN = "strain"
PLANE_STRESS = "stress"


@dataclass(frozen=True)
class LinearElastic:
    """Isotropic, linearly elastic material.

    Attributes:
        youngs_modulus: E, > 0.
        poissons_ratio: nu, in (-1, 0.5).
        plane: ``"strain"`` (default), ``"stress"`` or ``"axisymmetric"``; the out-of-plane
            assumption of a 2D body (its section): a slice of a long body, a thin plate, or a
            body of revolution about the y axis (x = r >= 0, y = z; forces per full circle;
            small kinematics; a model's bodies share it).
    """

    youngs_modulus: float
    poissons_ratio: float
    plane: str = PLANE_STRAIN

    #: Whether a body of this material carries a state from step to step (a plastic one,
    #: issue 41), and so answers its contact forces by Newton's method under small kinematics
    #: too (:attr:`vfem.bodies.Body.iterates`): not an elastic one.
    carries_state: ClassVar[bool] = False

    def validate(self, where: str = "material") -> None:
        """Raise :class:`InputError` naming ``where`` if the constants are not admissible.
        ``plane`` is the body's section's name, checked with it
        (:func:`vfem.bodies.section.section_of`)."""
        check_elastic_constants(self.youngs_modulus, self.poissons_ratio, where)

    def law(self, name: str, kinematics: str = "total") -> Material:
        """The constitutive law (:class:`~vfem.materials.protocol.Material`) a body of this
        material evaluates where it iterates (:mod:`vfem.nonlinear`): the hyperelastic law
        ``name`` (the body's ``law``, :data:`~vfem.materials.hyperelastic.LAWS`) whose
        small-strain constants are the material's, whatever the large ``kinematics``. A
        material with its own law (and state) answers with it."""
        return LAWS[name](self.youngs_modulus, self.poissons_ratio)

    def lame(self) -> tuple[float, float]:
        """Lamé constants (lambda, mu) of the 2D model (lambda modified for plane stress)."""
        E, nu = self.youngs_modulus, self.poissons_ratio
        mu = E / (2.0 * (1.0 + nu))
        lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        if self.plane == PLANE_STRESS:
            lam = 2.0 * lam * mu / (lam + 2.0 * mu)
        return lam, mu

    def plane_strain_modulus(self) -> float:
        """E/(1-nu^2), E in plane stress: the modulus in Hertz's E* (a slice in plane strain, a
        body of revolution and a 3D body alike)."""
        E, nu = self.youngs_modulus, self.poissons_ratio
        return E if self.plane == PLANE_STRESS else E / (1.0 - nu**2)
