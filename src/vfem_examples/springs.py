"""Thesis §4.2.1: two nonlinear springs pressed end to end — the 1D analogy, solved exactly.

Spring A (10 in, left end at 0, K = 1000(1 + 10c) lb/in) is pushed to the right in 0.5 in steps
against spring B (10 in, right end fixed at 22 in, K = 2000(1 + 20c^2) lb/in); c is the fractional
compression and K a secant stiffness. Contact begins after 2 in; steps 5 and 6 need the contact
iterations. The exact answers (solve F_A = F_B) are 12.196 in / 395.8 lb after step 5 and
12.431 in / 893.4 lb after step 6; the thesis's trace of step 5 starts with a 333 lb compatibility
force and a 109 lb equilibrium error.
"""

from __future__ import annotations

import logging
import time
from dataclasses import asdict, dataclass

from vfem.contact.formulations import SecantSpring, Step1D, solve_step

log = logging.getLogger(__name__)

#: The springs' stiffening (thesis eqs. 4.3.1 and 4.3.2): K_A = k_A (1 + 10 c) and
#: K_B = k_B (1 + 20 c^2), c the fractional compression
STIFFENING_A = 10.0
STIFFENING_B = 20.0
#: The thesis's answer after the last step (§4.2.1): the springs meet at 12.431 in (distances to
#: the nearest 0.001 in) with a contact force of "893 ± 1 lb"
THESIS_LAST_STEP = {"contact point": (12.431, 0.0005), "contact force": (893.0, 1.0)}


@dataclass(frozen=True)
class SpringsParameters:
    """Parameters of the 1D example (the thesis's values are the defaults)."""

    length_a: float = 10.0
    length_b: float = 10.0
    gap: float = 2.0
    stiffness_a: float = 1000.0
    stiffness_b: float = 2000.0
    step_size: float = 0.5
    steps: int = 6
    penetration_tolerance: float = 1e-6
    equilibrium_tolerance: float = 1e-3


Parameters = SpringsParameters


def run(params: SpringsParameters | None = None, out=None, on_step=None) -> dict:
    """Run the example; returns the ``summary.json`` dictionary with the iteration traces.

    With ``out``, the summary is also written to ``out/summary.json``.
    """
    p = params or SpringsParameters()
    start = time.perf_counter()
    a = SecantSpring(length=p.length_a, k0=p.stiffness_a, a=STIFFENING_A)
    b = SecantSpring(length=p.length_b, k0=p.stiffness_b, b=STIFFENING_B)
    left_a = 0.0  # prescribed displacement of A's left end
    da = db = 0.0  # compressions of A and B (their contact ends move into the bodies)
    b_left = p.length_a + p.gap
    steps: list[Step1D] = []
    for k in range(1, p.steps + 1):
        # Linear prediction: the increment is applied with the contact forces held, so each
        # spring keeps its compression and A's right end moves with its left end.
        left_a += p.step_size
        penetration = (p.length_a + left_a - da) - (b_left + db)
        da, db, history, ok = solve_step(
            a, b, da, db, penetration,
            penetration_tolerance=p.penetration_tolerance,
            equilibrium_tolerance=p.equilibrium_tolerance,
        )
        gap = (b_left + db) - (p.length_a + left_a - da)
        steps.append(Step1D(step=k, position=b_left + db if gap <= p.penetration_tolerance
                            else None, contact_force=a.reaction(da), converged=ok,
                            iterations=history, gap=max(gap, 0.0)))
        log.info("springs step %d: contact at %s in, force %.2f lb, %d iterations",
                 k, steps[-1].position, steps[-1].contact_force, len(history))
    summary = {
        "example": "springs",
        "converged": all(s.converged for s in steps),
        "steps": [{"step": s.step, "load_factor": s.step / p.steps,
                   "iterations": len(s.iterations), "converged": s.converged} for s in steps],
        "contact_point": [s.position for s in steps],  # None while the springs are apart
        "gap": [s.gap for s in steps],
        "contact_force": [s.contact_force for s in steps],
        "stiffness_a": a.stiffness(da),
        "stiffness_b": b.stiffness(db),
        "trace": [[asdict(it) for it in s.iterations] for s in steps],
        "parameters": asdict(p),
        "timings": {"total_s": time.perf_counter() - start},
    }
    if summary["converged"]:
        summary["verification"] = verification(summary, p)
    if out is not None:
        from vfem.io.results import write_summary

        write_summary(out, summary)
    return summary


