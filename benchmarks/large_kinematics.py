"""Wall time of the large-kinematics examples, source trees alternated in one session.

    python benchmarks/large_kinematics.py                       # this tree only
    python benchmarks/large_kinematics.py --tree before=/tmp/old/src --repeat 3

Each case is ``vfem run`` of a built-in example in a fresh process (imports, figures and
output included: what a user waits for), one tree after the other, ``--repeat`` rounds; it
prints every time, the median per tree and, against the first tree, the ratio of the medians,
and whether the printed answers agree (the run's lines without its times and folder, and its
exit status; trees whose summaries print other lines differ there: ``benchmarks/answers.py``
compares the numbers themselves). Issue 19's aim: the sliding example and the large gasket
three times faster than at 7d8849a.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CASES = {
    "sliding": ["sliding"],
    # the large gasket as docs/examples.md runs it, but with the backs moving 0.4 instead of
    # 0.5: at 0.5 the trees since fd4de95 stop at step 11, where the independent invariant
    # (b) finds a node 1.4e-4 inside (the limit), so their times are not comparable with
    # 7d8849a's 20 steps; at 0.4 every tree runs all 20
    "gasket_large": ["gasket", "--set", "kinematics=total", "--set", "order=1", "--set",
                     "n_through=3", "--set", "back_motion=0.4"],
}

HERE = Path(__file__).resolve().parents[1] / "src"


def run(tree: Path, args: list[str], out: Path) -> tuple[float, str]:
    """Seconds of ``vfem run`` with ``tree`` first on the path, and its printed answers."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    t0 = time.perf_counter()
    code = "from vfem.cli import main; raise SystemExit(main())"
    done = subprocess.run([sys.executable, "-c", code, "run", *args, "--out", str(out)],
                          env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    # the answers: every printed line without times and paths
    lines = [re.sub(r"\d+(\.\d+)? s\b", "", ln) for ln in done.stdout.splitlines()
             if not ln.strip().startswith("results:") and " results in " not in ln]
    return seconds, "\n".join(lines) + f"\nexit {done.returncode}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tree", action="append", default=[], metavar="NAME=SRC",
                    help="another source tree (its src folder); the first is the reference")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("cases", nargs="*", default=list(CASES))
    a = ap.parse_args()
    trees = dict(t.split("=", 1) for t in a.tree)
    trees["this tree"] = str(HERE)
    times: dict[tuple[str, str], list[float]] = {}
    answers: dict[tuple[str, str], str] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(a.repeat):
            for case in a.cases:
                for name, src in trees.items():
                    out = Path(tmp) / f"{case}-{len(times)}-{r}"
                    s, ans = run(Path(src), CASES[case], out)
                    times.setdefault((case, name), []).append(s)
                    answers[(case, name)] = ans
                    print(f"round {r + 1}  {case:13s} {name:12s} {s:7.2f} s", flush=True)
    first = next(iter(trees))
    print(f"\n{'case':13s} {'tree':12s} {'median':>8s} {'ratio':>7s}  answers")
    for case in a.cases:
        ref = statistics.median(times[(case, first)])
        for name in trees:
            m = statistics.median(times[(case, name)])
            same = "same" if answers[(case, name)] == answers[(case, first)] else "DIFFER"
            print(f"{case:13s} {name:12s} {m:7.2f}s {ref / m:6.2f}x  {same}")
    for case in a.cases:  # show what differs
        for name in trees:
            if answers[(case, name)] != answers[(case, first)]:
                print(f"\n--- {case}, {first}:\n{answers[(case, first)]}\n--- {name}:\n"
                      f"{answers[(case, name)]}")


if __name__ == "__main__":
    main()
