"""Thesis §5.5: the gasket example — a soft gasket pushed against a stiff one, then withdrawn.

Two gaskets of semicircular section (outer radius 1, thickness 0.1) bulge towards each other,
their centres 0.25 apart vertically and their faces 0.2 apart horizontally
(:func:`vfem.mesh.gasket_pair`). The back of each (its two cut ends) has every displacement
prescribed: x moves ``back_motion`` (0.25) towards the other gasket at load factor 1, y is held.
The load factors go 0.1, 0.2, ..., 1.0 and back down 0.9, ..., 0.0: each back approaches 0.025 per
step for ten steps, then retreats the same way. The faces first overlap (contact ignored) at
step 5 and overlap most at step 10; after step 20 every node must be back where it started.

The left gasket is the soft one; the right one is ``stiffness_ratio`` (10) times stiffer. Plane
strain, nu = 0.3: a gasket is a long extrusion whose section does not change along it.

Mesh: 120 x 1 nine-node quadrilaterals per gasket, the outer face curved. One element through
the thickness because each step's linear prediction drives the faces about 0.05 into each other
and a node may not go deeper than the element behind the opposing face (thesis §5.6): with two
elements (0.05 deep) the steps are cut; quadratic because one linear element locks in bending.
Contact candidates are chosen in the undeformed configuration, where the faces are 0.214 apart:
``search_distance`` 0.4 reaches past the contact of step 10. Numbers and the choice of the
paired variant: ``docs/examples.md``, Gasket.

The module also measures what the contact algorithm's own numbers cannot show: the state of the
faces in the *current* configuration (:func:`current_contact`): how far any node of one gasket
lies inside the other's deformed section, how wide a gap a loaded node bridges, and the angle
between each nodal contact force and its face's current normal. With the paired variant's
linear kinematics (pairs fixed in the undeformed configuration) these test whether the
small-strain idealisation still holds for gaskets that move 0.5 relative to each other.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from vfem.bodies import Body, PrescribedDisplacement, Support
from vfem.config import BodyConfig, Curve, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.search import project_points
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.io.runner import run_headline
from vfem.materials import LinearElastic
from vfem.solver import AnalysisResult, Model, StepResult


@dataclass(frozen=True)
class GasketParameters:
    """Parameters of the gasket example; the thesis's geometry and motion are the defaults.

    The thesis gives no material constants; the ratio of the two gaskets' moduli is
    ``stiffness_ratio`` (soft: ``soft_youngs_modulus``). Forces scale with the moduli, the
    displacements do not depend on them, only on the ratio.
    """

    radius: float = 1.0
    thickness: float = 0.1
    offset: float = 0.25  # vertical offset between the centres
    separation: float = 0.2  # horizontal clearance between the faces
    back_motion: float = 0.25  # each back's motion towards the other at load factor 1
    steps: int = 10  # loading steps; as many unloading steps follow
    soft_youngs_modulus: float = 1.0e6
    stiffness_ratio: float = 10.0
    poissons_ratio: float = 0.3
    plane: str = "strain"
    n_around: int = 120  # elements around each half annulus
    n_through: int = 1  # elements through the thickness
    order: int = 2  # 2: 9-node quadrilaterals, the contact face curved; 1: 4-node
    variant: str = "paired"
    search_distance: float = 0.4  # the faces start 0.2 apart; 0.25 is too short at step 10
    penetration_tolerance: float | None = None
    equilibrium_tolerance: float = 1e-3
    swap_bodies: bool = False  # list the stiff gasket first
    # "total" or "updated": large displacements (then order 1, e.g. n_through 3; docs/examples.md)
    kinematics: str = "small"


Parameters = GasketParameters

#: The steps the thesis draws (prediction and resolved position, Figs. 5.19 to 5.22).
SHOWN_STEPS = (5, 10)

#: The reference of the verification (:func:`verification`): the contact force at the full
#: motion (load factor 1, step 10) of the model refined around and through the thickness,
#: ``vfem run gasket --set n_around=480 --set n_through=2`` (about 17 s; docs/examples.md,
#: Gasket, *Why this mesh*), with E_soft = 1e6 (forces scale with the moduli)
REFINED_FORCE = 2456.69
#: Its refinement: elements around each gasket and through its thickness
REFINED_MESH = (480, 2)
#: The discretisation error of the force against the reference (docs/examples.md): one
#: quadratic element through the thickness reads it 0.76 % above two (at 480 around), and the
#: mesh around adds 0.99 %, 0.14 % and -0.01 % at 60, 120 and 240 elements (one element
#: through, against 480): second order, within THROUGH_ONE + AROUND_60 (60 / n_around)^2
THROUGH_ONE = 0.01
AROUND_60 = 0.015
#: ``vfem verify --slow``: twice as many elements around and two through the thickness (the
#: loading steps are then cut by the rind rule; 9 620 dofs, a few seconds)
VERIFY_SLOW = ("n_around=240", "n_through=2")
#: What reversibility is allowed under small kinematics with the paired variant, relative to
#: the largest force (forces) and to the backs' motion (positions): round-off. At a load factor
#: the loading and the unloading step end on the same contact set and solve the same linear
#: system for it, and once every force is released u = K^-1 0 = 0; what can differ is the
#: round-off of those solves, machine epsilon (2.2e-16) times their condition. The gaskets'
#: stiffness (free dofs) has condition 3.7e6 at the default mesh (a thin ring, one element
#: through its thickness), so the worst case is 8e-10 there (2.9e-9 at the slow run's 240 x 2,
#: condition 1.3e7); measured 4.6e-16 and 9.8e-16 of the force (the default, 30 around) and 0
#: of the motion: far below, as round-off is below its worst case
REVERSIBLE_ROUND_OFF = 1e-9


def load_factors(p: GasketParameters) -> tuple[float, ...]:
    """1/n, 2/n, ..., 1, then (n - 1)/n, ..., 0: n loading and n unloading steps."""
    n = p.steps
    return tuple(k / n for k in range(1, n + 1)) + tuple(k / n for k in range(n - 1, -1, -1))


def closure_at_first_touch(p: GasketParameters) -> float:
    """How far the backs must close (together) before the undeformed faces touch."""
    R = p.radius
    return p.separation + 2.0 * R - math.sqrt(4.0 * R**2 - p.offset**2)


def validate(p: GasketParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    if not (isinstance(p.steps, int) and p.steps >= 1):
        raise InputError(f"gasket: steps must be an integer >= 1, got {p.steps!r}")
    if not 0.0 < p.thickness < p.radius:
        raise InputError(f"gasket: need 0 < thickness < radius, got thickness {p.thickness!r} and "
                         f"radius {p.radius!r}")
    if not 0.0 <= p.offset < 2.0 * p.radius:
        raise InputError(f"gasket: offset must lie in [0, 2 radius), got {p.offset!r}")
    if p.separation <= 0.0:
        raise InputError(f"gasket: separation must be > 0, got {p.separation!r}")
    if p.stiffness_ratio <= 0.0:
        raise InputError(f"gasket: stiffness_ratio must be > 0, got {p.stiffness_ratio!r}")
    if p.n_around < 2 or p.n_through < 1:
        raise InputError("gasket: need n_around >= 2 and n_through >= 1")
    build(p).validate()


def centres(p: GasketParameters) -> dict[str, tuple[float, float]]:
    """The centres of the soft (left) and stiff (right) gaskets, as gasket_pair places them."""
    dx = p.radius + 0.5 * p.separation
    return {"soft": (-dx, -0.5 * p.offset), "stiff": (dx, 0.5 * p.offset)}


def config(p: GasketParameters | None = None) -> ModelConfig:
    """The two gaskets as data (what ``examples/gasket.toml`` holds for the defaults): their
    backs driven towards each other and back again."""
    p = p or GasketParameters()
    c = centres(p)
    opening = {"soft": "left", "stiff": "right"}  # each bulges towards the other
    direction = {"soft": 1.0, "stiff": -1.0}  # towards the other gasket
    moduli = {"soft": p.soft_youngs_modulus,
              "stiff": p.soft_youngs_modulus * p.stiffness_ratio}
    bodies = []
    for name in ("soft", "stiff"):
        mesh = MeshSpec(shape="gasket", parameters=as_parameters(
            centre=c[name], radius=p.radius, thickness=p.thickness, opening=opening[name],
            n_around=p.n_around, n_through=p.n_through),
            # quadratic elements: the contact face's facet midpoints on its circle
            curve=Curve("outer", c[name], p.radius) if p.order == 2 else None)
        bodies.append(BodyConfig(
            name=name,
            mesh=mesh,
            material=LinearElastic(moduli[name], p.poissons_ratio, p.plane),
            supports=(Support("back", ("y",)),),
            prescribed=(PrescribedDisplacement("back", "x", direction[name] * p.back_motion),),
            contact_boundaries=("outer",),
            order=p.order,
            kinematics=p.kinematics,
        ))
    if p.swap_bodies:
        bodies.reverse()
    settings = ContactSettings(variant=p.variant, search_distance=p.search_distance,
                               penetration_tolerance=p.penetration_tolerance,
                               equilibrium_tolerance=p.equilibrium_tolerance)
    return ModelConfig("gasket", tuple(bodies), settings,
                       Steps(load_factors=load_factors(p)))


def build(p: GasketParameters | None = None) -> Model:
    return config(p).build()


# -- the current configuration ------------------------------------------------------------------

def overlap_ignoring_contact(p: GasketParameters, load_factor: float) -> float:
    """How deep the outer faces overlap at ``load_factor`` with contact ignored (0 if apart).

    With contact ignored each gasket moves rigidly with its back (``Body.u_load`` is a
    translation: nothing else loads it), so the overlap is that of the two outer circles along
    the line of their centres, ``2 R - |c_soft - c_stiff|``.
    """
    dx = 2.0 * p.radius + p.separation - 2.0 * p.back_motion * load_factor
    return max(0.0, 2.0 * p.radius - math.hypot(dx, p.offset))


def _face(body: Body, centre: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The outer and inner faces' points of a gasket, each in order along the face.

    Ordered by their angle about the centre in the undeformed configuration; every point of a
    face, midpoints included, so a curved quadratic face is followed through its midpoints.
    """
    X = body.points.T
    out = []
    for name in ("outer", "inner"):
        idx = body.boundary_points(name)
        ang = np.arctan2(X[idx, 1] - centre[1], X[idx, 0] - centre[0])
        mid = np.angle(np.exp(1j * ang).mean())  # the middle of the face: no wrap-around
        out.append(idx[np.argsort(np.angle(np.exp(1j * (ang - mid))))])
    return out[0], out[1]


