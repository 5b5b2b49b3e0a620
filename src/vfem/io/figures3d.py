"""The figures of a 3D model's run (issue 39, item 5), drawn from its results folder's files
only (:func:`vfem.io.replot.generic` hands them the folder), so ``vfem plot`` redraws the same:

* ``pressure_<body>.png`` — at the most loaded step (the largest sum over the bodies and
  their nodes of the size of the VTU's nodal ``contact_force``), the nominal pressure
  (``contact.csv``'s: normal force over undeformed area) on each contact surface of the body,
  seen along the normal of the plane fitted to its nodes in contact (:func:`plane_fit`): filled
  contours over the faces around them (falling to zero at the free candidates next to them),
  those nodes marked. A contact surface: a connected patch of boundary faces whose corners are
  all candidates (a plate pressed between two others has two), one panel each.
* ``stick_slip_<body>.png`` (with friction) — the same views, the nodes marked by the VTU's
  ``friction_status``: stick (1), slip (2), free (0); none for a body whose nodes carry no
  pair's compatibility (-1: the other side of a paired contact, whose map shows it).
* ``deformed.png`` — the last step's deformed bodies as outlines: the feature edges of their
  boundary (the faces used by one cell only: where it folds by more than
  :data:`FEATURE_ANGLE` degrees, or on one face only) and each view's silhouette, in two planes
  that contain the contact normal (the contact seen edge-on); the undeformed outline thin grey
  behind, the displacements magnified as the 2D figures' are.
* ``von_mises.png`` — the deformed bodies' boundary faces at the most stressed step, each
  coloured by its cell's ``von_mises``, seen obliquely from the diagonal that sees the most
  stress (e.g. a quarter model's symmetry planes); hidden faces by depth order (a painter's
  algorithm: faces turned away left out, the rest drawn far to near as one 2D collection,
  100k faces in a second, where mplot3d takes minutes).

Linear and quadratic tetrahedra and hexahedra (faces by their corners; the maps' with their
mid-side nodes, :func:`face_nodes`), vectorised. What is not drawn, and why, is a note
``"<figure>: <why>"`` (no node in contact, unknown cells, over :data:`MAX_FACES` faces):
``summary.json``'s ``figures_notes``, printed by ``vfem run`` and ``vfem plot``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import plots
from .files import _safe

#: The faces of VTK's 3D cells by the cells' corner positions (hexahedron: bottom 0-3, top
#: 4-7; tetrahedron: any three of four); by the number of corners.
CELL_FACES = {8: ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6),
                  (3, 0, 4, 7)),
              4: ((0, 1, 2), (0, 1, 3), (1, 2, 3), (0, 2, 3))}
#: The corners of the cell types vfem writes (VTK's first nodes of a quadratic cell).
CORNERS = {"tetra": 4, "tetra10": 4, "hexahedron": 8, "hexahedron20": 8, "hexahedron27": 8}
_HEX_EDGES = ((0, 1), (1, 2), (2, 3), (0, 3), (4, 5), (5, 6), (6, 7), (4, 7), (0, 4), (1, 5),
              (2, 6), (3, 7))
#: The mid-side nodes of VTK's quadratic cells, after the corners: the corners each lies
#: between (an edge's two; a face's four: hexahedron27's face centres; its body centre left out).
MIDS = {"tetra10": ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)),
        "hexahedron20": _HEX_EDGES,
        "hexahedron27": _HEX_EDGES + ((0, 3, 4, 7), (1, 2, 5, 6), (0, 1, 4, 5), (2, 3, 6, 7),
                                      (0, 1, 2, 3), (4, 5, 6, 7))}
#: A face's triangles by its columns in :func:`face_nodes` (corners, then the mid-edge nodes,
#: corner i's to i + 1's, then the centre), by their number.
SPLIT = {3: ((0, 1, 2),), 4: ((0, 1, 2), (0, 2, 3)),
         6: ((0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5)),
         8: ((0, 4, 7), (4, 1, 5), (5, 2, 6), (6, 3, 7), (4, 5, 6), (4, 6, 7)),
         9: tuple(t for i in range(4) for t in ((i, 4 + i, 8), (i, 8, 4 + (i - 1) % 4)))}
#: Edges where the boundary folds by more than this (degrees) are drawn in ``deformed.png``.
FEATURE_ANGLE = 30.0
#: A plane whose normal is this close (degrees) to a coordinate axis is seen in that axis' plane.
SNAP_ANGLE = 5.0
#: The most boundary faces ``von_mises.png`` draws (about 10 s of matplotlib's drawing);
#: beyond, a note says to open ``results.pvd`` in ParaView.
MAX_FACES = 200_000
EDGED_FACES = 20_000  # up to this many faces drawn, their edges are drawn too (thin, dark)
ELEVATION = 30.0  # degrees: the oblique view's height above the contact plane
COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")


# -- geometry ------------------------------------------------------------------------------------


def boundary_faces(cells: np.ndarray, cell_type: str, points: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray] | None:
    """The boundary of a mesh of 3D cells: the faces (by their corners) used by one cell only,
    as ((f, 3 or 4) corner point numbers, (f,) the cell each belongs to). With ``points``, each
    face's corners are put in the order whose right-hand normal points out of its cell (away
    from the cell's centroid). None for a cell type whose faces are not known."""
    corners = CORNERS.get(cell_type)
    cells = np.asarray(cells)
    if corners is None or cells.ndim != 2 or cells.shape[1] < corners:
        return None
    cells = cells[:, :corners].astype(np.int64)
    local = np.asarray(CELL_FACES[corners])
    faces = cells[:, local].reshape(-1, local.shape[1])
    owner = np.repeat(np.arange(len(cells)), len(local))
    keep = plots.once(np.sort(faces, axis=1))
    faces, owner = faces[keep], owner[keep]
    if points is not None and len(faces):
        x = np.asarray(points, dtype=float)
        normal = _normals(x, faces)
        out = np.einsum("ij,ij->i", normal, x[faces].mean(axis=1) - x[cells[owner]].mean(axis=1))
        faces[out < 0] = faces[out < 0, ::-1]
    return faces, owner


