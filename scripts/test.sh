#!/usr/bin/env bash
# The whole test suite: install, build with warnings as errors, run every test on the CPU backend.
# When nvcc exists the CUDA backend is compiled too; its tests run on a GPU and report "skipped" without one.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DKDET_WARNINGS_AS_ERRORS=ON
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 1800
