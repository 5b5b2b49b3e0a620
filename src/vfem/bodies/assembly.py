"""The isotropic linear-elastic stiffness of a 3D body, assembled over all local dof pairs at once.

scikit-fem's ``asm(linear_elasticity(lam, mu), basis)`` evaluates the weak form once per pair
of local basis functions: 24 x 24 = 576 passes over the elements for a trilinear hexahedron,
144 for a linear tetrahedron, each building the stress of every quadrature point afresh. In 2D
that is cheap (36 to 324 small passes); in 3D it took 11 s for 9,000 dofs (2026-11-27, the
sphere example). Here the same integral

    K_e[i, j] = sum_q (lam div(phi_i) div(phi_j) + 2 mu eps(phi_i) : eps(phi_j)) dx_q

is one ``einsum`` over the gradients of scikit-fem's scalar basis (its elements, mapping
and quadrature, not re-implemented), in chunks of elements to bound the memory, and the
element matrices go into the global one as scikit-fem's ``COOData`` would put them (same dof
numbering: the vector element's ``Dofs``). The matrices agree to round-off
(tests/test_solids.py).
2D bodies keep scikit-fem's assembly, so their every bit stays as it was.
"""

from __future__ import annotations

import copy

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from skfem.mapping import MappingIsoparametric

#: Elements per chunk: a chunk's products take (nodes x 3)^2 x CHUNK doubles (a hexahedron's
#: 576 per element: 38 MB at 8,192 elements; 900 for a 10-node tetrahedron), and its scalar
#: basis the gradients at its quadrature points (a hexahedron's 64: 12 KB per element).
CHUNK = 8192


def cell_gradients(mesh, element, mapping=None, chunk: int | None = None,
                   which: np.ndarray | None = None):
    """The shape functions' gradients and the quadrature weights of ``mesh``'s cells, a chunk of
    elements at a time: yields ``(elements, G, dx)``, ``elements`` a slice, ``G`` (scalar
    shape functions, dim, elements, quadrature points) the gradient of each scalar shape
    function of ``element`` (scikit-fem's, its default quadrature), ``dx`` (elements,
    quadrature points) the weights times the Jacobian's determinant.

    A 3D body keeps no ``CellBasis``: an ``ElementVector`` basis of trilinear hexahedra holds
    24 vector functions' values and 3 x 3 gradients at 64 quadrature points, 147 KB per
    element (2.2 GiB for the 50,700-dof sphere of ``vfem bench sphere --dofs 100k``; the
    million-dof sphere was killed for memory while building it). Per chunk, a scalar basis on
    the chunk's elements gives the same numbers (scikit-fem's ``ElementVector`` takes each
    component's gradient from the scalar element, and the mapping works element by element:
    tests/test_solids.py checks that the stiffness is the same to the bit).

    With ``which`` (element numbers), only those elements, and ``elements`` is then an array
    of their numbers, not a slice."""
    from skfem import CellBasis, Dofs

    mapping = cell_mapping(mesh) if mapping is None else mapping
    dofs = Dofs(mesh, element)  # once, not per chunk
    nel, chunk = (mesh.nelements if which is None else len(which)), chunk or CHUNK
    for start in range(0, nel, chunk):
        elements = slice(start, min(start + chunk, nel))
        numbers = (np.arange(elements.start, elements.stop) if which is None
                   else np.asarray(which[elements]))
        if which is not None:
            elements = numbers
        basis = CellBasis(mesh, element, mapping=mapping, dofs=dofs, disable_doflocs=True,
                          elements=numbers)
        # contiguous, as the vector basis's were: einsum sums in another order otherwise
        # (a tetrahedron's gradients come strided from its affine mapping)
        yield (elements, np.ascontiguousarray(np.stack([f[0].grad for f in basis.basis])),
               np.ascontiguousarray(basis.dx))


