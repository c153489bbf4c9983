#!/usr/bin/env bash
# Builds and runs the libFuzzer harnesses of the mesh readers and the scene-file reader: clang++ with the
# address and undefined behaviour sanitizers, one harness per format (fuzz_reader.cpp with
# KDET_FUZZ_EXTENSION; fuzz_scene.cpp for `scene`). ctest calls:
#   run_fuzzers.sh build SOURCE_DIR BUILD_DIR CXX        compile the io sources and every harness
#   run_fuzzers.sh run BUILD_DIR FORMAT SECONDS SEED_DIR  fuzz one format for SECONDS from SEED_DIR/FORMAT
#   run_fuzzers.sh skip REASON                            report the test skipped
# Exit code 77 means skipped (the tests' SKIP_RETURN_CODE); a finding fails with libFuzzer's report.
set -euo pipefail
readonly skipped=77
readonly formats=(msh vtk mesh node obj off stl ply xyz) # fuzz_reader.cpp's; `scene` is built on its own

build() {
  local src=$1 out=$2 cxx=$3
  local flags=(-std=c++17 -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined
               -fno-sanitize-recover=undefined -I"$src/include" -I"$src/src" -I"$src/src/scenes/include")
  local stamp="$out/fuzzers.stamp"
  # Rebuild everything when any input is newer than the last build: a handful of files, no need for more.
  if [[ -e $stamp ]] && [[ -z $(find "$src/src/io" "$src/src/scenes" "$src/include/kdet" "$src/tests/fuzz" -newer "$stamp" -print -quit) ]]; then
    echo "fuzzers up to date"
    return
  fi
  mkdir -p "$out/obj"
  local objects=() pids=()
  for source in "$src"/src/io/*.cpp; do
    local object="$out/obj/$(basename "${source%.cpp}").o"
    objects+=("$object")
    "$cxx" "${flags[@]}" -fsanitize=fuzzer-no-link -c "$source" -o "$object" &
    pids+=($!)
    # Two compilers at a time: the machines that run the tests are small.
    if ((${#pids[@]} == 2)); then wait "${pids[0]}"; pids=("${pids[@]:1}"); fi
  done
  for pid in "${pids[@]}"; do wait "$pid"; done
  "$cxx" "${flags[@]}" -fsanitize=fuzzer "$src/tests/fuzz/fuzz_scene.cpp" "$src/src/scenes/scene_file.cpp" \
    -o "$out/fuzz_scene"
  for format in "${formats[@]}"; do
    "$cxx" "${flags[@]}" -fsanitize=fuzzer "-DKDET_FUZZ_EXTENSION=\".$format\"" \
      "$src/tests/fuzz/fuzz_reader.cpp" "${objects[@]}" -o "$out/fuzz_$format"
  done
  touch "$stamp"
}

run() {
  local out=$1 format=$2 seconds=$3 seeds=$4
  if [[ ! -x $out/fuzz_$format ]]; then
    echo "skipped: $out/fuzz_$format was not built (see the fuzz_build test)"
    exit $skipped
  fi
  # libFuzzer adds what it finds to the corpus folder: work on a copy so every run starts from the seeds.
  corpus=$(mktemp -d) # global: the exit trap runs after this function returns
  trap 'rm -rf "$corpus"' EXIT
  cp -r "$seeds/$format/." "$corpus"
  # A malloc above -malloc_limit_mb is reported as a finding: an absurd header count must not allocate.
  "$out/fuzz_$format" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512 \
    -print_final_stats=1 -artifact_prefix="$out/finding_${format}_" "$corpus"
}

case ${1:-} in
  build) build "$2" "$3" "$4" ;;
  run) run "$2" "$3" "$4" "$5" ;;
  skip) echo "skipped: $2"; exit $skipped ;;
  *) echo "usage: $0 build SOURCE_DIR BUILD_DIR CXX | run BUILD_DIR FORMAT SECONDS SEED_DIR | skip REASON" >&2; exit 2 ;;
esac
