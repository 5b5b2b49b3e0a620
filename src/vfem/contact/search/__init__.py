"""Closest points on a surface's segments and its outward normals: the candidates every later stage
reads (issue 38's pipeline: search → geometry → laws → solvers → formulations → invariants).

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .closest import normal_of_tangent, outward_normals, project_points

__all__ = ["normal_of_tangent", "outward_normals", "project_points"]