def face_nodes(cells: np.ndarray, cell_type: str, faces: np.ndarray, owner: np.ndarray
               ) -> np.ndarray:
    """The nodes on each of ``faces`` (:func:`boundary_faces`'s, of cells ``owner``): its
    corners, then a quadratic cell's (:data:`MIDS`) mid-edge node from each corner to the next
    and face centre (hexahedron27): (f, 6, 8 or 9) point numbers; ``faces`` for linear cells."""
    mids, k = MIDS.get(cell_type, ()), faces.shape[1]
    cells = np.asarray(cells)
    if not mids or cells.shape[1] < CORNERS[cell_type] + len(mids):
        return faces
    cells = cells[owner].astype(np.int64)
    slots = [np.sort(faces[:, [i, (i + 1) % k]], axis=1) for i in range(k)]  # its edges
    slots += [np.sort(faces, axis=1)] if len(mids[-1]) == k else []  # and its centre
    out = np.column_stack([faces] + [np.full(len(faces), -1)] * len(slots))
    for j, between in enumerate(mids, start=CORNERS[cell_type]):
        on = np.sort(cells[:, between], axis=1)
        for i, slot in enumerate(slots):
            if slot.shape == on.shape:
                out[:, k + i] = np.where(np.all(on == slot, axis=1), cells[:, j], out[:, k + i])
    return out if np.all(out >= 0) else faces


def _normals(x: np.ndarray, faces: np.ndarray, unit: bool = False) -> np.ndarray:
    """The faces' right-hand normals, of length twice their area (a quadrilateral's: the cross
    product of its diagonals); of length 1 with ``unit``."""
    p = x[faces]
    if faces.shape[1] == 3:
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    else:
        n = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
    if unit:
        n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    return n


