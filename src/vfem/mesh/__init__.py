"""Built-in parametric meshes for the examples."""

from .parametric import graded_layer, graded_quarter_disk, march

__all__ = ["graded_layer", "graded_quarter_disk", "march"]
