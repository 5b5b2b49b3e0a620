"""The tilted cube of issue 37 against a reference that vfem's formulation does not make.

The model (``../shared/models/d_tilted_cube.toml``, copied to ``tests/data/models``): a 0.5 cube
of coarse tetrahedra (E = 2e11) tilted 10 degrees about y, so that one edge lands first, its top
pushed 0.02 down into a block of hexahedra 2000 times softer (E = 1e8), 4 steps, small
kinematics, no friction. vfem is run twice per block mesh (n x n x 8 elements): by default (the
block carries compatibility) and with ``contact.compatibility_side = "cube"``.

**Reference** (for the same block mesh): the cube rigid — it is 2000 times stiffer; vfem's cube
shortens by 2e-5 = 0.1 % of the push — and the block's nodes held outside it, each against the
face it meets as the cube comes down (the bottom face where the node lies inside the edge line,
the side face beyond it): the exact contact state of a block on a rigid obstacle, found by an
active set on the block's compliance condensed to its top nodes (K solved directly, not vfem's
contact code). Two readings of it bracket what a block mesh can resolve:

* *nodes*: the block's nodes only — the cube's edge may pass between them (a lower bound of the
  force on that mesh);
* *nodes + edge*: the cube's edge held too, wherever it crosses a line of the block's nodes
  (the block's surface there, bilinear across the facet, below the edge): neither surface
  inside the other anywhere.

Both converge to the same force as the block mesh is refined (the edge's share is one row of
facets). Printed per mesh: the four forces, vfem's two against the reference with the edge, and
how deep the cube's edge lies inside the block between the cube's vertices in vfem's default
answer (read on the deformed block surface, linear on its facets' triangles).

    python benchmarks/tilted_cube.py                 # block meshes 24, 36, 48 (about 3 min)
    python benchmarks/tilted_cube.py --meshes 24 72  # others
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import meshio
import numpy as np
import skfem
from scipy.interpolate import LinearNDInterpolator
from skfem.models.elasticity import lame_parameters, linear_elasticity

from vfem.linalg import factorize

MODEL = Path(__file__).resolve().parents[1] / "tests" / "data" / "models" / "d_tilted_cube.toml"
E_BLOCK, NU, PUSH, TILT, HALF = 1.0e8, 0.3, 0.02, np.radians(10.0), 0.25


def _cube_faces():
    """The rigid cube's bottom and +x side faces after the push: (outward normal, a point)."""
    c, s = np.cos(TILT), np.sin(TILT)
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    lowest = -HALF * s  # the tilted cube's lowest z before it is lifted onto z = 0
    shift = np.array([0.0, 0.0, -lowest - PUSH])
    bottom = (R @ [0, 0, -1.0], R @ [0, 0, 0.0] + shift)
    side = (R @ [1.0, 0, 0], R @ [HALF, 0, 0] + shift)
    edge_x = HALF * c  # the lowest edge, at z = -PUSH
    return bottom, side, edge_x


