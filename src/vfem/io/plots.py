"""Figures of the examples (matplotlib, Agg backend: no display needed).

matplotlib is needed for the figures only, and imported when the first one is drawn
(:func:`require_matplotlib`, the one place that checks for it): without it vfem still imports,
solves and writes every other result; a run records why it drew no figure
(``summary.json``'s ``figures_not_drawn``, :func:`vfem.io.replot.draw_run`) and ``vfem run``
says so in one line; ``vfem plot`` stops with the message, exit status 2.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from ..errors import InputError

#: how to get the figures' one optional dependency
MATPLOTLIB_FIX = 'pip install matplotlib, or pip install -e ".[figures]"'

#: the axis label of a model coordinate (vfem has no unit system: lengths are the model's own)
LENGTH = "model units"
#: a fixed legend place beside the axes: never over the drawing, and fast (matplotlib's "best"
#: tests every position against every drawn vertex, minutes on a large mesh)
OUTSIDE = {"loc": "upper left", "bbox_to_anchor": (1.02, 1.0), "borderaxespad": 0.0}
_LINESTYLES = ("-", "--", ":", "-.")


@functools.cache
def _pyplot():
    """pyplot, switched to the Agg backend once (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def matplotlib_missing() -> str | None:
    """None when matplotlib can be imported (figures can be drawn), else why not and the fix:
    "matplotlib is not installed (pip install matplotlib, or ...)". The one check for it in
    vfem (:func:`require_matplotlib` raises with it)."""
    try:
        _pyplot()
    except ImportError as exc:
        if isinstance(exc, ModuleNotFoundError) and (exc.name or "").split(".")[0] == "matplotlib":
            why = "is not installed"
        else:  # installed but broken (a dependency of its own missing, a binary mismatch)
            why = f"cannot be imported: {(str(exc).splitlines() or [type(exc).__name__])[0]}"
        return f"matplotlib {why} ({MATPLOTLIB_FIX})"
    return None


def require_matplotlib():
    """``matplotlib.pyplot`` on the Agg backend, imported on the first call; every figure is
    drawn through it. Without matplotlib: :class:`~vfem.errors.InputError` "figures not drawn:
    matplotlib is not installed (...)", naming the fix (:func:`matplotlib_missing`)."""
    why = matplotlib_missing()
    if why is not None:
        raise InputError(f"figures not drawn: {why}")
    return _pyplot()


def save(plt, fig, path: Path) -> None:
    """Lay ``fig`` out tight, write it to ``path`` (PNG, 130 dpi) and close it: every 2D figure
    ends here. The layout is done once, here: ``tight_layout`` leaves a placeholder layout
    engine on the figure, and for any engine ``savefig`` draws the whole figure once more
    before drawing it into the file (matplotlib 3.6+, ``print_figure``). That first pass
    renders nothing but still walks every artist: little on vfem's figures (0.07 of 0.78 s of
    savefig on a 100k-dof Hertz run), half of the time where a collection's cells fill the
    axes (60k random triangles: 1.57 s a pass; issue 40). With the engine dropped the figure is
    drawn once, into the same pixels (tests/test_figure_drawing.py)."""
    fig.tight_layout()
    fig.set_layout_engine(None)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def hertz_pressure(path: Path, x_over_a: dict[str, np.ndarray], p_over_p0: dict[str, np.ndarray],
                   title: str, method: str = "vfem",
                   xlabel: str = "x / a (undeformed x over Hertz's half-width; dimensionless)",
                   per: str = "length") -> None:
    """p/p0 against x/a for each body, with Hertz's ellipse (like thesis Fig. 5.3);
    ``method``: the contact method that computed them (the legend's label)."""
    plt = require_matplotlib()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    s = np.linspace(0, 1, 200)
    ax.plot(s, np.sqrt(1 - s**2), "k-", lw=1.5, label="Hertz")
    for (name, xa), marker in zip(x_over_a.items(), ("o", "s", "^", "v")):
        order = np.argsort(xa)
        ax.plot(xa[order], p_over_p0[name][order], marker, ms=4, mfc="none", ls="",
                label=f"{method}, {name} (nodal force / undeformed {per})")
    ax.set_xlim(0, 1.4)
    ax.set_ylim(-0.1, 1.15)
    ax.axhline(0, color="0.7", lw=0.8)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("p / p0 (pressure over Hertz's peak; dimensionless)")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    save(plt, fig, path)


def _plan_axes(ax, x: np.ndarray, y: np.ndarray, ylabel: str) -> None:
    """A 3D contact surface seen along its normal: the nodes' extent, equal scales, x / a."""
    if len(x):
        ax.set_xlim(float(np.min(x)), float(np.max(x)))
        ax.set_ylim(float(np.min(y)), float(np.max(y)))
    ax.set_aspect("equal")
    ax.set_xlabel("x / a (undeformed)")
    ax.set_ylabel(ylabel)


def pressure_map(path: Path, x: np.ndarray, y: np.ndarray, p: np.ndarray, title: str,
                 label: str = "p / p0 (pressure over Hertz's peak)") -> None:
    """A 3D contact surface's pressure seen along its normal: filled contours of ``p`` over the
    nodes' undeformed (``x``, ``y``) (a triangulation of the points in that plane), with the
    circle of radius 1 (Hertz's r = a when x, y and p are scaled by a and p0; a punch's rim);
    ``label`` names the colour bar's quantity."""
    import matplotlib.tri as mtri

    plt = require_matplotlib()
    fig, ax = plt.subplots(figsize=(5.6, 5.0))
    top = max(1.0, float(np.max(p)) if len(p) else 1.0)
    if len(p) >= 3:
        cs = ax.tricontourf(mtri.Triangulation(x, y), np.clip(p, 0.0, None),
                            levels=np.linspace(0.0, top, 12), cmap="viridis")
        fig.colorbar(cs, ax=ax, label=label)
    ax.plot(x, y, ".", ms=2, color="0.3")
    s = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(s), np.sin(s), "w--", lw=1.2)
    _plan_axes(ax, x, y, "y / a (undeformed)")
    ax.set_title(title, fontsize=9)
    save(plt, fig, path)


