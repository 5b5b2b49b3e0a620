"""An independent check of a converged state: does any node of any body penetrate another?

The paired variant enforces compatibility at one surface of each pair (docs/method.md §6); the
other surface's nodes are free to indent it where its facets are longer or its geometry sharper.
This check measures that, for every candidate node of every body against every other body's
candidate surface, with the same linear kinematics as the analysis: the node's closest point on
the other undeformed surface, the outward normal there, and the gap
``g0 + n . (u_node - u_other(closest point))``; where the closest point is a vertex (a corner),
n is the direction from it to the node. Nodes whose closest point is an end of the other surface
(beyond its edge) are left out.

When any body is analysed under large displacements the same measure is taken on the deformed
surfaces: each node's current position against the other surface as it now lies.
"""

from __future__ import annotations

import numpy as np

from ..solver import AnalysisResult, StepResult


def largest_penetrations(result: AnalysisResult, step: StepResult | None = None
                         ) -> dict[str, dict]:
    """Per body: the largest penetration of its candidate nodes into another body.

    Returns ``{body: {"penetration": value (> 0 overlap, <= 0 none), "node": point number,
    "into": other body}}`` for the given step (default: the last).
    """
    step = step or result.steps[-1]
    surfaces = result.surfaces
    out = {}
    for s in surfaces:
        best = {"penetration": -np.inf, "node": -1, "into": ""}
        if s.nc == 0:
            out[s.body.name] = best
            continue
        large = any(b.large for b in result.model.bodies)
        u = step.bodies[s.body.name].displacement[s.nodes[: s.nc]]
        x = s.X[: s.nc] + u if large else s.X[: s.nc]
        for so in surfaces:
            if so is s or so.nc == 0:
                continue
            xo = so.X + step.bodies[so.body.name].displacement[so.nodes] if large else so.X
            seg, t, dist, n = so.project(x, xo)
            pos, _ = so.curve(seg, t, xo)
            # closest to a vertex (a corner of the other surface): measure along the line from
            # that vertex to the node, not along a facet normal that does not reach it
            at_vertex = ((t <= 0) | (t >= 1)) & (dist > 1e-12 * max(so.lengths.max(), 1e-300))
            n = np.where(at_vertex[:, None],
                         (x - pos) / np.maximum(dist, 1e-300)[:, None], n)
            if large:
                pen = -np.einsum("ij,ij->i", x - pos, n)
            else:
                uo = step.bodies[so.body.name].displacement[so.nodes[: so.nc]]
                uv = np.einsum("nk,nkd->nd", so.shape(t), uo[so.facets[seg]])
                pen = -(np.einsum("ij,ij->i", x - pos, n)
                        + np.einsum("ij,ij->i", u - uv, n))
            ends = so.facets[seg]
            off = (((t <= 0) & so.surface_ends[ends[:, 0]])
                   | ((t >= 1) & so.surface_ends[ends[:, 1]]))
            pen = np.where(off, -np.inf, pen)
            k = int(np.argmax(pen))
            if pen[k] > best["penetration"]:
                best = {"penetration": float(pen[k]), "node": int(s.nodes[k]),
                        "into": so.body.name}
        out[s.body.name] = best
    return out
