"""The isotropic linear-elastic stiffness of a 3D body, assembled over all local dof pairs at once.

scikit-fem's ``asm(linear_elasticity(lam, mu), basis)`` evaluates the weak form once per pair
of local basis functions: 24 x 24 = 576 passes over the elements for a trilinear hexahedron,
144 for a linear tetrahedron, each building the stress of every quadrature point afresh. In 2D
that is cheap (36 to 324 small passes); in 3D it took 11 s for 9,000 dofs (2026-11-27, the
sphere example). Here the same integral

    K_e[i, j] = sum_q (lam div(phi_i) div(phi_j) + 2 mu eps(phi_i) : eps(phi_j)) dx_q

is one ``einsum`` over the gradients scikit-fem's basis already holds (its elements, mapping
and quadrature, not re-implemented), in chunks of elements to bound the memory, and the
element matrices go into the global one as scikit-fem's ``COOData`` would put them (same dof
numbering: ``basis.element_dofs``). The matrices agree to round-off (tests/test_assembly3d.py).
2D bodies keep scikit-fem's assembly, so their every bit stays as it was.
"""

from __future__ import annotations

import copy

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from skfem.mapping import MappingIsoparametric

#: Elements per chunk: a chunk's products take (nodes x 3)^2 x CHUNK doubles (a hexahedron's
#: 576 per element: 38 MB at 8,192 elements; 900 for a 10-node tetrahedron).
CHUNK = 8192


def elasticity_stiffness(basis, lam: float, mu: float) -> csr_matrix:
    """The stiffness of isotropic linear elasticity (Lame's ``lam``, ``mu``) on ``basis``, a
    scikit-fem ``CellBasis`` of an ``ElementVector`` (any dimension), as a CSR matrix.

    The vector basis function of scalar function a and component c has the gradient
    e_c (x) grad N_a, so the element matrix needs only the scalar gradients G:

        K_e[(a, c), (b, d)] = sum_q w (lam G_ac G_bd + mu G_ad G_bc + mu delta_cd G_a . G_b)

    with the vector dof (a, c) at local index ``dim * a + c`` (scikit-fem's ``ElementVector``
    order, checked against the basis' dof numbering below).
    """
    dim = basis.mesh.dim()
    dofs = basis.element_dofs  # (nloc, nelems)
    nnode, nel = dofs.shape[0] // dim, dofs.shape[1]
    first = dofs[::dim]  # each scalar function's component 0
    if not np.array_equal(dofs, (first[:, None, :] + np.arange(dim)[None, :, None]
                                 ).reshape(dofs.shape)):
        raise AssertionError("unexpected vector dof order")  # a scikit-fem change: not input
    # grad N_a: row 0 of the gradient of (a, component 0), whose value is (N_a, 0, 0); read
    # from the vector basis already built (a scalar basis would map every point again)
    grads = np.stack([basis.basis[dim * a][0].grad[0] for a in range(nnode)])
    data = np.empty((nnode, dim, nnode, dim, nel))
    for start in range(0, nel, CHUNK):
        e = slice(start, min(start + CHUNK, nel))
        g = grads[:, :, e]
        gw = g * basis.dx[e]  # the weights on one factor
        cross = np.einsum("aceq,bdeq->acbde", gw, g)  # sum_q w G_ac G_bd
        dot = np.einsum("aceq,bceq->abe", gw, g)  # sum_q w G_a . G_b
        block = lam * cross + mu * cross.transpose(0, 3, 2, 1, 4)
        for c in range(dim):
            block[:, c, :, c] += mu * dot
        data[:, :, :, :, e] = block
    data = data.reshape(nnode * dim, nnode * dim, nel)
    data = 0.5 * (data + data.transpose(1, 0, 2))  # exactly symmetric
    rows = np.broadcast_to(dofs[:, None, :], data.shape)
    cols = np.broadcast_to(dofs[None, :, :], data.shape)
    n = basis.N
    return coo_matrix((data.ravel(), (rows.ravel(), cols.ravel())), shape=(n, n)).tocsr()


class _RememberingIsoparametric(MappingIsoparametric):
    """scikit-fem's isoparametric mapping (hexahedra), remembering its Jacobian's inverse and
    determinant at the cell quadrature points: a ``CellBasis`` asks for them once per basis
    function (24 times for a trilinear hexahedron, 81 for a quadratic one: 6 s of the 8-second
    sphere setup), always at the same points. The numbers are scikit-fem's own, computed once."""

    def invDF(self, X, tind=None):
        if tind is not None or X.ndim != 2:
            return super().invDF(X, tind)
        key = ("invDF", X.shape, X.tobytes())
        if key not in self._remembered:
            self._remembered[key] = super().invDF(X)
        return self._remembered[key]

    def detDF(self, X, tind=None, J=None):
        if tind is not None or J is not None or X.ndim != 2:
            return super().detDF(X, tind, J)
        key = ("detDF", X.shape, X.tobytes())
        if key not in self._remembered:
            self._remembered[key] = super().detDF(X)
        return self._remembered[key]


def cell_mapping(mesh):
    """The mapping a 3D body's ``CellBasis`` should use: ``mesh``'s own, its cell-point
    Jacobians remembered when it is isoparametric (:class:`_RememberingIsoparametric`)."""
    mapping = mesh.mapping()
    if type(mapping) is MappingIsoparametric:
        mapping = copy.copy(mapping)
        mapping.__class__ = _RememberingIsoparametric
        mapping._remembered = {}
    return mapping