def elasticity_stiffness(mesh, element, lam: float, mu: float, element_dofs=None,
                         mapping=None, gradient_bound: np.ndarray | None = None,
                         which: np.ndarray | None = None) -> csr_matrix:
    """The stiffness of isotropic linear elasticity (Lame's ``lam``, ``mu``) of ``mesh`` with
    the vector form of scalar ``element`` (scikit-fem's ``ElementVector``, its numbering:
    ``element_dofs``, (local dofs, elements), by default ``Dofs(mesh, ElementVector(element))``),
    as a CSR matrix, from :func:`cell_gradients` chunk by chunk.

    The vector basis function of scalar function a and component c has the gradient
    e_c (x) grad N_a, so the element matrix needs only the scalar gradients G:

        K_e[(a, c), (b, d)] = sum_q w (lam G_ac G_bd + mu G_ad G_bc + mu delta_cd G_a . G_b)

    with the vector dof (a, c) at local index ``dim * a + c`` (scikit-fem's ``ElementVector``
    order, checked against its dof numbering below).

    ``gradient_bound`` (an array of one entry per element), if given, receives each element's
    max over its quadrature points of sum_a |grad N_a|, from the same gradients (no pass of its
    own): the bound :func:`vfem.bodies.stresses.strain_beyond` screens strains with.
    """
    from skfem import Dofs, ElementVector

    dim = mesh.dim()
    if element_dofs is None:
        element_dofs = Dofs(mesh, ElementVector(element)).element_dofs
    n = int(element_dofs.max()) + 1 if element_dofs.size else 0
    if which is not None:
        which = np.asarray(which, dtype=int)
        element_dofs = element_dofs[:, which]
    dofs = element_dofs  # (nloc, nelems)
    nnode, nel = dofs.shape[0] // dim, dofs.shape[1]
    first = dofs[::dim]  # each scalar function's component 0
    if not np.array_equal(dofs, (first[:, None, :] + np.arange(dim)[None, :, None]
                                 ).reshape(dofs.shape)):
        raise AssertionError("unexpected vector dof order")  # a scikit-fem change: not input
    nloc = nnode * dim
    data = np.empty((nloc, nloc, nel))
    for e, g, dx in cell_gradients(mesh, element, mapping, which=which):
        if which is not None:  # element numbers -> their columns here
            e = np.searchsorted(which, e)
        if gradient_bound is not None:
            gradient_bound[e] = gradient_sums(g)
        gw = g * dx  # the weights on one factor
        cross = np.einsum("aceq,bdeq->acbde", gw, g)  # sum_q w G_ac G_bd
        dot = np.einsum("aceq,bceq->abe", gw, g)  # sum_q w G_a . G_b
        block = lam * cross + mu * cross.transpose(0, 3, 2, 1, 4)
        for c in range(dim):
            block[:, c, :, c] += mu * dot
        block = block.reshape(nloc, nloc, -1)
        data[:, :, e] = 0.5 * (block + block.transpose(1, 0, 2))  # exactly symmetric
    index = np.int32 if n < 2**31 else np.int64  # the indices' copies: half the bytes
    dofs = dofs.astype(index)
    rows = np.broadcast_to(dofs[:, None, :], data.shape).ravel()
    cols = np.broadcast_to(dofs[None, :, :], data.shape).ravel()
    return coo_matrix((data.ravel(), (rows, cols)), shape=(n, n)).tocsr()


def gradient_sums(g: np.ndarray) -> np.ndarray:
    """Per element, the largest over its quadrature points of sum_a |grad N_a| (``g``: (scalar
    shape functions, dim, elements, quadrature points), as :func:`cell_gradients` gives)."""
    if not g.size:
        return np.zeros(g.shape[2] if g.ndim == 4 else 0)
    return np.sqrt(np.einsum("adeq,adeq->aeq", g, g)).sum(axis=0).max(axis=1)


class _RememberingIsoparametric(MappingIsoparametric):
    """scikit-fem's isoparametric mapping (hexahedra), remembering its Jacobian's inverse and
    determinant at the cell quadrature points of the last elements asked for: a ``CellBasis``
    asks for them once per basis function (8 times for a trilinear hexahedron's scalar basis,
    27 for a quadratic one), always at the same points and elements (the whole mesh, or one
    chunk of :func:`cell_gradients`). The numbers are scikit-fem's own, computed once."""

    def _remember(self, kind: str, X, tind, compute):
        if X.ndim != 2:
            return compute()
        key = (X.shape, X.tobytes(), None if tind is None else np.asarray(tind).tobytes())
        kept = self._remembered.get(kind)
        if kept is None or kept[0] != key:  # one entry per kind: a chunk's, then the next's
            kept = self._remembered[kind] = (key, compute())
        return kept[1]

    def invDF(self, X, tind=None):
        return self._remember("invDF", X, tind, lambda: super(_RememberingIsoparametric,
                                                             self).invDF(X, tind))

    def detDF(self, X, tind=None, J=None):
        if J is not None:
            return super().detDF(X, tind, J)
        return self._remember("detDF", X, tind, lambda: super(_RememberingIsoparametric,
                                                             self).detDF(X, tind))


def cell_mapping(mesh):
    """The mapping a 3D body's ``CellBasis`` should use: ``mesh``'s own, its cell-point
    Jacobians remembered when it is isoparametric (:class:`_RememberingIsoparametric`)."""
    mapping = mesh.mapping()
    if type(mapping) is MappingIsoparametric:
        mapping = copy.copy(mapping)
        mapping.__class__ = _RememberingIsoparametric
        mapping._remembered = {}
    return mapping
