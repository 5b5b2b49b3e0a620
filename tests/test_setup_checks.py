"""Checks before the first step: bodies that start interpenetrated, and the memory estimate."""

import numpy as np
import pytest

import vfem.linalg.pardiso
import vfem.memory
from models import Raw, input_file, prescribed, rectangle_mesh, support, toml_body
from vfem import Body, LinearElastic, Model, PrescribedDisplacement, Support
from vfem.cli import main
from vfem.errors import AnalysisError, InputError
from vfem.mesh import rectangle
from vfem.solver import Analysis

E = 1000.0


def blocks(overlap: float, lower_rows: int = 4, refine: int = 1, triangles: bool = False,
           nu: float = 0.0) -> Model:
    """A unit block pressed into another by starting ``overlap`` deep in it, both held at their
    far faces; nu = 0, so the answer is one-dimensional: p = E overlap / (H_lower + H_upper).
    The lower block's elements are 1 / (``lower_rows`` ``refine``) deep (its rind); ``nu`` other
    than 0 for a stiffness without entries that cancel."""
    mat = LinearElastic(E, nu)
    n = refine
    lower = Body("lower", rectangle(0.0, -1.0, 1.0, 1.0, nx=2 * n, ny=lower_rows * n,
                                    triangles=triangles), mat,
                 supports=(Support("bottom"),), contact_boundaries=("top",))
    upper = Body("upper", rectangle(0.0, -overlap, 1.0, 1.0, nx=3 * n, ny=3 * n,
                                    triangles=triangles), mat,
                 supports=(Support("top"),), contact_boundaries=("bottom",))
    return Model("start", [lower, upper])


def test_an_overlap_within_the_rind_is_resolved_by_the_first_step():
    result = Analysis(blocks(0.05)).run()
    assert result.converged
    upper = result.steps[-1].bodies["upper"]
    on = upper.contact_status == 1
    assert on.sum() == 4  # the whole bottom face
    assert np.allclose(upper.contact_pressure[on], E * 0.05 / 2.0, rtol=1e-6)


def test_an_overlap_deeper_than_the_rind_is_refused_before_anything_is_factorized():
    analysis = Analysis(blocks(0.3))  # rows 0.25 deep
    with pytest.raises(InputError) as info:
        analysis.setup()
    message = str(info.value)
    assert "bodies 'upper' and 'lower' start deeply interpenetrated" in message
    assert "lies 0.3 inside 'lower'" in message and "(0.25;" in message
    assert "Move the bodies apart" in message
    assert not hasattr(analysis.model.bodies[0], "factor")
    # the same overlap with deeper surface elements is within their rind: allowed
    Analysis(blocks(0.3, lower_rows=2)).setup()


def test_a_body_behind_a_thin_one_is_not_inside_it():
    """Depth is measured to the candidate surface, but only nodes inside the other body count:
    a block under a thin plate whose lower face is not a contact candidate starts apart."""
    mat = LinearElastic(E, 0.3)
    plate = Body("plate", rectangle(0.0, 0.0, 3.0, 0.1, nx=6, ny=1), mat,
                 supports=(Support("left"),), contact_boundaries=("top",))
    below = Body("below", rectangle(1.0, -1.05, 1.0, 1.0, nx=2, ny=2), mat,
                 supports=(Support("bottom"),), prescribed=(
                     PrescribedDisplacement("top", "y", 0.0),))
    from vfem.contact.settings import ContactSettings

    Model("m", [plate, below], ContactSettings(search_distance=1.0)).contact_surfaces()


# -- memory -------------------------------------------------------------------------------------


@pytest.mark.parametrize("triangles", [False, True], ids=["quadrilaterals", "triangles"])
def test_fill_model_is_close_to_superlus_factors(triangles):
    """The documented model of nnz(L + U) against SuperLU itself (vfem.memory's docstring):
    cautious, within twice the actual fill, on bodies of about 2,000 dofs."""
    analysis = Analysis(blocks(0.01, refine=12, triangles=triangles, nu=0.3), "superlu")
    analysis.setup()
    for s in analysis.surfaces:
        b = s.body
        structural = vfem.memory.stiffness_entries(b)  # entries that cancel are not stored
        assert b.K.nnz <= structural <= 1.2 * b.K.nnz
        lu = b.factor._lu
        actual = lu.L.nnz + lu.U.nnz
        assert actual <= vfem.memory.factor_entries(b.ndofs, len(s.tracked_dofs)) <= 2 * actual


