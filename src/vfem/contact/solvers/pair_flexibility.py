"""The pair matrix W of the paired variant (eq. 4.2.4 in matrix form, thesis §4.3): the change of
every pair unknown's reading — a compatibility node's penetration, or with friction its relative
tangential displacement — per unit traction value of every unknown. A unit traction value puts
sparse nodal forces on both bodies of its pair (its node's facets on one side, the facets under
its virtual node on the other: :func:`force_rows`); each body's flexibility on its contact dofs
turns them into motion, read at the pair's nodes and virtual nodes. Formed densely from each
body's condensed flexibility, or, where the surfaces' flexibility is applied rather than formed
(issue 22), as the :class:`~vfem.contact.solvers.matrix_free.PairOperator` that applies it."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .matrix_free import PairOperator


def force_rows(surfaces: list, pairs: list, directions: list[list[np.ndarray]]
               ) -> tuple[np.ndarray, list[sp.csr_matrix]]:
    """The unknowns' offsets (pair by pair, each pair's directions in turn: (pairs + 1,)) and
    per body the sparse nodal forces on its candidate dofs per unit traction value
    ((dim nc, m)); ``directions``: per pair the directions of its unknowns, each (nodes, dim)."""
    offsets = np.cumsum([0] + [len(p.nodes) * len(dirs) for p, dirs in zip(pairs, directions)])
    m = int(offsets[-1])
    parts: list[list] = [[] for _ in surfaces]  # (rows, cols, values) per body
    for k, pair in enumerate(pairs):
        n = len(pair.nodes)
        for body, columns, sign in ((pair.fine, pair.fine_columns(), 1.0),
                                    (pair.coarse, pair.coarse_columns(), -1.0)):
            r, c = np.nonzero(columns)
            v = sign * columns[r, c]
            dim = surfaces[body].dim
            for j, direction in enumerate(directions[k]):
                for d in range(dim):  # the force along the direction's components
                    parts[body].append((dim * r + d, offsets[k] + j * n + c,
                                        v * direction[c, d]))
    dF = [sp.csr_matrix((np.concatenate([p[2] for p in ps]) if ps else [],
                         (np.concatenate([p[0] for p in ps]) if ps else [],
                          np.concatenate([p[1] for p in ps]) if ps else [])),
                        shape=(s.dim * s.nc, m))
          for s, ps in zip(surfaces, parts)]  # body forces per unit traction value
    return offsets, dF


def platen_rows(surfaces: list, platen_body: int | None, dF: list[sp.csr_matrix], m: int
                ) -> np.ndarray:
    """The platen's reaction per unit traction value (zero without a platen)."""
    dR = np.zeros(m)
    if platen_body is not None:
        s = surfaces[platen_body]
        dR = np.asarray(dF[platen_body].T @ s.platen_row).ravel()
    return dR


def pair_matrix(surfaces: list, pairs: list, directions: list[list[np.ndarray]],
                offsets: np.ndarray, dF: list[sp.csr_matrix], platen_rates: list[np.ndarray],
                executor):
    """W over every unknown of every pair (dense (m, m), or the operator that applies it) and
    the readings' change per unit platen motion ((m,): ``platen_rates``, per pair and direction
    in the unknowns' order, concatenated). Each body's motion under the unit forces is computed
    on the rank that owns it (``executor``)."""
    m = int(offsets[-1])
    dp_dplaten = np.concatenate(platen_rates or [np.zeros(0)])
    if any(s.matrix_free for s in surfaces):
        W = PairOperator(surfaces, [s.flexibility for s in surfaces], dF, pairs, directions,
                         offsets, executor)
        return W, dp_dplaten

    def motion(b: int) -> np.ndarray:  # C f as (f^T C^T)^T, on the body's owner
        s, f = surfaces[b], dF[b]
        return np.asarray((f.T @ (s.C if s.exactly_symmetric else s.C.T)).T).reshape(
            s.nc, s.dim, m)

    du = executor.map(range(len(surfaces)), motion)
    W = np.zeros((m, m))
    for k, pair in enumerate(pairs):
        n = len(pair.nodes)
        uf = pair.fine_read(du[pair.fine])  # (nodes, dim, m)
        coarse = du[pair.coarse]  # the virtual nodes' motion: a few coarse nodes each
        uc = (sp.csr_matrix(pair.interp) @ coarse.reshape(len(coarse), -1)).reshape(uf.shape)
        for j, direction in enumerate(directions[k]):
            rows = slice(offsets[k] + j * n, offsets[k] + (j + 1) * n)
            # along the normal: penetration p = -(gap0 + n.(u_f - u_c)), W = -dp/dq; along a
            # tangent t: the relative displacement t.(u_f - u_c) per unit traction
            W[rows] = np.einsum("id,idm->im", pair.reading(j, direction), uf - uc)
    return W, dp_dplaten