def exact(p: SpringsParameters, step: int) -> tuple[float, float, float, float] | None:
    """The exact state after ``step``, solved directly from F_A = F_B (not by the contact
    iteration): (contact point, contact force, A's and B's tangent stiffness there); None while
    the springs are apart.

    A's end has moved ``step`` x ``step_size``, so the compressions share the overlap
    s = step x step_size - gap: d_A + d_B = s, with k_A (1 + 10 d_A / L_A) d_A =
    k_B (1 + 20 (d_B / L_B)^2) d_B. Both forces grow with their compression, so the difference
    falls strictly from F_A(s) > 0 at d_B = 0 to -F_B(s) < 0 at d_B = s: one root, found by
    bisection to the last bit.
    """
    s = step * p.step_size - p.gap
    if s <= 0.0:
        return None

    def force_a(d: float) -> float:
        return p.stiffness_a * (1.0 + STIFFENING_A * d / p.length_a) * d

    def force_b(d: float) -> float:
        return p.stiffness_b * (1.0 + STIFFENING_B * (d / p.length_b) ** 2) * d

    lo, hi = 0.0, s
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if force_a(s - mid) > force_b(mid) else (lo, mid)
    db = 0.5 * (lo + hi)
    da = s - db
    tangent_a = p.stiffness_a * (1.0 + 2.0 * STIFFENING_A * da / p.length_a)
    tangent_b = p.stiffness_b * (1.0 + 3.0 * STIFFENING_B * (db / p.length_b) ** 2)
    return p.length_a + p.gap + db, force_b(db), tangent_a, tangent_b


def verification(s: dict, p: SpringsParameters) -> list[dict]:
    """The checks of a converged run (``summary.json``'s ``verification``;
    :mod:`vfem.io.verification`): where the springs meet and the force between them after the
    last two steps in contact, against the exact state (:func:`exact`), and after the last step
    against the thesis's numbers (§4.2.1) when the model is the thesis's.

    The tolerances are what the iteration's stopping test allows: it stops with the penetration
    P within ``penetration_tolerance`` and the equilibrium error E = F_A - F_B within
    ``equilibrium_tolerance`` (lb). To first order about the exact state (tangent stiffnesses
    k_A, k_B) that moves B's end, the contact point, by (k_A P + E) / (k_A + k_B) and the force
    by k_A (k_B P + E) / (k_A + k_B). Against the thesis, its rounding is added: distances to
    0.001 in, the force "± 1 lb".
    """
    from vfem.io.verification import check

    records = []
    contact = [k for k in range(1, p.steps + 1) if exact(p, k) is not None]
    pt, et = p.penetration_tolerance, p.equilibrium_tolerance
    basis = (f"the contact iteration's stopping test (penetration_tolerance {pt:g} in, "
             f"equilibrium_tolerance {et:g} lb), to first order through the springs' tangent "
             "stiffnesses")
    # a step the run left apart has no contact point (None): no record of it, only of its
    # force (the springs' reaction, which then fails against the exact state's)
    point = s["contact_point"]
    force = s["contact_force"]
    tolerance = {}
    for k in contact[-2:]:
        x, f, ka, kb = exact(p, k)
        tolerance[k] = (ka * pt + et) / (ka + kb), ka * (kb * pt + et) / (ka + kb)
        if point[k - 1] is not None:
            records.append(check(f"step {k}: contact point (in)", point[k - 1], x,
                                 "exact, F_A = F_B", tolerance[k][0], basis, measure="absolute"))
        records.append(check(f"step {k}: contact force (lb)", force[k - 1], f,
                             "exact, F_A = F_B", tolerance[k][1], basis, measure="absolute"))
    thesis = SpringsParameters()
    if contact and all(getattr(p, name) == getattr(thesis, name) for name in (
            "length_a", "length_b", "gap", "stiffness_a", "stiffness_b", "step_size", "steps")):
        k = contact[-1]
        (x, dx), (f, df) = THESIS_LAST_STEP["contact point"], THESIS_LAST_STEP["contact force"]
        also = " and the contact iteration's stopping test, as against the exact state"
        if point[k - 1] is not None:
            records.append(check(f"step {k}: contact point (in), thesis", point[k - 1], x,
                                 "thesis §4.2.1", dx + tolerance[k][0],
                                 "the thesis's rounding to 0.001 in" + also, measure="absolute"))
        records.append(check(f"step {k}: contact force (lb), thesis", force[k - 1], f,
                             "thesis §4.2.1", df + tolerance[k][1],
                             "the thesis's '± 1 lb'" + also, measure="absolute"))
    return records


def report(s: dict) -> list[str]:
    """The iteration trace of every step, in the thesis's terms."""
    lines = ["vfem: springs — thesis §4.2.1, two nonlinear springs pressed end to end"]
    for step, trace, x, f, gap in zip(s["steps"], s["trace"], s["contact_point"],
                                      s["contact_force"], s["gap"]):
        if x is None:
            lines.append(f"step {step['step']}: no contact, gap {gap:.4f} in")
            continue
        lines.append(f"step {step['step']}: contact point {x:.4f} in, contact force {f:.2f} lb, "
                     f"{step['iterations']} iterations")
        for k, it in enumerate(trace, 1):
            lines.append(
                f"    iteration {k}: penetration {it['penetration']:+.4f} in, "
                f"compatibility force {it['compatibility_force']:7.2f} lb, "
                f"equilibrium error {it['equilibrium_error']:+8.2f} lb "
                f"(A needs {it['reaction_a']:.1f}, B gives {it['reaction_b']:.1f}), "
                f"equilibrium corrections A {it['equilibrium_force_a']:+.2f} lb, "
                f"B {it['equilibrium_force_b']:+.2f} lb")
    return lines
