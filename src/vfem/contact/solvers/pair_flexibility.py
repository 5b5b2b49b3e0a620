"""The pair matrix W of the paired variant (eq. 4.2.4 in matrix form, thesis §4.3): the change of
every pair unknown's reading — a compatibility node's penetration, or with friction its relative
tangential displacement — per unit traction value of every unknown. A unit traction value puts
sparse nodal forces on both bodies of its pair (its node's facets on one side, the facets under
its virtual node on the other: :func:`force_rows`); each body's flexibility on its contact dofs
turns them into motion, read at the pair's nodes and virtual nodes. Formed densely from each
body's condensed flexibility, or, where the surfaces' flexibility is applied rather than formed
(issue 22), as the :class:`~vfem.contact.solvers.matrix_free.PairOperator` that applies it from
each body's sparse forces (:func:`force_rows`) and readings (:func:`read_rows`). Both are read
from the nonzero entries of the pairs' transfer and interpolation matrices, which are sparse, a
few a row (:func:`nonzeros`; issue 40)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .matrix_free import PairOperator


def nonzeros(A, rows: np.ndarray | None = None, cols: np.ndarray | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i, j, value) of the nonzero entries of ``A[rows][:, cols]`` (None: all), positions in
    that submatrix: a pair's N, T and virtual-node weights (``ContactPair.mass``,
    ``transfer``, ``interp``, ``at``) are sparse, a few entries a row (issue 40)."""
    B = sp.csr_array(A)
    if rows is not None:
        B = B[np.asarray(rows)]
    if cols is not None:
        B = B[:, np.asarray(cols)]
    B = sp.coo_array(B)
    keep = B.data != 0
    return B.row[keep], B.col[keep], B.data[keep]


def force_rows(surfaces: list, pairs: list, directions: list[list[np.ndarray]]
               ) -> tuple[np.ndarray, list[sp.csr_matrix]]:
    """The unknowns' offsets (pair by pair, each pair's directions in turn: (pairs + 1,)) and
    per body the sparse nodal forces on its candidate dofs per unit traction value
    ((dim nc, m)); ``directions``: per pair the directions of its unknowns, each (nodes, dim).
    A unit traction value of a compatibility node forces its facets' nodes (N, the pair's
    ``mass`` columns) and the other surface's nodes under them (T, ``transfer``); a held
    point, its own node (or its edge's two, ``at``) and the nodes of the facet under it
    (``interp`` transposed): :meth:`~vfem.contact.geometry.ContactPair.fine_columns`,
    ``coarse_columns``, read here from their nonzero entries only (:func:`nonzeros`)."""
    offsets = np.cumsum([0] + [len(p.nodes) * len(dirs) for p, dirs in zip(pairs, directions)])
    m = int(offsets[-1])
    parts: list[list] = [[] for _ in surfaces]  # (rows, cols, values) per body
    for k, pair in enumerate(pairs):
        n = len(pair.nodes)
        if pair.at is None:
            fine = nonzeros(pair.mass, cols=pair.nodes)
            coarse = nonzeros(pair.transfer, cols=pair.nodes)
        else:  # held points: their own weights, and the shape functions under them
            c, r, v = nonzeros(pair.at)
            fine = (r, c, v)
            c, r, v = nonzeros(pair.interp)
            coarse = (r, c, v)
        for body, (r, c, v), sign in ((pair.fine, fine, 1.0), (pair.coarse, coarse, -1.0)):
            v = sign * v
            dim = surfaces[body].dim
            for j, direction in enumerate(directions[k]):
                for d in range(dim):  # the force along the direction's components
                    parts[body].append((dim * r + d, offsets[k] + j * n + c,
                                        v * direction[c, d]))
    dF = [_csr(ps, (s.dim * s.nc, m)) for s, ps in zip(surfaces, parts)]
    return offsets, dF  # body forces per unit traction value


def read_rows(surfaces: list, pairs: list, directions: list[list[np.ndarray]],
              offsets: np.ndarray) -> list[sp.csr_matrix]:
    """Per body the sparse reading of its candidate dofs' motion by each unknown ((m, dim nc)):
    the relative displacement of a pair's point and its virtual point along the unknown's
    reading direction (``ContactPair.reading``), + at the point (its node, or ``at``'s
    weights), - at the virtual point (``interp``'s weights): W = sum over bodies of
    ``read[b] @ C_b @ dF[b]`` (eq. 4.2.4 in matrix form, :func:`force_rows`)."""
    m = int(offsets[-1])
    parts: list[list] = [[] for _ in surfaces]
    for k, pair in enumerate(pairs):
        n = len(pair.nodes)
        own = ((np.arange(n), pair.nodes, np.ones(n)) if pair.at is None
               else nonzeros(pair.at))
        for body, (i, node, w), sign in ((pair.fine, own, 1.0),
                                         (pair.coarse, nonzeros(pair.interp), -1.0)):
            dim = surfaces[body].dim
            for j, direction in enumerate(directions[k]):
                along = pair.reading(j, direction)
                for d in range(dim):
                    parts[body].append((offsets[k] + j * n + i, dim * node + d,
                                        sign * w * along[i, d]))
    return [_csr(ps, (m, s.dim * s.nc)) for s, ps in zip(surfaces, parts)]


