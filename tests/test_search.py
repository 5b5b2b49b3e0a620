"""Closest-point projection and point location in the rind."""

import numpy as np
from skfem import MeshTri

from vfem.bodies import Body, Support
from vfem.contact.geometry.surface import ContactSurface
from vfem.contact.search.closest import outward_normals, project_points
from vfem.materials import LinearElastic


def test_projection_onto_segments():
    a = np.array([[0.0, 0.0], [1.0, 0.0]])
    b = np.array([[1.0, 0.0], [2.0, 1.0]])
    pts = np.array([[0.25, 0.5], [0.25, -0.3], [3.0, 3.0], [-1.0, 0.0]])
    seg, t, d = project_points(pts, a, b)
    np.testing.assert_array_equal(seg, [0, 0, 1, 0])
    np.testing.assert_allclose(t, [0.25, 0.25, 1.0, 0.0])
    np.testing.assert_allclose(d, [0.5, 0.3, np.hypot(1, 2), 1.0])
    n = outward_normals(a, b)
    np.testing.assert_allclose(n[0], [0.0, -1.0])  # (t_y, -t_x)


def test_near_ties_are_judged_against_the_nearest_not_by_bins():
    """A point beside a corner, nearer to the side facet than to the bottom by less than the
    tie tolerance (1e-9 of the longest segment), is a tie, which the facet facing the point
    wins, wherever the point lies; fixed bins of the distance split such pairs whenever a bin's
    edge fell between them (random model 2d-49: Newton cycled as a patch's facet came and
    went). A difference well past the tolerance is no tie: the nearer facet wins."""
    a = np.array([[0.0, 0.0], [0.0, 1.0]])  # the bottom (outward normal -y), the side (-x)
    b = np.array([[1.0, 0.0], [0.0, 0.0]])
    up = np.array([[0.0, 1.0]])  # the point's own surface faces up, at the bottom
    for lead, winner in ((0.5e-9, 0), (10e-9, 1)):  # side nearer by this much (L = 1)
        for x in np.linspace(0.3, 0.5, 201):
            eps = np.sqrt(2.0 * x * lead)  # |corner - p| - x = lead, to first order
            seg, _, dist = project_points(np.array([[-x, eps]]), a, b, up)
            assert seg[0] == winner, (lead, x)


def test_surface_orientation_and_rind_location():
    mesh = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5)).with_boundaries(
        {"top": lambda x: x[1] > 1 - 1e-9, "bottom": lambda x: x[1] < 1e-9})
    body = Body("b", mesh, LinearElastic(1.0, 0.3), supports=(Support("bottom"),))
    body.setup()
    s = ContactSurface.build(body, mesh.boundaries["top"])
    xa, xb = s.segments(s.X)
    np.testing.assert_allclose(outward_normals(xa, xb), np.tile([0.0, 1.0], (len(xa), 1)))
    np.testing.assert_allclose(s.tributary.sum(), 1.0)
    found = s.locate(s.X, np.array([[0.3, 0.9], [0.3, 1.1], [0.3, 0.5], [0.999, 0.76]]))
    assert found[0] >= 0 and found[3] >= 0  # in the outer layer of elements
    assert found[1] == -1  # outside the body
    assert found[2] == -1  # inside, but deeper than the rind


def test_direct_and_tree_candidates_choose_the_same_segments(monkeypatch):
    """Few pairs take the direct candidate search, many the KD-tree (``DIRECT_PAIRS``): both
    give the same candidates, so the same segment, t and distance, ties included (points on
    the vertices two segments share, with normals deciding)."""
    from vfem.contact.search import closest as search

    rng = np.random.default_rng(7)
    for m, s in [(1, 1), (3, 40), (40, 40), (25, 300), (200, 30)]:
        a = np.cumsum(rng.random((s, 2)) - [0.0, 0.5], axis=0)
        b = np.vstack([a[1:], a[-1:] + [1.0, 0.0]])
        pts = a[rng.integers(0, s, m)] + rng.normal(0.0, 0.3, (m, 2))
        pts[: min(m, 5)] = b[: min(m, 5)]  # on shared vertices: ties
        normals = rng.normal(size=(m, 2))
        monkeypatch.setattr(search, "DIRECT_PAIRS", 10**9)
        direct = project_points(pts, a, b, normals, free=True)
        monkeypatch.setattr(search, "DIRECT_PAIRS", 0)
        tree = project_points(pts, a, b, normals, free=True)
        for x, y in zip(direct, tree):
            np.testing.assert_array_equal(x, y)
        # and the closest segment is the nearest one: no nearer point on any segment
        d = b - a
        t = np.clip(np.einsum("pmd,md->pm", pts[:, None] - a, d) / np.einsum("md,md->m", d, d),
                    0, 1)
        every = np.linalg.norm(pts[:, None] - (a + t[..., None] * d), axis=2)
        np.testing.assert_allclose(direct[2], every.min(axis=1), rtol=0, atol=1e-12)


def test_an_input_file_run_searches_its_candidates_once(monkeypatch, tmp_path):
    """``vfem run FILE`` checks the model (which builds its contact surfaces) and then solves
    it: the candidate search is done once (issue 40), and again when what it read changes."""
    from pathlib import Path

    import vfem
    from vfem import model as model_module
    from vfem.config import check
    from vfem.io import runner

    calls = []
    search = model_module.select_candidate_facets
    monkeypatch.setattr(model_module, "select_candidate_facets",
                        lambda *a, **k: calls.append(1) or search(*a, **k))
    path = Path(__file__).parent.parent / "examples" / "hertz.toml"
    config = vfem.load(path)
    model = check(config, path.parent)
    _, first = model.contact_surfaces()
    summary = runner.run(config, tmp_path / "out", model=model, figures=False)
    assert summary["converged"]
    assert len(calls) == 1
    model.load_factors = tuple(2 * f for f in model.load_factors)  # what it read changed
    _, again = model.contact_surfaces()
    assert len(calls) == 2
    assert [s.nc for s in first] == [s.nc for s in again]


def test_kept_answers_are_found_by_their_arguments_compared_exactly():
    """vfem.contact.geometry.kept.Kept (issue 40): an answer comes back only for the same
    arrays (entry for entry, copied when kept: a caller's later change misses), the same
    integers and the same objects; the oldest is let go past its size."""
    from vfem.contact.geometry.kept import Kept

    made = []
    kept = Kept(2)

    def make(tag):
        return lambda: made.append(tag) or tag

    x, owner = np.arange(6.0), object()
    assert kept.get((x, 7, owner), make("a")) == "a"
    assert kept.get((x.copy(), 7, owner), make("b")) == "a"  # equal arrays: found
    x[0] = -1.0  # the caller's array changed: the kept copy no longer matches
    assert kept.get((x, 7, owner), make("c")) == "c"
    assert kept.get((np.arange(6.0), 8, owner), make("d")) == "d"  # another integer
    assert kept.get((np.arange(6.0), 7, object()), make("e")) == "e"  # another object
    assert made == ["a", "c", "d", "e"]
    assert len(kept.entries) == 2
    assert kept.get((np.arange(6.0), 7, owner), make("f")) == "f"  # "a" was let go
    assert kept.get((None, 1), make("g"), keep=False) == "g" and len(kept.entries) == 2
