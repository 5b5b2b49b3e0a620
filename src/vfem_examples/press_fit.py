"""A shaft pressed into a hub with a radial interference (issue 21): an interference fit.

The shaft (radius b + delta) and the hub (bore b, outer radius c), of one material, start
overlapping by delta all round; the contact resolves the overlap in the first step (the
overlap must lie within the elements behind the surfaces: ``docs/method.md`` §12). Both are
held on rollers at their two end faces (z = 0 and z = L), so every section is in plane strain,
and on the two symmetry planes of the quarter model. Lame's thick cylinders in plane strain
(derived in ``docs/examples.md``): the radial displacement of the hub's bore under a pressure
p is p b (1 + nu) ((1 - 2 nu) b^2 + c^2) / (E (c^2 - b^2)), the shaft's surface moves by
-p b (1 + nu)(1 - 2 nu) / E, and their difference is delta:

    p = E delta (c^2 - b^2) / (2 b c^2 (1 - nu^2)).

The meshes: the hub a polar grid (:func:`vfem.mesh.solids.ring`, ``around`` facets per quarter
turn), the shaft a cylinder whose rim nodes lie at equal angles
(:func:`vfem.mesh.solids.cylinder` with ``around / 2`` divisions across: as many facets per
quarter turn), so the two faceted surfaces are similar polygons and the interference is the
same at every node (with facets at other angles, a faceting sag comparable with delta makes
the pressure scatter from node to node; ``docs/examples.md``).
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


@dataclass(frozen=True)
class PressFitParameters:
    """Parameters of the press fit example."""

    bore_radius: float = 1.0  # b: the hub's bore; the shaft's radius is b + interference
    hub_radius: float = 2.0  # c
    length: float = 0.5
    interference: float = 0.01  # delta, on the radius
    youngs_modulus: float = 200e3
    poissons_ratio: float = 0.3
    around: int = 24  # facets per quarter turn (even)
    radial: int = 8  # the hub's elements through its wall
    layers: int = 2  # along the axis
    hub_cells: str = "hex"  # or "tet"
    shaft_cells: str = "hex"
    swap_bodies: bool = False
    friction: float = 0.0  # Coulomb's mu between shaft and hub
    push: float = 0.0  # after the fit: the shaft's end faces moved this far along the axis
    push_steps: int = 2


Parameters = PressFitParameters

#: ``vfem verify --slow``: twice as many facets per quarter turn and elements through the wall
#: (the shaft's outer elements then need the interference halved: docs/examples.md)
VERIFY_SLOW = ("around=48", "radial=16", "interference=0.005")

#: the nodal pressure's error allowed against Lame's (relative): at the default mesh (24 facets
#: per quarter turn, 8 elements through the wall) the hub's nodes are within 0.27 % and their
#: mean error falls as the square of the wall's element size (0.77, 0.18 and 0.03 % at 4, 8 and
#: 16 through it); 48 facets and 16 through the wall: within 0.065 % (docs/examples.md, Press
#: fit). About four times the default's
PRESSURE_TOLERANCE = 0.01


def lame_fit(b: float, c: float, delta: float, shaft: tuple[float, float],
             hub: tuple[float, float]) -> dict[str, float]:
    """Lame's interference fit in plane strain: a solid shaft (Young's modulus and Poisson's
    ratio ``shaft``) of radius b + delta in a hub (``hub``) of bore b and outer radius c.

    Under a pressure p on its bore the hub's bore moves out by u_hub = p b (1 + nu_h)
    ((1 - 2 nu_h) b^2 + c^2) / (E_h (c^2 - b^2)); the solid shaft's surface moves by
    u_shaft = -p_s (b + delta) (1 + nu_s)(1 - 2 nu_s) / E_s under its own pressure p_s, which
    carries the same force over the radius b + delta, p_s = p b / (b + delta), so u_shaft =
    -p b (1 + nu_s)(1 - 2 nu_s) / E_s (exactly, in small strain). They meet when u_hub -
    u_shaft = delta:

        p = delta / (b (1 + nu_h)((1 - 2 nu_h) b^2 + c^2) / (E_h (c^2 - b^2))
                     + b (1 + nu_s)(1 - 2 nu_s) / E_s),

    one material: p = E delta (c^2 - b^2) / (2 b c^2 (1 - nu^2)). Returns ``pressure`` (p,
    on the bore), ``shaft_pressure`` (p_s), ``u_hub``, ``u_shaft`` (radial displacements at
    the fit) and ``hoop_bore`` (the hub's hoop stress at its bore, p (c^2 + b^2) / (c^2 -
    b^2)); the hub's hoop stress at radius r is p b^2 (1 + c^2 / r^2) / (c^2 - b^2)."""
    (Es, nus), (Eh, nuh) = shaft, hub
    hub_per_p = b * (1 + nuh) * ((1 - 2 * nuh) * b * b + c * c) / (Eh * (c * c - b * b))
    shaft_per_p = b * (1 + nus) * (1 - 2 * nus) / Es
    p = delta / (hub_per_p + shaft_per_p)
    return {"pressure": p, "shaft_pressure": p * b / (b + delta), "u_hub": p * hub_per_p,
            "u_shaft": -p * shaft_per_p, "hoop_bore": p * (c * c + b * b) / (c * c - b * b)}


