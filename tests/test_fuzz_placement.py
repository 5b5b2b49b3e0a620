"""Fuzzing two-body placements (issue 16, acceptance): every run converges with the invariants,
or stops with a clear message; none passes silently.

A lower block ([-1, 1] x [-1, 0], base fixed) and an upper body — a rectangle of quadrilaterals
or of triangles, or a punch with a circular face (``rounded_punch``) — whose top is held in x
and moved down by a prescribed displacement. Drawn at random (hypothesis): the initial gap
(an overlap of up to half the thinner surface layer of elements — inside the rind —, zero, or
up to four block element sizes apart), the push (always beyond the gap, so that they meet: by
0.1 % to 2 % of the block's height beyond it, or beyond touching where they start overlapped),
the horizontal offset (the upper body may overhang the block's edge, or be wider than the
block), the width ratio, the mesh-size ratio, the stiffness ratio E_top / E_bottom
(log-uniform in [1e-3, 1e3]), Poisson's ratio, the number of steps, the order in which the
bodies are listed, and small kinematics (one in ten "total"). Meshes stay small (a run takes
0.03 to 2 s, a few up to 15 s).

Each run must either

* converge, with every converged step's three invariants (``StepResult.invariants``,
  :mod:`vfem.contact.invariants.check`: force balance, no interpenetration beyond the tolerance and
  faceting allowance, no tension) holding — enforced by the solver or only recorded —, the
  last step at load factor 1, and, when the bodies moved rigidly would overlap at the end, a
  compressive contact force that is not zero; checked besides, independently of vfem's own
  check: no boundary node of one body deeper inside the other's deformed boundary than the
  penetration tolerance plus half the longest facet at hand (a node that went through);
* or stop with a clear message: a :class:`vfem.errors.VfemError` with a message, or
  ``converged = False`` with ``result.message`` (the steps that did converge still obey the
  invariants).

Anything else fails: an invariant broken in a step reported converged, a raw exception
(ValueError, IndexError, LinAlgError, ...), no contact force although the bodies overlap, a
"converged" run that stopped short of load factor 1 or without a message.

The default run draws ``EXAMPLES`` placements (derandomized: the same every run; about 25 s
when none fails, and it stops at the first failure, unshrunk); ``pytest -m slow`` draws
``SLOW_EXAMPLES`` (about 3 min, shrinking included); ``VFEM_FUZZ_EXPLORE=1`` draws new ones
(``--hypothesis-seed=N``). A failure prints the placement and its input file (TOML).

The failures found are kept below as minimal placements: ``FOUND`` (the property failed:
contact missed and reported converged, or a raw exception; all fixed, each a regression test
now) and ``UNSOLVED`` (ordinary placements that broke (b); with (b) enforced they stopped with
a message, which the property accepts, but had no answer: each now converges with the
invariants, ``SOLVED``).
"""

from __future__ import annotations

import logging
import math
import os
from dataclasses import asdict, dataclass

import numpy as np
import pytest

pytest.importorskip("hypothesis", reason="the fuzz tests need hypothesis: pip install -e .[test]")

from hypothesis import HealthCheck, Phase, example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import vfem  # noqa: E402
from invariant_record import step_violations  # noqa: E402
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps  # noqa: E402
from vfem.errors import VfemError  # noqa: E402
from vfem.io.input import dumps  # noqa: E402

#: placements drawn by the default run, and by the slow one (``pytest -m slow``)
EXAMPLES = 100
SLOW_EXAMPLES = 400

E_BLOCK = 1.0e3
BLOCK_WIDTH, BLOCK_HEIGHT = 2.0, 1.0


# -- a placement and its model --------------------------------------------------------------------


