"""One body split into subdomains (issue 43, serial): METIS's partition, the subdomain matrices,
the BDDC split solve against a direct one, contact models with a split body against the unsplit
run, the results' record of the partition and the input checks.

Tolerances: the split solve stops at a relative interface residual of 1e-12
(:data:`vfem.linalg.bddc.RTOL`), whose error is at most cond(S) times that (cond(S) ~ 1/h, at
most a few hundred on these meshes): 1e-10 of the largest displacement for the solve, and the
issue's 1e-8 for a whole contact analysis (its Newton and active-set iterations see the
flexibility through the same solve). The subdomain matrices add up to the stiffness to
round-off: each entry sums at most 8 (hexahedra) element contributions, so 1e-14 of the
largest entry.
"""

from __future__ import annotations

import functools
import json

import meshio
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import MeshHex2, MeshQuad2, MeshTet2, MeshTri2

import vfem
from vfem import linalg
from vfem.bodies import Body, condensation
from vfem.bodies.loads import Support, Traction
from vfem.bodies.subdomains import (
    body_partition,
    element_graph,
    partition,
    split_solve,
    subdomain_matrices,
)
from vfem.errors import AnalysisError, InputError
from vfem.io.input import load
from vfem.materials import J2Plastic, LinearElastic
from vfem.mesh.shapes import rectangle
from vfem.mesh.solids import box

#: METIS's default load imbalance of a k-way partition (ufactor 30: the largest part at most
#: 1.03 times the mean), and one element for the rounding of a small mesh
IMBALANCE = 1.03


def _body(dim: int, n: int, order: int, simplex: bool, k: int) -> Body:
    """A box (2D: a square) held at its bottom, a traction on its top, assembled."""
    if dim == 2:
        mesh, value = rectangle(nx=n, ny=n, triangles=simplex), (1.0, -0.5)
    else:
        mesh, value = box(nx=n, ny=n, nz=n, tetrahedra=simplex), (1.0, -0.5, 0.3)
    body = Body("box", mesh, LinearElastic(1000.0, 0.3), supports=(Support("bottom"),),
                tractions=(Traction("top", value=value),), order=order, subdomains=k)
    condensation.assemble(body)
    return body


MESHES = [pytest.param(2, 16, 1, False, id="quad1"), pytest.param(2, 12, 1, True, id="tri1"),
          pytest.param(2, 8, 2, False, id="quad2"), pytest.param(2, 8, 2, True, id="tri2"),
          pytest.param(3, 6, 1, False, id="hex1"), pytest.param(3, 4, 1, True, id="tet1"),
          pytest.param(3, 3, 2, False, id="hex2"), pytest.param(3, 3, 2, True, id="tet2")]


# -- the partition ------------------------------------------------------------------------------

#: meshes of 200 to 400 elements: enough for METIS to balance to its tolerance (a 27-element
#: cube cannot be halved within 3 %)
PARTITION_MESHES = {"quad": lambda: rectangle(nx=16, ny=16),
                    "tri": lambda: rectangle(nx=12, ny=12, triangles=True),
                    "hex": lambda: box(nx=6, ny=6, nz=6),
                    "tet": lambda: box(nx=4, ny=4, nz=4, tetrahedra=True)}


@pytest.mark.parametrize("kind", PARTITION_MESHES)
@pytest.mark.parametrize("k", [2, 4, 8, 16])
def test_partition_covers_balances_and_repeats(kind, k):
    mesh = PARTITION_MESHES[kind]()
    parts = partition(mesh, k)
    ne = mesh.nelements
    assert parts.shape == (ne,) and parts.min() == 0 and parts.max() == k - 1
    sizes = np.bincount(parts, minlength=k)
    assert (sizes > 0).all()
    assert sizes.max() <= IMBALANCE * ne / k + 1, sizes
    assert np.array_equal(parts, partition(mesh, k))  # the same on every run
    # each subdomain is contiguous: connected through shared facets
    xadj, adjncy = element_graph(mesh)
    for i in range(k):
        inside = np.flatnonzero(parts == i)
        seen, front = {inside[0]}, [inside[0]]
        while front:
            e = front.pop()
            for f in adjncy[xadj[e]:xadj[e + 1]]:
                if parts[f] == i and f not in seen:
                    seen.add(f)
                    front.append(f)
        assert len(seen) == len(inside), f"subdomain {i} in pieces"


