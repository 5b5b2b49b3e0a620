"""A run stopped after a step and resumed from its checkpoint must end with every number of the
uninterrupted run: the shared check of the friction tests (2D, large kinematics, 3D) and of
the compatibility side's switch (``test_side_switch.py``)."""

from __future__ import annotations

import numpy as np
import pytest


class Stop(Exception):
    """Raised from ``on_step`` to stop a run after a step, as a kill would."""


def assert_resumed_equals_whole(config, tmp_path, stop_after: int, whole=None,
                                before_resume=None, folder: str = "resumed"):
    """Run ``config`` into ``tmp_path / "whole"`` (unless ``whole``, its summary, is given), then
    into ``tmp_path / folder`` stopped after step ``stop_after`` and resumed (``before_resume``
    given that folder first, to change its checkpoints as an older version wrote them): every
    step's contact forces and frictional work equal, ``contact.csv`` the same bytes. Returns the
    resumed run's summary."""
    from vfem.io import runner

    if whole is None:
        whole = runner.run(config, tmp_path / "whole", figures=False)

    def stop(step):
        if step.step == stop_after:
            raise Stop

    with pytest.raises(Stop):
        runner.run(config, tmp_path / folder, figures=False, on_step=stop)
    if before_resume is not None:
        before_resume(tmp_path / folder)
    resumed = runner.run(config, tmp_path / folder, figures=False, resume=True)
    assert len(resumed["steps"]) == len(whole["steps"])
    for a, b in zip(whole["steps"], resumed["steps"], strict=True):
        for name in a["contact_force"]:
            np.testing.assert_array_equal(a["contact_force"][name], b["contact_force"][name])
        assert a.get("frictional_work") == b.get("frictional_work")  # (with friction)
    assert (tmp_path / folder / "contact.csv").read_text() == \
        (tmp_path / "whole" / "contact.csv").read_text()
    return resumed


def as_written_before_columns(folder) -> None:
    """Rewrite ``folder``'s checkpoints as vfem wrote them before the tangential arrays were
    (n, ntan) in 2D (2026-11-30): one-column tangential traction values and anchors as (n,), and
    no ``tangential`` mark in the state's record."""
    import json
    from pathlib import Path

    for path in sorted((Path(folder) / "checkpoint").glob("step*.npz")):
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        meta = json.loads(arrays["meta"].tobytes().decode())
        assert meta["state"].pop("tangential") == "columns"
        for key, value in arrays.items():
            if key.startswith(("unknown_shear_", "unknown_anchor_")) and value.ndim == 2 \
                    and value.shape[1] == 1:
                arrays[key] = value[:, 0]
        arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
        np.savez(path, **arrays)
