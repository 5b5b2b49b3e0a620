"""The 3D overlap quadrature (issue 21, item 3; plan C8): ``vfem.contact.geometry.overlap3d``.

Surfaces are scikit-fem's tensor meshes of the plane, lifted to 3D and placed by a rotation
and a translation, the opposing side a gap away and numbered the other way round (it faces the
compatibility side). Reference loads are scikit-fem's integrals on the 2D meshes."""

import numpy as np
import pytest
from skfem import Basis, ElementQuad1, ElementTriP1, LinearForm, MeshQuad, MeshTri

from vfem.contact.geometry.overlap3d import (
    candidate_pairs,
    overlap_matrices,
    overlap_quadrature,
    shape_values,
)

ANGLE = np.deg2rad(17.0)


def rotation(a=0.3, b=-0.7, c=1.1):
    """A fixed rotation of 3D space (so the interface plane is no coordinate plane)."""
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rz = np.array([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    return rz @ ry @ rx


R = rotation()
SHIFT = np.array([0.4, -1.3, 2.2])


def plane_mesh(kind, n, lo=0.0, hi=1.0, angle=0.0, offset=(0.0, 0.0), jitter=0.0):
    """A tensor mesh of [lo, hi]² (rotated in plane about the unit square's centre, shifted,
    interior nodes jittered), its elements counter-clockwise."""
    cls = MeshTri if kind == "tri" else MeshQuad
    m = cls.init_tensor(np.linspace(lo, hi, n + 1), np.linspace(lo, hi, n + 1))
    p = m.p.copy()
    if jitter:
        inner = (p > lo + 1e-12).all(axis=0) & (p < hi - 1e-12).all(axis=0)
        rng = np.random.default_rng(3)
        p[:, inner] += jitter * (hi - lo) / n * rng.uniform(-1, 1, (2, inner.sum()))
    c, s = np.cos(angle), np.sin(angle)
    p = np.array([[c, -s], [s, c]]) @ (p - 0.5) + 0.5 + np.asarray(offset)[:, None]
    t = m.t.copy()
    e = p[:, t]
    signed = ((e[0, 1] - e[0, 0]) * (e[1, 2] - e[1, 0])
              - (e[1, 1] - e[1, 0]) * (e[0, 2] - e[0, 0]))
    t[:, signed < 0] = t[::-1, signed < 0]
    return cls(p, t)


def lifted(m, gap=0.0, facing=False):
    """Points (n, 3) and facets (nf, k) of a plane mesh placed in 3D at height ``gap``; an
    opposing surface (``facing``) numbered clockwise, its normal towards the other."""
    X = np.vstack([m.p, np.full(m.p.shape[1], gap)]).T @ R.T + SHIFT
    f = m.t.T.copy()
    return X, (f[:, ::-1] if facing else f)


def loads(m, f=lambda x: 1.0 + 0 * x[0]):
    """The consistent nodal loads of the traction ``f`` (a function of the plane's x, y)."""
    e = ElementTriP1() if isinstance(m, MeshTri) else ElementQuad1()
    return LinearForm(lambda v, w: f(w.x) * v).assemble(Basis(m, e, intorder=6))


def linear(x):
    return 1.0 + 2.0 * x[0] - 3.0 * x[1]


def transfer(mc, mo, gap=0.25):
    xc, fc = lifted(mc)
    xo, fo = lifted(mo, gap, facing=True)
    pairs = candidate_pairs(xc, fc, xo, fo, reach=gap)
    q = overlap_quadrature(xc, fc, xo, fo, pairs)
    N, T = overlap_matrices(q, fc, fo, len(xc), len(xo))
    return q, N, T


CASES = {
    "tri 4 vs quad 7": (("tri", 4), ("quad", 7)),
    "quad 7 vs tri 4": (("quad", 7), ("tri", 4)),
    "tri 5 vs tri 8": (("tri", 5), ("tri", 8)),
    "quad 3 vs quad 5": (("quad", 3), ("quad", 5)),
}


@pytest.mark.parametrize("case", CASES)
def test_uniform_and_linear_tractions_cross_non_matching_meshes_exactly(case):
    (kc, nc), (ko, no) = CASES[case]
    mc, mo = plane_mesh(kc, nc), plane_mesh(ko, no)
    q, N, T = transfer(mc, mo)
    one = np.ones(N.shape[0])
    # both sides get the consistent loads of a uniform traction...
    assert np.abs(N @ one - loads(mc)).max() < 1e-14
    assert np.abs(T @ one - loads(mo)).max() < 1e-12
    # ...and of a linear one (P1 and Q1 interpolate it exactly): the rule is exact for phi psi
    g = linear(mc.p)
    assert np.abs(N @ g - loads(mc, linear)).max() < 1e-12
    assert np.abs(T @ g - loads(mo, linear)).max() < 1e-12
    assert abs(q.weight.sum() - 1.0) < 1e-14


@pytest.mark.parametrize(("kc", "ko"), [("tri", "quad"), ("quad", "tri")])
def test_a_mesh_rotated_17_degrees_in_plane(kc, ko):
    # the opposing unit square, rotated, lies inside the compatibility square [-0.5, 1.5]²:
    # the opposing side gets the consistent loads
    mc, mo = plane_mesh(kc, 6, -0.5, 1.5), plane_mesh(ko, 7, angle=ANGLE)
    q, N, T = transfer(mc, mo)
    assert np.abs(T @ np.ones(N.shape[0]) - loads(mo)).max() < 1e-12
    assert np.abs(T @ linear(mc.p) - loads(mo, linear)).max() < 1e-12
    assert abs(q.weight.sum() - 1.0) < 1e-14
    # the rotated square as the compatibility side, inside the other: its own loads
    mc, mo = plane_mesh(kc, 7, angle=ANGLE), plane_mesh(ko, 6, -0.5, 1.5)
    q, N, T = transfer(mc, mo)
    one = np.ones(N.shape[0])
    assert np.abs(N @ one - loads(mc)).max() < 1e-14
    assert np.abs(N @ linear(mc.p) - loads(mc, linear)).max() < 1e-12
    assert np.abs(T.sum(axis=0).A1 - N.sum(axis=0).A1).max() < 1e-14


@pytest.mark.parametrize(("kc", "ko", "jitter"),
                         [("tri", "quad", 0.3), ("quad", "tri", 0.3), ("tri", "tri", 0.3)])
def test_columns_of_T_sum_like_N_on_distorted_meshes(kc, ko, jitter):
    # non-parallelogram quadrilaterals: no polynomial rule is exact, yet the forces balance
    # and the overlap tiles the compatibility side exactly
    mc, mo = plane_mesh(kc, 5, jitter=jitter), plane_mesh(ko, 7, jitter=jitter)
    q, N, T = transfer(mc, mo)
    col_T, col_N = T.sum(axis=0).A1, N.sum(axis=0).A1
    assert np.abs(col_T - col_N).max() < 1e-14
    assert np.abs(N - N.T).max() < 1e-15
    assert abs(q.weight.sum() - 1.0) < 1e-14
    if kc == "tri":  # a P1 side's own loads are exact whatever the other side
        assert np.abs(col_T - loads(mc)).max() < 1e-14


@pytest.mark.parametrize(("kc", "ko"), [("tri", "quad"), ("quad", "tri"), ("quad", "quad")])
def test_half_overlapping_offset_square(kc, ko):
    mc = plane_mesh(kc, 4)
    mo = plane_mesh(ko, 7, offset=(0.5, 0.25))
    q, N, T = transfer(mc, mo)
    assert abs(q.weight.sum() - 0.5 * 0.75) < 1e-14
    assert abs(N.sum() - 0.375) < 1e-14 and abs(T.sum() - 0.375) < 1e-14
    # the square and its own rotation by 17° about its centre overlap in an octagon:
    # its cut corners are right triangles of hypotenuse h, 1 = h (1 + cos + sin)
    mo = plane_mesh(ko, 7, angle=ANGLE)
    q, _, _ = transfer(mc, mo)
    h = 1 / (1 + np.cos(ANGLE) + np.sin(ANGLE))
    assert abs(q.weight.sum() - (1 - 2 * h * h * np.sin(ANGLE) * np.cos(ANGLE))) < 1e-14


def test_one_triangle_pair_by_hand():
    # compatibility (0,0), (1,0), (0,1); opposing (0,0), (1,0), (1,1), 0.3 above, clockwise.
    # Overlap: the triangle (0,0), (1,0), (1/2,1/2) of area 1/4. With linear f, g on a triangle
    # of area A, int f g = A/12 (sum_v f g + sum_v f sum_v g); at its vertices
    # phi = (1,0,0), (0,1,1/2), (0,0,1/2) and psi (1-x, x-y, y) = (1,0,1/2), (0,1,0), (0,0,1/2)
    xc = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]]) @ R.T + SHIFT
    xo = np.array([[0, 0, 0.3], [1, 0, 0.3], [1, 1, 0.3]]) @ R.T + SHIFT
    fc, fo = np.array([[0, 1, 2]]), np.array([[0, 2, 1]])
    q = overlap_quadrature(xc, fc, xo, fo, np.array([[0, 0]]))
    N, T = overlap_matrices(q, fc, fo, 3, 3)
    by_hand = np.array([[5, 5, 2], [2, 5, 1], [1, 2, 1]]) / 96
    assert np.abs(T.toarray() - by_hand).max() < 1e-15
    # N: the P1 mass matrix of the overlap, A/12 (phi_i . phi_k + sums), phi[i, vertex]
    phi = np.array([[1, 0, 0], [0, 1, 0.5], [0, 0, 0.5]])
    s = phi.sum(axis=1)
    assert np.abs(N.toarray() - (phi @ phi.T + np.outer(s, s)) / 48).max() < 1e-15
    assert abs(q.weight.sum() - 0.25) < 1e-15 and len(q.weight) == 3  # degree 2: 3 points
    # the points lie on both facets at their local coordinates
    xi_c = shape_values(q.comp_xi, 3)
    assert np.abs(np.einsum("qk,kd->qd", xi_c, xc) - q.x).max() < 1e-15
    n = R[:, 2]
    on_o = np.einsum("qk,kd->qd", shape_values(q.opp_xi, 3), xo[fo[0]])
    assert np.abs(on_o - 0.3 * n - q.x).max() < 1e-14
    # farther than max_distance: nothing
    q = overlap_quadrature(xc, fc, xo, fo, np.array([[0, 0]]), max_distance=0.29)
    assert len(q.weight) == 0


