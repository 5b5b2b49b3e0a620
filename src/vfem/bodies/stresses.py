"""Stresses and strains of a body's displacement: output fields, not part of the body.

:func:`small_strain_stress` (linear elasticity, plane strain or stress, or 3D) and
:func:`cauchy_stress` (large kinematics, deformed configuration) give element averages with the
von Mises stress (in 3D: the six components sxx, syy, szz, syz, sxz, sxy); each body's
mechanics (:mod:`vfem.bodies.mechanics`) picks one, and :func:`stress` asks it.
:func:`max_strain` is the small-strain measure the solver's warning reads
(:data:`vfem.solver.SMALL_STRAIN_LIMIT`), whatever the kinematics.
"""

from __future__ import annotations

import numpy as np

from .assembly import cell_gradients, gradient_sums


def stress(body, u: np.ndarray) -> dict[str, np.ndarray]:
    """Element-average stresses of ``body`` at displacement ``u`` (ndofs): sxx, syy, sxy, szz
    and von Mises (per element); Cauchy stresses in the deformed configuration under large
    kinematics. A 3D body's: sxx, syy, szz, syz, sxz, sxy and von Mises."""
    return body.mechanics.stress(u)


def cauchy_stress(nonlinear, u: np.ndarray) -> dict[str, np.ndarray]:
    """Element-average Cauchy stresses of a :class:`~vfem.nonlinear.NonlinearBody` at ``u``,
    and the fields its material shows of its state (an equivalent plastic strain: issue 41)."""
    sig, szz, fields = nonlinear.cauchy_stress_at(u)
    if sig.shape[1] == 3 and not nonlinear.axisymmetric:  # (about an axis: szz the hoop)
        avg = {"sxx": sig[:, 0, 0], "syy": sig[:, 1, 1], "szz": sig[:, 2, 2],
               "syz": sig[:, 1, 2], "sxz": sig[:, 0, 2], "sxy": sig[:, 0, 1]}
    else:
        avg = {"sxx": sig[:, 0, 0], "syy": sig[:, 1, 1], "sxy": sig[:, 0, 1], "szz": szz}
    avg = _with_von_mises(avg)
    clash = sorted(set(fields) & set(avg))
    if clash:
        raise ValueError(f"the material's fields {clash} have the names of stresses")
    return {**avg, **fields}


def small_strain_stress(body, u: np.ndarray) -> dict[str, np.ndarray]:
    """Element-average linear-elastic stresses of ``body`` (assembled) at ``u``: its section's
    (:meth:`vfem.bodies.section.Section.stress`: plane strain, plane stress or 3D)."""
    return body.section.stress(body, u)


def plane_small_strain_stress(body, u: np.ndarray, out_of_plane) -> dict[str, np.ndarray]:
    """Element-average linear-elastic stresses of a 2D ``body`` (assembled) at ``u``: the
    stress of the element-average strain (the stress is linear in the strain), the average
    strain by one sparse product with :func:`plane_average_strain_operator`. ``out_of_plane``
    gives szz from the in-plane stresses and Poisson's ratio (the section's assumption)."""
    lam, mu = body.material.lame()
    nel = body.mesh.nelements
    e = plane_average_strain_operator(body) @ np.asarray(u, dtype=float)
    exx, eyy, exy = e[:nel], e[nel:2 * nel], e[2 * nel:]
    tr = exx + eyy
    avg = {"sxx": 2 * mu * exx + lam * tr, "syy": 2 * mu * eyy + lam * tr, "sxy": 2 * mu * exy}
    avg["szz"] = out_of_plane(avg, body.material.poissons_ratio)
    return _with_von_mises(avg)


def solid_small_strain_stress(body, u: np.ndarray) -> dict[str, np.ndarray]:
    """:func:`plane_small_strain_stress` of a 3D body: sxx, syy, szz, syz, sxz, sxy."""
    lam, mu = body.material.lame()
    nel = body.mesh.nelements
    e = solid_average_strain_operator(body) @ np.asarray(u, dtype=float)
    exx, eyy, ezz, eyz, exz, exy = e.reshape(6, nel)
    tr = exx + eyy + ezz
    avg = {"sxx": 2 * mu * exx + lam * tr, "syy": 2 * mu * eyy + lam * tr,
           "szz": 2 * mu * ezz + lam * tr, "syz": 2 * mu * eyz, "sxz": 2 * mu * exz,
           "sxy": 2 * mu * exy}
    return _with_von_mises(avg)