#: how the stick/slip figures mark a node by its friction status (a VTU's ``friction_status``):
#: (status, legend, marker style), in the order drawn (stick on top): -1 carries no pair's
#: compatibility, 0 free, 2 slip, 1 stick (:func:`stick_map`, :mod:`vfem.io.figures3d`)
FRICTION_MARKERS = ((-1, "no compatibility", dict(marker="x", ms=3, color="0.6")),
                    (0, "free", dict(marker=".", ms=2, color="0.6")),
                    (2, "slip", dict(marker="o", ms=4, mfc="none", color="tab:orange")),
                    (1, "stick", dict(marker="o", ms=4, color="tab:blue")))


def stick_map(path: Path, panels: list[tuple[str, np.ndarray, np.ndarray, np.ndarray, float]],
              title: str) -> None:
    """A 3D contact surface's stick and slip zones seen along its normal, one panel per
    (label, x, y, status, c): the nodes' undeformed (``x``, ``y``) marked by their friction
    status (1 stick: filled, 2 slip: open, 0 no contact: a dot), the circle of radius ``c``
    dashed (the stick zone of a theory) and the circle of radius 1 dotted (the contact's; x, y
    and c scaled by its radius)."""
    plt = require_matplotlib()
    fig, axes = plt.subplots(1, max(len(panels), 1), figsize=(4.2 * max(len(panels), 1), 3.4),
                             squeeze=False)
    s = np.linspace(0.0, 2.0 * np.pi, 361)
    for ax, (label, x, y, status, c) in zip(axes[0], panels):
        status = np.asarray(status)
        for value, name, style in FRICTION_MARKERS[1:]:  # free (unnamed), slip, stick
            on = status == value
            ax.plot(x[on], y[on], ls="", label=name if value else None, **style)
        ax.plot(c * np.cos(s), c * np.sin(s), "k--", lw=1.0)
        ax.plot(np.cos(s), np.sin(s), "k:", lw=1.0)
        _plan_axes(ax, x, y, "y / a")
        ax.set_title(label, fontsize=9)
    axes[0][-1].legend(fontsize=8, **OUTSIDE)
    fig.suptitle(title, fontsize=9)
    save(plt, fig, path)


def punch_pressure(path: Path, x: np.ndarray, p: np.ndarray, force: float, a: float,
                   title: str) -> None:
    """Nodal contact pressure against x under a flat punch of half-width ``a``, with Sadowsky's
    rigid punch on a half-plane carrying the same ``force``: P / (pi sqrt(a^2 - x^2))."""
    plt = require_matplotlib()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    s = np.linspace(-a, a, 801)[1:-1]
    ax.plot(s, force / (np.pi * np.sqrt(a**2 - s**2)), "k-", lw=1.2,
            label=f"Sadowsky, rigid punch on a half-plane: $P/(\\pi\\sqrt{{a^2-x^2}})$, "
                  f"a = {a:g}, P = {force:.4g}")
    ax.plot(x, p, "o", ms=4, mfc="none", color="tab:blue",
            label="vfem, block (nodal force / undeformed length)")
    for edge in (-a, a):
        ax.axvline(edge, color="0.6", lw=0.8, ls="--")
    ax.axhline(0, color="0.7", lw=0.8)
    top = max(float(np.max(p)) if len(p) else 0.0, 3 * force / (np.pi * a))
    ax.set_ylim(-0.05 * top, 1.4 * top)  # room for the legend above the corners
    ax.set_xlabel(f"x, undeformed ({LENGTH})")
    ax.set_ylabel(f"contact pressure p ({LENGTH})")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper center")
    save(plt, fig, path)


