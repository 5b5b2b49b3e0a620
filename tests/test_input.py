"""Input files: the examples as files, exact reproduction, the key reference, bad input."""

import dataclasses
import json
import re
from pathlib import Path

import numpy as np
import pytest

import vfem
from vfem.cli import main
from vfem.io.input import dumps, load, loads, reference
from vfem_examples import block, gasket, hertz, patch, punch, sliding, wedge

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
BAD = sorted((Path(__file__).parent / "data" / "bad_input").glob("*.toml"))


def example_files():
    """(file, the configuration the built-in example builds now) for every example file."""
    yield EXAMPLES / "hertz.toml", hertz.config(hertz.HertzParameters())
    yield EXAMPLES / "block.toml", block.config(block.Parameters())
    yield EXAMPLES / "gasket.toml", gasket.config(gasket.GasketParameters())
    yield EXAMPLES / "sliding.toml", sliding.config(sliding.Parameters())
    yield EXAMPLES / "punch" / "flat_punch.toml", punch.config(punch.Parameters())
    for key, config in patch.configs(patch.Parameters()).items():
        yield EXAMPLES / "patch" / f"{key}.toml", config
    for key, config in wedge.configs(wedge.WedgeParameters()).items():
        yield EXAMPLES / "wedge" / f"{key}.toml", config


@pytest.mark.parametrize(("path", "config"), list(example_files()),
                         ids=lambda v: v.name if isinstance(v, Path) else "")
def test_example_files_describe_the_built_in_models(path, config):
    """Regenerate with `vfem export EXAMPLE --out ...` when an example changes."""
    assert load(path) == config


def test_every_example_with_bodies_has_its_files():
    assert len(list(example_files())) == 5 + 12 + 5
    assert sorted(p.name for p in (EXAMPLES / "patch").glob("*.toml")) == sorted(
        f"{k}.toml" for k in patch.configs(patch.Parameters()))


@pytest.mark.parametrize("config", [hertz.config(hertz.HertzParameters(order=2, initial_gap=0.01)),
                                    gasket.config(), block.config(block.Parameters(steps=3))])
def test_writing_and_reading_back_gives_the_same_description(config):
    assert loads(dumps(config)) == config


def test_hertz_file_reproduces_the_built_in_run_exactly(hertz_level0):
    p, result, evaluated = hertz_level0
    from_file = vfem.solve(EXAMPLES / "hertz.toml")
    assert from_file.converged
    assert [s.iterations for s in from_file.steps] == [s.iterations for s in result.steps]
    cyl = from_file.steps[-1].bodies["cylinder"]
    assert cyl.contact_pressure.max() == evaluated["p_max"]  # the same digits
    assert float(cyl.contact_force[:, 1].sum()) == evaluated["total_contact_force"]
    assert np.array_equal(cyl.displacement, result.steps[-1].bodies["cylinder"].displacement)


@pytest.mark.slow
def test_block_file_via_the_command_line_matches_the_built_in_run(tmp_path, capsys):
    assert main(["-q", "run", "block", "--out", str(tmp_path / "builtin")]) == 0
    assert main(["run", str(EXAMPLES / "block.toml"), "--out", str(tmp_path / "file")]) == 0
    out = capsys.readouterr().out
    assert "vfem: block: converged" in out and "results:" in out  # the closing summary
    builtin = json.loads((tmp_path / "builtin" / "summary.json").read_text())
    s = json.loads((tmp_path / "file" / "summary.json").read_text())
    assert s["converged"] and s["input"].endswith("block.toml")
    assert s["bodies"]["large"]["contact_force"][1] == builtin["block"]["contact_force"]
    assert [x["iterations"] for x in s["steps"]] == [x["iterations"] for x in builtin["steps"]]
    for name in ("contact.csv", "results.pvd", "deformed.png", "contact_pressure.png",
                 "history.png"):
        assert (tmp_path / "file" / name).stat().st_size > 0