def outline_edges(x: np.ndarray, faces: np.ndarray, views: list[np.ndarray]
                  ) -> list[np.ndarray]:
    """The edges (e, 2) of the surface ``faces`` (outward corner order) at points ``x`` to draw
    seen along each direction of ``views`` (toward the viewer): the feature edges (the faces
    on it fold by more than :data:`FEATURE_ANGLE`, or it is on one face only) and the
    silhouette there (one face on it turned to the viewer, the other away)."""
    if not len(faces):
        return [np.zeros((0, 2), dtype=np.int64) for _ in views]
    edges, f1, f2, _ = plots.polygon_edges(faces)
    n = _normals(x, faces, unit=True)
    two = f2 >= 0
    fold = np.ones(len(edges), dtype=bool)
    fold[two] = np.einsum("ij,ij->i", n[f1[two]], n[f2[two]]) < np.cos(np.radians(FEATURE_ANGLE))
    out = []
    for d in views:
        facing = n @ d > 0
        silhouette = two & (facing[f1] != facing[np.where(two, f2, 0)])
        out.append(edges[fold | silhouette])
    return out


def plane_fit(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The plane nearest (least squares) to ``points`` (n, 3): (its centre, its unit normal —
    the least spread, by an SVD — its largest component positive, the singular values (3,),
    largest first: a second one near zero says the points lie on a line, the normal any across)."""
    x = np.asarray(points, dtype=float).reshape(-1, 3)
    centre = x.mean(axis=0) if len(x) else np.zeros(3)
    d = x - centre
    if len(d) < 3:
        d = np.vstack([d, np.zeros((3 - len(d), 3))])
    _, s, vt = np.linalg.svd(d, full_matrices=False)
    n = vt[-1] / np.linalg.norm(vt[-1])
    return centre, n * (1.0 if n[np.argmax(np.abs(n))] > 0 else -1.0), s


#: for a normal nearest each coordinate axis, the two coordinates a view of its plane shows
_IN_PLANE = {0: (1, 2), 1: (0, 2), 2: (0, 1)}


def view_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Axes (u, v, n) to see a plane along its ``normal``: n the normal, its largest component
    positive, made that coordinate axis when within :data:`SNAP_ANGLE` of it; u and v the two
    other axes (x before y before z) made orthogonal to n and each other (z = const: x, y)."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n) if np.any(n) else np.eye(3)[2]
    k = int(np.argmax(np.abs(n)))
    n = n if n[k] > 0 else -n
    if np.degrees(np.arccos(min(1.0, abs(n[k])))) <= SNAP_ANGLE:
        n = np.eye(3)[k]
    a, b = _IN_PLANE[k]
    u = np.eye(3)[a] - n[a] * n
    u /= np.linalg.norm(u)
    v = np.eye(3)[b] - n[b] * n - u[b] * u
    return u, v / np.linalg.norm(v), n


def axis_label(direction: np.ndarray) -> str:
    """A direction's name: the coordinate ("x", "y", "z") where it is one, else "along (0.97,
    0.00, -0.26)"."""
    d = np.asarray(direction, dtype=float)
    k = int(np.argmax(np.abs(d)))
    if np.allclose(np.abs(d), np.eye(3)[k], atol=1e-12):
        return ("-" if d[k] < 0 else "") + "xyz"[k]
    return "along ({:.2f}, {:.2f}, {:.2f})".format(*(d + 0.0))


def _seen(direction: np.ndarray) -> str:
    return "seen along " + axis_label(direction).removeprefix("along ")


