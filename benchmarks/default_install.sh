#!/bin/bash
# The default install on a fresh virtual environment (issue 39): which linear solver
# `pip install -e .` gives, and the wall time of hertz, circular_punch and sphere with it, then
# with SciPy's SuperLU alone (PARDISO and MKL uninstalled: the install before issue 39).
#
#     bash benchmarks/default_install.sh [VENV]      (default /tmp/vfem-default-install)
#
# Prints one line per run: backend, example, exit status, wall seconds (the process's, Python's
# start included) and the run's own closing line. Needs the network or a wheel cache for the
# install; the venv is made afresh.
set -u
venv=${1:-/tmp/vfem-default-install}
root=$(cd "$(dirname "$0")/.." && pwd)
rm -rf "$venv" && python3 -m venv "$venv" || exit 1
"$venv/bin/python" -m pip install -q -e "$root" || exit 1
out=$(mktemp -d)
for label in default superlu-alone; do
  if [ "$label" = superlu-alone ]; then
    "$venv/bin/python" -m pip uninstall -q -y pypardiso mkl intel-openmp tbb tcmlib umf \
      >/dev/null 2>&1
  fi
  echo "$label: vfem.linalg chooses $("$venv/bin/python" -c 'import vfem.linalg as l; print(l.resolve())')"
  for ex in hertz circular_punch sphere; do
    start=$(date +%s.%N)
    "$venv/bin/vfem" run "$ex" --no-figures --out "$out/$label/$ex" > "$out/$label.$ex.log" 2>&1
    rc=$?
    end=$(date +%s.%N)
    printf '%s %s rc=%d wall %.1f s; %s\n' "$label" "$ex" "$rc" \
      "$(python3 -c "print($end - $start)")" "$(grep -m1 '^vfem: .*contact iteration' "$out/$label.$ex.log")"
  done
done
