#!/usr/bin/env bash
# The whole test suite. Builds the library, tool and tests with AddressSanitizer and
# UndefinedBehaviorSanitizer and runs the tests under them (the slow thesis-scene and prepare tests, which
# add no new code paths, excepted), with the viewer left out so that its one-line refusal is tested too;
# then builds normally with warnings as errors, tests the Python package in a fresh virtual environment
# (scripts/test-python.sh), and runs every C++ test with ctest, including the projects built against the
# installed package and with add_subdirectory (tests/consumer). When nvcc exists the CUDA backend is
# compiled too; its tests run on a GPU and report "skipped" without one.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
source scripts/compiler-cache.sh

# Presets (CMakePresets.json): asan builds into build-sanitize/ (viewer off), release into build/.
cmake --preset asan >/dev/null
cmake --build --preset asan -j"$(nproc)" --target kdet_tests kdet_cli
echo "== the tests under AddressSanitizer and UndefinedBehaviorSanitizer"
KDET_DATA_DIR="${KDET_DATA_DIR:-$PWD/../shared/models}" build-sanitize/tests/kdet_tests \
  --gtest_filter='-Models/RealMesh.*bunny*:Models/RealMesh.*hand*:Prepare.*:*Thesis*'

echo "== every test, optimised build"
bash scripts/build.sh -DKDET_WARNINGS_AS_ERRORS=ON
# The Python package in a fresh virtual environment (pip wheel ., pip install ., pytest), checked against build/kdet.
bash scripts/test-python.sh
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 1800
