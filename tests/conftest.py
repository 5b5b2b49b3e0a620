import logging

import pytest

logging.getLogger("skfem").setLevel(logging.WARNING)


@pytest.fixture(scope="session")
def hertz_level0():
    """The Hertz example at its default (coarsest) mesh, solved once for several tests."""
    from vfem.examples.hertz import HertzParameters, build, evaluate
    from vfem.solver import Analysis

    p = HertzParameters()
    result = Analysis(build(p)).run()
    return p, result, evaluate(result, p)
