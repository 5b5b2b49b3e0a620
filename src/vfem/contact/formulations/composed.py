"""A formulation composed of parts: a paired formulation (small or large kinematics) and the
friction part it holds (issue 38: formulations composed, not one class per combination).

:func:`~vfem.contact.formulations.formulation.formulation_class` hands the solver a
:class:`Composed` where a model has friction: it declares its capabilities as data, as a class
does, and builds the formulation with its friction part when called with the formulation's
arguments.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..capabilities import Capabilities


@dataclass(frozen=True)
class Composed:
    """``formulation`` (a paired formulation's class) holding a ``friction`` part (a class
    built with the formulation and its settings), with the composition's ``capabilities``."""

    formulation: type
    friction: type
    capabilities: Capabilities

    def __call__(self, surfaces, pairs, settings, backend: str | None = None, **options):
        """The formulation, built with its friction part; it answers with the composition's
        capabilities."""
        out = self.formulation(surfaces, pairs, settings, backend, friction=self.friction,
                               **options)
        out.capabilities = self.capabilities
        return out
