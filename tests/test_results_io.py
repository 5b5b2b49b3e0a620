"""Results on disk (contact.csv, VTU/PVD) and figures regenerated from them without solving."""

import copy
import csv
import dataclasses
import json
import re
import shutil
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from vfem.errors import InputError
from vfem.io.replot import plot_results
from vfem.io.results import (
    CONTACT_COLUMNS,
    ResultsWriter,
    run_writing,
    step_record,
    write_summary,
)
from vfem_examples.patch import Parameters, build

POINT_FIELDS = ("displacement", "contact_force", "contact_pressure", "contact_status",
                "penetration")
CELL_FIELDS = ("stress_xx", "stress_yy", "stress_xy", "stress_zz", "von_mises")


def _patch(out, order=1, load_factors=(0.5, 1.0)):
    """The patch test (nu = 0, fixed base), 2 vs 3 elements across, in two steps."""
    p = Parameters(order=order)
    model = dataclasses.replace(build(p, 2, 3, 0.0), load_factors=load_factors)
    analysis, result = run_writing(model, out, None)
    assert result.converged
    write_summary(out, {"steps": [step_record(s) for s in result.steps]})
    exact = model.bodies[0].material.plane_strain_modulus() * p.displacement / 2.0  # E d / H
    return model, analysis, result, exact


@pytest.fixture(scope="module")
def patch(tmp_path_factory):
    out = tmp_path_factory.mktemp("patch")
    return (out, *_patch(out))


def _rows(out):
    with open(out / "contact.csv", newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader)
        return header, [dict(zip(header, r)) for r in reader]


def _pvd(out):
    return [ds.attrib for ds in ET.parse(out / "results.pvd").getroot().iter("DataSet")]


def test_contact_csv_has_every_candidate_node_of_every_step(patch):
    out, model, analysis, result, _ = patch
    header, rows = _rows(out)
    assert tuple(header) == CONTACT_COLUMNS
    expected = {(s.step, sf.body.name, int(n)) for s in result.steps for sf in analysis.surfaces
                for n in sf.nodes[: sf.nc]}
    got = [(int(r["step"]), r["body"], int(r["node"])) for r in rows]
    assert len(got) == len(set(got)) == len(expected)
    assert set(got) == expected
    assert {r["body"] for r in rows} == {"lower", "upper"}
    # the values read back exactly (17 significant digits)
    for r in rows:
        step = result.steps[int(r["step"]) - 1]
        body = next(b for b in model.bodies if b.name == r["body"])
        n = int(r["node"])
        assert float(r["load_factor"]) == step.load_factor
        assert (float(r["x"]), float(r["y"])) == tuple(body.points[:, n])
        br = step.bodies[body.name]
        assert (float(r["ux"]), float(r["uy"])) == tuple(br.displacement[n])
        assert float(r["pressure"]) == br.contact_pressure[n]
        assert float(r["gap"]) == -br.penetration[n]


def test_contact_csv_pressure_is_the_exact_patch_pressure(patch):
    out, _, _, _, exact = patch
    _, rows = _rows(out)
    on = [r for r in rows if r["status"] == "contact"]
    assert {r["status"] for r in rows} <= {"contact", "free"}
    assert {(r["step"], r["body"]) for r in on} == {(s, b) for s in ("1", "2")
                                                    for b in ("lower", "upper")}
    for r in on:
        p_exact = float(r["load_factor"]) * exact
        assert float(r["pressure"]) == pytest.approx(p_exact, rel=1e-8)
        assert abs(float(r["gap"])) < 1e-12
        # the interface is at y = 0: both blocks move down by the lower block's shortening
        assert float(r["y"]) == 0.0
        assert float(r["uy"]) == pytest.approx(-p_exact / 1e6, rel=1e-8)


def test_gap_is_minus_penetration(patch, tmp_path):
    """gap < 0 where the solver reports overlap (penetration > 0), and no "-0" when unmeasured."""
    _, model, analysis, result, _ = patch
    step = copy.deepcopy(result.steps[-1])
    lower = analysis.surfaces[0]
    node = int(lower.nodes[0])
    step.bodies["lower"].penetration[:] = 0.0
    step.bodies["lower"].penetration[node] = 2.5e-4
    writer = ResultsWriter(tmp_path, model, analysis.surfaces)
    writer.write_step(step)
    _, rows = _rows(tmp_path)
    gaps = {(r["body"], int(r["node"])): r["gap"] for r in rows}
    assert float(gaps[("lower", node)]) == -2.5e-4
    assert all(g == "0" for (b, n), g in gaps.items() if b == "lower" and n != node)
    assert not list(tmp_path.glob("*.part"))


