#!/usr/bin/env bash
# Configures and builds kdet into build/ with the `release` preset of CMakePresets.json (CUDA is added
# automatically when nvcc is found). Extra arguments go to the configure step, e.g. -DKDET_WARNINGS_AS_ERRORS=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release "$@" >/dev/null
cmake --build --preset release -j"$(nproc)"
