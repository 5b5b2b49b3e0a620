"""The contact surfaces and what is read on them: facet kinds (the dimension lives here), a body's
surface and its flexibility, the pairing of nodes with virtual nodes on the other surface, and
the transfer of tractions across it.

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .facets import FACET_READINGS, kind_of
from .facets3d import closest_on_facets
from .pairing import (
    EDGE_RATIO,
    FACING,
    ContactPair,
    Overlap,
    approach_gaps,
    common_normal,
    facing,
    held_edges,
    held_force_directions,
    held_nodes,
    overlap,
    read_facets,
    virtual_nodes,
)
from .surface import (
    ContactSurface,
    beyond,
    check_initial_overlap,
    exterior_facets,
    patch_ends,
    select_candidate_facets,
    symmetry_planes,
)
from .transfer import traction_from_forces

__all__ = [
    "approach_gaps",
    "beyond",
    "check_initial_overlap",
    "closest_on_facets",
    "common_normal",
    "ContactPair",
    "ContactSurface",
    "EDGE_RATIO",
    "exterior_facets",
    "FACET_READINGS",
    "FACING",
    "facing",
    "held_edges",
    "held_force_directions",
    "held_nodes",
    "kind_of",
    "Overlap",
    "overlap",
    "patch_ends",
    "read_facets",
    "select_candidate_facets",
    "symmetry_planes",
    "traction_from_forces",
    "virtual_nodes",
]
