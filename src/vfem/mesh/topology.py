"""scikit-fem's facet topology of a mesh, built once and carried along to the mesh's copies.

A scikit-fem mesh builds its facets (``facets``, ``t2f``) and their elements (``f2t``) lazily,
on first use, with a ``np.unique`` over the columns of the facets' node pairs (a lexicographic
sort of structured values) and two more ``np.unique`` for ``f2t``; and every copy of the mesh
(``with_boundaries``, ``dataclasses.replace``) starts without them. A built-in shape naming
its boundaries then paid for them twice, and the mesh checks a third time: at a million
triangles, about 2.5 s each. :func:`with_topology` builds the same arrays (same values, order
and types) from one stable sort of one integer key per element facet, and
:func:`share_topology` hands them to a copy of the mesh with the same elements.
:func:`named_boundaries` is ``Mesh.with_boundaries`` evaluated on the boundary facets only.

In 3D a facet has 3 (tetrahedra) or 4 (hexahedra) nodes: the facets are the sorted node tuples
in lexicographic order, found by one stable ``np.lexsort`` (the same order as scikit-fem's
``np.unique(..., axis=1)``); a hexahedral mesh keeps each facet's nodes as its first element
lists them (scikit-fem's ``MeshHex1`` builds its facets unsorted, in cyclic order).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace

import numpy as np
from skfem import Mesh

#: The attributes where scikit-fem caches a mesh's facets (see ``Mesh.facets``, ``Mesh.t2f``
#: and ``Mesh.f2t``).
CACHED = ("_facets", "_t2f", "_f2t")


def facet_topology(t: np.ndarray, indices, sort: bool = True
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(facets, t2f, f2t) of the elements ``t`` (nodes, ne) whose local facets are the node
    pairs ``indices`` (the reference element's ``facets``), as scikit-fem builds them.
    Facets of 3 or 4 nodes (3D): :func:`_facet_tuples`, with ``sort`` as scikit-fem's
    ``Mesh.build_entities`` (False: each facet's nodes as its first occurrence lists them).

    ``facets`` (2, nf): each facet's two nodes, smaller first, the facets in lexicographic
    order of those pairs; ``t2f`` (len(indices), ne): each element's facets; ``f2t`` (2, nf):
    the first and last element holding each facet in the order of ``t2f`` flattened by rows,
    the second -1 on the boundary. One stable argsort of ``lo * n + hi`` (n: one more than the
    largest node) orders the pairs as ``np.unique(..., axis=1)`` does and finds, in each run of
    equal keys, the first and the last occurrence that ``Mesh.build_inverse`` looks for.
    """
    t = np.asarray(t)
    ne = t.shape[1]
    if len(indices[0]) != 2:
        return _facet_tuples(t, indices, sort)
    pairs = np.hstack([t[list(ix)] for ix in indices])  # (2, len(indices) * ne)
    lo, hi = np.minimum(pairs[0], pairs[1]), np.maximum(pairs[0], pairs[1])
    n = np.int64(int(hi.max()) + 1 if hi.size else 1)
    key = lo.astype(np.int64) * n + hi
    order = np.argsort(key, kind="stable")
    ordered = key[order]
    first = np.ones(len(key), dtype=bool)
    first[1:] = ordered[1:] != ordered[:-1]
    starts = np.flatnonzero(first)
    ends = np.r_[starts[1:], len(key)] - 1
    unique = ordered[starts]
    facets = np.ascontiguousarray(np.vstack([unique // n, unique % n]).astype(t.dtype))
    inverse = np.empty(len(key), dtype=np.intp)
    inverse[order] = np.cumsum(first) - 1
    t2f = inverse.reshape(len(indices), ne)
    f2t = np.vstack([order[starts] % ne, order[ends] % ne]).astype(np.int32)
    f2t[1, f2t[0] == f2t[1]] = -1
    return facets, t2f, f2t


def _facet_tuples(t: np.ndarray, indices, sort: bool
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`facet_topology` for facets of any number of nodes: the facets' sorted node
    tuples ordered by one stable ``np.lexsort`` (first node first: the order of
    ``np.unique(..., axis=1)``); each run of equal tuples gives one facet, its first and last
    occurrence its elements (as ``Mesh.build_inverse``)."""
    ne = t.shape[1]
    indexing = np.hstack([t[list(ix)] for ix in indices])  # (k, len(indices) * ne)
    tuples = np.sort(indexing, axis=0)
    order = np.lexsort(tuples[::-1])  # stable: equal tuples keep their order of occurrence
    ordered = tuples[:, order]
    first = np.ones(indexing.shape[1], dtype=bool)
    first[1:] = (ordered[:, 1:] != ordered[:, :-1]).any(axis=0)
    starts = np.flatnonzero(first)
    ends = np.r_[starts[1:], indexing.shape[1]] - 1
    source = ordered if sort else indexing[:, order]
    facets = np.ascontiguousarray(source[:, starts])
    inverse = np.empty(indexing.shape[1], dtype=np.intp)
    inverse[order] = np.cumsum(first) - 1
    t2f = inverse.reshape(len(indices), ne)
    f2t = np.vstack([order[starts] % ne, order[ends] % ne]).astype(np.int32)
    f2t[1, f2t[0] == f2t[1]] = -1
    return facets, t2f, f2t


def _sorts_facets(mesh: Mesh) -> bool:
    """Whether scikit-fem builds ``mesh``'s facets with their nodes sorted (every mesh but the
    hexahedral ones, whose ``_init_facets`` keeps them in cyclic order)."""
    return type(mesh)._init_facets is Mesh._init_facets


def with_topology(mesh: Mesh) -> Mesh:
    """``mesh`` itself, its facets, ``t2f`` and ``f2t`` built (:func:`facet_topology`) unless
    it already has them. Only scikit-fem's lazy caches are filled, with the values it would
    compute; nothing else of the mesh changes."""
    if mesh.t.shape[1] and not all(hasattr(mesh, name) for name in CACHED):
        # (no elements: scikit-fem's own path, and its own error, as before)
        topology = facet_topology(mesh.t, mesh.elem.refdom.facets, _sorts_facets(mesh))
        for name, value in zip(CACHED, topology):
            setattr(mesh, name, value)
    return mesh


def share_topology(source: Mesh, copy: Mesh) -> Mesh:
    """``copy`` given the facet topology of ``source`` where both have the same elements (as a
    copy made by ``dataclasses.replace`` has); ``copy`` unchanged otherwise."""
    if (all(hasattr(source, name) for name in CACHED) and source.t.shape == copy.t.shape
            and source.elem.refdom is copy.elem.refdom and np.array_equal(source.t, copy.t)):
        for name in CACHED:
            setattr(copy, name, getattr(source, name))
    return copy


def named_boundaries(mesh: Mesh, tests: Mapping[str, Callable[[np.ndarray], np.ndarray]]
                     ) -> Mesh:
    """``mesh.with_boundaries(tests)`` (boundary facets only), its facet topology kept.

    Each test takes the facets' midpoints (2, k) and returns a boolean per column, as
    scikit-fem's tests do; here it sees the boundary facets' midpoints only, which gives the
    same facets (ascending, ``int32``) for tests that judge each point by itself, as the
    built-in shapes' do, without the midpoints and the set intersections of every facet. An
    array instead of a test is taken as the boundary's facets, as by scikit-fem.
    """
    with_topology(mesh)
    boundary = mesh.boundary_facets()
    midpoints = mesh.p[:, mesh.facets[:, boundary]].mean(axis=1)
    named = {name: boundary[np.asarray(test(midpoints), dtype=bool)] if callable(test) else test
             for name, test in tests.items()}
    copy = replace(mesh, _boundaries={**(mesh.boundaries or {}), **named})
    return share_topology(mesh, copy)


def centred(mesh: Mesh) -> tuple[Mesh, np.ndarray]:
    """``mesh`` moved to the centre of its bounding box, and that centre ((dim,): add it to a
    point of the moved mesh to find where it is). What a scikit-fem ``FacetBasis`` is built on:
    it maps the facets' points into their elements by Newton's iteration to an absolute 1e-12
    in the element's coordinates, which the round-off of coordinates a thousand elements from
    the origin does not reach (an O-ring's section at r = 100 in elements of 0.1: "Newton
    iteration didn't converge"). The facets and named boundaries are the mesh's."""
    centre = 0.5 * (mesh.p.min(axis=1) + mesh.p.max(axis=1))
    return mesh.translated(tuple(float(c) for c in -centre)), centre
