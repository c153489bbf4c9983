#!/usr/bin/env bash
# One command on a fresh Debian machine: install, build, and run the main job on the built-in scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
./build/kdet bench "$@"
