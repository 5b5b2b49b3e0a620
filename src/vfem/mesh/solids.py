"""Parametric 3D meshes (issue 21): numpy and scikit-fem only, no mesher.

:func:`box` is the 3D :func:`~vfem.mesh.shapes.rectangle` and :func:`~vfem.mesh.shapes.block`:
a tensor grid of hexahedra (or of tetrahedra, six to a hexahedron), uniform or graded towards
given planes. The axes follow the 2D shapes with z up: ``left``/``right`` are the faces
x = const, ``front``/``back`` the faces y = const (front: the smaller y, the side a viewer
looking along +y sees), ``bottom``/``top`` the faces z = const. Each mesh comes with
scikit-fem's facet topology already built (:mod:`vfem.mesh.topology`). One 2D shape lives here
too: :func:`cylinder_section`, the r-z section of :func:`cylinder` (a body of revolution meshed
as the 3D cylinder is, node for node in its plane y = 0).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from skfem import MeshHex, MeshQuad, MeshTet

from .parametric import check_count
from .shapes import _counter_clockwise, _grid_line, disk_map
from .topology import named_boundaries, share_topology, with_topology

__all__ = ["box", "cylinder", "cylinder_section", "ring", "FACES"]

#: The named faces of :func:`box`: name -> (axis, end) (end 0: the face at the smaller
#: coordinate).
FACES = {"left": (0, 0), "right": (0, 1), "front": (1, 0), "back": (1, 1),
         "bottom": (2, 0), "top": (2, 1)}


def box(x0: float = 0.0, y0: float = 0.0, z0: float = 0.0, width: float = 1.0,
        depth: float = 1.0, height: float = 1.0, nx: int = 1, ny: int = 1, nz: int = 1, *,
        h: float | None = None, h_fine: float | None = None, growth: float = 0.2,
        fine_x: Sequence[float] = (), fine_y: Sequence[float] = (),
        fine_z: Sequence[float] = (), plateau: float = 0.0,
        tetrahedra: bool = False) -> MeshHex | MeshTet:
    """The box ``[x0, x0 + width] x [y0, y0 + depth] x [z0, z0 + height]`` as a tensor grid of
    hexahedra (trilinear, scikit-fem's ``MeshHex``), or with ``tetrahedra`` each hexahedron
    split into six tetrahedra around its diagonal from its lowest to its highest corner (Kuhn's
    split: the neighbours' face diagonals agree, so the mesh is conforming).

    Divisions: ``nx`` x ``ny`` x ``nz`` equal ones; or, given ``h``, spacing at most ``h``; or,
    given ``h`` and ``h_fine``, graded: the spacing along x is ``h_fine`` at the planes
    x = ``fine_x`` (for instance under a punch's edge) and grows with ``growth`` per unit
    distance up to ``h``; likewise along y towards ``fine_y`` and along z towards ``fine_z``
    (an axis without fine planes is uniform); within ``plateau`` of those planes the spacing
    stays ``h_fine`` (a contact zone of even elements). Planes of ``fine_*`` inside the box are
    grid planes.

    Named boundaries: ``left`` (x = x0), ``right`` (x = x0 + width), ``front`` (y = y0),
    ``back`` (y = y0 + depth), ``bottom`` (z = z0) and ``top`` (z = z0 + height).
    """
    if not (width > 0 and depth > 0 and height > 0):
        raise ValueError(f"width, depth and height must be positive, got {width}, {depth}, "
                         f"{height}")
    x1, y1, z1 = x0 + width, y0 + depth, z0 + height
    if h is None:
        if not all(isinstance(n, (int, np.integer)) and n >= 1 for n in (nx, ny, nz)):
            raise ValueError(f"nx, ny and nz must be whole numbers >= 1, got {nx}, {ny}, {nz}")
        check_count((nx + 1.0) * (ny + 1.0) * (nz + 1.0), "box")
        lines = [np.linspace(a, b, int(n) + 1) for a, b, n in ((x0, x1, nx), (y0, y1, ny),
                                                                (z0, z1, nz))]
    else:
        for size in (width, depth, height):  # the count first: no line of a billion nodes
            check_count(size / h if h > 0 else float("inf"), "the element size h")
        lines = [_grid_line(a, b, h, h_fine, growth, fine, plateau)
                 for a, b, fine in ((x0, x1, fine_x), (y0, y1, fine_y), (z0, z1, fine_z))]
    check_count(float(np.prod([len(v) for v in lines], dtype=float)), "box")
    mesh = (MeshTet if tetrahedra else MeshHex).init_tensor(*lines)
    tol = 1e-9 * max(width, depth, height)
    ends = ((x0, x1), (y0, y1), (z0, z1))

    def face(axis: int, end: int):
        at = ends[axis][end]
        return lambda p: np.abs(p[axis] - at) < tol

    return named_boundaries(mesh, {name: face(axis, end) for name, (axis, end) in FACES.items()})


def cylinder(radius: float = 1.0, height: float = 1.0, *, end_radius: float | None = None,
             x0: float = 0.0, y0: float = 0.0, z0: float = 0.0, quarter: bool = True,
             half: bool = False, h_contact: float | None = None, h: float | None = None,
             growth: float = 0.2, plateau: float = 0.0, blend_from: float = 0.5,
             circle_from: float = 1.0, graded_end: str = "bottom",
             rings: Sequence[float] = (), grade_axis: bool = True,
             tetrahedra: bool = False) -> MeshHex | MeshTet:
    """A cylinder of ``radius`` about the vertical axis through (``x0``, ``y0``), its lower end
    at ``z0`` on the axis and its top face the plane ``z = z0 + height``: flat-ended (a
    circular punch), or with ``end_radius`` its lower end a spherical cap of that radius
    touching ``z = z0`` at the axis (a sphere's contact region: Hertz's indenter). With
    ``quarter`` only the part ``x >= x0, y >= y0`` (a quarter model with two symmetry planes);
    with ``half`` (and ``quarter = False``) the part ``y >= y0`` (a half model with one symmetry
    plane: a load along x breaks the symmetry about x = x0).

    The mesh is a tensor grid of hexahedra (or of six tetrahedra each, as :func:`box`) mapped
    onto the cylinder, graded towards the axis and the end: the spacing is ``h_contact`` within
    ``plateau`` of the axis (across) and of the end (up), growing by ``growth`` per unit
    distance beyond, up to ``h``; without
    ``h_contact`` it is ``h`` everywhere. In plan the grid's square rings stay squares inside
    ``blend_from`` times the radius (the contact zone keeps a straight, regular grid) and turn
    smoothly into the circle beyond; every column is then stretched vertically from the end
    surface to the top plane, so the nodes of ``contact`` lie on the sphere (or the plane).
    With ``circle_from`` below 1 the rings are circles already from that fraction of the
    radius on (``blend_from`` at most 0.58 of it): a block under a circular punch of radius
    ``circle_from * radius`` then has a grid circle under the punch's rim, with nodes at the
    punch's rim nodes' angles where both grids are even there (``rings``: radii made grid
    rings, the grid graded in plan towards them as towards the axis; with ``grade_axis``
    False towards the rings only, the axis' spacing then what the grading from the rings
    reaches: a punch's or a block's grid graded towards the punch's rim, where the traction
    is singular). ``graded_end = "top"`` grades the layers towards the top face instead (a
    block whose top is the contact); on a flat end the layers are graded alike at every
    radius.

    Named boundaries: ``contact`` (the lower end), ``top``, ``side`` (the cylinder's mantle)
    and, with ``quarter``, ``left`` (x = x0) and ``front`` (y = y0), as on :func:`box`; with
    ``half``, ``front`` (y = y0).
    """
    R = float(radius)
    if half and quarter:
        raise ValueError("half models the part y >= y0 and quarter the part x >= x0, y >= y0: "
                         "give quarter = False with half")
    across, up = _cylinder_lines(R, height, end_radius, 0.0 if quarter else -R, h_contact, h,
                                 growth, plateau, blend_from, circle_from, graded_end, rings,
                                 grade_axis)
    along = (_cylinder_lines(R, height, end_radius, 0.0, h_contact, h, growth, plateau,
                             blend_from, circle_from, graded_end, rings, grade_axis)[0]
             if half else across)
    check_count(float(len(across)) * len(along) * len(up), "cylinder")
    mesh = (MeshTet if tetrahedra else MeshHex).init_tensor(across, along, up / height)
    # names on the reference grid (u, v in [-1, 1] or [0, 1], w in [0, 1]), kept by the map
    tol = 1e-9
    ring = lambda p: np.maximum(np.abs(p[0]), np.abs(p[1]))  # noqa: E731
    tests = {"contact": lambda p: p[2] < tol, "top": lambda p: p[2] > 1 - tol,
             "side": lambda p: ring(p) > 1 - tol}
    if quarter:
        tests.update(left=lambda p: p[0] < tol, front=lambda p: p[1] < tol)
    elif half:
        tests.update(front=lambda p: p[1] < tol)
    mesh = named_boundaries(mesh, tests)
    u, v, w = mesh.p
    x, y = disk_map(u, v, R, blend_from, circle_from)
    z = _column_heights(np.hypot(x, y), w, up, R, height, end_radius, blend_from)
    p = np.vstack([x + x0, y + y0, z + z0])
    return share_topology(mesh, replace(mesh, doflocs=p))


def _cylinder_lines(R: float, height: float, end_radius: float | None, start: float,
                    h_contact: float | None, h: float | None, growth: float, plateau: float,
                    blend_from: float, circle_from: float, graded_end: str,
                    rings: Sequence[float], grade_axis: bool) -> tuple[np.ndarray, np.ndarray]:
    """The grid lines of :func:`cylinder` (and :func:`cylinder_section`), the parameters
    checked: across the plan from ``start`` (-R, or 0 for a quarter) to R, over R, graded
    towards the axis and the ``rings``; and the layers' heights from 0 to ``height``, graded
    towards the ``graded_end``."""
    if not (R > 0 and height > 0):
        raise ValueError(f"radius and height must be positive, got {R}, {height}")
    if end_radius is not None:
        if not end_radius > 0:
            raise ValueError(f"end_radius must be positive, got {end_radius}")
        if not end_radius - np.sqrt(max(end_radius ** 2 - R ** 2, 0.0)) < height \
                or not R < end_radius:
            raise ValueError(f"a spherical end of radius {end_radius:g} on a cylinder of radius "
                             f"{R:g} needs end_radius > radius and a height above "
                             f"{end_radius - np.sqrt(max(end_radius ** 2 - R ** 2, 0.0)):.6g} "
                             f"(the cap's rise), got {height:g}")
    if not 0.0 < circle_from <= 1.0:
        raise ValueError(f"circle_from must lie in (0, 1], got {circle_from}")
    if not 0.0 < blend_from <= 0.58 * circle_from:
        raise ValueError(f"blend_from must lie between 0 and 0.58 circle_from, got {blend_from}"
                         f" (circle_from {circle_from})")
    if graded_end not in ("bottom", "top"):
        raise ValueError(f"graded_end must be 'bottom' or 'top', got {graded_end!r}")
    if h is None:
        raise ValueError("give the element size h (and h_contact to grade the mesh)")
    if not (grade_axis or len(rings)):
        raise ValueError("grade_axis = False grades towards the rings only: give rings")
    fine = (((0.0,) if grade_axis else ()) + tuple(float(r) for r in rings)
            + tuple(-float(r) for r in rings)) if h_contact is not None else ()
    across = _grid_line(start, R, h, h_contact, growth, fine, plateau) / R
    # the layers graded towards the end only (the rings are radii, not heights)
    up = _grid_line(0.0, height, h, h_contact, growth, (0.0,) if h_contact is not None else (),
                    plateau)
    if graded_end == "top":
        up = height - up[::-1]
    return across, up


def _column_heights(rr: np.ndarray, w: np.ndarray, up: np.ndarray, R: float, height: float,
                    end_radius: float | None, blend_from: float) -> np.ndarray:
    """The heights above the end's lowest point of :func:`cylinder`'s nodes at plan radius
    ``rr`` on the reference layer ``w`` (one of ``up / height``): each column stretched from
    the end surface to the top plane."""
    bottom = (0.0 if end_radius is None
              else end_radius - np.sqrt(np.maximum(end_radius ** 2 - rr ** 2, 0.0)))
    # the layers: graded up from the end near the axis, turning into equal layers towards
    # the rim (where graded ones would make slabs thinner than the end's rise across them)
    layer = np.searchsorted(up / height, w - 1e-9)
    equal = layer / (len(up) - 1.0)
    gamma = (np.clip((rr / R - blend_from) / (1.0 - blend_from), 0.0, 1.0)
             if end_radius is not None else np.zeros_like(rr))
    return bottom + ((1.0 - gamma) * w + gamma * equal) * (height - bottom)


def cylinder_section(radius: float = 1.0, height: float = 1.0, *,
                     end_radius: float | None = None, x0: float = 0.0, y0: float = 0.0,
                     h_contact: float | None = None, h: float | None = None,
                     growth: float = 0.2, plateau: float = 0.0, blend_from: float = 0.5,
                     graded_end: str = "bottom", rings: Sequence[float] = (),
                     grade_axis: bool = True) -> MeshQuad:
    """The r-z section of :func:`cylinder` (2D, for ``plane = "axisymmetric"``): the cylinder's
    quarter model cut by its plane y = y0, node for node, with r along x from the axis
    x = ``x0`` and the axis along y, its end's lowest point at (``x0``, ``y0``). The same
    parameters make the same grid: the spacing ``h_contact`` within ``plateau`` of the axis
    (across) and of the end (up), growing by ``growth`` per unit distance beyond, up to ``h``
    (``rings``, ``grade_axis`` and ``graded_end`` as there); each column stretched from the
    end (the arc of radius ``end_radius`` touching y = y0 at the axis, or flat) to the top,
    its layers turning from graded to equal beyond ``blend_from`` times the radius. A body of
    revolution so meshed has the 3D cylinder's elements in its symmetry planes (where the 3D
    grid's plan is square, near the axis, the r-z one has no counterpart off those planes).

    Named boundaries: ``contact`` (the end), ``top``, ``side`` (x = x0 + radius) and ``left``
    (x = x0, the axis), as the 3D cylinder's boundaries cut by the plane.
    """
    R = float(radius)
    across, up = _cylinder_lines(R, height, end_radius, 0.0, h_contact, h, growth, plateau,
                                 blend_from, 1.0, graded_end, rings, grade_axis)
    check_count(float(len(across)) * len(up), "cylinder_section")
    grid = MeshQuad.init_tensor(across, up / height)
    t = _counter_clockwise(grid.p, grid.t)  # init_tensor's quadrilaterals are clockwise
    tol = 1e-9
    mesh = named_boundaries(MeshQuad(grid.p, t), {
        "contact": lambda p: p[1] < tol, "top": lambda p: p[1] > 1 - tol,
        "side": lambda p: p[0] > 1 - tol, "left": lambda p: p[0] < tol})
    u, w = mesh.p
    # the plane y = 0 of the cylinder's plan (disk_map) is its line x = R u: r = R u
    y = _column_heights(R * u, w, up, R, height, end_radius, blend_from)
    return share_topology(mesh, replace(mesh, doflocs=np.vstack([x0 + R * u, y0 + y])))


def ring(inner_radius: float = 1.0, outer_radius: float = 2.0, height: float = 1.0, *,
         x0: float = 0.0, y0: float = 0.0, z0: float = 0.0, quarter: bool = True,
         around: int = 16, radial: int = 4, layers: int = 2,
         tetrahedra: bool = False) -> MeshHex | MeshTet:
    """A thick-walled tube (a hub, a bearing ring) about the vertical axis through (``x0``,
    ``y0``): inner and outer radius, from ``z0`` up to ``z0 + height``; with ``quarter`` only
    the part ``x >= x0, y >= y0``. A polar grid of hexahedra (or of six tetrahedra each, as
    :func:`box`): ``around`` divisions per quarter turn, ``radial`` through the wall,
    ``layers`` along the axis; nodes of ``inner`` and ``outer`` lie on their circles.

    Named boundaries: ``inner``, ``outer``, ``bottom``, ``top`` and, with ``quarter``, ``left``
    (x = x0) and ``front`` (y = y0), as on :func:`box`.
    """
    if not (0 < inner_radius < outer_radius and height > 0):
        raise ValueError(f"need 0 < inner_radius < outer_radius and height > 0, got "
                         f"{inner_radius}, {outer_radius}, {height}")
    for name, n in (("around", around), ("radial", radial), ("layers", layers)):
        if not (isinstance(n, (int, np.integer)) and n >= 1):
            raise ValueError(f"{name} must be a whole number >= 1, got {n}")
    turns = 1 if quarter else 4
    check_count((around * turns + 1.0) * (radial + 1.0) * (layers + 1.0), "ring")
    r = np.linspace(inner_radius, outer_radius, radial + 1)
    theta = np.linspace(0.0, 0.5 * np.pi * turns, around * turns + 1)
    z = np.linspace(0.0, 1.0, layers + 1)
    mesh = (MeshTet if tetrahedra else MeshHex).init_tensor(r, theta, z)
    tol = 1e-9
    tests = {"inner": lambda p: p[0] < inner_radius + tol * outer_radius,
             "outer": lambda p: p[0] > outer_radius - tol * outer_radius,
             "bottom": lambda p: p[2] < tol, "top": lambda p: p[2] > 1 - tol}
    if quarter:
        tests.update(left=lambda p: p[1] > 0.5 * np.pi - tol, front=lambda p: p[1] < tol)
    mesh = named_boundaries(mesh, tests)
    rr, th, w = mesh.p
    p = np.vstack([x0 + rr * np.cos(th), y0 + rr * np.sin(th), z0 + w * height])
    if quarter:
        return share_topology(mesh, replace(mesh, doflocs=p))
    # the whole ring: the nodes at theta = 2 pi are those at 0, merged by position
    _, first, index = np.unique(np.rint(p.T / (1e-9 * outer_radius)).astype(np.int64), axis=0,
                                return_index=True, return_inverse=True)
    index = index.ravel()
    order = np.argsort(first)  # keep the nodes in their first-seen order
    renumber = np.empty_like(order)
    renumber[order] = np.arange(len(order))
    t = renumber[index[mesh.t]]
    whole = type(mesh)(np.ascontiguousarray(p[:, np.sort(first)]), np.ascontiguousarray(t))
    with_topology(whole)
    # the named facets again, by their nodes in the merged numbering
    mine = np.sort(whole.facets.T, axis=1)
    names = list(mesh.boundaries)
    asked = [np.sort(renumber[index[mesh.facets[:, mesh.boundaries[n]]]].T, axis=1)
             for n in names]
    _, inverse = np.unique(np.vstack([mine, *asked]), axis=0, return_inverse=True)
    inverse = inverse.ravel()
    facet_of = np.full(inverse.max() + 1, -1, dtype=np.int64)
    facet_of[inverse[: len(mine)]] = np.arange(len(mine))
    ends = np.cumsum([len(mine)] + [len(a) for a in asked])
    found = {n: np.sort(facet_of[inverse[lo:hi]]).astype(np.int32)
             for n, lo, hi in zip(names, ends[:-1], ends[1:])}
    return named_boundaries(whole, found)
