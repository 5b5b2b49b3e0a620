"""A contact surface that finds its own two sides (single-surface self-contact, issue 42).

A body whose surface may touch itself (``self_contact = true``, or a ``contact_pairs`` entry
naming one side twice, ``["ring:bore", "ring:bore"]``) is made one self-contact pair of two
sides, as if they had been named (:class:`~.sides.Side`, ``docs/method.md`` §15). The sides
are found here, once, on the undeformed geometry (:func:`split`):

1. **What a facet sees.** A ray from the facet's centre (the kind's first reading: a segment's
   midpoint, a triangle's or quadrilateral's centre) along its outward normal there; the first
   facet of the same surface it enters (:func:`~.pairing.ray_facet`), passing through the
   facet's own **neighbourhood** -- itself and every facet sharing a node with it -- and only
   if that facet faces it (:func:`~.pairing.opposed`: normals at least 120 degrees apart, the
   pairing's FACING rule). Seeing is made symmetric (f sees g where g sees f).
   **Why the neighbourhood is left out:** a node's closest point on a facet next to it is the
   node they share, at distance zero: read against its own neighbours every node of a curved
   or cornered boundary would be "touching". A ray entering a neighbour is a concave corner
   of the boundary (a notch's root), not another part of it.
2. **Runs.** The facets that see something, joined through shared nodes (2D: stretches along
   the boundary; 3D: patches joined by an edge or a node).
3. **Two sides.** The runs as a graph (run R -- run S where a facet of R sees one of S),
   coloured in two by breadth-first search from the run with the lowest mesh facet number in
   each connected part (so the order the facets are listed in never matters): colour 0 is side
   1, colour 1 side 2. The two sides so share no node.

Refused (:class:`~vfem.errors.InputError`): a run that sees itself (a round bore: every point
faces its antipode on one closed stretch) or runs seeing each other in an odd cycle: at rest
the two sides are not told apart by the geometry, and under large kinematics a split would
have to follow the deformation (not built). Nothing seen at all: no pair (a warning).
"""

from __future__ import annotations

import logging
from collections import deque

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ...errors import InputError
from .pairing import opposed, ray_facet
from .surface import ContactSurface

log = logging.getLogger(__name__)


def split(body, facets: np.ndarray, where: str, names: tuple[str, ...] | None = None
          ) -> tuple[np.ndarray, np.ndarray] | None:
    """The two sides of ``body``'s surface ``facets`` (mesh facet ids) that may touch each
    other, found on the undeformed geometry (module docstring): (side 1, side 2) as sorted mesh
    facet ids, or None where no facet sees another (logged as a warning). ``where`` begins
    the messages; ``names``: the boundaries the surface was named by (None: the body's whole
    contact surface), of which a refusal names those the offending facets lie on.

    Kept on the body for its mesh, order and ``facets``: a model's pairs are read several times
    (its check, its surfaces, the invariants), the split and its warning once.

    Raises:
        InputError: a stretch of the surface that sees itself, or an odd cycle.
    """
    facets = np.unique(np.asarray(facets, dtype=np.int64))
    kept = body.__dict__.setdefault("_own_sides", {})
    key = (id(body.mesh), body.order, facets.tobytes())
    if key not in kept:
        kept[key] = _split(body, facets, where, names)
    return kept[key]


def sees(s: ContactSurface) -> tuple[np.ndarray, np.ndarray]:
    """What each facet of ``s`` sees (module docstring, step 1): (f, g) the pairs, f's ray
    entering g first outside f's neighbourhood, g facing it; both ways, each pair once."""
    nf = len(s.facets)
    xi = np.repeat(s.kind.readings[:1], nf, axis=0)  # each facet's centre
    seg = np.arange(nf)
    pos, jn = s.surface_map(seg, xi)
    n = jn / np.maximum(np.linalg.norm(jn, axis=1), 1e-300)[:, None]
    near = neighbourhood(s)
    _, g = ray_facet(s, pos, n, skip=near)
    f = np.flatnonzero(g >= 0)
    g = g[f]
    facing = opposed(n[f], n[g])
    f, g = f[facing], g[facing]
    both = np.unique(np.vstack([np.column_stack([f, g]), np.column_stack([g, f])]), axis=0)
    return both[:, 0], both[:, 1]


