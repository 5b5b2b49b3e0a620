"""Seeded random two-body contact models, each answer checked by code of its own (issue 37's
acceptance study: "solve what users bring").

The examples and tests are models someone chose; this study draws models nobody chose, solves
each with vfem's defaults (the paired variant) and, in 2D, with the classical Lagrange baseline
(``contact.method = "lagrange"``, docs/baselines.md), and checks every converged answer with
code that knows nothing of either contact formulation. Each model ends in one of three classes:

* ``solved``: the analysis converged and every check below passes at every converged step;
* ``stopped``: no answer: the analysis did not converge, raised one of the library's errors
  (``vfem.errors``; the first ~100 characters of its message are kept), crashed, or ran past the
  per-model timeout ("stopped (timeout)");
* ``wrong``: it said "converged" but a check fails: a false answer.

**The distribution** (model ``2d-K`` draws from ``np.random.default_rng([seed, 2, K])``, model
``3d-K`` from ``[seed, 3, K]``, so a model never changes when the counts do). Units: the upper
body is 1 wide in plan; the lower body, a block with its top at y = 0 (z = 0 in 3D), is fixed at
its base.

* 2D (plane strain): upper body a flat punch (rectangle, quadrilaterals or triangles), a rounded
  punch (rectangle with filleted corners, ``filleted_punch``), a round-faced punch (arc face of
  radius 1-10, ``rounded_punch``), a half disk and a quarter disk, curved side down
  (``graded_half_disk``, ``graded_quarter_disk``: the quarter's lowest point is its corner), or
  a rectangle rotated by 1-6 degrees (meshed with Gmsh, read from a ``.msh`` file). Block 0.8-3
  wide, quadrilaterals or triangles. Elements linear, or quadratic for 25 % of the models (the
  arcs then curved, ``mesh.curve``, in half of those that have one).
* 3D: upper body a box (hexahedra or tetrahedra), a box tilted by 3-15 degrees about the x or y
  axis so that an edge lands first (Gmsh tetrahedra), a sphere-ended cylinder (end radius
  0.65-3) or a flat-ended cylinder (radius 0.5, ``cylinder``); block a box 0.8-2.2 in plan,
  hexahedra or tetrahedra. Linear elements; at most 15,000 dofs (both meshes coarsened
  together, keeping their ratio, until they fit).
* Stiffness ratio upper/lower log-uniform in [1e-3, 1e3] (lower E log-uniform in [1, 1e4]), each
  Poisson's ratio uniform in [0, 0.45]; facet-length ratio upper/lower log-uniform in [0.25, 4];
  initial gap 0 (15 %) or uniform in 0-5 of the shorter facet length, measured as the least
  vertical distance between the bodies over the block; the upper body's centre anywhere in plan
  where the two bodies still overlap (so it may overhang the block's edge: corner contact);
  2-6 equal load steps.
* Loading (the upper body's top held laterally): a prescribed displacement of the top, the gap
  plus a push, or (35 %) a force-controlled platen (docs/input.md, ``platen``). The push (or
  force) is chosen for a contact strain of a few percent at most: 0.2-2 % of the smallest of
  the overlap, the upper body's height and the block's height for flat faces; a Hertz
  estimate (contact half-width 2 R eps, eps 0.5-4 %; 1-5 % in 3D) for curved ones. Corners make
  the pointwise strain singular; each model records its largest strain.

**The checks**, on each body at every converged step, from the final fields alone (displacement
and contact force at the body's points, the solver's reported reactions), the meshes, the
materials and the supports this script set up. Nothing of the formulation is read (no pairing,
traction unknowns, tolerances' readings), and neither ``vfem.contact.invariants.check`` nor
``check3d`` (the solver's own invariants) is called; the stiffness is assembled here with
scikit-fem.

1. *Each body in equilibrium*: K u - f_contact, K assembled here (``skfem.models.elasticity.
   linear_elasticity``, Lame's constants from E and nu; plane strain in 2D), vanishes at the
   free dofs and equals the solver's reported reaction at the constrained ones, both within
   1e-8 of the largest nodal force of the model (or, where all forces are smaller than that,
   a body moved rigidly before it touches, 1e-14 of the largest |K| |u| of a dof: round-off);
   the supports hold (u = 0), the prescribed top is where it was told to be, the platen's dofs
   move together and its reaction is its force (within ``contact.platen_tolerance``, 1e-5),
   and no contact force acts off the boundary.
2. *Balance between the bodies*: the sum of both bodies' contact forces is within 1e-8 of the
   larger body's total.
3. *No tension*: each node's contact force along its own body's outward normal (the mean of its
   boundary facets' normals) is not tensile beyond 1e-6 of the largest nodal force. Quadratic
   elements: each vertex carries its own force plus half of each adjacent facet's midpoint
   force (its share under the linear hat function, which keeps a compressive traction
   compressive), compared at 5e-2: a quadratic traction interpolating values >= 0 may dip below
   zero between the nodes by up to 1/8 of them where a contact zone ends, so that reading may
   be slightly tensile on a correct answer.
4. *No interpenetration on the deformed geometry*: every boundary node of each body (vertices,
   and midpoints of quadratic facets) at X + u is tested against the other body's deformed
   boundary (2D: the polygon of its boundary facets, a quadratic facet as 8 chords of its
   curve, by ray parity; 3D: its boundary triangles, a quadrilateral as four triangles about
   its centre, by the winding number); a node inside is as deep as its distance to that
   boundary. A quadrilateral's four triangles are not the elements' own surface (bilinear on
   each facet, away from them by up to a quarter of its twist): near a quadrilateral, inside
   and depth are read on the bilinear patch itself (``_bilinear_depth``; a node on the rim
   of 3d-16's cylinder lay 7.4e-5 inside the triangles, 1.6e-5 inside the block's own
   surface). The rule: **wrong when depth > penetration tolerance + 2 % of the push**, the
   tolerance being vfem's default reading, 1e-5 of the shortest boundary facet of the model,
   and the push the model's imposed approach after the gap closes (prescribed: the top's final
   motion less the gap; platen: the platen's final motion less the gap), the depth the largest
   over the converged steps. Every model records depth / push (and, for the deepest node, a
   faceting estimate (L/2) tan(alpha/2): L the facet it is under, alpha its own boundary's
   turning there) so that the threshold can be discussed: a stiff body's corner between the
   nodes of a finer, softer surface lies inside it by a faceting depth that the solver's own
   invariant allows for, and this rule counts it once it passes 2 % of the push.
   *Small kinematics* (every model as drawn) is linear theory: the gap is linearised in the
   displacements, and on the deformed geometry a right answer differs from it by second-order
   terms. Where a node is deeper than the threshold, it is read again as that theory reads it:
   its offset from the material point of the other body nearest it at rest, both displaced,
   along the direction between them at rest (the other body's normal where they touch). If
   that reading is within the threshold and the node still lies over the same straight facet
   it touched at rest (or one that lay in its line, or plane, at rest: a block's flat top),
   its deformed depth is that facet's rotation times the node's slide along it and nothing
   else (``linearised_depth``), and the linearised reading counts; a node that has passed
   onto a facet that turned from it at rest is judged by its deformed depth (measured, seed
   0: the 2D linear models 2d-30, 2d-91, 2d-125, 2d-191, 2d-275, the quadratic 2d-165 and 3d-8 were
   2.0-8.0 % of the push inside on the deformed geometry and within it as linear theory
   reads them; 2d-91's block corner slid 4.8e-3 along a facet turned 0.037 rad). The summary
   line counts the solved models that are beyond the threshold on the deformed geometry.
   Under large kinematics (``--remedies``' "total") the deformed depth alone counts, and
   check 1's K u (linear elasticity's) is not applied.
   In 3D the **edges** are read too: 15 points along each sharp boundary edge of a body
   (its facets turning by 30 degrees or more across it: a box's edges), between its corners,
   on the deformed geometry alone (no linearised reading: it is a node's). Without them a
   stiff box's edge sinking into a softer, finer block between the box's vertices, where one
   of the block's facets spans it, went unseen (the tilted cube of issue 37:
   ``benchmarks/tilted_cube.py``, 0.0117 inside, 58 % of the push, every node outside).

**Plastic blocks** (``--plastic``, issue 41): the same models with the block elasto-plastic
(:func:`plastic`: J2, the yield stress 0.1-1 of the contact stress's scale E* eps, linear
isotropic hardening none or up to 0.1 E; linear elements). A body that carries a material
state is solved by Newton's method, and so the model by the Newton contact formulation
(``vfem.contact.formulations.large``), whose equilibrium check 1 (K u) does not apply.
**Bodies of revolution** (``--axisymmetric``, issue 42): the 2D models with both materials
``plane = "axisymmetric"``, moved out from the axis (:func:`axisymmetric`), the checks' K u =
f with an axisymmetric stiffness written here (:func:`_axisymmetric_elasticity`); a platen's
force per full circle round the upper body's centre line.

**Large kinematics** (``--large``): the same models with both bodies total Lagrangian (linear
elements, the block elastic; with ``--plastic`` too, plastic), solved by that formulation too.
Found on their first runs (2026-12-02): that formulation enforced contact at the compatibility
side's nodes alone, and the other surface's nodes then lay inside by up to the solver's
faceting allowance, beyond 2 % of the push on 125 (``--plastic``) and 133 (``--large``) of the
300 2D models (2d-6: 0.95 of the push, 2.7e-6 under small kinematics); it now holds them as
small kinematics does (docs/method.md §10: 1 and 0 wrong).

**Rerunning**::

    python3 benchmarks/random_models.py                      # 300 2D and 60 3D models, seed 0
    python3 benchmarks/random_models.py --count-2d 20 --count-3d 4 -v     # a quick look
    python3 benchmarks/random_models.py --only 2d-17 3d-4 -v              # chosen models again
    python3 benchmarks/random_models.py --json out.json      # every model's parameters, checks
    python3 benchmarks/random_models.py --dump 2d-17 /tmp/m17    # as an input file:
    vfem run /tmp/m17/random_2d-17.toml    # (add --set contact.method=lagrange for the baseline)
    python3 benchmarks/random_models.py --plastic --count-3d 6 --no-baseline  # plastic blocks
    python3 benchmarks/random_models.py --large --no-baseline    # large kinematics
    python3 benchmarks/random_models.py --axisymmetric --count-3d 0 --no-baseline  # r-z
    python3 benchmarks/random_models.py --remedies   # then each stop again: the other
                                          # compatibility side, 4x the steps, large kinematics

One line at the end sums it up per class (2D linear, 2D quadratic, 3D) and for the baseline
(the baselines need linear elements: run on the 2D linear models only; its answers get the same
checks); "warned of" counts the models on which vfem itself warned that a node lies inside
on the deformed geometry beyond what faceting and linear theory's second-order terms explain
(``Invariants.second_order``; the warning does not change a model's class: a wrong answer
warned of is still counted wrong); ``-v`` adds one line per model. Models run in parallel
(``--jobs``), each solve in its own process on one BLAS thread, killed after ``--timeout``
seconds. It measures the vfem it imports: ``PYTHONPATH=/tmp/tree/src python3
benchmarks/random_models.py`` measures another tree (``git archive COMMIT src | tar -x -C
/tmp/tree``).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one BLAS thread per worker, set before NumPy loads

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import json  # noqa: E402
import logging  # noqa: E402
import math  # noqa: E402
import multiprocessing as mp  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402
from multiprocessing.connection import wait as wait_for  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402
from skfem import (  # noqa: E402
    Basis,
    BilinearForm,
    ElementHex1,
    ElementQuad1,
    ElementQuad2,
    ElementTetP1,
    ElementTriP1,
    ElementTriP2,
    ElementVector,
    MeshHex,
    MeshTet,
    MeshTri,
    asm,
)
from skfem.models.elasticity import linear_elasticity  # noqa: E402

import vfem  # noqa: E402
from vfem.config import (  # noqa: E402
    BodyConfig,
    Curve,
    MeshSpec,
    ModelConfig,
    Steps,
    as_parameters,
)
from vfem.errors import VfemError  # noqa: E402
from vfem.materials import J2Plastic  # noqa: E402

SHAPES_2D = ("flat_punch", "rounded_punch", "round_face", "half_disk", "quarter_disk",
             "rotated_rect")
SHAPES_3D = ("box", "tilted_box", "sphere_cylinder", "flat_cylinder")
CLASSES = ("2D linear", "2D quadratic", "3D")

WIDTH = 1.0  # the upper body's width in plan (diameter of the cylinders)
MAX_DOFS = {(2, 1): 16_000, (2, 2): 30_000, (3, 1): 15_000}
RESIDUAL_TOL = 1e-8  # check 1, of the largest nodal force of the model
BALANCE_TOL = 1e-8  # check 2, of the larger body's total contact force
TENSION_TOL = {1: 1e-6, 2: 5e-2}  # check 3, of the largest nodal force, by element order
EDGE_ANGLE = 30.0  # check 4, 3D: degrees between facets that make an edge sharp
EDGE_POINTS = 15  # check 4, 3D: points read along each sharp edge between its corners
PUSH_FRACTION = 0.02  # check 4: depth allowed beyond the penetration tolerance, of the push
PEN_TOL_FACTOR = 1e-5  # vfem's default penetration tolerance, of the shortest facet
SUBDIVIDE = 8  # chords per quadratic facet in check 4
BC_TOL = 1e-12  # supports and prescribed motions, of the largest displacement
PLATEN_TOL = 1e-5  # the default contact.platen_tolerance


# -- the distribution ---------------------------------------------------------------------------


def _log_uniform(rng, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def _sizes(rng, span: float, ratio: float, n_lower: tuple[int, int], n_upper: tuple[int, int]
           ) -> tuple[float, float]:
    """Facet lengths (lower, upper = ratio * lower) with span / lower and WIDTH / upper facets
    within the given ranges (as far as the ratio allows), log-uniform between."""
    lo = max(span / n_lower[1], WIDTH / (n_upper[1] * ratio))
    hi = min(span / n_lower[0], WIDTH / (n_upper[0] * ratio))
    h = lo if lo >= hi else _log_uniform(rng, lo, hi)
    return h, ratio * h


def _plane_modulus(E: float, nu: float) -> float:
    return E / (1.0 - nu * nu)


def plastic(p: dict) -> dict:
    """Model ``p`` with its block elasto-plastic (``--plastic``, issue 41): J2 with the yield
    stress a share of the contact stress's scale E* eps, log-uniform in [0.1, 1], and linear
    isotropic hardening none (30 %) or log-uniform in [1e-3, 0.1] of the block's E; linear
    elements (a plastic body in a contact model takes no others). Drawn from
    ``[seed, dim, k, 41]``: the elastic parameters are the study's own."""
    q = dict(p)
    dim, k = p["dim"], int(p["id"].partition("d-")[2])
    rng = np.random.default_rng([p["seed"], dim, k, 41])
    q["order"], q["curved"] = 1, False
    q["yield_ratio"] = _log_uniform(rng, 0.1, 1.0)
    q["hardening_ratio"] = 0.0 if rng.random() < 0.3 else _log_uniform(rng, 1e-3, 0.1)
    return q


