"""Constitutive models. Linear elasticity is the small-strain default; the hyperelastic laws are
for large deformations (:mod:`vfem.nonlinear`), which evaluates any law that keeps the
:class:`Material` protocol (:mod:`.protocol`: stress, tangent and a state carried from step to
step)."""

from .elastic import LinearElastic
from .hyperelastic import LAWS, NeoHookean, SaintVenantKirchhoff
from .protocol import Material, Response, State

__all__ = ["LinearElastic", "NeoHookean", "SaintVenantKirchhoff", "LAWS", "Material", "Response",
           "State"]
