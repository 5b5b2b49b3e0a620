"""A stack of blocks pressed together (issue 22): many bodies, and contact zones as large as asked.

``blocks`` plates of alternating stiffness (an aluminium-like and a steel-like modulus) lie on
each other, each ``shrink`` narrower than the one below, so every upper plate's edges lie inside
the face of the plate beneath (an edge of the contact zone inside a surface, where the pressure
peaks). Quarter model (3D) or half model (2D, plane strain): every plate on rollers at the
symmetry planes (x = 0, and y = 0 in 3D), the lowest one held at its base, those between held
vertically at their outer side faces (their rims, as bolts hold a flange: each body of the
method has its own factorization, so each must be held), the top face of the highest pressed
down by ``press`` with its lateral motion held (a clamped press). The middle plates bend
between their rims and what presses on them, so their contact zones have edges inside the
faces where they end. Meshes do not
match across any interface: plate k has ``divisions + k % 2`` elements across (and its own
width), so the stiffer plates (odd k) have the finer meshes. The other way round, a stiff
coarse face on a soft fine one (``stiff_modulus`` and ``soft_modulus`` swapped), stopped at
invariant (b) with ``divisions`` 10, 12, 14 and 20 in 8 steps until issue 37, 1-1.4 % beyond
its tolerance: the check's two triangles per quadrilateral face part from the formulation's
bilinear face by a quarter of its twist, which (b) now allows for (docs/method.md §7,
docs/examples.md).

Every node of every upper face is in contact, so the contact zone grows as
``divisions**(dim - 1)``: two plates with ``divisions = 70`` in 3D make a flat-on-flat interface
of 71 x 71 against 72 x 72 nodes (29,004 contact dofs), about where the dense contact blocks
stop fitting (``contact.flexibility``, :mod:`vfem.contact.solvers.matrix_free`). ``blocks = 2`` with
a thin ``thickness`` is a flange-like pair of plates.

No closed form; the checks are those every contact solution must meet (every invariant at
every converged step: the forces balance, no body inside another, no tension), the contact
forces equal and opposite across each interface, the press's force equal to the reactions of
the base and the rims, and the same answer from either route to the flexibility and either
body order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vfem.bodies import PrescribedDisplacement, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import FLEXIBILITY_ROUTES, ContactSettings
from vfem.errors import InputError
from vfem.io.runner import run_headline
from vfem.materials import LinearElastic
from vfem.solver import AnalysisResult, Model


@dataclass(frozen=True)
class Parameters:
    """Parameters of the stack example (see the module docstring)."""

    dim: int = 3  # 2: plane strain; 3: a quarter model
    blocks: int = 3
    divisions: int = 8  # elements across the lowest plate (plate k: divisions + k % 2)
    layers: int = 2  # elements through each plate's thickness
    width: float = 1.0  # the lowest plate's half width
    thickness: float = 0.25
    shrink: float = 0.1  # each plate this fraction narrower than the one below
    stiff_modulus: float = 200e3  # plates 1, 3, 5, ... (one division more: the finer)
    soft_modulus: float = 70e3  # plates 0, 2, 4, ...
    poissons_ratio: float = 0.3
    press: float = 0.001  # the highest plate's top face, downwards
    steps: int = 1
    tetrahedra: bool = False  # 3D: tetrahedra instead of hexahedra (2D: triangles)
    flexibility: str = "auto"  # contact.flexibility: auto, dense or matrix_free
    reverse_bodies: bool = False  # list the plates from the top down


#: ``vfem verify --slow``: every plate's elements halved (16 divisions across, 4 layers)
VERIFY_SLOW = ("divisions=16", "layers=4")

#: The verification lists each interface's forces up to this many interfaces, else the worst.
LISTED_INTERFACES = 4

def validate(p: Parameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    if p.dim not in (2, 3):
        raise InputError(f"stack: dim must be 2 or 3, got {p.dim!r}")
    for name, low in (("blocks", 2), ("divisions", 1), ("layers", 1), ("steps", 1)):
        v = getattr(p, name)
        if not isinstance(v, int) or isinstance(v, bool) or v < low:
            raise InputError(f"stack: {name} must be a whole number >= {low}, got {v!r}")
    if p.blocks > 64:
        raise InputError(f"stack: blocks must be at most 64, got {p.blocks}")
    for name in ("width", "thickness", "stiff_modulus", "soft_modulus", "press"):
        v = getattr(p, name)
        if not (isinstance(v, (int, float)) and np.isfinite(v) and v > 0):
            raise InputError(f"stack: {name} must be a number > 0, got {v!r}")
    if not (0.0 <= p.shrink < 1.0 / p.blocks):
        raise InputError(f"stack: shrink must be >= 0 and below 1 / blocks "
                         f"({1.0 / p.blocks:.3g}), got {p.shrink!r}")
    if not (-1.0 < p.poissons_ratio < 0.5):
        raise InputError(f"stack: poissons_ratio must lie in (-1, 0.5), got "
                         f"{p.poissons_ratio!r}")
    if p.press >= 0.1 * p.thickness:
        raise InputError(f"stack: press ({p.press:g}) must be below a tenth of the thickness "
                         f"({p.thickness:g}): small kinematics")
    if p.flexibility not in FLEXIBILITY_ROUTES:
        raise InputError(f"stack: flexibility must be one of {FLEXIBILITY_ROUTES}, got "
                         f"{p.flexibility!r}")
    build(p).validate()


def plate_width(p: Parameters, k: int) -> float:
    """Plate k's half width (k = 0: the lowest)."""
    return p.width * (1.0 - k * p.shrink)


