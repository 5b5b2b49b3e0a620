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