def test_the_example_in_docs_input_runs_and_is_exact(tmp_path):
    text = (ROOT / "docs" / "input.md").read_text(encoding="utf-8")
    block_text = re.search(r"```toml\n(.*?)```", text, re.S).group(1)
    config = loads(block_text, "docs/input.md")
    result = vfem.solve(config)
    assert result.converged and len(result.steps) == 2
    for body in ("lower", "upper"):
        r = result.steps[-1].bodies[body]
        on = r.contact_status == 1
        assert on.sum() >= 3
        assert np.allclose(r.contact_pressure[on], 500.0, rtol=1e-8)


def test_docs_input_holds_the_generated_key_reference():
    text = (ROOT / "docs" / "input.md").read_text(encoding="utf-8")
    generated = text.split("<!-- generated: begin -->\n")[1].split("<!-- generated: end -->")[0]
    assert generated == reference(), "regenerate: vfem reference"


def test_every_key_has_help_text():
    import vfem.bodies as bodies
    import vfem.config as config
    from vfem.contact.settings import ContactSettings, PairFriction
    from vfem.io.input import SECTIONS, help_texts
    from vfem.materials import J2Plastic, LinearElastic

    classes = {"ContactSettings": ContactSettings, "PairFriction": PairFriction,
               "LinearElastic": LinearElastic, "J2Plastic": J2Plastic}
    for name in SECTIONS:
        cls = classes.get(name) or getattr(config, name, None) or getattr(bodies, name)
        helps = help_texts(cls)
        for f in dataclasses.fields(cls):
            if f.name != "parameters":
                assert helps.get(f.name), f"{name}.{f.name} has no help text"


@pytest.mark.parametrize("path", BAD, ids=lambda p: p.stem)
def test_bad_input_file_is_one_clear_message_and_exit_2(path, capsys, tmp_path):
    expected = path.read_text(encoding="utf-8").splitlines()[0].removeprefix("# expect: ")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert expected in err, err
    assert str(path) in err  # names the file
    assert err.count("\n") == 1 and "Traceback" not in err
    # `run` refuses it the same way, before writing anything
    out = tmp_path / "results"
    assert main(["-q", "run", str(path), "--out", str(out)]) == 2
    assert expected in capsys.readouterr().err
    assert not out.exists()


def test_the_bad_input_deck_is_large_enough():
    assert len(BAD) >= 15


def test_check_accepts_every_example_file(capsys):
    for path, _ in example_files():
        assert main(["check", str(path)]) == 0
    assert capsys.readouterr().out.count("is valid") == 22


