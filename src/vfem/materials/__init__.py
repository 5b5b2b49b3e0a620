"""Constitutive models. Linear elasticity is the small-strain default."""

from .elastic import LinearElastic

__all__ = ["LinearElastic"]
