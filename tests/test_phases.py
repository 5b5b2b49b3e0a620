"""The phase table of a run (issue 19, item 1): summary.json says where the time went."""

import json

import pytest

from vfem.cli import main
from vfem.result_types import PHASES, phase_table


def test_the_phases_add_up_to_the_run():
    timings = {"build_s": 0.5, "search_s": 0.1, "assemble_s": 1.0, "factorize_s": 2.0,
               "flexibility_s": 0.5, "contact_s": 0.25, "fields_s": 0.25, "output_s": 1.0,
               "figures_s": 3.0, "run_s": 10.0}
    table = phase_table(timings)
    assert table["factorization and condensation"] == 2.5
    assert "invariants" not in table  # a phase the run did not time is not listed
    assert sum(table.values()) == pytest.approx(10.0)
    assert table["other"] == pytest.approx(1.4)
    assert list(table)[:-1] == [label for label, keys in PHASES
                                if any(k in timings for k in keys)]


@pytest.mark.slow
def test_a_run_writes_its_phases(tmp_path):
    assert main(["-q", "run", "hertz", "--out", str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    phases = summary["phases"]
    for label in ("assembly", "factorization and condensation", "contact iterations",
                  "output: VTU, CSV, checkpoints", "figures"):
        assert phases[label] > 0, label
    assert all(v >= 0 for v in phases.values())
    assert phases["figures"] == pytest.approx(summary["timings"]["figures_s"])
