"""The exact transfer in 3D (issue 21, C8 of the 3D plan): ``transfer_matrices`` on two 3D
contact surfaces (``Triangle``/``Quad`` kinds, their ``overlap_quadrature`` on
contact/geometry/overlap3d.py), boxes stacked with non-matching faces, either side the compatibility
one. ``N`` (compatibility nodes)² and ``T`` (opposing nodes x compatibility nodes), 2D's
layout: ``T``'s columns sum like ``N``'s; a uniform or linear traction on the compatibility
side transferred by ``T`` gives the opposing side's consistent nodal loads."""

import numpy as np
import pytest
import scipy.sparse as sp

from vfem.bodies import Body, Support
from vfem.contact.geometry.surface import ContactSurface
from vfem.contact.geometry.transfer import transfer_matrices
from vfem.materials import LinearElastic
from vfem.mesh.solids import box

MAT = LinearElastic(200.0, 0.3)
GAP = 0.05  # between the lower box's top and the upper's bottom


def _surface(cells, n, upper, offset=(0.0, 0.0), order=1):
    z0 = 0.5 + GAP if upper else 0.0
    mesh = box(offset[0], offset[1], z0, 1.0, 1.0, 0.5, nx=n, ny=n, nz=1,
               tetrahedra=cells == "tet")
    face = "bottom" if upper else "top"
    body = Body("upper" if upper else "lower", mesh, MAT,
                supports=(Support("top" if upper else "bottom"),), order=order)
    return ContactSurface.build(body, mesh.boundaries[face])


def _transfer(sf, sc):
    fpatch, cpatch = np.arange(len(sf.facets)), np.arange(len(sc.facets))
    return transfer_matrices(sf, sc, fpatch, cpatch, sc.node_normals(sc.X, cpatch),
                             sc.patch_boundary(cpatch), GAP, sf.X, sc.X)


# (lower's cells, lower's n, upper's cells, upper's n)
PAIRS = [("hex", 4, "tet", 7), ("hex", 3, "hex", 5), ("tet", 4, "tet", 6), ("tet", 5, "hex", 2)]


def _both_orders():
    for low, nl, up, nu in PAIRS:
        yield pytest.param(low, nl, up, nu, True, id=f"{low}{nl}-{up}{nu}-upper-compat")
        yield pytest.param(low, nl, up, nu, False, id=f"{low}{nl}-{up}{nu}-lower-compat")


def _pair(low, nl, up, nu, upper_compat, offset=(0.0, 0.0)):
    lower, upper = _surface(low, nl, False), _surface(up, nu, True, offset)
    return (upper, lower) if upper_compat else (lower, upper)


def _consistent(s, values):
    """sum_j int psi_c psi_j values_j over the surface's candidate facets: a linear field's
    consistent nodal loads (exact: linear fields interpolate exactly)."""
    return s.mass_matrix(np.ones(len(s.facets))) @ values


@pytest.mark.parametrize(("low", "nl", "up", "nu", "upper_compat"), list(_both_orders()))
def test_columns_balance_and_a_uniform_traction_crosses_exactly(low, nl, up, nu, upper_compat):
    sf, sc = _pair(low, nl, up, nu, upper_compat)
    N, T = _transfer(sf, sc)
    assert N.shape == (sf.nc, sf.nc) and T.shape == (sc.nc, sf.nc)  # 2D's layout
    # (i) the opposing side's shape functions sum to one at every point: forces balance
    np.testing.assert_allclose(np.asarray(T.sum(axis=0)).ravel(),
                               np.asarray(N.sum(axis=0)).ravel(), rtol=0, atol=1e-12)
    assert sp.issparse(N) and sp.issparse(T)  # a facet's few nodes a column (issue 40)
    N, T = N.toarray(), T.toarray()
    np.testing.assert_allclose(N, N.T, rtol=0, atol=1e-15)
    # (ii) a uniform pressure: the compatibility side's and the opposing side's consistent
    # loads (their tributary areas), the totals the face's area
    q = np.ones(sf.nc)
    np.testing.assert_allclose(N @ q, sf.tributary, rtol=0, atol=1e-10)
    np.testing.assert_allclose(T @ q, sc.tributary, rtol=0, atol=1e-10)
    assert (T @ q).sum() == pytest.approx((N @ q).sum(), abs=1e-12)
    assert (T @ q).sum() == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize(("low", "nl", "up", "nu", "upper_compat"), list(_both_orders()))
