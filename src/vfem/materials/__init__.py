"""Constitutive models. Linear elasticity is the small-strain default; the hyperelastic laws are
for large deformations (:mod:`vfem.nonlinear`), which evaluates any law that keeps the
:class:`Material` protocol (:mod:`.protocol`: stress, tangent and a state carried from step to
step).

A body's ``material`` is one of :data:`MATERIALS`, the tables an input file's
``[bodies.material]`` may hold (:mod:`vfem.config` reads it as :data:`MaterialTable`, the key
reference lists each): its elastic constants and ``plane`` (the body's section), its checks
(``validate``), whether its bodies carry a state (``carries_state``: they then iterate under
small kinematics too) and the law they evaluate where they iterate (``law(name, kinematics)``,
the body's hyperelastic law's name and its kinematics). A material with parameters of its own
is one more class there: :class:`J2Plastic` (a yield stress and hardening, issue 41;
:mod:`.plastic`), read in the logarithmic strain under large kinematics (:mod:`.logstrain`).
"""

from typing import Union

from .elastic import LinearElastic
from .hyperelastic import LAWS, NeoHookean, SaintVenantKirchhoff
from .logstrain import LogarithmicStrain
from .plastic import J2Plastic
from .protocol import Material, Response, State

#: The material tables a body may be given, in the order an input file's ``[bodies.material]``
#: is tried against them (:func:`vfem.schema.convert`: the first whose keys fit)
MATERIALS: tuple[type, ...] = (LinearElastic, J2Plastic)
#: The type of a body's ``material`` in an input file: one of :data:`MATERIALS`
MaterialTable = Union[MATERIALS]  # noqa: UP007 - a union of a tuple built at run time

__all__ = ["J2Plastic", "LinearElastic", "LogarithmicStrain", "NeoHookean", "SaintVenantKirchhoff",
           "LAWS", "MATERIALS", "MaterialTable", "Material", "Response", "State"]
