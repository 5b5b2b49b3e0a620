"""Energy balance of a contact model with a plastic body (issue 41's acceptance: external work =
stored elastic energy + plastic dissipation within 1 %).

The flat punch of ``tests/test_plasticity.py`` (an elastic punch driven 2e-3 into an
elasto-plastic block with linear isotropic hardening, frictionless, then lifted off) on meshes
h, h/2, h/4 and with the push and the lift split into N steps each. Printed per run:

* ``work``: the work of the prescribed displacements' reactions, summed over the steps by
  trapezoids, ``sum (R_k + R_k-1) / 2 . (u_k - u_k-1)`` over every node (the rollers' dofs do
  not move: they do none);
* ``stored``: the block's elastic energy ``int 1/2 eps_e : C : eps_e`` and hardening energy
  ``int H_iso alpha^2 / 2`` at the end, plus the punch's ``u . (f_contact + R) / 2`` (linear);
* ``dissipated``: ``int Y alpha`` (with linear isotropic hardening the dissipation of a step is
  ``Y d(alpha)``, and alpha never decreases);
* their difference as a share of the work.

The contact forces' own work on the two bodies cancels only if the transfer of the tractions
is the transpose of the reading of the gaps; vfem's virtual elements are not exactly that (W is
not symmetric, ``docs/method.md`` §13), so the balance measures the formulation too.

    python3 benchmarks/contact_energy.py                 # h, h/2, h/4; 10 and 40 steps each way
    python3 benchmarks/contact_energy.py --refine 0 1 --steps 10
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import vfem  # noqa: E402
from test_plasticity import PUNCH  # noqa: E402
from vfem.io.input import loads  # noqa: E402


def punch_config(refine: int, steps: int):
    """The punch model with both meshes' ``h`` divided by 2^refine and ``steps`` load factors
    up to 1 and as many back to 0."""
    text = PUNCH.replace("h = 0.125", f"h = {0.125 / 2 ** refine!r}")
    text = text.replace("h = 0.1\n", f"h = {0.1 / 2 ** refine!r}\n")
    up = np.linspace(0.0, 1.0, steps + 1)[1:]
    down = np.linspace(1.0, 0.0, steps + 1)[1:]
    factors = ", ".join(repr(float(x)) for x in np.r_[up, down])
    text = text.replace("load_factors = [0.25, 0.5, 0.75, 1.0, 0.5, 0.0]",
                        f"load_factors = [{factors}]")
    return loads(text, "punch.toml")


def balance(refine: int, steps: int) -> dict:
    config = punch_config(refine, steps)
    t0 = time.perf_counter()
    result = vfem.solve(config)
    seconds = time.perf_counter() - t0
    if not result.converged:
        raise SystemExit(f"h/{2 ** refine}, {steps} steps: {result.message}")
    work = 0.0
    previous = {name: (np.zeros_like(b.displacement), np.zeros_like(b.reaction))
                for name, b in result.steps[0].bodies.items()}
    for step in result.steps:
        for name, b in step.bodies.items():
            u0, r0 = previous[name]
            work += float(np.sum(0.5 * (b.reaction + r0) * (b.displacement - u0)))
            previous[name] = (b.displacement, b.reaction)
    last = result.steps[-1].bodies
    punch = last["punch"]
    stored = 0.5 * float(np.sum(punch.displacement * (punch.contact_force + punch.reaction)))
    block = next(b for b in result.model.bodies if b.name == "block")
    nl = block.mechanics.nonlinear
    material = nl.material
    lam, mu = material.lame()
    g = nl.basis0.interpolate(nl.displacement).grad
    eps = np.zeros((3, 3) + g.shape[2:])
    eps[:2, :2] = 0.5 * (g + g.transpose(1, 0, 2, 3))
    elastic = eps - nl.material_state["plastic_strain"]
    tr = elastic[0, 0] + elastic[1, 1] + elastic[2, 2]
    dx = nl.basis0.dx
    stored += float(((0.5 * lam * tr ** 2
                      + mu * np.einsum("ij...,ij...->...", elastic, elastic)) * dx).sum())
    alpha = nl.material_state["equivalent_plastic_strain"]
    stored += float((0.5 * material.hardening_modulus * alpha ** 2 * dx).sum())
    dissipated = float((material.yield_stress * alpha * dx).sum())
    return {"h": f"h/{2 ** refine}", "steps": steps, "work": work, "stored": stored,
            "dissipated": dissipated, "off": (stored + dissipated - work) / work,
            "seconds": seconds}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--refine", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--steps", type=int, nargs="+", default=[10, 40])
    args = ap.parse_args(argv)
    print(f"{'mesh':>6} {'steps':>5} {'work':>12} {'stored':>12} {'dissipated':>12} "
          f"{'(stored+diss)/work-1':>21} {'s':>6}")
    for refine in args.refine:
        for steps in args.steps:
            r = balance(refine, steps)
            print(f"{r['h']:>6} {r['steps']:>5} {r['work']:12.6g} {r['stored']:12.6g} "
                  f"{r['dissipated']:12.6g} {r['off']:21.3e} {r['seconds']:6.1f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