def _inside(polygon: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Whether each point (n, 2) lies inside the closed ``polygon`` (m, 2), by the even-odd
    rule: a ray to the right of the point crosses its edges an odd number of times. A point on
    an edge may go either way (its distance to the face is then zero, whichever sign it gets)."""
    a = np.asarray(polygon, dtype=float)
    b = np.roll(a, -1, axis=0)
    dy = b[:, 1] - a[:, 1]
    slope = np.divide(b[:, 0] - a[:, 0], dy, out=np.zeros_like(dy), where=dy != 0)
    points = np.asarray(points, dtype=float)
    inside = np.zeros(len(points), dtype=bool)
    for start in range(0, len(points), 512):  # bounded memory: 512 points x m edges at a time
        x, y = points[start:start + 512, :1], points[start:start + 512, 1:]
        straddles = (a[:, 1] > y) != (b[:, 1] > y)  # never true for a horizontal edge
        crossings = straddles & (x < a[:, 0] + (y - a[:, 1]) * slope)
        inside[start:start + 512] = np.count_nonzero(crossings, axis=1) % 2 == 1
    return inside


def current_contact(model: Model, p: GasketParameters, displacements: dict[str, np.ndarray],
                    forces: dict[str, np.ndarray] | None = None,
                    status: dict[str, np.ndarray] | None = None) -> dict[str, float]:
    """How the two faces meet in the current (deformed) configuration, X + u.

    The contact algorithm measures its gaps its own way (the paired variant along normals
    fixed in the undeformed configuration); this measures them geometrically, for the figures'
    reader. ``displacements`` (and optionally ``forces``, the nodal contact forces, and
    ``status``, 1 at nodes in contact) per body, at its points. Returns

    * ``max_overlap``: the deepest any outer-face point of one gasket lies inside the other's
      deformed section (0 if none), measured to the other's deformed outer face (polyline
      through its points). Meaningful for overlaps shallower than the thickness;
    * ``min_gap``: the smallest signed distance from a face point to the other face (negative:
      overlap);
    * with ``forces`` and ``status``: ``max_loaded_gap``, the widest gap bridged by a node in
      contact carrying more than 1 % of the largest nodal force, and
      ``max_force_angle_deg``, the largest angle between the line of such a node's force and the
      normal of its own deformed face (0 for frictionless contact in the current
      configuration); ``tensile_nodes``, how many nodes carry a force pulling their face
      outwards (more than 1 % of the largest: consistent nodal forces of a traction next to the
      edge of contact can be so, most of all on quadratic facets).
    """
    c = centres(p)
    faces, outlines = {}, {}
    for b in model.bodies:
        x = b.points.T + displacements[b.name]
        outer, inner = _face(b, c[b.name])
        faces[b.name] = (outer, x)
        outlines[b.name] = np.vstack([x[outer], x[inner[::-1]]])
    out = {"max_overlap": 0.0, "min_gap": math.inf}
    fmax = 0.0
    if forces is not None:
        fmax = max(float(np.linalg.norm(f, axis=1).max(initial=0.0)) for f in forces.values())
    loaded_gap, angle, tensile = 0.0, 0.0, 0
    for b in model.bodies:
        other = next(o.name for o in model.bodies if o.name != b.name)
        outer, x = faces[b.name]
        oo, ox = faces[other]
        face_other = ox[oo]
        pts = x[outer]
        _, _, dist = project_points(pts, face_other[:-1], face_other[1:])
        inside = _inside(outlines[other], pts)
        gap = np.where(inside, -dist, dist)
        out["min_gap"] = min(out["min_gap"], float(gap.min()))
        out["max_overlap"] = max(out["max_overlap"], float(np.max(-gap, initial=0.0)))
        if forces is None or fmax == 0.0:
            continue
        f = forces[b.name][outer]
        fn = np.linalg.norm(f, axis=1)
        # outward normal of the deformed face at each point (central differences along it)
        tangent = pts[np.r_[1:len(pts), len(pts) - 1]] - pts[np.r_[0, 0:len(pts) - 1]]
        normal = np.column_stack([tangent[:, 1], -tangent[:, 0]])
        normal /= np.linalg.norm(normal, axis=1)[:, None]
        normal *= np.sign(np.einsum("ij,ij->i", normal, pts - outlines[b.name].mean(axis=0))
                          )[:, None]
        big = fn > 0.01 * fmax
        inward = -np.einsum("ij,ij->i", f, normal)
        tensile += int((big & (inward < 0)).sum())
        on = big & (status[b.name][outer] > 0 if status is not None else True)
        if on.any():
            loaded_gap = max(loaded_gap, float(gap[on].max()))
            cosine = np.abs(inward[on]) / fn[on]
            angle = max(angle, float(np.degrees(np.arccos(np.clip(cosine, 0.0, 1.0))).max()))
    if forces is not None:
        out.update(max_loaded_gap=loaded_gap, max_force_angle_deg=angle, tensile_nodes=tensile)
    return out


# -- results ------------------------------------------------------------------------------------

def total_force(step: StepResult, body: str = "soft") -> np.ndarray:
    """The resultant (x, y) of the contact forces the other gasket applies to ``body``."""
    return step.bodies[body].contact_force.sum(axis=0)


def prediction(model: Model, previous: StepResult | None, load_factor: float
               ) -> dict[str, np.ndarray]:
    """The linear prediction of a step (thesis Figs. 5.19 and 5.21), per body, at its points.

    As the solver predicts (``Analysis.solve_step``): the previous converged state's contact
    forces held, the backs moved to the new load factor. Before the first contact it is the
    configuration with contact ignored.
    """
    out = {}
    for b in model.bodies:
        f = np.zeros(b.ndofs)
        if previous is not None:
            f = previous.bodies[b.name].contact_force.ravel()
        out[b.name] = b.displacement(load_factor, 0.0, f).reshape(-1, 2)
    return out


def scheduled_steps(result: AnalysisResult) -> list[StepResult | None]:
    """The converged step at each scheduled load factor, None where the analysis stopped.

    A step the solver had to cut adds intermediate steps to ``result.steps``; the example's
    step k is the one that reached the k-th scheduled load factor.
    """
    out: list[StepResult | None] = []
    it = iter(result.steps)
    for lf in result.model.load_factors:
        out.append(next((s for s in it if abs(s.load_factor - lf) <= 1e-12), None))
    return out


def force_history(summary: dict) -> np.ndarray:
    """F[k], the total contact force after step k (F[0] = 0, the initial state)."""
    return np.r_[0.0, [r["force_magnitude"] for r in summary["steps"]]]


def summarize(result: AnalysisResult, p: GasketParameters) -> dict:
    """The ``summary.json`` dictionary of a gasket run."""
    from vfem.io.results import step_record

    model = result.model
    steps = scheduled_steps(result)
    rows = []
    previous = None
    for k, s in enumerate(steps):
        if s is None:
            break
        disp = {n: r.displacement for n, r in s.bodies.items()}
        forces = {n: r.contact_force for n, r in s.bodies.items()}
        status = {n: r.contact_status for n, r in s.bodies.items()}
        pred = current_contact(model, p, prediction(model, previous, s.load_factor))
        F, F_stiff = total_force(s), total_force(s, "stiff")
        back = {}
        for b in model.bodies:
            back[b.name] = [b.reaction_of(s.bodies[b.name], "back", c) for c in ("x", "y")]
        rows.append({
            **step_record(s),
            "step": k + 1,
            # F, the magnitude ("contact_force" is step_record's (x, y) per body)
            "force_magnitude": float(np.linalg.norm(F)),
            "contact_force_soft": [float(v) for v in F],
            "contact_force_stiff": [float(v) for v in F_stiff],
            "back_reaction": back,
            "contact_nodes": {n: int((v > 0).sum()) for n, v in status.items()},
            "prediction_overlap": pred["max_overlap"],
            "current_configuration": current_contact(model, p, disp, forces, status),
        })
        previous = s
    n = p.steps
    summary: dict = {
        "example": "gasket",
        "converged": result.converged and len(rows) == len(model.load_factors),
        "message": result.message,
        "steps": rows,
        "solver_steps": len(result.steps),
        "closure_at_first_touch": closure_at_first_touch(p),
        "overlap_ignoring_contact": [overlap_ignoring_contact(p, lf)
                                     for lf in model.load_factors[:n]],
    }
    overlap = [r["step"] for r in rows if r["prediction_overlap"] > 0]
    touch = [r["step"] for r in rows if r["force_magnitude"] > 0]
    summary["first_overlap_step"] = overlap[0] if overlap else None
    summary["first_contact_step"] = touch[0] if touch else None
    F = force_history(summary)
    summary["largest_force_step"] = int(np.argmax(F)) if F.max() > 0 else None
    summary["largest_force"] = float(F.max())
    if len(rows) == 2 * n:
        summary["mirror_error"] = (float(np.max(np.abs(F[: n + 1] - F[::-1][: n + 1])) / F.max())
                                   if F.max() > 0 else 0.0)
        summary["reversibility"] = float(max(np.abs(r.displacement).max()
                                             for r in steps[-1].bodies.values()))
    # Newton's third law across the interface: the two resultants must cancel
    imbalance = [float(np.linalg.norm(np.add(r["contact_force_soft"], r["contact_force_stiff"])))
                 / r["force_magnitude"] for r in rows if r["force_magnitude"] > 0]
    summary["max_force_imbalance"] = max(imbalance, default=0.0)
    summary["bodies"] = {s.body.name: {"nodes": int(s.body.npoints), "dofs": int(s.body.ndofs),
                                       "contact_candidate_nodes": int(s.nc),
                                       "youngs_modulus": s.body.material.youngs_modulus}
                         for s in result.surfaces}
    summary["dofs"] = int(sum(s.body.ndofs for s in result.surfaces))
    summary["parameters"] = asdict(p)
    summary["timings"] = result.timings
    summary["penetration_tolerance"] = result.penetration_tolerance
    if summary["converged"]:
        summary["verification"] = verification(summary, p, result.model.contact)
    return summary


def force_tolerance(p: GasketParameters) -> float | None:
    """The relative discretisation error allowed to the force at the full motion against
    :data:`REFINED_FORCE`, or None where the reference is not this model: another geometry,
    motion, stiffness ratio, Poisson's ratio or plane, linear elements, large kinematics, or
    candidate surfaces that do not reach past the contact (search distance under 0.3;
    docs/examples.md, *Why a search distance of 0.4*)."""
    d = GasketParameters()
    same = ("radius", "thickness", "offset", "separation", "back_motion", "stiffness_ratio",
            "poissons_ratio", "plane", "order", "kinematics")
    if any(getattr(p, k) != getattr(d, k) for k in same) or p.search_distance < 0.3:
        return None
    if p.n_through >= REFINED_MESH[1] and p.n_around >= REFINED_MESH[0]:
        return AROUND_60 * (60 / REFINED_MESH[0]) ** 2  # finer than the reference: its error
    through = THROUGH_ONE if p.n_through < REFINED_MESH[1] else 0.0
    return through + AROUND_60 * (60 / min(p.n_around, REFINED_MESH[0])) ** 2


def verification(s: dict, p: GasketParameters, contact: ContactSettings) -> list[dict]:
    """The gasket's checks (``summary.json``'s ``verification``; :mod:`vfem.io.verification`).
    The thesis shows this example for reversibility (§5.5, Fig. 5.23): unloading retraces
    loading, and after the last step every node is back where it started. With them, where the
    formulation enforces invariant (a) (the paired variant), the forces on the two gaskets
    equal and opposite at the worst step (:func:`vfem.io.verification.balance`), and, where the
    model is the thesis's, the force at the full motion against the refined model
    (:data:`REFINED_FORCE`, within :func:`force_tolerance`).

    Under small kinematics with the paired variant reversibility holds to round-off
    (:data:`REVERSIBLE_ROUND_OFF`): the contact state at a load factor is unique and each step
    reaches it exactly (one correction closes every gap, docs/method.md §5); once every force
    is released the displacements are u = 0 u_load + K^-1 0 = 0. Otherwise (the thesis
    variant, large kinematics) each state is the exact one only to the contact iteration's
    tolerances: its equilibrium tolerance, which bounds each node's error relative to the
    largest nodal force and is taken here on the total force (an estimate, not a bound), and
    its penetration tolerance for the positions."""
    from vfem.io.verification import balance, check, enforces_balance

    rows = s["steps"]
    n = p.steps
    F = force_history(s)
    largest = float(F.max())
    motion = abs(p.back_motion) or p.thickness  # the scale of the positions
    exact = p.variant == "paired" and p.kinematics == "small"
    if exact:
        forces = positions = REVERSIBLE_ROUND_OFF
        basis = ("round-off: at a load factor loading and unloading solve the same system on "
                 "the same contact set (the paired variant, small kinematics), and released "
                 "u = K^-1 0; machine epsilon times the solves' condition, 8e-10 at worst at the "
                 "default mesh (gasket.REVERSIBLE_ROUND_OFF)")
        where = basis
    else:
        forces = contact.equilibrium_tolerance
        positions = s["penetration_tolerance"] / motion
        basis = ("the contact iteration's equilibrium tolerance (contact.equilibrium_tolerance), "
                 "which bounds each node's error relative to the largest nodal force, taken on "
                 "the total force: an estimate, not a bound")
        where = ("the contact iteration's penetration tolerance (contact.penetration_tolerance) "
                 "over the backs' motion")
    records = []
    if largest > 0:
        # the loading step whose force unloading misses most (of equals, the larger force)
        miss = np.abs(F[:n] - F[::-1][:n])
        k = max(range(n), key=lambda j: (miss[j], F[j]))
        records.append(check(f"unloading: force after step {2 * n - k}", F[2 * n - k], F[k],
                             f"loading's after step {k}, the same load factor", forces, basis,
                             measure="scaled", scale=largest))
    records.append(check(f"after step {2 * n}: largest |u|", s["reversibility"], 0.0,
                         "the initial state: nothing loads the gaskets", positions, where,
                         measure="scaled", scale=motion))
    # the two gaskets' forces at each step with force: invariant (a)'s measure, the worst step
    loaded = []
    for k, r in enumerate(rows, start=1):
        soft, stiff = np.asarray(r["contact_force_soft"]), np.asarray(r["contact_force_stiff"])
        scale = max(float(np.linalg.norm(soft)), float(np.linalg.norm(stiff)))
        if scale > 0:
            loaded.append((float(np.linalg.norm(soft + stiff)) / scale, k, soft + stiff, scale))
    if loaded and enforces_balance(contact):
        _, k, total, scale = max(loaded, key=lambda x: x[0])
        records.append(balance(f"|F_soft + F_stiff|, worst step (step {k})",
                               float(np.linalg.norm(total)), 0.0, "equal and opposite",
                               scale=scale))
    tol = force_tolerance(p)
    if tol is not None:
        ref = REFINED_FORCE * p.soft_youngs_modulus / GasketParameters.soft_youngs_modulus
        records.append(check(
            f"step {n}: contact force", F[n], ref,
            f"the model refined to {REFINED_MESH[0]} x {REFINED_MESH[1]} elements", tol,
            f"discretisation: {THROUGH_ONE:.0%} for one element through the thickness, "
            f"{AROUND_60:.1%} (60 / n_around)^2 around (the refinement study, "
            "docs/examples.md)"))
    return records


# -- running ------------------------------------------------------------------------------------

def run(p: GasketParameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD per step, ``summary.json`` and the figures to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p),
                       (lambda model, r, summary: figure_data(r, summary, out)) if figures
                       else None, on_step, resume)


def figure_data(result: AnalysisResult, summary: dict, out) -> None:
    """What the figures need beyond the results files, into ``summary.json``'s
    ``figure_data``: the VTU step of each scheduled step (``scheduled``; a cut step adds solver
    steps) and, as extra VTU files, the configuration with contact ignored and the linear
    predictions of the steps drawn (:data:`SHOWN_STEPS`)."""
    from pathlib import Path

    from vfem.io.replot import write_frames

    model = result.model
    steps = scheduled_steps(result)
    frames = {"ignoring_contact": write_frames(
        Path(out), "ignoring_contact", model,
        {b.name: b.u_load.reshape(-1, 2) for b in model.bodies})}
    for k in SHOWN_STEPS:
        if k > len(steps) or steps[k - 1] is None:
            continue
        label = f"prediction{k:02d}"
        frames[label] = write_frames(Path(out), label, model, prediction(
            model, steps[k - 2] if k >= 2 else None, steps[k - 1].load_factor))
    summary["figure_data"] = {"frames": frames,
                              "scheduled": [s.step if s is not None else None for s in steps]}


def figures(folder) -> list:
    """The figures of a gasket results folder (:class:`vfem.io.replot.Folder`), which the run
    draws and ``vfem plot`` redraws: thesis Figs. 5.17 to 5.23, the force history (from
    ``summary.json``'s steps) and ``von_mises.png`` at the step of the largest force.

    Configurations at true scale, every element's boundary through its nodes (quadratic faces
    drawn through their midpoints); the soft gasket first, so each keeps its colour or line
    style in every figure.
    """
    from vfem.io import plots, replot

    s = folder.summary
    data = s.get("figure_data")
    if not folder.has_steps or not data:
        return []
    out = folder.directory
    method = replot.contact_label(s)
    n = s["parameters"]["steps"]
    scheduled = data["scheduled"]
    names: list[str] = []

    def frame(label, bodies, zero=False):
        bodies = sorted(bodies, key=lambda b: b.name)  # soft, stiff
        return (label, [(b.name, b.points, b.polygons,
                         0.0 * b.displacement if zero else b.displacement) for b in bodies])

    def save(name, frames, title, magnification=1.0, **kw):
        plots.configurations(out / name, frames, title, magnification=magnification, **kw)
        names.append(name)

    first = folder.steps[0].bodies
    save("initial.png", [frame("initial", first, zero=True)],
         "Gasket: initial configuration (soft left, stiff right)", magnification=None)
    save("ignoring_contact.png", [frame("initial", first, zero=True),
                                  frame(f"step {n}, contact ignored",
                                        folder.frames("ignoring_contact"))],
         f"Gasket: initial and step {n} positions, contact ignored")
    for k in SHOWN_STEPS:
        label = f"prediction{k:02d}"
        if label not in data["frames"]:
            continue
        res = folder.step(scheduled[k - 1]).bodies
        pred = folder.frames(label)
        save(f"step{k:02d}_prediction.png", [frame(f"step {k}, linear prediction", pred)],
             f"Gasket: linear prediction for step {k} (step {k - 1}'s contact forces held)")
        save(f"step{k:02d}_resolved.png", [frame(f"step {k}, resolved", res)],
             f"Gasket: resolved position after iterations, step {k}\n{method}")
        window = _contact_window(res)
        if window is not None:
            save(f"step{k:02d}_contact.png",
                 [frame(f"step {k}, linear prediction", pred), frame(f"step {k}, resolved", res)],
                 f"Gasket: contact region, step {k}\n{method}", window=window,
                 mesh_lines=False)
    if scheduled and scheduled[-1] is not None:
        save("initial_final.png", [frame("initial", first, zero=True),
                                   frame(f"final (step {2 * n})",
                                         folder.step(scheduled[-1]).bodies)],
             f"Gasket: initial and final configurations\n{method}")
    F = force_history(s)
    k = np.arange(n + 1)
    series = {"loading: after step k": F[: n + 1]}
    if len(F) == 2 * n + 1:
        series[f"unloading: after step {2 * n} - k"] = F[::-1][: n + 1]
    plots.history(out / "contact_force.png", k[: len(series["loading: after step k"])], series,
                  "step k", "total contact force on a gasket (model units)",
                  f"Gasket: contact force, loading and unloading (mirrored)\n{method}")
    names.append("contact_force.png")
    at = s.get("largest_force_step")
    step = folder.step(scheduled[at - 1]) if at else folder.steps[-1]
    vm = replot.von_mises(folder, step, "von_mises.png",
                          f"Gasket: von Mises stress at step {at or step.step} (largest contact "
                          f"force)\n{method}")
    return [out / name for name in names] + [vm]


def _contact_window(bodies) -> tuple[float, float, float, float] | None:
    """A square window around the nodes carrying contact force (current configuration) of a
    step's bodies (:class:`vfem.io.replot.BodyFrame`)."""
    pts = []
    for b in bodies:
        f = np.asarray(b.point_data["contact_force"], dtype=float)[:, :2]
        pts.append((b.points + b.displacement)[np.linalg.norm(f, axis=1) > 0])
    pts = np.vstack(pts)
    if len(pts) == 0:
        return None
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    half = 0.5 * float((hi - lo).max()) + 0.1
    cx, cy = 0.5 * (lo + hi)
    return (cx - half, cx + half, cy - half, cy + half)


