"""The invariants every converged step must satisfy, read from the full-mesh results alone: force
balance, no interpenetration, no tension.

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .check import InvariantCheck, step_invariants
from .measures import Invariants

__all__ = ["InvariantCheck", "Invariants", "step_invariants"]
