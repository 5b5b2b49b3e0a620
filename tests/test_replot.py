"""`vfem plot DIR` redraws exactly the figures the run drew, from the folder's files alone.

Every built-in example (at small settings) and an input file are run through the command line;
their PNGs are read back as pixels and deleted, `vfem plot` redraws them, and the redrawn set of
names and every pixel must equal the run's (Agg draws the same data identically). Then the
figures' content: every body in the legends, the magnification and the contact method in the
titles, units on the axes, every step the generic pressure plot names drawn visibly, and the
case label on every progress line of the wedge's cases.
"""

import json
from pathlib import Path

import matplotlib.figure
import matplotlib.image
import numpy as np
import pytest

from vfem.cli import Progress, main

ROOT = Path(__file__).resolve().parents[1]

#: each built-in example at settings that run in a few seconds
SMALL = {
    "springs": [],
    "patch": [],
    "hertz": [],
    "punch": ["block_columns=40", "block_rows=20", "punch_columns=9", "punch_rows=4"],
    "block": [],
    "gasket": ["n_around=60"],
    "sliding": ["block_columns=60", "block_rows=6", "punch_columns=16", "punch_rows=3",
                "press_steps=2", "slide_steps=4", "slide=0.5"],
    "wedge": ["mesh=coarse"],
}
#: the figures each run draws at those settings (the test of the whole set)
FIGURES = {
    "springs": set(),
    "patch": set(),
    "hertz": {"pressure.png", "deformed.png", "von_mises.png"},
    "punch": {"pressure.png", "deformed.png", "von_mises.png"},
    "block": {"initial.png", "prediction.png", "final.png", "corner.png", "pressure.png",
              "von_mises.png"},
    "gasket": {"initial.png", "ignoring_contact.png", "step05_prediction.png",
               "step05_resolved.png", "step05_contact.png", "step10_prediction.png",
               "step10_resolved.png", "step10_contact.png", "initial_final.png",
               "contact_force.png", "von_mises.png"},
    "sliding": {"reactions.png", "pressed.png", "halfway.png", "slid.png", "von_mises.png"},
    "wedge": {"mesh.png", "prediction.png", *(f"case{k}.png" for k in range(1, 6)),
              "cases_1_3_5.png", "cases_1_2_3.png", "cases_3_4_5.png",
              *(f"von_mises_case{k}.png" for k in range(1, 6))},
}
GENERIC = {"deformed.png", "contact_pressure.png", "history.png", "von_mises.png"}


def _pngs(folder: Path) -> dict[str, np.ndarray]:
    return {p.relative_to(folder).as_posix(): matplotlib.image.imread(p)
            for p in sorted(folder.rglob("*.png"))}


def _redraw(folder: Path) -> tuple[dict, dict]:
    """The run's pixels, then `vfem plot`'s, with the PNGs deleted in between."""
    before = _pngs(folder)
    for p in folder.rglob("*.png"):
        p.unlink()
    assert main(["-q", "plot", str(folder)]) == 0
    return before, _pngs(folder)


def _same(before: dict, after: dict) -> None:
    assert sorted(after) == sorted(before)
    for name, pixels in before.items():
        assert after[name].shape == pixels.shape, name
        assert np.array_equal(after[name], pixels), f"{name} redrawn differently"


class Runs(dict):
    """Each built-in example run at its small settings when a test first asks for it:
    example -> results folder (so the fast suite runs only the examples its tests name)."""

    def __init__(self, factory):
        super().__init__()
        self.factory = factory

    def __missing__(self, name: str) -> Path:
        folder = self.factory.mktemp(name)
        args = ["-q", "run", name, "--out", str(folder)]
        for s in SMALL[name]:
            args += ["--set", s]
        assert main(args) == 0, name
        self[name] = folder
        return folder


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return Runs(tmp_path_factory)


#: the examples whose small runs take seconds each: their figure tests are in the slow set
SLOW = {"block", "gasket", "sliding", "wedge", "punch", "patch"}


def examples(names) -> list:
    return [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in names]


@pytest.mark.parametrize("example", examples(SMALL))
def test_plot_redraws_every_figure_of_the_example_run(runs, example):
    folder = runs[example]
    summary = json.loads((folder / "summary.json").read_text())
    before, after = _redraw(folder)
    assert set(before) == FIGURES[example]
    assert set(summary.get("figures", [])) == FIGURES[example]
    if FIGURES[example]:
        assert summary["figure_set"] == example
    _same(before, after)


