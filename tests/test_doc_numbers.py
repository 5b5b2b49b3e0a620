"""The numbers in the README and docs that runs write (docs/doc_numbers.py): a stale block fails.

The quick blocks run here; the long ones (a refinement study of minutes) with ``-m slow``.
Regenerate with ``python3 docs/doc_numbers.py --write NAME``.
"""

import importlib.util
from pathlib import Path

import pytest

spec = importlib.util.spec_from_file_location(
    "doc_numbers", Path(__file__).parent.parent / "docs" / "doc_numbers.py")
numbers = importlib.util.module_from_spec(spec)
spec.loader.exec_module(numbers)


@pytest.mark.parametrize("name", [pytest.param(n, marks=() if quick else pytest.mark.slow)
                                  for n, (_, _, quick) in numbers.BLOCKS.items()])
def test_the_block_is_what_a_fresh_run_writes(name):
    assert numbers.current(name).strip(), f"block {name} is empty"
    diff = numbers.stale(name)
    assert not diff, f"stale: python3 docs/doc_numbers.py --write {name}\n{diff}"


def test_the_comparison_masks_only_times_and_round_off():
    a = "converged in 5 steps, 23 contact iterations, 1950 dofs, 0.5 s  penetration 4.2e-14"
    assert numbers.normalised(a) == numbers.normalised(a.replace("0.5 s", "12.25 s")
                                                       .replace("4.2e-14", "1.0e-19"))
    assert numbers.normalised(a) == numbers.normalised(a.replace("4.2e-14", "0.0e+00"))
    assert numbers.normalised(a) != numbers.normalised(a.replace("4.2e-14", "1.0e+00"))
    for changed in (a.replace("23 contact", "24 contact"), a.replace("1950", "1951"),
                    a.replace("4.2e-14", "4.2e-11")):
        assert numbers.normalised(a) != numbers.normalised(changed)
