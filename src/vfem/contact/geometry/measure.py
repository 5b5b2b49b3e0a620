"""The measure of a 2D contact surface: what N* (eq. 4.4.10) integrates, in its body's section's
measure (:meth:`ContactSurface.weight
<vfem.contact.geometry.surface.ContactSurface.weight>`: the mesh's length, times 2πr on a
body of revolution), and the virtual elements' Gauss points (in the mesh's length: the thesis
variant weighs the opposing traction by the opposing body's measure).
:class:`~vfem.contact.geometry.surface.ContactSurface` asks here (``mass_matrix``,
``quadrature``); the transfer's overlap quadrature weights as N* does
(:meth:`Segment.overlap_quadrature <vfem.contact.geometry.facets.Segment.overlap_quadrature>`),
and the invariants' consistent tension measure by the section's
:meth:`~vfem.bodies.section.Section.facet_mass`."""

from __future__ import annotations

import numpy as np
from skfem import BilinearForm, ElementLineP1, FacetBasis
from skfem.quadrature import get_quadrature
from skfem.refdom import RefLine

from ...errors import InputError
from ...mesh.topology import centred
from .bodymesh import _most_distorted


def virtual_quadrature(surface, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss points of the virtual elements on each candidate facet of ``surface``.

    Returns (xi, phi, w): local coordinates (nq,), shape function values (2, nq) of the
    facet's own 2-node element, and weights per facet (nf, nq) times the undeformed length.
    The thesis variant integrates the opposing traction over them in the opposing body's
    measure (its section's weight at the opposing point,
    :meth:`~vfem.contact.formulations.algorithm.VirtualElementContact._virtual_forces`): the
    own side's weight cancels out of the nominal traction carried across.
    """
    X, W = get_quadrature(RefLine, order)
    e = ElementLineP1()
    phi = np.vstack([e.lbasis(X, i)[0] for i in range(2)])
    return X[0], phi, surface.lengths[:, None] * W[None, :]


def facet_mass_entries(surface):
    """(facet, row, col, value) of every nonzero of every candidate facet's mass matrix
    ∫φφᵀ (times the section's weight) on the undeformed facet, by scikit-fem."""
    # on the mesh moved to its own centre (:func:`~vfem.mesh.topology.centred`); the weight
    # reads the points where they are
    moved, centre = centred(surface.body.mesh)
    try:
        fb = FacetBasis(moved, surface.body.element(), facets=surface.facet_ids)
    except Exception as exc:  # noqa: BLE001 - scikit-fem raises a bare Exception here
        # its map of the facets' quadrature points into their quadrilaterals (Newton's
        # iteration on the isoparametric map) failed: an element along the surface so
        # distorted that the map barely turns (a thin row on a steep part of a curve)
        raise InputError(
            f"body {surface.body.name!r}: the quadrature points of its contact facets could "
            f"not be mapped into their elements ({exc}); "
            f"{_most_distorted(surface.body.mesh, surface.facet_ids)} is too distorted: refine "
            "or regrade the mesh along the contact surface") from exc

    section = surface.body.section  # the boundary's measure (vfem.bodies.section)

    @BilinearForm
    def mass(u, v, w):
        return w["tag"] * u * v * section.weight(np.asarray(w.x) + centre.reshape(-1, 1, 1))

    nq = fb.X.shape[1]
    # scikit-fem's unsummed (per facet) entries; the tag tells which facet each came from
    ones = mass.coo_data(fb, tag=np.ones((len(surface.facet_ids), nq)))
    tagged = mass.coo_data(fb, tag=np.repeat(
        np.arange(1.0, len(surface.facet_ids) + 1)[:, None], nq, axis=1))
    # entries of the element's nodes off the facet vanish (to round-off) on the facet
    keep = np.abs(ones.data) > 1e-12 * np.abs(ones.data).max()
    facet = np.rint(tagged.data[keep] / ones.data[keep]).astype(int) - 1
    local = np.full(surface.body.npoints, -1)
    local[surface.nodes[: surface.nc]] = np.arange(surface.nc)
    rows, cols = local[ones.indices[0][keep]], local[ones.indices[1][keep]]
    return facet, rows, cols, ones.data[keep]
