"""Fuzzing the command line (issue 17, item 1): no command ends in a traceback.

Whatever the arguments, ``vfem`` exits 0 or 2 (bad input, one line naming it), never 1 with
"internal error" and never with a traceback. The cases, all deterministic:

* every parameter of every built-in example given hostile values through ``--set`` (zero,
  negative, NaN, infinite, huge, tiny, of another type, empty), for ``vfem run`` (checked up to
  the solve, which is stubbed out: nothing is solved) and ``vfem export`` (the model built as
  data);
* ``--set`` on an input file with dotted keys that exist, do not exist, point into arrays by
  name and number, or through values, with hostile values (``vfem check``);
* output locations: a file, a folder under a file, a path that cannot be made (under
  ``/proc``), a name too long for the file system, an empty name, another model's results.

Bugs it found, now fixed: ``vfem run hertz --set force=-1`` and ``vfem export hertz --set
force=-1`` (a square root of a negative number in Hertz's theory); ``vfem export`` built models
from parameters its ``run`` would have refused.
"""

from __future__ import annotations

import dataclasses
import itertools
from pathlib import Path

import pytest

import vfem.cli.run as cli_run
from vfem.cli import main
from vfem_examples import EXAMPLES, load

ROOT = Path(__file__).parent.parent
HOSTILE = ["0", "-1", "-1e300", "1e300", "nan", "inf", "-inf", "1e-300", "abc", "", "true",
           "[1, 2]", "3.5", "2**63"]


def parameter_cases() -> list[tuple[str, str, str]]:
    cases = []
    for name in EXAMPLES:
        fields = [f.name for f in dataclasses.fields(load(name).Parameters)]
        for field, value in itertools.product(fields, HOSTILE):
            cases.append((name, field, value))
    return cases


CASES = parameter_cases()


def one_line_or_nothing(capsys, status: int) -> None:
    err = capsys.readouterr().err
    assert status in (0, 2), err
    assert "Traceback" not in err and "internal error" not in err, err
    if status == 2:
        assert len(err.strip().splitlines()) == 1, err


def test_the_fuzzer_covers_every_parameter_of_every_example():
    assert len(CASES) >= 1500
    assert {c[0] for c in CASES} == set(EXAMPLES)


@pytest.fixture
def no_solve(monkeypatch):
    """The run checked up to the solve, which is not done (the figures and files neither)."""
    monkeypatch.setattr(cli_run, "_solve_and_report", lambda *args, **kwargs: 0)


@pytest.mark.parametrize("chunk", range(8))
@pytest.mark.slow
def test_hostile_example_parameters_are_refused_or_accepted(chunk, tmp_path, capsys, no_solve):
    for name, field, value in CASES[chunk::8]:
        status = main(["run", name, "--set", f"{field}={value}", "--out", str(tmp_path / "o"),
                       "--overwrite"])
        one_line_or_nothing(capsys, status)
        if name != "springs":  # the 1D analogy has no input file
            status = main(["export", name, "--set", f"{field}={value}", "--out",
                           str(tmp_path / "e")])
            one_line_or_nothing(capsys, status)


KEYS = ["name", "steps.count", "steps.load_factors", "contact.variant", "contact.max_iterations",
        "contact.search_distance", "contact.nope", "bodies", "bodies.0", "bodies.9.name",
        "bodies.cylinder.material.youngs_modulus", "bodies.flat.mesh.nx", "bodies.flat.mesh",
        "bodies.cylinder.platen.force", "bodies.cylinder.supports.0.components",
        "bodies.cylinder.supports.7.boundary", "bodies.ghost.material", "name.sub",
        "steps.count.more", "output.figures", "..", "bodies..mesh"]


@pytest.mark.parametrize("key", KEYS)
def test_hostile_input_file_assignments_are_refused_or_accepted(key, capsys):
    for value in HOSTILE + ["{ a = 1 }", '"text"', "[[1, 2], [3, 4]]"]:
        status = main(["-q", "check", str(ROOT / "examples" / "hertz.toml"), "--set",
                       f"{key}={value}"])
        one_line_or_nothing(capsys, status)


def test_output_locations(tmp_path, capsys, no_solve):
    afile = tmp_path / "afile"
    afile.write_text("x")
    other = tmp_path / "other"
    assert main(["-q", "run", "springs", "--out", str(other)]) == 0  # a model's folder ...
    (other / "summary.json").write_text("{}")
    (other / "results.pvd").write_text("")
    from vfem.io.folders import RECORD

    (other / RECORD).write_text('{"target": "gasket", "settings": [], "files": ["results.pvd"]}')
    locations = [str(afile), str(afile / "sub"), "/proc/vfem-cannot-make-this", "",
                 str(tmp_path / ("x" * 300)), str(other), str(tmp_path / "ok"), "/dev/null"]
    statuses = []
    for out in locations:
        for command in (["run", "hertz"], ["run", str(ROOT / "examples" / "hertz.toml")]):
            status = main([*command, "--out", out])
            one_line_or_nothing(capsys, status)
            statuses.append(status)
    assert statuses.count(0) == 2  # only the new folder
    assert afile.read_text() == "x" and (other / "results.pvd").exists()


def test_stray_arguments_are_usage_errors(capsys):
    for argv in (["run"], ["frobnicate"], ["run", "hertz", "--set"], ["plot"], ["-x"],
                 ["run", "hertz", "--solver", "nosuch"]):
        try:
            status = main(argv)
        except SystemExit as exc:  # argparse's usage errors
            status = exc.code
        err = capsys.readouterr().err
        assert status == 2 and "Traceback" not in err, (argv, err)
