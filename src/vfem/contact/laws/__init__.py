"""The contact laws node by node: the thesis's compatibility and equilibrium corrections (Eq.
4.1-4.6), relaxation and the release of tension; Coulomb's law (§1.10) in any dimension, and the
friction laws a pair may follow, node by node through one protocol (:class:`FrictionLaw`).

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .corrections import compatibility_displacement, equilibrium_force, relaxation, release_tension
from .coulomb import (
    CONE_TOLERANCE,
    coulomb_status,
    magnitudes,
    tangent_by_tangent,
)
from .friction_laws import (
    FRICTION_LAWS,
    FrictionLaw,
    beyond_cone,
    friction_law,
    law_bounds,
    law_record,
    law_text,
    reaches_cone,
    slip_onset,
)

__all__ = [
    "beyond_cone",
    "FRICTION_LAWS",
    "friction_law",
    "FrictionLaw",
    "law_bounds",
    "law_record",
    "law_text",
    "reaches_cone",
    "slip_onset",
    "compatibility_displacement",
    "CONE_TOLERANCE",
    "coulomb_status",
    "equilibrium_force",
    "magnitudes",
    "relaxation",
    "release_tension",
    "tangent_by_tangent",
]
