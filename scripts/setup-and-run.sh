#!/usr/bin/env bash
# One command on a fresh Debian machine: install, build, install the Python package into .venv, and run
# the main job on the built-in scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
source scripts/compiler-cache.sh
bash scripts/build.sh
# The Python package (import kdet) in .venv; the main job does not need it, so a failure only warns.
if [[ ! -x .venv/bin/python ]] || ! .venv/bin/python -c "import kdet" 2>/dev/null; then
  { python3 -m venv .venv && PATH="$PATH:/usr/local/cuda/bin" .venv/bin/python -m pip install -q --timeout 60 . &&
    echo "Python package installed: .venv/bin/python -c 'import kdet' (or source .venv/bin/activate)"; } ||
    echo "warning: the Python package was not installed into .venv (see README, Python)" >&2
fi
./build/kdet bench "$@"