def convergence(path: Path, series: dict[str, list[dict]], title: str) -> None:
    """p_max error and RMS profile error against contact facets across a, per series.

    ``series``: name -> rows with ``facets_across_a``, ``p_max_error`` and
    ``rms_error_averaged``. The p_max error is drawn signed (it may cross zero on its way to the
    model's own limit), the RMS error log-log.
    """
    plt = require_matplotlib()
    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.0), sharex=True)
    for (name, rows), marker in zip(series.items(), ("o", "s", "^", "v")):
        n = np.array([r["facets_across_a"] for r in rows], dtype=float)
        axes[0].semilogx(n, [r["p_max_error"] * 100 for r in rows], marker + "-", label=name)
        axes[1].loglog(n, [r["rms_error_averaged"] * 100 for r in rows], marker + "-",
                       label=name)
    axes[0].axhline(0.0, color="k", lw=0.8)
    axes[0].set_ylabel("p_max / p0 - 1  (%)")
    axes[1].set_ylabel("RMS profile error over |x| < a  (% of p0)")
    ticks = sorted({r["facets_across_a"] for rows in series.values() for r in rows})
    for ax in axes:
        ax.set_xlabel("contact facets across the half-width a")
        ax.set_xticks(ticks)
        ax.set_xticklabels([str(t) for t in ticks])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    save(plt, fig, path)




def magnified(title: str, magnification: float) -> str:
    """``title`` with the displacements' magnification stated, e.g. "... — displacements × 10"
    (× 1: true scale), so a reader never takes a magnified shape for the real one."""
    text = f"displacements × {magnification:g}" + (" (true scale)" if magnification == 1 else "")
    last = title.rsplit("\n", 1)[-1]
    return f"{title}{chr(10) if len(last) + len(text) > 70 else ' — '}{text}"


def configurations(path: Path, frames: list[tuple[str, list[tuple[np.ndarray, np.ndarray,
                                                                   np.ndarray]]]],
                   title: str, window: tuple[float, float, float, float] | None = None,
                   mesh_lines: bool | None = None, legend_loc: str | None = None,
                   magnification: float | None = None, axes: str = "xy") -> None:
    """One or more configurations of a model drawn over each other (thesis Figs. 5.4-5.23).

    ``frames``: (label, bodies) with bodies a list of (points (n, 2), cells (m, k) of vertex
    numbers, displacement (n, 2)), optionally preceded by the body's name (for the legend).
    With one frame each body gets its own colour and legend entry; with several, each frame
    gets its own colour and each named body its own line style (also in the legend), so every
    body can be told apart. Mesh lines are drawn when there is a single frame (default),
    outlines only when several are overlaid. ``window`` = (xmin, xmax, ymin, ymax), default:
    everything. ``legend_loc``: a matplotlib legend position inside the axes; default beside
    them. ``magnification``: the displacements are multiplied by it and the title says so
    (None: the title says nothing, for configurations that are not deformed shapes).
    ``axes``: the names of the two coordinates drawn ("xz" for a 3D body's plane y = 0).
    """
    plt = require_matplotlib()
    from matplotlib.collections import LineCollection
    from matplotlib.colors import to_rgba

    colors = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")
    mesh_lines = len(frames) == 1 if mesh_lines is None else mesh_lines
    scale = 1.0 if magnification is None else float(magnification)
    fig, ax = plt.subplots(figsize=(8.5, 4.6))
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    styles: dict[str, str] = {}  # body name -> line style (several frames)
    for k, (label, bodies) in enumerate(frames):
        for j, entry in enumerate(bodies):
            body_name, (p, t, u) = (entry[0], entry[1:]) if len(entry) == 4 else (None, entry)
            c = colors[(j if len(frames) == 1 else k) % len(colors)]
            ls = "-"
            if len(frames) > 1 and body_name is not None:
                ls = styles.setdefault(body_name, _LINESTYLES[len(styles) % len(_LINESTYLES)])
            x = np.asarray(p)[:, :2] + scale * np.asarray(u)[:, :2]
            lo, hi = np.minimum(lo, x.min(axis=0)), np.maximum(hi, x.max(axis=0))
            if len(frames) == 1:
                name = f"{label}: {body_name}" if body_name else (label if j == 0 else None)
            else:
                name = label if j == 0 else None
            if mesh_lines:
                cells = np.asarray(t)
                if window is not None:  # only the cells near the window (large meshes)
                    poly = x[cells]
                    near = _near(poly, window)
                    cells, poly = cells[near], poly[near]
                    fine = _fine(poly, window)  # too small for their edges to show
                    if fine.any():
                        _pixels(ax, window, poly[fine], to_rgba(c))
                    cells = cells[~fine]
                _mesh_lines(ax, x, cells, c, ls, name)
            else:
                ax.add_collection(LineCollection(x[_outline(np.asarray(t))], colors=c,
                                                 linewidths=0.9, linestyles=ls, label=name),
                                  autolim=False)
    if len(styles) > 1:  # which line style is which body
        for body_name, ls in styles.items():
            ax.plot([], [], color="0.3", ls=ls, lw=0.9, label=body_name)
    ratio = _frame(ax, window, lo, hi, axes)
    fig.set_size_inches(min(12.0, max(7.0, 3.6 * ratio + (2.9 if legend_loc is None else 1.2))),
                        4.6)
    ax.set_title(title if magnification is None else magnified(title, scale), fontsize=10)
    ax.legend(fontsize=8, **({"loc": legend_loc} if legend_loc else OUTSIDE))
    save(plt, fig, path)