def test_local_coordinates_of_quadrilaterals_map_back():
    mc, mo = plane_mesh("quad", 3, jitter=0.3), plane_mesh("quad", 4, jitter=0.3)
    xc, fc = lifted(mc)
    xo, fo = lifted(mo, 0.1, facing=True)
    q = overlap_quadrature(xc, fc, xo, fo, candidate_pairs(xc, fc, xo, fo, 0.1))
    back_c = np.einsum("qk,qkd->qd", shape_values(q.comp_xi, 4), xc[fc[q.comp_facet]])
    back_o = np.einsum("qk,qkd->qd", shape_values(q.opp_xi, 4), xo[fo[q.opp_facet]])
    assert np.abs(back_c - q.x).max() < 1e-14
    assert np.abs(back_o - 0.1 * R[:, 2] - q.x).max() < 1e-14
    inside = (q.opp_xi > -1e-12) & (q.opp_xi < 1 + 1e-12)
    assert inside.all()


def test_candidate_pairs_are_a_superset_and_distant_surfaces_give_nothing():
    mc, mo = plane_mesh("tri", 4), plane_mesh("quad", 7, offset=(3.0, 0.0))
    xc, fc = lifted(mc)
    xo, fo = lifted(mo, 0.0, facing=True)
    assert len(candidate_pairs(xc, fc, xo, fo)) == 0
    everything = np.array([(i, j) for i in range(len(fc)) for j in range(len(fo))])
    q = overlap_quadrature(xc, fc, xo, fo, everything)
    assert len(q.weight) == 0
    N, T = overlap_matrices(q, fc, fo, len(xc), len(xo))
    assert N.nnz == 0 and T.shape == (len(xo), len(xc))


