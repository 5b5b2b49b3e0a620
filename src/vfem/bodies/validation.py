"""Whether a body can be analysed: its definition checked (:func:`validate`) and its supports
holding every rigid-body motion (:func:`check_supported`), each refusal one message naming the
body and what is wrong."""

from __future__ import annotations

import math

import numpy as np
from skfem import MeshHex, MeshQuad, MeshTet, MeshTri

from ..errors import InputError
from ..materials import LAWS
from ..mesh.checks import check_mesh
from .discretisation import COMPONENTS, MESHES
from .loads import _shown, check_amplitude, constraints
from .section import SECTIONS, SOLID, check_plane, section_of


def _named_first(null: np.ndarray) -> np.ndarray:
    """The rows of ``null`` (an orthonormal basis of free rigid-body motions, as coefficients
    of the named modes) rewritten as the named modes that are free by themselves (unit rows),
    then an orthonormal basis of the rest: a roller-supported box is free to "translate in x"
    and "rotate about z", not in combinations of them."""
    n = null.shape[1]
    pure = [i for i in range(n) if np.linalg.norm(null[:, i]) > 1 - 1e-8]
    named = np.eye(n)[pure]
    if len(pure) == len(null):
        return named
    rest = null - (null @ named.T) @ named  # the part orthogonal to the named modes
    _, _, vt = np.linalg.svd(rest)
    return np.vstack([named, vt[: len(null) - len(pure)]])


def check_subdomains(body, where: str) -> None:
    """``subdomains``: an integer >= 1, at most the elements; above 1 a linear body only (the
    split solve stands in for the factorization of a constant stiffness, issue 43)."""
    k = body.subdomains
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise InputError(f"{where}: subdomains must be a whole number >= 1 (1: not split), "
                         f"got {k!r}")
    if k > 1 and body.iterates:
        why = (f"large kinematics ({body.kinematics!r})" if body.large
               else "a plastic material")
        raise InputError(f"{where}: only a linear body can be split into subdomains (small "
                         f"kinematics, elastic); this one has {why}: set subdomains = 1, "
                         f"not {k}")
    if k > body.mesh.nelements:
        raise InputError(f"{where}: more subdomains ({k}) than elements "
                         f"({body.mesh.nelements})")


def validate(body) -> None:
    """Raise :class:`InputError` naming the body if its definition cannot be analysed."""
    where = f"body {body.name!r}"
    if not isinstance(body.mesh, (MeshTri, MeshQuad, MeshTet, MeshHex)) or (
            type(body.mesh).__name__ not in MESHES):
        raise InputError(f"{where}: mesh must be triangles or quadrilaterals (2D), "
                         f"tetrahedra or hexahedra (3D), got {type(body.mesh).__name__}")
    # validate runs before every use of the body; the mesh is checked once
    if getattr(body, "_checked_mesh", None) is not body.mesh:
        check_mesh(body.mesh, where)
        body._checked_mesh = body.mesh
    if body.order not in (1, 2):
        raise InputError(f"{where}: order must be 1 (linear) or 2 (quadratic elements), "
                         f"got {body.order!r}")
    body.material.validate(f"{where}, material")
    check_plane(body.material.plane, f"{where}, material")
    if body.kinematics not in ("small", "total", "updated"):
        raise InputError(f"{where}: kinematics must be 'small', 'total' or 'updated', "
                         f"got {body.kinematics!r}")
    if not isinstance(body.self_contact, bool):
        raise InputError(f"{where}: self_contact must be true or false, got "
                         f"{body.self_contact!r}")
    if body.law not in LAWS:
        names = " or ".join(repr(name) for name in LAWS)
        raise InputError(f"{where}: law must be {names}, got {body.law!r}")
    check_subdomains(body, where)
    section = section_of(body)  # refuses a plane given to a 3D body
    if body.large and (body.order != 1 or not section.takes_large):
        taken = [s.name for s in SECTIONS.values() if s.takes_large]
        raise InputError(f"{where}: large kinematics ({body.kinematics!r}) needs linear "
                         "elements (order 1)"
                         + ("" if section is SOLID else f" and {' or '.join(taken)}"))
    if section.name == "axisymmetric":
        check_axisymmetric(body, where)
    names = set((body.mesh.boundaries or {}).keys())
    for bc in (*body.supports, *body.prescribed, *body.tractions,
               *((body.platen,) if body.platen else ()), *(body.contact_boundaries or ())):
        name = bc if isinstance(bc, str) else bc.boundary
        if name not in names:
            raise InputError(f"{where}: no boundary named {name!r}; the mesh has "
                             f"{', '.join(sorted(names)) or 'no named boundaries'}")
        if len(body.mesh.boundaries[name]) == 0:
            raise InputError(f"{where}: boundary {name!r} holds no facet of the mesh's "
                             "outline; check how it is defined (a shape's parameters, or "
                             "the mesh file's group)")
    comps = [("support", s.boundary, c) for s in body.supports
             for c in body.support_components(s)]
    comps += [("prescribed displacement", pd.boundary, pd.component)
              for pd in body.prescribed]
    comps += [("platen", body.platen.boundary, body.platen.component)] if body.platen else []
    allowed = body.components
    for kind, boundary, c in comps:
        if c not in allowed:
            names = " or ".join((", ".join(repr(a) for a in allowed[:-1]),
                                 repr(allowed[-1])))
            raise InputError(f"{where}: {kind} on {boundary!r}: component must be {names}"
                             + ("" if c not in COMPONENTS else
                                f" (the body's mesh is {body.dim}D)") + f", got {c!r}")
    for tr in body.tractions:
        if tr.pressure is not None:
            if len(tr.value):
                raise InputError(f"{where}: traction on {tr.boundary!r}: give value (a "
                                 "traction) or pressure, not both")
            if isinstance(tr.pressure, bool) or not isinstance(tr.pressure, (int, float)) \
                    or not math.isfinite(tr.pressure):
                raise InputError(f"{where}: traction on {tr.boundary!r}: pressure must be a "
                                 f"finite number, got {_shown(tr.pressure)}")
            continue
        if not isinstance(tr.value, (tuple, list)) or len(tr.value) != body.dim:
            raise InputError(
                f"{where}: traction on {tr.boundary!r}: value must have {body.dim} "
                f"components ({', '.join('t' + a for a in allowed)}) on a {body.dim}D "
                f"body, got {_shown(tr.value)}"
                + (" (or give pressure: a pressure along the boundary's normal)"
                   if not len(tr.value) else ""))
    for kind, loads in (("prescribed displacement", body.prescribed),
                        ("traction", body.tractions),
                        ("platen", (body.platen,) if body.platen else ())):
        for load in loads:
            if load.amplitude is not None:
                check_amplitude(load.amplitude, f"{where}: {kind} on {load.boundary!r}")
    values = [pd.value for pd in body.prescribed] + [v for t in body.tractions for v in t.value]
    values += [body.platen.force] if body.platen else []
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
        raise InputError(f"{where}: loads and prescribed displacements must be finite numbers")


