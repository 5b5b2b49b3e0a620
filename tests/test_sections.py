"""A body's section behind one protocol (issue 38: axisymmetric bodies, the next section, are a
class in :mod:`vfem.bodies.section` and an entry in its registry, not a change to every integral).

A section defined here, outside the library, and registered by the material's ``plane`` name
runs through :class:`vfem.bodies.section.Section` alone: a slab of plane strain ``DEPTH`` deep
(its measure ``DEPTH`` everywhere) must give the displacements, stresses and contact pressures of
the slab one deep, and ``DEPTH`` times its forces. A place that integrated over the mesh without
the section's measure — the stiffness, a traction, the contact surface's N* and tributary
lengths — would break the equality: the loads, the contact forces or the pressures would be off
by the factor ``DEPTH`` somewhere and not elsewhere. A constant measure cancels out of what is a
ratio of two integrals on one side (the transfer's N and T against the traction values, the
thesis variant's opposing traction, the invariants' recovered pressure against its largest), so
those are tried with a measure that varies along the surface (:class:`Graded`), or directly.

DEPTH is a power of two, so the deep model's arrays are the shallow one's times DEPTH up to the
order of the floating-point operations; the displacements are compared to 1e-9 of their
largest, the round-off of a contact problem whose flexibility matrices have condition numbers
up to about 1e6 here (1e-16 x 1e6 x margin).
"""

from __future__ import annotations

import numpy as np
import pytest

from models import (
    built,
    input_file,
    pressed,
    rectangle_mesh,
    slid,
    strip_surfaces,
    support,
    toml_body,
    traction,
)
from vfem.bodies.section import SECTIONS, PlaneStrain, section_of
from vfem.bodies.stresses import stress
from vfem.contact.formulations.algorithm import VirtualElementContact
from vfem.contact.geometry import ContactPairs
from vfem.contact.geometry.pairing import overlap
from vfem.contact.invariants.plane import _boundary_mass
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.solver import Analysis

DEPTH = 2.0


class Deep(PlaneStrain):
    """Plane strain over a depth of ``DEPTH``: every measure (and so the stiffness) times it."""

    name = "plane strain, deep"
    plane = "deep"

    def weight(self, x):
        return np.full(np.shape(x)[1:], DEPTH)  # an array, as a section whose measure varies

    def stiffness(self, body, lam, mu):
        return DEPTH * super().stiffness(body, lam, mu)

    def facet_mass(self, x, facets):
        return DEPTH * super().facet_mass(x, facets)


@pytest.fixture
def deep(monkeypatch):
    monkeypatch.setitem(SECTIONS, Deep.plane, Deep())


def pushed(friction=None, variant=None, block_loads=None) -> str:
    """A block on a wider base held at its bottom (non-matching meshes, 7 against 12 across):
    the block's top pressed down (or ``block_loads``), a traction on the base's left side."""
    contact = {k: v for k, v in (("friction", friction), ("variant", variant)) if v is not None}
    return input_file(
        "deep block",
        toml_body("lower", rectangle_mesh(-1.0, -1.0, 2.0, 1.0, 12, 6), support("bottom"),
                  traction("left", [3.0, 1.0]), contact_boundaries=["top"]),
        toml_body("upper", rectangle_mesh(-0.5, 0.0, 1.0, 0.5, 7, 4),
                  *(block_loads or (support("top", ["x"]), pressed(-0.01))),
                  contact_boundaries=["bottom"]),
        contact=contact or None, load_factors=[0.5, 1.0])


def run(text: str, plane: str, converges: bool = True):
    text = text.replace("poissons_ratio = 0.3", f'poissons_ratio = 0.3\nplane = "{plane}"')
    result = Analysis(built(text)).run()
    assert result.converged or not converges, result.message
    assert result.complete  # every step run and measured
    return result


def assert_deep(shallow, deep_run):
    bodies_a = {b.name: b for b in shallow.model.bodies}
    bodies_b = {b.name: b for b in deep_run.model.bodies}
    for a, b in zip(shallow.steps, deep_run.steps, strict=True):
        for name, ra in a.bodies.items():
            rb = b.bodies[name]
            scale = np.abs(ra.displacement).max()
            assert np.abs(rb.displacement - ra.displacement).max() <= 1e-9 * scale
            force = np.abs(ra.contact_force).max()
            assert force > 0
            assert np.abs(rb.contact_force - DEPTH * ra.contact_force).max() <= 1e-9 * force
            pressure = np.abs(ra.contact_pressure).max()
            assert np.abs(rb.contact_pressure - ra.contact_pressure).max() <= 1e-9 * pressure
            sa = stress(bodies_a[name], ra.displacement.ravel())
            sb = stress(bodies_b[name], rb.displacement.ravel())
            for key in ("sxx", "syy", "sxy", "szz", "von_mises"):
                s = np.abs(sa[key]).max()
                assert np.abs(sb[key] - sa[key]).max() <= 1e-9 * s


