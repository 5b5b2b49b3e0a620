"""The contact laws node by node: the thesis's compatibility and equilibrium corrections (Eq.
4.1-4.6), relaxation and the release of tension.

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .corrections import compatibility_displacement, equilibrium_force, relaxation, release_tension

__all__ = ["compatibility_displacement", "equilibrium_force", "relaxation", "release_tension"]
