"""The two corrections of the virtual finite element method (thesis §4.2), one implementation.

Everything is written in the *normal frame of a pair*: a body's own node against the (real or
virtual) node of the other body opposite it.

* a displacement is positive when it moves the node **out of** the other body;
* a contact force is positive when it is **compressive** (it pushes the node out of the other body);
* the penetration ``p`` is positive when the node is inside the other body.

With these signs the formulas for body A read the same for body B, which is how every body is
treated alike: each body computes the corrections of its own nodes from the pair (own stiffness,
opposing stiffness). The 1D spring example and the 2D/3D solver call these same functions with
scalars or with NumPy arrays (one entry per contact node).
"""

from __future__ import annotations

import numpy as np


def compatibility_displacement(k_own, k_other, penetration):
    """Corrective displacement of the own node that removes its share of a penetration.

    Thesis eq. (4.2.4): ``dU_A = K_B P / (K_A + K_B)`` out of the other body; the two shares add
    up to ``P`` and the force increments ``K_A dU_A`` and ``K_B dU_B`` are equal, so equilibrium
    is not disturbed to first order. A negative penetration (a node that carries compressive force
    but has left the other surface) gives a negative displacement: back towards the surface.
    """
    k_own = np.asarray(k_own, dtype=float)
    k_other = np.asarray(k_other, dtype=float)
    return k_other * np.asarray(penetration, dtype=float) / (k_own + k_other)


def compatibility_force(k_own, k_other, penetration):
    """Force increment that produces :func:`compatibility_displacement` (eq. 4.2.4).

    ``dF_A = K_A K_B P / (K_A + K_B)``, the same for both bodies. In two and three dimensions
    vfem turns the displacements into forces through the flexibility instead (thesis §4.5.2,
    stage 2), which keeps the interaction between nodes; this scalar form serves the 1D analogy.
    """
    k_own = np.asarray(k_own, dtype=float)
    k_other = np.asarray(k_other, dtype=float)
    return k_own * k_other * np.asarray(penetration, dtype=float) / (k_own + k_other)


def equilibrium_force(k_own, k_other, error):
    """Force increment of the own node that removes its share of an equilibrium error.

    Thesis eq. (4.2.7): ``dF_A = -K_A E_F / (K_A + K_B)``, where ``E_F`` is the own compressive
    force minus the opposing one. The two bodies' increments move both sides by the same
    ``-E_F / (K_A + K_B)``, so compatibility is not disturbed to first order.
    """
    k_own = np.asarray(k_own, dtype=float)
    k_other = np.asarray(k_other, dtype=float)
    return -k_own * np.asarray(error, dtype=float) / (k_own + k_other)


def relaxation(settings, iteration: int) -> float:
    """The factor on an iteration's corrections (thesis §5.6): ``first_relaxation`` for the
    first ``relaxed_iterations`` iterations of a solve, ``relaxation`` after them."""
    if iteration < settings.relaxed_iterations:
        return settings.first_relaxation
    return settings.relaxation


def release_tension(values: np.ndarray, tension: np.ndarray, released: np.ndarray,
                    iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """Tension release over several iterations (thesis §5.6): a node in tension gives up
    ``1 / iterations`` of its contact force (or traction value) in this iteration; one released
    part-way in the previous iteration and still in tension gives up the rest.

    ``values``: per node (rows) the force or traction; ``tension``, ``released``: per node.
    Returns the change of ``values`` (zero off ``tension``) and the nodes released part-way now.
    """
    frac = np.where(released, 1.0, 1.0 / iterations)
    change = np.zeros_like(values)
    share = frac[tension].reshape((-1,) + (1,) * (np.ndim(values) - 1))
    change[tension] = -(share * values[tension])
    return change, tension & (frac < 1.0)
