"""A stiff flat punch pressed into a softer block: a contact zone that ends at a sharp corner.

Issue 16's model (our dimensions; plane strain, whole model):

* the **block** [-2, 2] x [-2, 0], 80 x 40 quadrilaterals (facets 0.05 long on its top),
  E = 1e9, nu = 0.3, its base fixed;
* the **punch** [-0.5, 0.5] x [0, 0.5], 27 x 8 quadrilaterals, E = 2e11 (``stiffness_ratio``
  200 times the block's), nu = 0.3, its top held in x and moved down by ``indentation`` (0.01)
  over ``steps`` (4) steps. Its corners lie on block nodes.

The punch is 200 times stiffer, so the block carries compatibility (docs/method.md §6); the
block's nodes beyond the punch's corners are not over the punch and must carry nothing. The
reference needs no contact algorithm (:func:`reference_force`): the block alone, its top nodes
with |x| <= 0.5 moved down by the indentation and free to slide sideways — a rigid, frictionless
punch. The elastic punch's own compression makes the computed force a little lower (measured
-0.26 %). The pressure's shape is compared with Sadowsky's rigid punch on a half-plane,
p(x) = P / (pi sqrt(a^2 - x^2)), with P the computed force and a the punch's half-width; the
block is only 8a wide and 4a deep, so that shape is indicative, not a reference (the refinement
study of a wide, deep block is tests/test_punch.py's ``sadowsky``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vfem.bodies import PrescribedDisplacement, Support
from vfem.config import BodyConfig, MeshSpec, ModelConfig, Steps, as_parameters
from vfem.contact.settings import ContactSettings
from vfem.errors import InputError
from vfem.io.runner import run_headline
from vfem.materials import LinearElastic
from vfem.solver import AnalysisResult, Model

#: the magnification of the displacements in ``deformed.png``
MAGNIFICATION = 10.0

#: ``vfem verify --slow``: every mesh refined once (160 x 80 block, 54 x 16 punch)
VERIFY_SLOW = ("refinement=1",)

#: the contact's discretisation at the punch's corners, times sqrt(h / 2a) (h a block facet,
#: 2a the punch's width: the pressure is singular as 1/sqrt(r) at a corner, so what the corner's
#: facet misreads falls as sqrt(h)): with a rigid punch (``--set stiffness_ratio=1e6``) the
#: force is +0.062 % from the block alone's at 20 block facets across the punch and +0.038 % at
#: 40 (``refinement=1``; docs/examples.md, Punch), 0.0028 and 0.0024 times sqrt(h / 2a); twice
CORNER_DISCRETISATION = 0.0055


@dataclass(frozen=True)
class Parameters:
    """Parameters of the punch example (issue 16's model; see the module docstring)."""

    block_half_width: float = 2.0
    block_depth: float = 2.0
    block_columns: int = 80
    block_rows: int = 40
    block_youngs_modulus: float = 1.0e9
    punch_half_width: float = 0.5
    punch_height: float = 0.5
    punch_columns: int = 27
    punch_rows: int = 8
    stiffness_ratio: float = 200.0  # punch modulus / block modulus
    poissons_ratio: float = 0.3
    indentation: float = 0.01  # of the punch's top, downwards
    steps: int = 4
    refinement: int = 0  # doubles every mesh's columns and rows per level
    kinematics: str = "small"
    variant: str = "paired"
    search_distance: float | None = None
    swap_bodies: bool = False  # list the punch first


def _divisions(p: Parameters) -> tuple[int, int, int, int]:
    k = 2**p.refinement
    return p.block_columns * k, p.block_rows * k, p.punch_columns * k, p.punch_rows * k


def config(p: Parameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/punch/flat_punch.toml`` holds for the defaults)."""
    p = p or Parameters()
    bx, by, px, py = _divisions(p)
    block = BodyConfig(
        "block",
        MeshSpec(shape="rectangle", parameters=as_parameters(
            x0=-p.block_half_width, y0=-p.block_depth, width=2 * p.block_half_width,
            height=p.block_depth, nx=bx, ny=by)),
        LinearElastic(p.block_youngs_modulus, p.poissons_ratio),
        supports=(Support("bottom", ("x", "y")),), kinematics=p.kinematics)
    punch = BodyConfig(
        "punch",
        MeshSpec(shape="rectangle", parameters=as_parameters(
            x0=-p.punch_half_width, y0=0.0, width=2 * p.punch_half_width,
            height=p.punch_height, nx=px, ny=py)),
        LinearElastic(p.stiffness_ratio * p.block_youngs_modulus, p.poissons_ratio),
        supports=(Support("top", ("x",)),),
        prescribed=(PrescribedDisplacement("top", "y", -p.indentation),),
        kinematics=p.kinematics)
    bodies = (punch, block) if p.swap_bodies else (block, punch)
    return ModelConfig("flat_punch", bodies,
                       ContactSettings(variant=p.variant, search_distance=p.search_distance),
                       Steps(count=p.steps))


def configs(p: Parameters | None = None) -> dict[str, ModelConfig]:
    """The one model, keyed by its file's name: ``vfem export punch --out DIR`` writes
    ``DIR/flat_punch.toml`` (``examples/punch/flat_punch.toml`` beside the other punches)."""
    return {"flat_punch": config(p)}


def build(p: Parameters | None = None) -> Model:
    return config(p).build()


def validate(p: Parameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    if p.punch_half_width >= p.block_half_width:
        raise InputError("punch: punch_half_width must be less than block_half_width (the "
                         "punch must lie over the block)")
    if p.steps < 1:
        raise InputError(f"punch: steps must be at least 1, got {p.steps}")
    if p.refinement < 0:
        raise InputError(f"punch: refinement must be 0 or more, got {p.refinement}")
    build(p).validate()


def reference_force(p: Parameters | None = None) -> float:
    """The force of a rigid, frictionless punch, with no contact algorithm: the block alone
    (scikit-fem, the same bilinear quadrilaterals), its top nodes with |x| <= the punch's
    half-width moved down by the indentation and free sideways, its base fixed; small strain,
    plane strain. The sum of the vertical reactions at those nodes."""
    from skfem import Basis, ElementQuad1, ElementVector, MeshQuad, asm, condense, solve
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    p = p or Parameters()
    bx, by, _, _ = _divisions(p)
    w, d = p.block_half_width, p.block_depth
    m = MeshQuad.init_tensor(np.linspace(-w, w, bx + 1), np.linspace(-d, 0, by + 1))
    basis = Basis(m, ElementVector(ElementQuad1()))
    K = asm(linear_elasticity(*lame_parameters(p.block_youngs_modulus, p.poissons_ratio)),
            basis)
    tol = 1e-12 * max(w, d)
    bottom = basis.get_dofs(lambda x: np.abs(x[1] + d) <= tol).all()
    top = basis.get_dofs(lambda x: (np.abs(x[1]) <= tol)
                         & (np.abs(x[0]) <= p.punch_half_width + tol))
    ty = top.nodal["u^2"]
    u = np.zeros(K.shape[0])
    u[ty] = -p.indentation
    u = solve(*condense(K, np.zeros(K.shape[0]), u, D=np.concatenate([bottom, ty])))
    return float(-(K @ u)[ty].sum())


def _block_top(result: AnalysisResult) -> tuple[object, np.ndarray]:
    """The block and its top nodes, ordered by x."""
    block = next(b for b in result.model.bodies if b.name == "block")
    x, y = block.points
    top = np.flatnonzero(np.abs(y) <= 1e-12 * max(1.0, float(np.abs(x).max())))
    return block, top[np.argsort(x[top])]


def evaluate(result: AnalysisResult, p: Parameters) -> dict:
    """The last step against the rigid-punch reference: both bodies' contact forces and their
    balance, the force against :func:`reference_force`, the sideways force, and the contact
    zone's extent against the punch's width."""
    last = result.steps[-1]
    totals = {name: [float(r.contact_force[:, 0].sum()), float(r.contact_force[:, 1].sum())]
              for name, r in last.bodies.items()}
    load = abs(totals["block"][1])
    imbalance = max(abs(totals["block"][k] + totals["punch"][k]) for k in (0, 1))
    reference = reference_force(p)
    block, top = _block_top(result)
    x = block.points[0]
    r = last.bodies["block"]
    loaded = np.flatnonzero(np.abs(r.contact_force).sum(axis=1) > 0)
    a = p.punch_half_width
    outside = loaded[np.abs(x[loaded]) > a * (1 + 1e-12)]
    centre = top[int(np.argmin(np.abs(x[top])))]
    sadowsky_centre = load / (math.pi * a)
    return {
        "block_contact_force": totals["block"],
        "punch_contact_force": totals["punch"],
        "force": load,
        "force_balance": imbalance / load if load else math.inf,
        "reference_force": reference,
        "difference_from_reference": load / reference - 1.0,
        "sideways_force": totals["block"][0],
        "sideways_over_force": abs(totals["block"][0]) / load if load else math.inf,
        "contact_zone": ([float(x[loaded].min()), float(x[loaded].max())] if len(loaded)
                         else None),
        "punch_half_width": a,
        "block_nodes_loaded": int(len(loaded)),
        "block_nodes_in_contact": int((r.contact_status > 0).sum()),
        "block_nodes_outside_punch_loaded": int(len(outside)),
        "outside_punch_largest_force": (float(np.abs(r.contact_force[outside]).max())
                                        if len(outside) else 0.0),
        "largest_nodal_force": float(np.linalg.norm(r.contact_force, axis=1).max(initial=0.0)),
        "p_max_block": float(r.contact_pressure.max()),
        "p_max_block_at_x": float(x[int(np.argmax(r.contact_pressure))]),
        "p_max_punch": float(last.bodies["punch"].contact_pressure.max()),
        "p_centre_block": float(r.contact_pressure[centre]),
        "p_centre_sadowsky": sadowsky_centre,
        "reference_note": "the block alone, its top nodes with |x| <= a moved down by the "
                          "indentation and free sideways (a rigid frictionless punch; "
                          "small strain)",
    }


def summarize(result: AnalysisResult, p: Parameters) -> dict:
    from vfem.io.results import example_summary

    summary = example_summary("punch", result, p)
    summary["pressure_measure"] = "nominal: nodal contact force / undeformed tributary length"
    if result.steps and result.steps[-1].load_factor == 1.0:
        summary["punch"] = evaluate(result, p)
        if result.converged:
            summary["verification"] = verification(summary["punch"], p, result.model.contact)
    return summary


def force_tolerance(c: dict, p: Parameters) -> dict[str, float]:
    """What the rigid punch's force (:func:`reference_force`) leaves out, each part as a
    fraction of the force: the elastic punch's own compression, ``P (1 - nu^2) H / (2 a E_p)``
    under a uniform stress over the indentation (its share of the indentation, which the rigid
    punch gives wholly to the block), and the contact's discretisation at the corners,
    :data:`CORNER_DISCRETISATION` times the square root of a block facet over the punch's width.
    The tolerance is twice the first plus the second (the corners concentrate the compression:
    measured 1.33 times the uniform estimate, docs/examples.md)."""
    a, h = p.punch_half_width, 2 * p.block_half_width / _divisions(p)[0]
    compression = (c["force"] * (1 - p.poissons_ratio**2) * p.punch_height
                   / (2 * a * p.stiffness_ratio * p.block_youngs_modulus * p.indentation))
    corners = CORNER_DISCRETISATION * math.sqrt(h / (2 * a))
    return {"compression": compression, "corners": corners,
            "tolerance": 2 * compression + corners}


#: the reference of the force (:func:`reference_force`): no contact algorithm, the block alone
#: on the run's own block mesh, its top nodes under the punch moved down by the indentation and
#: free sideways (a rigid, frictionless punch; small strain), solved with scikit-fem
RIGID = ("the block alone, same mesh, no contact: its top under the punch moved down by the "
         "indentation (a rigid frictionless punch, small strain)")


def verification(c: dict, p: Parameters, settings: ContactSettings) -> list[dict]:
    """The punch run's checks (``summary.json``'s ``verification``;
    :mod:`vfem.io.verification`):

    * under small kinematics, the force against :data:`RIGID`: the block alone on the same
      block mesh under a rigid, frictionless punch's motion (:func:`reference_force`: no contact
      algorithm; a small-strain solve, so under ``kinematics = "total"`` it is no reference and
      there is no record), within what the rigid punch leaves out: the elastic punch's
      compression and the corners' discretisation (:func:`force_tolerance`);
    * where the formulation enforces invariant (a) (the paired variant), the two bodies' contact
      forces equal and opposite (:func:`vfem.io.verification.balance`);
    * no sideways force (a frictionless force lies along the flat face's normal, and the model
      is symmetric about x = 0);
    * no force on the block's nodes beyond the punch's corners (issue 16: they are not over the
      punch), within what the contact iteration leaves uncorrected at a node:
      ``contact.equilibrium_tolerance`` (``settings``, the model's) of the largest nodal force.
    """
    from vfem.io.verification import balance, check, enforces_balance

    records = []
    if p.kinematics == "small":
        tol = force_tolerance(c, p)
        records.append(check(
            "contact force", c["force"], c["reference_force"], RIGID, tol["tolerance"],
            f"the elastic punch's compression, {tol['compression']:.2%} of the force under a "
            f"uniform stress (P (1 - nu^2) H / (2 a E_p) over the indentation), twice, and "
            f"the corners' discretisation, {tol['corners']:.2%} at this block facet "
            "(docs/examples.md, Punch)"))
    if enforces_balance(settings):
        largest = max(math.hypot(*c["punch_contact_force"]), math.hypot(*c["block_contact_force"]))
        records.append(balance("contact force on the punch", c["punch_contact_force"][1],
                               -c["block_contact_force"][1], "the block's, equal and opposite",
                               scale=largest))
    eq = settings.equilibrium_tolerance
    records += [
        check("sideways force", c["sideways_force"], 0.0,
              "exact: frictionless, on a flat face, symmetric", 1e-10,
              "round-off: each contact force lies along the flat face's normal and the model is "
              "symmetric about x = 0 (1e-16 times the systems' condition, with margin)",
              measure="scaled", scale=c["force"]),
        check("largest force beyond the corners", c["outside_punch_largest_force"], 0.0,
              "exact: those block nodes are not over the punch", eq,
              f"the contact iteration leaves at most contact.equilibrium_tolerance ({eq:g}) of "
              "the largest nodal contact force uncorrected at a node (scaled by that force)",
              measure="scaled", scale=c["largest_nodal_force"]),
    ]
    return records


def run(p: Parameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example: VTU/PVD per step, ``summary.json`` and the figures in ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p),
                       (lambda model, result, summary: _figure_data(summary, p)) if figures
                       else None, on_step, resume)


def _figure_data(summary: dict, p: Parameters) -> None:
    """What the figures need beyond the results files: the corner's window and the
    magnification of ``deformed.png`` (into ``summary.json``'s ``figure_data``)."""
    a = p.punch_half_width
    h = 2 * a / _divisions(p)[2]  # the punch's facet length
    depth = MAGNIFICATION * p.indentation
    summary["figure_data"] = {
        "magnification": MAGNIFICATION,
        "corner_window": [a - 0.5 * a, a + 0.5 * a, -depth - 0.4 * a, -depth + 0.3 * a + h]}


def figures(folder) -> list[Path]:
    """The figures of a punch results folder (:class:`vfem.io.replot.Folder`), which the run
    draws and ``vfem plot`` redraws: ``pressure.png``, the block's nodal pressure along its top
    (the last step's VTU) against Sadowsky's shape for the computed force (``summary.json``'s
    ``punch``); ``deformed.png``, the right corner, displacements magnified; ``von_mises.png``,
    the same corner filled by the von Mises stress."""
    from vfem.io import plots, replot

    s = folder.summary
    if not folder.has_steps or "punch" not in s:  # the full indentation was not reached
        return []
    c, data = s["punch"], s["figure_data"]
    a = c["punch_half_width"]
    method = replot.contact_label(s)
    last = folder.steps[-1]
    block = next(b for b in last.bodies if b.name == "block")
    x, y = block.points.T
    top = np.flatnonzero(np.abs(y) <= 1e-12 * max(1.0, float(np.abs(x).max())))
    top = top[np.argsort(x[top], kind="stable")]
    keep = np.abs(x[top]) <= 2 * a
    pressure = np.asarray(block.point_data["contact_pressure"], dtype=float).ravel()
    out = folder.directory
    plots.punch_pressure(out / "pressure.png", x[top[keep]], pressure[top[keep]], c["force"], a,
                         f"Flat punch: block's contact pressure, force {c['force']:.4g} "
                         f"({c['difference_from_reference']:+.2%} from the rigid punch)\n"
                         f"{method}")
    meshes = [(b.name, b.points, b.polygons, b.displacement) for b in last.bodies]
    m, window = data["magnification"], tuple(data["corner_window"])
    plots.configurations(out / "deformed.png", [("deformed", meshes)],
                         f"Flat punch: the right corner\n{method}", window=window,
                         legend_loc="upper right", magnification=m)
    vm = replot.von_mises(folder, last, "von_mises.png",
                          f"Flat punch: von Mises stress at the right corner\n{method}",
                          window=window, magnification=m)
    return [out / "pressure.png", out / "deformed.png", vm]


def report(s: dict) -> list[str]:
    lines = [run_headline(s)]
    if "punch" in s:
        c = s["punch"]
        (bx, by), (px, py) = c["block_contact_force"], c["punch_contact_force"]
        lines.append(f"  contact force on the block ({bx:.6g}, {by:.6g}), on the punch "
                     f"({px:.6g}, {py:.6g}): balance {c['force_balance']:.1e}")
        lines.append(f"  force {c['force']:.6g}; rigid punch {c['reference_force']:.6g} (the block "
                     f"alone, small strain, its top under the punch moved "
                     f"{s['parameters']['indentation']:g}): {c['difference_from_reference']:+.3%}")
        zone = c["contact_zone"]
        where = (f"{zone[0]:.4g} to {zone[1]:.4g}" if zone else "none")
        lines.append(f"  sideways force {c['sideways_force']:.2e} "
                     f"({c['sideways_over_force']:.1e} of the force); block nodes carrying force: "
                     f"x from {where} (punch: |x| <= {c['punch_half_width']:g}), "
                     f"{c['block_nodes_outside_punch_loaded']} outside it")
        lines.append(f"  p at the centre {c['p_centre_block']:.4g} (Sadowsky's half-plane "
                     f"{c['p_centre_sadowsky']:.4g}), p_max {c['p_max_block']:.4g} at "
                     f"|x| = {abs(c['p_max_block_at_x']):.4g}")
    return lines
