"""Traction transfer across a contact interface (thesis §4.4-4.5): nodal forces from a traction
and back.

* :func:`transfer_matrices` — the paired variant: both sides' nodal forces per unit traction value
  of the compatibility side, ``F_fine = N q`` (eq. 4.4.11) and ``F_coarse = -T q`` (the same
  traction re-integrated over the other side's shape functions), equal and opposite for any
  traction;
* :func:`traction_from_forces` — the thesis variant: the continuous traction of nodal contact
  forces, ``N* q = Q`` (§4.4), that the virtual elements integrate.
"""

from __future__ import annotations

import numpy as np
from skfem.quadrature import get_quadrature
from skfem.refdom import RefLine

from .search import normal_of_tangent
from .surface import ContactSurface, beyond


def transfer_matrices(sf: ContactSurface, sc: ContactSurface, fpatch: np.ndarray,
              cpatch: np.ndarray, cnormals: np.ndarray, ends: np.ndarray, gap: float,
              xf: np.ndarray, xc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Both sides' nodal forces per unit traction value, from one integral over the overlap.

    ``N[i, k] = int phi_i(y) phi_k(y) dy`` (the compatibility side, eq. 4.4.11) and
    ``T[c, k] = int phi_c(proj(y)) phi_k(y) dy`` (the equilibrium side: the same traction
    re-integrated with its shape functions), both over the part of the patch ``fpatch`` of
    ``sf`` that lies over the patch ``cpatch`` of ``sc`` (points beyond its ends count
    nothing). Since the shape functions of each side sum to one, the two sides' forces are
    equal and opposite for any traction, to round-off, and force reaches only nodes whose
    facets overlap the other surface.

    Integrated over the fine facets, split where the projection onto the coarse patch passes
    one of its vertices (seen along its nodal normal), with a Gauss rule exact to degree 5
    on each piece: exact for the piecewise polynomial integrand (degree 4 at most, with
    quadratic elements) on straight facets, so a uniform traction crosses exactly. On
    curved (quadratic) facets the points and weights follow the curve; the splits are found
    on the chords. Positions ``xf``, ``xc`` may be deformed; the measure stays the fine
    side's undeformed length (the traction is nominal).
    """
    fa, fb = sf.segments(xf)
    fa, fb = fa[fpatch], fb[fpatch]
    d = fb - fa
    # the coarse patch's vertices seen along their normals: where they split the fine facets
    verts = np.unique(sc.facets[cpatch, :2])
    vn = cnormals[verts]
    P = xc[verts]
    # solve fa + s d = P + tau vn for every (facet, coarse vertex)
    det = d[:, None, 0] * (-vn[None, :, 1]) - d[:, None, 1] * (-vn[None, :, 0])
    rx = P[None, :, 0] - fa[:, None, 0]
    ry = P[None, :, 1] - fa[:, None, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (rx * (-vn[None, :, 1]) - ry * (-vn[None, :, 0])) / det
        tau = (d[:, None, 0] * ry - d[:, None, 1] * rx) / det
    # points farther than this from the coarse surface face something else (``gap``: the
    # largest gap of the pair's nodes)
    reach = gap + 2.0 * (sf.lengths.max() + sc.lengths.max())
    ok = np.isfinite(s) & (s > 1e-12) & (s < 1 - 1e-12) & (np.abs(tau) < reach)
    X, W = get_quadrature(RefLine, 5)
    xi, w = X[0], W
    # each fine facet's pieces between its ends and its cuts, in order along it (all facets at
    # once: the cuts sorted per row, repeated cuts giving empty pieces that are dropped)
    cuts = np.sort(np.hstack([np.zeros((len(fpatch), 1)), np.ones((len(fpatch), 1)),
                              np.where(ok, s, np.nan)]), axis=1)  # NaN (no cut) last
    lo, hi = cuts[:, :-1], cuts[:, 1:]
    piece = hi > lo  # False where either is NaN
    row = np.broadcast_to(np.arange(len(fpatch))[:, None], piece.shape)[piece]
    lo, hi = lo[piece], hi[piece]
    sloc = (lo[:, None] + (hi - lo)[:, None] * xi[None, :]).ravel()
    wts = ((hi - lo)[:, None] * w[None, :]).ravel()
    fac = np.repeat(np.asarray(fpatch)[row], len(xi))
    _, tangent = sf.curve(fac, sloc)
    wts = wts * np.linalg.norm(tangent, axis=1)
    pts, tangent = sf.curve(fac, sloc, xf)
    own = normal_of_tangent(tangent)
    own /= np.maximum(np.linalg.norm(own, axis=1), 1e-300)[:, None]
    seg, tt, dist, _, tf = sc.closest(pts, xc, cpatch, own)
    wts = np.where(beyond(sc, seg, tf, ends) | (dist > reach), 0.0, wts)
    N = np.zeros((sf.nc, sf.nc))
    T = np.zeros((sc.nc, sf.nc))
    fend, cend = sf.facets[fac], sc.facets[seg]
    fshape = sf.shape(sloc).T
    for fi, fw in zip(fend.T, fshape):
        for ci, cw in zip(cend.T, sc.shape(tt).T):
            np.add.at(T, (ci, fi), wts * cw * fw)
        for gi, gw in zip(fend.T, fshape):
            np.add.at(N, (gi, fi), wts * gw * fw)
    return N, T


def traction_from_forces(s: ContactSurface, F: np.ndarray) -> np.ndarray:
    """Redistribute nodal contact forces into a continuous traction: N* q = Q (§4.4).

    Facets none of whose nodes carry force are left out of N* (the thesis's N*), so the
    traction may jump at the edge of contact; nodes on no loaded facet get q = 0.
    """
    q = np.zeros_like(F)
    loaded = np.abs(F).sum(axis=1) > 0
    if not loaded.any():
        return q
    facet_on = loaded[s.facets].any(axis=1).astype(float)
    N = s.mass_matrix(facet_on)
    nodes = np.unique(s.facets[facet_on > 0])
    Nd = N[nodes][:, nodes].toarray()
    q[nodes] = np.linalg.solve(Nd, F[nodes])
    return q