def test_writer_without_surfaces_writes_no_contact_csv(patch, tmp_path):
    _, model, _, result, _ = patch
    ResultsWriter(tmp_path, model).write_step(result.steps[-1])
    assert (tmp_path / "results.pvd").is_file()
    assert not (tmp_path / "contact.csv").exists()


def test_vtu_series_has_every_field_and_step(patch):
    out, model, _, result, _ = patch
    entries = _pvd(out)
    assert len(entries) == 2 * len(model.bodies)
    for i, body in enumerate(model.bodies):
        mine = [e for e in entries if e["part"] == str(i)]
        assert [float(e["timestep"]) for e in mine] == [0.5, 1.0]
        assert {e["name"] for e in mine} == {body.name}
    for e in entries:
        m = meshio.read(out / e["file"])
        for f in POINT_FIELDS:
            assert f in m.point_data, (e["file"], f)
        for f in CELL_FIELDS:
            assert f in m.cell_data, (e["file"], f)
        assert m.point_data["displacement"].shape[1] == 3


@pytest.mark.slow
def test_plot_results_writes_the_figures(patch):
    out = patch[0]
    paths = plot_results(out)
    names = {p.name for p in paths}
    assert {"deformed.png", "contact_pressure.png", "history.png"} <= names
    for p in paths:
        assert p.parent == out
        assert p.is_file() and p.stat().st_size > 1000
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_plot_results_without_contact_csv_or_summary(patch, tmp_path):
    """Older results (no contact.csv) and no summary.json: the VTU fields suffice."""
    src = patch[0]
    for f in src.iterdir():
        if f.suffix in (".vtu", ".pvd"):
            shutil.copy(f, tmp_path / f.name)
    paths = plot_results(str(tmp_path))
    assert {p.name for p in paths} >= {"deformed.png", "contact_pressure.png", "history.png"}
    assert all(p.stat().st_size > 1000 for p in paths)


@pytest.mark.slow
def test_plot_results_with_quadratic_elements(tmp_path):
    _, _, result, _ = _patch(tmp_path, order=2, load_factors=(1.0,))
    assert len(result.steps) == 1
    m = meshio.read(tmp_path / "upper_step0001.vtu")
    assert m.cells[0].type == "quad9"
    paths = plot_results(tmp_path)
    assert all(p.stat().st_size > 1000 for p in paths)


def test_plot_results_errors_name_the_path(tmp_path):
    with pytest.raises(InputError, match=re.escape(str(tmp_path))):
        plot_results(tmp_path)  # empty: no results.pvd
    missing = tmp_path / "nowhere"
    with pytest.raises(InputError, match=re.escape(str(missing))):
        plot_results(missing)
    # the folder of a run that converged no step: its summary alone, and what the run said
    (tmp_path / "summary.json").write_text(json.dumps(
        {"converged": False, "message": "step 1 (load factor 0 -> 0.1) failed: no convergence"}))
    with pytest.raises(InputError, match=re.escape(
            f"{tmp_path}: its run wrote no step to draw (no results.pvd: it stopped before its "
            "first step converged); the run said: step 1 (load factor 0 -> 0.1) failed")):
        plot_results(tmp_path)
    (tmp_path / "results.pvd").write_text(
        '<?xml version="1.0"?>\n<VTKFile type="Collection"><Collection>\n'
        '<DataSet timestep="1" group="" part="0" file="gone_step0001.vtu"/>\n'
        "</Collection></VTKFile>\n", encoding="utf-8")
    with pytest.raises(InputError, match=re.escape(str(tmp_path / "gone_step0001.vtu"))):
        plot_results(tmp_path)


def test_pvd_names_bodies_and_keeps_the_load_factor_exactly(tmp_path):
    _, _, result, _ = _patch(tmp_path, load_factors=(1.0 / 3.0,))
    (e0, e1) = _pvd(tmp_path)
    assert float(e0["timestep"]) == result.steps[0].load_factor == 1.0 / 3.0
    assert (e0["name"], e1["name"]) == ("lower", "upper")
    assert np.isclose(float(e1["timestep"]), 1.0 / 3.0)


def test_contact_csv_marks_no_node_free_that_carries_force(tmp_path):
    """A node whose own gap is open but which carries the opposing surface's force (the
    cylinder's node just past the contact edge, loaded through a virtual element) reads
    ``carrying``, not ``free``: every ``free`` row has no pressure (issue 39)."""
    import csv

    from vfem.cli import main

    assert main(["-q", "run", "hertz", "--no-figures", "--out", str(tmp_path)]) == 0
    with open(tmp_path / "contact.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {r["status"] for r in rows} == {"contact", "carrying", "free"}
    assert all(float(r["pressure"]) == 0.0 for r in rows if r["status"] == "free")
    assert all(float(r["pressure"]) > 0.0 for r in rows if r["status"] == "carrying")
