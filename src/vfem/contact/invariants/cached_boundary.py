"""What the invariants' boundary geometries share in 2D
(:class:`vfem.contact.invariants.polygon._Polygon`) and 3D
(:class:`vfem.contact.invariants.check3d.Surface3`): a body's boundary at positions ``x``, each
quantity computed on first use and kept, the surface (the facets off symmetry planes) and the
bounding box."""

from __future__ import annotations

import numpy as np


class CachedBoundary:
    """A body's boundary ``boundary`` (its ``mirror``: per facet, on a symmetry plane) at
    positions ``x`` ((nb, dim), local numbering)."""

    #: invariant (b) asks ``inside`` of every node of another body in this one's box when
    #: there are fewer than this, without first ruling out those that cannot have entered
    #: (:meth:`~vfem.contact.invariants.check.InvariantCheck._may_enter`): below it, the
    #: bound's own arithmetic costs about what asking the nodes it rules out would
    bound_from = 0

    def __init__(self, boundary, x: np.ndarray):
        self.b, self.x = boundary, x
        self._cache: dict = {}

    def _get(self, key, make):
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    @property
    def surface(self) -> np.ndarray:
        """The facets that are surface (not on a symmetry plane); all of them if every one is."""
        return self._get("surface", lambda: np.flatnonzero(~self.b.mirror)
                         if (~self.b.mirror).any() else np.arange(len(self.b.mirror)))

    @property
    def box(self) -> tuple[np.ndarray, np.ndarray]:
        return self._get("box", lambda: (self.x.min(axis=0), self.x.max(axis=0)))


def scatter_add(n: int, index: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(n, d): each row of ``values`` (m, d) added at row ``index`` (m,) of zeros, in the
    order given: ``np.add.at``'s sums bit for bit (both add one term after another from 0),
    by ``np.bincount`` per column, some ten times faster than ``np.add.at`` on rows."""
    index = np.asarray(index, dtype=np.int64).ravel()
    values = np.asarray(values, dtype=float)
    values = values.reshape(len(index), values.shape[-1])
    return np.column_stack([np.bincount(index, values[:, c], minlength=n)
                            for c in range(values.shape[1])]).reshape(n, values.shape[1])
