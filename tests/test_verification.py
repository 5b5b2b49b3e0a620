"""The examples' verification records (vfem.io.verification) and ``vfem verify`` (issue 39)."""

from __future__ import annotations

import json
import math

import pytest

from vfem.cli import main
from vfem.contact.invariants.measures import FORCE_BALANCE_TOLERANCE
from vfem.contact.settings import ContactSettings
from vfem.io.verification import balance, check, enforces_balance, lines, passed, platen, table


def test_a_record_reads_its_error_by_its_measure():
    r = check("p", 101.0, 100.0, "closed form", 0.02, "discretisation")
    assert r["error"] == pytest.approx(0.01, rel=1e-12) and r["passed"]
    r = check("p", 103.0, 100.0, "closed form", 0.02, "discretisation")
    assert not r["passed"]
    r = check("gap", 1e-3, 0.0, "exact", 2e-3, "one facet", measure="absolute")
    assert r["error"] == 1e-3 and r["passed"]
    r = check("force", 10.5, 10.0, "applied", 0.01, "round-off", measure="scaled", scale=100.0)
    assert r["error"] == pytest.approx(0.005, rel=1e-12) and r["passed"] and r["scale"] == 100
    with pytest.raises(ValueError):
        check("x", 1.0, 1.0, "s", 1.0, "b", measure="scaled")
    with pytest.raises(ValueError):
        check("x", 1.0, 1.0, "s", 1.0, "b", measure="percent")


def test_a_record_holds_finite_numbers_only():
    """summary.json is strict JSON: no relative error against zero (it would be inf), no NaN
    or inf value, reference, tolerance or scale; each refusal names the quantity."""
    with pytest.raises(ValueError, match="^x: a relative error against a zero reference"):
        check("x", 1.0, 0.0, "zero", 1.0, "b")
    assert check("x", 1e-3, 0.0, "zero", 1e-2, "b", measure="absolute")["passed"]
    for bad in (math.nan, math.inf, -math.inf):
        for args in ((bad, 1.0, 1.0), (1.0, bad, 1.0), (1.0, 1.0, bad)):
            value, reference, tolerance = args
            with pytest.raises(ValueError, match="^point: the .* is not finite"):
                check("point", value, reference, "s", tolerance, "b", measure="absolute")
        with pytest.raises(ValueError, match="^f: a scaled error needs a positive scale"):
            check("f", 1.0, 1.0, "s", 1.0, "b", measure="scaled", scale=bad)
    record = check("f", 1.0, 1.0 + 1e-12, "s", 1e-9, "b", measure="scaled", scale=2.0)
    assert json.loads(json.dumps(record, allow_nan=False)) == record


def test_the_shared_checks_state_their_basis():
    """balance: invariant (a)'s tolerance, scaled by the larger force by default; platen: the
    model's own contact.platen_tolerance."""
    r = balance("flat", 3060.0 * (1 + 2e-9), 3060.0, "the cylinder's")
    assert r["passed"] and r["tolerance"] == FORCE_BALANCE_TOLERANCE and r["measure"] == "scaled"
    assert r["scale"] == pytest.approx(3060.0 * (1 + 2e-9), rel=1e-15)
    assert "invariant (a)" in r["basis"] and "FORCE_BALANCE_TOLERANCE" in r["basis"]
    assert not balance("flat", 3060.0 * (1 + 2e-8), 3060.0, "the cylinder's")["passed"]
    r = balance("sum", 1e-9, 0.0, "equal and opposite", scale=10.0, interface=True)
    assert r["passed"] and r["error"] == pytest.approx(1e-10) and "interface" in r["basis"]
    tight = ContactSettings(platen_tolerance=1e-7)
    r = platen("force", 1530.0 * (1 + 5e-7), 1530.0, tight)
    assert r["tolerance"] == 1e-7 and not r["passed"] and "1e-07" in r["basis"]
    assert platen("force", 1530.0 * (1 + 5e-7), 1530.0, ContactSettings())["passed"]
    assert enforces_balance(ContactSettings()) and enforces_balance(ContactSettings(friction=0.3))
    assert not enforces_balance(ContactSettings(variant="thesis"))
    assert not enforces_balance(ContactSettings(method="lagrange"))


def test_the_screen_and_the_table_say_which_failed():
    good = check("p_max", 1.001, 1.0, "Hertz", 0.005, "discretisation")
    bad = check("half-width", 1.2, 1.0, "Hertz", 0.05, "one facet")
    text = "\n".join(lines([good, bad]))
    assert "passed  p_max" in text and "FAILED  half-width" in text and "1 of 2 passed" in text
    assert "0.1 %" in text and "20 %" in text  # errors as percentages where relative
    rows = table([("hertz", good), ("hertz", bad)])
    assert len(rows) == 3 and rows[2].endswith("FAILED")
    assert passed([good]) and not passed([good, bad]) and not passed([])
    assert lines([]) == []


def test_vfem_verify_runs_the_examples_and_fails_on_a_missing_record(tmp_path, capsys):
    status = main(["verify", "hertz", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    report = json.loads((tmp_path / "verify.json").read_text())
    records = report["examples"]["hertz"]["verification"]
    assert status == 0 and report["passed"] and len(records) >= 4
    assert all(r["passed"] for r in records) and "checks passed" in out
    assert (tmp_path / "hertz" / "summary.json").is_file()
    assert main(["verify", "nonesuch"]) == 2
