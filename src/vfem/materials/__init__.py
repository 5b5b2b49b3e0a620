"""Constitutive models. Linear elasticity is the small-strain default; the hyperelastic laws are
for large deformations (:mod:`vfem.nonlinear`)."""

from .elastic import LinearElastic
from .hyperelastic import NeoHookean, SaintVenantKirchhoff

__all__ = ["LinearElastic", "NeoHookean", "SaintVenantKirchhoff"]
