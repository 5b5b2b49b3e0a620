"""Energy balance of a contact model with a plastic body (issue 41's acceptance: external work =
stored elastic energy + plastic dissipation within 1 %).

Two models, each loaded past yield and unloaded in N equal steps each way:

* ``punch``: the flat punch of ``tests/test_plasticity.py`` (an elastic punch driven 2e-3 into
  an elasto-plastic block with linear isotropic hardening, frictionless, then lifted off) on
  meshes h, h/2, h/4, h/8 (``--refine``): a body with corners;
* ``indentation``: the built-in example ``block_indentation`` (a stiff elastic cylinder pressed
  by a platen's force into an elastic-perfectly plastic block to 2.5 times Hertz's onset force
  and lifted off to a hundredth of it): a smooth contact. ``--steps 0`` keeps the example's own
  schedule (19 steps, 1 % apart near the onset and far apart past it).

Printed per run:

* ``work``: the work of the supports', prescribed displacements' and platen's reactions, summed
  over the steps by trapezoids, ``sum (R_k + R_k-1) / 2 . (u_k - u_k-1)`` over every node (the
  rollers' dofs do not move: they do none);
* ``stored``: the plastic body's elastic energy ``int 1/2 eps_e : C : eps_e`` and hardening
  energy ``int H_iso alpha^2 / 2`` at the end, plus the elastic body's ``u . (f_contact + R) / 2``
  (linear, no other load);
* ``dissipated``: ``int Y alpha`` (with linear isotropic hardening the dissipation of a step is
  ``Y d(alpha)``, and alpha never decreases);
* ``contact``: the contact forces' net work on the two bodies, summed by trapezoids as the work
  is (zero for a conservative contact: what one body gives the other takes);
* the balance ``(stored + dissipated) / work - 1`` and the contact's share ``contact / work``.

The contact forces' own work on the two bodies cancels only if each force acts along the
gradient of the gap it closes. vfem's held nodes read their gaps along the other facet's normal
and push along that surface's normal interpolated between its vertices (continuous as a node
slides over a vertex, which Newton's method needs: ``docs/method.md`` §13), and the virtual
elements integrate the tractions over the facets where the gaps are read at the virtual nodes;
where a body slides far under a corner the difference does work.

    python3 benchmarks/contact_energy.py              # punch: h, h/2, h/4; 10, 40 steps each way
    python3 benchmarks/contact_energy.py --refine 0 1 --steps 10
    python3 benchmarks/contact_energy.py --model indentation --steps 0 25 50
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


def indentation_config(steps: int, facets: int | None = None):
    """The built-in example ``block_indentation`` with ``steps`` equal load factors up to its
    peak and as many back to a hundredth of its force (0: its own schedule); ``facets`` its
    ``facets_per_half_width`` (None: its default, 32)."""
    import dataclasses

    from vfem.config import Steps
    from vfem_examples import block_indentation

    p = block_indentation.BlockIndentationParameters()
    if facets is not None:
        p = dataclasses.replace(p, facets_per_half_width=facets)
    config = block_indentation.config(p)
    if not steps:
        return config
    up = np.linspace(0.0, 1.0, steps + 1)[1:]
    down = 1.0 + np.linspace(0.0, 0.99, steps + 1)[1:]
    factors = tuple(float(x) for x in np.r_[up, down])
    return dataclasses.replace(config, steps=Steps(load_factors=factors))


def energies(result, plastic: str) -> dict:
    """The work of the reactions, the contact forces' net work, and the stored and dissipated
    energies at the end of ``result`` (module docstring); ``plastic`` names the J2 body (plane
    strain), the others linear elastic with no load but their reactions and contact forces."""
    work = contact = 0.0
    previous = {name: (np.zeros_like(b.displacement), np.zeros_like(b.reaction),
                       np.zeros_like(b.contact_force))
                for name, b in result.steps[0].bodies.items()}
    for step in result.steps:
        for name, b in step.bodies.items():
            u0, r0, c0 = previous[name]
            du = b.displacement - u0
            work += float(np.sum(0.5 * (b.reaction + r0) * du))
            contact += float(np.sum(0.5 * (b.contact_force + c0) * du))
            previous[name] = (b.displacement, b.reaction, b.contact_force)
    stored = 0.0
    for name, b in result.steps[-1].bodies.items():
        if name != plastic:
            stored += 0.5 * float(np.sum(b.displacement * (b.contact_force + b.reaction)))
    body = next(b for b in result.model.bodies if b.name == plastic)
    nl = body.mechanics.nonlinear
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
    return {"work": work, "stored": stored, "dissipated": dissipated, "contact": contact,
            "off": (stored + dissipated - work) / work, "contact_share": contact / work}


def balance(model: str, refine: int, steps: int, facets: int | None = None) -> dict:
    """Run ``model`` (``punch`` on the mesh h / 2^refine, or ``indentation`` with ``facets``)
    in ``steps`` steps each way and measure its energies (:func:`energies`)."""
    if model == "punch":
        config, plastic, label = punch_config(refine, steps), "block", f"h/{2 ** refine}"
    else:
        config, plastic = indentation_config(steps, facets), "block"
        label = f"a/{facets or 32}"
    t0 = time.perf_counter()
    result = vfem.solve(config)
    seconds = time.perf_counter() - t0
    if not result.converged:
        raise SystemExit(f"{model} {label}, {steps} steps: {result.message}")
    return {"mesh": label, "steps": steps or "own", "seconds": seconds,
            **energies(result, plastic)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", choices=("punch", "indentation"), default="punch")
    ap.add_argument("--refine", type=int, nargs="+", default=[0, 1, 2],
                    help="punch: the meshes h / 2^refine")
    ap.add_argument("--steps", type=int, nargs="+", default=[10, 40],
                    help="equal steps each way (indentation: 0, the example's own schedule)")
    ap.add_argument("--facets", type=int, default=None,
                    help="indentation: the block's elements over the peak's half-width (32)")
    args = ap.parse_args(argv)
    refines = args.refine if args.model == "punch" else [0]
    print(f"{'mesh':>7} {'steps':>5} {'work':>12} {'stored':>12} {'dissipated':>12} "
          f"{'contact':>12} {'(stored+diss)/work-1':>21} {'contact/work':>12} {'s':>6}")
    for refine in refines:
        for steps in args.steps:
            r = balance(args.model, refine, steps, args.facets)
            print(f"{r['mesh']:>7} {r['steps']:>5} {r['work']:12.6g} {r['stored']:12.6g} "
                  f"{r['dissipated']:12.6g} {r['contact']:12.4e} {r['off']:21.3e} "
                  f"{r['contact_share']:12.3e} {r['seconds']:6.1f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