def average_strain_operator(body):
    """The sparse operator (3 nelems x ndofs) from a displacement to each element's average
    small strain (exx, eyy, exy stacked), built once per body from its basis's shape-function
    gradients and quadrature weights (each vector shape function moves one component, i % 2).
    Stresses of every step and body are then one sparse product (issue 19: recomputing them
    by interpolation took 0.6 s per step of a 462k-dof body). A 3D body's is 6 nelems x ndofs:
    exx, eyy, ezz, eyz, exz, exy (tensor shear strains, half the engineering ones)."""
    return body.section.average_strain_operator(body)


def plane_average_strain_operator(body):
    """:func:`average_strain_operator` of a 2D body (3 nelems x ndofs)."""
    return _average_strain_2d(body, hoop=False)


def _average_strain_2d(body, hoop: bool):
    """The element-average strain operator of a 2D body, cached on it: exx, eyy, exy averaged
    over the element's area, or with ``hoop`` (a body of revolution) over its volume (the
    weight r) with the hoop strain u_r / r as a fourth block."""
    cached = body.__dict__.get("_average_strain")
    if cached is not None and cached[0] is body.basis:
        return cached[1]
    import scipy.sparse as sp

    basis = body.basis
    r = basis.mapping.F(basis.X)[0] if hoop else None  # (element, quadrature point)
    w = basis.dx * r if hoop else basis.dx
    total = w.sum(axis=1)
    nel = basis.nelems
    rows, cols, vals = [], [], []
    elements = np.arange(nel)
    for i in range(basis.Nbfun):
        c = i % 2  # ElementVector: shape function i moves component i % 2
        f = basis.basis[i][0]
        avg = (f.grad[c] * w[None]).sum(axis=2) / total[None]  # (derivative, element)
        dofs = basis.element_dofs[i]
        rows += [c * nel + elements, 2 * nel + elements]  # exx from d/dx of u_x, eyy of u_y
        cols += [dofs, dofs]
        vals += [avg[c], 0.5 * avg[1 - c]]  # exy: half of d(u_x)/dy + d(u_y)/dx
        if hoop and c == 0:  # the hoop strain u_r / r
            rows.append(3 * nel + elements)
            cols.append(dofs)
            vals.append((np.asarray(f)[0] / r * w).sum(axis=1) / total)
    op = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                       shape=((4 if hoop else 3) * nel, basis.N))
    body.__dict__["_average_strain"] = (basis, op)
    return op


def solid_average_strain_operator(body):
    """:func:`average_strain_operator` of a 3D body, from the gradients of a chunk of elements
    at a time (:func:`~vfem.bodies.assembly.cell_gradients`: a 3D body keeps no basis)."""
    cached = body.__dict__.get("_average_strain")
    if cached is not None and cached[0] is body.mesh:
        return cached[1]
    import scipy.sparse as sp

    element_dofs = body.dof_map.element_dofs  # (vector shape functions, elements)
    nel = body.mesh.nelements
    rows, cols, vals = [], [], []
    for e, grads, w in cell_gradients(body.mesh, body.element()):
        total = w.sum(axis=1)
        elements = np.arange(e.start, e.stop)
        for i in range(element_dofs.shape[0]):
            c = i % 3  # ElementVector: shape function i moves component i % 3
            g = grads[i // 3]  # (derivative, element, quadrature point): N_a's gradient
            avg = (g * w[None]).sum(axis=2) / total[None]  # (derivative, element)
            dofs = element_dofs[i, e]
            rows.append(c * nel + elements)  # exx, eyy, ezz from d/dx, d/dy, d/dz of u_c
            cols.append(dofs)
            vals.append(avg[c])
            for d in range(3):  # the shears: half of d(u_c)/dd + d(u_d)/dc
                if d != c:
                    rows.append(_SHEAR[frozenset((c, d))] * nel + elements)
                    cols.append(dofs)
                    vals.append(0.5 * avg[d])
    n = body.dof_map.N
    op = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(6 * nel, n))
    op.sort_indices()  # each row's terms in dof order, whatever the chunks
    body.__dict__["_average_strain"] = (body.mesh, op)
    return op


