"""benchmarks/flexibility.py --sphere (issue 40, item 1: the routes to each body's flexibility,
docs/benchmarks.md) on a small sphere: it runs, and what its table says of the routes holds
there too: the Schur complement's order has at least the plain one's factor entries;
PARDISO's partial solve orders the marked dofs last as the Schur complement does (its factor
entries nearer the Schur order's than a tenth of the way back to the plain order's); the
out-of-core factorization keeps no more memory than the in-core one."""

import sys
from pathlib import Path

import pytest

from vfem import linalg

pytestmark = pytest.mark.skipif(not linalg.is_available("pardiso"),
                                reason="PARDISO not installed")


def test_the_routes_to_the_flexibility_run_and_order_alike(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(Path(__file__).parent.parent / "benchmarks"))
    monkeypatch.chdir(tmp_path)  # (the out-of-core factors' files)
    import flexibility

    rows = flexibility.sphere([5_000], columns=64, repeat=1)
    assert {r["body"] for r in rows} == {"sphere", "flat"}
    for r in rows:
        assert r["contact_dofs"] > 0
        assert r["nnz_schur"] >= r["nnz_plain"] > 0
        assert abs(r["nnz_partial"] - r["nnz_schur"]) <= 0.1 * (r["nnz_schur"] - r["nnz_plain"])
        assert 0 < r["out_of_core_mib"] <= r["in_core_mib"]
    sys.modules.pop("flexibility", None)
