"""The thread policy (vfem.threads): one place sizes the pools; --threads and VFEM_THREADS are
checked like any input."""

import json
import subprocess
import sys

import pytest

from vfem import threads
from vfem.cli import main
from vfem.errors import InputError


def test_the_requested_count_is_checked(monkeypatch):
    monkeypatch.delenv("VFEM_THREADS", raising=False)
    assert threads.requested(None) == threads.default_threads() >= 1
    assert threads.requested("3") == 3 and threads.requested(2) == 2
    assert threads.requested("off") is None and threads.requested("OFF") is None
    for bad in ("0", "-1", "x", "1.5", " "):
        with pytest.raises(InputError, match="--threads must be a whole number"):
            threads.requested(bad)
    monkeypatch.setenv("VFEM_THREADS", "none")
    with pytest.raises(InputError, match="VFEM_THREADS must be a whole number"):
        threads.requested(None)
    monkeypatch.setenv("VFEM_THREADS", "1")
    assert threads.requested(None) == 1


def test_the_policy_puts_the_dense_blas_on_one_thread():
    code = "import json, numpy, vfem.threads as t; t.apply(2); print(json.dumps(t.info()))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    blas = [p["threads"] for p in json.loads(out) if p["library"] == "openblas"]
    assert blas and all(n == 1 for n in blas)


def test_the_command_line_refuses_a_bad_count_and_accepts_off(capsys, tmp_path):
    assert main(["--threads", "0", "run", "springs", "--out", str(tmp_path / "a")]) == 2
    assert "--threads must be a whole number of threads >= 1" in capsys.readouterr().err
    assert main(["-q", "--threads", "off", "run", "springs", "--out", str(tmp_path / "b")]) == 0
    assert main(["-q", "--threads", "1", "run", "springs", "--out", str(tmp_path / "c")]) == 0
