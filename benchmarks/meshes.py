"""How long the built-in examples take to make their meshes (issue 19, item 6).

    python benchmarks/meshes.py                      # every case below, once each
    python benchmarks/meshes.py hertz_100k hertz_1M --repeat 3
    PYTHONPATH=/tmp/mesh_head/src python benchmarks/meshes.py hertz_1M   # another tree

The cases: the Hertz example at about 100k and 1M dofs (:func:`vfem_tools.bench.
hertz_parameters`, as the large-run benchmarks size it), the 1M one's mesh also with quadratic
elements (``hertz_1M_order2``: four times the dofs), and at its defaults, linear and
quadratic; the wedge, block, gasket, punch and sliding examples and the patch test's cases at
their defaults. Each measurement runs in a fresh process (built-in meshes are cached within a
process), which imports the ``vfem`` found on its path: point ``PYTHONPATH`` at another tree (a
``git worktree`` of the commit before a change) to time that tree, and alternate the two.

Printed per case and run: the bodies' dofs (two per point), ``meshes_s``, the seconds to make
every body's mesh from its description (the shape functions of :mod:`vfem.mesh` and, with
quadratic elements, the curved midpoints), and ``model_s``, the seconds of the model's build
that follow with those meshes already made (bodies and the mesh checks of
:mod:`vfem.mesh.checks`). With ``--repeat N`` each case runs N times and the fastest run of
each is printed last.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys


def configs(case: str) -> list:
    """The model descriptions (:class:`vfem.config.ModelConfig`) of one case."""
    import importlib
    import os

    import vfem

    # the tree's own examples: beside the library since issue 38, inside it before (an import
    # that merely succeeds may come from an editable install's tree, later on the path)
    tree = os.path.dirname(os.path.dirname(vfem.__file__))
    beside = os.path.isdir(os.path.join(tree, "vfem_examples"))
    ex = "vfem_examples" if beside else "vfem.examples"
    block, gasket, hertz, patch, punch, sliding, wedge = (
        importlib.import_module(f"{ex}.{name}")
        for name in ("block", "gasket", "hertz", "patch", "punch", "sliding", "wedge"))
    hertz_parameters = importlib.import_module(
        "vfem_tools.bench" if beside else "vfem.tools.bench").hertz_parameters

    cases = {
        "hertz_100k": lambda: [hertz.config(hertz_parameters(100_000))],
        "hertz_1M": lambda: [hertz.config(hertz_parameters(1_000_000))],
        "hertz_1M_order2": lambda: [hertz.config(hertz_parameters(1_000_000, order=2))],
        "hertz": lambda: [hertz.config(hertz.HertzParameters())],
        "hertz_order2": lambda: [hertz.config(hertz.HertzParameters(order=2))],
        "wedge": lambda: [wedge.config(wedge.WedgeParameters())],
        "block": lambda: [block.config(block.Parameters())],
        "gasket": lambda: [gasket.config(gasket.GasketParameters())],
        "punch": lambda: [punch.config(punch.Parameters())],
        "sliding": lambda: [sliding.config(sliding.Parameters())],
        "patch": lambda: list(patch.configs(patch.Parameters()).values()),
    }
    return cases[case]()


CASES = ["hertz_100k", "hertz_1M", "hertz_1M_order2", "hertz", "hertz_order2", "wedge", "block",
         "gasket", "punch", "sliding", "patch"]


def measure(case: str) -> dict:
    """One case in this process: seconds to make the meshes, then to build the models."""
    import time

    from vfem import config

    models = configs(case)
    config._shape_mesh.cache_clear()  # a config may have made its meshes (the wedge's steps)
    t0 = time.perf_counter()
    for model in models:
        for body in model.bodies:
            body.mesh.make()
    t1 = time.perf_counter()
    built = [model.build() for model in models]
    t2 = time.perf_counter()
    dofs = sum(2 * b.npoints for m in built for b in m.bodies)
    return {"case": case, "dofs": dofs, "meshes_s": t1 - t0, "model_s": t2 - t1}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", nargs="*", metavar="CASE",
                        help=f"some of {', '.join(CASES)} (default: all)")
    parser.add_argument("--repeat", type=int, default=1, help="runs per case (fresh process)")
    parser.add_argument("--one", help=argparse.SUPPRESS)  # a child: one case, JSON out
    args = parser.parse_args()
    unknown = sorted(set(args.cases) - set(CASES))
    if unknown:
        parser.error(f"unknown case(s) {', '.join(unknown)}; cases: {', '.join(CASES)}")
    args.cases = args.cases or CASES
    if args.one:
        print(json.dumps(measure(args.one)))
        return
    import vfem

    print(f"vfem from {vfem.__file__}")
    print(f"{'case':14s} {'dofs':>10s} {'meshes_s':>9s} {'model_s':>9s}")
    best: dict[str, dict] = {}
    for _ in range(args.repeat):
        for case in args.cases:
            out = subprocess.run([sys.executable, __file__, "--one", case], check=True,
                                 capture_output=True, text=True).stdout
            r = json.loads(out.strip().splitlines()[-1])
            print(f"{case:14s} {r['dofs']:10d} {r['meshes_s']:9.3f} {r['model_s']:9.3f}",
                  flush=True)
            if case not in best or r["meshes_s"] < best[case]["meshes_s"]:
                best[case] = r
    if args.repeat > 1:
        print("fastest:")
        for case, r in best.items():
            print(f"{case:14s} {r['dofs']:10d} {r['meshes_s']:9.3f} {r['model_s']:9.3f}")


if __name__ == "__main__":
    main()
