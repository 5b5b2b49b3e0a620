"""Built-in parametric meshes for the examples."""

from .parametric import graded_layer, graded_quarter_disk, march
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

__all__ = [
    "block",
    "gasket",
    "gasket_pair",
    "graded_layer",
    "graded_nodes",
    "graded_quarter_disk",
    "march",
    "rectangle",
    "wedge",
    "wedge_grid",
    "wedge_plate",
    "wedge_plate_grid",
]