def _mesh_lines(ax, x: np.ndarray, cells: np.ndarray, colour, linestyle: str,
                label: str | None) -> None:
    """Draw the edges of ``cells`` (m, k) (points ``x`` (n, 2)) as two compound paths: every
    edge, and again the edges two cells share. Two objects for Agg to stroke, where a
    PolyCollection of the cells made and transformed a path per cell (0.35 s for the 60k
    cells of a 100k-dof Hertz close-up, issue 40); drawn twice, a shared edge looks as it did
    when each of its cells drew it. Added with ``add_artist``: ``add_patch`` would take the
    limits from every segment in a Python loop (they are the figure's window, :func:`_frame`).
    """
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as Curve

    edges, _, _, count = (polygon_edges(cells) if len(cells)
                          else (np.zeros((0, 2), dtype=np.int64),) * 3 + (np.zeros(0),))
    for chosen, name in ((edges, label), (edges[count >= 2], None)):
        codes = np.tile(np.array([Curve.MOVETO, Curve.LINETO], dtype=Curve.code_type),
                        len(chosen))
        ax.add_artist(PathPatch(Curve(x[chosen].reshape(-1, 2), codes), facecolor="none",
                                edgecolor=colour, linewidth=0.4, linestyle=linestyle,
                                label=name))


def _window(window, lo: np.ndarray, hi: np.ndarray) -> tuple[float, float, float, float]:
    """A figure's window: the one given, else the box ``lo``..``hi`` padded by 3 %."""
    if window is not None:
        return window
    pad = 0.03 * (hi - lo).max()
    return (lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad)


def _frame(ax, window, lo: np.ndarray, hi: np.ndarray, axes: str = "xy") -> float:
    """Axes of a configuration figure: ``window`` (xmin, xmax, ymin, ymax; default the box
    ``lo``..``hi`` padded by 3 %), equal scales, coordinate labels. Returns the window's
    width over its height, for the figure's shape."""
    window = _window(window, lo, hi)
    ax.set_xlim(window[0], window[1])
    ax.set_ylim(window[2], window[3])
    ax.set_aspect("equal")
    ax.set_xlabel(f"{axes[0]} ({LENGTH})")
    ax.set_ylabel(f"{axes[1]} ({LENGTH})")
    return (window[1] - window[0]) / max(window[3] - window[2], 1e-300)


def von_mises(path: Path, bodies: list[tuple[str, np.ndarray, np.ndarray, np.ndarray,
                                             np.ndarray]],
              title: str, magnification: float = 1.0,
              window: tuple[float, float, float, float] | None = None) -> None:
    """The deformed bodies filled by their elements' von Mises stress, one colour scale for all.

    ``bodies``: (name, points (n, 2), cells (m, k) point numbers around each cell,
    displacement (n, 2), von Mises stress per cell (m,)). Each body's outline is drawn in its
    own colour and named in the legend. The cells are filled as one image (:func:`_fill`):
    fast on large meshes.
    """
    plt = require_matplotlib()
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize

    cmap = colormaps["viridis"]
    colors = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")
    fig, ax = plt.subplots(figsize=(8.5, 4.6))
    values = [np.asarray(b[4], dtype=float).ravel() for b in bodies]
    finite = np.concatenate([v[np.isfinite(v)] for v in values] + [np.zeros(1)])
    norm = Normalize(vmin=float(finite.min()), vmax=float(finite.max()) or 1.0)
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    deformed = []
    for (_, p, _, u, _) in bodies:
        x = np.asarray(p)[:, :2] + magnification * np.asarray(u)[:, :2]
        lo, hi = np.minimum(lo, x.min(axis=0)), np.maximum(hi, x.max(axis=0))
        deformed.append(x)
    shown = _window(window, lo, hi) if bodies else window
    filled = []
    for j, ((name, _, t, _, _), v, x) in enumerate(zip(bodies, values, deformed)):
        poly = x[np.asarray(t)]
        if window is not None:  # only the cells near the window (large meshes)
            near = _near(poly, window)
            poly, v = poly[near], v[near]
            fine = _fine(poly, window)  # drawn as an image's pixels
            if fine.any():
                _pixels(ax, window, poly[fine], cmap(norm(v[fine])))
            poly, v = poly[~fine], v[~fine]
        filled.append((poly, cmap(norm(v))))
        ax.add_collection(LineCollection(x[_outline(np.asarray(t))],
                                         colors=colors[j % len(colors)], linewidths=1.0,
                                         label=name), autolim=False)
    if filled:
        _fill(ax, shown, filled)
    # a figure shaped like the window (equal axes leave the rest blank)
    ratio = _frame(ax, window, lo, hi)
    fig.set_size_inches(min(12.0, max(5.5, 3.4 * ratio + 2.4)), 4.6)
    ax.set_title(magnified(title, magnification), fontsize=10)
    if bodies:
        fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax,
                     label=f"von Mises stress ({LENGTH})", shrink=0.8, pad=0.02)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.0, -0.15), ncol=4,
              borderaxespad=0.0, title="outlines")
    save(plt, fig, path)


