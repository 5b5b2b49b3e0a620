"""One hyperelastic body under large displacements, solved incrementally by Newton's method.

This is the geometrically (and materially) nonlinear counterpart of :class:`vfem.bodies.Body`:
plane strain or 3D, a hyperelastic material (:mod:`vfem.materials.hyperelastic`), prescribed
displacements and dead nodal forces scaled by a load factor. A large-kinematics
:class:`~vfem.bodies.Body` wraps one; the contact iteration (:mod:`vfem.contact.formulations.large`)
drives it through a trial state: :meth:`NonlinearBody.linearize` and :meth:`NonlinearBody.move` for
its Newton corrections, :meth:`NonlinearBody.equilibrate` under the converged contact forces, then
:meth:`NonlinearBody.accept` (or :meth:`NonlinearBody.discard` when a step is cut).

Equilibrium (thesis eq. 3.10.8, the configurational derivative of the potential energy vanishes)
in referential form is the residual

    R(u) = int_V0 grad(v) : P dV0 - f = 0,    P = F S,   S = dW/dE,

for every virtual displacement ``v``: ``B(u)^T S`` with ``B`` the variation of the Green–Lagrange
strain, ``dE = sym(F^T grad v)``. Its derivative, the tangent stiffness, is

    K = int_V0 grad(dv) : A : grad(v) dV0,     A_iJkL = F_iI D_IJKL F_kK  +  delta_ik S_JL
                                                        (material)         (geometric, initial
                                                                            stress)

with ``D = dS/dE``. Two formulations (thesis §2.7, §2.8) give the same discrete solution:

* ``"total"`` Lagrangian: the reference and configuration of transformation is the unstrained
  mesh ``C_U``; the unknown is the total displacement, ``F = I + grad_X u``; the strain splits as
  ``E = E1 + E2 + E3`` (eqs. 2.7.19–2.7.21) with the coupling terms of ``E2`` active.
* ``"updated"`` Lagrangian: each load step starts from the last converged configuration ``C_1``:
  the mesh coordinates are moved by the converged displacement and gradients are taken on the
  moved mesh. The strain state carried from step to step is the thesis's pseudo-strain ``11_1 E``
  (the Almansi strain of ``C_1``), obtained at the end of each step by the change of reference of
  eq. 2.8.9. In the step the strain is ``11_1 E + E2 + E3`` with ``E2 = sym(h)`` (the coupling
  terms vanish, eq. 2.7.36) and ``E3 = h^T h / 2``, ``h`` the increment's gradient in ``C_1``
  (eq. 2.8.11). The stress conjugate to it per unit volume of ``C_1`` is the push-forward of the
  material's ``S`` to ``C_1`` (:func:`vfem.kinematics.push_forward_stress`); for the isotropic
  materials here it depends on ``C_1`` only through ``b_1 = (I - 2 11_1E)^-1``, so the carried
  pseudo-strain is the whole state (the push-forward uses ``V_1 = sqrt(b_1)``, which differs from
  ``F_1`` by a rotation an isotropic law does not see).

Each load step is solved by Newton's method from the last converged state; the step's increment
of the prescribed displacements enters with the first correction. The residual norm per iteration
and the ratio ``r_k+1 / r_k^2`` (constant when convergence is quadratic) are logged at INFO level
and kept in :attr:`NonlinearBody.steps` / :attr:`NonlinearBody.history`.

Both are exact discretisations of the same problem on the same quadrature points (with isoparametric
elements a quadrature point of the moved mesh is the same material point, and ``dV1 = J1 dV0``
there), so they agree to the Newton tolerance.

A third form, ``"small"``, serves a law with history under small kinematics (J2 plasticity,
:mod:`vfem.materials.plastic`, issue 41): the strain is the small strain ``sym(grad u)``, the
stress the Cauchy stress it answers, ``F = I`` and no initial-stress term, so the residual is
``int B^T sigma`` and the tangent ``int B^T C B`` with the law's consistent tangent ``C``;
Newton's method then answers the material's nonlinearity alone.

Bodies of revolution (``axisymmetric=True``, issue 42) take the 3D path on their 2D mesh: the
displacement gradient about the axis is 3x3, its (3, 3) slot the hoop ``u_r / r`` (and of a
virtual displacement ``v_r / r``), so ``F``, ``E``, ``S`` and ``A`` are the 3D ones with no
out-of-plane assumption, and every integral carries ``2 pi r`` (of the reference mesh in the
total form, of ``C_1`` in the updated one: ``dV = 2 pi r dA`` of the configuration the gradients
are taken on).

3D bodies (tetrahedra, hexahedra; issue 21, C16) take the same path with 3x3 tensors: the
dimension is the mesh's (``self.dim``), dofs are ``dim * node + component``, no out-of-plane
stress is carried, and the left stretch ``V_1`` of the updated form is the square root of
``b_1`` by its eigenvectors (the 2x2 closed form stays the 2D one).
"""

from __future__ import annotations

import functools
import logging
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import MatrixRankWarning
from skfem import (
    Basis,
    BilinearForm,
    ElementVector,
    LinearForm,
    Mesh,
    MeshHex1,
    MeshHex2,
    MeshQuad1,
    MeshQuad2,
    MeshTet1,
    MeshTet2,
    MeshTri1,
    MeshTri2,
    condense,
    solve,
)
from skfem.helpers import ddot, grad, mul
from skfem.quadrature import get_quadrature
from skfem.refdom import RefHex, RefQuad, RefTri

from .errors import AnalysisError, ElementInverted, InputError, NewtonNotConverged
from .kinematics import (
    change_reference,
    deformation_gradient,
    determinant,
    green_lagrange,
    inverse,
    push_forward_stress,
    strain_increment,
    updated_strain_increment,
)
from .materials.protocol import Material, State

log = logging.getLogger(__name__)

TOTAL = "total"
UPDATED = "updated"
#: small kinematics for a law with history (a plastic one, issue 41): the strain is
#: sym(grad u), F = I, no geometric stiffness; Newton's method answers the law alone
SMALL = "small"
COMPONENTS = {"x": 0, "y": 1, "z": 2}

# linear mesh -> the quadratic-geometry mesh of the same connectivity (for P2/Q2)
_QUADRATIC_MESH: dict[type, type] = {MeshTri1: MeshTri2, MeshQuad1: MeshQuad2,
                                     MeshTet1: MeshTet2, MeshHex1: MeshHex2}


_MAX_HALVINGS = 8


#: an iterate would turn an element inside out (det F <= 0 at a quadrature point)
_Inverted = ElementInverted


