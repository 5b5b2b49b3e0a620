"""``vfem bench sphere`` (issue 21): the 3D benchmark's rows, and what it refuses."""

import json
import shutil

import pytest

from vfem.cli import main
from vfem_tools import bench

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None,
                               reason="CalculiX (ccx) is not installed")


def test_sphere_parameters_follow_the_dofs():
    for facets, dofs in bench._SPHERE_DOFS:  # the measured points are met exactly
        assert bench.sphere_parameters(dofs).facets_per_radius == facets
    asked = [5e3, 3e4, 1e5, 3e5, 1e6, 3e6]
    chosen = [bench.sphere_parameters(d).facets_per_radius for d in asked]
    assert chosen == sorted(chosen) and chosen[0] == 3 and chosen[-1] > 43
    assert bench.sphere_parameters(1e6).facets_per_radius == 37  # between 928k and 1.4M
    assert bench.sphere_parameters(level=1).refinement == 1


@pytest.mark.parametrize("facets,dofs", bench._SPHERE_DOFS[:3])
def test_sphere_dofs_table_is_measured(facets, dofs):
    from vfem_examples.sphere import SphereParameters, build

    model = build(SphereParameters(facets_per_radius=facets, steps=1))
    assert sum(3 * b.mesh.p.shape[1] for b in model.bodies) == dofs


@pytest.mark.slow
def test_bench_sphere_prints_and_saves_its_rows(tmp_path, capsys):
    path = tmp_path / "bench.json"
    assert main(["bench", "sphere", "--dofs", "8k", "--in-process", "--json", str(path),
                 "--markdown", str(tmp_path / "bench.md")]) == 0
    out = capsys.readouterr().out
    assert "ratio" in out and "p_max err" in out
    (row,) = json.loads(path.read_text())
    assert row["converged"] and row["invariants_passed"]
    assert row["dofs"] > 3000 and row["contact_dofs"] > 100 and row["ratio"] > 0
    assert abs(row["p_max_error"]) < 0.15 and row["peak_mib"] > 0
    assert "| contact dofs |" in (tmp_path / "bench.md").read_text()


def test_bench_sphere_refuses_the_hertz_only_options(capsys):
    assert main(["bench", "sphere", "--patch"]) == 2
    assert "--patch is for hertz only" in capsys.readouterr().err


def test_calculix_rows_format():
    row = {"dofs": 7623, "facets_across_a": 3, "ccx_s": 21.96, "ccx_timed_out": False,
           "ccx_timeout_s": 600.0, "ccx_increments": 2, "ccx_iterations_total": 43,
           "ccx_p_max_error_raw": 7.4, "ccx_p_max_error_nodal": -0.041,
           "ccx_force_error": 1e-7, "vfem_s": 2.0, "vfem_p_max_error": -0.0407,
           "ccx_rms_error_over_p0": 0.01, "vfem_rms_error_over_p0": 0.01, "ratio": 10.98}
    assert "21.96" in bench.format_sphere_calculix_row(row)
    stopped = {**row, "ccx_s": float("nan"), "ccx_timed_out": True, "ratio": float("nan")}
    assert "> 600" in bench.format_sphere_calculix_row(stopped)
    table = bench.sphere_calculix_markdown([row, stopped])
    assert "| 7 623 | 3 | 21.96 |" in table and "| > 600 |" in table


@needs_ccx
def test_calculix_row_stopped_at_its_timeout():
    vfem = {"vfem_s": 1.0, "backend": "superlu", "iterations": 1, "converged": True,
            "p_max_error": 0.0, "dofs": 0}
    row = bench.sphere_calculix_row({"dofs": 5000}, vfem, timeout=0.5)
    assert row["ccx_timed_out"] and row["ccx_s"] != row["ccx_s"]  # NaN
    assert row["dofs"] == 7623


@pytest.mark.slow
@needs_ccx
def test_bench_sphere_with_calculix(tmp_path, capsys):
    path = tmp_path / "bench.json"
    assert main(["bench", "sphere", "--dofs", "8k", "--in-process", "--calculix", "--json",
                 str(path), "--markdown", str(tmp_path / "bench.md")]) == 0
    out = capsys.readouterr().out
    assert "ccx/vfem" in out
    table = json.loads(path.read_text())
    (v,), (c,) = table["sphere"], table["calculix"]
    assert c["dofs"] == v["dofs"] and not c["ccx_timed_out"]
    assert abs(c["ccx_force_error"]) < 1e-4  # ccx's contact force is the platen's
    # the same mesh read the same way: ccx's p_max within its penalty's error of vfem's
    # (measured at 7,623 dofs, penalty 1e9: -4.10 % and -4.07 %)
    assert abs(c["ccx_p_max_error_nodal"] - v["p_max_error"]) < 5e-3
    assert c["ratio"] > 0 and "| ccx / vfem |" in (tmp_path / "bench.md").read_text()