def _components(faces: np.ndarray, npoints: int) -> np.ndarray:
    """The connected patch of each face of ``faces`` (faces sharing a point are connected)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    a, b = faces.ravel(), np.roll(faces, -1, axis=1).ravel()
    graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(npoints, npoints))
    _, label = connected_components(graph, directed=False)
    return label[faces[:, 0]]


# -- the data ------------------------------------------------------------------------------------


@dataclass
class Surface:
    """One contact surface of a body as its maps draw it (local numbers index ``nodes``)."""

    nodes: np.ndarray  # its points' numbers in the body (corners and mid-side nodes)
    uv: np.ndarray  # (n, 2) their in-plane coordinates
    pressure: np.ndarray
    contact: np.ndarray  # whether each is in contact
    triangles: np.ndarray  # (t, 3) over them
    edges: np.ndarray  # (e, 2) the faces' edges
    axes: tuple[np.ndarray, np.ndarray, np.ndarray]  # the view's (u, v, n)
    fitted: np.ndarray  # the fitted plane's normal
    at: float  # the nodes in contact's mean coordinate along the view's normal

    @property
    def title(self) -> str:
        n, fit = self.axes[2], self.fitted
        if np.allclose(n, fit, atol=1e-12):
            return _seen(n)
        off = np.degrees(np.arccos(min(1.0, abs(float(n @ fit)))))
        return f"{_seen(n)} (fitted normal {axis_label(fit)[6:]}, {off:.1f}° off)"


def _faces_of(frame, cache: dict):
    """``frame``'s outward boundary faces and their cells, or None (kept in ``cache``)."""
    if frame.name not in cache:
        cache[frame.name] = boundary_faces(frame.polygons, frame.cell_type, frame.points)
    return cache[frame.name]


def surfaces(frame, contact, found) -> list[Surface]:
    """The contact surfaces of ``frame`` that have nodes in contact (``contact``: its
    :class:`~vfem.io.replot.ContactNodes` at the step), each with the faces around those nodes:
    ``found`` its boundary faces (:func:`boundary_faces`), or None (then one surface of the
    nodes in contact alone, triangulated in its plane)."""
    n = len(frame.points)
    candidate = np.isin(np.arange(n), contact.node)
    touching = np.isin(np.arange(n), contact.node[contact.contact])
    pressure = np.zeros(n)
    pressure[contact.node] = contact.pressure
    x = frame.points
    if found is None or not len(found[0]):
        return [_surface(x, np.flatnonzero(touching), touching, pressure, None)]
    keep = candidate[found[0]].all(axis=1)  # their nodes then with the mid-side ones:
    faces = face_nodes(frame.polygons, frame.cell_type, *(f[keep] if keep.any() else f
                                                          for f in found))
    if not keep.any():  # e.g. the VTU fields' nodes in contact only: the faces around them
        faces = faces[touching[faces].any(axis=1)]
    label = _components(faces[:, :found[0].shape[1]], n)
    out = []
    for patch in np.unique(label):  # (few: the body's contact boundaries)
        own = faces[label == patch]
        near = own[touching[own].any(axis=1)]
        if len(near):
            out.append(_surface(x, np.unique(near), touching, pressure, near))
    return sorted(out, key=lambda s: -int(s.contact.sum()))


def _surface(x, nodes, touching, pressure, faces) -> Surface:
    on = nodes[touching[nodes]]
    _, fitted, s = plane_fit(x[on])
    k = 3 if faces is not None and faces.shape[1] in (3, 6) else 4  # corners a face
    if (len(on) < 3 or s[1] <= 1e-9 * s[0]) and faces is not None:  # on a line: the faces'
        fitted = view_axes(_normals(x, faces[:, :k]).sum(axis=0))[2]
    u, v, normal = view_axes(fitted)
    uv = x[nodes] @ np.column_stack([u, v])  # coordinates along u and v, not from the centre
    tri, edges = np.zeros((0, 3), dtype=np.int64), np.zeros((0, 2), dtype=np.int64)
    if faces is not None:
        local = np.searchsorted(nodes, faces)  # (mid-side nodes too: their pressure)
        ring = np.arange(2 * k).reshape(2, k).T.ravel() if faces.shape[1] > k else range(k)
        edges = plots.polygon_edges(local[:, ring])[0]
        tri = local[:, SPLIT[faces.shape[1]]].reshape(-1, 3)
        e1, e2 = uv[tri[:, 1]] - uv[tri[:, 0]], uv[tri[:, 2]] - uv[tri[:, 0]]
        area = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        size = float(np.ptp(uv, axis=0).max()) if len(uv) else 0.0
        tri = tri[area > 1e-10 * size ** 2]  # faces seen edge-on add nothing
    return Surface(nodes, uv, pressure[nodes], touching[nodes], tri, edges, (u, v, normal),
                   fitted, float(np.mean(x[on] @ normal)) if len(on) else 0.0)


