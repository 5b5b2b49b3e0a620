import logging
import os

import pytest

# Under pytest-xdist (``-n auto``, pyproject.toml) each worker is a process of its own: one
# thread each for the sparse factorizations too (vfem.threads), or the workers' thread pools
# would fight for the cores (the CLI tests' subprocesses inherit it)
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.setdefault("VFEM_THREADS", "1")

logging.getLogger("skfem").setLevel(logging.WARNING)


@pytest.fixture(scope="session")
def hertz_level0():
    """The Hertz example at its default (coarsest) mesh, solved once for several tests."""
    from vfem.solver import Analysis
    from vfem_examples.hertz import HertzParameters, build, evaluate

    p = HertzParameters()
    result = Analysis(build(p)).run()
    return p, result, evaluate(result, p)
