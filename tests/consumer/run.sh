#!/usr/bin/env bash
# Builds tests/consumer, a project outside kdet's tree, in a fresh folder and checks that it reports the
# same colliding pairs as the `kdet` command on the two meshes it writes.
#   run.sh installed BUILD WORK      installs BUILD into WORK/prefix (and checks the installed files:
#                                    no path of this machine's source or build tree, no private header),
#                                    then builds the consumer with find_package(kdet) against it
#   run.sh subdirectory BUILD WORK   builds the consumer with kdet's source tree as add_subdirectory
# BUILD is a configured and built kdet build folder (its `kdet` command is the reference of the second
# form); WORK is emptied first. CMAKE (default: cmake) is the cmake to use.
set -euo pipefail
mode="$1"
build="$(cd "$2" && pwd)"
work="$3"
source="$(cd "$(dirname "$0")/../.." && pwd)"
cmake="${CMAKE:-cmake}"
rm -rf "$work"
mkdir -p "$work/out"
work="$(cd "$work" && pwd)"
cuda_path=(); [[ -d /usr/local/cuda/bin ]] && cuda_path=("PATH=$PATH:/usr/local/cuda/bin")

case "$mode" in
installed)
  "$cmake" --install "$build" --prefix "$work/prefix" >/dev/null
  # The installed files must not point back into this machine's trees (a package is relocatable).
  if leaks="$(grep -rlF -e "$source" -e "$build" "$work/prefix")"; then
    echo "installed files name the source or build tree:" >&2
    echo "$leaks" >&2
    exit 1
  fi
  if private="$(grep -rnE '#include +"|src/' "$work/prefix/include")"; then
    echo "installed headers reach past include/kdet:" >&2
    echo "$private" >&2
    exit 1
  fi
  if [[ -d "$work/prefix/include/kdet" ]] && ls "$work/prefix/include/kdet" | grep -qE '^(scenes|prepare)\.hpp$'; then
    echo "the benchmark harness's headers were installed" >&2
    exit 1
  fi
  env "${cuda_path[@]}" "$cmake" -S "$source/tests/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
  kdet="$work/prefix/bin/kdet"
  ;;
subdirectory)
  # kdet is compiled again inside the consumer, with the build type and warning flags of BUILD: the same
  # compile commands, which a compiler cache (scripts/test.sh sets ccache when it exists) answers.
  settings=()
  for name in CMAKE_BUILD_TYPE KDET_WARNINGS_AS_ERRORS; do
    value="$(sed -n "s/^$name:[A-Z]*=//p" "$build/CMakeCache.txt")"
    [[ -n "$value" ]] && settings+=("-D$name=$value")
  done
  env "${cuda_path[@]}" "$cmake" -S "$source/tests/consumer" -B "$work/build" -DKDET_SOURCE_DIR="$source" \
    "${settings[@]}" >/dev/null
  kdet="$build/kdet"
  ;;
*)
  echo "usage: run.sh installed|subdirectory BUILD WORK" >&2
  exit 2
  ;;
esac
"$cmake" --build "$work/build" -j"$(nproc)" >/dev/null
"$work/build/consumer" "$work/out"
"$kdet" collide "$work/out/a.mesh" "$work/out/b.mesh" --pairs "$work/out/expected.txt" >/dev/null
if ! cmp -s "$work/out/expected.txt" "$work/out/pairs.txt"; then
  echo "the consumer's pairs differ from kdet collide's:" >&2
  diff "$work/out/expected.txt" "$work/out/pairs.txt" | head >&2
  exit 1
fi
[[ -s "$work/out/pairs.txt" ]] || { echo "no colliding pairs: the meshes were meant to overlap" >&2; exit 1; }
if [[ -x "$work/build/consumer_mpi" ]]; then
  OMP_NUM_THREADS=1 mpirun -np 2 --oversubscribe --allow-run-as-root "$work/build/consumer_mpi" "$work/out" >/dev/null
  if ! cmp -s "$work/out/expected.txt" "$work/out/pairs_mpi.txt"; then
    echo "the consumer's distributed pairs differ from kdet collide's:" >&2
    diff "$work/out/expected.txt" "$work/out/pairs_mpi.txt" | head >&2
    exit 1
  fi
  echo "$mode: kdet::mpi on 2 ranks: the same pairs"
fi
echo "$mode: $(wc -l <"$work/out/pairs.txt") pairs, the same as kdet collide's"
