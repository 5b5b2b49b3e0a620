"""What a run with friction tells its reader (issue 20, a new user's trial): the work the
friction dissipated on every closing screen that reads friction (0, never a negative
round-off, where nothing slipped), the laws that ran in ``summary.json``'s
``contact_settings`` and on the screen (both coefficients of the static/dynamic law)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from vfem.cli import main
from vfem.io.runner import ROUND_OFF, dissipated, friction_line

ROOT = Path(__file__).resolve().parents[1]
FRICTION = ROOT / "examples" / "friction"

#: the sliding example at settings that run in a few seconds (as tests/test_replot.py)
SLIDING = ["block_columns=60", "block_rows=6", "punch_columns=16", "punch_rows=3",
           "press_steps=2", "slide_steps=4", "slide=0.5"]
#: the Cattaneo example, shorter
CATTANEO = ["press_steps=2", "shear_steps=4"]


def _run(capsys, *args) -> tuple[str, dict]:
    """``vfem run ...`` (exit status 0): what it printed and its summary.json."""
    out = Path(args[args.index("--out") + 1])
    assert main(["run", *args]) == 0
    printed = capsys.readouterr().out
    return printed, json.loads((out / "summary.json").read_text())


def _sets(settings: list[str]) -> list[str]:
    return [a for s in settings for a in ("--set", s)]


# -- the work dissipated -------------------------------------------------------------------------

def test_round_off_is_shown_as_zero_and_real_work_as_it_is():
    steps = [{"external_work": 0.01}, {"external_work": 0.0005}]
    stick = {"frictional_work_total": -2.3e-17, "steps": steps}
    assert dissipated(stick) == 0.0
    assert "work dissipated 0 over the run, to round-off" in friction_line(stick)
    assert "-2.3e-17" not in friction_line(stick)
    # just above the threshold, and a real (even negative) reading, are shown as they are
    above = 2 * ROUND_OFF * 0.0105
    assert dissipated({"frictional_work_total": above, "steps": steps}) == above
    assert dissipated({"frictional_work_total": -1e-3, "steps": steps}) == -1e-3
    assert dissipated({"frictional_work_total": 0.0072, "steps": steps}) == 0.0072
    assert dissipated({"steps": steps}) is None and friction_line({"steps": steps}) == ""


def test_a_run_that_only_sticks_prints_zero_work_not_a_negative_round_off(tmp_path, capsys):
    printed, summary = _run(capsys, str(FRICTION / "patch_stick.toml"), "--out",
                            str(tmp_path), "--no-figures")
    assert abs(summary["frictional_work_total"]) < 1e-12  # round-off (-2.8e-17 here)
    assert summary["external_work_total"] == pytest.approx(0.01045, rel=1e-9)
    assert len(summary["steps"]) == 2
    assert all("external_work" in x and "frictional_work" in x for x in summary["steps"])
    line = next(x for x in printed.splitlines() if "work dissipated" in x)
    assert "work dissipated 0 over the run, to round-off" in line, line
    assert "work dissipated -" not in printed


@pytest.mark.slow
def test_the_cattaneo_and_sliding_screens_give_the_total_work(tmp_path, capsys):
    printed, summary = _run(capsys, "cattaneo", *_sets(CATTANEO), "--out", str(tmp_path / "c"),
                            "--no-figures")
    total = summary["frictional_work_total"]
    assert total > 0
    lines = printed.splitlines()
    line = next(x for x in lines if "work dissipated" in x)
    assert f"work dissipated {total:.4g} over the run" in line
    assert "upper/lower: Coulomb, mu = 0.3" in line
    # beside the other friction readings: after the steps of the shear, before the forces
    report = lines[:next(k for k, x in enumerate(lines) if x.startswith("  verification"))]
    assert lines.index(line) == 1 + max(k for k, x in enumerate(report) if "Q/(mu P)" in x)
    printed, summary = _run(capsys, "sliding", *_sets(SLIDING + ["friction=0.3"]), "--out",
                            str(tmp_path / "s"), "--no-figures")
    total = summary["frictional_work_total"]
    assert total > 0
    lines = printed.splitlines()
    line = next(x for x in lines if "work dissipated" in x)
    assert f"work dissipated {total:.4g} over the run" in line
    assert lines.index(line) == 1 + next(k for k, x in enumerate(lines)
                                         if x.startswith("  friction mu = 0.3"))
    printed, summary = _run(capsys, "sliding", *_sets(SLIDING), "--out", str(tmp_path / "f"),
                            "--no-figures")
    assert "work dissipated" not in printed and "frictional_work_total" not in summary


# -- the laws that ran ---------------------------------------------------------------------------

def test_contact_settings_record_the_law_and_the_screen_gives_both_coefficients(tmp_path,
                                                                              capsys):
    printed, summary = _run(capsys, str(FRICTION / "pushed_block.toml"), "--out",
                            str(tmp_path / "p"), "--no-figures")
    pair = {"bodies": ["base", "block"], "law": "static_dynamic", "mu_static": 0.3,
            "mu_dynamic": 0.2}
    assert summary["contact_settings"] == {
        "variant": "paired", "method": "vfem",
        "friction": {"law": "static_dynamic", "mu_static": 0.3, "mu_dynamic": 0.2,
                     "pairs": [pair]}}
    line = next(x for x in printed.splitlines() if "work dissipated" in x)
    assert "friction (base/block: static mu = 0.3, dynamic mu = 0.2)" in line, line
    # an example's summary, figures drawn or not: Coulomb's law and its mu
    _, summary = _run(capsys, "cattaneo", *_sets(CATTANEO), "--out", str(tmp_path / "c"),
                      "--no-figures")
    assert summary["contact_settings"]["friction"] == {
        "law": "coulomb", "mu": 0.3,
        "pairs": [{"bodies": ["upper", "lower"], "law": "coulomb", "mu": 0.3}]}
    # frictionless: no friction recorded
    _, summary = _run(capsys, str(ROOT / "examples" / "hertz.toml"), "--out",
                      str(tmp_path / "h"), "--no-figures")
    assert summary["contact_settings"] == {"variant": "paired", "method": "vfem"}


def test_different_laws_in_different_pairs_are_recorded_per_pair():
    from vfem.contact.settings import ContactSettings, PairFriction
    from vfem.io.replot import contact_settings, friction_laws_text
    from vfem.solver import Model

    class Named:
        def __init__(self, name):
            self.name = name

    contact = ContactSettings(friction=0.25, pairs=(
        PairFriction(("a", "b"), 0.2, "static_dynamic", static_friction=0.4),
        PairFriction(("b", "c"), 0.3, "elastoplastic", slip_stiffness=1e4)))
    model = Model("three", [Named("a"), Named("b"), Named("c")], contact=contact)
    settings = contact_settings(model)
    assert settings["friction"]["law"] == "per pair"
    assert [p["law"] for p in settings["friction"]["pairs"]] == [
        "static_dynamic", "coulomb", "elastoplastic"]  # a/b, a/c (contact.friction), b/c
    assert friction_laws_text(settings) == (
        "a/b: static mu = 0.4, dynamic mu = 0.2; a/c: Coulomb, mu = 0.25; b/c: "
        "elasto-plastic, mu = 0.3, slip stiffness 10000")


# -- friction.png: the Coulomb limit beside the traction -----------------------------------------

@pytest.fixture
def lines(monkeypatch):
    """Per figure saved: its lines by label ("_" labels: the lines the legend does not name,
    under their own key as a list)."""
    import matplotlib.figure

    seen = {}
    save = matplotlib.figure.Figure.savefig

    def record(fig, path, *args, **kw):
        named, other = {}, []
        for ax in fig.axes:
            for line in ax.get_lines():
                if line.get_label().startswith("_"):
                    other.append(line)
                else:
                    named[line.get_label()] = line
        seen[Path(path).name] = {**named, "_": other}
        return save(fig, path, *args, **kw)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", record)
    return seen


@pytest.mark.parametrize("model, body, bounds", [
    ("patch_stick", "upper", {"upper: ±mu q = 0.3 q, Coulomb limit": 0.3}),
    ("pushed_block", "block", {"block: ±mu_s q = 0.3 q, stick limit": 0.3,
                               "block: ±mu_d q = 0.2 q, slip": 0.2})])
@pytest.mark.slow
def test_friction_png_draws_the_coulomb_limit_beside_the_traction(model, body, bounds, tmp_path,
                                                                 lines):
    """friction.png: the lines +mu q and -mu q, q the normal traction at the nodes in contact
    (both coefficients of the static/dynamic law), so a reader sees a slipping node on its
    limit and a sticking one within it; a redraw from the folder draws the same."""
    import meshio
    import numpy as np

    assert main(["-q", "run", str(FRICTION / f"{model}.toml"), "--out", str(tmp_path)]) == 0
    last = sorted(tmp_path.glob(f"{body}_step*.vtu"))[-1]
    fields = meshio.read(last).point_data
    status = np.asarray(fields["friction_status"]).ravel()
    on = status > 0
    q = np.asarray(fields["contact_traction"]).ravel()[on]
    shear = np.hypot(*np.asarray(fields["contact_shear"])[on, :2].T)
    drawn = lines["friction.png"]
    for label, mu in bounds.items():
        upper = np.sort(drawn[label].get_ydata())
        assert upper == pytest.approx(np.sort(mu * q), rel=1e-12), label
        assert any(np.allclose(np.sort(line.get_ydata()), np.sort(-mu * q), rtol=1e-12)
                   for line in drawn["_"]), f"-{label}"
    slips, sticks = status[on] == 2, status[on] == 1
    mu = min(bounds.values())  # a slipping node carries the (dynamic) coefficient
    assert shear[slips] == pytest.approx(mu * q[slips], rel=1e-9)
    assert np.all(shear[sticks] <= max(bounds.values()) * q[sticks] * (1 + 1e-9))
    assert (model == "patch_stick") == (sticks.all() and not slips.any())
    assert main(["-q", "plot", str(tmp_path)]) == 0
    assert set(lines["friction.png"]) - {"_"} >= set(bounds)


# -- a resume of another model names what differs ------------------------------------------------

@pytest.mark.slow
def test_a_resume_with_other_settings_names_each_setting_stored_and_now(tmp_path, capsys):
    out = tmp_path / "c"
    assert main(["-q", "run", "cattaneo", *_sets(CATTANEO), "--out", str(out),
                 "--no-figures"]) == 0
    checkpoints = sorted((out / "checkpoint").glob("*.npz"))
    before = [p.read_bytes() for p in checkpoints]
    assert main(["-q", "run", "cattaneo", *_sets(CATTANEO + ["friction=0.2"]), "--resume",
                 str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"vfem: error: {out}: its results were written by a different model "
                          "(contact.friction: stored 0.3, now 0.2); give the same model")
    assert err.count("\n") == 1 and "Traceback" not in err
    assert [p.read_bytes() for p in checkpoints] == before  # nothing changed
    # several settings: each named, the meshes made from them after the settings themselves
    assert main(["-q", "run", "cattaneo", *_sets(CATTANEO + ["facets_upper=8", "force=250"]),
                 "--resume", str(out)]) == 2
    err = capsys.readouterr().err
    assert "bodies.upper.platen.force: stored -300.0, now -250.0; " in err
    assert err.index("platen.force") < err.index("bodies.upper.mesh: stored ")
    assert err.count("\n") == 1


def test_the_differences_are_named_briefly():
    from vfem.io.checkpoint import differences

    stored = {f"k{i}": str(i) for i in range(6)} | {"long": "x" * 100}
    now = {f"k{i}": str(i + 1) for i in range(6)} | {"long": "y" * 100, "new": "1"}
    text = differences(stored, now)
    assert text.startswith("k0: stored 0, now 1; k1: stored 1, now 2; ")
    assert text.endswith("; and 4 more")  # k4, k5, long, new
    assert differences({"a": "1"}, {"a": "1"}) == ""
    assert differences({"a": "1"}, {}) == "a: stored 1, now (none)"
    text = differences({"long": "x" * 100}, {"long": "y" * 100})
    assert "x" * 57 + "..." in text and "x" * 58 not in text


# -- vfem plot on an unfinished example run ------------------------------------------------------

@pytest.mark.slow
def test_plotting_an_unfinished_example_run_says_why_its_own_figures_are_not_drawn(
        tmp_path, capsys, monkeypatch):
    """A sliding run interrupted after step 3: ``vfem plot`` says in one line which example,
    how far it came and why its own figures (reactions.png, ...: the evaluation of the
    finished run) are not drawn, draws the generic figures of the steps done, and names the
    command that finishes it; once resumed, its own figures and no such line."""
    from vfem import cli

    out = tmp_path / "s"
    sets = _sets(SLIDING + ["friction=0.3"])
    progress = cli.Progress.__call__

    def stop_after_3(self, step):
        progress(self, step)
        if step.step == 3:
            raise KeyboardInterrupt

    monkeypatch.setattr(cli.Progress, "__call__", stop_after_3)
    assert main(["-q", "run", "sliding", *sets, "--out", str(out)]) == 130
    monkeypatch.setattr(cli.Progress, "__call__", progress)
    capsys.readouterr()
    assert main(["plot", str(out)]) == 0
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1, captured.err
    assert captured.err.startswith(
        f"vfem: {out}: an unfinished run of the sliding example (3 steps done: interrupted, or "
        "still running); its own figures need the finished run's evaluation, so the generic "
        "figures of the steps done are drawn instead; to finish it: vfem run sliding "
        "--set block_columns=60")
    assert captured.err.rstrip().endswith(f"--set friction=0.3 --resume {out}")
    assert {"history.png", "friction.png"} <= {p.name for p in out.glob("*.png")}
    assert "reactions.png" not in captured.out
    # the command it names finishes the run: the example's own figures, and no such line
    assert main(["-q", "run", "sliding", *sets, "--resume", str(out)]) == 0
    assert main(["plot", str(out)]) == 0
    captured = capsys.readouterr()
    assert captured.err == "" and "reactions.png" in captured.out
    # an input file's unfinished run gets the generic figures, which are its own: no line
    stopped = tmp_path / "p"
    monkeypatch.setattr(cli.Progress, "__call__", stop_after_3)
    assert main(["-q", "run", str(FRICTION / "pushed_block.toml"), "--out", str(stopped)]) == 130
    capsys.readouterr()
    assert main(["plot", str(stopped)]) == 0
    assert capsys.readouterr().err == ""
