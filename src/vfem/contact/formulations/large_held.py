"""The held nodes of large kinematics (issue 41; issue 37's both surfaces enforced, moved to the
current configuration): the equilibrium side's nodes held by point forces against the
compatibility surface where they would penetrate, paired anew in every Newton iteration
(:func:`pair_held`), their guards among a correction's unknowns (:func:`set_guards`), and
those held whatever their guard, deeper than the other surface's faceting explains
(:func:`hold_protruding`).

Functions of the formulation ``form`` (a :class:`~vfem.contact.formulations.large.
LargeDeformationContact`), as :mod:`.follower` is.
"""

from __future__ import annotations

import logging

import numpy as np

from ..geometry import corner_spread, held_now
from ..state import ContactState

log = logging.getLogger(__name__)


def held_patches(form, pair) -> tuple[np.ndarray, np.ndarray] | None:
    """A held pair's patches on the current geometry (its own side's, the other's): its
    compatibility pair's, just paired
    (:meth:`~vfem.contact.formulations.large.LargeDeformationContact.penetrations`), or None
    where the two surfaces no longer face each other."""
    forward = form._guarding_pair(pair)
    if forward is None or form.contact_pairs[forward].patches is None:
        return None
    fpatch, cpatch = form.contact_pairs[forward].patches
    return cpatch, fpatch


def pair_held(form, state: ContactState, k: int, x: list[np.ndarray]) -> np.ndarray:
    """Pair k's held nodes (a ``point`` pair: the equilibrium side's nodes,
    :func:`~vfem.contact.formulations.pairmaking.held_anew`) paired anew on the current
    geometry (:func:`~vfem.contact.geometry.held.held_now`): their force and gap
    directions, virtual nodes, transfer and guards; returns their penetrations (a node past
    the other patch carries nothing)."""
    pair = form.contact_pairs[k]
    patches = held_patches(form, pair)
    if patches is None:
        pair.carries = np.zeros(len(pair.nodes), dtype=bool)
        form.tractions(state, k)[:] = 0.0
        return np.full(len(pair.nodes), -np.inf)
    s, so = form.surfaces[pair.fine], form.surfaces[pair.coarse]
    start = form._unknown_offsets()[k]
    fixed = pair.feature | form._forced_of(start, len(pair.nodes))
    (pair.normal, pair.gap_normal, gap, pair.interp, pair.transfer, pair.rind_depth, past,
     pair.guard) = held_now(s, so, x[pair.fine], x[pair.coarse], pair.nodes, *patches,
                            fixed)
    pair.carries = ~past
    pair.patches = patches
    form.tractions(state, k)[past] = 0.0
    return -gap


def set_guards(form, sets: list[np.ndarray]
               ) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The held nodes among a correction's unknowns (per pair its nodes ``sets``, in
    order) and each one's guard among them: the positions of the compatibility nodes of
    the facet its virtual node lies on (-1 for one not among them, which never touches,
    and for a held node past the other patch, a feature or one
    :meth:`~vfem.contact.formulations.pairset.PairSet.enforce` holds);
    (None, None) where none is held."""
    pairs = form.contact_pairs
    if not any(p.point for p in pairs):
        return None, None
    starts = np.cumsum([0] + [len(s_) for s_ in sets])
    reserve = np.concatenate([np.full(len(s_), pair.point) for pair, s_ in zip(pairs, sets)])
    width = max(p.guard.shape[1] for p in pairs if p.point)
    guard = np.full((len(reserve), width), -1)
    for k, (pair, s_) in enumerate(zip(pairs, sets)):
        forward = form._guarding_pair(pair) if pair.point else None
        if forward is None or not len(s_):
            continue
        where = np.full(form.surfaces[pair.coarse].nc + 1, -1)
        where[pairs[forward].nodes[sets[forward]]] = (starts[forward]
                                                      + np.arange(len(sets[forward])))
        g = where[pair.guard[s_]]  # (-1, none, reads the last entry: -1)
        guard[starts[k]:starts[k + 1], : g.shape[1]] = g
    return reserve, guard


def hold_protruding(form, state: ContactState, pens: list[np.ndarray],
                    traction_values: list[np.ndarray]) -> int:
    """Hold, for the rest of the step (as
    :meth:`~vfem.contact.formulations.pairset.PairSet.enforce` does), every held node that
    its guard excuses (the compatibility nodes of the facet under it all touching) but that
    lies deeper inside that facet than the facet's own faceting explains: ``(L/2) tan(a/2)``,
    L the facet's size and a the angle between the compatibility surface's normals at its
    corners (the most a node on the curve through them can lie beyond the chord). Returns how
    many it held (the state then is not converged: the next correction holds them).

    **Why**: the guard leaves such a node out because between compatibility nodes in contact
    the other surface protrudes by the compatibility side's faceting, two conditions of
    nearly one where it is held (:func:`~vfem.contact.geometry.held.held_nodes`). A node that
    lies deeper protrudes by its own surface's turning: a contact the compatibility side's
    nodes miss. Measured on random model 2d-234 under ``--large`` (a soft punch's straight
    face on a stiffer block whose corner it overhangs): a block node 0.096 from the nearest
    punch node, where the block's surface bends by 0.2 degrees, converged 1.5e-4 (2.3 % of
    the push) inside the punch's straight facet."""
    held = 0
    x = form.positions(state)
    tol = form.penetration_tolerance
    offsets = form._unknown_offsets()
    for k, pair in enumerate(form.contact_pairs):
        guarded = form._guard_touching(pair, traction_values)
        if guarded is None or pair.patches is None or not len(pair.nodes):
            continue
        free = ~form._forced_of(offsets[k], len(pair.nodes))
        ask = np.flatnonzero(guarded & free & (traction_values[k] <= 0) & (pens[k] > tol))
        if not len(ask):
            continue
        so = form.surfaces[pair.coarse]
        corners = pair.guard[ask][:, : so.kind.corners]
        size, turn = corner_spread(x[pair.coarse][corners],
                                   so.node_normals(x[pair.coarse], pair.patches[1])[corners])
        deep = ask[pens[k][ask] > tol + 0.5 * size * np.tan(0.5 * np.minimum(turn, 0.5 * np.pi))]
        if not len(deep):
            continue
        if form._forced is None:
            form._forced = np.zeros(offsets[-1], dtype=bool)
        form._forced[offsets[k] + deep] = True
        held += len(deep)
    if held:
        log.info("%d held nodes deeper inside the other surface than its faceting explains: "
                 "held", held)
    return held