@dataclass(frozen=True)
class Placement:
    """Two bodies placed: every number that makes the model (lengths absolute)."""

    shape: str  # "rectangle", "triangles" or "rounded"
    block_nx: int  # the block's columns (element size 2 / block_nx, square elements)
    width: float  # the upper body's width
    height: float  # and height
    nx: int  # its columns
    ny: int  # and rows
    radius: float  # "rounded": the face's radius
    centre: float  # the upper body's centre x
    gap: float  # its lowest point's initial height above the block (< 0: overlap)
    push: float  # its top's prescribed downward displacement (> gap)
    stiffness_ratio: float  # E_top / E_bottom
    poissons_ratio: float
    steps: int
    kinematics: str  # "small" or "total" (both bodies)
    upper_first: bool  # the upper body listed first

    @property
    def block_ny(self) -> int:
        return max(2, self.block_nx // 2)

    def config(self) -> ModelConfig:
        block = BodyConfig(
            name="block",
            mesh=MeshSpec(shape="rectangle", parameters=(
                ("x0", -0.5 * BLOCK_WIDTH), ("y0", -BLOCK_HEIGHT), ("width", BLOCK_WIDTH),
                ("height", BLOCK_HEIGHT), ("nx", self.block_nx), ("ny", self.block_ny))),
            material=vfem.LinearElastic(E_BLOCK, self.poissons_ratio),
            supports=(vfem.Support("bottom"),),
            kinematics=self.kinematics)
        if self.shape == "rounded":
            mesh = MeshSpec(shape="rounded_punch", parameters=(
                ("x0", self.centre), ("y0", self.gap), ("width", self.width),
                ("height", self.height), ("radius", self.radius), ("nx", self.nx),
                ("ny", self.ny)))
        else:
            mesh = MeshSpec(shape="rectangle", parameters=(
                ("x0", self.centre - 0.5 * self.width), ("y0", self.gap),
                ("width", self.width), ("height", self.height), ("nx", self.nx),
                ("ny", self.ny), ("triangles", self.shape == "triangles")))
        upper = BodyConfig(
            name="upper", mesh=mesh,
            material=vfem.LinearElastic(E_BLOCK * self.stiffness_ratio, self.poissons_ratio),
            supports=(vfem.Support("top", ("x",)),),
            prescribed=(vfem.PrescribedDisplacement("top", "y", -self.push),),
            kinematics=self.kinematics)
        bodies = (upper, block) if self.upper_first else (block, upper)
        return ModelConfig(name="fuzz placement", bodies=bodies, steps=Steps(count=self.steps))

    def toml(self) -> str:
        return dumps(self.config(), header=f"fuzz placement: {self}")


def rind(shape: str, height: float, ny: int) -> float:
    """The height of the upper body's layer of elements at its face."""
    if shape == "rounded":  # rows graded towards the face in ratio 1.25 (shapes.rounded_punch)
        return height / sum(1.25**k for k in range(ny))  # at the lowest point, about
    return height / ny


def placement(shape: str, block_nx: int, width_ratio: float, mesh_ratio: float,
              radius_ratio: float, offset: float, gap: float, indent: float,
              log_stiffness: float, poissons_ratio: float, steps: int, large: bool,
              upper_first: bool) -> Placement:
    """A placement from the drawn fractions: ``width_ratio`` the upper width over the block's,
    ``mesh_ratio`` its element size over the block's, ``radius_ratio`` the face's radius over
    its half width, ``offset`` in [-1, 1] its centre from the block's centre to 40 % of its
    width beyond the block's edge, ``gap`` in [-1, 4]: negative, that fraction of half the
    thinner surface layer (inside the rind); positive, block element sizes; ``indent`` the
    final indentation over the block's height."""
    h = BLOCK_WIDTH / block_nx
    width = width_ratio * BLOCK_WIDTH
    size = h * mesh_ratio
    nx = min(max(1, round(width / size)), 60)
    radius = radius_ratio * 0.5 * width
    sag = radius - math.sqrt(max(radius**2 - (0.5 * width) ** 2, 0.0)) if shape == "rounded" \
        else 0.0
    height = max(0.5 * width, 0.25) + sag
    ny = min(max(1, round(height / size)), 30)
    if shape == "rounded":
        nx = max(nx, 4)
        ny = max(ny, 2)
    block_rind = BLOCK_HEIGHT / max(2, block_nx // 2)
    g = gap * 0.5 * min(block_rind, rind(shape, height, ny)) if gap < 0 else gap * h
    centre = offset * (0.5 * BLOCK_WIDTH + 0.4 * width)
    return Placement(shape=shape, block_nx=block_nx, width=width, height=height, nx=nx, ny=ny,
                     radius=radius, centre=centre, gap=g, push=max(g, 0.0) + indent * BLOCK_HEIGHT,
                     stiffness_ratio=10.0**log_stiffness, poissons_ratio=poissons_ratio,
                     steps=steps, kinematics="total" if large else "small",
                     upper_first=upper_first)


@st.composite
def placements(draw) -> Placement:
    large = draw(st.integers(0, 9)) == 0  # one in ten under large kinematics
    return placement(
        shape=draw(st.sampled_from(["rectangle", "triangles", "rounded"])),
        block_nx=draw(st.integers(6, 24)),
        width_ratio=draw(st.floats(0.1, 1.3)),
        mesh_ratio=draw(st.floats(0.3, 3.0)),
        radius_ratio=draw(st.floats(1.0, 6.0)),
        offset=draw(st.one_of(st.just(0.0), st.floats(-1.0, 1.0))),
        gap=draw(st.one_of(st.just(0.0), st.floats(-1.0, 0.0), st.floats(0.0, 4.0))),
        indent=draw(st.floats(1e-3, 2e-2)),
        log_stiffness=draw(st.one_of(st.just(0.0), st.floats(-3.0, 3.0))),
        poissons_ratio=draw(st.floats(0.0, 0.45)),
        steps=draw(st.integers(1, 4)),
        large=large,
        upper_first=draw(st.booleans()))


# -- an independent reading of interpenetration ------------------------------------------------


def boundary_segments(body, x: np.ndarray) -> np.ndarray:
    """(nf, 2, 2) the body's boundary facets (end points) at positions ``x`` ((n, 2))."""
    facets = body.mesh.facets[:, body.mesh.boundary_facets()]
    return np.stack([x[facets[0]], x[facets[1]]], axis=1)


def depth_inside(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """For each point, its distance to the polygon made of ``segments`` if it lies inside it
    (ray casting: any order of the segments), else 0."""
    a, b = segments[:, 0], segments[:, 1]
    px, py = points[:, 0:1], points[:, 1:2]
    crosses = (a[:, 1] > py) != (b[:, 1] > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = a[:, 0] + (py - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    inside = (crosses & (px < xc)).sum(axis=1) % 2 == 1
    d = b - a
    t = np.clip(((points[:, None] - a) * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-300), 0, 1)
    dist = np.linalg.norm(points[:, None] - (a + t[..., None] * d), axis=-1).min(axis=1)
    return np.where(inside, dist, 0.0)


def deepest_node(bodies, displacements) -> tuple[float, float, str]:
    """The deepest boundary node of one body inside the other (bodies at X + u): (depth, what
    it may be by the faceting of either surface — half the longest facet of the two —, where)."""
    worst = (0.0, 0.0, "")
    for i, bi in enumerate(bodies):
        for j, bj in enumerate(bodies):
            if i == j:
                continue
            xi = bi.points.T + displacements[i]
            xj = bj.points.T + displacements[j]
            nodes = np.unique(bi.mesh.facets[:, bi.mesh.boundary_facets()])
            segs_i = boundary_segments(bi, xi)
            segs_j = boundary_segments(bj, xj)
            depth = depth_inside(xi[nodes], segs_j)
            k = int(np.argmax(depth))
            if depth[k] > worst[0]:
                longest = max(np.linalg.norm(segs_i[:, 1] - segs_i[:, 0], axis=1).max(),
                              np.linalg.norm(segs_j[:, 1] - segs_j[:, 0], axis=1).max())
                worst = (float(depth[k]), 0.5 * float(longest),
                         f"node {nodes[k]} of {bi.name!r} at {xi[nodes[k]]} inside {bj.name!r}")
    return worst


# -- the property -------------------------------------------------------------------------------


def outcome(p: Placement) -> tuple[str, list[str]]:
    """Solve the placement: ("converged" | "stopped: message", the problems found)."""
    problems: list[str] = []
    model = None
    try:
        model = p.config().build()
        result = vfem.solve(model)
    except VfemError as exc:
        message = str(exc).strip()
        return f"stopped: {type(exc).__name__}: {message}", (
            [] if message else [f"{type(exc).__name__} without a message"])
    except Exception as exc:  # noqa: BLE001 - what the property is about
        import traceback

        return "raised", [f"raw {type(exc).__name__}: {exc}\n{traceback.format_exc()}"]
    problems.extend(step_violations(result))
    if not result.converged:
        if not result.message.strip():
            problems.append("not converged, and no message")
        return f"stopped: {result.message}", problems
    if not result.steps or result.steps[-1].load_factor != 1.0:
        problems.append(f"converged, but the last step is at load factor "
                        f"{result.steps[-1].load_factor if result.steps else None}")
        return "converged", problems
    last = result.steps[-1]
    names = [b.name for b in model.bodies]
    # the bodies moved rigidly (the block still, the upper body down by the push) overlap?
    rigid = [np.zeros((b.npoints, 2)) for b in model.bodies]
    rigid[names.index("upper")][:, 1] = -p.push
    overlap = deepest_node(model.bodies, rigid)[0]
    force = last.bodies["upper"].contact_force.sum(axis=0)
    tol = result.penetration_tolerance
    if overlap > 10 * tol + 1e-9 * BLOCK_HEIGHT:
        stiffness = min(E_BLOCK, E_BLOCK * p.stiffness_ratio)
        if not force[1] > 1e-9 * stiffness * overlap:
            problems.append(f"converged with contact force {force} on the upper body, "
                            f"although moved rigidly the bodies overlap by {overlap:.3g}")
    depth, facet, where = deepest_node(
        model.bodies, [last.bodies[n].displacement for n in names])
    if depth > tol + facet:
        problems.append(f"converged with {where} by {depth:.3g} (deformed), beyond the "
                        f"tolerance {tol:.3g} plus half the longest facet {facet:.3g}")
    return "converged", problems


def check(p: Placement) -> None:
    what, problems = outcome(p)
    assert not problems, (f"{p}\n{what}\n" + "\n".join(problems)
                          + "\n--- input file ---\n" + p.toml())


# -- failures found (issue 16): each a minimal placement, a regression test now -----------------


def rect(**kw) -> Placement:
    """A placement on the block of 20 columns with a flat 10 x 5 upper body, E ratio 1, one
    step of 0.015 (small kinematics), changed by ``kw``."""
    base = dict(shape="rectangle", block_nx=20, width=1.0, height=0.5, nx=10, ny=5, radius=1.0,
                centre=0.0, gap=0.0, push=0.015, stiffness_ratio=1.0, poissons_ratio=0.3,
                steps=1, kinematics="small", upper_first=False)
    return Placement(**{**base, **kw})


#: Silent failures: the property does not hold (contact missed and reported converged, or a raw
#: exception). name -> (placement, what was measured). Each is the smallest model found for its
#: failure (from some thousand random placements).
FOUND = {
    "overhang, inner corner past the middle of the block's last facet: contact missed": (
        rect(block_nx=7, width=1.2, height=0.6, nx=2, ny=1, centre=1.46, push=0.002,
             stiffness_ratio=50.0),
        "converged, 0 nodes in contact, contact force (0, 0), exit 0; the upper body's corner "
        "(0.86, -0.002) 2e-3 inside the block, (b) passes: allowed 0.143 (faceting allowance, "
        "half the block's facet) - any stiffness ratio; with the corner at x = 0.80 it works"),
    "the same overhang dropped from 1.0 above in 4 steps: contact missed": (
        rect(block_nx=7, width=1.2, height=0.6, nx=2, ny=1, centre=1.46, gap=1.0, push=1.002,
             stiffness_ratio=50.0, steps=4),
        "converged, contact force (0, 0); (b) passes (2e-3 deep, allowed 0.143)"),
    "the same overhang under large kinematics: raw ValueError": (
        rect(block_nx=7, width=1.2, height=0.6, nx=2, ny=1, centre=1.46, push=0.002,
             stiffness_ratio=50.0, kinematics="total"),
        "ValueError: need at least one array to concatenate "
        "(contact/formulations/large.py, _correct_all, with no contact pair)"),
    "overlap inside the rind across the block's corner: contact missed": (
        rect(block_nx=8, width=0.8, height=1.2, nx=1, ny=2, centre=1.018, gap=-0.09,
             push=0.0021),
        "converged with contact force (0, 0); block node 39 at (0.75, 0) 0.0921 inside the upper "
        "body, (b) passes: allowed 0.4"),
    "the same overlap under large kinematics: raw ValueError": (
        rect(block_nx=8, width=0.8, height=1.2, nx=1, ny=2, centre=1.018, gap=-0.09,
             push=0.0021, kinematics="total"),
        "ValueError: need at least one array to concatenate "
        "(contact/formulations/large.py, _correct_all)"),
    "stiff rounded punch, its lowest node between the coarser block's nodes: contact missed": (
        rect(shape="rounded", block_nx=11, width=0.4, height=0.35, nx=4, ny=2, radius=0.3,
             push=0.002, stiffness_ratio=4.0),
        "converged, 0 nodes in contact, force (0, 0); the punch's lowest node 2e-3 inside the "
        "block, (b) passes: allowed 5.4e-2 although no node touches; E ratio 1 works"),
    "equal materials, coarse rounded punch on a finer block: its first touch is missed": (
        rect(shape="rounded", block_nx=18, width=1.5, height=0.95, nx=4, ny=3, radius=1.5,
             centre=-0.16, push=0.005),
        "converged, contact force (0, 0): the punch's lowest node 5e-3 inside the block, "
        "between block nodes 0.111 apart whose gaps are larger, (b) passes: allowed 7.06e-3; "
        "the same at push 0.001 and 0.003; E ratio 0.2 works, centre 0 (lowest node on a block "
        "node) works (found by the default fuzz at 100 examples)"),
}

#: FOUND placements that stopped clearly (invariant (b) named the node) but did not converge: a
#: convex vertex of the equilibrium side first touching between the compatibility side's nodes
#: (no node of the compatibility side near it); held since issue 37 (a held node is left out
#: only where every compatibility node of the facet under it touches).
FIRST_TOUCH = ("stiff rounded punch, its lowest node between the coarser block's nodes: contact "
               "missed",
               "equal materials, coarse rounded punch on a finer block: its first touch is missed")

#: Ordinary placements that did not converge with the invariants (each now in SOLVED): with
#: (b) recorded only they converged breaking it; with (b) enforced they stopped (cut 6 times:
#: the depth is first order in the increment, so no cut removes it). Not silent, no answer.
UNSOLVED = {
    "overlap inside the rind, soft one-element body": (
        rect(block_nx=12, width=0.25, height=0.25, nx=1, ny=1, centre=0.05, gap=-0.04,
             push=0.01, stiffness_ratio=0.1),
        "contact force (0, 0) and block node 48 at (0, 0) 0.05 inside the upper body (allowed "
        "1.67e-6); enforced: stops at step 1 (0.0402 inside); centre 0.0 works"),
    "a block node 0.002 beyond the punch's corner slides under it (small kinematics)": (
        rect(centre=-0.902),
        "block node 76 (X = -0.4; the punch's corner at -0.402, the punch overhangs the "
        "block's other edge) slides 0.0048 towards the punch, the corner 0.0032 the other "
        "way: 3.74e-3 inside the punch (linearised 7.1e-3) against 2.68e-4 allowed, carrying "
        "-0.38; enforced: stops at step 2 of 4; centred (no overhang) it works"),
    "large kinematics, flat punch on matching nodes, E ratio 1": (
        rect(kinematics="total"),
        "block node 65 at the punch's corner 2.97e-3 inside the punch (20 % of the "
        "indentation, 1.0e-3 at push 0.005: first order) against 2.53e-4 allowed while the "
        "contact iteration reports 5.7e-12; E ratios 0.2 to 2 and 'updated' alike, E ratio >= "
        "5 and small kinematics work; enforced: stops at step 1 (6.15e-5 against 8.17e-6)"),
    "large kinematics: a node of the upper body 0.03 inside the block's corner": (
        rect(centre=-0.87, kinematics="total"),
        "upper node 24 at (-0.9683, -0.0123) 1.70e-3 inside the block against 3.1e-5 allowed "
        "(contact iteration: 4e-13), also with 16 steps; small kinematics works; enforced: "
        "stops at step 1 (2.89e-5 against 2.14e-6)"),
    "large kinematics: a one-element punch between two block nodes, one under its middle": (
        rect(block_nx=6, width=0.25, height=0.25, nx=1, ny=1, push=0.015625,
             poissons_ratio=0.0, kinematics="total"),
        "(hypothesis's shrunk example) contact missed: force (0, 0), block node 15 at (0, 0) "
        "0.0156 inside the punch (the whole push); enforced: stops at step 1, with 64 steps at "
        "step 3 (force 1e-2 instead of about 4); E ratios 0.5 and 5 and nx = 2 alike; small "
        "kinematics, or 7 block columns, work"),
}


@pytest.mark.parametrize("name", sorted(FOUND))
def test_found(name):
    """Each was a silent failure (see FOUND); each now converges with the invariants or stops
    with a clear message. Fixed by reading a facet's facing and overlap at its ends as well as
    its midpoint (contact/formulations/paired.py ``facing``), by granting the faceting allowance
    only under facets that touch (contact/invariants/check.py), and by a large-kinematics correction
    with no pair."""
    check(FOUND[name][0])


#: Placements of UNSOLVED that converge with the invariants since the fixes above (the last two:
#: a facet over which a vertex of the other surface lies, facing it, joins the patch).
SOLVED = ("large kinematics: a node of the upper body 0.03 inside the block's corner",
          "large kinematics: a one-element punch between two block nodes, one under its middle",
          # a facet over which a vertex of the other surface lies, facing it, is in the patch
          "overlap inside the rind, soft one-element body",
          "large kinematics, flat punch on matching nodes, E ratio 1",
          # the equilibrium side's nodes held where they would penetrate (issue 37)
          "a block node 0.002 beyond the punch's corner slides under it (small kinematics)")


@pytest.mark.parametrize("name", SOLVED)
def test_solved_placements_converge(name):
    what, problems = outcome({**UNSOLVED, **FOUND}[name][0])
    assert what == "converged" and not problems, f"{what}\n" + "\n".join(problems)


@pytest.mark.parametrize("name", FIRST_TOUCH)
def test_first_touches_converge(name):
    """Stricter than the property: these converge, with the invariants."""
    p = FOUND[name][0]
    what, problems = outcome(p)
    assert what == "converged" and not problems, f"{p}\n{what}\n" + "\n".join(problems)


def test_every_ordinary_placement_is_solved():
    """No UNSOLVED placement is left out of SOLVED (each converges with the invariants)."""
    assert set(UNSOLVED) <= set(SOLVED)


FUZZ = dict(derandomize="VFEM_FUZZ_EXPLORE" not in os.environ, deadline=None, database=None,
            print_blob=True, suppress_health_check=[HealthCheck.too_slow,
                                                    HealthCheck.data_too_large])


@pytest.fixture(autouse=True, scope="module")
def quiet_solver():
    """The solver warns about every cut step and unenforced invariant: not the test's output."""
    logger = logging.getLogger("vfem")
    level = logger.level
    logger.setLevel(logging.ERROR)
    yield
    logger.setLevel(level)


@settings(max_examples=EXAMPLES, phases=(Phase.explicit, Phase.reuse, Phase.generate), **FUZZ)
@given(placements())
# found by hypothesis 6.170 (2026-11-25): a semicircular punch face (radius = half its width)
# meshed in 30 rows graded 1.25, whose thinnest, steepest elements (edges in ratio 833) scikit-
# fem's facet basis could not map into; it raised a bare Exception, now an InputError
@example(Placement(shape="rounded", block_nx=16, width=2.5, height=2.5, nx=60, ny=30,
                   radius=1.25, centre=0.0, gap=-6.5019676097128454e-06, push=0.001,
                   stiffness_ratio=1.0, poissons_ratio=0.0, steps=2, kinematics="total",
                   upper_first=False))
@pytest.mark.slow
def test_placements_converge_with_the_invariants_or_stop_clearly(p):
    check(p)


@pytest.mark.slow
@settings(max_examples=SLOW_EXAMPLES, **FUZZ)
@given(placements())
def test_more_placements(p):
    check(p)


@pytest.mark.slow
def test_the_placements_reach_what_they_should():
    """The generator draws what the property is about: overlaps inside the rind, touching and
    far-apart starts, overhangs, extreme stiffness ratios, each shape, large kinematics."""
    from hypothesis import find

    for condition in (lambda p: p.gap < 0, lambda p: p.gap == 0,
                      lambda p: p.gap > 3 * BLOCK_WIDTH / p.block_nx,
                      lambda p: abs(p.centre) + 0.5 * p.width > 0.5 * BLOCK_WIDTH,
                      lambda p: p.stiffness_ratio < 2e-3, lambda p: p.stiffness_ratio > 5e2,
                      lambda p: p.shape == "rounded", lambda p: p.shape == "triangles",
                      lambda p: p.kinematics == "total"):
        find(placements(), condition, settings=settings(database=None, max_examples=2000))
    p = find(placements(), lambda p: p.gap < 0, settings=settings(database=None))
    assert p.push > p.gap
    assert asdict(p)  # plain values, printed with a failure
