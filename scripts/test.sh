#!/usr/bin/env bash
# The whole test suite. Builds the library, tool and tests with AddressSanitizer and
# UndefinedBehaviorSanitizer and runs the tests under them (the slow thesis-scene and prepare tests, which
# add no new code paths, excepted), with the viewer left out so that its one-line refusal is tested too;
# then builds normally with warnings as errors and runs every test with
# ctest. When nvcc exists the CUDA backend is compiled too; its tests run on a GPU and report "skipped"
# without one.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh

cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKDET_ENABLE_CUDA=OFF -DKDET_BUILD_BENCHMARKS=OFF \
  -DKDET_BUILD_VIEWER=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined" >/dev/null
cmake --build build-sanitize -j"$(nproc)" --target kdet_tests kdet_cli
echo "== the tests under AddressSanitizer and UndefinedBehaviorSanitizer"
KDET_DATA_DIR="${KDET_DATA_DIR:-$PWD/../shared/models}" build-sanitize/tests/kdet_tests \
  --gtest_filter='-Models/RealMesh.*bunny*:Models/RealMesh.*hand*:Prepare.*:*Thesis*'

echo "== every test, optimised build"
bash scripts/build.sh -DKDET_WARNINGS_AS_ERRORS=ON
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 1800
