"""Isotropic linear elasticity in plane strain or plane stress."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

PLANE_STRAIN = "strain"
PLANE_STRESS = "stress"


def check_elastic_constants(E: float, nu: float, where: str) -> None:
    """Raise :class:`InputError` naming ``where`` unless E > 0 and -1 < nu < 0.5 (finite)."""
    if not (isinstance(E, (int, float)) and math.isfinite(E)) or E <= 0:
        raise InputError(f"{where}: youngs_modulus must be a finite number > 0, got {E!r}")
    if not (isinstance(nu, (int, float)) and math.isfinite(nu)) or not -1.0 < nu < 0.5:
        raise InputError(
            f"{where}: poissons_ratio must lie in (-1, 0.5), got {nu!r}"
            + (" (0.5 is incompressible, which displacement elements cannot represent)"
               if isinstance(nu, (int, float)) and nu >= 0.5 else "")
        )


@dataclass(frozen=True)
class LinearElastic:
    """Isotropic, linearly elastic material.

    Attributes:
        youngs_modulus: E, > 0.
        poissons_ratio: nu, in (-1, 0.5).
        plane: ``"strain"`` (default) or ``"stress"``; the out-of-plane assumption of a 2D body
            (its section, :mod:`vfem.bodies.section`).
    """

    youngs_modulus: float
    poissons_ratio: float
    plane: str = PLANE_STRAIN

    def validate(self, where: str = "material") -> None:
        """Raise :class:`InputError` naming ``where`` if the constants are not admissible.
        ``plane`` is the body's section's name, checked with it
        (:func:`vfem.bodies.section.section_of`)."""
        check_elastic_constants(self.youngs_modulus, self.poissons_ratio, where)

    def lame(self) -> tuple[float, float]:
        """Lamé constants (lambda, mu) of the 2D model (lambda modified for plane stress)."""
        E, nu = self.youngs_modulus, self.poissons_ratio
        mu = E / (2.0 * (1.0 + nu))
        lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        if self.plane == PLANE_STRESS:
            lam = 2.0 * lam * mu / (lam + 2.0 * mu)
        return lam, mu

    def plane_strain_modulus(self) -> float:
        """E/(1-nu^2) in plane strain, E in plane stress: the modulus in Hertz's E*."""
        E, nu = self.youngs_modulus, self.poissons_ratio
        return E / (1.0 - nu**2) if self.plane == PLANE_STRAIN else E
