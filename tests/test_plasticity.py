"""J2 plasticity in small strain (issue 41): the return map's consistent tangent, the
homogeneous stress-strain curves against their closed forms (uniaxial stress in 3D, uniaxial
strain in 2D: elastic, yield, hardening, unloading, reverse yield), Newton's convergence past
yield, a step cut and a saved state restored bit for bit, and the input file's table."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from skfem import MeshHex, MeshQuad

from vfem.errors import InputError
from vfem.materials import J2Plastic
from vfem.nonlinear import NonlinearBody
from vfem_examples.thick_cylinder import peak_von_mises, plastic_radius

E, NU, Y, H_ISO, H_KIN = 200e3, 0.3, 250.0, 2000.0, 1000.0
STEEL = J2Plastic(E, NU, Y, H_ISO, H_KIN)


def strain(rng, dim, scale):
    e = rng.standard_normal((dim, dim, 2, 3)) * scale
    return 0.5 * (e + e.transpose(1, 0, 2, 3))


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("material", [
    STEEL, J2Plastic(E, NU, Y),
    J2Plastic(E, NU, Y, kinematic_modulus=H_KIN, hardening_curve=((0.0, Y), (2e-3, 400.0),
                                                                  (6e-3, 450.0)))],
    ids=["hardening", "perfect", "curve"])
def test_the_tangent_is_the_derivative_of_the_return_map(dim, material):
    """Central differences of the returned stress (step h: truncation h^2 |sigma'''|, round-off
    eps |sigma| / h, both below 1e-9 of |C| here) against the consistent tangent, at points
    that flow and points that unload, from a state already plastic."""
    rng = np.random.default_rng(dim)
    state = material.response(strain(rng, dim, 3e-3), material.initial_state(dim, (2, 3))).state
    E1 = strain(rng, dim, 3e-3)
    r = material.response(E1, state)
    flows = r.state["equivalent_plastic_strain"] > state["equivalent_plastic_strain"]
    assert flows.any() and (~flows).any() or flows.all()
    assert_tangent(material, E1, state, 1e-8)


def assert_tangent(material, E1, state, h: float, tol: float = 1e-8) -> None:
    """``material``'s tangent at the strain ``E1`` from ``state`` against central differences
    of its stress (step ``h``), within ``tol`` of its largest entry."""
    C = material.response(E1, state).moduli()
    dim = E1.shape[0]
    for k in range(dim):
        for m in range(dim):
            d = np.zeros_like(E1)
            d[k, m] += h / 2
            d[m, k] += h / 2
            num = (material.response(E1 + d, state).stress
                   - material.response(E1 - d, state).stress) / (2 * h)
            assert np.abs(num - C[:, :, k, m]).max() <= tol * np.abs(C).max()


@pytest.mark.parametrize("material", [
    dataclasses.replace(STEEL, plane="stress"), J2Plastic(E, NU, Y, plane="stress"),
    J2Plastic(E, NU, Y, kinematic_modulus=H_KIN, plane="stress",
              hardening_curve=((0.0, Y), (2e-3, 400.0), (6e-3, 450.0)))],
    ids=["hardening", "perfect", "curve"])
def test_the_plane_stress_tangent_is_the_derivative_of_its_return(material):
    """Plane stress: central differences of the in-plane stress, each with its own eps_zz
    found by the return, against the condensed tangent: 1e-8 of |C|, as in 3D; sigma_zz
    vanishes to 1e-12 of the stress."""
    rng = np.random.default_rng(7)
    state = material.response(strain(rng, 2, 3e-3), material.initial_state(2, (2, 3))).state
    E1 = strain(rng, 2, 3e-3)
    r = material.response(E1, state)
    assert (r.state["equivalent_plastic_strain"] > state["equivalent_plastic_strain"]).any()
    assert not r.out_of_plane.any()
    eps = np.zeros((3, 3, 2, 3))
    eps[:2, :2] = E1
    zz = material._plane_stress(eps, state)
    sigma3, _, _ = material._return(eps, state)  # eps's zz is the one found
    assert np.abs(sigma3[2, 2]).max() <= 1e-12 * (Y + np.abs(zz.stress).max())
    assert_tangent(material, E1, state, 1e-8)


def uniaxial_stress(path):
    """The closed form of uniaxial stress under a strain path (linear pieces): elastic slope
    E, flow where |sigma - c| = Y + H_iso alpha (c = H_kin eps_p the back stress's axial
    reading, alpha the accumulated plastic strain), during which sigma = Y_now + c with
    d sigma = E H / (E + H) d eps, H = H_iso + H_kin (module docstring of vfem.materials.plastic).
    Each piece is monotonic, so each reaches its end in one elastic and one plastic part."""
    H = H_ISO + H_KIN
    eps_p, alpha, out = 0.0, 0.0, []
    for eps in path:
        trial = E * (eps - eps_p)
        c, radius = H_KIN * eps_p, Y + H_ISO * alpha
        over = abs(trial - c) - radius
        if over > 0:
            dg = over / (E + H)
            sign = math.copysign(1.0, trial - c)
            eps_p += sign * dg
            alpha += dg
        out.append(E * (eps - eps_p))
    return out


def block(mesh, material, dim):
    body = NonlinearBody(mesh, material, formulation="small", name="block")
    for c, face in zip("xyz", ("x0", "y0", "z0")[:dim]):
        body.prescribe(body.boundary_dofs(face, c))
    return body


def boxes(dim):
    edges = (np.linspace(0.0, 1.0, 3),) * dim
    mesh = (MeshHex if dim == 3 else MeshQuad).init_tensor(*edges)
    faces = {"x0": lambda x: x[0] == 0, "x1": lambda x: x[0] == 1, "y0": lambda x: x[1] == 0,
             "y1": lambda x: x[1] == 1}
    if dim == 3:
        faces.update({"z0": lambda x: x[2] == 0, "z1": lambda x: x[2] == 1})
    return mesh.with_boundaries(faces)


#: the top's displacement (the block's height is 1: the axial strain) at each step: loaded
#: past yield in compression, unloaded, yielded the other way, reloaded
PATH = [-1e-3, -3e-3, -6e-3, -4e-3, -2e-3, 0.0, 2e-3, -2e-3]


def run(body, top):
    at = np.r_[0.0, PATH]
    body.prescribe(top, lambda lf: np.full(len(top), np.interp(lf, np.arange(len(at)), at)))
    forces, records = [], []
    for k in range(1, len(at)):
        records.append(body.equilibrate(float(k), tol=1e-13))
        body.accept()
        forces.append(float(body.reactions()[top].sum()))
    return forces, records


def test_uniaxial_stress_in_3d_follows_the_closed_form():
    """A block on frictionless supports (rollers on three faces), its top moved: the axial
    stress is the uniaxial closed form at every step to round-off (1e-10 of Y), and each
    plastic step takes one correction past the elastic predictor (the tangent is exact on a
    homogeneous field)."""
    body = block(boxes(3), STEEL, 3)
    forces, records = run(body, body.boundary_dofs("z1", "z"))
    expected = uniaxial_stress(PATH)
    assert max(abs(f - s) for f, s in zip(forces, expected)) <= 1e-10 * Y
    assert min(expected) < -Y and max(expected) > Y  # both ways past yield
    assert all(r.iterations <= 2 for r in records)
    alpha = body.material_state["equivalent_plastic_strain"]
    assert np.ptp(alpha) <= 1e-12 * alpha.max()  # homogeneous


def test_uniaxial_stress_in_plane_stress_follows_the_closed_form():
    """A plane-stress block on rollers, its top moved: uniaxial stress, the same closed form
    as the 3D block's (the plate's thickness strain found by the return), to 1e-10 Y; Newton's
    corrections past yield converge quadratically (four, where the 3D block needs one: the
    condensed tangent of the elastic predictor is not the plastic one)."""
    body = block(boxes(2), dataclasses.replace(STEEL, plane="stress"), 2)
    forces, records = run(body, body.boundary_dofs("y1", "y"))
    expected = uniaxial_stress(PATH)
    assert max(abs(f - s) for f, s in zip(forces, expected)) <= 1e-10 * Y
    assert all(r.iterations <= 5 for r in records)
    assert body.material_state["plastic_strain"][2, 2].max() > 0  # the plate thickens


#: a hardening curve (equivalent plastic strain, yield stress) through two kinks to a plateau
CURVE = ((0.0, Y), (2e-3, 400.0), (6e-3, 450.0))


def test_uniaxial_stress_on_a_hardening_curve_follows_the_closed_form():
    """The block of the uniaxial test on a piecewise-linear hardening curve (with kinematic
    hardening beside it), pressed monotonically through both kinks onto the plateau and
    unloaded a little: while loading |sigma| = sigma_y(eps_p) + H_kin eps_p = E (|eps| - eps_p),
    solved segment by segment; to 1e-10 of Y at every step."""
    material = J2Plastic(E, NU, Y, kinematic_modulus=H_KIN, hardening_curve=CURVE)
    material.validate()
    path = [-1e-3, -2e-3, -3.5e-3, -6e-3, -9e-3, -1.2e-2, -1.1e-2]
    body = block(boxes(3), material, 3)
    top = body.boundary_dofs("z1", "z")
    at = np.r_[0.0, path]
    body.prescribe(top, lambda lf: np.full(len(top), np.interp(lf, np.arange(len(at)), at)))
    start = np.array([a for a, _ in CURVE])
    level = np.array([v for _, v in CURVE])
    slope = np.r_[np.diff(level) / np.diff(start), 0.0]
    eps_p = 0.0
    for k, eps in enumerate(path, start=1):
        body.equilibrate(float(k), tol=1e-13)
        body.accept()
        force = float(body.reactions()[top].sum())
        if abs(eps) > abs(path[k - 2]) or k == 1:  # loading: the curve's closed form
            for j in range(len(start)):  # E (|eps| - e) = level_j + slope_j (e - start_j) + H_kin e
                e = (E * abs(eps) - level[j] + slope[j] * start[j]) / (E + slope[j] + H_KIN)
                if j == len(start) - 1 or e <= start[j + 1]:
                    break
            eps_p = max(e, 0.0)
            expected = -E * (abs(eps) - eps_p)
        else:  # unloading: elastic from the last state
            expected = -E * (abs(eps) - eps_p)
        assert abs(force - expected) <= 1e-10 * Y, (k, force, expected)
    assert body.material_state["equivalent_plastic_strain"].max() > CURVE[-1][0]  # plateau


@pytest.mark.parametrize(("curve", "words"), [
    (((0.0, 200.0), (1e-3, 300.0)), r"must start at \[0, yield_stress\]"),
    (((0.0, Y), (1e-3, 300.0), (1e-3, 350.0)), "plastic strains must increase"),
    (((0.0, Y), (1e-3, 240.0)), "must not fall"),
])
def test_bad_hardening_curves_are_named(curve, words):
    with pytest.raises(InputError, match=words):
        J2Plastic(E, NU, Y, hardening_curve=curve).validate("body 'block', material")
    with pytest.raises(InputError, match="not both"):
        J2Plastic(E, NU, Y, 10.0, hardening_curve=CURVE).validate("body 'block', material")


def uniaxial_strain(path):
    """The closed form of uniaxial strain (a plane-strain block in a die) under a strain path:
    a proportional path, q = sigma_yy - sigma_xx = 2 mu eps_yy while elastic, then
    |q - c| = Y + H_iso alpha (c the back stress's reading); the mean stress K eps_yy
    throughout, so sigma_yy = K eps_yy + 2/3 q. The axial stress at each step."""
    lam, mu = STEEL.lame()
    bulk = lam + 2 * mu / 3
    H = H_ISO + H_KIN
    eps_p = alpha = 0.0  # the axial plastic strain (yy; xx = zz = -eps_p / 2), accumulated
    out = []
    for eps in path:
        # deviatoric tensors a diag(-1/3, 2/3, -1/3), read by a (norm sqrt(2/3) |a|): the
        # trial q = 2 mu (eps - 3/2 eps_p), the back stress's c = H_kin eps_p, the radius
        # Y + H_iso alpha; a flow d eps_p moves them by -3 mu, H_kin and H_iso times it
        q_trial = 2 * mu * (eps - 1.5 * eps_p)
        c = H_KIN * eps_p
        over = abs(q_trial - c) - (Y + H_ISO * alpha)
        if over > 0:
            dg = over / (3 * mu + H)
            eps_p += math.copysign(dg, q_trial - c)
            alpha += dg
        out.append(bulk * eps + 2 / 3 * 2 * mu * (eps - 1.5 * eps_p))
    assert alpha > 0.0
    return out


def test_uniaxial_strain_in_plane_strain_follows_the_closed_form():
    """A plane-strain block held laterally (a die), its top moved: uniaxial strain's closed
    form (:func:`uniaxial_strain`) to 1e-10 Y."""
    body = block(boxes(2), STEEL, 2)
    body.prescribe(body.boundary_dofs("x1", "x"))  # the die's wall
    top = body.boundary_dofs("y1", "y")
    forces, _ = run(body, top)
    for force, sigma_yy in zip(forces, uniaxial_strain(PATH)):
        assert abs(force - sigma_yy) <= 1e-10 * Y


def test_newton_converges_quadratically_past_yield():
    """A block squeezed by a rigid flat die over part of its top (a heterogeneous plastic
    zone): the relative residuals fall quadratically (each below a constant times the
    square of the one before) once near the solution."""
    body = block(boxes(2).refined(2), J2Plastic(E, NU, Y, H_ISO), 2)
    mesh = body.mesh
    die = np.flatnonzero((np.abs(mesh.doflocs[1] - 1) < 1e-12) & (mesh.doflocs[0] <= 0.5))
    dofs = body.node_dofs(die, "y")
    body.prescribe(dofs, lambda lf: np.full(len(dofs), -5e-4 * lf))
    for k in (1.0, 2.0):
        body.equilibrate(k, tol=1e-12)
        body.accept()
    record = body.equilibrate(3.0, tol=1e-12)  # the plastic zone grows under the die's edge
    before = body.material_state["equivalent_plastic_strain"]
    after = body._trial_state.material_state["equivalent_plastic_strain"]
    assert before.max() > 0 and (after > before).sum() > (before > 0).sum()
    r = record.relative_residuals
    assert record.iterations >= 3 and r[-1] <= 1e-12
    ratios = [b / a**2 for a, b in zip(r[1:-1], r[2:]) if a < 1e-3]
    assert ratios and max(ratios) < 1e3


def test_a_cut_step_and_a_saved_state_restore_bit_for_bit():
    body = block(boxes(3), STEEL, 3)
    top = body.boundary_dofs("z1", "z")
    body.prescribe(top, lambda lf: np.full(len(top), -3e-3 * lf))
    body.equilibrate(1.0, tol=1e-13)
    body.accept()
    saved = body.saved_state()
    first = body.equilibrate(2.0, tol=1e-13)  # a step in plastic flow ...
    u1, state1 = body.trial_displacement().copy(), body._trial_state.material_state
    body.discard()  # ... cut
    assert body.equilibrate(2.0, tol=1e-13).residuals == first.residuals
    assert np.array_equal(body.trial_displacement(), u1)
    for k, v in body._trial_state.material_state.items():
        assert np.array_equal(v, state1[k])
    body.accept()
    body.restore_state(saved)  # the state saved (a checkpoint's) put back
    body.equilibrate(2.0, tol=1e-13)
    assert np.array_equal(body.trial_displacement(), u1)


@pytest.mark.parametrize(("change", "words"), [
    ({"yield_stress": 0.0}, "yield_stress must be > 0"),
    ({"hardening_modulus": -1.0}, "hardening_modulus must be >= 0"),
    ({"model": "tresca"}, "model must be 'von_mises'"),
])
def test_bad_parameters_are_named(change, words):
    values = {"youngs_modulus": E, "poissons_ratio": NU, "yield_stress": Y, **change}
    with pytest.raises(InputError, match=words):
        J2Plastic(**values).validate("body 'block', material")


PUNCH = """
name = "plastic punch"

[steps]
load_factors = [0.25, 0.5, 0.75, 1.0, 0.5, 0.0]

[[bodies]]
name = "block"
[bodies.mesh]
shape = "block"
x0 = 0.0
y0 = 0.0
width = 1.0
height = 0.5
h = 0.125
symmetry = "left"
[bodies.material]
youngs_modulus = 200000.0
poissons_ratio = 0.3
yield_stress = 250.0
hardening_modulus = 2000.0
[[bodies.supports]]
boundary = "bottom"
components = ["y"]
[[bodies.supports]]
boundary = "symmetry"
components = ["x"]

[[bodies]]
name = "punch"
[bodies.mesh]
shape = "block"
x0 = 0.0
y0 = 0.5
width = 0.3
height = 0.3
h = 0.1
symmetry = "left"
[bodies.material]
youngs_modulus = 400000.0
poissons_ratio = 0.3
[[bodies.supports]]
boundary = "symmetry"
components = ["x"]
[[bodies.prescribed]]
boundary = "top"
component = "y"
value = -0.002
"""


def test_a_punch_into_a_plastic_block_leaves_a_dent_and_reads_the_same_either_way():
    """A flat punch pressed past yield into an elasto-plastic block and taken back out
    (frictionless contact, Newton's bodies): every step converges with the invariants met;
    the plastic zone grows while loading and is kept while unloading; at the end the punch
    has left the block (no contact force) and a dent stays; the bodies listed the other way
    round give the same answers to the contact tolerances."""
    import vfem
    from vfem.io.input import loads

    config = loads(PUNCH, "punch.toml")
    results = [vfem.solve(config),  # and with the bodies listed the other way round
               vfem.solve(dataclasses.replace(config, bodies=config.bodies[::-1]))]
    first, second = results
    assert first.converged and second.converged
    assert all(s.invariants["passed"] for s in first.steps + second.steps)
    force = [float(s.bodies["punch"].contact_force[:, 1].sum()) for s in first.steps]
    assert force[3] < force[0] * 3.5  # past yield: less than proportional to the push
    assert abs(force[-1]) <= 1e-9 * abs(force[3])  # lifted off
    dent = first.steps[-1].bodies["block"].displacement[:, 1].min()
    assert dent < -1e-4  # a dent of the plastic flow's size stays
    for a, b in zip(first.steps, second.steps):
        fa = a.bodies["punch"].contact_force[:, 1].sum()
        fb = b.bodies["punch"].contact_force[:, 1].sum()
        assert fb == pytest.approx(fa, rel=1e-8, abs=1e-9 * abs(force[3]))


def test_a_punch_into_a_plastic_plate_in_plane_stress():
    """The flat punch and block as thin plates (plane stress, both bodies): every step
    converges with the invariants met, the punch leaves a dent and lifts off, and the plate
    carries less than the plane-strain slice at every loaded step (softer elastically, E
    against E / (1 - nu^2), and yielding sooner: no out-of-plane stress to confine it)."""
    import vfem
    from vfem.io.input import loads

    def solve(plane):
        text = PUNCH.replace("poissons_ratio = 0.3\n", f'poissons_ratio = 0.3\nplane = "{plane}"\n')
        result = vfem.solve(loads(text, "punch.toml"))
        assert result.converged and all(s.invariants["passed"] for s in result.steps)
        return result, [float(s.bodies["punch"].contact_force[:, 1].sum())
                        for s in result.steps]

    (plate, f_plate), (_, f_slice) = solve("stress"), solve("strain")
    assert all(0 < a < b for a, b in zip(f_plate[:4], f_slice[:4]))
    assert abs(f_plate[-1]) <= 1e-9 * f_plate[3]
    assert plate.steps[-1].bodies["block"].displacement[:, 1].min() < -1e-4


def test_a_plastic_run_killed_and_resumed_ends_as_the_whole_run(tmp_path):
    """Stopped after the step past yield and resumed from its checkpoint (the plastic
    strains, back stresses and equivalent plastic strains saved with the body): every later
    step's contact forces and the points yielded as in the uninterrupted run."""
    from resume_check import assert_resumed_equals_whole
    from vfem.io.input import loads

    config = loads(PUNCH, "punch.toml")
    resumed = assert_resumed_equals_whole(config, tmp_path, stop_after=3)
    whole = json.loads((tmp_path / "whole" / "summary.json").read_text())
    points = [s["yielded_points"]["block"] for s in whole["steps"]]
    assert points == [s["yielded_points"]["block"] for s in resumed["steps"]]
    assert points[0] < points[3] == points[-1]  # the plastic zone kept on unloading


def thick_cylinder(nr: int = 40, nt: int = 12):
    """A quarter of a plane-strain thick cylinder, a = 1, b = 2, of quadratic triangles (which
    do not lock under the plastic flow's incompressibility, as bilinear quadrilaterals do:
    they carried 1.03 times the limit pressure), the rings graded towards the bore; unit
    pressure on the bore as a load history (small strain: a dead load), symmetry planes."""
    from skfem import FacetBasis, LinearForm, MeshTri, asm
    from skfem.helpers import dot

    r = 2.0 ** np.linspace(0.0, 1.0, nr + 1)
    t = np.linspace(0.0, np.pi / 2, nt + 1)
    polar = MeshTri.init_tensor(r, t)
    mesh = MeshTri(np.vstack([polar.p[0] * np.cos(polar.p[1]),
                              polar.p[0] * np.sin(polar.p[1])]), polar.t).with_boundaries({
        "bore": lambda x: np.hypot(x[0], x[1]) < 1.0 + 1e-6,
        "x_axis": lambda x: np.abs(x[1]) < 1e-12, "y_axis": lambda x: np.abs(x[0]) < 1e-12})
    body = NonlinearBody(mesh, J2Plastic(E, 0.49, Y), formulation="small", order=2,
                         name="cylinder")
    body.prescribe(body.boundary_dofs("x_axis", "y"))
    body.prescribe(body.boundary_dofs("y_axis", "x"))
    bore = FacetBasis(body.mesh, body.basis0.elem, facets=mesh.boundaries["bore"])
    unit = asm(LinearForm(lambda v, w: -dot(w.n, v)), bore)  # n points into the bore
    body.set_load_history(lambda p: p * unit)
    x = body.basis0.mapping.F(body.basis0.X)
    return body, np.hypot(x[0], x[1])


@pytest.mark.slow
def test_a_thick_cylinder_yields_and_collapses_as_hill_says():
    """Hill's elastic-perfectly plastic thick cylinder (The Mathematical Theory of Plasticity,
    1950, ch. V): plane strain, bore a = 1, outer radius b = 2, nu = 0.49 (Hill's p(c) is
    exact for nu -> 1/2), k = Y / sqrt(3).

    * first yield at the bore from the elastic (Lame) stresses with nu's sigma_zz: the
      finite elements' largest von Mises stress at unit pressure (at the Gauss points and on
      the boundary: the bore) gives it within 0.5 %;
    * with the plastic zone out to c, p = k (1 - c^2/b^2 + 2 ln(c/a)): within 1 % at every
      pressure (c read where the yielded quadrature points end:
      :func:`vfem_examples.thick_cylinder.plastic_radius`);
    * the limit pressure 2 k ln(b/a): carried at 0.995 of it, not at 1.01 (no equilibrium:
      Newton's method fails there)."""
    from vfem.errors import AnalysisError

    body, radius = thick_cylinder()
    a, b, nu, k = 1.0, 2.0, 0.49, Y / math.sqrt(3.0)
    A = a * a / (b * b - a * a)  # Lame at r = a per unit pressure
    s_rr, s_tt = -1.0, A * (1.0 + b * b / (a * a))
    s_zz = nu * (s_rr + s_tt)
    p_yield = Y / math.sqrt(0.5 * ((s_rr - s_tt) ** 2 + (s_tt - s_zz) ** 2 + (s_zz - s_rr) ** 2))
    p_limit = 2.0 * k * math.log(b / a)

    body.equilibrate(0.9 * p_yield, tol=1e-10)
    body.accept()
    assert not body.material_state["equivalent_plastic_strain"].any()
    # the elastic solution's peak, at the Gauss points and on the boundary (the bore)
    vm = peak_von_mises(body, body.displacement)
    assert Y / (vm / (0.9 * p_yield)) == pytest.approx(p_yield, rel=5e-3)

    for share in (1.1, 1.3, 1.5, 1.7, 1.8):
        p = share * p_yield
        body.equilibrate(p, tol=1e-10, max_iter=40)
        body.accept()
        yielded = body.material_state["equivalent_plastic_strain"] > 0
        c = plastic_radius(radius, yielded)
        assert a < c < b
        assert p == pytest.approx(k * (1 - c * c / (b * b) + 2 * math.log(c / a)), rel=1e-2)
    body.equilibrate(0.995 * p_limit, tol=1e-10, max_iter=40)
    body.accept()
    with pytest.raises(AnalysisError, match="singular|did not converge"):
        body.equilibrate(1.01 * p_limit, tol=1e-10, max_iter=40)


def test_external_work_is_stored_energy_plus_dissipation():
    """The block of the uniaxial test loaded past yield and back in 120 steps: the work of the
    top's force (trapezoids over the steps) equals the elastic energy stored, the hardening
    energy stored (H_iso alpha^2 / 2 + |beta|^2 / (4/3 H_kin), whose gradients are the
    hardening forces) and the dissipation, within 1e-3 of the work (the trapezoids' error on
    the piecewise-linear curve; 1 % is the issue's). The dissipation of a step at a point is
    the return's xi : d eps_p - H_iso alpha d alpha = Y d alpha (Simo & Hughes 1998, §2.3):
    never negative."""
    body = block(boxes(3), STEEL, 3)
    top = body.boundary_dofs("z1", "z")
    path = np.r_[np.linspace(0.0, -6e-3, 61), np.linspace(-6e-3, 1e-3, 61)[1:]]
    body.prescribe(top, lambda lf: np.full(len(top), np.interp(lf, np.arange(len(path)), path)))
    lam, mu = STEEL.lame()
    dx = body.basis0.dx
    work, dissipation, force = 0.0, 0.0, 0.0
    for k in range(1, len(path)):
        before = body.material_state["equivalent_plastic_strain"]
        body.equilibrate(float(k), tol=1e-13)
        body.accept()
        step = body.material_state["equivalent_plastic_strain"] - before
        assert (step >= 0).all()
        dissipation += float((Y * step * dx).sum())
        new = float(body.reactions()[top].sum())
        work += 0.5 * (force + new) * (path[k] - path[k - 1])  # (the area is 1)
        force = new
    g = body.basis0.interpolate(body.displacement).grad
    eps = np.zeros((3, 3) + g.shape[2:])
    eps[:] = 0.5 * (g + g.transpose(1, 0, 2, 3))
    elastic = eps - body.material_state["plastic_strain"]
    tr = elastic[0, 0] + elastic[1, 1] + elastic[2, 2]
    stored = float(((0.5 * lam * tr**2 + mu * np.einsum("ij...,ij...->...", elastic, elastic))
                    * dx).sum())
    alpha, beta = body.material_state["equivalent_plastic_strain"], \
        body.material_state["back_stress"]
    hardening = float(((0.5 * H_ISO * alpha**2
                        + 0.75 / H_KIN * np.einsum("ij...,ij...->...", beta, beta)) * dx).sum())
    assert dissipation > 0.5 * work > 0
    assert stored + hardening + dissipation == pytest.approx(work, rel=1e-3)


@pytest.mark.slow
def test_yield_starts_under_a_hertz_contact_where_and_when_hertz_says():
    """The Hertz cylinder (``vfem_examples.hertz``, nu = 0.3) of J2 material, pressed by a
    force whose Hertz half-width is a = 0.004 R (the elastic half-space's stresses hold to
    about a / 2R: a disk's own stress from its load, P / pi R, adds 0.4 % of p0 to the von
    Mises stress here, 2.7 % at the example's a = 0.06 R); yield stress Y = p0 / 1.794 at the
    force, so that first yield is due at load factor 1 on the axis at 0.704 a (von Mises
    under McEwen's stresses). The first load factor with a yielded point lies within 2 % of
    1, and the first yielded points lie, on average, within one element of 0.704 a deep."""
    from vfem.solver import Analysis
    from vfem_examples import hertz

    E1, nu = 1.0e6, 0.3
    probe = hertz.HertzParameters(cylinder_poissons_ratio=nu)
    e_star = hertz.theory(probe)["e_star"]
    a = 0.004
    force = a * a * math.pi * e_star / 8.0  # on the half model
    p = dataclasses.replace(probe, force=force)
    theory = hertz.theory(p)
    assert theory["a_theory"] == pytest.approx(a, rel=1e-12)
    z = np.linspace(1e-3, 3.0, 300001)  # McEwen's stresses on the axis, per p0, z per a
    sx = -((1 + 2 * z * z) / np.sqrt(1 + z * z) - 2 * z)
    sz = -1 / np.sqrt(1 + z * z)
    sy = nu * (sx + sz)
    vm = np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2))
    assert 1 / vm.max() == pytest.approx(1.794, abs=5e-4)
    depth = z[vm.argmax()]
    Y = theory["p0_theory"] * vm.max()
    model = hertz.build(p)
    cylinder = next(b for b in model.bodies if b.name == "cylinder")
    cylinder.material = J2Plastic(E1, nu, Y)
    model.load_factors = (0.5, 0.9, 0.96, 0.97, 0.98, 0.99, 1.0, 1.01, 1.02, 1.03)
    result = Analysis(model).run()
    assert result.converged
    first = next(s for s in result.steps if s.yielded["cylinder"] > 0)
    assert abs(first.load_factor - 1.0) <= 0.02
    r = first.bodies["cylinder"]
    nl = cylinder.nonlinear
    x = nl.basis0.mapping.F(nl.basis0.X)  # quadrature points
    # the points that yielded in that step, the first to yield (from the virgin state)
    g = nl.basis0.interpolate(np.ravel(r.displacement)).grad
    state = nl.material.response(0.5 * (g + np.swapaxes(g, 0, 1)),
                                 nl.material.initial_state(2, x.shape[1:])).state
    yielded = state["equivalent_plastic_strain"] > 0
    bottom = float(nl.mesh.doflocs[1].min())
    h = a / p.facets_per_half_width  # the elements' size there
    a_now = a * math.sqrt(first.load_factor)
    depths = x[1][yielded] - bottom
    assert abs(depths.mean() - depth * a_now) <= h


def test_a_plastic_table_is_written_and_read_back_as_it_was():
    """``vfem export`` / :func:`vfem.io.input.dumps` writes a plastic material's table (its
    hardening curve as an array of pairs) so that reading it gives the same model."""
    from vfem.io.input import dumps, loads

    text = PUNCH.replace("hardening_modulus = 2000.0",
                         "hardening_curve = [[0.0, 250.0], [0.002, 400.0], [0.006, 450.0]]\n"
                         "kinematic_modulus = 500.0")
    config = loads(text, "punch.toml")
    block = next(b for b in config.bodies if b.name == "block")
    assert isinstance(block.material, J2Plastic)
    assert block.material.hardening_curve == CURVE[:1] + ((2e-3, 400.0), (6e-3, 450.0))
    assert loads(dumps(config, "written back"), "again.toml") == config


def test_the_thick_cylinder_input_file_yields_and_flows_as_hill_says(tmp_path):
    """``examples/thick_cylinder.toml``, the model above through the input file: quadratic
    quadrilaterals (order 2, a plastic body that touches no other), the bore's pressure a
    ``pressure`` traction, one step per pressure. Against Lame and Hill (as above): no point
    yielded at 0.9 of Lame's first-yield pressure and some at 1.1 of it; at 1.1 to 1.8 of it
    the pressure within 1 % of k (1 - c^2/b^2 + 2 ln(c/a)), c where the yielded quadrature
    points end (:func:`~vfem_examples.thick_cylinder.plastic_radius`); 0.995 of the limit
    pressure carried."""
    from pathlib import Path

    import vfem
    from vfem.solver import Analysis

    path = Path(__file__).resolve().parents[1] / "examples" / "thick_cylinder.toml"
    config = vfem.load(path)
    analysis = Analysis(config.build(tmp_path))
    body = analysis.model.bodies[0]
    a, b, nu = 1.0, 2.0, body.material.poissons_ratio
    k = body.material.yield_stress / math.sqrt(3.0)
    A = a * a / (b * b - a * a)
    s_rr, s_tt = -1.0, A * (1.0 + b * b / (a * a))
    s_zz = nu * (s_rr + s_tt)
    p_yield = body.material.yield_stress / math.sqrt(
        0.5 * ((s_rr - s_tt) ** 2 + (s_tt - s_zz) ** 2 + (s_zz - s_rr) ** 2))
    p_limit = 2.0 * k * math.log(b / a)
    seen = []

    def on_step(step):
        nl = body.mechanics.nonlinear
        x = nl.basis0.mapping.F(nl.basis0.X)
        yielded = nl.material_state["equivalent_plastic_strain"] > 0
        c = plastic_radius(np.hypot(x[0], x[1]), yielded)
        seen.append((step.load_factor, c))

    result = analysis.run(on_step)
    assert result.converged, result.message
    pressures = [p for p, _ in seen]
    assert pressures == pytest.approx([s * p_yield for s in (0.9, 1.1, 1.3, 1.5, 1.7, 1.8)]
                                      + [0.995 * p_limit], rel=2e-4)  # (the file's rounding)
    assert seen[0][1] is None and seen[1][1] is not None
    for p, c in seen[1:-1]:
        assert a < c < b
        assert p == pytest.approx(k * (1 - c * c / (b * b) + 2 * math.log(c / a)), rel=1e-2)


@pytest.mark.parametrize("kinematics", ["small", "total"])
def test_a_punch_into_a_plastic_block_with_coulomb_friction(kinematics):
    """The flat punch past yield with Coulomb friction (mu = 0.3) against the plastic block,
    the block under small and under finite strain (issue 41, item 3: plastic bodies in
    contact with friction, the invariants unchanged): every step converges with the
    invariants met; every node's tangential contact force within mu times its normal one
    (to the contact tolerance's share of the largest force); friction acts (some node's
    tangential force is a tenth of mu times its normal one or more, the block's surface
    drawn in under the punch); a dent stays and the punch lifts off; the bodies listed the
    other way round give the same forces to 1e-8 of the peak."""
    import vfem
    from vfem.io.input import loads

    text = PUNCH + "\n[contact]\nfriction = 0.3\n"
    if kinematics != "small":
        text = text.replace('name = "block"\n', f'name = "block"\nkinematics = "{kinematics}"\n')
    config = loads(text, "punch.toml")
    first, second = (vfem.solve(config),
                     vfem.solve(dataclasses.replace(config, bodies=config.bodies[::-1])))
    assert first.converged and second.converged, (first.message, second.message)
    assert all(s.invariants["passed"] for s in first.steps + second.steps)
    peak = max(abs(float(s.bodies["punch"].contact_force[:, 1].sum())) for s in first.steps)
    acted = 0.0
    for step in first.steps:
        for name in ("punch", "block"):
            f = step.bodies[name].contact_force
            assert np.all(np.abs(f[:, 0]) <= 0.3 * np.abs(f[:, 1]) + 1e-8 * peak)
            touching = np.abs(f[:, 1]) > 1e-6 * peak
            if touching.any():
                acted = max(acted, float((np.abs(f[touching, 0])
                                          / (0.3 * np.abs(f[touching, 1]))).max()))
    assert acted >= 0.1
    assert first.steps[-1].bodies["block"].displacement[:, 1].min() < -1e-4
    assert abs(float(first.steps[-1].bodies["punch"].contact_force[:, 1].sum())) <= 1e-9 * peak
    for a, b in zip(first.steps, second.steps):
        assert np.allclose(b.bodies["punch"].contact_force, a.bodies["punch"].contact_force,
                           rtol=0, atol=1e-8 * peak)
