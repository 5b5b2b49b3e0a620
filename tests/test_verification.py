"""The examples' verification records (vfem.io.verification) and ``vfem verify`` (issue 39)."""

from __future__ import annotations

import json
import math

import pytest

from vfem.cli import main
from vfem.io.verification import check, lines, passed, table


def test_a_record_reads_its_error_by_its_measure():
    r = check("p", 101.0, 100.0, "closed form", 0.02, "discretisation")
    assert r["error"] == pytest.approx(0.01, rel=1e-12) and r["passed"]
    r = check("p", 103.0, 100.0, "closed form", 0.02, "discretisation")
    assert not r["passed"]
    r = check("gap", 1e-3, 0.0, "exact", 2e-3, "one facet", measure="absolute")
    assert r["error"] == 1e-3 and r["passed"]
    r = check("force", 10.5, 10.0, "applied", 0.01, "round-off", measure="scaled", scale=100.0)
    assert r["error"] == pytest.approx(0.005, rel=1e-12) and r["passed"] and r["scale"] == 100
    assert check("x", 1.0, 0.0, "zero", 1.0, "b")["error"] == math.inf  # relative to zero
    with pytest.raises(ValueError):
        check("x", 1.0, 1.0, "s", 1.0, "b", measure="scaled")
    with pytest.raises(ValueError):
        check("x", 1.0, 1.0, "s", 1.0, "b", measure="percent")


def test_the_screen_and_the_table_say_which_failed():
    good = check("p_max", 1.001, 1.0, "Hertz", 0.005, "discretisation")
    bad = check("half-width", 1.2, 1.0, "Hertz", 0.05, "one facet")
    text = "\n".join(lines([good, bad]))
    assert "passed  p_max" in text and "FAILED  half-width" in text and "1 of 2 passed" in text
    assert "0.1 %" in text and "20 %" in text  # errors as percentages where relative
    rows = table([("hertz", good), ("hertz", bad)])
    assert len(rows) == 3 and rows[2].endswith("FAILED")
    assert passed([good]) and not passed([good, bad]) and not passed([])
    assert lines([]) == []


def test_vfem_verify_runs_the_examples_and_fails_on_a_missing_record(tmp_path, capsys):
    status = main(["verify", "hertz", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    report = json.loads((tmp_path / "verify.json").read_text())
    records = report["examples"]["hertz"]["verification"]
    assert status == 0 and report["passed"] and len(records) >= 4
    assert all(r["passed"] for r in records) and "checks passed" in out
    assert (tmp_path / "hertz" / "summary.json").is_file()
    assert main(["verify", "nonesuch"]) == 2