def report(s: dict) -> list[str]:
    """The closing lines of a gasket run."""
    rows = s["steps"]
    lines = [run_headline(s)]
    lines.append(f"  first overlap at step {s['first_overlap_step']}, largest contact force "
                 f"{s['largest_force']:.6g} at step {s['largest_force_step']}")
    if "mirror_error" in s:
        lines.append(f"  unloading mirrors loading to {s['mirror_error']:.1e} of the largest "
                     f"force; after step {len(rows)} no node is more than "
                     f"{s['reversibility']:.1e} from its start")
    if rows:
        geo = [r["current_configuration"] for r in rows]
        lines.append(f"  current configuration: deepest overlap "
                     f"{max(g['max_overlap'] for g in geo):.2e}, widest gap bridged by a node "
                     f"in contact {max(g['max_loaded_gap'] for g in geo):.2e}, forces up to "
                     f"{max(g['max_force_angle_deg'] for g in geo):.1f} deg off the face normal")
        imbalance = s["max_force_imbalance"]
        if imbalance > 1e-6:
            lines.append(f"  WARNING: the contact forces on the two gaskets differ by up to "
                         f"{imbalance:.1%} of the force")
        else:
            lines.append(f"  contact forces on the two gaskets balance to {imbalance:.1e}")
    return lines
