"""The contact surfaces and what is read on them: facet kinds (the dimension lives here), what
contact reads of a body's mesh and where the bodies lie (the candidates), a body's surface and
its flexibility, the pairing of nodes with virtual nodes on the other surface, and the transfer
of tractions across it.

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .bodymesh import exterior_facets, symmetry_planes
from .closest3d import closest_on_facets
from .facets import FACET_READINGS, kind_of
from .held import corner_spread, held_edges, held_force_directions, held_nodes, held_now
from .pairing import (
    EDGE_RATIO,
    FACING,
    ContactPair,
    Overlap,
    approach_gaps,
    common_normal,
    facing,
    overlap,
    read_facets,
    virtual_nodes,
)
from .placement import check_initial_overlap, select_candidate_facets
from .sides import ContactPairs, Side, SurfacePair, zone_mask, zone_nodes
from .surface import ContactSurface, beyond, patch_ends
from .tangent_basis import tangent_axes, tangents
from .transfer import traction_from_forces

__all__ = [
    "approach_gaps",
    "beyond",
    "check_initial_overlap",
    "closest_on_facets",
    "common_normal",
    "ContactPair",
    "ContactPairs",
    "ContactSurface",
    "EDGE_RATIO",
    "exterior_facets",
    "FACET_READINGS",
    "FACING",
    "facing",
    "corner_spread",
    "held_edges",
    "held_force_directions",
    "held_nodes",
    "held_now",
    "kind_of",
    "Overlap",
    "overlap",
    "patch_ends",
    "read_facets",
    "select_candidate_facets",
    "Side",
    "SurfacePair",
    "symmetry_planes",
    "tangent_axes",
    "tangents",
    "traction_from_forces",
    "virtual_nodes",
    "zone_mask",
    "zone_nodes",
]
