"""How right a built-in example is: its ``verification`` list (issue 39).

Every built-in example compares what it computed with a reference it did not compute: a closed
form (Hertz, Lamé, Boussinesq, Cattaneo–Mindlin), the thesis's figure, an exact property of the
problem (a uniform pressure, forces equal and opposite, the applied load), or a converged model.
Each comparison is one record of ``summary.json``'s ``verification`` list::

    {"quantity": "peak pressure p_max", "value": 31879.1, "reference": 31848.0,
     "source": "Hertz's closed form (Johnson, Contact Mechanics, eq. 4.45)",
     "measure": "relative", "error": 0.00098, "tolerance": 0.01,
     "basis": "discretisation: ...", "passed": true}

``measure`` says how ``error`` is read: ``relative`` (|value - reference| / |reference|),
``absolute`` (|value - reference|, in the quantity's unit), or ``scaled`` (|value - reference|
over the ``scale`` the record names, e.g. the largest force). ``basis`` says where the tolerance
comes from: the discretisation error at the example's default mesh (its refinement study in
``docs/examples.md``), or round-off for what holds exactly. A tolerance is never fitted to one
run; it is what the error analysis allows, so a record that fails says the answer is wrong or the
mesh too coarse for the reference, and the closing screen and ``vfem verify`` say which.
"""

from __future__ import annotations

import math

MEASURES = ("relative", "absolute", "scaled")


def check(quantity: str, value: float, reference: float, source: str, tolerance: float,
          basis: str, measure: str = "relative", scale: float | None = None) -> dict:
    """One verified quantity: ``value`` against ``reference`` (from ``source``), passed when its
    error by ``measure`` is at most ``tolerance`` (whose ``basis`` the record states)."""
    if measure not in MEASURES:
        raise ValueError(f"{quantity}: unknown measure {measure!r}; the measures are "
                         f"{', '.join(MEASURES)}")
    value, reference = float(value), float(reference)
    difference = abs(value - reference)
    if measure == "relative":
        error = difference / abs(reference) if reference else math.inf
    elif measure == "scaled":
        if not scale or scale <= 0:
            raise ValueError(f"{quantity}: a scaled error needs a positive scale")
        error = difference / float(scale)
    else:
        error = difference
    record = {"quantity": quantity, "value": value, "reference": reference, "source": source,
              "measure": measure, "error": float(error), "tolerance": float(tolerance),
              "basis": basis, "passed": bool(error <= tolerance)}
    if measure == "scaled":
        record["scale"] = float(scale)
    return record


def passed(records: list[dict]) -> bool:
    """Whether every record passed (and there is at least one)."""
    return bool(records) and all(r["passed"] for r in records)


def _amount(x: float, relative: bool) -> str:
    """An error or a tolerance: a percentage where it reads as one, else in powers of ten."""
    if relative and x >= 1e-4:
        return f"{100 * x:.3g} %"
    return f"{x:.1e}"


def lines(records: list[dict]) -> list[str]:
    """The closing screen's verification: one line per record (quantity, value, reference,
    error and tolerance, and the reference's source), then how many passed."""
    if not records:
        return []
    out = ["  verification, against references the run did not compute (summary.json's "
           "verification says where each tolerance comes from):"]
    width = max(len(r["quantity"]) for r in records)
    for r in records:
        rel = r["measure"] == "relative"
        mark = "passed" if r["passed"] else "FAILED"
        out.append(f"    {mark}  {r['quantity']:<{width}}  {r['value']:.6g} against "
                   f"{r['reference']:.6g} ({r['source']}): error {_amount(r['error'], rel)}, "
                   f"allowed {_amount(r['tolerance'], rel)}")
    failed = sum(not r["passed"] for r in records)
    out.append(f"    {len(records) - failed} of {len(records)} passed"
               + (f"; {failed} FAILED" if failed else ""))
    return out


def table(rows: list[tuple[str, dict]]) -> list[str]:
    """``vfem verify``'s table: (example, record) rows, aligned."""
    head = ("example", "quantity", "value", "reference", "error", "tolerance", "")
    body = []
    for name, r in rows:
        rel = r["measure"] == "relative"
        body.append((name, r["quantity"], f"{r['value']:.6g}", f"{r['reference']:.6g}",
                     _amount(r["error"], rel), _amount(r["tolerance"], rel),
                     "passed" if r["passed"] else "FAILED"))
    widths = [max(len(x[i]) for x in (head, *body)) for i in range(len(head))]
    fmt = lambda x: "  ".join(  # noqa: E731
        c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(x, widths)))
    return [fmt(head).rstrip(), *(fmt(x) for x in body)]