def neighbourhood(s: ContactSurface) -> sp.csr_array:
    """(nf, nf) true where two facets of ``s`` share a node (each facet with itself)."""
    nf, k = s.facets.shape
    incidence = sp.csr_array((np.ones(nf * k), (np.repeat(np.arange(nf), k),
                                                s.facets.ravel())), shape=(nf, s.nc))
    return (incidence @ incidence.T).astype(bool).tocsr()


def _split(body, facets: np.ndarray, where: str, names: tuple[str, ...] | None
           ) -> tuple[np.ndarray, np.ndarray] | None:
    s = ContactSurface.build(body, facets, tributary=False)
    if not len(s.facets):
        return None
    f, g = sees(s)
    if not len(f):
        log.warning("%s: no facet of the surface of body %r faces another part of it (a ray "
                    "along each facet's normal meets none facing it): no self-contact pair", where,
                    body.name)
        return None
    seeing = np.unique(f)
    near = neighbourhood(s)[seeing][:, seeing]
    count, label = connected_components(near, directed=False)
    run = np.full(len(s.facets), -1)
    run[seeing] = label
    ids = s.facet_ids
    lowest = np.full(count, np.iinfo(np.int64).max)
    np.minimum.at(lowest, label, ids[seeing])
    rf, rg = run[f], run[g]
    own = rf == rg
    if own.any():
        _refuse(body, ids[seeing[label == rf[own][0]]], where, names,
                "across one closed stretch (a round bore: each point faces the one opposite)")
    colour, clash = two_colours(count, rf, rg, lowest)
    if clash is not None:
        _refuse(body, ids[seeing[np.isin(label, clash)]], where, names,
                "in an odd cycle of parts, each facing the next")
    side = colour[run[seeing]]
    return np.sort(ids[seeing[side == 0]]), np.sort(ids[seeing[side == 1]])


def two_colours(count: int, r: np.ndarray, s: np.ndarray, lowest: np.ndarray
                ) -> tuple[np.ndarray, tuple[int, int] | None]:
    """(count,) colours 0 and 1 of ``count`` runs such that runs ``r[k]`` and ``s[k]`` (which
    see each other) differ, and None; or, where none exists (an odd cycle), the colours so far
    and two runs of one colour that see each other. Breadth-first from the run with the
    ``lowest`` mesh facet number of each connected part, coloured 0: the colours depend on
    the facets' numbers, not on the order they are listed in."""
    links = sp.csr_array((np.ones(len(r)), (r, s)), shape=(count, count))
    links = (links + links.T).tocsr()
    colour = np.full(count, -1)
    for start in np.argsort(lowest, kind="stable"):
        if colour[start] >= 0:
            continue
        colour[start] = 0
        queue = deque([start])
        while queue:
            a = queue.popleft()
            for b in links.indices[links.indptr[a]:links.indptr[a + 1]]:
                if colour[b] < 0:
                    colour[b] = 1 - colour[a]
                    queue.append(b)
                elif colour[b] == colour[a]:
                    return colour, (int(a), int(b))
    return colour, None


def _refuse(body, ids: np.ndarray, where: str, names: tuple[str, ...] | None, how: str):
    """Raise the refusal of a surface whose two sides are not told apart at rest, naming the
    boundaries its offending facets ``ids`` lie on."""
    mesh = body.mesh
    on = [b for b in (names if names is not None else sorted(mesh.boundaries or {}))
          if np.isin(mesh.boundaries[b], ids).any()]
    what = (f" (boundar{'y' if len(on) == 1 else 'ies'} {', '.join(repr(b) for b in on)})"
            if on else "")
    raise InputError(f"{where}: the surface of body {body.name!r}{what} faces itself {how}: "
                     "at rest its two sides cannot be told apart; name them as the pair's two "
                     f"sides, e.g. ['{body.name}:upper', '{body.name}:lower']")
