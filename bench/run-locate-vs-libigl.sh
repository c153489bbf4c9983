#!/usr/bin/env bash
# Point location against libigl and VTK (bench/locate_vs_libigl.py): a virtual environment in
# build-bench-locate/ with libigl, VTK and NumPy from PyPI and kdet's Python package built from this tree
# (or, with KDET_PYTHONPATH set, a kdet package already built there). Arguments go to the script.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=build-bench-locate/venv
[[ -x $venv/bin/python ]] || python3 -m venv "$venv"
pip=("$venv/bin/python" -m pip --disable-pip-version-check)
"${pip[@]}" install -q --timeout 60 numpy libigl vtk
if [[ -n ${KDET_PYTHONPATH:-} ]]; then
  export PYTHONPATH="$KDET_PYTHONPATH"
elif ! "$venv/bin/python" -c "import kdet" 2>/dev/null; then
  "${pip[@]}" install -q . --config-settings=build-dir=build-bench-locate/cmake
fi
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'); commit $(git rev-parse --short HEAD)"
echo "libigl $("$venv/bin/python" -m pip show libigl 2>/dev/null | sed -n 's/^Version: //p'), vtk $("$venv/bin/python" -m pip show vtk 2>/dev/null | sed -n 's/^Version: //p'), kdet $("$venv/bin/python" -c 'import kdet; print(kdet.__version__)')"
"$venv/bin/python" bench/locate_vs_libigl.py "$@"