def lame(p: PressFitParameters) -> float:
    """Lame's contact pressure of the fit, plane strain, one material (:func:`lame_fit`)."""
    material = (p.youngs_modulus, p.poissons_ratio)
    return lame_fit(p.bore_radius, p.hub_radius, p.interference, material, material)["pressure"]


def push_out_force(p: PressFitParameters) -> float:
    """The force that slides the whole shaft in the hub (every node slipping): mu times
    Lame's pressure times the contact area, 2 pi b L mu p (the whole fit)."""
    return p.friction * lame(p) * 2.0 * math.pi * p.bore_radius * p.length


def validate(p: PressFitParameters) -> None:
    """Raise :class:`~vfem.errors.InputError` if the parameters make no valid model."""
    for name in ("bore_radius", "hub_radius", "length", "interference"):
        value = getattr(p, name)
        if not (isinstance(value, (int, float)) and 0 < value < math.inf):
            raise InputError(f"press_fit: {name} must be a finite number > 0, got {value!r}")
    if not p.bore_radius < p.hub_radius:
        raise InputError(f"press_fit: hub_radius must exceed bore_radius, got {p.hub_radius} "
                         f"and {p.bore_radius}")
    if not (isinstance(p.around, int) and p.around >= 2 and p.around % 2 == 0):
        raise InputError(f"press_fit: around must be an even number >= 2, got {p.around!r}")
    for name in ("friction", "push"):
        value = getattr(p, name)
        if not (isinstance(value, (int, float)) and 0 <= value < math.inf):
            raise InputError(f"press_fit: {name} must be a finite number >= 0, got {value!r}")
    if not (isinstance(p.push_steps, int) and p.push_steps >= 1):
        raise InputError(f"press_fit: push_steps must be at least 1, got {p.push_steps!r}")
    for name in ("hub_cells", "shaft_cells"):
        if getattr(p, name) not in ("hex", "tet"):
            raise InputError(f"press_fit: {name} must be 'hex' or 'tet', got "
                             f"{getattr(p, name)!r}")
    build(p).validate()


