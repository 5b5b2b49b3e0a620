"""The follower stiffness of large-kinematics contact: how the nodal contact forces turn with
the surfaces they act on, at fixed traction values (the coupling :mod:`.large`'s Newton
correction linearises; thesis Ch. 2-3, the forces act along the current normals).

Functions of the formulation ``form`` (a :class:`~vfem.contact.formulations.large.
LargeDeformationContact` or its frictional variant), which supplies the pairing on the current
geometry (``_normals_at``, ``_forces_at``, ``_traction_change``, ``positions``, ``tractions``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..geometry import ContactSurface
from ..state import ContactState


def facet_neighbours(s: ContactSurface) -> list[np.ndarray]:
    """Per candidate node of ``s``: the nodes of the facets it is on (itself included); the
    surface's topology, found once."""
    if getattr(s, "_facet_neighbours", None) is None:
        inc = s.incidence()
        adj = (inc @ inc.T + sp.identity(s.nc, format="csr")).tocsr()
        adj.sort_indices()
        s._facet_neighbours = np.split(adj.indices, adj.indptr[1:-1])
    return s._facet_neighbours


def follower_stiffness(form, state: ContactState, coloured: bool = True
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The derivative B of the stacked candidate nodal forces with respect to the stacked
    candidate positions, at fixed traction values: its nonzero columns J and B[:, J].

    The forces depend on the positions of the compatibility-side nodes carrying traction
    (through where their virtual nodes lie) and of the opposing nodes around those virtual
    nodes (through the normals there). By forward differences of the loaded nodes' normals
    (``form._normals_at``).

    **Coloured** (issue 19: one evaluation per coordinate took a quarter of the sliding
    example): the coordinates that move disjoint sets of loaded nodes' normals
    (:func:`follower_moves`) are perturbed together, one evaluation for each such group;
    each column is the change of the forces of the nodes it moves, each node's force
    change ``N_A q_A dn_A`` (and ``-T_A q_A dn_A`` on the other side; a held node's point
    force, which reaches the other surface through the shape functions at its virtual node,
    also moves with that node: ``-dT_A q_A n_A``, without which Newton's method converged
    only linearly in the sliding example, 8 iterations a step against 5). With
    ``coloured=False`` (kept for the test that compares the two) each coordinate is
    perturbed alone and its column is the difference of all the forces
    (``form._forces_at``); the two agree to the round-off of that difference.
    """
    x = form.positions(state)
    off = form._offsets
    coords: set[int] = set()
    for k, pair in enumerate(form.contact_pairs):
        on = np.flatnonzero(form.tractions(state, k) != 0)
        if not len(on):
            continue
        sc = form.surfaces[pair.coarse]
        seg = sc.closest(x[pair.fine][pair.nodes[on]], x[pair.coarse])[0]
        near = np.isin(sc.facets, sc.facets[seg]).any(axis=1)  # the facets and neighbours
        for body, nodes in ((pair.fine, pair.nodes[on]), (pair.coarse, sc.facets[near])):
            nodes = np.unique(nodes)
            coords.update((off[body] + form.surfaces[body].dofs_of(nodes)).tolist())
    J = np.array(sorted(coords), dtype=int)
    if not len(J):
        return J, np.zeros((off[-1], 0))
    h = 1e-7 * max(float(s.sizes.max()) for s in form.surfaces)
    body_of = np.searchsorted(off, J, side="right") - 1
    Bj = np.zeros((off[-1], len(J)))

    def perturbed(group):
        xp = list(x)
        for col in group:
            j, b = J[col], body_of[col]
            if xp[b] is x[b]:
                xp[b] = x[b].copy()
            dim = form.surfaces[b].dim
            xp[b][(j - off[b]) // dim, (j - off[b]) % dim] += h
        return xp

    if not coloured:
        base = form._forces_at(state, x)
        for col in range(len(J)):
            Bj[:, col] = (form._forces_at(state, perturbed([col])) - base) / h
        return J, Bj
    base_n = form._normals_at(state, x)
    groups, moves = follower_moves(form, base_n, J, body_of)
    for group in groups:
        pert_n = form._normals_at(state, perturbed(group))
        for col in group:
            for k, pair in enumerate(form.contact_pairs):
                hit = moves[k][col]
                if not len(hit):
                    continue
                on = base_n[k][0][hit]
                dqn = form._traction_change(state, k, on, base_n[k][1][hit],
                                            pert_n[k][1][hit], h)
                nodes = pair.nodes[on]
                for side, M, sign in ((pair.fine, pair.mass, 1.0),
                                      (pair.coarse, pair.transfer, -1.0)):
                    Bj[off[side]:off[side + 1], col] += sign * (M[:, nodes] @ dqn).ravel()
                if base_n[k][3] is not None:  # a held node's force moves with its virtual node
                    qn = form._traction_vectors(state, k, on, base_n[k][1][hit])
                    moved = (pert_n[k][3][hit] - base_n[k][3][hit]) / h
                    Bj[off[pair.coarse]:off[pair.coarse + 1], col] -= (moved.T @ qn).ravel()
    return J, Bj


def follower_moves(form, base: list, J: np.ndarray, body_of: np.ndarray
                   ) -> tuple[list[list[int]], list[list[np.ndarray]]]:
    """Groups of the columns ``J`` of :func:`follower_stiffness` that may be perturbed
    together, and per pair and column the loaded nodes (positions among the pair's loaded
    nodes) whose normals the column's coordinate moves. ``base``: ``form._normals_at`` at
    the unperturbed positions (the loaded nodes and their virtual nodes' facets).

    A coordinate of node n moves, in each pair: if n is on the compatibility side, the
    loaded nodes among n and its facet neighbours (n's own virtual node; the neighbours'
    nodal normals, which break projection ties); if n is on the other side, the loaded nodes
    whose virtual node lies on a facet with a node among n's facet neighbours (n's facets
    move, the nodal normals of their nodes turn, and a projection may pass to a facet
    sharing a vertex with its own). Two coordinates join a group when they move no node in
    common (greedy, in column order).
    """
    off = form._offsets
    neighbours = [facet_neighbours(s) for s in form.surfaces]
    empty = np.zeros(0, dtype=int)
    moves: list[list[np.ndarray]] = [[empty] * len(J) for _ in form.contact_pairs]
    node_of = (J - off[body_of]) // np.array([form.surfaces[b].dim for b in body_of])
    for k, (pair, (on, _, seg, _)) in enumerate(zip(form.contact_pairs, base)):
        if not len(on):
            continue
        sf, sc = form.surfaces[pair.fine], form.surfaces[pair.coarse]
        nodes = pair.nodes[on]
        local = np.full(sf.nc, -1)
        local[nodes] = np.arange(len(nodes))
        # coarse node -> the loaded nodes with a virtual node on a facet at it
        on_facet = np.zeros((sc.nc, len(nodes)), dtype=bool)
        for col_nodes in sc.facets[seg].T:
            on_facet[col_nodes, np.arange(len(nodes))] = True
        for col, (b, n) in enumerate(zip(body_of, node_of)):
            hit = np.zeros(len(nodes), dtype=bool)
            if b == pair.fine:
                i = local[neighbours[b][n]]
                hit[i[i >= 0]] = True
            if b == pair.coarse:
                hit |= on_facet[neighbours[b][n]].any(axis=0)
            moves[k][col] = np.flatnonzero(hit)
    groups: list[list[int]] = []
    taken: list[list[set]] = []
    for col in range(len(J)):
        mine = [set(m[col].tolist()) for m in moves]
        for group, used in zip(groups, taken):
            if all(u.isdisjoint(m) for u, m in zip(used, mine)):
                group.append(col)
                for u, m in zip(used, mine):
                    u.update(m)
                break
        else:
            groups.append([col])
            taken.append(mine)
    return groups, moves
