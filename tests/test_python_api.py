"""docs/python-api.md: every Python block runs as written (from the repository root)."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "python-api.md").read_text(
    encoding="utf-8"), re.S)


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_python_api_doc_block_runs(index, monkeypatch, capsys):
    monkeypatch.chdir(ROOT)
    exec(compile(BLOCKS[index], f"docs/python-api.md block {index + 1}", "exec"), {})
    assert capsys.readouterr().out  # each block shows its result


def test_the_doc_has_its_examples():
    assert len(BLOCKS) >= 4