def check_supports(body) -> None:
    """Without assembling anything: raise :class:`InputError` if the body is invalid or
    its supports leave it free to move as a rigid body (``vfem check``)."""
    validate(body)
    constraints(body)
    check_supported(body)


def check_axisymmetric(body, where: str) -> None:
    """What a body of revolution needs (issue 42): its mesh in the r-z half-plane (x = r >= 0,
    to round-off of its size)."""
    x = body.mesh.p[0]
    span = float(np.ptp(body.mesh.p, axis=1).max()) if x.size else 0.0
    if x.size and x.min() < -1e-12 * span:
        node = int(np.argmin(x))
        raise InputError(f"{where}: an axisymmetric body's mesh lies in the r-z half-plane, "
                         f"x = r >= 0 (the axis is x = 0), but node {node} is at x = "
                         f"{x[node]:.6g}")


def rigid_modes(body) -> dict[str, np.ndarray]:
    """The body's rigid-body motions by name, each (npoints, dim): its section's
    (:meth:`~vfem.bodies.section.Section.rigid_modes`): in 2D the translations in x and y
    and the rotation; in 3D the translations in x, y and z and the rotations about the axes
    x, y and z through the points' centroid."""
    return body.section.rigid_modes(body.points)


def check_supported(body) -> None:
    """Refuse a body that can move as a rigid body: its stiffness would be singular. The
    message names the free motions (2D: the translations in x and y, the rotation; 3D:
    the translations in x, y and z, the rotations about x, y and z)."""
    modes = rigid_modes(body)
    R = np.column_stack([m.ravel() for m in modes.values()])  # interleaved dofs
    Rc = R[body.fixed_dofs]
    names = list(modes)
    n = len(names)
    # (rows of zeros up to n: vt is then n x n without the full, fixed dofs squared, U)
    A = Rc if len(Rc) >= n else np.vstack([Rc, np.zeros((n - len(Rc), n))])
    _, sv, vt = np.linalg.svd(A, full_matrices=False)
    tol = 1e-10 * max(1.0, float(np.abs(R).max())) * max(1, len(Rc))
    rank = int((sv > tol).sum())
    if rank < n:
        null = vt[rank:]  # the free motions' coefficients, an orthonormal basis
        if body.dim == 3:
            null = _named_first(null)
        free = []
        for v in null:
            parts = [names[i] for i in np.flatnonzero(np.abs(v) > 1e-6 * np.abs(v).max())]
            free.append(parts[0] if len(parts) == 1
                        else "a combination of " + " and ".join(parts))
        raise InputError(
            f"body {body.name!r} is not supported: it can move freely as a rigid body "
            f"({'; '.join(free)}), so its stiffness is singular; add supports or a platen"
        )