def large(p: dict) -> dict:
    """Model ``p`` with both bodies under large kinematics (``--large``): total Lagrangian,
    linear elements (large-kinematics contact takes no others), the block elastic or, with
    ``--plastic``, plastic. The Newton contact formulation solves it, as it solves every
    plastic model."""
    q = dict(p)
    q["order"], q["curved"] = 1, False
    q["kinematics"] = "total"
    return q


def axisymmetric(p: dict) -> dict:
    """Model ``p`` (2D) as bodies of revolution (``--axisymmetric``, issue 42): both materials'
    ``plane = "axisymmetric"``, the model moved out from the axis by WIDTH times 1 plus a
    log-uniform share in [0.02, 10] (the upper body's left edge then 0.05 WIDTH to 10 WIDTH
    from it: an annular punch on an annular block, the measure 2 pi r varying across the
    contact by up to a factor of 40), drawn from ``[seed, dim, k, 42]``. The checks read the
    axisymmetric stiffness (:class:`BodyCheck`); the rest is the plane-strain model's."""
    q = dict(p)
    k = int(p["id"].partition("d-")[2])
    rng = np.random.default_rng([p["seed"], p["dim"], k, 42])
    q["axis_offset"] = WIDTH * (1.0 + _log_uniform(rng, 0.02, 10.0))
    return q


def draw(seed: int, dim: int, k: int) -> dict:
    """The parameters of model ``{dim}d-{k}`` (plain numbers: JSON and TOML print them)."""
    rng = np.random.default_rng([seed, dim, k])
    p: dict = {"id": f"{dim}d-{k}", "dim": dim, "seed": seed}
    p["shape"] = str(rng.choice(SHAPES_2D if dim == 2 else SHAPES_3D))
    p["order"] = 2 if dim == 2 and rng.random() < 0.25 else 1
    p["E_lower"] = _log_uniform(rng, 1.0, 1e4)
    p["stiffness_ratio"] = _log_uniform(rng, 1e-3, 1e3)
    p["E_upper"] = p["E_lower"] * p["stiffness_ratio"]
    p["nu_upper"], p["nu_lower"] = (float(v) for v in rng.uniform(0.0, 0.45, 2))
    p["mesh_ratio"] = _log_uniform(rng, 0.25, 4.0)
    p["loading"] = "platen" if rng.random() < 0.35 else "displacement"
    p["steps"] = int(rng.integers(2, 7))
    p["gap_facets"] = 0.0 if rng.random() < 0.15 else float(rng.uniform(0.0, 5.0))
    p["height"] = float(rng.uniform(0.4, 1.0))
    p["upper_simplices"] = bool(rng.random() < 0.4)
    p["lower_simplices"] = bool(rng.random() < 0.4)
    p["aspect_lower"] = float(rng.uniform(1.0, 2.0))  # element height / width in the block
    p["aspect_upper"] = float(rng.uniform(1.0, 1.6))
    shape = p["shape"]
    if dim == 2:
        p["block_width"] = float(rng.uniform(0.8, 3.0))
        p["block_height"] = float(rng.uniform(0.3, 1.2))
        p["h_lower"], p["h_upper"] = _sizes(rng, p["block_width"], p["mesh_ratio"], (6, 60),
                                            (4, 60))
        margin = 0.05 * WIDTH
        p["centre"] = [float(rng.uniform(-0.5 * WIDTH + margin,
                                         p["block_width"] + 0.5 * WIDTH - margin))]
        if shape == "rounded_punch":
            p["fillet_radius"] = float(rng.uniform(0.05, 0.35)) * WIDTH
        elif shape == "round_face":
            p["face_radius"] = _log_uniform(rng, 1.0, 10.0) * WIDTH
        elif shape in ("half_disk", "quarter_disk"):
            p["growth"] = float(rng.uniform(0.3, 2.0))
        elif shape == "rotated_rect":
            p["angle_deg"] = float(rng.uniform(1.0, 6.0) * rng.choice([-1.0, 1.0]))
        p["curved"] = bool(p["order"] == 2 and shape in ("round_face", "half_disk",
                                                          "quarter_disk")
                           and rng.random() < 0.5)
    else:
        p["block_width"] = float(rng.uniform(0.8, 2.2))
        p["block_depth"] = float(rng.uniform(0.8, 2.2))
        p["block_height"] = float(rng.uniform(0.3, 0.8))
        p["h_lower"], p["h_upper"] = _sizes(rng, max(p["block_width"], p["block_depth"]),
                                            p["mesh_ratio"], (4, 20), (3, 20))
        p["height"] = float(rng.uniform(0.4, 0.8))
        margin = 0.05 * WIDTH
        for _ in range(1000):  # the upper body's centre: its footprint overlaps the block's
            c = [float(rng.uniform(-0.5 * WIDTH + margin, p["block_width"] + 0.5 * WIDTH
                                   - margin)),
                 float(rng.uniform(-0.5 * WIDTH + margin, p["block_depth"] + 0.5 * WIDTH
                                   - margin))]
            if "cylinder" not in shape:
                break
            nearest = np.clip(c, 0.0, [p["block_width"], p["block_depth"]])
            if np.hypot(*(np.asarray(c) - nearest)) < 0.5 * WIDTH - margin:
                break
        p["centre"] = c
        if shape == "sphere_cylinder":
            p["end_radius"] = float(rng.uniform(1.3, 6.0)) * 0.5 * WIDTH
        elif shape == "tilted_box":
            p["tilt_axis"] = str(rng.choice(["x", "y"]))
            p["angle_deg"] = float(rng.uniform(3.0, 15.0) * rng.choice([-1.0, 1.0]))
    curved_face = shape in ("round_face", "half_disk", "quarter_disk", "sphere_cylinder")
    p["strain"] = (_log_uniform(rng, 0.005, 0.04) if curved_face and dim == 2
                   else _log_uniform(rng, 0.01, 0.05) if curved_face
                   else _log_uniform(rng, 0.002, 0.02))
    return p


# -- meshes and the model ------------------------------------------------------------------------


def scalar_element(mesh, order: int):
    if isinstance(mesh, MeshTet):
        return ElementTetP1()
    if isinstance(mesh, MeshHex):
        return ElementHex1()
    if isinstance(mesh, MeshTri):
        return ElementTriP2() if order == 2 else ElementTriP1()
    return ElementQuad2() if order == 2 else ElementQuad1()