def config(p: Parameters | None = None) -> ModelConfig:
    """The model as data (``vfem export stack`` writes it as ``examples/stack.toml``)."""
    p = p or Parameters()
    rollers = (Support("left", ("x",)),) + ((Support("front", ("y",)),) if p.dim == 3 else ())
    lateral = ("x", "y") if p.dim == 3 else ("x",)
    vertical = "z" if p.dim == 3 else "y"
    rims = ("right", "back") if p.dim == 3 else ("right",)
    bodies = []
    for k in range(p.blocks):
        w, n = plate_width(p, k), p.divisions + k % 2
        if p.dim == 3:
            mesh = MeshSpec(shape="box", parameters=as_parameters(
                x0=0.0, y0=0.0, z0=k * p.thickness, width=w, depth=w, height=p.thickness,
                nx=n, ny=n, nz=p.layers, tetrahedra=p.tetrahedra))
        else:
            mesh = MeshSpec(shape="rectangle", parameters=as_parameters(
                x0=0.0, y0=k * p.thickness, width=w, height=p.thickness, nx=n, ny=p.layers,
                triangles=p.tetrahedra))
        mat = LinearElastic(p.stiff_modulus if k % 2 else p.soft_modulus, p.poissons_ratio)
        supports = rollers
        prescribed = ()
        if k == 0:
            supports = supports + (Support("bottom", (vertical,)),)
        elif k < p.blocks - 1:  # held at its rim, as bolts hold a flange's
            supports = supports + tuple(Support(face, (vertical,)) for face in rims)
        if k == p.blocks - 1:
            prescribed = (PrescribedDisplacement("top", vertical, -p.press),) + tuple(
                PrescribedDisplacement("top", c, 0.0) for c in lateral)
        faces = (("top",) if k < p.blocks - 1 else ()) + (("bottom",) if k > 0 else ())
        bodies.append(BodyConfig(f"plate{k}", mesh, mat, supports=supports,
                                 prescribed=prescribed, contact_boundaries=faces))
    if p.reverse_bodies:
        bodies.reverse()
    # each plate touches its neighbours only: without the pairs named, every two plates
    # would be paired (a plate's nodes measured against a plate three layers down)
    neighbours = tuple((f"plate{k}", f"plate{k + 1}") for k in range(p.blocks - 1))
    return ModelConfig("stack", tuple(bodies), ContactSettings(flexibility=p.flexibility),
                       Steps(count=p.steps), contact_pairs=neighbours)


def build(p: Parameters | None = None) -> Model:
    return config(p).build()