def test_missing_input_file(capsys):
    assert main(["check", "no/such/model.toml"]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_export_refuses_springs_and_needs_a_folder_for_several_models(capsys, tmp_path):
    assert main(["export", "springs"]) == 2
    assert "no input file" in capsys.readouterr().err
    assert main(["export", "patch"]) == 2
    assert "give --out DIR" in capsys.readouterr().err
    assert main(["export", "hertz", "--set", "order=2"]) == 0
    assert loads(capsys.readouterr().out) == hertz.config(hertz.HertzParameters(order=2))


def test_the_export_header_is_plain_text_naming_the_whole_command(capsys, tmp_path):
    """The comment lines ``vfem export`` writes: no Markdown backticks (which read as part of
    the command, and closed before its --set options), the command with every --set and the
    run that solves the same model, the example's title whole (Cattaneo's spans two lines)."""
    assert main(["export", "sliding", "--set", "friction=0.3", "--set", "slide=1.5"]) == 0
    text = capsys.readouterr().out
    header = [x for x in text.splitlines() if x.startswith("#")]
    assert "`" not in "".join(header)
    assert "# Written by: vfem export sliding --set friction=0.3 --set slide=1.5" in header
    assert ("# vfem run <this file> solves the same model as: vfem run sliding --set "
            "friction=0.3 --set slide=1.5") in header
    assert loads(text) == sliding.config(sliding.Parameters(friction=0.3, slide=1.5))
    assert main(["export", "cattaneo"]) == 0
    header = " ".join(x[2:] for x in capsys.readouterr().out.splitlines() if x.startswith("#"))
    assert "then sheared by a growing sideways motion with P held (issue 20)." in header
    assert main(["-q", "export", "wedge", "--out", str(tmp_path)]) == 0
    for path in tmp_path.glob("*.toml"):
        assert "`" not in path.read_text(), path.name
    # the files in examples/ that vfem export wrote say the same
    for path, _ in example_files():
        written = [x for x in path.read_text().splitlines() if "vfem export" in x]
        assert written and not any("`" in x for x in written), path


@pytest.mark.slow
def test_plot_redraws_the_figures_of_a_results_folder(tmp_path, capsys):
    assert main(["-q", "run", str(EXAMPLES / "patch" / "2x10_nu0.toml"), "--out",
                 str(tmp_path)]) == 0
    for name in ("deformed.png", "contact_pressure.png", "history.png"):
        (tmp_path / name).unlink()
    assert main(["plot", str(tmp_path)]) == 0
    assert (tmp_path / "contact_pressure.png").stat().st_size > 0
    assert main(["plot", str(tmp_path / "nothing")]) == 2
    assert "nothing" in capsys.readouterr().err


@pytest.mark.slow
def test_progress_prints_a_line_per_step_when_not_on_a_terminal(tmp_path, capsys):
    assert main(["run", str(EXAMPLES / "patch" / "4x7_nu0.toml"), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"\[#{20}\] step +1 +load factor +1\.0000 +1 iterations", out)


@pytest.mark.slow
def test_hertz_meshed_in_gmsh_agrees_with_the_built_in_hertz(tmp_path, hertz_level0, capsys):
    """examples/hertz_gmsh: make the mesh with the gmsh API, solve it from its input file."""
    pytest.importorskip("gmsh")
    import importlib.util
    import shutil

    folder = EXAMPLES / "hertz_gmsh"
    spec = importlib.util.spec_from_file_location("make_mesh", folder / "make_mesh.py")
    make_mesh = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_mesh)
    make_mesh.build(tmp_path / "hertz.msh")
    shutil.copy(folder / "hertz_gmsh.toml", tmp_path)
    out = tmp_path / "results"
    assert main(["-q", "run", str(tmp_path / "hertz_gmsh.toml"), "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    p_max = s["bodies"]["cylinder"]["max_contact_pressure"]
    assert p_max == pytest.approx(hertz_level0[2]["p_max"], rel=0.02)  # the bar
    assert p_max == pytest.approx(hertz_level0[2]["p0_theory"], rel=0.003)
    assert s["bodies"]["cylinder"]["contact_force"][1] == pytest.approx(1530.0, rel=1e-9)


def test_progress_on_a_terminal_shows_each_contact_iteration(tmp_path):
    """On a terminal the bar is redrawn in place, with the iteration under way and its errors."""
    import io

    from vfem.cli import Progress

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    screen = Terminal()
    config = load(EXAMPLES / "hertz.toml")
    progress = Progress(config.steps.factors(), stream=screen)
    result = vfem.solve(config, tmp_path, on_step=progress)
    progress.close()
    text = screen.getvalue()
    assert text.count("\r") == sum(len(s.history) for s in result.steps) + len(result.steps)
    last = len(result.steps[-1].history) - 1
    assert f"step   5  iteration {last:3d}  penetration" in text
    assert "[####################] step   5  load factor  1.0000" in text


@pytest.mark.parametrize("directory", ["/etc/vfem", "../elsewhere", "results/../../up", "C:\\out",
                                       "..\\up", "\\\\server\\share", "", "a\0b"])
def test_output_directory_of_an_input_file_must_stay_inside_the_working_directory(directory):
    from vfem.config import Output
    from vfem.errors import InputError

    with pytest.raises(InputError, match="output.directory: .* is not a folder inside the "
                                         "working directory"):
        Output(directory)


@pytest.mark.parametrize("directory", ["results/model", ".", "a/../b", "results/./x"])
def test_relative_output_directories_stay_allowed(directory):
    from vfem.config import Output

    assert Output(directory).directory == directory