#: how the maps' step is chosen, for their titles and notes (:func:`total_contact_force`)
MOST_LOADED = "the largest sum of nodal contact force magnitudes"


def total_contact_force(step) -> float:
    """The sum over ``step``'s bodies and nodes of the size of the VTU's ``contact_force`` (not
    the resultant's: ~0 where contact balances itself, a shrink fit, a plate pressed both sides)."""
    return sum(float(np.linalg.norm(np.asarray(b.point_data["contact_force"], dtype=float)
                                    [:, :3], axis=1).sum())
               for b in step.bodies if "contact_force" in b.point_data)


def _step_text(step) -> str:
    return f"step {step.step} (load factor {step.load_factor:.6g})"


# -- the figures ---------------------------------------------------------------------------------


def figures(folder, steps: list, label: str, magnification: float, notes: list[str]
            ) -> list[Path]:
    """Draw the 3D figures of ``folder`` (a :class:`~vfem.io.replot.Folder`, its ``steps``;
    ``label`` the contact method, for the titles), add to ``notes`` what was not drawn and why,
    return the paths written (the module's docstring says which)."""
    directory = Path(folder.directory)
    cache: dict = {}
    for b in steps[-1].bodies:
        if _faces_of(b, cache) is None:
            notes.append(f"deformed.png, von_mises.png: {b.name!r} left out: its cells are "
                         f"VTK's {b.cell_type!r}, whose faces vfem does not know (it draws "
                         f"{', '.join(CORNERS)})")
    loads = [total_contact_force(s) for s in steps]
    loaded = steps[int(np.argmax(loads))]
    written, normal = _contact_maps(folder, loaded, loads, cache, label, notes)
    written.append(_deformed(directory, steps[-1], cache, normal, label, magnification))
    peak = max(steps, key=lambda s: max((float(np.max(b.cell_data["von_mises"], initial=0.0))
                                         for b in s.bodies if "von_mises" in b.cell_data),
                                        default=0.0))
    path = _von_mises_figure(directory / "von_mises.png", peak, cache, normal, label,
                             magnification, notes)
    if path is not None:
        written.append(path)
    return written


def _contact_maps(folder, step, loads, cache, label, notes) -> tuple[list[Path], np.ndarray]:
    """The pressure (with friction, stick/slip) maps of each body at ``step``, the most loaded:
    their paths, the normal of the surface with the most nodes in contact (z where none)."""
    written, best, normal = [], 0, np.eye(3)[2]
    when = _step_text(step) + (", the most loaded" if max(loads) > 0 else "")
    for b in step.bodies:
        name = _safe(b.name)
        frictional = "friction_status" in b.point_data
        figs = [f"pressure_{name}.png"] + ([f"stick_slip_{name}.png"] if frictional else [])
        c = folder.contact(step, b)
        if not np.any(c.contact):
            why = "at any step" if max(loads) == 0 else f"at {when} ({MOST_LOADED})"
            notes.extend(f"{f}: no node of {b.name!r} in contact {why}" for f in figs)
            continue
        shown = surfaces(b, c, _faces_of(b, cache))
        if not shown:
            notes.extend(f"{f}: no boundary face of {b.name!r} holds its nodes in contact "
                         f"({int(np.sum(c.contact))} at {when})" for f in figs)
            continue
        top = max(int(s.contact.sum()) for s in shown)
        if top > best:
            best, normal = top, shown[0].axes[2]
        path = folder.directory / figs[0]
        _pressure_figure(path, shown, f"Contact pressure on {b.name!r}, {when}\n({MOST_LOADED})"
                         f"\nnominal: normal force / undeformed area, from "
                         f"{folder.contact_source}\n{label}")
        written.append(path)
        if frictional:
            status = np.asarray(b.point_data["friction_status"]).ravel()
            if not np.any(status[c.node[c.contact]] >= 0):
                notes.append(f"{figs[1]}: the nodes of {b.name!r} carry no pair's "
                             "compatibility (friction_status -1): the other body's map shows "
                             "this contact's stick and slip")
                continue
            path = folder.directory / figs[1]
            _stick_figure(path, shown, status, f"Stick and slip on {b.name!r}, {when}\n"
                          f"(the VTU's friction_status; undeformed positions)\n{label}")
            written.append(path)
    return written, normal


