"""``vfem bench sphere`` (issue 21): the 3D benchmark's rows, and what it refuses."""

import json

from vfem.cli import main
from vfem.tools import bench


def test_sphere_parameters_follow_the_dofs():
    assert bench.sphere_parameters(26_160).facets_per_radius == 6
    assert bench.sphere_parameters(300_000).facets_per_radius == 22
    assert bench.sphere_parameters(level=1).refinement == 1


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
    assert main(["bench", "sphere", "--calculix"]) == 2
    assert "--calculix is for hertz only" in capsys.readouterr().err
