"""Step cutting, results that survive interruption, and ``--resume`` (issue 7).

A failed step must leave no trace: the retry starts from exactly the saved converged state. A
run killed after some steps leaves those steps readable, and ``--resume`` continues to the same
answer as a run that was never interrupted.
"""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import meshio
import numpy as np
import pytest

from vfem.contact.state import CycleWatch, SolveResult
from vfem.io import checkpoint
from vfem.io.results import run_writing
from vfem.solver import Analysis
from vfem_examples import gasket, hertz, wedge


def _arrays(cp) -> dict[str, np.ndarray]:
    """Every array of a checkpoint's state, by name (deep copies)."""
    out = {"load_factor": np.array(cp.state.load_factor),
           "platen": np.array(cp.state.platen_displacement)}
    for i, (f, r) in enumerate(zip(cp.state.forces, cp.state.released)):
        out[f"force{i}"], out[f"released{i}"] = f.copy(), r.copy()
    for k, value in cp.state.unknowns().items():
        out[k] = np.array(value, copy=True)
    for name, state in cp.bodies.items():
        for key, v in state.items():
            out[f"{name}.{key}"] = np.array(v, copy=True)
    return out


def _large_gasket():
    p = gasket.Parameters(order=1, n_through=2, n_around=40, back_motion=0.25, steps=3)
    cfg = gasket.config(p)
    bodies = tuple(dataclasses.replace(b, kinematics="updated") for b in cfg.bodies)
    return dataclasses.replace(cfg, bodies=bodies).build()


@pytest.mark.parametrize("make", [lambda: hertz.build(hertz.HertzParameters(steps=3)),
                                  pytest.param(_large_gasket, marks=pytest.mark.slow)],
                         ids=["hertz-linear", "gasket-updated"])
def test_a_failed_step_restarts_from_the_saved_state_exactly(make):
    """Step 2's first attempt iterates (moving forces, traction values and the large bodies'
    trial states), then is made to fail; the retry must see the state saved after step 1, bit
    for bit, and the analysis must still reach the uninterrupted run's answer."""
    analysis = Analysis(make())
    analysis.setup()
    real = analysis.contact.solve
    saved, seen, calls = {}, {}, []

    def solve(state, on_iteration=None):
        calls.append(state.load_factor)
        if len(calls) == 2:  # step 2, first attempt: really iterate, then fail
            res = real(state, on_iteration)
            return SolveResult(False, res.iterations, res.history, res.pairings,
                               "injected failure")
        if len(calls) == 3:  # the retry: what does it start from?
            seen.update(_arrays(dataclasses.replace(analysis.checkpoint(), state=state)))
            seen["load_factor"] = np.array(saved["load_factor"])  # the retry's is the cut one
            for b in analysis.model.bodies:
                if b.large:
                    seen[f"{b.name}.trial"] = b.nonlinear.trial_displacement().copy()
        return real(state, on_iteration)

    def on_step(step):
        if step.step == 1:
            saved.update(_arrays(analysis.checkpoint()))
            for b in analysis.model.bodies:
                if b.large:
                    saved[f"{b.name}.trial"] = b.nonlinear.saved_state()["u"].copy()

    analysis.contact.solve = solve
    result = analysis.run(on_step)
    assert result.converged, result.message
    assert result.steps[1].cuts == 1 and calls[2] < calls[1]  # retried with half the increment
    assert saved.keys() == seen.keys()
    for key in saved:
        assert np.array_equal(saved[key], seen[key]), key
    reference = Analysis(make()).run()  # elastic and frictionless: the path does not matter
    at = {s.load_factor: s for s in result.steps}
    scale = max(np.abs(b.displacement).max() for s in reference.steps for b in s.bodies.values())
    for ref in reference.steps:
        for name, r in ref.bodies.items():
            u = at[ref.load_factor].bodies[name].displacement
            assert np.abs(u - r.displacement).max() <= 1e-6 * scale


def test_cycling_contact_sets_are_noticed():
    """The same set coming back three times with the error not falling is a cycle; a set that
    stays the same while the error falls is convergence."""
    nodes = np.array([10, 11, 12])
    a, b = np.array([1, 1, 0], bool), np.array([1, 0, 1], bool)
    watch = CycleWatch()
    assert all(watch([("block", nodes, a)], 1.0 / (k + 1), k) is None for k in range(20))
    watch = CycleWatch()
    messages = [watch([("block", nodes, m)], 0.5, k) for k, m in enumerate([a, b] * 4)]
    assert messages[:4] == [None] * 4  # a b a b: two returns, not yet a cycle
    assert "nodes 11, 12 of body 'block' keep switching" in messages[4]


@pytest.mark.slow
def test_one_step_runs_converge_to_the_stepped_answers():
    """All the load at once: Hertz converges directly, the wedge through step cutting (its
    tip would cross the plate's surface layer), both to the stepped runs' answers."""
    one = hertz.build(hertz.HertzParameters(steps=1))
    r1 = Analysis(one).run()
    p5 = hertz.HertzParameters(steps=5)
    r5 = Analysis(hertz.build(p5)).run()
    e1, e5 = hertz.evaluate(r1, p5), hertz.evaluate(r5, p5)
    assert r1.converged and abs(e1["p_max"] / e5["p_max"] - 1) < 1e-3
    p = wedge.WedgeParameters(steps=1)
    stepped = wedge.WedgeParameters()
    for case in (1, 3, 5):
        r = Analysis(wedge.build(p, case)).run()
        assert r.converged, r.message
        assert max(s.cuts for s in r.steps) >= 1  # the step had to be cut
        ref = Analysis(wedge.build(stepped, case)).run()
        e, e_ref = (wedge.evaluate(x.model, x.steps, p) for x in (r, ref))
        assert e["plate_share"] == pytest.approx(e_ref["plate_share"], rel=1e-2, abs=1e-4)