def _panels(plt, spans: list, width: float = 5.0):
    """A row of panels, one per (width, height) of what each shows, the figure as tall."""
    tall = max(float(h / max(w, 1e-300)) for w, h in spans)
    fig, axes = plt.subplots(1, len(spans), squeeze=False, layout="constrained", figsize=(
        width * len(spans) + 1.2, float(np.clip(width * tall + 2.2, 3.6, 8.0))))
    return fig, axes[0]


def _finish(plt, fig, path: Path, title: str) -> None:
    fig.suptitle(title, fontsize=9)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def _window(ax, xy: np.ndarray) -> None:
    """Equal scales, the extent of the points ``xy`` (n, 2) padded by 4 %."""
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    pad = 0.04 * float((hi - lo).max() or 1.0)
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")


def _plan(ax, s: Surface, k: int, count: int, colour: str, ncol: int) -> None:
    """A surface's view: its face edges thin in ``colour`` (unless too many to tell apart),
    equal scales, its nodes' extent padded, the axes named, the legend below."""
    from matplotlib.collections import LineCollection
    from matplotlib.transforms import ScaledTranslation

    if 0 < len(s.edges) < 20_000:
        ax.add_collection(LineCollection(s.uv[s.edges], colors=colour, linewidths=0.4,
                                         alpha=0.6, zorder=1.5), autolim=False)
    _window(ax, s.uv)
    u, v, _ = s.axes
    ax.set_xlabel(f"{axis_label(u)}, undeformed ({plots.LENGTH})", fontsize=8)
    ax.set_ylabel(f"{axis_label(v)}, undeformed ({plots.LENGTH})", fontsize=8)
    where = f"surface {k + 1} of {count}, at {axis_label(s.axes[2])} = {s.at:.4g}, "
    ax.set_title((where if count > 1 else "") + s.title, fontsize=8)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, 0.0), ncol=ncol,
              borderaxespad=0.0, bbox_transform=ax.transAxes + ScaledTranslation(
                  0.0, -0.5, ax.figure.dpi_scale_trans))  # below the axis' labels


def _pressure_figure(path: Path, shown: list[Surface], title: str) -> None:
    """Filled contours of each surface's pressure in its plane (one panel each, one colour
    scale), the nodes in contact marked, the free candidates around them dotted."""
    import matplotlib.tri as mtri

    plt = plots.require_matplotlib()
    fig, axes = _panels(plt, [np.ptp(s.uv, axis=0) for s in shown])
    top = max(float(np.max(s.pressure, initial=0.0)) for s in shown) or 1.0
    levels = np.linspace(0.0, top, 13)
    filled = None
    for k, (ax, s) in enumerate(zip(axes, shown)):
        p = np.clip(s.pressure, 0.0, None)
        tri = None
        if len(s.triangles):  # the surface's own faces
            tri = mtri.Triangulation(s.uv[:, 0], s.uv[:, 1], s.triangles)
        elif len(s.uv) >= 3 and np.ptp(s.uv, axis=0).min() > 0:  # faces not known: Delaunay's
            tri = mtri.Triangulation(s.uv[:, 0], s.uv[:, 1])
        if tri is not None:
            filled = ax.tricontourf(tri, p, levels=levels, cmap="viridis")
        on = s.contact
        ax.plot(*s.uv[~on].T, ".", ms=2, color="0.5", label=f"free candidates ({(~on).sum()})")
        ax.plot(*s.uv[on].T, ".", ms=3, color="k", label=f"in contact ({on.sum()})")
        _plan(ax, s, k, len(shown), "w", 2)
    if filled is not None:
        fig.colorbar(filled, ax=list(axes), label=f"nominal contact pressure ({plots.LENGTH})",
                     shrink=0.8)
    _finish(plt, fig, path, title)


