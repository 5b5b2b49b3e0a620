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
    a = SecantSpring(length=p.length_a, k0=p.stiffness_a, a=10.0)
    b = SecantSpring(length=p.length_b, k0=p.stiffness_b, b=20.0)
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
    if out is not None:
        from vfem.io.results import write_summary

        write_summary(out, summary)
    return summary


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
