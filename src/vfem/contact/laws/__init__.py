"""The contact laws node by node: the thesis's compatibility and equilibrium corrections (Eq.
4.1-4.6), relaxation and the release of tension; Coulomb's law (§1.10) in any dimension.

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .corrections import compatibility_displacement, equilibrium_force, relaxation, release_tension
from .coulomb import (
    CONE_TOLERANCE,
    coulomb_status,
    magnitudes,
    tangent_axes,
    tangent_by_tangent,
    tangents,
)

__all__ = [
    "compatibility_displacement",
    "CONE_TOLERANCE",
    "coulomb_status",
    "equilibrium_force",
    "magnitudes",
    "relaxation",
    "release_tension",
    "tangent_axes",
    "tangent_by_tangent",
    "tangents",
]
