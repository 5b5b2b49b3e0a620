"""Hertz in CalculiX and in vfem on the same meshes: time and p_max error, by refinement.

    python benchmarks/calculix.py [LEVEL ...] [--threads N] [--penalty K] [--ccx PATH]
                                  [--keep DIR] [--json FILE]

Needs ``ccx`` (Debian: calculix-ccx); prints nothing but a note without it. Run it with
``OMP_NUM_THREADS=1`` in the environment for one thread on both sides (``--threads`` sets ccx's).
"""

import argparse
import json
import shutil
import sys

from vfem_tools.bench import calculix_rows

if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("levels", type=int, nargs="*", default=[0, 1, 2])
    ap.add_argument("--threads", type=int, default=1, help="ccx's threads (default 1)")
    ap.add_argument("--penalty", type=lambda t: None if t.lower() == "hard" else float(t),
                    default=1e11, help="contact stiffness (1e11), or hard: ccx's own")
    ap.add_argument("--ccx", default="ccx", help="the CalculiX executable")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per ccx run")
    ap.add_argument("--keep", help="a folder for ccx's files (deck, log, .dat, .frd, .sta)")
    ap.add_argument("--json", help="write the rows to this file")
    args = ap.parse_args()
    if shutil.which(args.ccx) is None:
        sys.exit(f"{args.ccx!r} not found: install CalculiX (apt install calculix-ccx)")
    rows = calculix_rows(args.levels, print_row=print, ccx=args.ccx, threads=args.threads,
                         penalty=args.penalty, timeout=args.timeout, keep=args.keep)
    if rows:
        print(f"ccx: {rows[0]['ccx_solver']} solver, {rows[0]['ccx_threads']} thread(s), "
              f"penalty {'hard' if args.penalty is None else f'{args.penalty:g}'}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
