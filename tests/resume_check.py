"""A run stopped after a step and resumed from its checkpoint must end with every number of the
uninterrupted run: the shared check of the friction tests (2D, large kinematics, 3D) and of
the compatibility side's switch (``test_side_switch.py``)."""

from __future__ import annotations

import numpy as np
import pytest


class Stop(Exception):
    """Raised from ``on_step`` to stop a run after a step, as a kill would."""


def assert_resumed_equals_whole(config, tmp_path, stop_after: int, whole=None):
    """Run ``config`` into ``tmp_path / "whole"`` (unless ``whole``, its summary, is given), then
    into ``tmp_path / "resumed"`` stopped after step ``stop_after`` and resumed: every step's
    contact forces and frictional work equal, ``contact.csv`` the same bytes. Returns the
    resumed run's summary."""
    from vfem.io import runner

    if whole is None:
        whole = runner.run(config, tmp_path / "whole", figures=False)

    def stop(step):
        if step.step == stop_after:
            raise Stop

    with pytest.raises(Stop):
        runner.run(config, tmp_path / "resumed", figures=False, on_step=stop)
    resumed = runner.run(config, tmp_path / "resumed", figures=False, resume=True)
    assert len(resumed["steps"]) == len(whole["steps"])
    for a, b in zip(whole["steps"], resumed["steps"], strict=True):
        for name in a["contact_force"]:
            np.testing.assert_array_equal(a["contact_force"][name], b["contact_force"][name])
        assert a.get("frictional_work") == b.get("frictional_work")  # (with friction)
    assert (tmp_path / "resumed" / "contact.csv").read_text() == \
        (tmp_path / "whole" / "contact.csv").read_text()
    return resumed