@pytest.mark.slow
def test_resume_continues_to_the_same_answer(tmp_path):
    """Checkpoints of the last steps removed (as if the run had stopped after step 2): the
    resumed run rewrites steps 3-5 identically, and a checkpoint of another model is refused."""
    p = hertz.HertzParameters(steps=5)
    full, cut = tmp_path / "full", tmp_path / "cut"
    run_writing(hertz.build(p), full)
    run_writing(hertz.build(p), cut)
    for k in (3, 4, 5):
        (cut / "checkpoint" / f"step{k:04d}.npz").unlink()
        for f in cut.glob(f"*_step{k:04d}.vtu"):
            f.unlink()
    _, resumed = run_writing(hertz.build(p), cut, resume=True)
    assert [s.step for s in resumed.steps] == [1, 2, 3, 4, 5]
    for f in sorted(full.glob("*.vtu")):
        a = meshio.read(f).point_data["displacement"]
        b = meshio.read(cut / f.name).point_data["displacement"]
        assert np.abs(a - b).max() <= 1e-12 * np.abs(a).max(), f.name
    assert (full / "contact.csv").read_text() == (cut / "contact.csv").read_text()
    other = hertz.build(dataclasses.replace(p, force=1000.0))
    with pytest.raises(Exception, match="written by a different model"):
        checkpoint.read(cut, other)


def _steps_on_disk(out: Path) -> tuple[int, dict]:
    """Completed steps whose every VTU file reads back, and the summary (valid JSON)."""
    summary = json.loads((out / "summary.json").read_text())
    n = 0
    while True:
        files = sorted(out.glob(f"*_step{n + 1:04d}.vtu"))
        if len(files) != 2:
            return n, summary
        for f in files:
            assert np.isfinite(meshio.read(f).point_data["displacement"]).all()
        n += 1


@pytest.mark.slow
def test_a_killed_run_keeps_its_steps_and_resumes_to_the_same_answer(tmp_path):
    """SIGKILL in the middle of a run: the steps completed are readable, summary.json is valid
    and lists them, and ``--resume`` reaches the uninterrupted answer to 1e-12."""
    args = ["gasket", "--set", "order=1", "--set", "n_through=2", "--set", "n_around=40",
            "--set", "back_motion=0.5", "--set", "kinematics=updated",
            "--no-figures"]  # the steps and the summary are what this is about
    cli = [sys.executable, "-m", "vfem.cli", "-q", "run"]
    killed, full = tmp_path / "killed", tmp_path / "full"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.Popen([*cli, *args, "--out", str(killed)], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while not (killed / "checkpoint" / "step0003.npz").exists() and time.time() < deadline:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done, summary = _steps_on_disk(killed)
    assert 3 <= done < 20, done  # killed part way
    assert summary["status"] == "running" and len(summary["steps"]) >= done - 1
    assert len(list((killed / "checkpoint").glob("step*.npz"))) in (done, done - 1)
    subprocess.run([*cli, *args, "--resume", str(killed)], env=env, check=True,
                   stdout=subprocess.DEVNULL)
    subprocess.run([*cli, *args, "--out", str(full)], env=env, check=True,
                   stdout=subprocess.DEVNULL)
    # (20 scheduled steps; the first unloading steps of this coarse gasket are cut since the
    # held nodes of large kinematics, issue 41: docs/method.md §10)
    assert _steps_on_disk(killed)[0] == _steps_on_disk(full)[0] >= 20
    for f in sorted(full.glob("*.vtu")):
        a = meshio.read(f).point_data["displacement"]
        b = meshio.read(killed / f.name).point_data["displacement"]
        assert np.abs(a - b).max() <= 1e-12 * max(np.abs(a).max(), 1e-300), f.name
    final = json.loads((killed / "summary.json").read_text())
    reference = json.loads((full / "summary.json").read_text())
    assert final["converged"] and final["largest_force"] == pytest.approx(
        reference["largest_force"], rel=1e-12)


@pytest.mark.slow
def test_resume_mistakes_are_one_message_and_exit_2(tmp_path, capsys):
    from vfem.cli import main

    done = tmp_path / "hertz"
    assert main(["-q", "run", "hertz", "--out", str(done)]) == 0
    cases = [
        (["run", "hertz", "--resume", str(tmp_path / "nothing")], "no checkpoints there"),
        (["run", "hertz", "--resume", str(done), "--out", str(tmp_path / "x")],
         "leave out --out"),
        (["run", "patch", "--resume", str(done)], "cannot be resumed"),
        (["run", "hertz", "--set", "force=1000", "--resume", str(done)],
         "written by a different model"),
    ]
    for args, message in cases:
        assert main(["-q", *args]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1 and "Traceback" not in err
    summary = json.loads((done / "summary.json").read_text())
    assert main(["-q", "run", "hertz", "--resume", str(done)]) == 0  # nothing left: same summary
    assert json.loads((done / "summary.json").read_text())["hertz"] == summary["hertz"]