def _csr(parts: list, shape: tuple[int, int]) -> sp.csr_matrix:
    """The sparse matrix of (rows, cols, values) parts."""
    if not parts:
        return sp.csr_matrix(shape)
    return sp.csr_matrix((np.concatenate([p[2] for p in parts]),
                          (np.concatenate([p[0] for p in parts]),
                           np.concatenate([p[1] for p in parts]))), shape=shape)


def platen_rows(surfaces: list, platen_body: int | None, dF: list[sp.csr_matrix], m: int
                ) -> np.ndarray:
    """The platen's reaction per unit traction value (zero without a platen)."""
    dR = np.zeros(m)
    if platen_body is not None:
        s = surfaces[platen_body]
        dR = np.asarray(dF[platen_body].T @ s.platen_row).ravel()
    return dR


#: W is kept sparse (:func:`pair_matrix`, ``sparse_ok``) where its bodies' blocks cover at most
#: this fraction of it: pairs that share no body do not couple (a stack of plates: W block
#: tridiagonal), and a dense W over many pairs is O(m^2) memory and its solves O(m^3) on every
#: MPI rank (docs/scaling.md, issue 40). Dense factorizations are faster than sparse ones on a
#: matrix this full or fuller, so a few bodies' W stays dense.
SPARSE_DENSITY = 0.25

#: ... and it has at least this many unknowns (below, dense solves take milliseconds)
SPARSE_MIN = 1000


def pair_matrix(surfaces: list, pairs: list, directions: list[list[np.ndarray]],
                offsets: np.ndarray, dF: list[sp.csr_matrix], platen_rates: list[np.ndarray],
                executor, sparse_ok: bool = False):
    """W over every unknown of every pair (dense (m, m), sparse where ``sparse_ok`` and its
    bodies' blocks cover little of it (:data:`SPARSE_DENSITY`), or the operator that applies
    it) and the readings' change per unit platen motion ((m,): ``platen_rates``, per pair and
    direction in the unknowns' order, concatenated). Each body's motion under the unit forces
    is computed on the rank that owns it (``executor``)."""
    m = int(offsets[-1])
    dp_dplaten = np.concatenate(platen_rates or [np.zeros(0)])
    if any(s.matrix_free for s in surfaces):
        W = PairOperator(surfaces, [s.flexibility for s in surfaces], dF,
                         read_rows(surfaces, pairs, directions, offsets), executor)
        return W, dp_dplaten

    read = read_rows(surfaces, pairs, directions, offsets)
    # W's entries that may be nonzero: pairs k and l couple where they share a body
    touches = np.zeros((len(pairs), len(surfaces)))
    for k, pair in enumerate(pairs):
        touches[k, [pair.fine, pair.coarse]] = 1.0
    sizes = np.diff(offsets).astype(float)
    covered = float(sizes @ ((touches @ touches.T) > 0) @ sizes) if len(pairs) else 0.0
    if sparse_ok and m >= SPARSE_MIN and covered <= SPARSE_DENSITY * m * m:
        # each body's block: the unknowns that read its motion (rows) by those that force it
        rows = [np.flatnonzero(np.diff(r.indptr)) for r in read]
        cols = [np.unique(f.indices) for f in dF]

        def block(b: int) -> np.ndarray:
            """Body b's block of W (rows[b], cols[b]), on its owner."""
            s = surfaces[b]
            if not len(rows[b]) or not len(cols[b]):
                return np.zeros((len(rows[b]), len(cols[b])))
            f = dF[b][:, cols[b]]
            motion = np.asarray((f.T @ (s.C if s.exactly_symmetric else s.C.T)).T)
            return read[b][rows[b]] @ motion

        # every block to every rank (together the size of the sparse W), summed in the
        # bodies' order on each: the same W everywhere, and the serial run's
        blocks = executor.map(range(len(surfaces)), block)
        W = sp.csr_matrix((np.concatenate([blocks[b].ravel() for b in range(len(surfaces))]),
                           (np.concatenate([np.repeat(rows[b], len(cols[b]))
                                            for b in range(len(surfaces))]),
                            np.concatenate([np.tile(cols[b], len(rows[b]))
                                            for b in range(len(surfaces))]))), shape=(m, m))
        W.sum_duplicates()
        return W, dp_dplaten

    def part(b: int) -> np.ndarray:
        """Body b's part of W, read[b] C_b dF[b], on its owner: its motion under the unit
        forces (C f as (f^T C^T)^T), read at the pairs' points (+) and virtual points (-)
        along each unknown's direction (along the normal: penetration p = -(gap0 + n.(u_f -
        u_c)), W = -dp/dq; along a tangent t: the relative displacement t.(u_f - u_c) per
        unit traction)."""
        s, f = surfaces[b], dF[b]
        if read[b].nnz == 0 or f.nnz == 0:
            return 0.0  # (in no pair: nothing to add, no (m, m) of zeros made)
        motion = np.asarray((f.T @ (s.C if s.exactly_symmetric else s.C.T)).T)
        return read[b] @ motion

    # each body's part where its flexibility is (vfem.parallel: summed over the owners, the
    # sum to every rank; no body's motion sent to every rank)
    W = executor.total(range(len(surfaces)), part, (m, m))
    return W, dp_dplaten