def _stick_figure(path: Path, shown: list[Surface], status: np.ndarray, title: str) -> None:
    """Each surface's nodes in its plane marked by their friction status, its faces' edges
    thin behind."""
    plt = plots.require_matplotlib()
    fig, axes = _panels(plt, [np.ptp(s.uv, axis=0) for s in shown])
    for k, (ax, s) in enumerate(zip(axes, shown)):
        st = status[s.nodes]
        for value, name, style in plots.FRICTION_MARKERS:
            on = st == value
            if on.any():
                ax.plot(*s.uv[on].T, ls="", label=f"{name} ({on.sum()})", **style)
        _plan(ax, s, k, len(shown), "0.7", 4)
    _finish(plt, fig, path, title)


def _deformed(directory: Path, step, cache, normal, label, magnification) -> Path:
    """``deformed.png``: two panels, each the plane of the contact normal ``normal`` and one of
    the coordinate axes across it (x and y for a normal near z), the bodies' outlines
    (:func:`outline_edges`) deformed (magnified) over the undeformed ones in thin grey."""
    from matplotlib.collections import LineCollection

    views = []
    for a in _IN_PLANE[int(np.argmax(np.abs(normal)))]:
        h = np.eye(3)[a] - normal[a] * normal
        h /= np.linalg.norm(h)
        views.append((h, np.cross(h, normal)))  # across, and toward the viewer
    drawn = [(j, b, found[0]) for j, b in enumerate(step.bodies)
             if (found := _faces_of(b, cache)) is not None]
    shapes = [(j, b.name, faces, b.points, b.points + magnification * b.displacement)
              for j, b, faces in drawn]
    everything = np.vstack([x for *_, x0, x1 in shapes for x in (x0, x1)]
                           or [np.zeros((1, 3))])  # (the origin only when nothing is drawn)
    plt = plots.require_matplotlib()
    fig, axes = _panels(plt, [np.ptp(everything @ np.column_stack([h, normal]), axis=0)
                              for h, _ in views], 5.4)
    for j, name, faces, x0, x1 in shapes:  # each outline in both views (one edge table)
        for x, colour, width, z, what in ((x0, "0.7", 0.5, 1, None if j else "undeformed"),
                                          (x1, COLORS[j % len(COLORS)], 0.9, 2, name)):
            for ax, (h, _), edges in zip(axes, views, outline_edges(x, faces,
                                                                    [d for _, d in views])):
                ax.add_collection(LineCollection((x @ np.column_stack([h, normal]))[edges],
                                                 colors=colour, linewidths=width, zorder=z,
                                                 label=what), autolim=False)
    for ax, (h, d) in zip(axes, views):
        _window(ax, everything @ np.column_stack([h, normal]))
        ax.set_xlabel(f"{axis_label(h)} ({plots.LENGTH})", fontsize=8)
        ax.set_ylabel(f"{axis_label(normal)}: the contact normal ({plots.LENGTH})", fontsize=8)
        ax.set_title(_seen(-d), fontsize=8)
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, fontsize=7, loc="outside lower center", ncol=6)
    _finish(plt, fig, path := directory / "deformed.png", plots.magnified(
        f"Deformed configuration, {_step_text(step)}: outlines (feature edges, > "
        f"{FEATURE_ANGLE:g}° folds, and silhouettes)\n{label}", magnification))
    return path