def evaluate(result: AnalysisResult, p: Parameters) -> dict:
    """The press's force, the base's and the rims' reactions (their sum the press's: nothing
    else holds the stack vertically) and per interface the total vertical contact force on the
    upper plate's bottom and on the lower plate's top (equal and opposite)."""
    last = result.steps[-1]
    axis = p.dim - 1
    component = "zy"[p.dim == 2]
    bodies = {b.name: b for b in result.model.bodies}

    def reaction(name: str, face: str | None = None) -> float:
        """The vertical force the constraints on ``face`` (every constraint of the body:
        each constrained dof once) apply to body ``name``."""
        body, r = bodies[name], last.bodies[name]
        if face is not None:
            return body.reaction_of(r, face, component)
        return float(np.asarray(r.reaction).ravel()[axis::p.dim].sum())

    def face_force(name: str, face: str) -> float:
        body = bodies[name]
        nodes = np.unique(body.facet_points(body.mesh.boundaries[face]))
        return float(last.bodies[name].contact_force[nodes, axis].sum())

    press = -reaction(f"plate{p.blocks - 1}", "top")
    held = sum(reaction(f"plate{k}") for k in range(p.blocks - 1))
    interfaces = []
    for k in range(p.blocks - 1):
        up, down = face_force(f"plate{k + 1}", "bottom"), face_force(f"plate{k}", "top")
        interfaces.append({"force": up, "force_below": down, "equal_and_opposite_error":
                           abs(up + down) / max(abs(up), 1e-300)})
    return {"press_force": press, "held_force": held,
            "balance_error": abs(press - held) / abs(press), "interfaces": interfaces,
            "contact_dofs": int(sum(p.dim * s.nc for s in result.surfaces)),
            "matrix_free": result.flexibility == "matrix_free"}


def summarize(result: AnalysisResult, p: Parameters) -> dict:
    """The ``summary.json`` dictionary of a stack run."""
    from vfem.io.results import solid_summary

    summary = solid_summary("stack", result, p, "stack", evaluate)
    if result.converged and "stack" in summary:  # converged at full load
        summary["verification"] = verification(summary["stack"], p)
    return summary


def verification(m: dict, p: Parameters) -> list[dict]:
    """The run's checks (``summary.json``'s ``verification``; :mod:`vfem.io.verification`).
    No closed form: exact properties of the problem, each to invariant (a)'s tolerance
    (FORCE_BALANCE_TOLERANCE). The press's force against the reactions of the base and the rims:
    nothing else holds the stack vertically, each plate's reactions balance its own contact
    forces to the round-off of its solve, and the contact forces of all the plates sum to zero
    within invariant (a)'s tolerance of the largest plate's total (enforced at every converged
    step). At each interface (the worst, beyond :data:`LISTED_INTERFACES`) the upper plate's
    contact force against the lower one's, equal and opposite: both follow from one traction,
    to round-off (:func:`vfem.io.verification.balance`, one interface of several)."""
    from vfem.contact.invariants.measures import FORCE_BALANCE_TOLERANCE
    from vfem.io.verification import balance, check

    part = "quarter model" if p.dim == 3 else "half model"
    tol = FORCE_BALANCE_TOLERANCE
    records = [check(
        f"press force ({part})", m["press_force"], m["held_force"],
        "the base's and rims' reactions (forces balance)", tol,
        f"invariant (a): the plates' contact forces sum to zero within {tol:g} of the largest "
        "plate's total, the top plate's, the press's force (FORCE_BALANCE_TOLERANCE, "
        "enforced), and each plate's reactions balance its contact forces to the round-off of "
        "its solve")]
    rows = list(enumerate(m["interfaces"]))
    where = part
    if len(rows) > LISTED_INTERFACES:
        rows = [max(rows, key=lambda r: r[1]["equal_and_opposite_error"])]
        where = f"{part}; the worst of {len(m['interfaces'])} interfaces"
    for k, i in rows:
        records.append(balance(
            f"contact force on plate{k + 1}'s bottom ({where})", i["force"], -i["force_below"],
            f"plate{k}'s top, equal and opposite", interface=True))
    return records


def run(p: Parameters, out, on_step=None, figures: bool = True, resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD per step and ``summary.json`` to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), None, on_step, resume)


def report(s: dict) -> list[str]:
    """The closing lines of a stack run."""
    lines = [run_headline(s, contact_dofs=True)]
    if "stack" in s:
        m = s["stack"]
        worst = max(i["equal_and_opposite_error"] for i in m["interfaces"])
        lines.append(f"  press force {m['press_force']:.6g}, base and rims {m['held_force']:.6g} "
                     f"({m['balance_error']:.1e} apart); interfaces equal and opposite within "
                     f"{worst:.1e}; {m['contact_dofs']} contact dofs, flexibility "
                     f"{'matrix-free' if m['matrix_free'] else 'dense'}")
    return lines