def _fill(ax, window, layers: list[tuple[np.ndarray, np.ndarray]]) -> None:
    """Fill cells as one image over ``window`` (:func:`_image_shape` pixels): ``layers`` of
    (polygons (m, k, 2), colours (m, 4)), later layers over earlier ones. A pixel takes the
    colour of the cell its centre lies in (each polygon a fan of triangles from its first
    point, each triangle filled row by row between its edges); the rest is transparent. Drawn
    as the cells' layer (zorder 1, under the outlines), without antialiasing as a
    PolyCollection filled them before, whose path per cell took 0.33 s to make and draw for
    the 60k cells of a 100k-dof Hertz figure (issue 40); the cost here is the image's."""
    nx, ny = _image_shape(window)
    x0, dx = window[0], (window[1] - window[0]) / nx
    y0, dy = window[2], (window[3] - window[2]) / ny
    image = np.zeros((ny, nx, 4))
    for poly, rgba in layers:
        if not len(poly):
            continue
        k = poly.shape[1]
        # in pixel units (a pixel's centre at integer + 0.5)
        tri = (np.concatenate([poly[:, [0, i, i + 1]] for i in range(1, k - 1)])
               - [x0, y0]) / [dx, dy]  # (t, 3, 2)
        colour = np.tile(np.asarray(rgba, dtype=float), (k - 2, 1))
        # the rows whose centres each triangle spans
        first = np.maximum(np.ceil(tri[:, :, 1].min(axis=1) - 0.5), 0).astype(np.int64)
        last = np.minimum(np.floor(tri[:, :, 1].max(axis=1) - 0.5), ny - 1).astype(np.int64)
        which, row = _runs(first, np.maximum(last - first + 1, 0))
        y = row + 0.5
        # where the row's centre line crosses each edge: the span between the crossings
        left, right = np.full(len(row), np.inf), np.full(len(row), -np.inf)
        for a, b in ((0, 1), (1, 2), (2, 0)):
            ya, yb = tri[which, a, 1], tri[which, b, 1]
            xa, xb = tri[which, a, 0], tri[which, b, 0]
            crosses = (np.minimum(ya, yb) <= y) & (y <= np.maximum(ya, yb)) & (ya != yb)
            with np.errstate(invalid="ignore", divide="ignore"):
                xc = np.where(crosses, xa + (y - ya) * (xb - xa) / (yb - ya), np.nan)
            left = np.fmin(left, xc)
            right = np.fmax(right, xc)
        start = np.maximum(np.ceil(left - 0.5), 0)
        stop = np.minimum(np.floor(right - 0.5), nx - 1)
        ok = np.isfinite(start) & np.isfinite(stop) & (stop >= start)
        run, col = _runs(start[ok].astype(np.int64), (stop[ok] - start[ok]).astype(np.int64) + 1)
        image[row[ok][run], col] = colour[which[ok][run]]
    ax.imshow(image, extent=window, origin="lower", interpolation="nearest", aspect="auto",
              zorder=1)


