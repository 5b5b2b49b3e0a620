"""Stresses and strains of a body's displacement: output fields, not part of the body.

:func:`small_strain_stress` (linear elasticity, plane strain or stress) and
:func:`cauchy_stress` (large kinematics, deformed configuration) give element averages with the
von Mises stress; each body's mechanics (:mod:`vfem.bodies.mechanics`) picks one, and
:func:`stress` asks it. :func:`max_strain` is the small-strain measure the solver's warning reads
(:data:`vfem.solver.SMALL_STRAIN_LIMIT`), whatever the kinematics.
"""

from __future__ import annotations

import numpy as np


def stress(body, u: np.ndarray) -> dict[str, np.ndarray]:
    """Element-average stresses of ``body`` at displacement ``u`` (ndofs): sxx, syy, sxy, szz
    and von Mises (per element); Cauchy stresses in the deformed configuration under large
    kinematics."""
    return body.mechanics.stress(u)


def cauchy_stress(nonlinear, u: np.ndarray) -> dict[str, np.ndarray]:
    """Element-average Cauchy stresses of a :class:`~vfem.nonlinear.NonlinearBody` at ``u``."""
    sig, szz = nonlinear.cauchy_stress_at(u)
    avg = {"sxx": sig[:, 0, 0], "syy": sig[:, 1, 1], "sxy": sig[:, 0, 1], "szz": szz}
    return _with_von_mises(avg)


def small_strain_stress(body, u: np.ndarray) -> dict[str, np.ndarray]:
    """Element-average linear-elastic stresses of ``body`` (assembled) at ``u``: the stress of
    the element-average strain (the stress is linear in the strain), the average strain by one
    sparse product with :func:`average_strain_operator`."""
    lam, mu = body.material.lame()
    nel = body.basis.nelems
    e = average_strain_operator(body) @ np.asarray(u, dtype=float)
    exx, eyy, exy = e[:nel], e[nel:2 * nel], e[2 * nel:]
    tr = exx + eyy
    avg = {"sxx": 2 * mu * exx + lam * tr, "syy": 2 * mu * eyy + lam * tr, "sxy": 2 * mu * exy}
    nu = body.material.poissons_ratio
    avg["szz"] = (nu * (avg["sxx"] + avg["syy"]) if body.material.plane == "strain"
                  else np.zeros_like(avg["sxx"]))
    return _with_von_mises(avg)


def average_strain_operator(body):
    """The sparse operator (3 nelems x ndofs) from a displacement to each element's average
    small strain (exx, eyy, exy stacked), built once per body from its basis's shape-function
    gradients and quadrature weights (each vector shape function moves one component, i % 2).
    Stresses of every step and body are then one sparse product (issue 19: recomputing them
    by interpolation took 0.6 s per step of a 462k-dof body)."""
    cached = body.__dict__.get("_average_strain")
    if cached is not None and cached[0] is body.basis:
        return cached[1]
    import scipy.sparse as sp

    basis = body.basis
    w = basis.dx  # (element, quadrature point)
    total = w.sum(axis=1)
    nel = basis.nelems
    rows, cols, vals = [], [], []
    elements = np.arange(nel)
    for i in range(basis.Nbfun):
        c = i % 2  # ElementVector: shape function i moves component i % 2
        g = basis.basis[i][0].grad[c]  # (derivative, element, quadrature point)
        avg = (g * w[None]).sum(axis=2) / total[None]  # (derivative, element)
        dofs = basis.element_dofs[i]
        normal = (0 if c == 0 else 1) * nel + elements  # exx from d/dx of u_x, eyy of u_y
        rows += [normal, 2 * nel + elements]
        cols += [dofs, dofs]
        vals += [avg[c], 0.5 * avg[1 - c]]  # exy: half of d(u_x)/dy + d(u_y)/dx
    op = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(3 * nel, basis.N))
    body.__dict__["_average_strain"] = (basis, op)
    return op


def max_strain(body, u: np.ndarray) -> tuple[float, int]:
    """The largest strain of displacement ``u`` (ndofs) as small kinematics reads it: the
    largest absolute principal value of the in-plane small-strain tensor sym(grad u)
    (``|(exx + eyy) / 2| + sqrt(((exx - eyy) / 2)^2 + exy^2)``) over every quadrature
    point of the mesh, and the element where it is. Independent of the material; what
    the solver compares with :data:`vfem.solver.SMALL_STRAIN_LIMIT` after each step. The
    gradient is summed from the basis's own shape-function gradients, each vector shape
    function's one nonzero component only (4 times faster than ``basis.interpolate``:
    0.05 s for 160k dofs; after :meth:`~vfem.bodies.Body.assemble`); for linear triangles,
    whose strain is constant in each element, from :func:`average_strain_operator`."""
    basis = body.basis
    if body.order == 1 and body.mesh.t.shape[0] == 3:
        # linear triangles: the strain is constant in each element, its average (one sparse
        # product, :func:`average_strain_operator`) is its value at every quadrature point
        # (issue 19: 0.15 s per step and body at 1M dofs otherwise, 5 % of the run)
        nel = basis.nelems
        e = average_strain_operator(body) @ np.asarray(u, dtype=float)
        exx, eyy, exy = e[:nel], e[nel:2 * nel], e[2 * nel:]
        per_element = np.abs(0.5 * (exx + eyy)) + np.sqrt((0.5 * (exx - eyy)) ** 2 + exy**2)
        if not per_element.size:
            return 0.0, 0
        element = int(np.argmax(per_element))
        return float(per_element[element]), element
    return _max_strain_at_quadrature(body, u)


def _max_strain_at_quadrature(body, u: np.ndarray) -> tuple[float, int]:
    """:func:`max_strain` over every quadrature point (any element)."""
    basis = body.basis
    ue = np.asarray(u, dtype=float)[basis.element_dofs]  # (shape functions, elements)
    grad = None  # (component, derivative, element, quadrature point)
    for i in range(basis.Nbfun):
        c = i % 2  # ElementVector: shape function i moves component i % 2
        g = basis.basis[i][0].grad[c]  # (derivative, element, quadrature point)
        if grad is None:
            grad = np.zeros((2,) + g.shape)
        grad[c] += ue[i][:, None] * g
    exx, eyy, exy = grad[0, 0], grad[1, 1], 0.5 * (grad[0, 1] + grad[1, 0])
    principal = np.abs(0.5 * (exx + eyy)) + np.sqrt((0.5 * (exx - eyy)) ** 2 + exy**2)
    per_element = principal.max(axis=1) if principal.size else np.zeros(1)
    element = int(np.argmax(per_element))
    return float(per_element[element]), element


def _with_von_mises(avg: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    sxx, syy, sxy, szz = avg["sxx"], avg["syy"], avg["sxy"], avg["szz"]
    avg["von_mises"] = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2)
                               + 3 * sxy**2)
    return avg


__all__ = ["cauchy_stress", "max_strain", "small_strain_stress", "stress"]
