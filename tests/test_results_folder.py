"""Issue 17, items 2 and 5: results folders that cannot be mixed up, and ``--set`` for input files.

A run records what it wrote (``.vfem-run.json``); a later run into the same folder clears exactly
those files (never another file), another model's results are kept unless ``--overwrite`` is
given, ``summary.json`` says what was run, and the default folder's name carries ``--set``.
"""

import dataclasses
import json
from pathlib import Path

import pytest

from vfem.cli import main
from vfem.io.folders import RECORD

HERTZ = Path(__file__).parent.parent / "examples" / "hertz.toml"
TWO = Path(__file__).parent.parent / "examples" / "punch" / "two_punches.toml"


def vtus(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.glob("*.vtu"))


@pytest.mark.slow
def test_a_shorter_run_of_the_same_model_leaves_no_stale_step(tmp_path, capsys):
    model = tmp_path / "hertz.toml"
    model.write_text(HERTZ.read_text())
    out = tmp_path / "out"
    assert main(["-q", "run", str(model), "--out", str(out), "--set", "steps.count=8"]) == 0
    assert len(vtus(out)) == 16
    (out / "notes.txt").write_text("mine")  # a file vfem did not write
    model.write_text(HERTZ.read_text().replace("count = 5", "count = 3"))  # the model edited
    assert "count = 3" in model.read_text()
    assert main(["-q", "run", str(model), "--out", str(out), "--set", "steps.count=8"]) == 0
    assert len(vtus(out)) == 16
    # the same model (file) without the --set: its own earlier files cleared, no --overwrite
    assert main(["-q", "run", str(model), "--out", str(out)]) == 0
    assert vtus(out) == [f"{b}_step000{k}.vtu" for b in ("cylinder", "flat") for k in (1, 2, 3)]
    assert sorted(p.name for p in (out / "checkpoint").iterdir()) == [
        "step0001.npz", "step0002.npz", "step0003.npz"]
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "results.pvd").read_text().count("<DataSet") == 6
    record = json.loads((out / RECORD).read_text())
    assert "notes.txt" not in record["files"] and "summary.json" in record["files"]
    run = json.loads((out / "summary.json").read_text())["run"]
    assert run["target"] == str(model.resolve()) and run["settings"] == []
    assert run["command"].endswith(str(out)) and run["vfem_version"]