def test_a_warped_quadrilateral_gets_its_surface_measure():
    # one corner lifted 0.05: the weights of a fully covered facet add up to its true area
    # (a tensor Gauss rule of 400 points on the bilinear map), to the rule's accuracy
    xc = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.05], [0, 1, 0]])
    xo = np.array([[-1, -1, 0.5], [2, -1, 0.5], [2, 2, 0.5], [-1, 2, 0.5]])
    q = overlap_quadrature(xc, np.array([[0, 1, 2, 3]]), xo, np.array([[0, 3, 2, 1]]),
                           np.array([[0, 0]]))
    g, w = np.polynomial.legendre.leggauss(20)
    x, e = np.meshgrid((g + 1) / 2, (g + 1) / 2)
    a, b, c = xc[1] - xc[0], xc[3] - xc[0], xc[0] - xc[1] + xc[2] - xc[3]
    jn = np.cross(a + e[..., None] * c, b + x[..., None] * c)
    area = (np.linalg.norm(jn, axis=2) * np.outer(w, w) / 4).sum()
    assert area > 1.0008 and abs(q.weight.sum() - area) < 1e-11


def graded(kind, n, power=3.0):
    """A mesh of the unit square graded towards x = y = 0 (facet sizes from (1/n)^power to
    about 3/n): the far field of a graded body beside its fine contact zone."""
    m = plane_mesh(kind, n)
    return type(m)(m.p**power, m.t)


@pytest.mark.parametrize("kc,ko", [("tri", "quad"), ("quad", "tri"), ("quad", "quad")])
def test_the_plane_test_keeps_every_overlapping_pair_of_graded_meshes(kc, ko):
    """The candidates drop pairs whose projections on the compatibility plane cannot meet,
    which a reach that grows with the largest facet lets in by the hundred: the quadrature
    from the candidates is the one from every pair, to the bit, with far fewer pairs."""
    mc, mo = graded(kc, 12), graded(ko, 9, power=2.0)
    xc, fc = lifted(mc)
    xo, fo = lifted(mo, 0.05, facing=True)
    reach = 0.05 + 2.0 * 0.3  # the pairing's: the gap and twice the largest facets
    pairs = candidate_pairs(xc, fc, xo, fo, reach)
    everything = np.array([(i, j) for i in range(len(fc)) for j in range(len(fo))])
    wide = overlap_quadrature(xc, fc, xo, fo, everything, max_distance=reach)
    narrow = overlap_quadrature(xc, fc, xo, fo, pairs, max_distance=reach)
    for name in ("weight", "comp_facet", "comp_xi", "opp_facet", "opp_xi", "x"):
        np.testing.assert_array_equal(getattr(wide, name), getattr(narrow, name))
    assert len(np.unique(wide.pair)) <= len(pairs) < 0.25 * len(everything)
    assert wide.weight.sum() == pytest.approx(1.0, rel=1e-12)  # the whole unit square
