"""How to write the VTU files (issue 19, item 5): meshio's encodings measured on one body's step
as vfem writes it (points, quadrilaterals, seven point fields, five cell fields), at a few sizes.

    python benchmarks/vtu_output.py [--points 100000 1000000] [--repeat 3]

For each encoding (binary raw, binary zlib at meshio's level and at vfem's,
``vfem.io.files.VTU_ZLIB_LEVEL``, binary lzma) it prints the write time, the
file size and the time meshio takes to read it back (a stand-in for ParaView's reader, which also
has to inflate compressed blocks), medians of ``--repeat`` runs.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import meshio
import numpy as np

from vfem.io.files import vtu_compression

ENCODINGS = {"binary, raw": dict(binary=True, compression=None),
             "binary, zlib level 6 (meshio's)": dict(binary=True, compression="zlib"),
             "binary, zlib level 1 (vfem's)": dict(binary=True, compression="zlib", level=1),
             "binary, lzma": dict(binary=True, compression="lzma")}


def mesh(points: int) -> meshio.Mesh:
    n = int(np.sqrt(points))
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    p = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * n)])
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).ravel()
    quads = np.column_stack([a, a + 1, a + n + 1, a + n])
    rng = np.random.default_rng(0)
    vec = rng.normal(size=(n * n, 3)) * 1e-3
    point_data = {"displacement": vec, "contact_force": np.zeros_like(vec),
                  "contact_pressure": np.zeros(n * n), "contact_traction": np.zeros(n * n),
                  "contact_status": np.zeros(n * n, dtype=np.int32),
                  "penetration": np.zeros(n * n), "reaction": np.zeros_like(vec)}
    cells = len(quads)
    cell_data = {k: [rng.normal(size=cells) * 1e6] for k in ("sxx", "syy", "sxy", "szz",
                                                             "von_mises")}
    return meshio.Mesh(p, [("quad", quads)], point_data=point_data, cell_data=cell_data)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, nargs="+", default=[100_000, 1_000_000])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        for points in args.points:
            m = mesh(points)
            print(f"{len(m.points)} points, {len(m.cells[0].data)} cells:")
            for name, encoding in ENCODINGS.items():
                path = Path(tmp) / "body.vtu"
                write, read = [], []
                for _ in range(args.repeat):
                    options = dict(encoding)
                    level = options.pop("level", None)
                    t0 = time.perf_counter()
                    if level is None:
                        meshio.vtu.write(path, m, **options)
                    else:
                        with vtu_compression(level):
                            meshio.vtu.write(path, m, **options)
                    t1 = time.perf_counter()
                    meshio.read(path)
                    t2 = time.perf_counter()
                    write.append(t1 - t0)
                    read.append(t2 - t1)
                size = path.stat().st_size / 2**20
                print(f"  {name:32s} write {statistics.median(write):7.3f} s  "
                      f"read {statistics.median(read):7.3f} s  {size:8.1f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
