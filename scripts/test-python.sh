#!/usr/bin/env bash
# The Python package's tests, in a fresh virtual environment (build-python/venv), as a user installs it:
# `pip wheel .` builds the wheel (its contents are checked), `pip install .` installs the package, and
# pytest runs python/tests, which compare the pairs with those of the C++ command build/kdet (or
# $KDET_CLI) on the models in ../shared/models (or $KDET_DATA_DIR). Both pip calls share one CMake
# build folder (build-python/cmake), so the library is compiled once (--config-settings, not -C: Debian's
# pip 23.0 lacks the short form). pytest, Hypothesis (the property-based tests), meshio and matplotlib
# come from PyPI. Extra arguments go to pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$PATH:/usr/local/cuda/bin"
export KDET_CLI="${KDET_CLI:-$PWD/build/kdet}"
export KDET_DATA_DIR="${KDET_DATA_DIR:-$PWD/../shared/models}"
[[ -x "$KDET_CLI" ]] || { echo "test-python: $KDET_CLI not found; build first (scripts/build.sh) or set KDET_CLI" >&2; exit 1; }

venv=build-python/venv
rm -rf "$venv" build-python/dist
python3 -m venv "$venv"
python=("$venv/bin/python")
pip=("${python[@]}" -m pip --disable-pip-version-check)
"${pip[@]}" install -q --timeout 60 pytest hypothesis meshio matplotlib
# Warnings are errors here as in build/ (the bindings are held to them too), which also keeps the library's
# compile commands equal to build/'s for a compiler cache (scripts/compiler-cache.sh).
settings=(--config-settings=build-dir=build-python/cmake --config-settings=cmake.define.KDET_WARNINGS_AS_ERRORS=ON)

"${pip[@]}" wheel -q --timeout 60 . -w build-python/dist "${settings[@]}"
"${python[@]}" - build-python/dist <<'PY'
import pathlib, sys, zipfile
wheel, = pathlib.Path(sys.argv[1]).glob("kdet-*.whl")
names = zipfile.ZipFile(wheel).namelist()
wanted = ["kdet/__init__.py", "kdet/py.typed", "kdet/_kdet.pyi"]
missing = [n for n in wanted if n not in names] + ([] if any(n.startswith("kdet/_kdet.") and n.endswith(".so") for n in names) else ["kdet/_kdet*.so"])
stray = [n for n in names if not n.startswith(("kdet/", "kdet-"))]
if missing or stray:
    sys.exit(f"{wheel.name}: missing {missing}, not part of the package {stray}")
print(f"{wheel.name}: {len(names)} files, stubs and extension included, nothing else")
PY
"${pip[@]}" install -q . "${settings[@]}"
echo "== the Python package's tests"
"${python[@]}" -m pytest -rs python/tests "$@"
