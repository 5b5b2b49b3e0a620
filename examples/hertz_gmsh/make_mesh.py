"""Build the Hertz example's two bodies with Gmsh and write them to one ``.msh`` (format 4.1).

The geometry is that of the built-in example (``vfem_examples.hertz``, ``vfem.mesh.parametric``):

* ``cylinder``: the lower-right quarter of a disc of radius 1 centred at (0, 1), touching the x
  axis at the origin; triangles. Physical curves ``contact`` (the arc from (0, 0) to (1, 1)),
  ``symmetry`` (x = 0) and ``top`` (y = 1).
* ``flat``: the layer [0, 1] x [-0.1, 0]; quadrilaterals (``flat_quads=False``: triangles).
  Physical curves ``surface`` (y = 0), ``bottom`` (y = -0.1) and ``symmetry`` (x = 0).

``symmetry`` is one physical curve holding the x = 0 edges of both bodies:
:func:`vfem.mesh.imports.read_mesh` gives each body the part of it that lies on its own boundary.
The bodies are separate geometric entities and share no node: each has its own node at the
origin, where they touch.

Element sizes follow the built-in meshes: a Distance + Threshold field from the origin, size
``size`` (default a / ``facets_per_half_width``, a = 0.061168 the Hertz half-width) within 1.5 a,
then growing with slope ``growth`` up to ``max_size``; the flat's sizes near the origin are
``flat_size_ratio`` times the cylinder's (non-matching meshes).

Usage::

    python3 examples/hertz_gmsh/make_mesh.py [--out examples/hertz_gmsh/hertz.msh]
                                             [--facets-per-half-width 12]

then read each body with ``read_mesh(path, cells="cylinder")`` / ``cells="flat"``.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

HALF_WIDTH = 0.061168  # Hertz's contact half-width of the built-in example (vfem_examples.hertz)


def build(path: str | os.PathLike, size: float | None = None, *,
          facets_per_half_width: int = 12, max_size: float = 0.05, growth: float = 0.15,
          flat_size_ratio: float = 1.37, plateau: float = 1.5 * HALF_WIDTH,
          radius: float = 1.0, flat_width: float = 1.0, flat_thickness: float = 0.1,
          flat_quads: bool = True, order: int = 1) -> Path:
    """Mesh the Hertz cylinder and flat with Gmsh and write them to ``path`` (msh 4.1).

    Args:
        path: the ``.msh`` file to write (its folder is created if needed).
        size: the cylinder's element size near the origin; default
            ``HALF_WIDTH / facets_per_half_width``.
        facets_per_half_width: facets across the Hertz half-width when ``size`` is not given.
        max_size: the largest element size, away from the contact (in the flat at most half
            its thickness).
        growth: the slope of the size beyond ``plateau`` (size per unit distance).
        flat_size_ratio: the flat's size near the origin over the cylinder's.
        plateau: the distance from the origin within which the size is ``size``.
        radius, flat_width, flat_thickness: the geometry (defaults: the built-in example's).
        flat_quads: quadrilaterals in the flat (recombined); False: triangles.
        order: 1 (3-node triangles, 4-node quadrilaterals) or 2 (6-node triangles, 9-node
            quadrilaterals, the arc's midpoints on the circle).

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        ImportError: gmsh is not installed (``pip install gmsh``).
    """
    import gmsh

    if order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, not {order}")
    h_cyl = HALF_WIDTH / facets_per_half_width if size is None else float(size)
    h_flat = flat_size_ratio * h_cyl
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("Geometry.AutoCoherence", 0)  # keep the two origins apart
        gmsh.model.add("hertz")
        geo = gmsh.model.geo
        R = radius

        # cylinder: arc (0,0) -> (1,1) about (0,1), top edge back to (0,1), symmetry edge down
        c0 = geo.addPoint(0.0, 0.0, 0.0)
        c_centre = geo.addPoint(0.0, R, 0.0)
        c1 = geo.addPoint(R, R, 0.0)
        arc = geo.addCircleArc(c0, c_centre, c1)
        top = geo.addLine(c1, c_centre)
        cyl_sym = geo.addLine(c_centre, c0)
        cylinder = geo.addPlaneSurface([geo.addCurveLoop([arc, top, cyl_sym])])

        # flat: counter-clockwise from its own origin point
        f0 = geo.addPoint(0.0, 0.0, 0.0)
        f1 = geo.addPoint(0.0, -flat_thickness, 0.0)
        f2 = geo.addPoint(flat_width, -flat_thickness, 0.0)
        f3 = geo.addPoint(flat_width, 0.0, 0.0)
        flat_sym = geo.addLine(f0, f1)
        bottom = geo.addLine(f1, f2)
        right = geo.addLine(f2, f3)
        surface = geo.addLine(f3, f0)
        flat = geo.addPlaneSurface([geo.addCurveLoop([flat_sym, bottom, right, surface])])
        geo.synchronize()

        gmsh.model.addPhysicalGroup(2, [cylinder], name="cylinder")
        gmsh.model.addPhysicalGroup(2, [flat], name="flat")
        gmsh.model.addPhysicalGroup(1, [arc], name="contact")
        gmsh.model.addPhysicalGroup(1, [top], name="top")
        gmsh.model.addPhysicalGroup(1, [surface], name="surface")
        gmsh.model.addPhysicalGroup(1, [bottom], name="bottom")
        gmsh.model.addPhysicalGroup(1, [right], name="right")
        gmsh.model.addPhysicalGroup(1, [cyl_sym, flat_sym], name="symmetry")

        # sizes: h_min within the plateau, then growing linearly with slope `growth`
        field = gmsh.model.mesh.field
        distance = field.add("Distance")
        field.setNumbers(distance, "PointsList", [c0, f0])
        thresholds, restricted = [], []
        for surf, curves, points in ((cylinder, [arc, top, cyl_sym], [c0, c1, c_centre]),
                                     (flat, [flat_sym, bottom, right, surface], [f0, f1, f2, f3])):
            threshold = field.add("Threshold")
            field.setNumber(threshold, "InField", distance)
            only = field.add("Restrict")
            field.setNumber(only, "InField", threshold)
            field.setNumbers(only, "SurfacesList", [surf])
            field.setNumbers(only, "CurvesList", curves)
            field.setNumbers(only, "PointsList", points)
            thresholds.append(threshold)
            restricted.append(only)
        smallest = field.add("Min")
        field.setNumbers(smallest, "FieldsList", restricted)
        field.setAsBackgroundMesh(smallest)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)

        def sizes(threshold: int, h_min: float, h_max: float) -> None:
            h_max = max(h_max, h_min)
            field.setNumber(threshold, "SizeMin", h_min)
            field.setNumber(threshold, "SizeMax", h_max)
            field.setNumber(threshold, "DistMin", plateau)
            field.setNumber(threshold, "DistMax", plateau + (h_max - h_min) / growth + 1e-12)

        flat_max = min(max_size, 0.5 * flat_thickness)  # at least two layers through the flat
        sizes(thresholds[0], h_cyl, max_size)
        if flat_quads:
            gmsh.model.mesh.setRecombine(2, flat)
            gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)  # blossom
        # Blossom may leave triangles: try the 2D algorithms in turn (Frontal-Delaunay for
        # quadrilaterals, Frontal-Delaunay, Delaunay, MeshAdapt), then slightly smaller sizes.
        attempts = [(s, a) for s in (1.0, 0.85, 0.7) for a in (8, 6, 5, 1)] if flat_quads \
            else [(1.0, 6)]
        for scale, algorithm in attempts:
            sizes(thresholds[1], scale * min(h_flat, flat_max), scale * flat_max)
            gmsh.model.mesh.clear()
            if flat_quads:
                # Only a boundary of an even number of edges can be meshed in quadrilaterals:
                # make it even with the number of edges on the far side (x = flat_width).
                gmsh.model.mesh.generate(1)
                others = sum(len(gmsh.model.mesh.getElements(1, c)[1][0])
                             for c in (flat_sym, bottom, surface))
                n_right = max(1, round(flat_thickness / (scale * flat_max)))
                n_right += (others + n_right) % 2
                gmsh.model.mesh.setTransfiniteCurve(right, n_right + 1)
                gmsh.model.mesh.clear()
            gmsh.model.mesh.setAlgorithm(2, flat, algorithm)
            gmsh.model.mesh.generate(2)
            if not flat_quads or list(gmsh.model.mesh.getElements(2, flat)[0]) == [3]:
                break  # (3: the 4-node quadrilateral)
        else:
            raise RuntimeError(f"gmsh left triangles in the flat's quadrilateral mesh at size "
                               f"{h_cyl:g}; try another size or flat_quads=False (--triangles)")
        if order == 2:
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)  # 9-node quadrilaterals
            gmsh.model.mesh.setOrder(2)

        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.SaveAll", 0)  # the elements of physical groups only
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).with_name("hertz.msh")),
                        help="the .msh file to write (default: hertz.msh next to this script)")
    parser.add_argument("--facets-per-half-width", type=int, default=12,
                        help="facets across the Hertz half-width on the cylinder (default 12)")
    parser.add_argument("--order", type=int, choices=(1, 2), default=1,
                        help="element order (default 1)")
    parser.add_argument("--triangles", action="store_true",
                        help="mesh the flat in triangles instead of quadrilaterals")
    args = parser.parse_args(argv)
    try:
        import gmsh  # noqa: F401
    except ImportError:
        print("make_mesh.py needs the gmsh Python package: pip install gmsh", file=sys.stderr)
        return 2
    path = build(args.out, facets_per_half_width=args.facets_per_half_width, order=args.order,
                 flat_quads=not args.triangles)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