def axisymmetric_average_strain_operator(body):
    """:func:`average_strain_operator` of a body of revolution (4 nelems x ndofs): exx (e_rr),
    eyy (e_zz), exy (e_rz) and the hoop strain e_tt = u_r / r, each element's average over its
    volume (the weight 2 pi r)."""
    return _average_strain_2d(body, hoop=True)


def axisymmetric_small_strain_stress(body, u: np.ndarray) -> dict[str, np.ndarray]:
    """:func:`plane_small_strain_stress` of a body of revolution: sxx (s_rr), syy (s_zz),
    sxy (s_rz) and szz the hoop stress s_tt, from the elements' average strains."""
    lam, mu = body.material.lame()
    nel = body.mesh.nelements
    e = axisymmetric_average_strain_operator(body) @ np.asarray(u, dtype=float)
    err, ezz, erz, ett = e.reshape(4, nel)
    tr = err + ezz + ett
    avg = {"sxx": 2 * mu * err + lam * tr, "syy": 2 * mu * ezz + lam * tr, "sxy": 2 * mu * erz,
           "szz": 2 * mu * ett + lam * tr}
    return _with_von_mises(avg)


def axisymmetric_max_strain(body, u: np.ndarray) -> tuple[float, int]:
    """:func:`max_strain` of a body of revolution: the largest absolute principal strain of
    the in-plane tensor and the hoop strain u_r / r at every quadrature point."""
    basis = body.basis
    f = basis.interpolate(np.asarray(u, dtype=float))
    g = f.grad
    r = basis.mapping.F(basis.X)[0]
    exx, eyy, exy = g[0, 0], g[1, 1], 0.5 * (g[0, 1] + g[1, 0])
    in_plane = np.abs(0.5 * (exx + eyy)) + np.sqrt((0.5 * (exx - eyy)) ** 2 + exy**2)
    per_element = np.maximum(in_plane, np.abs(np.asarray(f)[0] / r)).max(axis=1)
    if not per_element.size:
        return 0.0, 0
    element = int(np.argmax(per_element))
    return float(per_element[element]), element


def max_strain(body, u: np.ndarray) -> tuple[float, int]:
    """The largest strain of displacement ``u`` (ndofs) as small kinematics reads it: the
    largest absolute principal value of the in-plane small-strain tensor sym(grad u)
    (``|(exx + eyy) / 2| + sqrt(((exx - eyy) / 2)^2 + exy^2)``) over every quadrature
    point of the mesh, and the element where it is. Independent of the material; what
    the solver compares with :data:`vfem.solver.SMALL_STRAIN_LIMIT` after each step. The
    gradient is summed from the basis's own shape-function gradients, each vector shape
    function's one nonzero component only (4 times faster than ``basis.interpolate``:
    0.05 s for 160k dofs; after :meth:`~vfem.bodies.Body.assemble`); for linear triangles,
    whose strain is constant in each element, from :func:`average_strain_operator`. In 3D the
    largest absolute eigenvalue of the 3 x 3 strain tensor (:func:`_largest_eigenvalue`)."""
    return body.section.max_strain(body, u)


