"""The contract between a material law and the bodies that evaluate it (issue 38: the seam a
plastic law takes, without touching contact; under the total Lagrangian formulation, since the
updated one stands the left stretch for the deformation gradient, which only a law without
history allows, and refuses a law with state).

A body under large kinematics (:class:`vfem.nonlinear.NonlinearBody`) asks its material, at every
quadrature point of an iterate, for the second Piola-Kirchhoff stress ``S`` that answers the
Green-Lagrange strain ``E`` and the tangent ``dS/dE`` Newton's method needs (thesis Ch. 3), given
the **state** the material carries from the last converged step: nothing for an elastic law;
plastic strain, back stress and equivalent plastic strain for an elasto-plastic one (issue 41).

The state is a dict of arrays over the quadrature points, ``(..., nelements, nq)``. The body
keeps the converged one; an iterate's :class:`Response` says which state it *would* commit, and
the body commits it only when its step converges (:meth:`NonlinearBody.accept`), drops it when a
step is cut (:meth:`NonlinearBody.discard`) and saves it with the body's state (checkpoints,
``--resume``, :meth:`NonlinearBody.saved_state`), so a path-dependent law is restored bit for bit.

A law may also show what it will of its state: a method ``fields(state)`` giving named arrays
(nelements, nq) over the quadrature points (an equivalent plastic strain, a yielded flag), which
the body writes as element averages beside its stresses
(:meth:`NonlinearBody.cauchy_stress_at`, the VTU's cell fields). It is optional, outside the
protocol's runtime check: a law without it shows nothing.

The body that evaluates a law is one that iterates (:attr:`vfem.bodies.Body.iterates`): under
large kinematics, or of a material that carries state (its material table's ``law(name)``,
:mod:`vfem.materials`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

#: a material's state: named arrays over the quadrature points, ``(..., nelements, nq)``
State = dict[str, np.ndarray]


@dataclass
class Response:
    """What a material answers at the quadrature points of one iterate.

    Attributes:
        stress: ``S``, (dim, dim, nelements, nq).
        moduli: gives ``dS/dE``, (dim, dim, dim, dim, nelements, nq), when first asked: an
            iterate whose tangent is never assembled does not pay for it.
        out_of_plane: ``S_33`` (nelements, nq) of a plane-strain body; None in 3D.
        state: the state this iterate commits if its step converges (the given one, unchanged,
            for a law without history).
    """

    stress: np.ndarray
    moduli: Callable[[], np.ndarray]
    out_of_plane: np.ndarray | None
    state: State


@runtime_checkable
class Material(Protocol):
    """A material law a large-kinematics body evaluates (see the module docstring).

    ``youngs_modulus`` is its small-strain modulus: the body's scale of force (the floor of its
    Newton reference force).
    """

    youngs_modulus: float

    def validate(self, where: str = "material") -> None:
        """Raise :class:`~vfem.errors.InputError` naming ``where`` if the law's parameters are
        not admissible."""

    def initial_state(self, dim: int, points: tuple[int, int]) -> State:
        """The state at rest over ``points = (nelements, nq)`` quadrature points of a ``dim``-D
        body: an empty dict for a law without history."""

    def response(self, E: np.ndarray, state: State) -> Response:
        """The stress, its tangent and the state to commit for the Green-Lagrange strain ``E``
        (dim, dim, nelements, nq), from the converged ``state``."""


__all__ = ["Material", "Response", "State"]