@pytest.mark.parametrize("variant", [None, "thesis"])
def test_a_slab_twice_as_deep_carries_twice_the_forces_at_the_same_displacements(deep, variant):
    """The thesis variant stops at its fixed point outside its tolerance on this model
    (docs/method.md §5); every iterate of the deep model is still the shallow one's times
    DEPTH, so its last is compared."""
    text = pushed(variant=variant)
    converges = variant is None
    shallow, deep_run = run(text, "strain", converges), run(text, "deep", converges)
    assert deep_run.converged == shallow.converged
    assert_deep(shallow, deep_run)


def test_the_deep_slab_under_friction_too(deep):
    text = pushed(friction=0.3, block_loads=(pressed(-0.01), slid(0.02)))
    assert_deep(run(text, "strain"), run(text, "deep"))


def test_a_body_is_given_its_section_by_its_plane_and_its_mesh(deep):
    model = built(pushed().replace("poissons_ratio = 0.3",
                                   'poissons_ratio = 0.3\nplane = "deep"', 1))
    assert isinstance(section_of(model.bodies[0]), Deep)
    assert section_of(model.bodies[1]).name == "plane strain"


def test_a_plane_that_names_no_section_is_refused_naming_the_sections():
    text = pushed().replace("poissons_ratio = 0.3", 'poissons_ratio = 0.3\nplane = "deep"', 1)
    with pytest.raises(InputError, match=r"body 'lower', material: plane must be 'strain' or "
                                         r"'stress' or 'axisymmetric', got 'deep'"):
        built(text)


# -- a measure that varies: the contact geometry weighs by it where it integrates ---------------


class Graded(PlaneStrain):
    """Plane strain whose depth grows along x, 1 + x: only its measure is read below (the
    contact surfaces' geometry), as a body of revolution's 2πr would be."""

    name = "plane strain, graded"
    plane = "graded"

    def weight(self, x):
        return 1.0 + np.asarray(x)[0]


def graded_strips(monkeypatch, n_lower=4, n_upper=7):
    """The two facing unit strips of ``models.strip_surfaces`` (quadrilaterals below y = 0,
    triangles above), both of the graded section, set up: their contact surfaces."""
    monkeypatch.setitem(SECTIONS, Graded.plane, Graded())
    return strip_surfaces(n_lower, n_upper, plane=Graded.plane)


def test_the_transfer_of_a_uniform_traction_carries_the_sections_measure(monkeypatch):
    """A uniform traction of 1 on the compatibility side gives each of its nodes ∫ φ_i w ds:
    the row sums of its N* (scikit-fem's integral, with the weight) and 1.5 in all (∫ 1 + x
    over the unit strip); the other side carries the same total. Exact for the linear weight
    (degree 3 against rules of degree 5, and of 3 for N*): to round-off."""
    lower, upper = graded_strips(monkeypatch)
    geo = overlap(upper, lower)
    carried = geo.mass @ np.ones(upper.nc)
    consistent = upper.mass_matrix(np.ones(len(upper.facets))) @ np.ones(upper.nc)
    assert np.abs(carried - consistent).max() <= 1e-14 * 1.5
    assert abs(carried.sum() - 1.5) <= 1e-14 * 1.5
    assert abs((geo.transfer @ np.ones(upper.nc)).sum() - 1.5) <= 1e-14 * 1.5


def test_the_thesis_variants_virtual_elements_read_each_side_in_its_own_measure(monkeypatch):
    """The upper strip slid by s = 1/4 to the right: a uniform nominal traction q on it (per
    its own undeformed measure, 1 + X) reaches the lower strip over x in [s, 1], where the
    upper's material point is X = x - s. The virtual forces add up to the upper's force over
    its overlapped part, ∫_0^(1-s) q (1 + X) dX = 1.03125 q, and not to ∫_s^1 q (1 + x) dx =
    1.21875 q, the lower's measure. The lower's facets end at x = s, so the Gauss rule (order
    7) is exact on each: to round-off."""
    lower, upper = graded_strips(monkeypatch)
    contact = VirtualElementContact([lower, upper], ContactPairs.every(2),
                                    ContactSettings(variant="thesis"))
    shift = 0.25
    x = [lower.X.copy(), upper.X + np.array([shift, 0.0])]
    q = np.array([0.0, -1.0])
    tractions = [np.zeros((lower.nc, 2)), np.tile(q, (upper.nc, 1))]
    total = contact._virtual_forces(0, x, tractions).sum(axis=0)
    expected = (1 - shift) + (1 - shift) ** 2 / 2
    assert np.abs(total - expected * q).max() <= 1e-13 * expected


def test_the_invariants_consistent_measure_is_taken_in_the_sections_measure(monkeypatch):
    """The boundary mass matrix of the consistent tension measure is the section's facet mass:
    ``DEPTH`` times plane strain's for the deep slab, whose row sums are then ``DEPTH`` times
    the facets' lengths around each node (exact: the same products)."""
    lower, _ = graded_strips(monkeypatch)
    x, facets = lower.X, lower.facets
    local = np.arange(lower.nc)
    plain = _boundary_mass(PlaneStrain(), x, facets, local, lower.nc).toarray()
    deep = _boundary_mass(Deep(), x, facets, local, lower.nc).toarray()
    assert np.array_equal(deep, DEPTH * plain)
    assert abs(plain.sum() - 1.0) <= 1e-15  # the unit strip's length