def test_a_linear_traction_crosses_exactly(low, nl, up, nu, upper_compat):
    """The rule is exact for phi psi on flat parallelograms and triangles, so a linear
    traction (interpolated exactly by either side) gives the opposing consistent loads."""
    sf, sc = _pair(low, nl, up, nu, upper_compat)
    N, T = _transfer(sf, sc)

    def field(x):
        return 1.0 + 0.7 * x[:, 0] - 0.4 * x[:, 1]

    q = field(sf.X[: sf.nc])
    np.testing.assert_allclose(N @ q, _consistent(sf, q), rtol=0, atol=1e-10)
    np.testing.assert_allclose(T @ q, _consistent(sc, field(sc.X[: sc.nc])), rtol=0, atol=1e-10)
    assert (T @ q).sum() == pytest.approx((N @ q).sum(), abs=1e-12)


@pytest.mark.parametrize("upper_compat", [True, False])
def test_an_offset_box_transfers_over_the_overlap_only(upper_compat):
    """The upper box shifted by (0.3, 0.2): only the 0.7 x 0.8 overlap carries; nodes whose
    facets do not reach it get nothing, and the columns still balance."""
    sf, sc = _pair("hex", 4, "tet", 5, upper_compat, offset=(0.3, 0.2))
    N, T = _transfer(sf, sc)
    q = np.ones(sf.nc)
    assert (N @ q).sum() == pytest.approx(0.56, abs=1e-12)
    assert (T @ q).sum() == pytest.approx(0.56, abs=1e-12)
    np.testing.assert_allclose(np.asarray(T.sum(axis=0)).ravel(),
                               np.asarray(N.sum(axis=0)).ravel(), rtol=0, atol=1e-12)
    # a node of the opposing side outside the overlap's closure gets no force
    x = sc.X[: sc.nc]
    lo = np.array([0.3, 0.2])
    hi = np.array([1.0, 1.0])
    out = np.any((x[:, :2] < lo - 0.26) | (x[:, :2] > hi + 0.26), axis=1)  # facets <= 0.25
    assert out.any()
    np.testing.assert_array_equal((T @ q)[out], 0.0)


@pytest.mark.parametrize("upper_compat", [True, False], ids=["upper-compat", "lower-compat"])
@pytest.mark.parametrize(("other", "n", "order", "degree"), [("tet", 5, 2, 2), ("hex", 2, 1, 1)],
                         ids=["t6-t6", "t6-q4"])
def test_quadratic_triangles_transfer_a_traction_they_interpolate_exactly(other, n, order,
                                                                         degree, upper_compat):
    """Quadratic tetrahedra's 6-node facets, clipped as their four corner-and-midpoint
    triangles (``FacetKind.linear_pieces``) with the degree-5 rule: a quadratic traction
    between two of them, a linear one against linear hexahedra, gives both sides' consistent
    loads to round-off, and the columns balance."""
    upper = _surface("tet", 3, True, order=2)
    lower = _surface(other, n, False, order=order)
    sf, sc = (upper, lower) if upper_compat else (lower, upper)
    N, T = _transfer(sf, sc)

    def field(x):
        linear = 1.0 + 0.7 * x[:, 0] - 0.4 * x[:, 1]
        return linear + (0.5 * x[:, 0] * x[:, 1] - 0.3 * x[:, 1] ** 2 if degree == 2 else 0.0)

    q = field(sf.X[: sf.nc])
    np.testing.assert_allclose(N @ q, _consistent(sf, q), rtol=0, atol=1e-12)
    np.testing.assert_allclose(T @ q, _consistent(sc, field(sc.X[: sc.nc])), rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.asarray(T.sum(axis=0)).ravel(),
                               np.asarray(N.sum(axis=0)).ravel(), rtol=0, atol=1e-12)


def test_quadratic_quadrilaterals_are_refused():
    sf, sc = _surface("hex", 2, True, order=2), _surface("hex", 2, False)
    with pytest.raises(NotImplementedError, match="quadratic hexahedra"):
        _transfer(sf, sc)


def test_deformed_positions_keep_the_nominal_measure():
    """Both surfaces stretched alike in-plane (x 1.1, y 0.9) and moved: the same pieces in
    local coordinates, the weights the undeformed measure, so N and T are the undeformed
    ones (the traction is nominal, as 2D)."""
    sf, sc = _pair("hex", 4, "tet", 7, True)
    N0, T0 = _transfer(sf, sc)
    stretch = np.array([1.1, 0.9, 1.0])
    shift = np.array([0.2, -0.1, 0.05])
    xf, xc = sf.X * stretch + shift, sc.X * stretch + shift
    fpatch, cpatch = np.arange(len(sf.facets)), np.arange(len(sc.facets))
    N, T = transfer_matrices(sf, sc, fpatch, cpatch, sc.node_normals(xc, cpatch),
                             sc.patch_boundary(cpatch), GAP, xf, xc)
    np.testing.assert_allclose(N.toarray(), N0.toarray(), rtol=0, atol=1e-13)
    np.testing.assert_allclose(T.toarray(), T0.toarray(), rtol=0, atol=1e-13)