def strain_beyond(body, u: np.ndarray, limit: float) -> tuple[float, int] | None:
    """:func:`max_strain` where it exceeds ``limit``, else None: the solver's warning after
    every step (:meth:`vfem.solver.Analysis.warn_large_strain`), at a fraction of its price.

    A screen first, exact and cheap: in an element with nodal displacements u_a, since
    sum_a grad N_a = 0, grad u(q) = sum_a (u_a - c) (x) grad N_a(q) for any constant c, so
    with c the element's mean nodal displacement

        max |eigenvalue of sym grad u(q)| <= |sym grad u(q)|_F <= |grad u(q)|_F
                                         <= max_a |u_a - c| * sum_a |grad N_a(q)|

    and the last factor's largest value over the element's quadrature points (its *gradient
    bound*) is geometry alone, taken from the assembly's own gradients
    (:func:`~vfem.bodies.assembly.elasticity_stiffness`) or, failing them, once per body.

    Linear elements (their nodes the mesh's, x = sum_a N_a x_a, so sum_a x_a (x) grad N_a = I)
    take out the element's own linear field as well: for any matrix G,
    grad u(q) = G + sum_a r_a (x) grad N_a(q) with r_a = u_a - c - G (x_a - xbar), so

        max |eigenvalue of sym grad u(q)| <= |sym G|_F + max_a |r_a| * sum_a |grad N_a(q)|

    with G the least-squares fit of u_a - c by G (x_a - xbar): a rotation or a uniform strain
    then costs the screen nothing (:func:`strain_bound`).

    Only the elements whose bound exceeds ``limit`` get :func:`max_strain`'s eigenvalues at
    their quadrature points: none in a body that strains well within it (issue 40: every
    point's eigenvalues every step were 22.6 % of ``vfem run cattaneo3d``). The value and
    element returned are :func:`max_strain`'s whenever it exceeds ``limit``
    (tests/test_strain_warning.py)."""
    u = np.asarray(u, dtype=float)
    if not body.section.strain_is_gradient:
        # the bound is of the displacement's gradient alone: a section whose strain has more
        # (a body of revolution's hoop strain u_r / r) reads every point
        strain, element = max_strain(body, u)
        return (strain, element) if strain > limit else None
    if not body.mesh.nelements:
        return None
    if not _constant_strain(body):  # (linear simplices: the exact strain, one sparse product)
        suspect = np.flatnonzero(strain_bound(body, u) * (1 + 1e-9) > limit)
        if not suspect.size:
            return None
        if body.dim == 3:
            strain, element = _max_strain_at_quadrature_3d(body, u, suspect)
            return (strain, element) if strain > limit else None
    strain, element = max_strain(body, u)  # 2D: one vectorised pass
    return (strain, element) if strain > limit else None


def _constant_strain(body) -> bool:
    """Whether the body's strain is constant in each element (linear triangles and
    tetrahedra), read exactly by one sparse product (:func:`average_strain_operator`): cheaper
    than any screen."""
    return body.order == 1 and body.mesh.t.shape[0] == body.dim + 1


def strain_bound(body, u: np.ndarray) -> np.ndarray:
    """(elements,) an upper bound of each element's largest absolute principal strain over its
    quadrature points: :func:`strain_beyond`'s screen, for a body whose strain is its
    displacement's symmetric gradient. Measured on ``vfem bench sphere --dofs 100k`` after
    its step (trilinear hexahedra, largest strain 2.5 % in both bodies): with the mean motion c
    alone taken out the bound reached 18 % and 5,487 of the 30,724 elements went to the
    eigenvalues (1.5 s a step at 278k dofs); with the linear field taken out too, 2.7 and
    2.9 %, none, 0.03 s (issue 40)."""
    u = np.asarray(u, dtype=float)
    ue = u[body.dof_map.element_dofs].reshape(-1, body.dim, body.mesh.nelements)  # (a, c, e)
    centre = ue.mean(axis=0)
    d = ue - centre
    # round-off: sum_a grad N_a is zero (and sum_a x_a (x) grad N_a the identity) only to its
    # own rounding, times the rigid motion c (and the fitted field's size times the reach)
    scale = np.sqrt((centre**2).sum(axis=0))
    linear = 0.0
    fit = _linear_fit(body) if ue.shape[0] == body.mesh.t.shape[0] else None
    if fit is not None:
        X, P, reach = fit
        Gt = np.einsum("aie,aje->eij", P, d)  # G^T, each element's least squares
        d = d - np.einsum("aie,eij->aje", X, Gt)
        linear = np.sqrt((0.25 * (Gt + np.swapaxes(Gt, 1, 2)) ** 2).sum(axis=(1, 2)))
        scale = scale + np.sqrt((Gt**2).sum(axis=(1, 2))) * reach
    spread = np.sqrt((d**2).sum(axis=1)).max(axis=0)
    return linear + (spread + 1e-12 * scale) * _gradient_bound(body)


