"""Parametric 3D meshes (issue 21): numpy and scikit-fem only, no mesher.

:func:`box` is the 3D :func:`~vfem.mesh.shapes.rectangle` and :func:`~vfem.mesh.shapes.block`:
a tensor grid of hexahedra (or of tetrahedra, six to a hexahedron), uniform or graded towards
given planes. The axes follow the 2D shapes with z up: ``left``/``right`` are the faces
x = const, ``front``/``back`` the faces y = const (front: the smaller y, the side a viewer
looking along +y sees), ``bottom``/``top`` the faces z = const. Each mesh comes with
scikit-fem's facet topology already built (:mod:`vfem.mesh.topology`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from skfem import MeshHex, MeshTet

from .parametric import check_count
from .shapes import _grid_line
from .topology import named_boundaries

__all__ = ["box", "FACES"]

#: The named faces of :func:`box`: name -> (axis, end) (end 0: the face at the smaller
#: coordinate).
FACES = {"left": (0, 0), "right": (0, 1), "front": (1, 0), "back": (1, 1),
         "bottom": (2, 0), "top": (2, 1)}


def box(x0: float = 0.0, y0: float = 0.0, z0: float = 0.0, width: float = 1.0,
        depth: float = 1.0, height: float = 1.0, nx: int = 1, ny: int = 1, nz: int = 1, *,
        h: float | None = None, h_fine: float | None = None, growth: float = 0.2,
        fine_x: Sequence[float] = (), fine_y: Sequence[float] = (),
        fine_z: Sequence[float] = (), tetrahedra: bool = False) -> MeshHex | MeshTet:
    """The box ``[x0, x0 + width] x [y0, y0 + depth] x [z0, z0 + height]`` as a tensor grid of
    hexahedra (trilinear, scikit-fem's ``MeshHex``), or with ``tetrahedra`` each hexahedron
    split into six tetrahedra around its diagonal from its lowest to its highest corner (Kuhn's
    split: the neighbours' face diagonals agree, so the mesh is conforming).

    Divisions: ``nx`` x ``ny`` x ``nz`` equal ones; or, given ``h``, spacing at most ``h``; or,
    given ``h`` and ``h_fine``, graded: the spacing along x is ``h_fine`` at the planes
    x = ``fine_x`` (for instance under a punch's edge) and grows with ``growth`` per unit
    distance up to ``h``; likewise along y towards ``fine_y`` and along z towards ``fine_z``
    (an axis without fine planes is uniform). Planes of ``fine_*`` inside the box are grid
    planes.

    Named boundaries: ``left`` (x = x0), ``right`` (x = x0 + width), ``front`` (y = y0),
    ``back`` (y = y0 + depth), ``bottom`` (z = z0) and ``top`` (z = z0 + height).
    """
    if not (width > 0 and depth > 0 and height > 0):
        raise ValueError(f"width, depth and height must be positive, got {width}, {depth}, "
                         f"{height}")
    x1, y1, z1 = x0 + width, y0 + depth, z0 + height
    if h is None:
        if not all(isinstance(n, (int, np.integer)) and n >= 1 for n in (nx, ny, nz)):
            raise ValueError(f"nx, ny and nz must be whole numbers >= 1, got {nx}, {ny}, {nz}")
        check_count((nx + 1.0) * (ny + 1.0) * (nz + 1.0), "box")
        lines = [np.linspace(a, b, int(n) + 1) for a, b, n in ((x0, x1, nx), (y0, y1, ny),
                                                                (z0, z1, nz))]
    else:
        for size in (width, depth, height):  # the count first: no line of a billion nodes
            check_count(size / h if h > 0 else float("inf"), "the element size h")
        lines = [_grid_line(a, b, h, h_fine, growth, fine)
                 for a, b, fine in ((x0, x1, fine_x), (y0, y1, fine_y), (z0, z1, fine_z))]
    check_count(float(np.prod([len(v) for v in lines], dtype=float)), "box")
    mesh = (MeshTet if tetrahedra else MeshHex).init_tensor(*lines)
    tol = 1e-9 * max(width, depth, height)
    ends = ((x0, x1), (y0, y1), (z0, z1))

    def face(axis: int, end: int):
        at = ends[axis][end]
        return lambda p: np.abs(p[axis] - at) < tol

    return named_boundaries(mesh, {name: face(axis, end) for name, (axis, end) in FACES.items()})