# -- forms: residual and tangent, as scikit-fem states them ---------------------------------------
# (what :class:`_ElementArrays` computes by whole arrays; tests/test_nonlinear.py checks the two
# against each other)

@LinearForm
def _internal_force_form(v, w):
    """``grad(v) : P``, P = F S the first Piola–Kirchhoff stress (per unit reference volume)."""
    return ddot(w["P"], grad(v))


@BilinearForm
def _tangent_form(du, v, w):
    """``grad(v) : A : grad(du)`` with ``A = dP/dF`` (material + geometric stiffness)."""
    return ddot(np.einsum("ijkl...,kl...->ij...", np.asarray(w["A"]), grad(du)), grad(v))


class _ElementArrays:
    """A large body's element quantities on one basis by whole arrays: the tangent stiffness of
    :func:`_tangent_form`, the internal force of :func:`_internal_force_form` and the
    displacement gradient.

    Per element ``K_e = sum_q w_q B_q^T A_q B_q``, ``B_q`` the gradients of the basis functions
    (``grad(v) : X = B_q[:, i] . X`` flattened, from scikit-fem's basis), then one scatter into
    the sparsity pattern found once per basis. It gives ``asm(_tangent_form, basis, A=A)`` to
    round-off. **Why** (issue 19, measured with one thread): scikit-fem calls the form once per
    pair of local basis functions (64 for a bilinear quadrilateral, 144 for a quadratic
    triangle), each an einsum over every quadrature point; the tangent took 60 % of a
    linearisation in the sliding example. On 1,920 bilinear quadrilaterals 14.7 ms against
    3.4 ms, on 3,840 quadratic triangles 61 ms against 13 ms (the scatter included), the same
    matrix to 4e-16.
    """

    def __init__(self, basis: Basis, axisymmetric: bool = False):
        nb = basis.Nbfun
        ne, nq = basis.nelems, basis.X.shape[-1]
        G = np.array([np.asarray(basis.basis[j][0].grad) for j in range(nb)])
        self.dx = basis.dx
        if axisymmetric:
            # a body of revolution (issue 42): the gradient of (u_r, u_z) about the y axis is
            # the 3x3 [[du_r/dr, du_r/dz, 0], [du_z/dr, du_z/dz, 0], [0, 0, u_r / r]] (the hoop
            # stretch r'/r = 1 + u_r / r, no twist), and every integral has the measure 2 pi r:
            # the 3D forms of the module's docstring with 3x3 tensors, per full circle
            V = np.array([np.asarray(basis.basis[j][0]) for j in range(nb)])
            r = np.asarray(basis.global_coordinates())[0]  # (ne, nq), > 0 inside
            G3 = np.zeros((nb, 3, 3, ne, nq))
            G3[:, :2, :2] = G
            G3[:, 2, 2] = V[:, 0] / r
            G = G3
            self.dx = basis.dx * 2.0 * np.pi * r
        dim = G.shape[1]  # the tensors': the mesh's, or 3 about an axis
        #: B[e, q, (c, J), i]: d(v_i)_c / dX_J (and v_r / r in the hoop slot (2, 2))
        self.B = np.ascontiguousarray(G.transpose(3, 4, 1, 2, 0).reshape(ne, nq, dim * dim, nb))
        self.shape = (ne, nq, dim * dim)
        dofs = basis.element_dofs  # (nb, ne)
        self.element_dofs = np.ascontiguousarray(dofs.T)
        rows = np.broadcast_to(dofs.T[:, :, None], (ne, nb, nb)).ravel()
        cols = np.broadcast_to(dofs.T[:, None, :], (ne, nb, nb)).ravel()
        keys, self.slot = np.unique(rows.astype(np.int64) * basis.N + cols, return_inverse=True)
        self.indices = (keys % basis.N).astype(np.int32)
        self.indptr = np.searchsorted(keys // basis.N, np.arange(basis.N + 1)).astype(np.int32)
        self.N = basis.N

    @classmethod
    def of(cls, basis: Basis, axisymmetric: bool = False) -> _ElementArrays:
        """The assembly for ``basis``, made once and kept on it (a total-Lagrangian body's
        reference basis lives as long as the body, an updated one's basis for its step)."""
        key = "_vfem_tangent_assembly_rz" if axisymmetric else "_vfem_tangent_assembly"
        found = getattr(basis, key, None)
        if found is None:
            found = cls(basis, axisymmetric)
            setattr(basis, key, found)
        return found

    def gradient(self, u: np.ndarray) -> np.ndarray:
        """``basis.interpolate(u).grad`` (dim, dim, ne, nq) by the same gradients (3x3 with
        the hoop component about an axis), to
        round-off: one batched product instead of scikit-fem's sum over the basis functions
        (a third of the time of a large body's state in the sliding example)."""
        ne, nq, m = self.shape
        dim = int(round(m ** 0.5))
        g = np.einsum("eqmj,ej->meq", self.B, u[self.element_dofs], optimize=True)
        # contiguous: the einsums downstream ran 20 times slower on the strided view
        return np.ascontiguousarray(g).reshape(dim, dim, ne, nq)

    def internal_force(self, P: np.ndarray) -> np.ndarray:
        """``asm(_internal_force_form, basis, P=P)`` to round-off: ``sum_q w_q B_q^T P_q`` per
        element, scattered by the element dofs."""
        ne, nq, m = self.shape
        Pw = np.ascontiguousarray((P * self.dx).transpose(2, 3, 0, 1)).reshape(ne, nq, m)
        fe = np.einsum("eqmj,eqm->ej", self.B, Pw, optimize=True)
        return np.bincount(self.element_dofs.ravel(), weights=fe.ravel(), minlength=self.N)

    def assemble(self, A: np.ndarray) -> sp.csr_matrix:
        """The CSR tangent for the moduli ``A`` (dim, dim, dim, dim, ne, nq)."""
        ne, nq, m = self.shape
        Am = (A * self.dx).transpose(4, 5, 0, 1, 2, 3).reshape(ne, nq, m, m)
        AB = (Am @ self.B).reshape(ne, nq * m, -1)
        # (ne, i, j): the sum over q and (c, J) of B_i A B_j (B transposed as a view: no
        # second copy of the gradients kept, as fast)
        Ke = np.matmul(self.B.reshape(ne, nq * m, -1).transpose(0, 2, 1), AB)
        data = np.bincount(self.slot, weights=Ke.ravel(), minlength=len(self.indices))
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.N, self.N))


