"""The contact formulations, composed from the stages below: the paired variant (small and large
kinematics, frictionless and Coulomb), the thesis variant, the classical baselines and the
one-dimensional springs; ``formulation_class`` chooses one by the model's settings.

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .baselines import GlobalContact
from .formulation import check_capabilities, formulation_class
from .group import SurfaceGroup
from .large import LargeDeformationContact
from .onedim import SecantSpring, Step1D, solve_step
from .paired import PairedContact

__all__ = [
    "check_capabilities",
    "formulation_class",
    "GlobalContact",
    "LargeDeformationContact",
    "PairedContact",
    "SecantSpring",
    "solve_step",
    "Step1D",
    "SurfaceGroup",
]