@pytest.mark.slow
def test_plot_redraws_the_figures_of_an_input_file_run(tmp_path):
    assert main(["-q", "run", str(ROOT / "examples" / "hertz.toml"), "--out",
                 str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["figure_set"] == "input"
    before, after = _redraw(tmp_path)
    assert GENERIC <= set(before) == set(summary["figures"])
    _same(before, after)


@pytest.mark.parametrize("example", ["gasket", "input"])
@pytest.mark.slow
def test_no_figures_leaves_them_to_vfem_plot_which_draws_the_same(runs, example, tmp_path,
                                                                   capsys):
    """``vfem run --no-figures``: every result but the figures, a line saying so, and
    ``vfem plot`` draws the very figures the run would have drawn (a built-in example whose
    figures need data from the run, and an input file); a later run draws them again."""
    if example == "input":
        model = [str(ROOT / "examples" / "hertz.toml")]
        drawn = tmp_path / "drawn"
        assert main(["-q", "run", *model, "--out", str(drawn)]) == 0
    else:
        model = [example] + [a for s in SMALL[example] for a in ("--set", s)]
        drawn = runs[example]
    out = tmp_path / "deferred"
    assert main(["run", *model, "--no-figures", "--out", str(out)]) == 0
    assert "figures not drawn: --no-figures (vfem plot" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["figures"] == [] and not list(out.rglob("*.png"))
    assert (out / "results.pvd").exists()
    assert main(["-q", "plot", str(out)]) == 0
    _same(_pngs(drawn), _pngs(out))
    if example == "input":  # the next run in the process draws its figures again
        again = tmp_path / "again"
        assert main(["-q", "run", *model, "--out", str(again)]) == 0
        assert _pngs(again)


@pytest.mark.slow
def test_a_folder_without_a_figure_set_gets_the_generic_figures(runs, tmp_path, capsys):
    """Results written before figure sets were recorded: the generic figures, no traceback."""
    src = runs["hertz"]
    for f in src.iterdir():
        if f.suffix in (".vtu", ".pvd", ".csv"):
            (tmp_path / f.name).write_bytes(f.read_bytes())
    summary = json.loads((src / "summary.json").read_text())
    for key in ("figure_set", "figures", "contact_settings"):
        summary.pop(key)
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    assert main(["plot", str(tmp_path)]) == 0
    drawn = {p.name for p in tmp_path.glob("*.png")}
    assert GENERIC <= drawn and "pressure.png" not in drawn
    assert "Traceback" not in capsys.readouterr().err


@pytest.fixture
def drawn(monkeypatch):
    """What each figure saved shows: file name -> its axes' titles, axis labels, legend
    texts and lines (recorded as matplotlib saves it)."""
    seen = {}
    save = matplotlib.figure.Figure.savefig

    def record(fig, path, *args, **kw):
        axes = fig.axes
        seen[Path(path).name] = {
            "titles": " ".join([ax.get_title() for ax in axes]
                               + [fig._suptitle.get_text() if fig._suptitle else ""]),
            "labels": [ax.get_xlabel() + "|" + ax.get_ylabel() for ax in axes],
            "legend": [t.get_text() for ax in axes if ax.get_legend()
                       for t in ax.get_legend().get_texts()],
            "lines": [line for ax in axes for line in ax.get_lines()],
        }
        return save(fig, path, *args, **kw)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", record)
    return seen


SHAPES = {  # figures of deformed shapes, per example
    "hertz": ["deformed.png", "von_mises.png"],
    "punch": ["deformed.png", "von_mises.png"],
    "block": ["prediction.png", "final.png", "corner.png", "von_mises.png"],
    "gasket": ["ignoring_contact.png", "step05_prediction.png", "step10_resolved.png",
               "step10_contact.png", "initial_final.png", "von_mises.png"],
    "sliding": ["pressed.png", "slid.png", "von_mises.png"],
    "wedge": ["prediction.png", "case1.png", "cases_1_3_5.png", "von_mises_case3.png"],
}
BODIES = {"hertz": ("cylinder", "flat"), "punch": ("block", "punch"), "block": ("small", "large"),
          "gasket": ("soft", "stiff"), "sliding": ("block", "punch"), "wedge": ("wedge", "plate")}


@pytest.mark.parametrize("example", examples(SHAPES))
def test_deformed_shapes_name_every_body_the_scale_and_the_units(runs, example, drawn):
    assert main(["-q", "plot", str(runs[example])]) == 0
    for name in SHAPES[example]:
        fig = drawn[name]
        legend = " ".join(fig["legend"])
        for body in BODIES[example]:
            assert body in legend, (name, body, legend)
        assert "displacements ×" in fig["titles"], name
        assert all("model units" in label for label in fig["labels"]), name
    vm = next(n for n in SHAPES[example] if n.startswith("von_mises"))
    assert any("von Mises stress (model units)" in label for label in drawn[vm]["labels"])
    for name in SHAPES[example][-2:]:  # results of the analysis: the method is in the title
        assert "contact: vfem, paired variant" in drawn[name]["titles"], name


@pytest.mark.slow
def test_the_title_names_a_classical_method(tmp_path, drawn):
    assert main(["-q", "run", "hertz", "--set", "method=lagrange", "--out", str(tmp_path)]) == 0
    assert "contact: lagrange" in drawn["deformed.png"]["titles"]
    assert "contact: lagrange" in drawn["pressure.png"]["titles"]


@pytest.mark.slow
def test_the_pressure_plot_draws_every_step_it_names(tmp_path, drawn):
    """A step whose profile is a single node (the first touch) is a point, which a line without
    a marker leaves undrawn although the legend names it; a step with no node in contact says
    so. Then the generic figure of a run: every step it names is drawn."""
    from vfem.io import plots

    profiles = {"cylinder": [("step 1", np.array([]), np.array([])),
                             ("step 2", np.array([0.0]), np.array([5.0])),
                             ("step 3", np.array([0.0, 0.1]), np.array([9.0, 4.0]))]}
    plots.contact_pressure_profiles(tmp_path / "p.png", profiles, "test")
    lines = {line.get_label(): line for line in drawn["p.png"]["lines"]
             if not line.get_label().startswith("_")}
    assert set(lines) == {"cylinder: step 1: no node in contact", "cylinder: step 2",
                          "cylinder: step 3"}
    assert lines["cylinder: step 2"].get_marker() not in ("None", "", None)
    assert main(["-q", "run", str(ROOT / "examples" / "hertz.toml"), "--out",
                 str(tmp_path / "r")]) == 0
    fig = drawn["contact_pressure.png"]
    named = [line for line in fig["lines"] if line.get_label().startswith(("cylinder", "flat"))]
    assert len(named) == 10  # 2 bodies x every one of the 5 steps (at most MAX_PROFILES)
    for line in named:
        assert len(line.get_xdata()) > 0 and line.get_marker() not in ("None", "", None)
    assert all("model units" in label for label in fig["labels"])


def test_each_case_of_the_wedge_labels_its_progress(tmp_path, capsys):
    assert main(["run", "wedge", "--set", "mesh=coarse", "--set", "figures=false", "--out",
                 str(tmp_path)]) == 0
    lines = [x for x in capsys.readouterr().out.splitlines() if "load factor" in x]
    assert [x.split(":")[0].strip() for x in lines] == [f"case {k}" for k in range(1, 6)]


def test_progress_prefixes_the_case_and_counts_its_steps_anew():
    import io
    from types import SimpleNamespace

    stream = io.StringIO()
    progress = Progress([0.5, 1.0], stream=stream)
    step = SimpleNamespace(step=1, load_factor=0.5, iterations=2, history=[], cuts=0)
    progress.start_case("case 1")
    progress(step)
    progress.start_case("case 2")
    progress(step)
    first, second = stream.getvalue().splitlines()
    assert first.startswith("  case 1: [##########..........]")
    assert second.startswith("  case 2: [##########..........]")


@pytest.fixture
def legends(monkeypatch):
    """Per figure saved: each legend's box and its axes' box, in pixels, as drawn, and the
    figure's box."""
    seen = {}
    save = matplotlib.figure.Figure.savefig

    def record(fig, path, *args, **kw):
        out = save(fig, path, *args, **kw)  # drawn: the boxes are final
        renderer = fig.canvas.get_renderer()
        seen[Path(path).name] = {
            "figure": fig.bbox,
            "boxes": [(ax.get_legend().get_window_extent(renderer),
                       ax.get_window_extent(renderer)) for ax in fig.axes if ax.get_legend()]}
        return out

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", record)
    return seen


@pytest.mark.parametrize("model, figure", [
    pytest.param(["sliding", *(a for s in SMALL["sliding"] + ["friction=0.3"]
                               for a in ("--set", s))], "reactions.png", marks=pytest.mark.slow),
    pytest.param([str(ROOT / "examples" / "friction" / "pushed_block.toml")], "history.png",
                 marks=pytest.mark.slow)])
def test_the_legends_of_the_step_histories_stand_beside_the_curves(model, figure, tmp_path,
                                                                  legends):
    """reactions.png (sliding) and history.png (an input file's run): each panel's legend
    outside its axes, where it covers no curve (inside, at "upper right", it covered the last
    points of the tangential reaction and of a held contact force), and whole in the figure."""
    assert main(["-q", "run", *model, "--out", str(tmp_path)]) == 0
    boxes = legends[figure]["boxes"]
    assert boxes, figure
    for legend, axes in boxes:
        assert not legend.overlaps(axes), (figure, legend, axes)
        assert legends[figure]["figure"].contains(legend.x0, legend.y0)
        assert legends[figure]["figure"].contains(legend.x1, legend.y1)
