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

Two checks every example with two bodies in contact shares, each with its tolerance's basis
written once: :func:`balance` (the two sides' contact forces equal and opposite: invariant (a))
and :func:`platen` (a force-controlled platen's force met: ``contact.platen_tolerance``).

A record holds finite numbers only (``summary.json`` is strict JSON): :func:`check` refuses a
value, reference, tolerance or scale that is not finite, and a relative error against a zero
reference.
"""

from __future__ import annotations

import math

MEASURES = ("relative", "absolute", "scaled")


def check(quantity: str, value: float, reference: float, source: str, tolerance: float,
          basis: str, measure: str = "relative", scale: float | None = None) -> dict:
    """One verified quantity: ``value`` against ``reference`` (from ``source``), passed when its
    error by ``measure`` is at most ``tolerance`` (whose ``basis`` the record states).

    Raises ValueError for an unknown measure, a scaled measure without a positive scale, a
    relative measure against a zero reference (no relative error exists: compare absolutely or
    scaled), or a value, reference, tolerance or scale that is not finite (a record holds
    numbers ``summary.json`` can write as strict JSON: an example with nothing to read records
    nothing)."""
    if measure not in MEASURES:
        raise ValueError(f"{quantity}: unknown measure {measure!r}; the measures are "
                         f"{', '.join(MEASURES)}")
    value, reference, tolerance = float(value), float(reference), float(tolerance)
    for name, x in (("value", value), ("reference", reference), ("tolerance", tolerance)):
        if not math.isfinite(x):
            raise ValueError(f"{quantity}: the {name} is not finite ({x}); a verification "
                             "record holds finite numbers only")
    difference = abs(value - reference)
    if measure == "relative":
        if reference == 0.0:
            raise ValueError(f"{quantity}: a relative error against a zero reference; "
                             "compare it absolutely or scaled")
        error = difference / abs(reference)
    elif measure == "scaled":
        if scale is None or not math.isfinite(float(scale)) or float(scale) <= 0:
            raise ValueError(f"{quantity}: a scaled error needs a positive scale")
        error = difference / float(scale)
    else:
        error = difference
    record = {"quantity": quantity, "value": value, "reference": reference, "source": source,
              "measure": measure, "error": float(error), "tolerance": tolerance,
              "basis": basis, "passed": bool(error <= tolerance)}
    if measure == "scaled":
        record["scale"] = float(scale)
    return record


def enforces_balance(settings) -> bool:
    """Whether the formulation that ``settings`` (a model's
    :class:`~vfem.contact.settings.ContactSettings`) choose enforces invariant (a) on every
    converged step (the paired variant, small or large kinematics, with or without friction).
    The thesis variant only records its invariants (its forces act along the other body's
    normals: a resultant of 0.5-6 % by design) and a classical baseline's are compared, not
    enforced: for them :func:`balance`'s tolerance has no basis, and the examples leave it out."""
    from vfem.contact.formulations import formulation_class

    return formulation_class(settings, large=False).capabilities.invariants == "enforced"


def balance(quantity: str, value: float, reference: float, source: str,
            scale: float | None = None, interface: bool = False) -> dict:
    """Two sides' contact forces, equal and opposite: ``value`` (one body's total contact
    force, or its component along an axis) against ``reference`` (the other's, negated), or
    the length of their sum against 0. The error is scaled by ``scale``: invariant (a)'s, the
    largest body's total contact force in magnitude (of the modelled part, times what makes it
    the whole where the forces are the whole's); by default the larger of ``|value|`` and
    ``|reference|``, which is that scale where the forces have no other component.

    The tolerance is invariant (a)'s, :data:`vfem.contact.invariants.measures.
    FORCE_BALANCE_TOLERANCE`: every converged step of a formulation that enforces it
    (:func:`enforces_balance`) has every body's contact forces summing to zero within it of the
    largest body's total (:meth:`vfem.contact.invariants.check.InvariantCheck._force_balance`;
    a step that breaks it fails), and the paired variant makes both sides' nodal forces from one
    traction (docs/method.md §6), so what is left is round-off. ``interface``: one contact
    interface of several bodies, where invariant (a) bounds only the sum over all of them; its
    two sides still come from one traction, to round-off, and are allowed the same."""
    from vfem.contact.invariants import Invariants

    tol = Invariants().force_tolerance  # FORCE_BALANCE_TOLERANCE, read through the stage's face
    value, reference = float(value), float(reference)
    scale = max(abs(value), abs(reference)) if scale is None else float(scale)
    if interface:
        basis = (f"round-off: this interface's two sides' nodal forces come from one traction "
                 f"(the paired variant, docs/method.md §6); allowed invariant (a)'s tolerance, "
                 f"{tol:g} of the force (FORCE_BALANCE_TOLERANCE), which the solver enforces "
                 "on the sum over all the bodies at every converged step")
    else:
        basis = (f"invariant (a): every converged step's contact forces sum to zero within "
                 f"{tol:g} of the largest body's total (FORCE_BALANCE_TOLERANCE, enforced by "
                 "the solver; vfem.contact.invariants); both sides' nodal forces come from one "
                 "traction (docs/method.md §6), so what is left is round-off")
    return check(quantity, value, reference, source, tol, basis, measure="scaled", scale=scale)


def platen(quantity: str, value: float, applied: float, settings) -> dict:
    """A force-controlled platen's force met: ``value`` (the contact force on the platen's body
    along the platen, which is the platen's reaction by that body's own equilibrium) against
    ``applied``, relative, to the ``platen_tolerance`` of ``settings``: the
    :class:`~vfem.contact.settings.ContactSettings` the model was built with (a contact solve
    converges only with the platen's reaction that close to its force,
    :meth:`vfem.contact.formulations.group.SurfaceGroup.platen_met`)."""
    tol = float(settings.platen_tolerance)
    return check(quantity, value, applied, "the platen's force", tol,
                 f"a converged contact solve meets the platen's force to the model's "
                 f"contact.platen_tolerance ({tol:g}, relative); the platen's reaction is its "
                 "body's contact force by that body's equilibrium")


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