def _linear_fit(body):
    """For linear elements whose nodes and geometry are the mesh's corners, once per mesh:
    X (node, coordinate, element) the nodes less their centroid, P = X (X^T X)^-1 (the same
    shape: G^T = sum_a P_a (x) (u_a - c) fits u_a - c by G X_a in least squares), and each
    element's reach |centroid| + max_a |X_a| (for the round-off); else None."""
    mesh = body.mesh
    kept = body.__dict__.get("_linear_fit")
    if kept is not None and kept[0] is mesh:
        return kept[1]
    fit = None
    if body.order == 1 and mesh.doflocs.shape == mesh.p.shape:
        xe = np.moveaxis(mesh.p[:, mesh.t], 0, 1)
        centroid = xe.mean(axis=0)
        X = xe - centroid
        inverse = np.linalg.inv(np.einsum("aie,aje->eij", X, X))
        P = np.einsum("aje,eji->aie", X, inverse)
        reach = np.sqrt((centroid**2).sum(axis=0)) + np.sqrt((X**2).sum(axis=1)).max(axis=0)
        fit = (X, P, reach)
    body.__dict__["_linear_fit"] = (mesh, fit)
    return fit


def _gradient_bound(body) -> np.ndarray:
    """(elements,) each element's max over its quadrature points of sum_a |grad N_a| (the
    scalar shape functions a): kept from the body's 3D assembly, or computed here once."""
    kept = body.__dict__.get("_gradient_bound")
    if kept is not None and kept[0] is body.mesh:
        return kept[1]
    if body.dim == 3:
        bound = np.empty(body.mesh.nelements)
        for e, grads, _ in cell_gradients(body.mesh, body.element()):
            bound[e] = gradient_sums(grads)
    else:  # the kept basis: scalar function a's gradient is vector function dim * a's own
        basis = body.basis
        g = np.stack([basis.basis[i][0].grad[i % body.dim]
                      for i in range(0, basis.Nbfun, body.dim)])
        bound = gradient_sums(g)
    body.__dict__["_gradient_bound"] = (body.mesh, bound)
    return bound


def plane_max_strain(body, u: np.ndarray) -> tuple[float, int]:
    """:func:`max_strain` of a 2D body."""
    basis = body.basis
    if _constant_strain(body):
        # linear triangles: the strain is constant in each element, its average (one sparse
        # product, :func:`average_strain_operator`) is its value at every quadrature point
        # (issue 19: 0.15 s per step and body at 1M dofs otherwise, 5 % of the run)
        nel = basis.nelems
        e = plane_average_strain_operator(body) @ np.asarray(u, dtype=float)
        exx, eyy, exy = e[:nel], e[nel:2 * nel], e[2 * nel:]
        per_element = np.abs(0.5 * (exx + eyy)) + np.sqrt((0.5 * (exx - eyy)) ** 2 + exy**2)
        if not per_element.size:
            return 0.0, 0
        element = int(np.argmax(per_element))
        return float(per_element[element]), element
    return _max_strain_at_quadrature(body, u)


def solid_max_strain(body, u: np.ndarray) -> tuple[float, int]:
    """:func:`max_strain` of a 3D body."""
    if _constant_strain(body):  # linear tetrahedra: constant
        nel = body.mesh.nelements
        e = (solid_average_strain_operator(body) @ np.asarray(u, dtype=float)).reshape(6, nel)
        per_element = _largest_eigenvalue(*e)
        if not per_element.size:
            return 0.0, 0
        element = int(np.argmax(per_element))
        return float(per_element[element]), element
    return _max_strain_at_quadrature_3d(body, u)


def _max_strain_at_quadrature(body, u: np.ndarray) -> tuple[float, int]:
    """:func:`max_strain` over every quadrature point (any element)."""
    basis = body.basis
    dim = body.mesh.p.shape[0]
    ue = np.asarray(u, dtype=float)[basis.element_dofs]  # (shape functions, elements)
    grad = None  # (component, derivative, element, quadrature point)
    for i in range(basis.Nbfun):
        c = i % dim  # ElementVector: shape function i moves component i % dim
        g = basis.basis[i][0].grad[c]  # (derivative, element, quadrature point)
        if grad is None:
            grad = np.zeros((dim,) + g.shape)
        grad[c] += ue[i][:, None] * g
    if dim == 3:
        principal = _largest_eigenvalue(
            grad[0, 0], grad[1, 1], grad[2, 2], 0.5 * (grad[1, 2] + grad[2, 1]),
            0.5 * (grad[0, 2] + grad[2, 0]), 0.5 * (grad[0, 1] + grad[1, 0]))
    else:
        exx, eyy, exy = grad[0, 0], grad[1, 1], 0.5 * (grad[0, 1] + grad[1, 0])
        principal = np.abs(0.5 * (exx + eyy)) + np.sqrt((0.5 * (exx - eyy)) ** 2 + exy**2)
    per_element = principal.max(axis=1) if principal.size else np.zeros(1)
    element = int(np.argmax(per_element))
    return float(per_element[element]), element