@pytest.mark.slow
def test_fill_model_in_3d_is_close_to_superlus_factors():
    """3D (vfem.memory.SUPERLU_3D, fitted on the sphere example at 5,000-21,000 dofs a body):
    a coarser sphere than the fit's, hexahedra within 0.7 to 1.5 times SuperLU's nnz(L + U), a
    tetrahedral sphere cautious (the fill of tetrahedra, fewer neighbours a node, is lower);
    the stiffness's structural count exact (the 2D law, before, gave a 3D body's factors 5 to
    7 times too few entries)."""
    from vfem_examples import sphere

    for cells in ("hex", "tet"):
        p = sphere.Parameters(facets_per_radius=3, steps=1, sphere_cells=cells)
        analysis = Analysis(sphere.build(p), "superlu")
        analysis.setup()
        for s in analysis.surfaces:
            b = s.body
            structural = vfem.memory.stiffness_entries(b)
            assert b.K.nnz <= structural <= 1.05 * b.K.nnz
            lu = b.factor._lu
            actual = lu.L.nnz + lu.U.nnz
            model = vfem.memory.factor_entries(b.ndofs, len(s.condensed_dofs), dim=3)
            low, high = (0.7, 1.5) if cells == "hex" else (1.0, 2.0)  # fewer tet neighbours
            print(cells, b.name, f"{model / actual:.2f}")
            assert low * actual <= model <= high * actual, (cells, b.name, model / actual)


@pytest.mark.skipif(not vfem.linalg.pardiso.available(), reason="PARDISO is not installed")
@pytest.mark.slow
def test_pardiso_3d_bytes_per_factor_entry():
    """vfem.memory counts a 3D body's PARDISO factors at PARDISO_3D_FACTOR_BYTES per entry of
    nnz(L): PARDISO's own count of its memory agrees, to within the indices' share, which
    falls as the supernodes grow (measured, the Schur block included: 11.6 to 11.9 bytes at
    13k dofs a body, here; 10.9 to 11.1 at 25k; 9.0 to 9.6 from 187k to 889k)."""
    from vfem_examples import sphere

    analysis = Analysis(sphere.build(sphere.Parameters(facets_per_radius=6, steps=1)),
                        "pardiso")
    analysis.setup()
    for s in analysis.surfaces:
        factor = s.body.factor
        per_entry = factor.factor_bytes / factor.factor_entries
        assert 0.9 * vfem.memory.PARDISO_3D_FACTOR_BYTES <= per_entry \
            <= 1.25 * vfem.memory.PARDISO_3D_FACTOR_BYTES, (s.body.name, per_entry)


def test_a_model_larger_than_the_memory_available_is_refused(monkeypatch, caplog):
    monkeypatch.setattr(vfem.memory, "available_memory", lambda: 2**20)
    analysis = Analysis(blocks(0.05))
    with caplog.at_level("INFO", logger="vfem.memory"):
        with pytest.raises(AnalysisError) as info:
            analysis.setup()
    message = str(info.value)
    assert "the analysis needs about" in message and "only 1 MiB is available" in message
    assert "coarser meshes" in message
    assert "estimated memory for the set-up" in caplog.text
    assert not hasattr(analysis.model.bodies[0], "factor")  # stopped before factorizing


def test_unknown_available_memory_skips_the_check(monkeypatch):
    monkeypatch.setattr(vfem.memory, "available_memory", lambda: None)
    Analysis(blocks(0.05)).setup()


def test_available_memory_is_a_positive_number_here():
    available = vfem.memory.available_memory()
    assert available is None or available > 0


def test_running_out_of_memory_anyway_is_a_clear_analysis_error(monkeypatch):
    def no_memory(self, *args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(Body, "setup", no_memory)
    with pytest.raises(AnalysisError, match="out of memory while factorizing the bodies"):
        Analysis(blocks(0.05)).setup()


def test_the_command_line_reports_it_without_a_traceback(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(vfem.memory, "available_memory", lambda: 2**20)
    path = tmp_path / "model.toml"
    path.write_text(input_file(
        "two blocks",
        toml_body("lower", rectangle_mesh(y0=-1.0, nx=2, ny=2), support("bottom"), nu=0.0,
                  contact_boundaries=["top"]),
        toml_body("upper", rectangle_mesh(nx=3, ny=3), support("left", ["x"]),
                  prescribed("top", "y", Raw("-1e-3")), nu=0.0, contact_boundaries=["bottom"])))
    assert main(["-q", "run", str(path), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert "needs about" in err and "Traceback" not in err
