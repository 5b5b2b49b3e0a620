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
import scipy.sparse as sp

from .surface import ContactSurface


def transfer_matrices(sf: ContactSurface, sc: ContactSurface, fpatch: np.ndarray,
              cpatch: np.ndarray, cnormals: np.ndarray, ends: np.ndarray, gap: float,
              xf: np.ndarray, xc: np.ndarray) -> tuple[sp.csr_array, sp.csr_array]:
    """Both sides' nodal forces per unit traction value, from one integral over the overlap.

    ``N[i, k] = int phi_i(y) psi_k(y) dy`` (the compatibility side, eq. 4.4.11) and
    ``T[c, k] = int phi_c(proj(y)) psi_k(y) dy`` (the equilibrium side: the same traction
    re-integrated with its shape functions), ``psi_k`` the traction's interpolation
    (:meth:`~vfem.contact.geometry.facets.FacetKind.traction_shape`: the shape functions, piecewise
    linear on 3-node segments), both over the part of the patch ``fpatch`` of
    ``sf`` that lies over the patch ``cpatch`` of ``sc`` (points beyond its ends count
    nothing); both sparse, a facet's few nodes a column. Since the shape functions of each
    side sum to one, the two sides' forces are equal and opposite for any traction, to
    round-off, and force reaches only nodes whose facets overlap the other surface.

    ``ends`` is the coarse patch's boundary (:meth:`ContactSurface.patch_boundary`). The
    quadrature is the fine side's kind's
    (:meth:`~vfem.contact.geometry.facets.FacetKind.overlap_quadrature`); for segments: over the
    fine facets, split where the projection onto the coarse patch passes one of its vertices (seen
    along its nodal normal), with a Gauss rule exact to degree 5 on each piece: exact for the
    piecewise polynomial integrand (degree 4 at most, with quadratic elements) on straight
    facets, so a uniform traction crosses exactly. On curved (quadratic) facets the points and
    weights follow the curve; the splits are found on the chords. Positions ``xf``, ``xc`` may
    be deformed; the measure stays the fine side's undeformed length (the traction is
    nominal). For triangles and quadrilaterals (3D, linear facets): the clipped overlaps of
    :mod:`~vfem.contact.geometry.overlap3d`, exact on a flat interface
    (``Triangle.overlap_quadrature``).
    """
    # points farther than this from the coarse surface face something else (``gap``: the
    # largest gap of the pair's nodes)
    reach = gap + 2.0 * (sf.sizes.max() + sc.sizes.max())
    fac, sloc, wts = sf.kind.overlap_quadrature(sf, fpatch, sc, cpatch, cnormals, reach, xf, xc)
    pts, jn = sf.surface_map(fac, sloc, xf)
    own = jn / np.maximum(np.linalg.norm(jn, axis=1), 1e-300)[:, None]
    seg, tt, dist, _, tf = sc.closest(pts, xc, cpatch, own)
    wts = np.where(sc.beyond(seg, tf, ends) | (dist > reach), 0.0, wts)
    fend, cend = sf.facets[fac], sc.facets[seg]
    fshape, tshape = sf.shape(sloc).T, sf.kind.traction_shape(sloc).T
    N, T = ([], [], []), ([], [], [])
    for fi, fw in zip(fend.T, tshape):  # the traction's interpolation (piecewise linear)
        for ci, cw in zip(cend.T, sc.shape(tt).T):
            T[0].append(ci), T[1].append(fi), T[2].append(wts * cw * fw)
        for gi, gw in zip(fend.T, fshape):
            N[0].append(gi), N[1].append(fi), N[2].append(wts * gw * fw)
    return _summed(N, (sf.nc, sf.nc)), _summed(T, (sc.nc, sf.nc))


def _summed(parts: tuple[list, list, list], shape: tuple[int, int]) -> sp.csr_array:
    """The sparse matrix of the (rows, cols, values) parts, repeated entries summed: N and T
    have a facet's few nodes a column (issue 40: stored dense, (nc, nc) numbers a pair, 4 GB
    each at 23,000 nodes)."""
    rows, cols, vals = (np.concatenate(p) if p else np.zeros(0) for p in parts)
    A = sp.csr_array((vals, (rows.astype(np.int64), cols.astype(np.int64))), shape=shape)
    A.sum_duplicates()
    return A


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