@pytest.mark.slow
def test_two_models_in_one_folder(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["-q", "run", str(TWO), "--out", str(out), "--set", "steps.count=1"]) == 0
    first = sorted(p.name for p in out.iterdir())
    assert main(["-q", "run", str(HERTZ), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "two_punches.toml" in err and "--overwrite" in err
    assert sorted(p.name for p in out.iterdir()) == first  # untouched
    assert main(["-q", "run", str(HERTZ), "--out", str(out), "--overwrite"]) == 0
    names = {p.name for p in out.iterdir()}
    assert not any(n.startswith(("block", "left", "right", "punch")) for n in names), names
    assert {"summary.json", "results.pvd", "cylinder_step0005.vtu", RECORD} <= names


@pytest.mark.slow
def test_a_folder_written_before_the_record(tmp_path):
    out = tmp_path / "old"
    out.mkdir()
    (out / "summary.json").write_text("{}")
    for k in range(1, 17):
        (out / f"cylinder_step{k:04d}.vtu").write_text("")
    (out / "mine.vtu").write_text("")
    assert main(["-q", "run", str(HERTZ), "--out", str(out)]) == 0
    assert vtus(out) == sorted([f"{b}_step000{k}.vtu" for b in ("cylinder", "flat")
                                for k in range(1, 6)] + ["mine.vtu"])


@pytest.mark.slow
def test_default_folder_carries_the_settings(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["-q", "run", "hertz", "--set", "force=1000"]) == 0
    assert main(["-q", "run", "hertz"]) == 0
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["hertz", "hertz_force=1000"]
    a = json.loads((tmp_path / "results" / "hertz_force=1000" / "summary.json").read_text())
    assert a["parameters"]["force"] == 1000 and a["run"]["settings"] == ["force=1000"]


@pytest.mark.slow
def test_set_changes_an_input_file_key_checked_like_the_file(tmp_path, capsys):
    out = tmp_path / "changed"
    assert main(["-q", "run", str(HERTZ), "--out", str(out), "--set", "contact.max_iterations=150",
                 "--set", "bodies.flat.material.poissons_ratio=0.25"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["config"]["contact"]["max_iterations"] == 150
    flat = next(b for b in s["config"]["bodies"] if b["name"] == "flat")
    assert flat["material"]["poissons_ratio"] == 0.25
    for change, words in (("contact.variantt=thesis", "did you mean 'variant'"),
                          ("bodies.cyl.material.youngs_modulus=3", "there are 'cylinder', 'flat'"),
                          ("bodies.5.material.youngs_modulus=3", "has 2 entries"),
                          ("steps.count=abc", "steps.count: expected an integer"),
                          ("name.x=1", "is the string"),
                          ("steps.count", "expects KEY=VALUE"),
                          ("bodies.-1.name=z", "no entry named '-1'"),
                          ("bodies.flat.tractions.0.value=1", "the file has no"),
                          ("steps.load_factors=[0.5, 1.0]", "not both"),
                          ("contact.variant=foo", "with --set contact.variant=foo:")):
        assert main(["check", str(HERTZ), "--set", change]) == 2
        err = capsys.readouterr().err
        assert words in err and len(err.strip().splitlines()) == 1, err


def test_ctrl_c_before_the_first_step_offers_no_resume(tmp_path, monkeypatch, capsys):
    import vfem.io.runner as runner

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "run", interrupted)
    assert main(["-q", "run", str(HERTZ), "--out", str(tmp_path / "o")]) == 130
    err = capsys.readouterr().err
    assert "nothing to resume" in err and "--resume" not in err


@pytest.mark.slow
def test_the_python_api_keeps_its_folder_the_same_way(tmp_path):
    import vfem
    from vfem.errors import InputError

    out = tmp_path / "api"
    config = vfem.load(HERTZ)
    eight = dataclasses.replace(config, steps=dataclasses.replace(config.steps, count=8))
    vfem.solve(eight, out)
    assert len(vtus(out)) == 16
    vfem.solve(HERTZ, out)  # the same model's name: its earlier files cleared
    assert len(vtus(out)) == 10
    other = vfem.load(TWO)
    try:
        vfem.solve(other, out)
        raise AssertionError("another model's results were overwritten")
    except InputError as exc:
        assert "holds the results of another run" in str(exc)
    vfem.solve(other, out, overwrite=True)
    assert not any(n.startswith("cylinder") for n in vtus(out))


def test_a_model_name_cannot_send_results_elsewhere(tmp_path, monkeypatch):
    from vfem.io.folders import default_folder

    for name in ("../../escaped", "/tmp/abs", "", ".", "..", "a/b\\c"):
        folder = default_folder(name, [])
        assert folder.parent == Path("results") and folder.name not in ("", ".", ".."), folder


@pytest.mark.slow
def test_a_refused_resume_changes_nothing_and_a_resume_keeps_the_description(tmp_path, capsys):
    out = tmp_path / "r"
    assert main(["-q", "run", str(HERTZ), "--out", str(out)]) == 0
    record = (out / RECORD).read_text()
    summary = (out / "summary.json").read_text()
    assert main(["-q", "run", str(HERTZ), "--resume", str(out), "--set",
                 "contact.variant=thesis"]) == 2
    err = capsys.readouterr().err
    assert "different model" in err
    assert "(contact.variant: stored 'paired', now 'thesis')" in err  # which setting, both values
    assert err.count("\n") == 1 and "Traceback" not in err
    assert (out / RECORD).read_text() == record and (out / "summary.json").read_text() == summary
    assert main(["-q", "run", str(HERTZ), "--resume", str(out)]) == 0
    run = json.loads((out / "summary.json").read_text())["run"]
    assert run["command"] == json.loads(record)["command"]  # the run continued
    assert run["resumed"][-1]["command"].endswith(f"--resume {out}")


def test_an_empty_model_and_plotting_a_file_are_told_plainly(capsys):
    assert main(["run", ""]) == 2
    assert "no model given" in capsys.readouterr().err
    assert main(["plot", str(HERTZ)]) == 2
    assert "is a file, not a results folder" in capsys.readouterr().err
