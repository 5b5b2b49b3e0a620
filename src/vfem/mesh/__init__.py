"""Built-in parametric meshes for the examples (2D: :mod:`.shapes`, :mod:`.parametric`; 3D:
:mod:`.solids`).

Each shape returns its mesh with scikit-fem's facet topology already built, once
(:mod:`vfem.mesh.topology`): at a million elements, scikit-fem's own lazy build took seconds
and was repeated for every copy of the mesh.
"""

from .parametric import graded_half_disk, graded_layer, graded_quarter_disk, march
from .shapes import (
    block,
    gasket,
    gasket_pair,
    graded_nodes,
    rectangle,
    wedge,
    wedge_grid,
    wedge_plate,
    wedge_plate_grid,
)
from .solids import box

__all__ = [
    "block",
    "box",
    "gasket",
    "gasket_pair",
    "graded_layer",
    "graded_nodes",
    "graded_half_disk",
    "graded_quarter_disk",
    "march",
    "rectangle",
    "wedge",
    "wedge_grid",
    "wedge_plate",
    "wedge_plate_grid",
]
