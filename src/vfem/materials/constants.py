"""The elastic constants every isotropic material of vfem is given, and their check: the linear
elastic material (:mod:`.elastic`) and the hyperelastic laws built from its constants
(:mod:`.hyperelastic`) read them alike."""

from __future__ import annotations

import math

from ..errors import InputError


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