def _view(normal: np.ndarray, faces: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """The oblique view (toward the viewer, unit): :data:`ELEVATION` above the plane of
    ``normal``, from the one of its four diagonals that sees the most stress (the sum of the
    faces' von Mises times their area seen; ``faces``: (normals with length twice the area,
    von Mises) per body)."""
    h1, h2, _ = view_axes(normal)
    c, s = np.cos(np.radians(ELEVATION)), np.sin(np.radians(ELEVATION))
    views = [c * (s1 * h1 + s2 * h2) / np.sqrt(2.0) + s * normal
             for s1, s2 in ((-1, -1), (1, -1), (1, 1), (-1, 1))]

    def seen(d):
        return sum(float(np.sum(np.clip(n @ d, 0.0, None) * np.nan_to_num(v)))
                   for n, v in faces)

    return max(views, key=seen)


def _von_mises_figure(path: Path, step, cache, normal, label, magnification, notes
                      ) -> Path | None:
    """``von_mises.png`` (see the module's docstring); None, with a note, when there are more
    than :data:`MAX_FACES` boundary faces or no body has a ``von_mises`` field."""
    from matplotlib import colormaps
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import Normalize

    bodies = []
    for b in step.bodies:
        found, vm = _faces_of(b, cache), b.cell_data.get("von_mises")
        if found is None:
            continue
        if vm is None:
            notes.append(f"von_mises.png: {b.name!r} left out: no von_mises cell field in "
                         f"{Path(b.path).name}")
            continue
        x = b.points + magnification * b.displacement
        bodies.append((x, found[0], np.ravel(vm)[found[1]], _normals(x, found[0])))
    count = sum(len(f) for _, f, _, _ in bodies)
    if count > MAX_FACES or not bodies:
        why = (f"{count} boundary faces, more than the {MAX_FACES} it draws at most (a "
               "painter's algorithm in matplotlib); open results.pvd in ParaView"
               if bodies else "no body to draw")
        notes.append(f"von_mises.png: {why}")
        return None
    d = _view(normal, [(n, v) for _, _, v, n in bodies])
    up = normal - (normal @ d) * d
    up /= np.linalg.norm(up)
    right = np.cross(up, d)
    polys, values, depth = [], [], []
    for x, faces, v, n in bodies:
        front = n @ d > 0  # faces turned away are hidden behind the front ones
        f = faces[front]
        if f.shape[1] == 3:
            f = f[:, [0, 1, 2, 2]]
        p = x[f]
        polys.append(np.stack([p @ right, p @ up], axis=-1))
        values.append(v[front])
        depth.append((p @ d).mean(axis=1))
    order = np.argsort(np.concatenate(depth), kind="stable")  # far first
    poly, value = np.concatenate(polys)[order], np.concatenate(values)[order]
    plt = plots.require_matplotlib()
    fig, ax = plt.subplots(figsize=(7.6, 6.0), layout="constrained")
    finite = value[np.isfinite(value)]
    norm = Normalize(vmin=float(finite.min(initial=0.0)),
                     vmax=float(finite.max(initial=0.0)) or 1.0)
    edged = len(poly) <= EDGED_FACES
    faces = PolyCollection(poly, array=value, cmap=colormaps["viridis"], norm=norm,
                           edgecolors=(0.1, 0.1, 0.1, 0.35) if edged else "face",
                           linewidths=0.2 if edged else 0.3)
    ax.add_collection(faces, autolim=False)
    _window(ax, poly.reshape(-1, 2))
    ax.axis("off")
    _triad(ax, right, up)
    fig.colorbar(faces, ax=ax, label=f"von Mises stress ({plots.LENGTH})", shrink=0.8)
    _finish(plt, fig, path, plots.magnified(
        f"von Mises stress on the bodies' surfaces, {_step_text(step)}, the most stressed\n"
        "seen from ({:.2f}, {:.2f}, {:.2f}): {:g}° above the contact plane; each face the "
        "value of its cell\n{}".format(*d, ELEVATION, label), magnification))
    return path


def _triad(ax, right: np.ndarray, up: np.ndarray) -> None:
    """x, y, z as arrows in the lower left corner, as the view shows them."""
    for k, name in enumerate("xyz"):
        at = np.array([0.08, 0.08]), np.array([right[k], up[k]])
        ax.annotate(name, xy=at[0], xytext=at[0] + 0.08 * at[1], xycoords="axes fraction",
                    fontsize=7, ha="center", va="center",
                    arrowprops=dict(arrowstyle="<-", lw=0.8, color="0.2", shrinkA=4, shrinkB=0))
