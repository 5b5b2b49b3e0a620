"""The sphere-indentation example (issue 41, ``vfem_examples.sphere_indentation``): its theory,
its mesh and its parameters. Its run is checked by its own verification (``summary.json``) in
the slow set (``tests/test_examples_invariants.py`` runs ``examples/sphere_indentation.toml``
and the built-in; ``tests/test_doc_numbers.py`` keeps ``docs/examples.md``'s numbers of it
current)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vfem.errors import InputError
from vfem.materials import J2Plastic, LinearElastic
from vfem_examples import sphere
from vfem_examples import sphere_indentation as si


def test_hubers_onset_under_a_sphere():
    """Von Mises on the axis under Hertz's sphere peaks at 0.620 p0, 0.481 a deep for
    nu = 0.3 (Johnson 1985, §3.4: p0 = 1.60 Y at 0.48 a; the issue's 1.613 Y at 0.481 a), at
    0.63 a for nu = 0.5 (less shear below a nearly incompressible surface), and the stresses
    it reads are Johnson's at the surface: sigma_z = -p0, sigma_r = -(1 + 2 nu)/2 p0."""
    ratio, depth = si.onset(0.3)
    assert ratio == pytest.approx(1.613, abs=5e-4) and depth == pytest.approx(0.481, abs=1e-3)
    r5, d5 = si.onset(0.5)
    assert d5 > depth and r5 > ratio
    z = 1e-6  # (at the surface: |sigma_z - sigma_r| = p0 (1 - 2 nu)/2, 0.2 p0 for nu = 0.3)
    sr = -(1.3) * (1 - z * math.atan(1 / z)) + 0.5 / (1 + z * z)
    assert abs(-1 / (1 + z * z) - sr) == pytest.approx(0.2, abs=1e-5)


def test_the_onset_force_is_hertzs_and_the_mesh_resolves_it():
    """The onset force is a quarter of Hertz's P for a = onset_contact_radius R; the yield
    stress puts Huber's onset at it; the flat is J2 and the sphere elastic; the meshes' fine
    zone (1.2 a) covers the peak's contact radius; the flat's elements at the contact are
    flat_size_ratio a / facets."""
    p = si.SphereIndentationParameters()
    th = si.theory(p)
    h = sphere.theory(si._sphere(p, 4 * th["onset_force"]))
    assert h["a_theory"] == pytest.approx(p.onset_contact_radius * p.radius, rel=1e-12)
    assert h["p0_theory"] / th["yield_stress"] == pytest.approx(th["p0_over_Y"], rel=1e-12)
    assert th["a_peak"] < sphere.PLATEAU * th["a_onset"]
    model = si.build(p)
    flat = next(b for b in model.bodies if b.name == "flat")
    ball = next(b for b in model.bodies if b.name == "sphere")
    assert isinstance(flat.material, J2Plastic) and isinstance(ball.material, LinearElastic)
    assert flat.material.yield_stress == pytest.approx(th["yield_stress"], rel=1e-12)
    x, y, z = flat.mesh.p
    top = np.abs(z) < 1e-12
    xs = np.unique(np.round(x[top & (np.abs(y) < 1e-12)], 12))
    under = xs[xs <= th["a_onset"]]
    h_flat = p.flat_size_ratio * th["a_onset"] / p.facets_per_radius
    assert 0.9 * h_flat <= np.diff(under).max() <= h_flat * (1 + 1e-9)


def test_the_platen_passes_the_onset_in_steps_of_a_hundredth():
    p = si.SphereIndentationParameters()
    cfg = si.config(p)
    ball = next(b for b in cfg.bodies if b.name == "sphere")
    assert ball.platen.force == pytest.approx(-p.overload * si.theory(p)["onset_force"])
    forces = [p.overload * (lf if lf <= 1 else 2 - lf) for lf in cfg.steps.load_factors]
    assert max(forces) == pytest.approx(p.overload)
    assert [round(f, 6) for f in forces[2:10]] == [0.96, 0.97, 0.98, 0.99, 1.0, 1.01, 1.02,
                                                   1.03]
    assert forces[-1] == pytest.approx(0.01)


@pytest.mark.parametrize("change, words", [
    ({"overload": 1.0}, "overload must exceed 1.03"),
    ({"overload": 2.0}, "overload must be at most 1.7"),
    ({"onset_contact_radius": 0.2}, "onset_contact_radius must be at most 0.1"),
    ({"onset_contact_radius": -1.0}, "onset_contact_radius must be a finite number > 0"),
    ({"flat_size_ratio": math.inf}, "flat_size_ratio must be a finite number > 0"),
    ({"hardening_modulus": -1.0}, "hardening_modulus must be a finite number >= 0"),
    ({"facets_per_radius": 0}, "facets_per_radius must be at least 1"),
])
def test_bad_parameters_are_named(change, words):
    p = dataclasses.replace(si.SphereIndentationParameters(), **change)
    with pytest.raises(InputError, match=words):
        si.validate(p)