def config(p: PressFitParameters | None = None) -> ModelConfig:
    """The model as data (what ``examples/press_fit.toml`` holds for the defaults)."""
    p = p or PressFitParameters()
    b, c, L = p.bore_radius, p.hub_radius, p.length
    rollers = (Support("left", ("x",)), Support("front", ("y",)))
    hub = BodyConfig(
        name="hub",
        mesh=MeshSpec(shape="ring", parameters=as_parameters(
            inner_radius=b, outer_radius=c, height=L, around=p.around, radial=p.radial,
            layers=p.layers, tetrahedra=p.hub_cells == "tet")),
        material=LinearElastic(p.youngs_modulus, p.poissons_ratio),
        supports=(Support("bottom", ("z",)), Support("top", ("z",)), *rollers),
        contact_boundaries=("inner",),
    )
    radius = b + p.interference
    across = max(1, p.around // 2)
    if p.push > 0:  # the fit at load factor 0.5, then the push on a load curve
        curve = ((0.0, 0.0), (0.5, 0.0), (1.0, 1.0))
        ends = {"prescribed": tuple(PrescribedDisplacement(face, "z", p.push, curve)
                                    for face in ("contact", "top"))}
        steps = Steps(load_factors=(0.5, *(0.5 + 0.5 * (k + 1) / p.push_steps
                                          for k in range(p.push_steps))))
    else:
        ends = {"supports": (Support("contact", ("z",)), Support("top", ("z",)))}
        steps = Steps(count=1)
    shaft = BodyConfig(
        name="shaft",
        mesh=MeshSpec(shape="cylinder", parameters=as_parameters(
            radius=radius, height=L, h=radius / across * (1 + 1e-9),
            tetrahedra=p.shaft_cells == "tet")),
        material=LinearElastic(p.youngs_modulus, p.poissons_ratio),
        supports=(*ends.get("supports", ()), *rollers),
        prescribed=ends.get("prescribed", ()),
        contact_boundaries=("side",),
    )
    bodies = (hub, shaft) if p.swap_bodies else (shaft, hub)
    return ModelConfig("press_fit", bodies, ContactSettings(friction=p.friction), steps)


def build(p: PressFitParameters | None = None) -> Model:
    return config(p).build()


def evaluate(result: AnalysisResult, p: PressFitParameters) -> dict:
    """Each body's nodal contact pressure on its contact surface against Lame's: the largest
    and mean relative error, and the radial force against p times the quarter's area."""
    target = lame(p)
    fit = next((s for s in result.steps if s.load_factor == 0.5), result.steps[-1])
    last = fit if p.push > 0 else result.steps[-1]
    out = {"lame_pressure": target,
           "radial_force_theory": target * 0.5 * math.pi * p.bore_radius * p.length}
    for name, boundary in (("hub", "inner"), ("shaft", "side")):
        body = next(b for b in result.model.bodies if b.name == name)
        r = last.bodies[name]
        nodes = np.unique(body.mesh.facets[:, body.mesh.boundaries[boundary]])
        x = body.mesh.p[:, nodes]
        radial = x[:2] / np.hypot(*x[:2])
        rel = r.contact_pressure[nodes] / target - 1
        out[name] = {
            "largest_error": float(np.abs(rel).max()),
            "worst_pressure": float(r.contact_pressure[nodes][np.argmax(np.abs(rel))]),
            "mean_error": float(rel.mean()),
            "nodes": int(len(nodes)),
            "nodes_in_contact": int((r.contact_status[nodes] > 0).sum()),
            # the force the other body puts on it, outwards (the hub) or inwards (the shaft),
            # resolved on the 45-degree diagonal of the quarter: p b L (the quarter's)
            "radial_force": float(np.abs(np.einsum("ij,ij->j", r.contact_force[nodes, :2].T,
                                                   radial)).sum()),
        }
    f_shaft = last.bodies["shaft"].contact_force.sum(axis=0)
    f_hub = last.bodies["hub"].contact_force.sum(axis=0)
    # the two bodies' resultants on the quarter, equal and opposite
    out["force_balance"] = float(np.abs(f_shaft + f_hub).max() / np.abs(f_hub).max())
    # invariant (a)'s reading of it: |the sum| and the larger body's |total| (the quarter's)
    out["contact_force_sum"] = float(np.linalg.norm(f_shaft + f_hub))
    out["largest_body_contact_force"] = float(max(np.linalg.norm(f_shaft), np.linalg.norm(f_hub)))
    if p.push > 0:  # the axial force the hub puts on the shaft, step by step (the whole fit)
        out["push"] = [{"load_factor": s.load_factor,
                        "axial_force": float(-4.0 * s.bodies["shaft"].contact_force[:, 2].sum()),
                        "slipping_nodes": int((s.bodies["shaft"].friction_status == 2).sum())
                        if s.bodies["shaft"].friction_status is not None else 0}
                       for s in result.steps if s.load_factor > 0.5]
        out["push_out_force_theory"] = push_out_force(p)
    return out


def summarize(result: AnalysisResult, p: PressFitParameters) -> dict:
    """The ``summary.json`` dictionary of a press fit run: :func:`~vfem.io.results.
    example_summary` with the bodies' sizes and ``lame``."""
    from vfem.io.results import solid_summary

    summary = solid_summary("press_fit", result, p, "lame", evaluate)
    if result.converged and "lame" in summary:
        summary["verification"] = verification(summary["lame"], p)
    return summary


#: Lame's thick cylinders in plane strain (the module docstring; docs/examples.md derives it)
LAME = "Lamé"


def verification(m: dict, p: PressFitParameters) -> list[dict]:
    """The press fit's checks (``summary.json``'s ``verification``;
    :mod:`vfem.io.verification`): the worst node's pressure of each body against Lame's (the
    shaft's nominal pressure, on its undeformed surface of radius b + delta, is Lame's times
    b / (b + delta): the same force on a larger area); the radial force on the hub's quarter
    against Lame's pressure on the bore's area, p (pi / 2) b L; the two bodies' resultants,
    equal and opposite (invariant (a), :func:`vfem.io.verification.balance`); with a push and
    friction, the axial force against 2 pi b L mu p. The pressures' tolerance:
    :data:`PRESSURE_TOLERANCE` (the discretisation)."""
    from vfem.io.verification import balance, check

    p_lame = m["lame_pressure"]
    b, delta = p.bore_radius, p.interference
    basis = ("discretisation: the hub's nodes within 0.27 % at the default mesh, the mean error "
             "falling as the square of the wall's element size (docs/examples.md, Press fit)")
    records = [
        check("hub's nodal pressure, worst node", m["hub"]["worst_pressure"], p_lame, LAME,
              PRESSURE_TOLERANCE, basis),
        check("shaft's nodal pressure, worst node", m["shaft"]["worst_pressure"],
              p_lame * b / (b + delta), "Lamé, on the shaft's radius b + delta",
              PRESSURE_TOLERANCE, basis),
        check("radial force on the hub's quarter", m["hub"]["radial_force"],
              m["radial_force_theory"], "Lamé's p on the bore, p (pi/2) b L", PRESSURE_TOLERANCE,
              basis),
        balance("contact forces' sum, |shaft + hub| (the quarter's)", m["contact_force_sum"],
                0.0, "equal and opposite", scale=m["largest_body_contact_force"]),
    ]
    if m.get("push") and p.friction > 0:
        records.append(check(
            "push-out axial force", m["push"][-1]["axial_force"], m["push_out_force_theory"],
            "2 pi b L mu p (Lamé's p)", PRESSURE_TOLERANCE,
            "the fit's pressure's discretisation (as the pressures'): every node slipping "
            "carries mu times it"))
    return records


def run(p: PressFitParameters, out, on_step=None, figures: bool = True,
        resume: bool = False) -> dict:
    """Run the example, writing VTU/PVD per step, ``summary.json`` and the figures to ``out``."""
    from vfem.io.results import run_example

    return run_example(build(p), out, lambda r: summarize(r, p), figures, on_step, resume)


def figures(folder) -> list[Path]:
    """``pressure.png``: both bodies' nodal contact pressure over Lame's against the angle
    around the axis, every layer of nodes, at the fit (before a push)."""
    from vfem.io import plots

    s = folder.summary
    if not folder.has_steps or "lame" not in s:
        return []
    target = s["lame"]["lame_pressure"]
    # the fit (with a push, the step at load factor 0.5: the evaluation's, before any slip)
    fit = next((st for st in folder.steps
                if s["parameters"].get("push", 0) > 0 and st.load_factor == 0.5),
               folder.steps[-1])
    last = fit
    curves = []
    for frame in last.bodies:
        c = folder.contact(last, frame)
        angle = np.degrees(np.arctan2(c.x[:, 1], c.x[:, 0]))
        order = np.argsort(angle)
        curves.append((f"{frame.name} (nodal force / undeformed area)", angle[order],
                       c.pressure[order] / target, np.array([0.0, 90.0]), np.ones(2)))
    out = folder.directory
    plots.profiles(out / "pressure.png", curves, "angle around the axis (degrees)",
                   "p / p_Lame (contact pressure over Lame's)",
                   f"Press fit, {s['dofs']} dofs: interference "
                   f"{s['parameters']['interference']:g} on radius "
                   f"{s['parameters']['bore_radius']:g}\nline: Lame (plane strain)")
    return [out / "pressure.png"]


def report(s: dict) -> list[str]:
    """The closing lines of a press fit run."""
    lines = [run_headline(s, contact_dofs=True)]
    if "lame" in s:
        m = s["lame"]
        lines.append(f"  Lame's pressure {m['lame_pressure']:.6g}: the hub's nodes within "
                     f"{m['hub']['largest_error']:.2%} (mean {m['hub']['mean_error']:+.2%}), "
                     f"the shaft's within {m['shaft']['largest_error']:.2%} "
                     f"(mean {m['shaft']['mean_error']:+.2%})")
        if m.get("push"):
            last, theory = m["push"][-1], m["push_out_force_theory"]
            lines.append(f"  push-out: axial force {last['axial_force']:.6g} with "
                         f"{last['slipping_nodes']} nodes slipping (2 pi b L mu p = "
                         f"{theory:.6g}, {last['axial_force'] / theory - 1:+.2%})")
    return lines