def _max_strain_at_quadrature_3d(body, u: np.ndarray, which: np.ndarray | None = None
                                 ) -> tuple[float, int]:
    """:func:`max_strain` of a 3D body over every quadrature point, a chunk of elements at a
    time (:func:`~vfem.bodies.assembly.cell_gradients`); over elements ``which`` alone if
    given."""
    ue = np.asarray(u, dtype=float)[body.dof_map.element_dofs]  # (shape functions, elements)
    best, where = -1.0, 0
    for e, grads, _ in cell_gradients(body.mesh, body.element(), which=which):
        numbers = np.arange(e.start, e.stop) if isinstance(e, slice) else e
        # grad u_c = sum_a u_(a, c) grad N_a: (component, derivative, element, quadrature point)
        grad = np.einsum("ace,adeq->cdeq", ue[:, e].reshape(-1, 3, len(numbers)), grads)
        principal = _largest_eigenvalue(
            grad[0, 0], grad[1, 1], grad[2, 2], 0.5 * (grad[1, 2] + grad[2, 1]),
            0.5 * (grad[0, 2] + grad[2, 0]), 0.5 * (grad[0, 1] + grad[1, 0]))
        per_element = principal.max(axis=1)
        k = int(np.argmax(per_element))
        if per_element[k] > best:
            best, where = float(per_element[k]), int(numbers[k])
    return max(best, 0.0), where


def _largest_eigenvalue(xx, yy, zz, yz, xz, xy) -> np.ndarray:
    """The largest absolute eigenvalue of symmetric 3 x 3 tensors given by their six
    components (arrays of one shape), in closed form (the trigonometric solution of the
    characteristic cubic): no loop and no 3 x 3 arrays per point."""
    q = (xx + yy + zz) / 3.0
    a, b, c = xx - q, yy - q, zz - q
    p2 = (a * a + b * b + c * c + 2.0 * (xy * xy + xz * xz + yz * yz)) / 6.0
    p = np.sqrt(p2)
    with np.errstate(invalid="ignore", divide="ignore"):
        det = (a * (b * c - yz * yz) - xy * (xy * c - yz * xz) + xz * (xy * yz - b * xz))
        r = np.clip(np.where(p > 0, det / (2.0 * np.where(p > 0, p, 1.0) ** 3), 0.0), -1, 1)
    phi = np.arccos(r) / 3.0
    largest = q + 2.0 * p * np.cos(phi)
    smallest = q + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0)
    return np.maximum(np.abs(largest), np.abs(smallest))


#: The row block of each shear strain in a 3D :func:`average_strain_operator` (components'
#: pairs: yz, xz, xy).
_SHEAR = {frozenset((1, 2)): 3, frozenset((0, 2)): 4, frozenset((0, 1)): 5}


def _with_von_mises(avg: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    sxx, syy, sxy, szz = avg["sxx"], avg["syy"], avg["sxy"], avg["szz"]
    if "syz" in avg:  # 3D: the three shears
        avg["von_mises"] = np.sqrt(
            0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2)
            + 3 * (sxy**2 + avg["syz"] ** 2 + avg["sxz"] ** 2))
        return avg
    avg["von_mises"] = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2)
                               + 3 * sxy**2)
    return avg


__all__ = ["axisymmetric_average_strain_operator", "axisymmetric_max_strain",
           "axisymmetric_small_strain_stress", "cauchy_stress", "max_strain",
           "plane_average_strain_operator", "plane_max_strain",
           "plane_small_strain_stress", "small_strain_stress", "solid_average_strain_operator",
           "solid_max_strain", "solid_small_strain_stress", "stress"]
