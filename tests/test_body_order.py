"""No master/slave bias, measured: every example gives the same answer with its bodies listed in
the other order (issue 4). Each example has a ``swap_bodies`` parameter; the key numbers must
agree to 1e-8 relative. The wedge's and the gasket's are in ``test_wedge.py`` and
``test_gasket.py``, on the meshes those files already solve."""

import dataclasses

import pytest

from vfem.contact.formulations.onedim import SecantSpring, solve_step
from vfem.solver import Analysis
from vfem_examples import block, hertz, patch


def _both_orders(module, params, evaluate):
    out = []
    for swap in (False, True):
        p = dataclasses.replace(params, swap_bodies=swap)
        out.append(evaluate(Analysis(module.build(p)).run(), p))
    return out


@pytest.mark.parametrize("order", [1, 2])
def test_hertz(order):
    a, b = _both_orders(hertz, hertz.HertzParameters(order=order), hertz.evaluate)
    for key in ("p_max", "p_max_flat", "a_estimate", "total_contact_force",
                "rms_error_over_p0"):
        assert b[key] == pytest.approx(a[key], rel=1e-8), key


def test_block():
    a, b = _both_orders(block, block.Parameters(), block.evaluate)
    for key in ("contact_force", "small_reaction_y", "corner_pressure"):
        assert b[key] == pytest.approx(a[key], rel=1e-8), key


@pytest.mark.parametrize("nu", [0.0, 0.3])
def test_patch(nu):
    cases = []
    for swap in (False, True):
        p = patch.Parameters(swap_bodies=swap)
        model = patch.build(p, 4, 7, nu)
        result = Analysis(model).run()
        cases.append({name: r.contact_pressure[r.contact_status > 0]
                      for name, r in result.steps[-1].bodies.items()})
    for name in cases[0]:
        assert cases[1][name] == pytest.approx(cases[0][name], rel=1e-8)


def test_springs_mirrored():
    """The 1D analogy: the same overlap resolved with A and B exchanged gives the same force."""
    a, b = SecantSpring(10.0, 1000.0, a=10.0), SecantSpring(10.0, 2000.0, b=20.0)
    kw = dict(penetration_tolerance=1e-9, equilibrium_tolerance=1e-9)
    da, db, _, ok1 = solve_step(a, b, 0.1, 0.05, 0.4, **kw)
    db2, da2, _, ok2 = solve_step(b, a, 0.05, 0.1, 0.4, **kw)
    assert ok1 and ok2
    assert a.reaction(da2) == pytest.approx(a.reaction(da), rel=1e-8)
    assert da2 == pytest.approx(da, rel=1e-8) and db2 == pytest.approx(db, rel=1e-8)
