"""``vfem verify`` (src/vfem/cli/verify.py): its exit statuses and its refusals (issue 39)."""

from __future__ import annotations

import json

from vfem.cli import main
from vfem.errors import AnalysisError
from vfem.io.verification import check
from vfem_examples import hertz


def test_a_missing_record_fails_the_example(monkeypatch, capsys):
    monkeypatch.setattr(hertz, "verification", lambda *args: [])
    assert main(["verify", "hertz"]) == 1
    out = capsys.readouterr().out
    assert "hertz: no verification recorded" in out and "failed: hertz" in out


def test_a_record_beyond_its_tolerance_fails_the_example(monkeypatch, tmp_path, capsys):
    wrong = check("peak pressure", 1.1, 1.0, "a reference", 0.01, "a basis")
    monkeypatch.setattr(hertz, "verification", lambda *args: [wrong])
    assert main(["verify", "hertz", "--out", str(tmp_path)]) == 1
    assert "FAILED" in capsys.readouterr().out
    report = json.loads((tmp_path / "verify.json").read_text())
    assert not report["passed"] and not report["examples"]["hertz"]["passed"]


def test_an_example_that_fails_is_its_row_and_the_others_still_run(monkeypatch, capsys):
    def fails(*args, **kwargs):
        raise AnalysisError("no convergence (a test)")

    monkeypatch.setattr(hertz, "run", fails)
    assert main(["verify", "hertz", "springs"]) == 1
    out = capsys.readouterr().out
    assert "hertz: NOT converged (no convergence (a test))" in out
    assert "springs:" in out and "failed: hertz" in out


def test_out_must_be_a_new_an_empty_or_an_earlier_verify_folder(tmp_path, capsys):
    a_file = tmp_path / "f"
    a_file.write_text("x")
    assert main(["verify", "springs", "--out", str(a_file)]) == 2
    other = tmp_path / "other"
    other.mkdir()
    (other / "mine.txt").write_text("keep me")
    assert main(["verify", "springs", "--out", str(other)]) == 2
    assert (other / "mine.txt").read_text() == "keep me"
    err = capsys.readouterr().err
    assert "a file, not a folder" in err and "holds other files" in err
    again = tmp_path / "again"
    assert main(["verify", "springs", "--out", str(again)]) == 0
    assert main(["verify", "springs", "--out", str(again)]) == 0  # its own folder, rerun
