"""matplotlib is optional (issue 18, item 6): it draws the figures and nothing else.

Each case runs the command line in a fresh Python in which ``import matplotlib`` fails as it
does when it is not installed (``sys.modules["matplotlib"] = None``: ModuleNotFoundError).
A run still solves and writes every other result, says in one line that it drew no figure and
keeps its exit status; ``vfem plot`` stops with the fix, exit status 2; neither shows a
traceback.
"""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

#: the line a run prints instead of its figures, and the fix vfem plot names
FIGURES_LINE = ('vfem: figures not drawn: matplotlib is not installed (pip install matplotlib, '
                'or pip install -e ".[figures]")')
PLOT_ERROR = ('vfem: error: figures not drawn: matplotlib is not installed (pip install '
              'matplotlib, or pip install -e ".[figures]")')

#: Python without matplotlib: every import of it fails, then the arguments go to vfem's main
WITHOUT_MATPLOTLIB = (
    "import sys\n"
    "sys.modules['matplotlib'] = None\n"
    "from vfem.cli import main\n"
    "status = main(sys.argv[1:])\n"
    "assert not [m for m, v in sys.modules.items() if m.startswith('matplotlib') and v]\n"
    "sys.exit(status)\n")


def vfem(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", WITHOUT_MATPLOTLIB, *args], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


def _no_traceback(p: subprocess.CompletedProcess) -> None:
    assert "Traceback" not in p.stdout + p.stderr
    assert "internal error" not in p.stderr


@pytest.fixture(scope="module")
def hertz(tmp_path_factory) -> tuple[Path, subprocess.CompletedProcess]:
    """``vfem run hertz`` without matplotlib: the README's main job, which draws figures."""
    cwd = tmp_path_factory.mktemp("no_matplotlib")
    return cwd / "hertz", vfem("run", "hertz", "--out", "hertz", cwd=cwd)


@pytest.mark.slow
def test_every_module_imports_without_matplotlib():
    code = ("import sys, importlib, pkgutil\n"
            "sys.modules['matplotlib'] = None\n"
            "import vfem, vfem.solver, vfem.cli, vfem_examples, vfem_tools\n"
            "for package in (vfem, vfem_examples, vfem_tools):\n"
            "    for m in pkgutil.walk_packages(package.__path__, package.__name__ + '.'):\n"
            "        importlib.import_module(m.name)\n"
            "from vfem.io.plots import matplotlib_missing\n"
            "print(matplotlib_missing())\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == FIGURES_LINE.removeprefix("vfem: figures not drawn: ")


def test_a_run_that_draws_figures_writes_the_rest_and_says_so_in_one_line(hertz):
    out, p = hertz
    assert p.returncode == 0, p.stderr
    _no_traceback(p)
    assert (p.stdout + p.stderr).count("figures not drawn") == 1
    assert FIGURES_LINE in p.stderr.splitlines()
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert summary["converged"] is True
    assert summary["figures"] == [] and summary["figure_set"] == "hertz"
    assert summary["figures_not_drawn"] == FIGURES_LINE.removeprefix("vfem: figures not drawn: ")
    for name in ("results.pvd", "contact.csv", "reactions.csv", "cylinder_step0005.vtu",
                 "flat_step0005.vtu"):
        assert (out / name).stat().st_size > 0, name
    assert not list(out.glob("*.png"))


@pytest.mark.slow
def test_springs_runs_without_matplotlib(tmp_path):
    """The 1D example draws no figure: nothing to say about figures."""
    p = vfem("run", "springs", "--out", "springs", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    _no_traceback(p)
    assert "figures not drawn" not in p.stdout + p.stderr
    assert json.loads((tmp_path / "springs" / "summary.json").read_text())["converged"] is True


@pytest.mark.parametrize("folder", ["hertz", "springs"])
@pytest.mark.slow
def test_plot_names_the_fix_and_exits_2(hertz, tmp_path, folder):
    out, _ = hertz
    if folder == "springs":  # a folder whose run drew no figure: plot still needs matplotlib
        assert vfem("run", "springs", "--out", "springs", cwd=tmp_path).returncode == 0
        out = tmp_path / "springs"
    p = vfem("plot", str(out), cwd=tmp_path)
    assert p.returncode == 2
    _no_traceback(p)
    assert p.stderr.strip() == PLOT_ERROR
    assert p.stdout == ""
    assert not list(out.glob("*.png"))


@pytest.mark.slow
def test_plot_draws_the_figures_once_matplotlib_is_there(hertz, tmp_path):
    """The folder a run without matplotlib wrote holds all the figures need."""
    from vfem.cli import main

    out = tmp_path / "hertz"
    shutil.copytree(hertz[0], out)
    assert main(["-q", "plot", str(out)]) == 0
    assert {p.name for p in out.glob("*.png")} == {"pressure.png", "deformed.png",
                                                   "von_mises.png"}
