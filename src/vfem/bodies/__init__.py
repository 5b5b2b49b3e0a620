"""One deformable body: mesh, material, supports and loads, with its own stiffness and
factorization.

Bodies never share a matrix. Contact reaches a body only as nodal forces on its contact surface,
so for a linear body the whole response the contact algorithm needs is

    u = load_factor * u_load + platen_displacement * u_platen + K^-1 f_contact

where ``u_load`` is the solution under the body's loads and prescribed displacements at load factor
1, ``u_platen`` the solution for a unit motion of its force-controlled platen (if any), and
``K^-1`` is applied with the body's own factorization, supports kept.

The public face of the package (:class:`Body` and the boundary conditions it takes). Its modules,
one responsibility each:

* :mod:`.body` -- :class:`Body`, what the user defines and the one entry point to the rest;
* :mod:`.discretisation` -- the elements, the points carrying the dofs, their numbering, cells;
* :mod:`.loads` -- supports, prescribed displacements, tractions, platens, load curves, and the
  constrained dofs and load cases they make;
* :mod:`.validation` -- the checks of a body's definition and supports;
* :mod:`.assembly` -- the 3D stiffness, a chunk of elements at a time;
* :mod:`.condensation` -- stiffness, factorization, load cases' solves, the flexibility on the
  contact dofs;
* :mod:`.mechanics` -- how the body answers its contact forces, linearly or under large
  kinematics (:class:`~.mechanics.BodyMechanics`);
* :mod:`.reactions` -- the constraints' forces on the body;
* :mod:`.stresses`, :mod:`.results` -- the stresses and one body's results.
"""

from .body import Body
from .discretisation import COMPONENTS
from .loads import (
    AllComponents,
    LoadCase,
    Platen,
    PrescribedDisplacement,
    Support,
    Traction,
    check_amplitude,
    curve_key,
    multiplier,
    superpose,
)
from .mechanics import Linearization

__all__ = ["Body", "Support", "PrescribedDisplacement", "Traction", "Platen", "Linearization",
           "LoadCase", "check_amplitude", "multiplier", "superpose", "curve_key", "AllComponents",
           "COMPONENTS"]