def _runs(start: np.ndarray, length: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Runs of consecutive integers, run i from ``start[i]``, ``length[i]`` long (>= 0): for
    each of their integers, its run and the integer."""
    run = np.repeat(np.arange(len(start)), length)
    return run, start[run] + np.arange(int(length.sum())) - np.repeat(np.cumsum(length)
                                                                      - length, length)


#: in a close-up (a figure with a window), cells narrower than this many of the image's pixels
#: are drawn as pixels of an image, not as one polygon each: their edges could not be told
#: apart, and a million polygons take seconds to draw (issue 19, item 3: figures at any size)
FINE_CELL_PIXELS = 3.0
#: the columns of that image across the window (about the axes' width in pixels: 8.5 to 12 in
#: figures at 130 dpi)
IMAGE_COLUMNS = 1000


def _near(poly: np.ndarray, window) -> np.ndarray:
    """Which cells (polygons (m, k, 2)) lie near ``window`` (centroids within a fifth of its
    width of it): the cells a close-up draws."""
    cx, cy = poly[..., 0].mean(axis=1), poly[..., 1].mean(axis=1)
    pad = 0.2 * (window[1] - window[0])
    return ((cx > window[0] - pad) & (cx < window[1] + pad)
            & (cy > window[2] - pad) & (cy < window[3] + pad))


def _image_shape(window) -> tuple[int, int]:
    w, h = window[1] - window[0], window[3] - window[2]
    return IMAGE_COLUMNS, max(1, min(IMAGE_COLUMNS, round(IMAGE_COLUMNS * h / max(w, 1e-300))))


def _fine(poly: np.ndarray, window) -> np.ndarray:
    """Which cells are narrower than :data:`FINE_CELL_PIXELS` pixels of the close-up's image."""
    pixel = (window[1] - window[0]) / IMAGE_COLUMNS
    size = np.maximum(np.ptp(poly[..., 0], axis=1), np.ptp(poly[..., 1], axis=1))
    return size < FINE_CELL_PIXELS * pixel


def _pixels(ax, window, poly: np.ndarray, rgba: np.ndarray) -> None:
    """Draw the fine cells ``poly`` (m, k, 2) as an image over ``window``: every pixel holding
    a vertex or the centroid of a cell takes that cell's colour (``rgba``, (m, 4) or one
    colour), the pixels around them (within a cell's width: one pixel) the colour of the
    nearest such pixel; the rest transparent. The cost is that of the image, not the mesh."""
    from scipy import ndimage

    nx, ny = _image_shape(window)
    pts = np.concatenate([poly, poly.mean(axis=1, keepdims=True)], axis=1)  # (m, k + 1, 2)
    ix = np.floor((pts[..., 0] - window[0]) / (window[1] - window[0]) * nx).astype(np.int64)
    iy = np.floor((pts[..., 1] - window[2]) / (window[3] - window[2]) * ny).astype(np.int64)
    cell = np.broadcast_to(np.arange(len(poly))[:, None], ix.shape)
    inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
    owner = np.full((ny, nx), -1, dtype=np.int64)
    owner[iy[inside], ix[inside]] = cell[inside]
    hit = owner >= 0
    if not hit.any():
        return
    covered = ndimage.binary_dilation(hit, structure=np.ones((3, 3), bool))
    nearest = ndimage.distance_transform_edt(~hit, return_distances=False,
                                             return_indices=True)
    owner = owner[nearest[0], nearest[1]]
    colours = np.broadcast_to(np.asarray(rgba, dtype=float), (len(poly), 4))
    image = colours[owner].copy()
    image[~covered, 3] = 0.0
    ax.imshow(image, extent=window, origin="lower", interpolation="nearest",
              aspect="auto", zorder=0.5)


def _outline(cells: np.ndarray) -> np.ndarray:
    """(e, 2) boundary edges of a mesh given by its cells: the edges of one cell only."""
    edges, _, _, count = polygon_edges(np.asarray(cells))
    return edges[count == 1]


def _groups(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The equal rows of ``rows`` (m, k) (integers, each row sorted): (``order``, the rows in
    ascending order (stable); ``start``, where each distinct row begins in ``order``; ``count``,
    how many times it occurs). Pairs are sorted by one integer each: a 1D sort, several times
    faster than np.unique(axis=0) (1.5 s of a 465k-dof Hertz run's figures), in the same
    order."""
    rows = np.asarray(rows, dtype=np.int64).reshape(len(rows), -1)
    if not len(rows):
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, empty
    if rows.shape[1] == 2:
        key = rows[:, 0] * (int(rows[:, 1].max()) + 1) + rows[:, 1]
        order = np.argsort(key, kind="stable")
        same = key[order][1:] == key[order][:-1]
    else:
        order = np.lexsort(rows.T[::-1])
        same = np.all(rows[order][1:] == rows[order][:-1], axis=1)
    start = np.flatnonzero(np.r_[True, ~same])
    return order, start, np.diff(np.append(start, len(rows)))


def once(rows: np.ndarray) -> np.ndarray:
    """The indices (ascending) of the rows of ``rows`` (integers, each row sorted) that occur
    exactly once (a mesh's boundary: the facets of one cell only)."""
    order, start, count = _groups(rows)
    return np.sort(order[start[count == 1]])


def polygon_edges(polygons: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                  np.ndarray]:
    """The edges of polygons (m, k) (each one's k points in turn, the last back to the first),
    each once: ((e, 2) point numbers, the lower first, in ascending order; (e,) a polygon on
    each; (e,) the other polygon on it, -1 where it is on one only or on more than two; (e,)
    how many polygons it is on). A 2D mesh's outline, a 3D surface's folds."""
    polygons = np.asarray(polygons)
    a, b = polygons.ravel(), np.roll(polygons, -1, axis=1).ravel()
    owner = np.repeat(np.arange(len(polygons)), polygons.shape[1])
    pairs = np.column_stack([np.minimum(a, b), np.maximum(a, b)]).astype(np.int64)
    order, start, count = _groups(pairs)
    first = order[start]
    other = np.where(count == 2, owner[order[np.minimum(start + 1, len(order) - 1)]], -1)
    return pairs[first], owner[first], other, count


def history(path: Path, x: np.ndarray, series: dict[str, np.ndarray], xlabel: str, ylabel: str,
            title: str) -> None:
    """Quantities against the step (e.g. the contact force of the gasket's load and unload)."""
    plt = require_matplotlib()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for (name, y), marker in zip(series.items(), ("o-", "s--", "^-", "v--")):
        ax.plot(x, y, marker, ms=4, label=name)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    save(plt, fig, path)


def profiles(path: Path, curves: list[tuple[str, np.ndarray, np.ndarray, np.ndarray,
                                            np.ndarray]],
             xlabel: str, ylabel: str, title: str) -> None:
    """Computed values (markers) against a theory (a line of the same colour), per curve:
    (label, x, y of the nodes, x, y of the theory)."""
    plt = require_matplotlib()
    fig, ax = plt.subplots(figsize=(7.0, 4.4))
    colors = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")
    for (label, x, y, xt, yt), c in zip(curves, colors * (len(curves) // 6 + 1)):
        ax.plot(xt, yt, "-", color=c, lw=1.2)
        ax.plot(x, y, "o", ms=3.5, mfc="none", color=c, label=label)
    _finish_profiles(plt, fig, ax, path, xlabel, ylabel, title)


def _finish_profiles(plt, fig, ax, path: Path, xlabel: str, ylabel: str, title: str,
                     legend_size: int = 8) -> None:
    """A profile figure's zero line, labels, title, grid and legend beside the axes; saved."""
    ax.axhline(0, color="0.7", lw=0.8)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=legend_size, **OUTSIDE)
    save(plt, fig, path)


def friction_profiles(path: Path, bodies: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
                      title: str,
                      limits: dict[str, tuple[np.ndarray, list[tuple[str, float]]]] | None = None
                      ) -> None:
    """The tangential traction against x per body: (x, signed traction, status 1 stick or 2
    slip) of the nodes in contact; sticking nodes filled, slipping ones open. ``limits``: per
    body, the normal traction q at those nodes and the coefficients of its law, each (what it
    is, mu): drawn as the lines +mu q and -mu q beside the traction (the Coulomb limit: a
    slipping node lies on it, a sticking one within)."""
    plt = require_matplotlib()
    fig, ax = plt.subplots(figsize=(9.0, 4.4))
    colors = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")
    for (name, (x, s, status)), c in zip(bodies.items(), colors * (len(bodies) // 6 + 1)):
        if not len(x):
            continue
        order = np.argsort(x, kind="stable")
        q, coefficients = (limits or {}).get(name, (None, []))
        for (what, mu), ls in zip(coefficients, ("--", ":", "-.")):
            bound = mu * np.asarray(q, dtype=float)[order]
            ax.plot(x[order], bound, ls, color=c, lw=1.0, alpha=0.8,
                    label=f"{name}: ±{what.replace(' q', f' q = {mu:g} q', 1)}")
            ax.plot(x[order], -bound, ls, color=c, lw=1.0, alpha=0.8)
        ax.plot(x[order], s[order], "-", color=c, lw=0.8)
        for code, fill, what in ((1, c, "sticks"), (2, "none", "slips")):
            pick = status == code
            if pick.any():
                ax.plot(x[pick], s[pick], "o", ms=4, mfc=fill, color=c, label=f"{name}: {what}")
    _finish_profiles(plt, fig, ax, path, f"x, undeformed ({LENGTH})",
                     f"tangential traction, sign of its x part ({LENGTH})", title)


def contact_pressure_profiles(path: Path, bodies: dict[str, list[tuple[str, np.ndarray,
                                                                    np.ndarray]]],
                              title: str, xlabel: str = f"x, undeformed ({LENGTH})",
                              ylabel: str = f"nominal contact pressure ({LENGTH})") -> None:
    """Contact pressure against x, per body: the last profile of each body bold, the ones
    before it as lighter lines of the same colour.

    ``bodies``: name -> profiles (label, x, pressure), oldest first; the last one is emphasized.
    A body without nodes in contact is listed in the legend as such.
    """
    plt = require_matplotlib()
    colors = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")
    fig, ax = plt.subplots(figsize=(8.5, 4.2))
    markers = ("o", "s", "^", "v", "D", "x")
    for j, (name, profiles) in enumerate(bodies.items()):
        c = colors[j % len(colors)]
        if not profiles or all(len(x) == 0 for _, x, _ in profiles):
            ax.plot([], [], color=c, label=f"{name}: no node in contact")
            continue
        *before, (label, x, p) = profiles
        if len(x) == 0:
            label += ": no node in contact"
        for k, (lab, xb, pb) in enumerate(before):
            # with a marker: a step with a single node in contact is a point, which a line
            # alone does not draw (the legend would name a step the plot does not show)
            order = np.argsort(xb, kind="stable")
            ax.plot(np.asarray(xb)[order], np.asarray(pb)[order], "-", color=c, lw=0.8,
                    marker=".", ms=3, alpha=0.25 + 0.45 * (k + 1) / (len(before) + 1),
                    label=f"{name}: {lab}" + ("" if len(xb) else ": no node in contact"))
        order = np.argsort(x, kind="stable")
        ax.plot(np.asarray(x)[order], np.asarray(p)[order], "-", color=c, lw=1.4,
                marker=markers[j % len(markers)], ms=4, mfc="none", label=f"{name}: {label}")
    _finish_profiles(plt, fig, ax, path, xlabel, ylabel, title, legend_size=7)


def history_panels(path: Path, panels: list[tuple[str, dict[str, tuple[np.ndarray, np.ndarray]],
                                                  bool]],
                   xlabel: str, title: str) -> None:
    """Several quantities against the step, one panel each, stacked with a shared x axis.

    ``panels``: (ylabel, series name -> (x, y), logarithmic y axis). On a logarithmic axis,
    values <= 0 are left out (a panel with none left stays linear). Each panel's legend
    stands beside it (:data:`OUTSIDE`), never over its curves (inside, at "upper right", it
    covered the last points of a curve that ends high: the tangential reaction of a slide,
    the contact force of a held load).
    """
    plt = require_matplotlib()
    from matplotlib.ticker import MaxNLocator

    fig, axes = plt.subplots(len(panels), 1, figsize=(8.6, 2.4 * len(panels) + 0.8),
                             sharex=True, squeeze=False)
    for ax, (ylabel, series, log) in zip(axes[:, 0], panels):
        positive = False
        for (name, (x, y)), marker in zip(series.items(), ("o-", "s--", "^-", "v--", "D-")):
            x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
            if log:
                keep = y > 0
                positive |= bool(keep.any())
                if not keep.all():
                    name += " (values <= 0 not drawn)"
                x, y = x[keep], y[keep]
            ax.plot(x, y, marker, ms=4, label=name)
        if log and positive:
            ax.set_yscale("log")
        elif all(np.all(np.mod(y, 1) == 0) for _, y in series.values()):
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_ylabel(ylabel, fontsize=8)
        ax.grid(alpha=0.3, which="both")
        if series:
            ax.legend(fontsize=7, **OUTSIDE)
    axes[-1, 0].set_xlabel(xlabel)
    axes[-1, 0].xaxis.set_major_locator(MaxNLocator(integer=True))
    fig.suptitle(title, fontsize=10)
    save(plt, fig, path)


def benchmark_times(path: Path, rows: list[dict], title: str) -> None:
    """Wall time against dofs, log-log: each (method, backend) solve next to the plain linear
    solve of the same mesh with the same backend (dashed), from ``vfem bench`` rows."""
    plt = require_matplotlib()
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    series: dict[tuple[str, str], list[dict]] = {}
    for r in rows:
        series.setdefault((r["method"], r["backend"]), []).append(r)
    colours = {}
    for (method, backend), rs in series.items():
        rs = sorted(rs, key=lambda r: r["dofs"])
        n = [r["dofs"] for r in rs]
        colour = colours.setdefault(backend, f"C{len(colours)}")
        marker = {"vfem": "o", "penalty": "s", "lagrange": "^", "augmented": "v"}.get(method, "x")
        ax.loglog(n, [r["vfem_s"] for r in rs], marker + "-", color=colour,
                  label=f"{method}, {backend}")
        if method == "vfem":
            ax.loglog(n, [r["plain_solve_s"] for r in rs], marker + "--", color=colour,
                      alpha=0.6, mfc="none", label=f"plain linear solve, {backend}")
    ax.set_xlabel("dofs (both bodies)")
    ax.set_ylabel("wall time (s)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=10)
    save(plt, fig, path)
