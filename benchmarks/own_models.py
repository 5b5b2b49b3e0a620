"""Models that no issue names, checked for the invariants every converged step must keep
(issue 18's review): a punch narrower than the block (both its corners inside the contact),
stiff on soft and soft on stiff, starting apart, mesh ratios 3:1 and 1:3, small and large
kinematics (pressing, and pressing then sliding with and without a search distance; stiff on
soft and soft on stiff under total and updated Lagrangian, a 21k-dof block), the Lagrange
baseline and the thesis variant.

    python benchmarks/own_models.py                               # this tree
    PYTHONPATH=/tmp/before/src python benchmarks/own_models.py    # another (a git worktree)

Prints per model the worst force balance and depth beyond the allowance over its steps, the
steps that break an invariant (from the solver's own records), and the punch's force, the
block's largest pressure and the iterations, to 12 digits, to compare two trees.
"""
import sys
from pathlib import Path

import numpy as np
from skfem import MeshQuad, MeshTri

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from invariant_record import step_violations
from vfem.bodies import Body, PrescribedDisplacement, Support
from vfem.contact.settings import ContactSettings
from vfem.materials import LinearElastic
from vfem.solver import Analysis, Model


def rect(x0, x1, y0, y1, nx, ny, name, E, tri=False, **kw):
    cls = MeshTri if tri else MeshQuad
    m = cls.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    t = 1e-9
    m = m.with_boundaries({"top": lambda x: x[1] > y1 - t, "bottom": lambda x: x[1] < y0 + t})
    return Body(name, m, LinearElastic(E, 0.3), **kw)


def case(name, bodies, settings=None, steps=(0.25, 0.5, 0.75, 1.0)):
    r = Analysis(Model(name, bodies, settings or ContactSettings(), load_factors=steps)).run()
    worst_bal = max(s.invariants["force_balance"] for s in r.steps) if r.steps else float("nan")
    worst_pen = max(s.invariants["penetration"] - s.invariants["allowed"] for s in r.steps) \
        if r.steps else float("nan")
    bad = step_violations(r)
    print(f"{name:58s} converged {r.converged!s:5s} steps {len(r.steps)} "
          f"balance {worst_bal:.1e}  deepest-minus-allowed {worst_pen:.1e}  "
          f"violations {len(bad)}" + ("" if r.converged else f"  [{r.message[:120]}]"))
    for b in bad[:3]:
        print("   ", b)
    if r.steps:
        last = r.steps[-1].bodies
        print(f"    punch force y {last['punch'].contact_force[:, 1].sum():.12e}, max block "
              f"pressure {last['block'].contact_pressure.max():.12e}, iterations "
              f"{[s.iterations for s in r.steps]}")
    return r


def punch_on_block(gap, ratio, E_punch, E_block, tri, kinematics="small", settings=None,
                   tag="", slide=0.0, block_mesh=(20, 8)):
    block = rect(0, 1, -0.4, 0, *block_mesh, "block", E_block, tri=tri,
                 supports=(Support("bottom"),), contact_boundaries=("top",),
                 kinematics=kinematics)
    # a punch narrower than the block: its two corners lie inside the contact zone
    n = max(2, int(round(8 * ratio)))
    if slide:  # pressed in over the first half of the schedule, then slid along +x
        motion = (PrescribedDisplacement("top", "y", -(gap + 0.004), ((0, 0), (0.5, 1), (1, 1))),
                  PrescribedDisplacement("top", "x", slide, ((0, 0), (0.5, 0), (1, 1))))
        held = ()
    else:
        motion = (PrescribedDisplacement("top", "y", -(gap + 0.004)),)
        held = (Support("top", ("x",)),)
    punch = rect(0.3, 0.7, gap, gap + 0.2, n, 4, "punch", E_punch, supports=held,
                 prescribed=motion, contact_boundaries=("bottom",), kinematics=kinematics)
    return case(f"punch E{E_punch:.0e}/block E{E_block:.0e} gap {gap} ratio {ratio} "
                f"{'tri' if tri else 'quad'} {kinematics}{tag}", [block, punch], settings)


# stiff against soft, corners inside the contact, starting apart, a 3:1 and a 1:3 mesh ratio
punch_on_block(0.002, 3.0, 2e11, 1e9, tri=True)
punch_on_block(0.002, 1 / 3, 2e11, 1e9, tri=False)
# soft punch on a stiff block (the soft side has the edge), starting touching
punch_on_block(0.0, 2.0, 1e8, 2e11, tri=True)
# equal stiffness, body order swapped by the names' order does not matter; large kinematics
punch_on_block(0.001, 1.5, 1e9, 1e9, tri=False, kinematics="total")
# large kinematics, starting apart, then sliding 0.2 along the block: every top facet a
# candidate (the default), and a search distance given (issue 19: honoured along the path)
for distance in (None, 0.02):
    punch_on_block(0.001, 1.5, 1e9, 1e9, tri=True, kinematics="total", slide=0.2,
                   settings=ContactSettings(search_distance=distance),
                   tag=f" slide, search {distance}")
# large kinematics as issue 19 reworked it (whole-array tangent, PARDISO analysis taken over,
# coloured follower differences, lazy linearisation) on models it was not tuned on: stiff on
# soft starting apart with a 3:1 mesh ratio (total and updated Lagrangian), soft on stiff with
# 1:3 and sliding, and a block of 21k dofs (PARDISO's threads above 20,000 dofs)
for kin in ("total", "updated"):
    punch_on_block(0.002, 3.0, 2e10, 1e9, tri=True, kinematics=kin, tag=" stiff on soft")
punch_on_block(0.0, 1 / 3, 1e8, 2e9, tri=False, kinematics="updated", slide=0.1,
               tag=" soft on stiff, slide")
punch_on_block(0.001, 2.0, 1e10, 1e9, tri=False, kinematics="total", block_mesh=(150, 70),
               tag=" 21k-dof block")
# the classical Lagrange baseline and the thesis variant on the stiff-on-soft model (recorded)
punch_on_block(0.002, 3.0, 2e11, 1e9, tri=True, settings=ContactSettings(method="lagrange"),
               tag=" [lagrange]")
punch_on_block(0.002, 3.0, 2e11, 1e9, tri=True, settings=ContactSettings(variant="thesis"),
               tag=" [thesis]")