class Geometry:
    """A body's mesh as the checks see it: the points (scikit-fem's dofs of the scalar
    element, which number the body's points), its boundary facets as lists of points, their
    outward normals, and the boundary drawn at any positions of the points (2D: chords; 3D:
    triangles)."""

    def __init__(self, mesh, order: int):
        self.mesh, self.order, self.dim = mesh, order, mesh.p.shape[0]
        self.element = scalar_element(mesh, order)
        if order == 1:
            self.X = np.asarray(mesh.p, dtype=float)
            dofs = None
        else:
            basis = Basis(mesh, self.element)
            self.X, dofs = basis.doflocs, basis.dofs
        bf = mesh.boundary_facets()
        corners = mesh.facets[:, bf].T.copy()  # (nf, 2, 3 or 4)
        centroid = mesh.p[:, mesh.t[:, mesh.f2t[0, bf]]].mean(axis=1).T  # adjacent element
        if self.dim == 3 and corners.shape[1] == 4:
            corners = _order_quads(mesh.p, corners)
        P = mesh.p[:, corners].transpose(1, 2, 0)  # (nf, k, dim)
        if self.dim == 2:
            d = P[:, 1] - P[:, 0]
            n = np.column_stack([d[:, 1], -d[:, 0]])
        else:
            n = 0.5 * np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
            if corners.shape[1] == 4:  # the quadrilateral's vector area
                n = 0.5 * np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 1])
        flip = np.einsum("ij,ij->i", n, P.mean(axis=1) - centroid) < 0
        n[flip] *= -1.0
        corners[flip] = corners[flip][:, ::-1]  # outward (3D: by the right-hand rule)
        self.normal = n / np.linalg.norm(n, axis=1)[:, None]  # (nf, dim), unit, outward
        self.size = (np.linalg.norm(P[:, 1] - P[:, 0], axis=1) if self.dim == 2 else
                     np.max([np.linalg.norm(P[:, i] - P[:, i - 1], axis=1)
                             for i in range(P.shape[1])], axis=0))
        self.corners = corners
        self.mids = dofs.facet_dofs[0, bf] if order == 2 else None  # 2D quadratic facets
        nodes = [corners.ravel()] + ([self.mids] if self.mids is not None else [])
        self.bnodes = np.unique(np.concatenate(nodes))
        self.npoints = self.X.shape[1]
        # each boundary node's normal (the mean of its facets'), and its own turning
        acc = np.zeros((self.npoints, self.dim))
        for j in range(corners.shape[1]):
            np.add.at(acc, corners[:, j], self.normal * self.size[:, None])
        if self.mids is not None:
            acc[self.mids] += self.normal
        norm = np.linalg.norm(acc, axis=1)
        self.node_normal = np.divide(acc, norm[:, None], out=np.zeros_like(acc),
                                     where=norm[:, None] > 0)
        cos = np.ones(self.npoints)
        for j in range(corners.shape[1]):  # the largest angle between a node's facet normals
            np.minimum.at(cos, corners[:, j],
                          np.einsum("ij,ij->i", self.normal, self.node_normal[corners[:, j]]))
        self.turning = 2.0 * np.arccos(np.clip(cos, -1.0, 1.0))
        self.sharp_edges = self._sharp_edges() if self.dim == 3 and order == 1 else \
            np.zeros((0, 2), dtype=int)

    def _sharp_edges(self) -> np.ndarray:
        """3D: (k, 2) the boundary's edges (corner points) across which its facets turn by
        :data:`EDGE_ANGLE` or more: a box's edges, not a faceted cylinder's."""
        c = self.corners
        k = c.shape[1]
        ends = np.sort(np.stack([c, np.roll(c, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
        facet = np.repeat(np.arange(len(c)), k)
        keys, inverse, counts = np.unique(ends, axis=0, return_inverse=True,
                                          return_counts=True)
        inverse = inverse.ravel()
        order = np.argsort(inverse, kind="stable")
        first = np.concatenate([[0], np.cumsum(counts)[:-1]])
        f1, f2 = facet[order[first]], facet[order[first + counts - 1]]
        cos = np.einsum("ij,ij->i", self.normal[f1], self.normal[f2])
        return keys[(counts == 2) & (cos < math.cos(math.radians(EDGE_ANGLE)))]

    def surface(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The boundary at point positions ``x`` (dim, npoints): 2D segments (m, 2, 2), 3D
        triangles (m, 3, 3), and for each the length of the facet it belongs to."""
        c = self.corners
        if self.dim == 2:
            if self.mids is None:
                return x[:, c].transpose(1, 2, 0), self.size
            s = np.linspace(0.0, 1.0, SUBDIVIDE + 1)
            N = np.array([(1 - s) * (1 - 2 * s), s * (2 * s - 1), 4 * s * (1 - s)])  # (3, k)
            nodes = np.column_stack([c, self.mids])  # (nf, 3)
            pts = np.einsum("jk,dfj->fkd", N, x[:, nodes])  # (nf, k, 2)
            segs = np.stack([pts[:, :-1], pts[:, 1:]], axis=2).reshape(-1, 2, 2)
            return segs, np.repeat(self.size, SUBDIVIDE)
        P = x[:, c].transpose(1, 2, 0)  # (nf, k, 3)
        if c.shape[1] == 3:
            return P, self.size
        centre = P.mean(axis=1)
        tris = np.stack([np.stack([P[:, i], P[:, (i + 1) % 4], centre], axis=1)
                         for i in range(4)], axis=1).reshape(-1, 3, 3)
        return tris, np.repeat(self.size, 4)


def _order_quads(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Corners of quadrilateral facets (nf, 4) in cyclic order: of the three orders, the one
    with the shortest perimeter."""
    orders = np.array([[0, 1, 2, 3], [0, 1, 3, 2], [0, 2, 1, 3]])
    per = np.stack([sum(np.linalg.norm(p[:, q[:, o[i]]] - p[:, q[:, o[(i + 1) % 4]]], axis=0)
                        for i in range(4)) for o in orders])
    return np.take_along_axis(q, orders[per.argmin(axis=0)], axis=1)


def lowest_over(geo: Geometry, lo: np.ndarray, hi: np.ndarray) -> float:
    """The lowest point (last coordinate) of the body's boundary over the box lo <= x <= hi in
    plan (2D: an interval of x; 3D: a rectangle of (x, y)): vertices inside, crossings of the
    facets' edges with its sides, its corners under facets."""
    segs, _ = geo.surface(geo.X)
    d = geo.dim
    if d == 2:
        a, b = segs[:, 0], segs[:, 1]
        cand = [np.vstack([a, b])]
        for xc in (lo[0], hi[0]):
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (xc - a[:, 0]) / (b[:, 0] - a[:, 0])
            ok = (t >= 0) & (t <= 1)
            cand.append(a[ok] + t[ok, None] * (b[ok] - a[ok]))
        pts = np.vstack(cand)
        inside = (pts[:, 0] >= lo[0] - 1e-12) & (pts[:, 0] <= hi[0] + 1e-12)
        return float(pts[inside, 1].min())
    tris = segs
    cand = [tris.reshape(-1, 3)]
    for i in range(3):  # edges against the four sides
        a, b = tris[:, i], tris[:, (i + 1) % 3]
        for axis in (0, 1):
            for xc in (lo[axis], hi[axis]):
                with np.errstate(divide="ignore", invalid="ignore"):
                    t = (xc - a[:, axis]) / (b[:, axis] - a[:, axis])
                ok = (t >= 0) & (t <= 1)
                cand.append(a[ok] + t[ok, None] * (b[ok] - a[ok]))
    for cx in (lo[0], hi[0]):  # the corners, under (or over) facets
        for cy in (lo[1], hi[1]):
            a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
            det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1]
                                                                                 - a[:, 1])
            with np.errstate(divide="ignore", invalid="ignore"):
                l1 = ((cx - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0])
                      * (cy - a[:, 1])) / det
                l2 = ((b[:, 0] - a[:, 0]) * (cy - a[:, 1]) - (cx - a[:, 0])
                      * (b[:, 1] - a[:, 1])) / det
                ok = (l1 >= 0) & (l2 >= 0) & (l1 + l2 <= 1) & np.isfinite(l1)
            z = a[ok, 2] + l1[ok] * (b[ok, 2] - a[ok, 2]) + l2[ok] * (c[ok, 2] - a[ok, 2])
            cand.append(np.column_stack([np.full(ok.sum(), cx), np.full(ok.sum(), cy), z]))
    pts = np.vstack(cand)
    tol = 1e-12
    inside = np.all((pts[:, :2] >= lo - tol) & (pts[:, :2] <= hi + tol), axis=1)
    return float(pts[inside, 2].min())


def _gmsh_rotated(path: Path, p: dict) -> None:
    """The rotated rectangle (2D) or tilted box (3D) as a Gmsh file: named top, bottom, ...;
    its plan centre at the origin, lowest point anywhere (placed afterwards)."""
    import gmsh

    w, hgt, h, th = WIDTH, p["height"], p["h_upper"], math.radians(p["angle_deg"])
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("upper")
        if p["dim"] == 2:
            s = gmsh.model.occ.addRectangle(-0.5 * w, 0.0, 0.0, w, hgt)
            gmsh.model.occ.rotate([(2, s)], 0.0, 0.5 * hgt, 0.0, 0.0, 0.0, 1.0, th)
            axis = np.array([0.0, 0.0, 1.0])
            ent, dim = s, 2
        else:
            s = gmsh.model.occ.addBox(-0.5 * w, -0.5 * w, 0.0, w, w, hgt)
            axis = np.array([1.0, 0.0, 0.0] if p["tilt_axis"] == "x" else [0.0, 1.0, 0.0])
            gmsh.model.occ.rotate([(3, s)], 0.0, 0.0, 0.5 * hgt, *axis, th)
            ent, dim = s, 3
        gmsh.model.occ.synchronize()
        c, s_ = math.cos(th), math.sin(th)
        k = axis / np.linalg.norm(axis)  # Rodrigues: the rotation back
        K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        R = np.eye(3) + s_ * K + (1 - c) * K @ K
        names: dict[str, list[int]] = {}
        for _, b in gmsh.model.getBoundary([(dim, ent)], oriented=False):
            x = np.array(gmsh.model.occ.getCenterOfMass(dim - 1, b))
            local = R.T @ (x - [0.0, 0.5 * hgt, 0.0] if dim == 2 else x - [0.0, 0.0, 0.5 * hgt])
            up = local[1] if dim == 2 else local[2]
            if up > 0.5 * hgt - 1e-7:
                name = "top"
            elif up < -0.5 * hgt + 1e-7:
                name = "bottom"
            elif dim == 2 or abs(local[0]) > 0.5 * w - 1e-7:
                name = "left" if local[0] < 0 else "right"
            else:
                name = "front" if local[1] < 0 else "back"
            names.setdefault(name, []).append(b)
        for name, tags in names.items():
            gmsh.model.addPhysicalGroup(dim - 1, tags, name=name)
        gmsh.model.addPhysicalGroup(dim, [ent], name="upper")
        gmsh.option.setNumber("Mesh.MeshSizeMin", h)
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.model.mesh.generate(dim)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


def _upper_spec(p: dict, folder: Path) -> tuple[MeshSpec, str, tuple | None]:
    """The upper body's mesh, unplaced: (spec, its top boundary, (arc boundary, centre, radius)
    for a circular face)."""
    shape, w, hgt, h = p["shape"], WIDTH, p["height"], p["h_upper"]
    n = max(2, round(w / h))
    rows = max(2, round(hgt / (h * p["aspect_upper"])))
    if shape == "flat_punch":
        return MeshSpec(shape="rectangle", parameters=as_parameters(
            x0=-0.5 * w, y0=0.0, width=w, height=hgt, nx=n, ny=rows,
            triangles=p["upper_simplices"])), "top", None
    if shape == "rounded_punch":
        r = p["fillet_radius"]
        n_arc = max(2, round(0.5 * math.pi * r / h))
        return MeshSpec(shape="filleted_punch", parameters=as_parameters(
            x0=0.0, y0=0.0, width=w, height=hgt, radius=r, n_flat=max(1, round((w - 2 * r) / h)),
            n_arc=n_arc, rows=n_arc + max(2, round((hgt - r) / (h * p["aspect_upper"]))))
        ), "top", None
    if shape == "round_face":
        R = p["face_radius"]
        return MeshSpec(shape="rounded_punch", parameters=as_parameters(
            x0=0.0, y0=0.0, width=w, height=hgt, radius=R, nx=n, ny=max(3, rows))
        ), "top", ("face", (0.0, R), R)
    if shape in ("half_disk", "quarter_disk"):
        R = 0.5 * w if shape == "half_disk" else w
        h_max = max(h, min(R / 3.0, 6.0 * h))
        params = as_parameters(radius=R, h_contact=h, h_max=h_max, growth=p["growth"])
        kind = "graded_half_disk" if shape == "half_disk" else "graded_quarter_disk"
        return (MeshSpec(shape=kind, parameters=params), "flat" if shape == "half_disk"
                else "top", ("contact", (0.0, R), R))
    if shape == "box":
        return MeshSpec(shape="box", parameters=as_parameters(
            x0=-0.5 * w, y0=-0.5 * w, z0=0.0, width=w, depth=w, height=hgt, nx=n, ny=n,
            nz=rows, tetrahedra=p["upper_simplices"])), "top", None
    if shape in ("sphere_cylinder", "flat_cylinder"):
        extra = {"end_radius": p["end_radius"]} if shape == "sphere_cylinder" else {}
        return MeshSpec(shape="cylinder", parameters=as_parameters(
            radius=0.5 * w, height=hgt, quarter=False, h=h, tetrahedra=p["upper_simplices"],
            **extra)), "top", None
    # rotated_rect, tilted_box: Gmsh
    _gmsh_rotated(folder / "upper.msh", p)
    return MeshSpec(file="upper.msh"), "top", None


def _lower_spec(p: dict) -> MeshSpec:
    W, H, h = p["block_width"], p["block_height"], p["h_lower"]
    rows = max(2, round(H / (h * p["aspect_lower"])))
    if p["dim"] == 2:
        return MeshSpec(shape="rectangle", parameters=as_parameters(
            x0=0.0, y0=-H, width=W, height=H, nx=max(2, round(W / h)), ny=rows,
            triangles=p["lower_simplices"]))
    D = p["block_depth"]
    return MeshSpec(shape="box", parameters=as_parameters(
        x0=0.0, y0=0.0, z0=-H, width=W, depth=D, height=H, nx=max(2, round(W / h)),
        ny=max(2, round(D / h)), nz=rows, tetrahedra=p["lower_simplices"]))


def _ndofs(mesh, order: int) -> int:
    from skfem.assembly import Dofs

    return int(Dofs(mesh, scalar_element(mesh, order)).N) * mesh.p.shape[0]


def _overlap(p: dict, geo: Geometry, shift: np.ndarray) -> float:
    """The plan overlap of the placed upper body and the block: a length (2D), an area (3D)."""
    x = geo.X + shift[:, None]
    if p["dim"] == 2:
        return max(0.0, min(x[0].max(), p["block_width"]) - max(x[0].min(), 0.0))
    if "cylinder" in p["shape"]:  # a disk of radius WIDTH / 2 about the centre: sampled
        u = (np.arange(200) + 0.5) / 200 - 0.5
        U, V = np.meshgrid(u * WIDTH, u * WIDTH)
        disk = U ** 2 + V ** 2 <= 0.25 * WIDTH ** 2
        X, Y = U + p["centre"][0], V + p["centre"][1]
        inside = disk & (X >= 0) & (X <= p["block_width"]) & (Y >= 0) & (Y <= p["block_depth"])
        return float(inside.sum() * (WIDTH / 200) ** 2)
    lo, hi = x[:2].min(axis=1), x[:2].max(axis=1)
    size = np.minimum(hi, [p["block_width"], p["block_depth"]]) - np.maximum(lo, 0.0)
    return float(np.prod(np.maximum(size, 0.0)))


def build(p: dict, folder: Path) -> tuple[ModelConfig, dict]:
    """The model of parameters ``p`` as an input-file description (mesh files, if any, written
    into ``folder``), and what the checks need: the gap, the push (for a platen: its force),
    the boundary conditions, the sizes used."""
    p = dict(p)
    dim, order = p["dim"], p["order"]
    for _ in range(8):  # coarsen both meshes together until the model fits its dofs
        upper_spec, top, arc = _upper_spec(p, folder)
        lower_spec = _lower_spec(p)
        upper_mesh, lower_mesh = upper_spec.make(folder), lower_spec.make(folder)
        ndofs = _ndofs(upper_mesh, order) + _ndofs(lower_mesh, order)
        if ndofs <= MAX_DOFS[dim, order]:
            break
        scale = 1.05 * (ndofs / MAX_DOFS[dim, order]) ** (1.0 / dim)
        p["h_lower"] *= scale
        p["h_upper"] *= scale
    curve = None
    if arc is not None and p.get("curved"):
        upper_spec = dataclasses.replace(upper_spec, curve=Curve(arc[0], arc[1], arc[2]))
        upper_mesh = upper_spec.make(folder)
    geo = Geometry(upper_mesh, order)
    centre = 0.5 * (geo.X[: dim - 1].min(axis=1) + geo.X[: dim - 1].max(axis=1))
    plan = np.asarray(p["centre"]) - centre
    block_hi = np.array([p["block_width"]] + ([p["block_depth"]] if dim == 3 else []))
    lowest = lowest_over(geo, -plan, block_hi - plan)
    h_min = min(p["h_lower"], p["h_upper"])
    gap = p["gap_facets"] * h_min
    shift = np.append(plan, gap - lowest)
    off_axis = np.zeros(dim)
    off_axis[0] = p.get("axis_offset", 0.0)  # --axisymmetric: the whole model moved out
    placed = shift + off_axis
    translate = tuple(float(v) for v in placed)
    if arc is not None and p.get("curved"):
        curve = Curve(arc[0], tuple(float(c + s) for c, s in zip(arc[1], placed)), arc[2])
    upper_spec = dataclasses.replace(upper_spec, translate=translate, curve=curve)

    # the push: a contact strain of p["strain"]
    eps, overlap = p["strain"], _overlap(p, geo, shift)
    Ep = 1.0 / (1.0 / _plane_modulus(p["E_upper"], p["nu_upper"])
                + 1.0 / _plane_modulus(p["E_lower"], p["nu_lower"]))
    length = overlap if dim == 2 else math.sqrt(overlap)
    flat_push = eps * min(length, p["height"], p["block_height"])
    flat_force = eps * Ep * overlap
    R = {"round_face": p.get("face_radius"), "half_disk": 0.5 * WIDTH, "quarter_disk": WIDTH,
         "sphere_cylinder": p.get("end_radius")}.get(p["shape"])
    if R is None:
        push, force = flat_push, flat_force
    elif dim == 2:  # Hertz: half-width a = 2 R eps, approach ~ a^2 / R, F = pi a^2 E* / (4 R)
        a = min(2.0 * R * eps, 0.4 * WIDTH)
        push, force = a * a / R, min(math.pi * a * a * Ep / (4.0 * R), flat_force)
    else:  # Hertz: a = R eps, approach a^2 / R, F = 4/3 E* sqrt(R) d^1.5
        a = min(R * eps, 0.4 * WIDTH)
        push = a * a / R
        force = min(4.0 / 3.0 * Ep * math.sqrt(R) * push ** 1.5, flat_force)
    if "axis_offset" in p:  # per full circle: round the upper body's centre line
        force *= 2.0 * math.pi * (p["axis_offset"] + p["centre"][0])
    comps = ("x", "y", "z")[:dim]
    vertical = comps[-1]
    held = vfem.Support(top, comps[:-1])
    if p["loading"] == "platen":
        motion = {"platen": vfem.Platen(top, vertical, -force)}
    else:
        motion = {"prescribed": (vfem.PrescribedDisplacement(top, vertical, -(gap + push)),)}
    section = {"plane": "axisymmetric"} if "axis_offset" in p else {}
    upper = BodyConfig("upper", upper_spec, vfem.LinearElastic(p["E_upper"], p["nu_upper"],
                                                               **section),
                       order=order, supports=(held,), **motion)
    material = vfem.LinearElastic(p["E_lower"], p["nu_lower"], **section)
    if "yield_ratio" in p:  # --plastic: the block elasto-plastic, yielding at a share of the
        # contact stress's scale E* eps
        Y = p["yield_ratio"] * Ep * eps
        material = J2Plastic(p["E_lower"], p["nu_lower"], Y,
                             hardening_modulus=p["hardening_ratio"] * p["E_lower"])
    lower_spec = _lower_spec(p)
    if "axis_offset" in p:
        lower_spec = dataclasses.replace(lower_spec, translate=tuple(float(v) for v in off_axis))
    lower = BodyConfig("block", lower_spec, material,
                       order=order, supports=(vfem.Support("bottom", comps),))
    if "kinematics" in p:  # --large
        upper, lower = (dataclasses.replace(b, kinematics=p["kinematics"])
                        for b in (upper, lower))
    n = p["steps"]
    config = ModelConfig(f"random_{p['id']}", (upper, lower),
                         steps=Steps(load_factors=tuple((i + 1) / n for i in range(n))))
    info = {"gap": gap, "push": push, "force": force if p["loading"] == "platen" else None,
            "top": top, "h_lower": p["h_lower"], "h_upper": p["h_upper"], "ndofs": ndofs,
            "overlap": overlap, "lowest": lowest}
    return config, info


# -- the independent checks ------------------------------------------------------------------


def _lame(E: float, nu: float) -> tuple[float, float]:
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


class BodyCheck:
    """One body's stiffness (assembled here), constrained dofs and boundary (:class:`Geometry`)."""

    def __init__(self, body, bcs: list[tuple]):
        self.name, self.dim = body.name, body.mesh.p.shape[0]
        self.geo = Geometry(body.mesh, body.order)
        vb = Basis(body.mesh, ElementVector(self.geo.element))
        d = self.dim
        if not all(np.allclose(vb.doflocs[:, c::d], self.geo.X) for c in range(d)):
            raise AssertionError("scikit-fem's vector dofs are not interleaved by point")
        E, nu = body.material.youngs_modulus, body.material.poissons_ratio
        form = (_axisymmetric_elasticity if body.material.plane == "axisymmetric"
                else linear_elasticity)
        self.K = asm(form(*_lame(E, nu)), vb).tocsr()
        self.ndofs = self.K.shape[0]
        self.support, self.prescribed, self.platen = [], [], None
        for kind, boundary, comps, value in bcs:
            for c in comps:
                dofs = vb.get_dofs(body.mesh.boundaries[boundary]).all(f"u^{'xyz'.index(c) + 1}")
                if kind == "support":
                    self.support.append(dofs)
                elif kind == "prescribed":
                    self.prescribed.append((dofs, value))
                else:
                    self.platen = (dofs, value)
        fixed = self.support + [d_ for d_, _ in self.prescribed]
        fixed += [self.platen[0]] if self.platen else []
        self.fixed = np.unique(np.concatenate(fixed)) if fixed else np.zeros(0, dtype=int)
        self.free = np.setdiff1d(np.arange(self.ndofs), self.fixed)
        interior = np.setdiff1d(np.arange(self.geo.npoints), self.geo.bnodes)
        self.interior_dofs = (interior[:, None] * d + np.arange(d)).ravel()
        self.vb = vb


def _axisymmetric_elasticity(lam: float, mu: float) -> BilinearForm:
    """Isotropic elasticity on a body of revolution about the y axis, written here from the
    strains (e_rr, e_zz, e_tt = u_r / r, e_rz) and the measure 2 pi r dA, not read from vfem
    (its own is :class:`vfem.bodies.section.Axisymmetric`'s): ``--axisymmetric``'s K u = f."""

    @BilinearForm
    def form(u, v, w):
        r = w.x[0]

        def strain(f):
            g = f.grad
            return (g[0, 0], g[1, 1], f[0] / r, 0.5 * (g[0, 1] + g[1, 0]))

        a, b = strain(u), strain(v)
        ta, tb = a[0] + a[1] + a[2], b[0] + b[1] + b[2]
        inner = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2.0 * a[3] * b[3]
        return 2.0 * np.pi * r * (lam * ta * tb + 2.0 * mu * inner)

    return form


def _inside_2d(pts: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """Ray parity: which points lie inside the closed polylines ``segs`` (m, 2, 2)."""
    out = np.zeros(len(pts), dtype=bool)
    a, b = segs[:, 0], segs[:, 1]
    for i in range(0, len(pts), 256):
        P = pts[i:i + 256, None, :]
        ya, yb = a[None, :, 1], b[None, :, 1]
        cross = (ya > P[..., 1]) != (yb > P[..., 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            x = a[None, :, 0] + (P[..., 1] - ya) * (b[None, :, 0] - a[None, :, 0]) / (yb - ya)
        out[i:i + 256] = (cross & (P[..., 0] < x)).sum(axis=1) % 2 == 1
    return out


def _distance_2d(pts: np.ndarray, segs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance from each point to the nearest segment, and that segment."""
    a, b = segs[:, 0], segs[:, 1]
    d = b - a
    L2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    dist, which = np.empty(len(pts)), np.empty(len(pts), dtype=int)
    for i in range(0, len(pts), 256):
        P = pts[i:i + 256, None, :]
        t = np.clip(np.einsum("pmj,mj->pm", P - a[None], d) / L2, 0.0, 1.0)
        r = np.linalg.norm(P - (a[None] + t[..., None] * d[None]), axis=2)
        which[i:i + 256] = r.argmin(axis=1)
        dist[i:i + 256] = r.min(axis=1)
    return dist, which


def _winding_3d(pts: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """The winding number of the closed, outward-oriented triangulation ``tris`` (m, 3, 3)
    about each point (1 inside, 0 outside; van Oosterom and Strackee's solid angles)."""
    out = np.empty(len(pts))
    for i in range(0, len(pts), 32):
        A = tris[None, :, 0] - pts[i:i + 32, None]
        B = tris[None, :, 1] - pts[i:i + 32, None]
        C = tris[None, :, 2] - pts[i:i + 32, None]
        a, b, c = (np.linalg.norm(v, axis=2) for v in (A, B, C))
        num = np.einsum("pmj,pmj->pm", A, np.cross(B, C))
        den = (a * b * c + np.einsum("pmj,pmj->pm", A, B) * c
               + np.einsum("pmj,pmj->pm", A, C) * b + np.einsum("pmj,pmj->pm", B, C) * a)
        out[i:i + 32] = 2.0 * np.arctan2(num, den).sum(axis=1) / (4.0 * np.pi)
    return out


def _distance_3d(pts: np.ndarray, tris: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance from each point to the nearest triangle, and that triangle."""
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    n = np.cross(b - a, c - a)
    n2 = np.maximum(np.einsum("ij,ij->i", n, n), 1e-300)
    dist, which = np.empty(len(pts)), np.empty(len(pts), dtype=int)

    def seg(P, u, v):
        d = v - u
        t = np.clip(np.einsum("pmj,mj->pm", P - u[None], d)
                    / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
        return np.linalg.norm(P - (u[None] + t[..., None] * d[None]), axis=2)

    for i in range(0, len(pts), 32):
        P = pts[i:i + 32, None, :]
        w = P - a[None]
        s = np.einsum("pmj,mj->pm", w, n) / n2  # the plane's distance along n / |n|^2
        Q = P - s[..., None] * n[None]  # the projection on the plane
        # barycentric coordinates of Q
        l1 = np.einsum("pmj,mj->pm", np.cross(c[None] - b[None], Q - b[None]), n) / n2
        l2 = np.einsum("pmj,mj->pm", np.cross(a[None] - c[None], Q - c[None]), n) / n2
        l3 = 1.0 - l1 - l2
        inside = (l1 >= 0) & (l2 >= 0) & (l3 >= 0)
        r = np.where(inside, np.abs(s) * np.sqrt(n2)[None],
                     np.minimum(np.minimum(seg(P, a, b), seg(P, b, c)), seg(P, c, a)))
        which[i:i + 32] = r.argmin(axis=1)
        dist[i:i + 32] = r.min(axis=1)
    return dist, which


def _bilinear_depth(pts: np.ndarray, quads: np.ndarray, nearest: int = 12
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points ``pts`` (m, 3) against quadrilateral facets ``quads`` (nf, 4, 3; corners in
    cyclic order, outward by the right-hand rule) as the finite elements draw them: bilinear
    patches x(a, b) = (1-a)(1-b) x0 + a(1-b) x1 + a b x2 + (1-a) b x3. For each point, the
    foot of its normal on the nearest patch it projects into (Newton's method on (a, b), over
    the ``nearest`` patches by centre); returns the signed distance along the patch's outward
    normal there (< 0: behind it, inside), the patch, and whether any patch took the point."""
    k = min(nearest, len(quads))
    cand = cKDTree(quads.mean(axis=1)).query(pts, k=k)[1].reshape(len(pts), k)
    q = quads[cand]  # (m, k, 4, 3)
    P = pts[:, None, :]
    a = np.full(cand.shape, 0.5)
    b = np.full(cand.shape, 0.5)
    for _ in range(25):  # Newton on |x(a, b) - P|^2 (exact for a flat patch in one)
        xa = (1 - b)[..., None] * (q[..., 1, :] - q[..., 0, :]) + b[..., None] * (
            q[..., 2, :] - q[..., 3, :])
        xb = (1 - a)[..., None] * (q[..., 3, :] - q[..., 0, :]) + a[..., None] * (
            q[..., 2, :] - q[..., 1, :])
        r = (((1 - a) * (1 - b))[..., None] * q[..., 0, :] + (a * (1 - b))[..., None]
             * q[..., 1, :] + (a * b)[..., None] * q[..., 2, :] + ((1 - a) * b)[..., None]
             * q[..., 3, :]) - P
        J11, J12, J22 = ((u * v).sum(axis=-1) for u, v in ((xa, xa), (xa, xb), (xb, xb)))
        g1, g2 = (r * xa).sum(axis=-1), (r * xb).sum(axis=-1)
        det = J11 * J22 - J12**2
        det = np.where(np.abs(det) > 0, det, 1e-300)
        a, b = a - (J22 * g1 - J12 * g2) / det, b - (J11 * g2 - J12 * g1) / det
    n = np.cross(xa, xb)
    n /= np.maximum(np.linalg.norm(n, axis=-1), 1e-300)[..., None]
    ok = (a >= -1e-9) & (a <= 1 + 1e-9) & (b >= -1e-9) & (b <= 1 + 1e-9)
    d = np.where(ok, np.linalg.norm(r, axis=-1), np.inf)
    best = d.argmin(axis=1)
    rows = np.arange(len(pts))
    took = np.isfinite(d[rows, best])
    signed = np.where(took, -(r[rows, best] * n[rows, best]).sum(axis=-1), np.inf)
    return signed, np.where(took, cand[rows, best], -1), took


def _closest(P: np.ndarray, facets: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """The distance from point P to the nearest of ``facets`` (2D segments (m, 2, 2), 3D
    triangles (m, 3, 3)): the distance, and for every facet within round-off of it its index
    and the weights of its corners that give the closest point ((k,), (k, 2 or 3))."""
    a = facets[:, 0]
    if facets.shape[1] == 2:
        d = facets[:, 1] - a
        t = np.clip(np.einsum("mj,mj->m", P - a, d)
                    / np.maximum(np.einsum("mj,mj->m", d, d), 1e-300), 0.0, 1.0)
        w = np.column_stack([1.0 - t, t])
    else:
        b, c = facets[:, 1], facets[:, 2]
        n = np.cross(b - a, c - a)
        n2 = np.maximum(np.einsum("ij,ij->i", n, n), 1e-300)
        Q = P - (np.einsum("mj,mj->m", P - a, n) / n2)[:, None] * n
        l1 = np.einsum("mj,mj->m", np.cross(c - b, Q - b), n) / n2
        l2 = np.einsum("mj,mj->m", np.cross(a - c, Q - c), n) / n2
        w = np.column_stack([l1, l2, 1.0 - l1 - l2])
        out = (w < 0).any(axis=1)
        if out.any():  # the nearest point of the triangle's edges
            best = np.full(out.sum(), np.inf)
            wo = np.zeros((out.sum(), 3))
            for i in range(3):
                u, v = facets[out, i], facets[out, (i + 1) % 3]
                e = v - u
                t = np.clip(np.einsum("mj,mj->m", P - u, e)
                            / np.maximum(np.einsum("mj,mj->m", e, e), 1e-300), 0.0, 1.0)
                r = np.linalg.norm(P - (u + t[:, None] * e), axis=1)
                better = r < best
                best[better] = r[better]
                wo[better] = 0.0
                wo[better, i] = 1.0 - t[better]
                wo[better, (i + 1) % 3] = t[better]
            w[out] = wo
    r = np.linalg.norm(P - np.einsum("mk,mkj->mj", w, facets), axis=1)
    near = np.flatnonzero(r <= r.min() + 1e-9 * max(float(np.ptp(facets)), 1e-300))
    return float(r.min()), near, w[near]


def _facet_normals(facets: np.ndarray) -> np.ndarray:
    """Unit outward normals of oriented segments (2D) or triangles (3D)."""
    if facets.shape[1] == 2:
        d = facets[:, 1] - facets[:, 0]
        n = np.column_stack([d[:, 1], -d[:, 0]])
    else:
        n = np.cross(facets[:, 1] - facets[:, 0], facets[:, 2] - facets[:, 0])
    return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]


def linearised_depth(A: BodyCheck, node: int, xA: np.ndarray, surfaces: tuple
                     ) -> tuple[float, float, bool]:
    """Node ``node`` of A against B as small kinematics reads it: the gap between the node and
    the material point of B nearest it at rest, along the direction between them at rest (B's
    outward normal where they touch at rest), with both points displaced: -(x_P - x_Q) . n0
    (``surfaces``: B's boundary at rest, its facets' sizes and B's boundary now, as
    :meth:`Geometry.surface` draws them). The depth (> 0: inside), the tangential part of
    x_P - x_Q over the length of B's facet there (the slide, which small kinematics takes to
    be small), and whether the node is still nearest to that same straight facet of B on the
    deformed geometry, or to one that lay in its line (plane) at rest.

    Small kinematics linearises the gap in the displacements. While the node stays over the
    straight facet it touched at rest, its deformed depth is -(x_P - x_Q) . n with n that
    facet's normal now: the two readings differ by -(x_P - x_Q) . (n - n0), the slide times
    the facet's rotation, second order in the displacements, which no small-kinematics answer
    is free of; over a facet that lay in the same line (plane) at rest, the same with that
    facet's rotation. Once the node has passed onto a facet that turned from it at rest the
    difference is no longer that term alone (B's faceting, or a rigid approach along a curved
    surface), and is not read as one."""
    surf0, size, surf = surfaces  # B's boundary at rest (with its facets' sizes) and now
    XP, xP = A.geo.X[:, node], xA[:, node]
    dist0, near, w = _closest(XP, surf0)
    Q0 = np.einsum("k,kj->j", w[0], surf0[near[0]])
    if dist0 > 1e-9 * float(size[near].min()):
        n0 = (XP - Q0) / dist0
    else:  # touching at rest: B's outward normal there (the mean where facets meet)
        n0 = _facet_normals(surf0[near]).sum(axis=0)
        n0 /= max(float(np.linalg.norm(n0)), 1e-300)
    xQ = np.einsum("k,kj->j", w[0], surf[near[0]])
    r = xP - xQ
    depth = -float(r @ n0)
    slide = float(np.linalg.norm(r - (r @ n0) * n0 - (XP - Q0 - dist0 * n0)))
    _, now, _ = _closest(xP, surf)
    # the same straight facet, or one in the same line (plane) at rest: a block's flat top,
    # a quadratic facet's chords on a straight side
    n_rest, n_now = _facet_normals(surf0[near[:1]])[0], _facet_normals(surf0[now])
    off = np.einsum("kj,j->k", surf0[now].mean(axis=1) - surf0[near[0]].mean(axis=0), n_rest)
    flat = (np.einsum("kj,j->k", n_now, n_rest) >= 1.0 - 1e-12) & (
        np.abs(off) <= 1e-9 * float(size[near[0]]))
    return depth, slide / float(size[near[0]]), bool(flat.any())


def penetration(A: BodyCheck, xA: np.ndarray, B: BodyCheck, xB: np.ndarray,
                threshold: float = math.inf, small: bool = False) -> dict:
    """The deepest boundary node of A inside B, both at their deformed positions (dim, n).

    With ``small`` (small kinematics), a node deeper than ``threshold`` is read again as
    small kinematics reads it (:func:`linearised_depth`); where that reading is within the
    threshold and the node is still over the straight facet it touched at rest (or one in its
    line at rest), its depth on the deformed geometry is the linearisation's own second-order
    error and the linearised reading is "judged"; otherwise the deformed depth is. "judged"
    is the largest depth so counted, "second_order" how many nodes were read so."""
    nodes = A.geo.bnodes
    pts = xA[:, nodes].T
    surf, size = B.geo.surface(xB)
    best = {"depth": 0.0, "judged": 0.0, "second_order": 0}
    edge = _edge_depth(A, xA, B, xB, surf)
    if edge is not None:
        best.update(edge)
    inside, dist, which = _inside_depths(pts, B, xB, surf)
    if len(inside) == 0:
        return best
    j = int(dist.argmax())
    node = int(nodes[inside[j]])
    L, alpha = float(size[which[j]]), float(A.geo.turning[node])
    judged, excused, readings = dist.copy(), 0, {}
    if small:
        surfaces = (*B.geo.surface(B.geo.X), surf)
        for i in np.flatnonzero(dist > threshold):
            readings[i] = lin, _, same = linearised_depth(A, int(nodes[inside[i]]), xA,
                                                          surfaces)
            if lin <= threshold and same:
                judged[i], excused = max(lin, 0.0), excused + 1
    out = {"depth": float(dist[j]), "body": A.name, "node": node, "into": B.name,
           "at": [float(v) for v in pts[inside[j]]],
           "faceting_estimate": 0.5 * L * math.tan(0.5 * min(alpha, 3.0)),
           "judged": float(judged.max()), "second_order": excused}
    if j in readings:
        out["linearised"], out["slide"], out["same_facet"] = readings[j]
    if edge is not None and edge["depth"] > out["depth"]:
        out = {**edge, "judged": out["judged"], "second_order": excused}
    out["judged"] = max(out["judged"], edge["judged"] if edge is not None else 0.0)
    return out


def _inside_depths(pts: np.ndarray, B: BodyCheck, xB: np.ndarray, surf: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Of the points ``pts`` (n, dim), those inside B (deformed at ``xB``, its boundary
    ``surf``): (their indices, depth, the facet piece of B nearest each)."""
    dim = pts.shape[1]
    lo = surf.reshape(-1, dim).min(axis=0)
    hi = surf.reshape(-1, dim).max(axis=0)
    near = np.flatnonzero(np.all((pts >= lo) & (pts <= hi), axis=1))
    none = (np.zeros(0, dtype=int), np.zeros(0), np.zeros(0, dtype=int))
    if len(near) == 0:
        return none
    if dim == 2:
        inside = near[_inside_2d(pts[near], surf)]
    else:
        wind = _winding_3d(pts[near], surf) > 0.5
        if B.geo.corners.shape[1] == 4:
            # quadrilaterals: the four triangles about the centre are not the elements' own
            # (bilinear) surface, which departs from them by up to a quarter of the facet's
            # twist |x0 - x1 + x2 - x3|; near the surface, the depth is the bilinear patch's
            quads = xB[:, B.geo.corners].transpose(1, 2, 0)
            band = 0.25 * float(np.linalg.norm(quads[:, 0] - quads[:, 1] + quads[:, 2]
                                               - quads[:, 3], axis=1).max())
            dtri, _ = _distance_3d(pts[near], surf)
            again = np.flatnonzero(wind | (dtri <= band))
            signed, _, took = _bilinear_depth(pts[near[again]], quads)
            wind[again[took]] = signed[took] < 0
        inside = near[wind]
    if len(inside) == 0:
        return none
    dist, which = (_distance_2d if dim == 2 else _distance_3d)(pts[inside], surf)
    if dim == 3 and B.geo.corners.shape[1] == 4:
        quads = xB[:, B.geo.corners].transpose(1, 2, 0)
        signed, quad, took = _bilinear_depth(pts[inside], quads)
        dist = np.where(took, -signed, dist)
        which = np.where(took, 4 * quad, which)  # (a triangle of that quadrilateral)
    return inside, dist, which


def _edge_depth(A: BodyCheck, xA: np.ndarray, B: BodyCheck, xB: np.ndarray,
                surf: np.ndarray) -> dict | None:
    """3D: the deepest point inside B of A's sharp edges between their corners
    (:data:`EDGE_POINTS` along each, linear between the corners' deformed positions), read on
    the deformed geometry alone: a stiff box's edge that sinks into a softer, finer block
    between the box's vertices, where one of the block's facets spans it (the tilted cube of
    issue 37: 0.0117 inside, 58 % of the push, every node outside). None without sharp edges
    or with none of their points inside."""
    e = A.geo.sharp_edges
    if not len(e):
        return None
    t = np.arange(1, EDGE_POINTS + 1) / (EDGE_POINTS + 1)
    a, b = xA[:, e[:, 0]].T, xA[:, e[:, 1]].T  # (k, 3)
    pts = ((1 - t)[None, :, None] * a[:, None] + t[None, :, None] * b[:, None]).reshape(-1, 3)
    inside, dist, _ = _inside_depths(pts, B, xB, surf)
    if not len(inside):
        return None
    j = int(dist.argmax())
    k = int(inside[j]) // EDGE_POINTS
    return {"depth": float(dist[j]), "judged": float(dist[j]), "body": A.name,
            "edge": [int(e[k, 0]), int(e[k, 1])], "into": B.name,
            "at": [float(v) for v in pts[inside[j]]]}


def tension(bc: BodyCheck, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The normal component (outward: > 0 is tensile) of each boundary node's contact force,
    and the magnitudes it is compared with; quadratic: vertices with half their facets'
    midpoint forces."""
    g = bc.geo
    if g.mids is None:
        nodes = g.bnodes
        F = f[nodes]
    else:
        F = f.copy()
        for j in range(2):
            np.add.at(F, g.corners[:, j], 0.5 * f[g.mids])
        nodes = np.unique(g.corners)
        F = F[nodes]
    return np.einsum("ij,ij->i", F, g.node_normal[nodes]), np.linalg.norm(F, axis=1)


def max_strain(bc: BodyCheck, u: np.ndarray) -> float:
    """The largest absolute principal small strain at the quadrature points."""
    G = np.asarray(bc.vb.interpolate(u).grad)  # (dim, dim, nel, nqp)
    e = 0.5 * (G + G.transpose(1, 0, 2, 3))
    if bc.dim == 2:
        m, r = 0.5 * (e[0, 0] + e[1, 1]), np.hypot(0.5 * (e[0, 0] - e[1, 1]), e[0, 1])
        return float(np.max(np.abs(m) + r))
    vals = np.linalg.eigvalsh(np.moveaxis(e, (0, 1), (-2, -1)).reshape(-1, 3, 3))
    return float(np.abs(vals).max())


def check(result, p: dict, info: dict) -> dict:
    """Checks 1-4 (module docstring) at every converged step; the worst values and the checks
    that failed."""
    dim = p["dim"]
    top, vertical = info["top"], ("x", "y", "z")[dim - 1]
    lateral = ("x", "y", "z")[: dim - 1]
    bcs = {"block": [("support", "bottom", ("x", "y", "z")[:dim], 0.0)],
           "upper": [("support", top, lateral, 0.0)]}
    if p["loading"] == "platen":
        bcs["upper"].append(("platen", top, (vertical,), -info["force"]))
    else:
        bcs["upper"].append(("prescribed", top, (vertical,), -(info["gap"] + info["push"])))
    bodies = {b.name: BodyCheck(b, bcs[b.name]) for b in result.model.bodies}
    shortest = min(float(bc.geo.size.min()) for bc in bodies.values())
    if dim == 2 and p["order"] == 2:
        shortest *= 0.5  # a quadratic facet's nodes half a facet apart
    pen_tol = PEN_TOL_FACTOR * shortest
    worst = {"residual": 0.0, "reaction_mismatch": 0.0, "bc": 0.0, "platen": 0.0,
             "off_boundary": 0.0, "balance": 0.0, "tension": 0.0, "depth": 0.0,
             "judged_depth": 0.0, "second_order": 0, "max_strain": 0.0}
    small = not any(b.iterates for b in result.model.bodies)  # (Newton's: large, plastic)
    failed: dict[str, int] = {}
    deepest, push = None, info["push"]
    steps = result.steps
    if p["loading"] == "platen" and steps:  # the platen's final motion less the gap
        bc, u = bodies["upper"], steps[-1].bodies["upper"].displacement.ravel()
        push = max(float(abs(u[bc.platen[0]].mean())) - info["gap"], 0.0)
    threshold = pen_tol + PUSH_FRACTION * push
    for s in steps:
        lf, fields = s.load_factor, s.bodies
        nodal = max(max(float(np.abs(fields[n].contact_force).max()),
                        float(np.abs(fields[n].reaction).max())
                        if fields[n].reaction is not None else 0.0) for n in bodies)
        totals, readings = {}, []
        for name, bc in bodies.items():
            fb = fields[name]
            u, f = fb.displacement.ravel(), fb.contact_force.ravel()
            r = bc.K @ u - f
            # the largest nodal force, or where forces are smaller still (a body moved rigidly
            # before it touches) the round-off of K u: 1e-14 of the largest |K| |u| of a dof
            scale = max(nodal, 1e-6 * float((abs(bc.K) @ np.abs(u)).max()), 1e-300)
            worst["residual"] = max(worst["residual"], float(np.abs(r[bc.free]).max()) / scale)
            if fb.reaction is not None:
                mism = np.abs(r[bc.fixed] - fb.reaction.ravel()[bc.fixed]).max()
                worst["reaction_mismatch"] = max(worst["reaction_mismatch"],
                                                 float(mism) / scale)
            umax = max(float(np.abs(u).max()), 1e-300)
            errs = [np.abs(u[d_]).max() for d_ in bc.support]
            errs += [np.abs(u[d_] - v * lf).max() for d_, v in bc.prescribed]
            if bc.platen is not None:
                d_, F = bc.platen
                errs.append(np.ptp(u[d_]))
                worst["platen"] = max(worst["platen"],
                                      abs(float(r[d_].sum()) - F * lf) / abs(F * lf))
            worst["bc"] = max(worst["bc"], float(max(errs)) / umax)
            worst["off_boundary"] = max(worst["off_boundary"],
                                        float(np.abs(f[bc.interior_dofs]).max(initial=0.0))
                                        / scale)
            totals[name] = fb.contact_force.sum(axis=0)
            readings.append(tension(bc, fb.contact_force))
            worst["max_strain"] = max(worst["max_strain"], max_strain(bc, u))
        ref = max(float(mag.max(initial=0.0)) for _, mag in readings)
        pull = max(float(normal.max(initial=0.0)) for normal, _ in readings)
        if ref > 0:
            worst["tension"] = max(worst["tension"], pull / ref)
            if pull > TENSION_TOL[p["order"]] * ref:
                failed.setdefault("tension", s.step)
        big = max(float(np.linalg.norm(t)) for t in totals.values())
        bal = float(np.linalg.norm(sum(totals.values()))) / big if big > 0 else 0.0
        worst["balance"] = max(worst["balance"], bal)
        if bal > BALANCE_TOL:
            failed.setdefault("balance", s.step)
        x = {n: bc.geo.X + fields[n].displacement.T for n, bc in bodies.items()}
        for a, b in (("upper", "block"), ("block", "upper")):
            pen = penetration(bodies[a], x[a], bodies[b], x[b], threshold, small)
            if pen["depth"] > worst["depth"]:
                worst["depth"], deepest = pen["depth"], dict(pen, step=s.step)
            worst["judged_depth"] = max(worst["judged_depth"], pen["judged"])
            worst["second_order"] = max(worst["second_order"], pen["second_order"])
        if worst["judged_depth"] > threshold:
            failed.setdefault("penetration", s.step)
        for key, limit in (("residual", RESIDUAL_TOL), ("reaction_mismatch", RESIDUAL_TOL),
                           ("bc", BC_TOL), ("platen", PLATEN_TOL),
                           ("off_boundary", RESIDUAL_TOL)):
            if not small and key in ("residual", "reaction_mismatch", "platen"):
                continue  # K u is linear elasticity's: a Newton body has its own balance
            if worst[key] > limit:
                failed.setdefault(key, s.step)
    return {**worst, "deepest": deepest, "push": push, "pen_tol": pen_tol,
            "threshold": threshold, "depth_over_push": worst["depth"] / push if push > 0
            else (math.inf if worst["depth"] > 0 else 0.0),
            "failed": failed}


# -- one solve in its own process -----------------------------------------------------------


def solve_one(p: dict, method: str) -> dict:
    """Build model ``p``, solve it with ``method`` ("vfem" or "lagrange") and check it."""
    vfem.threads.apply(1)
    logging.getLogger("vfem").setLevel(logging.ERROR)  # the strain warnings: recorded here
    logging.getLogger("skfem").setLevel(logging.ERROR)
    rec: dict = {"method": method}
    with tempfile.TemporaryDirectory(prefix="vfem-random-") as tmp:
        try:
            config, info = build(p, Path(tmp))
            config = _variant(config, method)
            model = config.build(Path(tmp))
        except Exception as exc:  # the generator's fault, not the solver's
            return {**rec, "status": "invalid", "message": _first(exc)}
        rec.update(ndofs=info["ndofs"], gap=info["gap"], push_nominal=info["push"],
                   force=info["force"], h_lower=info["h_lower"], h_upper=info["h_upper"],
                   overlap=info["overlap"])
        t0 = time.perf_counter()
        try:
            result = vfem.solve(model)
        except VfemError as exc:
            return {**rec, "status": "stopped", "message": _first(exc), "message_full": str(exc),
                    "seconds": time.perf_counter() - t0}
        except Exception as exc:  # not one of the library's: a crash
            return {**rec, "status": "stopped", "message": "crash: " + _first(exc),
                    "seconds": time.perf_counter() - t0,
                    "traceback": traceback.format_exc()[-2000:]}
        rec.update(seconds=time.perf_counter() - t0, steps=len(result.steps),
                   iterations=[s.iterations for s in result.steps],
                   solver_pen_tol=result.penetration_tolerance,
                   # the solver switched a pair's compatibility side on the way (issue 37)
                   switched=bool(result.steps and result.steps[-1].compatibility_switched),
                   # vfem warned that a node lies inside on the deformed geometry beyond what
                   # faceting and linear theory's second order explain (its own invariant (b)
                   # reading, recorded, not enforced: Invariants.second_order)
                   warned=any(bool(s.invariants and s.invariants.get("second_order"))
                              for s in result.steps))
        try:
            checks = check(result, p, info)
        except Exception:
            return {**rec, "status": "stopped" if not result.converged else "check-error",
                    "message": result.message[:100] if not result.converged else "",
                    "traceback": traceback.format_exc()[-2000:]}
        rec["checks"] = checks
        if not result.converged:
            return {**rec, "status": "stopped", "message": result.message[:100].strip(),
                    "message_full": result.message, "cause": _cause(result.message)}
        if checks["failed"]:
            return {**rec, "status": "wrong", "message": ", ".join(checks["failed"])}
        return {**rec, "status": "solved", "message": ""}


#: the remedies tried on each stopped model (``--remedies``): the other body on the
#: compatibility side (each of the two forced), four times the steps, large kinematics
REMEDIES = ("side=upper", "side=block", "steps x4", "total")


def _variant(config: ModelConfig, method: str) -> ModelConfig:
    """The model as ``method`` solves it: "vfem" as drawn, "lagrange" the baseline, or one of
    :data:`REMEDIES`."""
    if method == "lagrange":
        return dataclasses.replace(config, contact=vfem.Contact(method="lagrange"))
    if method.startswith("side="):
        return dataclasses.replace(config, contact=dataclasses.replace(
            config.contact, compatibility_side=method[5:]))
    if method == "steps x4":
        n = 4 * len(config.steps.load_factors)
        return dataclasses.replace(config, steps=vfem.Steps(
            load_factors=tuple((i + 1) / n for i in range(n))))
    if method == "total":
        return dataclasses.replace(config, bodies=tuple(
            dataclasses.replace(b, kinematics="total") for b in config.bodies))
    return config


def remedy_summary(stopped: list[str], tried: dict[str, dict[str, dict]]) -> str:
    """One line: of the stopped models, how many each remedy solves (and turns wrong)."""
    parts = []
    for r in REMEDIES:
        recs = [tried[i][r] for i in stopped if r in tried[i]]
        n = {k: sum(x["status"] == k for x in recs) for k in ("solved", "wrong", "invalid")}
        parts.append(f"{r}: {n['solved']} solved, {n['wrong']} wrong"
                     + (f" ({n['invalid']} not applicable)" if n["invalid"] else ""))
    either = sum(any(tried[i].get(f"side={b}", {}).get("status") == "solved"
                     for b in ("upper", "block")) for i in stopped)
    return (f"remedies for the {len(stopped)} stopped models: " + "; ".join(parts)
            + f"; the other compatibility side (either forced) {either}")


def _cause(message: str) -> str:
    """What failed, from a stop's message: the step and the cause after "cut N times:"
    without the advice."""
    head, _, cause = message.partition(" failed with the increment cut ")
    cause = cause.partition(": ")[2] if cause else message
    return f"{head.split(' (')[0]}: {cause.split(' What to change')[0]}"[:100]


def _first(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {' '.join(str(exc).split())}"[:100]


def _child(task, conn) -> None:
    try:
        conn.send(solve_one(*task))
    except BaseException as exc:  # pragma: no cover - reported by the parent
        conn.send({"method": task[1], "status": "stopped", "message": "crash: " + _first(exc)})
    finally:
        conn.close()


def run_all(tasks: list[tuple[dict, str]], jobs: int, timeout: float, done) -> None:
    """Each task in its own (forked) process, ``jobs`` at a time, killed after ``timeout``."""
    ctx = mp.get_context("fork")
    pending, running = list(tasks), {}
    try:
        while pending or running:
            while pending and len(running) < jobs:
                task = pending.pop(0)
                recv, send = ctx.Pipe(duplex=False)
                proc = ctx.Process(target=_child, args=(task, send), daemon=True)
                proc.start()
                send.close()
                running[recv] = (proc, time.monotonic(), task)
            ready = wait_for(list(running), timeout=1.0)
            for conn in list(running):
                proc, t0, task = running[conn]
                rec = None
                if conn in ready:
                    try:
                        rec = conn.recv()
                    except EOFError:
                        proc.join(5)
                        rec = {"method": task[1], "status": "stopped",
                               "message": f"crash: the process ended ({proc.exitcode})"}
                elif time.monotonic() - t0 > timeout:
                    proc.kill()
                    rec = {"method": task[1], "status": "stopped",
                           "message": f"timeout ({timeout:g} s)", "seconds": timeout}
                if rec is not None:
                    proc.join(5)
                    conn.close()
                    del running[conn]
                    done(task[0], rec)
    finally:
        for proc, _, _ in running.values():
            proc.kill()


# -- the command ------------------------------------------------------------------------------


def model_class(p: dict) -> str:
    return "3D" if p["dim"] == 3 else "2D quadratic" if p["order"] == 2 else "2D linear"


def line(p: dict, recs: dict) -> str:
    """One model's line (-v)."""
    def part(r):
        if r is None:
            return "-"
        c = r.get("checks") or {}
        text = f"{r['status']}"
        if r.get("message"):
            text += f" [{(r.get('cause') or r['message'])[:70]}]"
        if c:
            text += f" depth/push {c['depth_over_push']:.2g}"
            if c["depth"] > c["threshold"] and c.get("judged_depth", c["depth"]) < c["depth"]:
                # (beyond the threshold on the deformed geometry, within it as small
                # kinematics reads it: check 4)
                text += f" (linearised {c['judged_depth'] / c['push']:.2g})"
        if r.get("switched"):
            text += " (side switched)"
        if "seconds" in r:
            text += f" {r['seconds']:.1f}s"
        return text

    extra = f" lagrange {part(recs.get('lagrange'))}" if "lagrange" in recs else ""
    return (f"{p['id']:7s} {model_class(p):12s} {p['shape']:15s} E {p['stiffness_ratio']:8.2g} "
            f"h {p['mesh_ratio']:4.2f} {p['loading']:12s} vfem {part(recs.get('vfem'))}{extra}")


def summary(models: list[dict], results: dict, seed: int, seconds: float) -> tuple[str, dict]:
    counts = {}
    for cls in CLASSES:
        recs = [results[p["id"]]["vfem"] for p in models if model_class(p) == cls]
        st = [r["status"] for r in recs]
        counts[cls] = {s: st.count(s) for s in ("solved", "stopped", "wrong", "invalid",
                                                 "check-error")}
        counts[cls]["total"] = len(recs)
        # solved on the linearised reading alone: deeper than the threshold on the deformed
        # geometry by small kinematics' second-order term (check 4)
        counts[cls]["second order"] = sum(
            r["status"] == "solved" and r["checks"]["depth"] > r["checks"]["threshold"]
            for r in recs)
        counts[cls]["switched"] = sum(r["status"] == "solved" and bool(r.get("switched"))
                                      for r in recs)
        for status in ("solved", "wrong"):
            counts[cls][f"{status} warned"] = sum(r["status"] == status and bool(r.get("warned"))
                                                  for r in recs)
        for kind in ("timeout", "crash"):
            counts[cls][kind] = sum(r["status"] == "stopped" and r["message"].startswith(kind)
                                    for r in recs)
    parts = []
    for cls in CLASSES:
        c = counts[cls]
        if c["total"]:
            other = "".join(f", {c[k]} {k}" for k in ("invalid", "check-error") if c[k])
            which = ", ".join(f"{c[k]} {k}" for k in ("timeout", "crash") if c[k])
            second = (f", {c['second order']} of the solved beyond it on the deformed geometry"
                      if c["second order"] else "")
            if c["switched"]:
                second += (f", {c['switched']} of the solved with the compatibility side "
                           "switched")
            if c["solved warned"]:
                second += f", {c['solved warned']} of the solved warned of"
            warned = (f" [{c['wrong warned']} warned of]" if c["wrong warned"] else "")
            parts.append(f"{cls} {c['solved']}/{c['total']} solved ({c['stopped']} stopped"
                         f"{f' [{which}]' if which else ''}, {c['wrong']} wrong{warned}{other}"
                         f"{second})")
    text = f"random models (seed {seed}): " + ", ".join(parts)
    lag = [results[p["id"]]["lagrange"] for p in models if "lagrange" in results[p["id"]]]
    if lag:
        st = [r["status"] for r in lag]
        conv = st.count("solved") + st.count("wrong")
        counts["lagrange 2D linear"] = {s: st.count(s) for s in ("solved", "stopped", "wrong")}
        counts["lagrange 2D linear"]["total"] = len(lag)
        text += (f"; lagrange 2D linear {conv}/{len(lag)} converged, {st.count('wrong')} wrong "
                 f"({st.count('solved')} solved, {st.count('stopped')} stopped)")
    return text + f"; {seconds:.0f} s", counts


def dump(p: dict, folder: Path) -> Path:
    """Model ``p`` as an input file (and its mesh file, if any) in ``folder``."""
    from vfem.io.input import dumps

    folder.mkdir(parents=True, exist_ok=True)
    config, info = build(p, folder)
    path = folder / f"{config.name}.toml"
    header = (f"benchmarks/random_models.py, seed {p['seed']}, model {p['id']}\n"
              f"{model_class(p)}, {p['shape']}, gap {info['gap']:.6g}, push {info['push']:.6g}"
              f"\nthe Lagrange baseline: vfem run {path.name} --set contact.method=lagrange")
    path.write_text(dumps(config, header))
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--count-2d", type=int, default=300)
    ap.add_argument("--count-3d", type=int, default=60)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per solve")
    ap.add_argument("--only", nargs="+", metavar="ID", help="model ids, e.g. 2d-17 3d-4")
    ap.add_argument("--json", metavar="FILE", help="every model's parameters and checks")
    ap.add_argument("--no-baseline", action="store_true", help="skip the Lagrange baseline")
    ap.add_argument("--dump", nargs=2, metavar=("ID", "DIR"),
                    help="write model ID as a vfem input file (and mesh) into DIR")
    ap.add_argument("-v", "--verbose", action="store_true", help="one line per model")
    ap.add_argument("--large", action="store_true",
                    help="the same models under large kinematics (total Lagrangian, linear "
                         "elements), solved by the Newton contact formulation")
    ap.add_argument("--axisymmetric", action="store_true",
                    help="the 2D models as bodies of revolution, moved out from the axis "
                         "(issue 42); no 3D models")
    ap.add_argument("--plastic", action="store_true",
                    help="the same models with the block elasto-plastic (issue 41)")
    ap.add_argument("--remedies", action="store_true",
                    help="then try each stopped model again with the other compatibility side, "
                         "four times the steps and large kinematics (the remedies the stop "
                         "messages name) and print what each solves")
    args = ap.parse_args(argv)

    def parse(ident: str) -> dict:
        dim, _, k = ident.lower().partition("d-")
        if dim not in ("2", "3") or not k.isdigit():
            ap.error(f"model ids look like 2d-17 or 3d-4, got {ident!r}")
        return draw(args.seed, int(dim), int(k))

    def variant(models: list[dict]) -> list[dict]:
        """The models as the flags make them (the dumped one too)."""
        if args.axisymmetric:
            models = [axisymmetric(p) for p in models if p["dim"] == 2]
        if args.plastic:
            models = [plastic(p) for p in models]
        if args.large:
            models = [large(p) for p in models]
        return models

    if args.dump:
        dumped = variant([parse(args.dump[0])])
        if not dumped:
            ap.error(f"{args.dump[0]} is a 3D model: --axisymmetric takes 2D models only")
        path = dump(dumped[0], Path(args.dump[1]))
        print(f"wrote {path}: vfem run {path}")
        return 0
    if args.only:
        models = [parse(i) for i in args.only]
    else:
        models = ([draw(args.seed, 2, k) for k in range(args.count_2d)]
                  + [draw(args.seed, 3, k) for k in range(args.count_3d)])
    models = variant(models)
    tasks = []
    for p in models:  # each model's solves one after the other: its line comes when both are done
        tasks.append((p, "vfem"))
        if not args.no_baseline and p["dim"] == 2 and p["order"] == 1:
            tasks.append((p, "lagrange"))
    by_id = {p["id"]: p for p in models}
    results: dict[str, dict] = {p["id"]: {} for p in models}
    progress = sys.stderr.isatty()
    finished = [0]

    def done(p, rec):
        results[p["id"]][rec["method"]] = rec
        finished[0] += 1
        want = 1 + (not args.no_baseline and p["dim"] == 2 and p["order"] == 1)
        if args.verbose and len(results[p["id"]]) == want:
            print(line(by_id[p["id"]], results[p["id"]]), flush=True)
        if progress:
            print(f"\r{finished[0]}/{len(tasks)}", end="", file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    run_all(tasks, args.jobs, args.timeout, done)
    if progress:
        print(file=sys.stderr)
    text, counts = summary(models, results, args.seed, time.perf_counter() - t0)
    if args.json:
        out = {"command": " ".join(["python3", "benchmarks/random_models.py",
                                    *(argv if argv is not None else sys.argv[1:])]),
               "summary": text, "counts": counts,
               "models": [{"parameters": p, **results[p["id"]]} for p in models]}
        Path(args.json).write_text(json.dumps(out, indent=1, default=_json_default))
    print(("bodies of revolution (--axisymmetric): " if args.axisymmetric else "")
          + ("plastic block (--plastic): " if args.plastic else "")
          + ("large kinematics (--large): " if args.large else "") + text)
    if args.remedies:
        stopped = [p["id"] for p in models if results[p["id"]]["vfem"]["status"] == "stopped"]
        tried: dict[str, dict] = {i: {} for i in stopped}

        def tried_one(p, rec):
            tried[p["id"]][rec["method"]] = rec
            if args.verbose and len(tried[p["id"]]) == len(REMEDIES):
                print(p["id"], ", ".join(f"{r} {tried[p['id']][r]['status']}"
                                         for r in REMEDIES), flush=True)

        run_all([(by_id[i], r) for i in stopped for r in REMEDIES], args.jobs, args.timeout,
                tried_one)
        print(remedy_summary(stopped, tried))
    return 0


def _json_default(v):
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    return str(v)


if __name__ == "__main__":
    sys.exit(main())