@dataclass
class _State:
    """Kinematic and stress fields at the quadrature points of ``basis`` for one iterate.

    The material tangent ``D`` is computed when first read (``moduli``): an iterate whose
    tangent is never assembled (the last of a Newton iteration, a halved correction) does
    not pay for it (about a third of a state's time with the neo-Hookean law)."""

    basis: Basis
    F: np.ndarray  # (dim, dim, ne, nq) deformation gradient from the reference of the formulation
    S: np.ndarray  # (dim, dim, ne, nq) 2nd Piola–Kirchhoff stress relative to that reference
    moduli: Callable[[], np.ndarray]  # gives D
    S33: np.ndarray | None  # (ne, nq) out-of-plane S_33 (plane strain); None in 3D
    material_state: State  # what this iterate would commit (materials.protocol)
    geometric: bool = True  # the initial-stress term (False: small kinematics, F = I)

    @functools.cached_property
    def D(self) -> np.ndarray:
        """(dim, dim, dim, dim, ne, nq) dS/dE."""
        return self.moduli()

    def first_piola(self) -> np.ndarray:
        return mul(self.F, self.S)

    def tangent_moduli(self) -> np.ndarray:
        """``A_iJkL = F_iI D_IJKL F_kK + delta_ik S_JL`` (small kinematics: ``D``)."""
        if not self.geometric:
            return self.D
        A = np.einsum("iI...,IJKL...,kK...->iJkL...", self.F, self.D, self.F)
        for i in range(A.shape[0]):
            A[i, :, i] += self.S
        return A


@dataclass
class NewtonStep:
    """The record of one load step.

    Attributes:
        load_factor: the load factor the step reached.
        residuals: norm of the residual on the free dofs, one entry per evaluation: the first at
            the last converged state under the step's loads (zero for a step driven by prescribed
            displacements only: those enter with the first correction), the last the converged
            one. ``len(residuals) - 1`` Newton corrections were made.
        reference_force: the force the residuals are measured against: the largest over the
            step's iterations of the external and internal force norms (the latter includes the
            reactions), not below a floor ``1e-6 E L`` (a load that strains the body by 1e-6;
            needed when nothing loads it, e.g. a rigid motion).
        converged: whether the tolerance was met.
        seconds: wall time of the step.
    """

    load_factor: float
    residuals: list[float] = field(default_factory=list)
    reference_force: float = 0.0
    converged: bool = False
    seconds: float = 0.0

    @property
    def iterations(self) -> int:
        return max(len(self.residuals) - 1, 0)

    @property
    def relative_residuals(self) -> list[float]:
        return [r / self.reference_force for r in self.residuals]

    @property
    def quadratic_ratios(self) -> list[float]:
        """``r_{k+1} / r_k^2`` on the relative residuals; bounded when convergence is quadratic."""
        r = self.relative_residuals
        return [b / a**2 if a > 0 else math.nan for a, b in zip(r[:-1], r[1:])]


Values = float | np.ndarray | Callable[[float], np.ndarray]