def test_partition_is_the_same_in_a_fresh_process():
    """METIS's seed is fixed: another interpreter (another run) gets the same partition."""
    import subprocess
    import sys

    code = ("from vfem.bodies.subdomains import partition; from vfem.mesh.solids import box; "
            "print(partition(box(nx=6, ny=6, nz=6, tetrahedra=True), 8).tolist())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    here = partition(box(nx=6, ny=6, nz=6, tetrahedra=True), 8)
    assert json.loads(out) == here.tolist()


def test_element_graph_is_the_shared_facets():
    mesh = rectangle(nx=3, ny=2)
    xadj, adjncy = element_graph(mesh)
    degree = np.diff(xadj)
    # 3 x 2 quadrilaterals: corner elements have 2 neighbours, the middle ones 3
    assert sorted(degree.tolist()) == [2, 2, 2, 2, 3, 3]
    for e in range(mesh.nelements):
        for f in adjncy[xadj[e]:xadj[e + 1]]:
            assert len(set(mesh.t[:, e]) & set(mesh.t[:, f])) == 2  # one shared edge


def test_one_subdomain_is_the_body():
    assert not partition(rectangle(nx=4, ny=4), 1).any()


# -- the subdomain matrices and the split solve ---------------------------------------------------

@pytest.mark.parametrize("dim, n, order, simplex", MESHES)
@pytest.mark.parametrize("k", [2, 4, 8])
def test_split_solve_equals_direct(dim, n, order, simplex, k):
    body = _body(dim, n, order, simplex, k)
    K_ff = body.K_ff
    nf = K_ff.shape[0]
    matrices, dofs = subdomain_matrices(body, body_partition(body))
    total = sp.csr_matrix((nf, nf))
    for A, d in zip(matrices, dofs):
        R = sp.csr_matrix((np.ones(len(d)), (np.arange(len(d)), d)), shape=(len(d), nf))
        total = total + R.T @ A @ R
    assert abs(total - K_ff).max() <= 1e-14 * abs(K_ff).max()

    f = body.f_load[body.free_dofs]
    direct = spla.spsolve(K_ff, f)
    rng = np.random.default_rng(0)
    block = np.column_stack([f, rng.standard_normal(nf), np.zeros(nf)])
    direct_block = np.column_stack([direct, spla.spsolve(K_ff, block[:, 1]), np.zeros(nf)])
    trailing = np.arange(0, nf, max(1, nf // 7))
    split = split_solve(body, trailing=trailing)
    x = split.solve(f)
    assert x.shape == f.shape
    assert abs(x - direct).max() <= 1e-10 * abs(direct).max()
    X = split.solve(block)
    scale = abs(direct_block).max(axis=0)
    scale[2] = 1.0
    assert (abs(X - direct_block).max(axis=0) <= 1e-10 * scale).all()
    E = np.zeros((nf, len(trailing)))
    E[trailing, np.arange(len(trailing))] = 1.0
    inverse = spla.spsolve(K_ff.tocsc(), sp.csc_matrix(E)).toarray()[trailing]
    assert abs(split.trailing_inverse - inverse).max() <= 1e-10 * abs(inverse).max()
    assert np.array_equal(split.trailing_inverse, split.trailing_inverse.T)
    assert 0 < max(split.iterations) <= 60  # bounded: measured 8 to 35 on these meshes


def _top_and_bottom(mesh):
    """``mesh`` with its ``bottom`` and ``top`` boundaries named (its last coordinate 0, 1)."""
    d = mesh.p.shape[0] - 1
    return mesh.with_boundaries({"bottom": lambda x: x[d] < 1e-9,
                                 "top": lambda x: x[d] > 1 - 1e-9})


CURVED = {"tri2": lambda: MeshTri2.from_mesh(rectangle(nx=6, ny=6, triangles=True)),
          "quad2": lambda: MeshQuad2.from_mesh(rectangle(nx=6, ny=6)),
          "hex2": lambda: MeshHex2.from_mesh(box(nx=3, ny=3, nz=3)),
          "tet2": lambda: MeshTet2.from_mesh(box(nx=3, ny=3, nz=3, tetrahedra=True))}


@pytest.mark.parametrize("kind", [*CURVED, "axisymmetric"])
def test_split_solve_on_quadratic_geometry_and_axisymmetric(kind):
    """The meshes of quadratic geometry (their own nodes the points) and the axisymmetric
    section (its own stiffness form, per full circle) split as the others do."""
    if kind == "axisymmetric":
        mesh = rectangle(x0=0.5, nx=8, ny=8)
        material = LinearElastic(1000.0, 0.3, plane="axisymmetric")
    else:
        mesh = _top_and_bottom(CURVED[kind]())
        material = LinearElastic(1000.0, 0.3)
    value = (1.0, -0.5, 0.3)[: mesh.p.shape[0]]
    body = Body("b", mesh, material, supports=(Support("bottom"),),
                tractions=(Traction("top", value=value),), order=2, subdomains=4)
    condensation.assemble(body)
    f = body.f_load[body.free_dofs]
    direct = spla.spsolve(body.K_ff, f)
    x = split_solve(body).solve(f)
    assert abs(x - direct).max() <= 1e-10 * abs(direct).max()


@pytest.mark.parametrize("backend", linalg.available())
def test_split_solve_with_every_backend(backend):
    """The subdomains' and the coarse factorizations by any installed backend: the same
    answer; a one-column block comes back as a block."""
    body = _body(3, 4, 1, False, 4)
    f = body.f_load[body.free_dofs]
    direct = spla.spsolve(body.K_ff, f)
    split = split_solve(body, backend)
    assert split.subdomains[0].A_II.name == backend
    X = split.solve(f[:, None])
    assert X.shape == (len(f), 1)
    assert abs(X[:, 0] - direct).max() <= 1e-10 * abs(direct).max()


def test_unconverged_interface_solve_stops(monkeypatch):
    """Past its iteration limit the split solve raises, naming the body, instead of returning
    an unconverged answer."""
    from vfem.linalg import bddc

    body = _body(2, 8, 1, False, 4)
    split = split_solve(body)
    monkeypatch.setattr(bddc, "MAX_ITERATIONS", 2)
    with pytest.raises(AnalysisError, match=r"body 'box': the subdomains' interface problem "
                                            r"did not converge in 2 iterations"):
        split.solve(body.f_load[body.free_dofs])


def test_island_subdomain_gets_primal_points():
    """A subdomain inside another (its cut touches neither the boundary nor a third
    subdomain) has no primal point by the rule; the completion gives it two, else its Neumann
    problem would float and the split solve could not equal the direct one."""
    body = _body(2, 8, 1, False, 2)
    centre = body.mesh.p[:, body.mesh.t].mean(axis=1)
    island = (abs(centre[0] - 0.5) < 0.2) & (abs(centre[1] - 0.5) < 0.2)
    body._partition = (body.mesh, 2, island.astype(int))
    f = body.f_load[body.free_dofs]
    direct = spla.spsolve(body.K_ff, f)
    split = split_solve(body)
    assert split.n_primal >= 4  # two points, two dofs each
    assert abs(split.solve(f) - direct).max() <= 1e-10 * abs(direct).max()


def test_cut_between_supports_needs_no_coarse_problem():
    """A square held on its left and right sides, cut across between them: the cut's ends are
    supported, so there is no free primal dof (an empty coarse problem), and each half is held
    by its supports alone."""
    mesh = rectangle(nx=8, ny=8)
    body = Body("held", mesh, LinearElastic(1000.0, 0.3),
                supports=(Support("left"), Support("right")),
                tractions=(Traction("top", value=(0.0, -1.0)),), subdomains=2)
    condensation.assemble(body)
    upper = mesh.p[1, mesh.t].mean(axis=0) > 0.5
    body._partition = (body.mesh, 2, upper.astype(int))
    f = body.f_load[body.free_dofs]
    direct = spla.spsolve(body.K_ff, f)
    split = split_solve(body)
    assert split.n_primal == 0
    assert abs(split.solve(f) - direct).max() <= 1e-10 * abs(direct).max()


# -- contact models with a split body --------------------------------------------------------------

SPHERE = ("bodies.sphere.mesh.h_contact=0.5", "bodies.flat.mesh.h_fine=0.6")  # 1,944 + 3,000 dofs
#: coarser cylinders (4,400 + 3,300 dofs): the friction's stick and slip zones all the same
CATTANEO = ("bodies.upper.mesh.h_max=0.1", "bodies.lower.mesh.h_max=0.1")
MODELS = {"stack": ("examples/stack.toml", "plate1", ()),
          "sphere": ("examples/sphere.toml", "flat", SPHERE),
          "cattaneo": ("examples/cattaneo.toml", "lower", CATTANEO)}


@functools.cache
def _run(model: str, route: str, k: int):
    path, body, sets = MODELS[model]
    config = load(path, [*sets, f"contact.flexibility={route}", f"bodies.{body}.subdomains={k}"])
    built = config.build()
    return vfem.solve(built), built


@pytest.mark.parametrize("k", [2, 4, 8])
@pytest.mark.parametrize("model, route", [("stack", "dense"), ("stack", "matrix_free"),
                                          ("sphere", "dense"), ("sphere", "matrix_free"),
                                          ("cattaneo", "dense")])
def test_split_body_contact_equals_unsplit(model, route, k):
    """Every node's displacement and contact force, every step, equal to the unsplit run's to
    1e-8 of the largest (the matrix-free route refuses friction: cattaneo is dense only)."""
    whole, _ = _run(model, route, 1)
    split, built = _run(model, route, k)
    assert whole.converged and split.converged
    assert len(split.steps) == len(whole.steps)
    body = next(b for b in built.bodies if b.name == MODELS[model][1])
    assert len(body.subdomain_sizes["dofs"]) == k and max(body.factor.iterations) > 0
    for a, b in zip(whole.steps, split.steps, strict=True):
        assert b.load_factor == a.load_factor
        for name, ra in a.bodies.items():
            rb = b.bodies[name]
            for field in ("displacement", "contact_force"):
                x, y = getattr(ra, field), getattr(rb, field)
                assert abs(y - x).max() <= 1e-8 * abs(x).max(), (name, field)


def test_partition_in_results(tmp_path):
    """The VTU has each element's subdomain as a cell field, summary.json the sizes; an
    unsplit body has neither (its files as before)."""
    from vfem.io import runner

    config = load("examples/stack.toml", ["bodies.plate1.subdomains=4"])
    model = config.build()
    summary = runner.run(config, tmp_path, figures=False, model=model)
    sizes = summary["subdomains"]["plate1"]
    plate1 = next(b for b in model.bodies if b.name == "plate1")
    assert sizes["count"] == 4 and sum(sizes["elements"]) == plate1.mesh.nelements
    assert sizes["pcg_iterations_max"] > 0
    assert set(summary["subdomains"]) == {"plate1"}
    assert json.loads((tmp_path / "summary.json").read_text())["subdomains"] == summary[
        "subdomains"]
    vtu = meshio.read(tmp_path / "plate1_step0001.vtu")
    assert np.array_equal(vtu.cell_data["subdomain"][0], body_partition(plate1))
    assert "subdomain" not in meshio.read(tmp_path / "plate0_step0001.vtu").cell_data
    # the screen says the split was used, for the split body alone
    split_lines = [line for line in runner.report(summary, tmp_path) if "subdomains" in line]
    assert len(split_lines) == 1 and "'plate1' split into 4 subdomains" in split_lines[0]


# -- input ----------------------------------------------------------------------------------------

def test_subdomains_key_checked():
    with pytest.raises(InputError, match=r"plate1.*subdomains must be a whole number >= 1.*0"):
        load("examples/stack.toml", ["bodies.plate1.subdomains=0"]).build()
    with pytest.raises(InputError, match=r"subdomains: expected an integer, got the string"):
        load("examples/stack.toml", ["bodies.plate1.subdomains=many"])
    with pytest.raises(InputError, match=r"body 'base': only a linear body can be split into "
                                         r"subdomains .*large kinematics \('total'\).*not 2"):
        load("examples/friction/slide3d.toml", ["bodies.base.subdomains=2"]).build()
    with pytest.raises(InputError, match=r"more subdomains \(100000\) than elements"):
        load("examples/stack.toml", ["bodies.plate1.subdomains=100000"]).build()


def test_plastic_body_refuses_subdomains():
    body = Body("soft", rectangle(nx=2, ny=2),
                J2Plastic(youngs_modulus=1000.0, poissons_ratio=0.3, yield_stress=1.0),
        supports=(Support("bottom"),), subdomains=2)
    with pytest.raises(InputError, match=r"body 'soft': only a linear body .*a plastic material"):
        body.validate()