def rigid_reference(n: int, nz: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """The cube's force (3,) on the n x n x nz block for a rigid cube: the block's nodes held,
    and the block's nodes and the cube's edge held."""
    m = skfem.MeshHex.init_tensor(np.linspace(-0.6, 0.6, n + 1), np.linspace(-0.6, 0.6, n + 1),
                                  np.linspace(-0.6, 0.0, nz + 1))
    basis = skfem.Basis(m, skfem.ElementVector(skfem.ElementHex1()))
    K = skfem.asm(linear_elasticity(*lame_parameters(E_BLOCK, NU)), basis).tocsc()
    X = m.p.T
    nd = basis.nodal_dofs
    free = np.setdiff1d(np.arange(K.shape[0]), nd[:, np.isclose(X[:, 2], -0.6)].ravel())
    pos = -np.ones(K.shape[0], dtype=int)
    pos[free] = np.arange(len(free))
    (nb, qb), (ns, qs), edge_x = _cube_faces()
    # candidates: the top nodes under and just beyond the cube's lower half
    top = np.flatnonzero(np.isclose(X[:, 2], 0.0) & (X[:, 0] > 0.06) & (X[:, 0] < 0.34)
                         & (np.abs(X[:, 1]) < HALF + 0.06))
    cols = pos[nd[:, top].T.ravel()]
    B = np.zeros((len(free), len(cols)))
    B[cols, np.arange(len(cols))] = 1.0
    W = factorize(K[free][:, free].tocsr()).solve(B)[cols]  # the top nodes' compliance
    W = 0.5 * (W + W.T)
    # constraints g0 + a . u >= 0 (columns of A), u the candidates' displacements
    A, g0 = [], []
    Xt = X[top]
    for i, p in enumerate(Xt):
        normal, point = (nb, qb) if p[0] <= edge_x else (ns, qs)
        if abs(p[1]) > HALF + 1e-9:
            continue  # beyond the cube's ends
        a = np.zeros(len(cols))
        a[3 * i:3 * i + 3] = normal
        A.append(a)
        g0.append(normal @ (p - point))
    nodes = len(A)
    h = 1.2 / n
    index = {tuple(np.round(p[:2], 9)): i for i, p in enumerate(Xt)}
    x0 = -0.6 + np.floor((edge_x + 0.6) / h) * h
    xi = (edge_x - x0) / h
    # the block's surface is bilinear across a facet, so linear along the edge between
    # two lines of nodes: held where it crosses them and at the cube's ends
    ys = [-HALF, HALF] + [-0.6 + k * h for k in range(n + 1) if abs(-0.6 + k * h) < HALF]
    for y in np.unique(np.round(ys, 12)):
        y0 = -0.6 + min(np.floor((y + 0.6) / h), n - 1) * h
        eta = (y - y0) / h
        a = np.zeros(len(cols))
        for dx, dy, w in ((0, 0, (1 - xi) * (1 - eta)), (1, 0, xi * (1 - eta)),
                          (0, 1, (1 - xi) * eta), (1, 1, xi * eta)):
            a[3 * index[(round(x0 + dx * h, 9), round(y0 + dy * h, 9))] + 2] -= w
        A.append(a)
        g0.append(-PUSH)  # the block's surface (z = 0 at rest) below the edge's z
    A, g0 = np.array(A).T, np.array(g0)
    return _contact(A[:, :nodes], g0[:nodes], W, n), _contact(A, g0, W, n)


def _contact(A: np.ndarray, g0: np.ndarray, W: np.ndarray, n: int) -> np.ndarray:
    """The cube's force for the constraints g0 + A^T u >= 0 on the compliance W."""
    M = A.T @ W @ A
    # active set (principal pivoting) on the complementarity problem
    # lam >= 0, g = g0 + M lam >= 0, lam g = 0
    act = g0 < 0
    for _ in range(20 * len(g0)):
        lam = np.zeros(len(g0))
        ia = np.flatnonzero(act)
        if len(ia):
            lam[ia] = np.linalg.solve(M[np.ix_(ia, ia)], -g0[ia])
        if (lam < -1e-9 * np.abs(lam).max()).any():
            act[np.argmin(lam)] = False
            continue
        g = g0 + M @ lam
        v = np.flatnonzero(~act & (g < -1e-13))
        if not len(v):
            break
        act[v[np.argmin(g[v])]] = True
    else:
        raise RuntimeError(f"the reference's active set did not settle on the {n} mesh")
    return -(A @ lam).reshape(-1, 3).sum(axis=0)  # on the cube


def run_vfem(n: int, side: str | None, out: Path) -> dict:
    text = MODEL.read_text()
    text = re.sub(r"\bnx = \d+", f"nx = {n}", text)
    text = re.sub(r"\bny = \d+", f"ny = {n}", text)
    model = out / f"cube{n}.toml"
    model.write_text(text.replace('file = "d_tilted_cube.msh"',
                                  f'file = "{MODEL.with_suffix(".msh")}"'))
    run = out / f"{side or 'default'}{n}"
    cmd = [sys.executable, "-m", "vfem", "run", str(model), "--no-figures", "--out", str(run)]
    if side:
        cmd += ["--set", f"contact.compatibility_side={side}"]
    subprocess.run(cmd, check=False, capture_output=True)
    summary = json.loads((run / "summary.json").read_text())
    return {"converged": summary["converged"],
            "force": np.array(summary["bodies"]["cube"]["contact_force"]), "dir": run}


def edge_depth(run: Path) -> float:
    """How deep the cube's lowest edge lies inside the block between the cube's vertices, on
    the last step's deformed geometry."""
    last = sorted(run.glob("block_step*.vtu"))[-1]
    b, c = meshio.read(last), meshio.read(str(last).replace("block_", "cube_"))
    top = np.isclose(b.points[:, 2], 0.0)
    surf = b.points[top] + b.point_data["displacement"][top]
    height = LinearNDInterpolator(surf[:, :2], surf[:, 2])
    x = c.points + c.point_data["displacement"]
    edge = np.flatnonzero((c.points[:, 0] > HALF * np.cos(TILT) - 1e-6)
                          & (c.points[:, 2] < 1e-6))
    edge = edge[np.argsort(c.points[edge, 1])]
    t = np.linspace(0.0, 1.0, 41)[:, None]
    pts = np.concatenate([(1 - t) * x[a] + t * x[b] for a, b in zip(edge[:-1], edge[1:])])
    return float(np.nanmax(height(pts[:, :2]) - pts[:, 2]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", type=int, nargs="+", default=[24, 36, 48])
    args = ap.parse_args()
    print(f"{'block':>6} {'ref nodes':>10} {'ref +edge':>10} {'default':>10} {'cube side':>10}"
          f" {'default/ref':>11} {'cube/ref':>9} {'edge inside':>11}")
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.meshes:
            nodes, ref = (f[2] for f in rigid_reference(n))
            d, c = run_vfem(n, None, Path(tmp)), run_vfem(n, "cube", Path(tmp))
            mark = {True: "", False: "*"}
            print(f"{n:>6} {nodes:10.4g} {ref:10.4g} {d['force'][2]:10.4g}{mark[d['converged']]}"
                  f" {c['force'][2]:10.4g}{mark[c['converged']]} {d['force'][2] / ref:11.3f}"
                  f" {c['force'][2] / ref:9.3f} {edge_depth(d['dir']):11.2e}")
    print("(forces: the cube's vertical contact force; * not converged; 'edge inside': the "
          "default answer's cube edge below the block's deformed surface)")


if __name__ == "__main__":
    main()
