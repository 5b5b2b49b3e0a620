"""How to read the contact pressure on Hertz: the paired variant's traction q at the nodes, or the
nodal force over the tributary length (the traction averaged with the node's shape function).

    python benchmarks/pressure_reading.py [FACETS_PER_HALF_WIDTH ...]

Prints, per mesh (default 12, 24, 48 facets across a), for the cylinder's nodes: p_max against
p0, the largest error over |x| < 0.8 a, the RMS error over |x| < a and the error at x = 0 (all in
% of p0); then the same model mirrored into a full one (no symmetry plane). With the cylinder's
contact zone meshed in layers (``vfem.mesh.graded_quarter_disk``) the reading is smooth, with no
dip at x = 0. docs/method.md §6 holds this table (``python3 docs/doc_numbers.py --write
method-pressure-reading``).
"""

import sys

import numpy as np
from skfem import MeshTri

import vfem
from vfem.bodies import Body, Platen, Support
from vfem.solver import Model
from vfem_examples.hertz import HertzParameters, build, theory


def errors(result, a: float, p0: float) -> dict[str, np.ndarray]:
    s = next(s for s in result.surfaces if s.body.name == "cylinder")
    nodes = s.nodes[: s.nc]
    x = np.abs(s.X[: s.nc, 0])
    r = result.steps[-1].bodies["cylinder"]
    hertz = p0 * np.sqrt(np.clip(1 - (x / a) ** 2, 0, None))
    out = {}
    for name, p in (("traction q", r.contact_traction[nodes]),
                    ("force / tributary", r.contact_pressure[nodes])):
        e = (p - hertz) / p0
        out[name] = 100 * np.array([p.max() / p0 - 1, np.abs(e[x < 0.8 * a]).max(),
                                    np.sqrt(np.mean(e[x < a] ** 2)), e[np.argmin(x)]])
    return out


def mirrored(p: HertzParameters) -> Model:
    """The half model's meshes mirrored about x = 0; the cylinder held in x on its top."""
    half = build(p)
    bodies = []
    for b in half.bodies:
        q = b.mesh.p.copy()
        q[0] *= -1
        t = b.mesh.t
        flip = t[[0, 2, 1]] if isinstance(b.mesh, MeshTri) else t[::-1]
        pts = np.hstack([b.mesh.p, q])
        key = np.round(pts.T / 1e-12).astype(np.int64)
        _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
        mesh = type(b.mesh)(pts[:, first], inverse.ravel()[np.hstack([t, flip + q.shape[1]])])
        if b.name == "cylinder":
            top = mesh.p[1].max()
            mesh = mesh.with_boundaries({"top": lambda x, top=top: x[1] > top - 1e-9})
            bodies.append(Body(b.name, mesh, b.material, supports=(Support("top", ("x",)),),
                               platen=Platen("top", "y", -2 * p.force)))
        else:
            bottom = mesh.p[1].min()
            mesh = mesh.with_boundaries({"bottom": lambda x, b0=bottom: x[1] < b0 + 1e-9})
            bodies.append(Body(b.name, mesh, b.material,
                               supports=(Support("bottom", ("x", "y")),)))
    return Model("hertz mirrored", bodies, half.contact, half.load_factors)


if __name__ == "__main__":
    levels = [int(n) for n in sys.argv[1:]] or [12, 24, 48]
    print(f"{'facets':>6} {'model':>8} {'reading':>18} {'p_max':>8} {'max<0.8a':>9} "
          f"{'RMS<a':>7} {'at x=0':>7}   (% of p0)")
    for n in levels:
        p = HertzParameters(facets_per_half_width=n)
        th = theory(p)
        runs = [("half", build(p))] + ([("mirrored", mirrored(p))] if n == levels[0] else [])
        for label, model in runs:
            for name, e in errors(vfem.solve(model), th["a_theory"], th["p0_theory"]).items():
                print(f"{n:6d} {label:>8} {name:>18} {e[0]:+8.3f} {e[1]:9.3f} {e[2]:7.3f} "
                      f"{e[3]:+7.3f}")