def gauss_rule(element) -> tuple[np.ndarray, np.ndarray]:
    """The points and weights of ``element``'s full Gauss rule, which a Newton body integrates
    with and keeps its material state at: p + 1 Gauss points a direction on quadrilaterals and
    hexahedra of degree p (2 x 2 and 2 x 2 x 2 for bilinear and trilinear, 3 x 3 and 3 x 3 x 3
    for quadratic ones: exact to degree 2p + 1), the centroid of a linear triangle or
    tetrahedron (its strain is constant), three and four points on quadratic ones (exact to
    degree 2): the rules of CalculiX's CPE4, C3D8, CPE3, C3D4, CPE6 and C3D10. Each integrates
    the stiffness of an affine element exactly. They are the points where a degree-p element's
    stresses are most accurate (Barlow, *Int. J. Numer. Meth. Eng.* 10, 1976: the Gauss points
    of order p are the element's optimal stress points), so that a law with history (a plastic
    one) yields where the element's stress is best read, not where it is extrapolated towards
    a corner: scikit-fem's default (order twice the element's highest degree: 4 x 4 x 4
    points on a trilinear hexahedron) samples points near the corners, and on the sphere's
    flat at Hertz's onset force their largest von Mises stress read 1.0108 Y against 0.9960 Y
    at the Gauss points (issue 41, ``docs/method.md`` §13), with 8 times the states to
    return."""
    ref = element.refdom
    p = element.maxdeg
    if ref is RefTri and p == 1:
        return np.full((2, 1), 1.0 / 3.0), np.array([0.5])
    if ref in (RefQuad, RefHex):
        return get_quadrature(ref, 2 * (p // ref.dim()) + 1)
    return get_quadrature(ref, max(1, 2 * (p - 1)))


class NonlinearBody:
    """A hyperelastic body, plane strain or 3D, under large displacements (see the module
    docstring).

    Args:
        mesh: a scikit-fem ``MeshTri1`` or ``MeshQuad1`` (or their quadratic-geometry ``MeshTri2``
            / ``MeshQuad2``), or in 3D ``MeshTet1`` / ``MeshHex1`` (``MeshTet2`` / ``MeshHex2``);
            named boundaries are used by :meth:`boundary_dofs`.
        material: :class:`SaintVenantKirchhoff`, :class:`NeoHookean`, or any law with the
            :class:`~vfem.materials.Material` protocol: its state (none for these two) is
            carried from step to step, committed by :meth:`accept`.
        order: 1 (P1/Q1) or 2 (P2/Q2). Elements are isoparametric: with ``order=2`` a linear mesh is
            given quadratic geometry (``MeshTri2.from_mesh``), so that the updated formulation can
            move the midside nodes with the displacement.
        formulation: ``"total"`` or ``"updated"`` Lagrangian.
        name: used in messages.
        axisymmetric: a body of revolution about the y axis (issue 42): its 2D mesh is the
            r-z half-plane (x = r >= 0), its tensors 3x3 with the hoop stretch 1 + u_r / r
            (thesis eqs. 2.7.19–2.7.21 and 2.8.11 as in 3D, the gradient's (3, 3) slot u_r / r
            and the others out of the plane zero) and every integral the measure 2 pi r: forces
            per full circle, as the linear :class:`~vfem.bodies.section.Axisymmetric` body's.

    Dofs are scikit-fem's ``ElementVector`` numbering on :attr:`basis0` (x and y, and z in 3D, of
    each node interleaved: ``dim * node + component``). Prescribe with :meth:`prescribe` and load
    with :meth:`add_nodal_forces`, then call :meth:`solve`.
    """

    def __init__(self, mesh: Mesh, material: Material, *, order: int = 1,
                 formulation: str = TOTAL, name: str = "body", axisymmetric: bool = False):
        self.name = name
        if not isinstance(material, Material):
            raise InputError(f"{name}: material must be SaintVenantKirchhoff or NeoHookean, "
                             f"or a law with the methods of vfem.materials.Material, "
                             f"got {type(material).__name__}")
        material.validate(f"{name}: material")
        if formulation not in (TOTAL, UPDATED, SMALL):
            raise InputError(f"{name}: formulation must be 'total', 'updated' or 'small', "
                             f"got {formulation!r}")
        if order not in (1, 2):
            raise InputError(f"{name}: order must be 1 or 2, got {order!r}")
        self.material = material
        self.formulation = formulation
        self.order = order
        self._boundaries = mesh.boundaries
        self.mesh = self._working_mesh(mesh)
        self.basis0 = Basis(self.mesh, ElementVector(self.mesh.elem()),
                            quadrature=gauss_rule(self.mesh.elem()))
        self.ndofs = self.basis0.N
        self.dim = dim = self.mesh.dim()
        if axisymmetric and dim != 2:
            raise InputError(f"{name}: a body of revolution has a 2D (r-z) mesh, got a {dim}D one")
        self.axisymmetric = bool(axisymmetric)
        #: the dimension of its tensors: the mesh's, or 3 for a body of revolution (its hoop
        #: components; its dofs stay the mesh's two a node)
        self.tensor_dim = 3 if axisymmetric else dim
        # the node of each dof, as positions in mesh.doflocs: isoparametric elements have their
        # nodes at the mesh's doflocs, x and y (and z) interleaved
        if not all(np.allclose(self.basis0.doflocs[:, c::dim], self.mesh.doflocs)
                   for c in range(dim)):
            raise InputError(f"{name}: dof numbering does not follow the mesh nodes")
        p = self.mesh.doflocs
        span = p.max(axis=1) - p.min(axis=1)
        # (np.hypot takes two coordinates: a third would be its out= argument)
        self.length = float(np.hypot(*span)) if dim == 2 else float(np.linalg.norm(span))
        self.nodal_forces = np.zeros(self.ndofs)
        self._load_history: Callable[[float], np.ndarray] | None = None
        self._prescribed: list[tuple[np.ndarray, Values]] = []
        self.displacement = np.zeros(self.ndofs)
        self.load_factor = 0.0
        self.steps: list[NewtonStep] = []
        # updated Lagrangian state: the current configuration C_1 and the pseudo-strain 11_1 E
        self._reset_updated_state()
        # the material's converged state at the quadrature points (materials.protocol)
        self.material_state = material.initial_state(self.tensor_dim,
                                                     self.pseudo_strain.shape[2:])

    # -- set-up ---------------------------------------------------------------------------------

    def _working_mesh(self, mesh: Mesh) -> Mesh:
        if isinstance(mesh, (MeshTri2, MeshQuad2, MeshTet2, MeshHex2)):
            if self.order != 2:
                raise InputError(f"{self.name}: a quadratic-geometry mesh needs order=2")
            return mesh
        for linear, quadratic in _QUADRATIC_MESH.items():
            if isinstance(mesh, linear):
                if self.order == 1:
                    return mesh
                m2 = quadratic.from_mesh(mesh)
                if not np.array_equal(m2.facets, mesh.facets):  # boundaries index the facets
                    raise InputError(f"{self.name}: facet numbering changed with the P2 geometry")
                return m2
        raise InputError(f"{self.name}: mesh must be MeshTri1/MeshQuad1/MeshTri2/MeshQuad2 (2D) "
                         f"or MeshTet1/MeshHex1/MeshTet2/MeshHex2 (3D), "
                         f"got {type(mesh).__name__}")

    def _reset_updated_state(self) -> None:
        self.current_mesh = self.mesh
        self.current_basis = self.basis0
        nq = self.basis0.X.shape[-1]
        self.pseudo_strain = np.zeros((self.tensor_dim, self.tensor_dim, self.mesh.nelements,
                                       nq))
        self._u_at_current = np.zeros(self.ndofs)
        self._stretch_cache: tuple[np.ndarray, np.ndarray] | None = None
        self._delta = np.zeros(self.ndofs)  # trial displacement since the converged state
        self._trial_state: _State | None = None
        self._trial_converged = False

    def boundary_dofs(self, boundary: str | np.ndarray, component: str | None = None
                      ) -> np.ndarray:
        """Dofs on a named boundary (or on an array of facet indices), one component or all."""
        if isinstance(boundary, str):
            if not self._boundaries or boundary not in self._boundaries:
                names = sorted(self._boundaries or {})
                raise InputError(f"{self.name}: no boundary {boundary!r} (have {names})")
            facets = self._boundaries[boundary]
        else:
            facets = np.asarray(boundary, dtype=int)
        dofs = self.basis0.get_dofs(facets)
        if component is None:
            return np.sort(dofs.all())
        self._check_component(component)
        return np.sort(dofs.all(f"u^{COMPONENTS[component] + 1}"))

    def _check_component(self, component: str) -> None:
        if component not in COMPONENTS or COMPONENTS[component] >= self.dim:
            names = [repr(c) for c in list(COMPONENTS)[: self.dim]]
            names = ", ".join(names[:-1]) + " or " + names[-1]  # 'x' or 'y'; 'x', 'y' or 'z'
            raise InputError(f"{self.name}: component must be {names}, got {component!r}")

    def node_dofs(self, nodes: np.ndarray, component: str | None = None) -> np.ndarray:
        """Dofs of the given nodes (columns of ``mesh.doflocs``)."""
        nodes = np.asarray(nodes, dtype=int)
        dim = self.dim
        if component is None:
            return np.stack([dim * nodes + c for c in range(dim)], axis=-1).ravel()
        self._check_component(component)
        return dim * nodes + COMPONENTS[component]

    def prescribe(self, dofs: np.ndarray, values: Values = 0.0) -> None:
        """Prescribe the (total) displacement of ``dofs``.

        ``values`` is a number or an array (one per dof): the displacement at load factor 1,
        scaled by the load factor; or a callable ``values(load_factor) -> array`` for a
        displacement that is not proportional to the load factor (e.g. a finite rotation).
        A dof prescribed twice takes the last value.
        """
        dofs = np.asarray(dofs, dtype=int).ravel()
        if np.any((dofs < 0) | (dofs >= self.ndofs)):
            raise InputError(f"{self.name}: prescribed dof out of range")
        if not callable(values):
            values = np.broadcast_to(np.asarray(values, dtype=float), dofs.shape).copy()
        self._prescribed.append((dofs, values))

    def add_nodal_forces(self, dofs: np.ndarray, forces: float | np.ndarray) -> None:
        """Add dead nodal forces (fixed direction, at load factor 1) on ``dofs``."""
        dofs = np.asarray(dofs, dtype=int).ravel()
        np.add.at(self.nodal_forces, dofs,
                  np.broadcast_to(np.asarray(forces, dtype=float), dofs.shape))

    def set_load_history(self, loads: Callable[[float], np.ndarray]) -> None:
        """Dead nodal forces that are not proportional to the load factor: ``loads(load_factor)``
        (ndofs) replaces ``load_factor * nodal_forces`` (load curves, :class:`vfem.bodies.Body`
        passes its :meth:`~vfem.bodies.Body.applied_load`)."""
        self._load_history = loads

    def dead_loads(self, load_factor: float) -> np.ndarray:
        """The dead nodal forces (ndofs) at ``load_factor``."""
        if self._load_history is None:
            return load_factor * self.nodal_forces
        return np.asarray(self._load_history(load_factor), dtype=float)

    def _dirichlet(self, load_factor: float) -> tuple[np.ndarray, np.ndarray]:
        """Prescribed dofs and their total displacement at ``load_factor``."""
        values: dict[int, float] = {}
        for dofs, v in self._prescribed:
            vals = (np.asarray(v(load_factor), dtype=float).ravel() if callable(v)
                    else load_factor * v)
            values.update(zip(dofs.tolist(), vals.tolist()))
        D = np.array(sorted(values), dtype=int)
        return D, np.array([values[d] for d in D.tolist()], dtype=float)

    # -- state at the quadrature points -----------------------------------------------------------

    def _state(self, delta: np.ndarray) -> _State:
        """Fields for the iterate ``u_C1 + delta`` (``delta``: displacement since the step start).

        Total: gradients on the initial mesh of the total displacement; the strain of thesis
        eq. 2.7.11 with ``C_A = C_U`` (E4 = 0): ``E1 + E2 + E3 = E(G0 + g)``.
        Updated: gradients on the current mesh ``C_1`` of the increment; strain
        ``11_1 E + E2 + E3`` (eqs. 2.7.31–2.7.36, 2.8.11).
        """
        if self.formulation == SMALL:  # eps = sym(grad u), F = I (issue 41)
            arrays = self._arrays(self.basis0)
            g = arrays.gradient(self._u_at_current + delta)
            eps = 0.5 * (g + g.transpose(1, 0, 2, 3))
            r = self.material.response(eps, self.material_state)
            F = deformation_gradient(np.zeros_like(g))  # I
            return _State(self.basis0, F, r.stress, r.moduli, r.out_of_plane, r.state,
                          geometric=False)
        if self.formulation == TOTAL:
            basis = self.basis0
            G0 = self._arrays(basis).gradient(self._u_at_current)
            g = self._arrays(basis).gradient(delta)
            F = deformation_gradient(G0 + g)
            self._check_orientation(F)
            E = strain_increment(G0, g).total
            r = self.material.response(E, self.material_state)
            return _State(basis, F, r.stress, r.moduli, r.out_of_plane, r.state)
        basis = self.current_basis
        h = self._arrays(basis).gradient(delta)
        f = deformation_gradient(h)
        self._check_orientation(f)
        E_pseudo = updated_strain_increment(h, self.pseudo_strain).total
        S, moduli, S33, material_state = self._pushed_material(E_pseudo)
        return _State(basis, f, S, moduli, S33, material_state)

    def _pushed_material(self, E_pseudo: np.ndarray
                         ) -> tuple[np.ndarray, Callable[[], np.ndarray], np.ndarray, dict]:
        """Stress and tangent conjugate to the pseudo-strain in ``C_1``, per unit volume of ``C_1``
        (the tangent as a function, :class:`_State`), and the material state to commit.

        With ``F_1`` the deformation gradient of ``C_1`` the material sees the Green–Lagrange
        strain ``E = F_1^T E_pseudo F_1`` (eq. 2.8.9 read backwards) and the conjugate stress in
        ``C_1`` is ``J_1^-1 F_1 S F_1^T``, the tangent ``J_1^-1 F_1 F_1 F_1 F_1 : D``. Isotropy lets
        ``V_1 = b_1^(1/2)``, ``b_1 = (I - 2 11_1E)^-1``, stand for ``F_1`` for a law without
        history. A law with history (a plastic one, issue 41) keeps its state in the frame of
        the reference configuration, which a rotation of ``C_1`` turns: it is given ``F_1``
        itself, from the converged displacement's gradient on the initial mesh (the same
        material point: the elements are isoparametric), and sees exactly the total form's
        strain.
        """
        if self.material_state:  # F_1 itself: E = F_1^T E_pseudo F_1, S_c = F_1 S F_1^T / J_1
            V, J1 = self._configuration()
            Vt = np.ascontiguousarray(np.swapaxes(V, 0, 1))
        else:  # V_1, symmetric
            V, J1 = self._left_stretch()
            Vt = V
        E = mul(Vt, mul(E_pseudo, V))
        r = self.material.response(E, self.material_state)
        S_c = mul(V, mul(r.stress, Vt)) / J1

        def D_c() -> np.ndarray:
            D = r.moduli()
            return np.einsum("iI...,jJ...,IJKL...,kK...,lL...->ijkl...", V, V, D, V, V) / J1

        S33 = r.out_of_plane
        return S_c, D_c, (None if S33 is None else S33 / J1), r.state

    def _left_stretch(self) -> tuple[np.ndarray, np.ndarray]:
        """``V_1 = b_1^(1/2)`` and ``J_1 = det V_1`` from the carried pseudo-strain (Almansi).

        ``11_1E = (I - b_1^-1)/2`` so ``b_1^-1 = I - 2 11_1E``; the square root of a symmetric
        positive-definite 2x2 matrix ``M`` is ``(M + sqrt(det M) I) / sqrt(tr M + 2 sqrt(det M))``.
        In 3D, by the eigenvectors of ``b_1^-1`` (:meth:`_left_stretch_3d`).
        """
        if self._stretch_cache is not None:
            return self._stretch_cache
        if self.tensor_dim == 3:
            self._stretch_cache = self._left_stretch_3d()
            return self._stretch_cache
        b_inv = -2.0 * self.pseudo_strain
        b_inv[0, 0] += 1.0
        b_inv[1, 1] += 1.0
        b = inverse(b_inv)
        s = np.sqrt(determinant(b))  # = J_1
        V = b.copy()
        V[0, 0] += s
        V[1, 1] += s
        V /= np.sqrt(b[0, 0] + b[1, 1] + 2.0 * s)
        self._stretch_cache = (V, s)
        return V, s

    def _configuration(self) -> tuple[np.ndarray, np.ndarray]:
        """``F_1`` and ``J_1 = det F_1`` of the converged configuration ``C_1``, by the
        displacement's gradient on the initial mesh (kept for the step)."""
        if self._stretch_cache is None:
            F1 = deformation_gradient(self._arrays(self.basis0).gradient(self._u_at_current))
            self._stretch_cache = (F1, determinant(F1))
        return self._stretch_cache

    def _left_stretch_3d(self) -> tuple[np.ndarray, np.ndarray]:
        """``V_1`` and ``J_1`` of a 3D body: ``b_1^-1 = I - 2 11_1E = Q diag(m) Q^T`` (symmetric
        positive definite), so ``V_1 = Q diag(m^-1/2) Q^T`` and ``J_1 = prod(m)^-1/2``."""
        b_inv = -2.0 * self.pseudo_strain
        for i in range(3):
            b_inv[i, i] += 1.0
        m, Q = np.linalg.eigh(np.moveaxis(b_inv, (0, 1), (-2, -1)))  # (ne, nq, 3), (ne, nq, 3, 3)
        if np.any(m <= 0.0):
            raise AnalysisError(f"{self.name}: the carried strain is not that of a deformation "
                                "(I - 2 E_Almansi not positive definite)")
        V = np.einsum("...ik,...k,...jk->...ij", Q, 1.0 / np.sqrt(m), Q)
        return np.ascontiguousarray(np.moveaxis(V, (-2, -1), (0, 1))), 1.0 / np.sqrt(m.prod(-1))

    def _arrays(self, basis: Basis) -> _ElementArrays:
        """The element arrays of ``basis`` (about the axis for a body of revolution)."""
        return _ElementArrays.of(basis, self.axisymmetric)

    def _check_orientation(self, F: np.ndarray) -> None:
        J = determinant(F)
        if np.any(J <= 0.0):
            raise _Inverted(f"{self.name}: an element turned inside out (det F = "
                            f"{float(J.min()):.3g}); use smaller load steps")

    # -- assembled quantities ---------------------------------------------------------------------

    def _internal(self, state: _State) -> np.ndarray:
        return self._arrays(state.basis).internal_force(state.first_piola())

    def _tangent(self, state: _State):
        return self._arrays(state.basis).assemble(state.tangent_moduli())

    def internal_force(self) -> np.ndarray:
        """Internal nodal forces ``int grad(v) : P`` at the current state (ndofs)."""
        return self._internal(self._state(np.zeros(self.ndofs)))

    def tangent_stiffness(self):
        """Tangent stiffness (material + geometric) at the current state, all dofs, CSR.

        In the updated formulation it is taken with respect to the displacement from the current
        configuration; both formulations give the same matrix at a converged state.
        """
        return self._tangent(self._state(np.zeros(self.ndofs)))

    def reactions(self) -> np.ndarray:
        """``f_int - load_factor f_ext`` (ndofs): on the prescribed dofs the forces the supports
        apply to the body (equilibrium: ``f_int = f_ext + reactions``); round-off elsewhere after
        a converged step."""
        return self.internal_force() - self.dead_loads(self.load_factor)

    # -- Newton ---------------------------------------------------------------------------------

    def solve(self, load_factor_steps: Sequence[float] | int, tol: float = 1e-10,
              max_iter: int = 25) -> list[NewtonStep]:
        """Apply the load in steps, Newton's method in each; return the steps' records.

        Args:
            load_factor_steps: the load factors to reach in turn (e.g. ``[0.25, 0.5, 1.0]``), or
                a number of equal steps to 1.
            tol: converged when ``|R_free| <= tol * reference_force`` (see :class:`NewtonStep`),
                or when a Newton correction falls to round-off (``1e-13 L``).
            max_iter: Newton corrections allowed per step.

        Raises:
            AnalysisError: a step did not converge or an element turned inside out; the body keeps
                the last converged state.
        """
        if isinstance(load_factor_steps, int):
            load_factor_steps = [(i + 1) / load_factor_steps for i in range(load_factor_steps)]
        records = []
        for lf in load_factor_steps:
            records.append(self._step(float(lf), tol, max_iter))
        return records

    @property
    def history(self) -> list[list[float]]:
        """Residual norms per step (see :attr:`NewtonStep.residuals`), all steps so far."""
        return [s.residuals for s in self.steps]

    def _step(self, load_factor: float, tol: float, max_iter: int) -> NewtonStep:
        """One load step: Newton's method from the last converged state, then accepted."""
        self.discard()
        record = self.equilibrate(load_factor, tol=tol, max_iter=max_iter)
        self.accept()
        log.info("%s: load factor %.6g converged in %d iterations (%.3f s)", self.name,
                 load_factor, record.iterations, record.seconds)
        return record

    def equilibrate(self, load_factor: float, extra_force: np.ndarray | None = None,
                    tol: float = 1e-10, max_iter: int = 25) -> NewtonStep:
        """Newton's method for equilibrium at ``load_factor`` with ``extra_force`` (ndofs, dead
        nodal forces, e.g. contact forces) added to the loads, *without* accepting the result.

        It starts from the last trial iterate of the current step (the last converged state
        after :meth:`accept` or :meth:`discard`), so a contact iteration that changes the
        contact forces a little is re-equilibrated in one or two corrections. The trial state is
        what :meth:`trial_displacement` and :meth:`linearize` see; :meth:`accept` makes it the
        new converged state (the updated formulation then moves its reference), :meth:`discard`
        goes back to the last converged one.

        The step's increment of the prescribed displacements enters through the first Newton
        correction (``K_ff d_f = -R_f - K_fD d_D``) rather than by moving those nodes alone first,
        which would crush the elements next to them before the rest of the body follows.

        Raises:
            AnalysisError: no convergence in ``max_iter`` corrections, or an element turned
                inside out; the trial state is left at the last converged one.
        """
        t0 = time.perf_counter()
        record = NewtonStep(load_factor)
        D, uD = self._dirichlet(load_factor)
        free = np.setdiff1d(np.arange(self.ndofs), D)
        delta = self._delta.copy()  # displacement since the last converged state
        pending = np.zeros(self.ndofs)  # prescribed increment not yet applied
        pending[D] = uD - (self._u_at_current + delta)[D]
        f_ext = self._loads(load_factor, extra_force)
        last_correction = math.inf
        previous = None
        self._trial_converged = False
        try:
            state = self._state(delta)
        except _Inverted:
            self.discard()
            raise
        for k in range(max_iter + 1):
            f_int = self._internal(state)
            R = f_int - f_ext
            r = float(np.linalg.norm(R[free]))
            ref = self._reference_force(f_ext, f_int)
            record.residuals.append(r)
            record.reference_force = max(record.reference_force, ref)
            ratio = (r / ref) / (previous / ref) ** 2 if previous else math.nan
            log.debug("%s: load factor %.6g, iteration %d: |R| = %.3e (relative %.3e), "
                      "r_k+1/r_k^2 = %.3g", self.name, load_factor, k, r, r / ref, ratio)
            previous = r
            if not pending.any() and (r <= tol * ref or last_correction <= 1e-13 * self.length):
                record.converged = True
                break
            if k == max_iter:
                break
            K = self._tangent(state)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", MatrixRankWarning)  # singular: below
                correction = solve(*condense(K, -R, D=D, x=pending))
            if not np.isfinite(correction).all():
                self.steps.append(record)
                self.discard()
                raise NewtonNotConverged(
                    f"{self.name}: the tangent stiffness is singular at load factor "
                    f"{load_factor:g} (iteration {k + 1}): nothing holds the body against "
                    "the load there (a plastic collapse at its limit load, or a mechanism)")
            # A full Newton correction far from the solution can turn elements inside out (the
            # linearised rotation of a slender part stretches it); halve it until none is. Near
            # the solution the full correction is always taken, so convergence stays quadratic.
            # What a halving leaves of the prescribed increment stays pending for the next one.
            fraction = 1.0
            for halvings in range(_MAX_HALVINGS + 1):
                try:
                    state = self._state(delta + fraction * correction)
                    break
                except _Inverted:
                    if halvings == _MAX_HALVINGS:
                        self.discard()
                        raise
                    fraction *= 0.5
                    log.info("%s: correction halved (an element would turn inside out)",
                             self.name)
            correction *= fraction
            pending *= 1.0 - fraction
            last_correction = float(np.abs(correction).max())
            delta += correction
        record.seconds = time.perf_counter() - t0
        if not record.converged:
            self.steps.append(record)
            self.discard()
            raise NewtonNotConverged(
                f"{self.name}: Newton did not converge in {max_iter} iterations at load factor "
                f"{load_factor:g} (|R| = {record.residuals[-1]:.3e}, reference "
                f"{record.reference_force:.3e})")
        if record.iterations > 1:
            log.info("%s: load factor %.6g, residuals %s (quadratic ratios r_k+1/r_k^2 %s)",
                     self.name, load_factor,
                     ", ".join(f"{r:.2e}" for r in record.relative_residuals),
                     ", ".join(f"{q:.3g}" for q in record.quadratic_ratios))
        self._delta = delta
        self._trial_state = state
        self._trial_load_factor = load_factor
        self._trial_converged = True
        self.steps.append(record)
        return record

    def adopt(self, delta: np.ndarray, load_factor: float, record: NewtonStep) -> None:
        """Take the trial state that :meth:`equilibrate` reached elsewhere (the body's owner
        over MPI ranks, :mod:`vfem.parallel`): the displacement ``delta`` since the converged
        state at ``load_factor``, and its record. The state at the quadrature points is
        computed here from ``delta``, as the last iterate there computed it, so every rank
        holds the same numbers."""
        self._delta = np.array(delta, dtype=float)
        self._trial_state = self._state(self._delta)
        self._trial_load_factor = load_factor
        self._trial_converged = True
        self.steps.append(record)

    def accept(self) -> None:
        """Make the last trial state (see :meth:`equilibrate`) the converged state."""
        if not self._trial_converged:
            raise AnalysisError(f"{self.name}: no converged trial state to accept")
        self.material_state = self._trial_state.material_state  # (a converged trial's)
        self._accept(self._delta)
        self.load_factor = self._trial_load_factor
        self.discard()
        log.debug("%s: load factor %.6g accepted", self.name, self.load_factor)

    def discard(self) -> None:
        """Forget the trial state: the next :meth:`equilibrate` starts from the converged one."""
        self._delta = np.zeros(self.ndofs)
        self._trial_state = None
        self._trial_converged = False

    def saved_state(self) -> dict[str, np.ndarray]:
        """The converged state as arrays (step cutting restores it, checkpoints store it):
        everything the next step depends on; :meth:`restore_state` puts it back exactly."""
        state = {"load_factor": np.array(self.load_factor), "u": self._u_at_current.copy()}
        state.update({f"material_{k}": v.copy() for k, v in self.material_state.items()})
        if self.formulation == UPDATED:
            state["pseudo_strain"] = self.pseudo_strain.copy()
            state["current_doflocs"] = self.current_mesh.doflocs.copy()
        return state

    def restore_state(self, state: dict[str, np.ndarray]) -> None:
        """Make ``state`` (from :meth:`saved_state`) the converged state, with no trial."""
        self._reset_updated_state()
        if self.formulation == UPDATED:
            self.pseudo_strain = np.array(state["pseudo_strain"], dtype=float)
            self.current_mesh = replace(self.mesh, doflocs=np.array(state["current_doflocs"]))
            self.current_basis = Basis(self.current_mesh, self.basis0.elem,
                                       quadrature=(self.basis0.X, self.basis0.W))
        self._u_at_current = np.array(state["u"], dtype=float)
        self.displacement = self._u_at_current.copy()
        self.load_factor = float(state["load_factor"])
        self.material_state = {k: np.array(state[f"material_{k}"]) for k in self.material_state}

    def trial_displacement(self) -> np.ndarray:
        """Total displacement (ndofs) of the trial state (the converged one without a trial)."""
        return self._u_at_current + self._delta

    def linearize(self, load_factor: float, extra_force: np.ndarray | None = None):
        """Newton's system at the trial state, for a caller that solves it together with other
        unknowns (the contact iteration of :mod:`vfem.contact.formulations.large`) instead of
        :meth:`equilibrate`.

        Returns ``(R, ref, K, D, pending)``: the residual ``f_int - f_ext`` (ndofs; ``f_ext``
        the loads at ``load_factor`` plus ``extra_force``), the reference force of the
        convergence test (see :class:`NewtonStep`), the tangent stiffness (CSR), the prescribed
        dofs and what their prescribed values at ``load_factor`` still lack (ndofs, zero off
        ``D``). Move the trial state with :meth:`move`.
        """
        R, ref, tangent, D, pending = self.residual(load_factor, extra_force)
        return R, ref, tangent(), D, pending

    def residual(self, load_factor: float, extra_force: np.ndarray | None = None):
        """As :meth:`linearize`, with a function that assembles the tangent in place of the
        tangent itself: ``(R, ref, tangent, D, pending)`` (the contact iteration's check needs
        the residual; the tangent only when it corrects)."""
        D, uD = self._dirichlet(load_factor)
        state = self._trial_state if self._trial_state is not None else self._state(self._delta)
        f_ext = self._loads(load_factor, extra_force)
        f_int = self._internal(state)
        pending = np.zeros(self.ndofs)
        pending[D] = uD - (self._u_at_current + self._delta)[D]
        return (f_int - f_ext, self._reference_force(f_ext, f_int),
                lambda: self._tangent(state), D, pending)

    def _loads(self, load_factor: float, extra_force: np.ndarray | None) -> np.ndarray:
        """External nodal forces: the dead loads at ``load_factor`` plus ``extra_force``."""
        f_ext = self.dead_loads(load_factor)
        return f_ext if extra_force is None else f_ext + extra_force

    def _reference_force(self, f_ext: np.ndarray, f_int: np.ndarray) -> float:
        """What residuals are measured against (:class:`NewtonStep`): the larger force norm,
        not below a load that strains the body by 1e-6."""
        return max(float(np.linalg.norm(f_ext)), float(np.linalg.norm(f_int)),
                   1e-6 * self.material.youngs_modulus * self.length)

    def move(self, correction: np.ndarray) -> None:
        """Add ``correction`` (ndofs) to the trial displacement (see :meth:`linearize`).

        Raises:
            AnalysisError: an element would turn inside out; the trial state is unchanged.
        """
        state = self._state(self._delta + correction)
        self._delta = self._delta + correction
        self._trial_state = state
        self._trial_converged = False

    def internal_force_at(self, u: np.ndarray) -> np.ndarray:
        """Internal nodal forces (ndofs) at the total displacement ``u``."""
        return self._internal(self._state(np.asarray(u, dtype=float) - self._u_at_current))

    def cauchy_stress_at(self, u: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
        """Element averages over the current volume at the total displacement ``u``: the
        in-plane Cauchy stress (nelems, 2, 2) and ``sigma_zz`` (nelems,); in 3D the Cauchy
        stress (nelems, 3, 3) and its zz component; and the fields the material shows of the
        state it would commit there (its optional ``fields``, :mod:`vfem.materials.protocol`;
        by name, (nelems,) each)."""
        state = self._state(np.asarray(u, dtype=float) - self._u_at_current)
        J = determinant(state.F)
        w = self._arrays(state.basis).dx * J
        shown = getattr(self.material, "fields", None)  # optional (materials.protocol)
        fields = {} if shown is None else {
            name: (v * w).sum(axis=-1) / w.sum(axis=-1)
            for name, v in shown(state.material_state).items()}
        sig = push_forward_stress(state.S, state.F)
        avg = (sig * w).sum(axis=-1) / w.sum(axis=-1)
        if state.S33 is None:
            avg = np.moveaxis(avg, -1, 0)
            return avg, avg[:, 2, 2].copy(), fields
        szz = (state.S33 / J * w).sum(axis=-1) / w.sum(axis=-1)
        return np.moveaxis(avg, -1, 0), szz, fields

    def _accept(self, delta: np.ndarray) -> None:
        """Make the converged iterate the new state.

        Updated: ``C_2`` becomes the configuration of transformation and reference. The carried
        pseudo-strain ``21_1 E = 11_1 E + E2 + E3`` is transformed to ``C_2`` by eq. 2.8.9 with
        ``F = I + h`` (eq. 2.8.15), and the mesh nodes move by the increment.
        """
        if self.formulation == UPDATED:
            h = self._arrays(self.current_basis).gradient(delta)
            E_pseudo = updated_strain_increment(h, self.pseudo_strain).total
            self.pseudo_strain = change_reference(E_pseudo, h)
            self._stretch_cache = None
            moved = self.current_mesh.doflocs + self._by_component(delta)
            self.current_mesh = replace(self.current_mesh, doflocs=moved)
            self.current_basis = Basis(self.current_mesh, self.current_basis.elem,
                                       quadrature=(self.basis0.X, self.basis0.W))
        self._u_at_current = self._u_at_current + delta
        self.displacement = self._u_at_current.copy()

    # -- results --------------------------------------------------------------------------------

    def _by_component(self, u: np.ndarray) -> np.ndarray:
        """(dim, npoints) of a dof vector: ``u[c::dim]`` stacked."""
        return np.vstack([u[c::self.dim] for c in range(self.dim)])

    def deformed_points(self) -> np.ndarray:
        """(dim, npoints) current positions of the mesh nodes (``mesh.doflocs`` +
        displacement)."""
        return self.mesh.doflocs + self._by_component(self.displacement)

    def deformed_mesh(self) -> Mesh:
        """The mesh in the current configuration (what contact search runs on)."""
        return replace(self.mesh, doflocs=self.deformed_points())

    def green_lagrange_strain(self) -> np.ndarray:
        """(dim, dim, nelems, nqp) Green–Lagrange strain relative to the initial mesh (small
        kinematics: the small strain sym(grad u))."""
        g = self._arrays(self.basis0).gradient(self.displacement)
        if self.formulation == SMALL:
            return 0.5 * (g + np.swapaxes(g, 0, 1))
        return green_lagrange(g)

    def second_piola_kirchhoff(self) -> np.ndarray:
        """(dim, dim, nelems, nqp) 2nd Piola–Kirchhoff stress relative to the initial mesh (the
        material at its converged state)."""
        return self.material.response(self.green_lagrange_strain(), self.material_state).stress

    def stress(self) -> np.ndarray:
        """(nelems, dim, dim) element averages (over the current volume) of the Cauchy stress."""
        return self.cauchy_stress_at(self.displacement)[0]

    def out_of_plane_stress(self) -> np.ndarray:
        """(nelems,) element averages of the Cauchy ``sigma_zz = S_33 / J`` (plane strain; in 3D
        the zz component of :meth:`stress`)."""
        return self.cauchy_stress_at(self.displacement)[1]


__all__ = ["NonlinearBody", "NewtonStep", "SMALL", "TOTAL", "UPDATED"]
