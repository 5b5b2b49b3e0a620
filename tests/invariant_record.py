"""Shared by the tests that read a step's recorded invariants (``Invariants.record()``)."""


def violations(inv: dict) -> list[str]:
    """The invariants a step's record (``Invariants.record()``) breaks, all three, enforced or
    not (``Invariants.message()`` names only the enforced ones), in words; and a line if the
    record's own verdict (``failed``) disagrees with its measures."""
    out = []
    if inv["force_balance"] > inv["force_balance_tolerance"]:
        out.append(f"(a) force balance {inv['force_balance']:.3g} > "
                   f"{inv['force_balance_tolerance']:.3g}")
    w = inv["where"]
    if w is not None and inv["penetration"] > inv["allowed"]:
        out.append(f"(b) interpenetration: node {w['node']} of {w['body']!r} at "
                   f"({w['x']:.6g}, {w['y']:.6g}) {inv['penetration']:.3g} inside {w['into']!r}, "
                   f"allowed {inv['allowed']:.3g} (deformed depth {w['deformed_depth']:.3g}, "
                   f"linearised {w['linearised_depth']})")
    if inv["tension"] > inv["tension_tolerance"]:
        t = inv["tension_where"]
        out.append(f"(c) tension: node {t['node']} of {t['body']!r} F.n = {t['value']:.6g}, "
                   f"{inv['tension']:.3g} of the largest > {inv['tension_tolerance']:.3g}")
    if sorted(inv["failed"]) != sorted({"(a)": "force balance", "(b)": "interpenetration",
                                        "(c)": "tension"}[v[:3]] for v in out):
        out.append(f"the record's failed {inv['failed']} disagrees with its measures")
    return out


def step_violations(result) -> list[str]:
    """Every converged step's broken invariants, one line each (and a step without its
    invariants recorded)."""
    out = []
    for step in result.steps:
        if not step.converged:
            continue
        where = f"step {step.step} (load factor {step.load_factor:.6g})"
        if not step.invariants:
            out.append(f"{where}: no invariants recorded")
            continue
        out.extend(f"{where}: {v}" for v in violations(step.invariants))
    return out
