#!/usr/bin/env bash
# The GPU checks of the CUDA backend on the `device` machine (bundle: scripts/gpu-bundle.sh), in parts
# that each fit one device call of at most 10 minutes:
#   checks   the CUDA tests (GPU pair sets against the CPU backend's), compute-sanitizer memcheck and
#            racecheck on them, and resolution-4 kdet against GPU brute force on the same frames
#   matrix   the thesis benchmark matrix with --backend cuda (scripts/run-thesis-matrix.sh), bounded
#            by MATRIX_MINUTES [8]
#   scaling  the procedural scene from 100k to 4M tets, frames around the deepest one (60)
# usage: scripts/gpu-session.sh checks|matrix|scaling
# Everything goes into $OUT/gpu-<part>.tar.gz, and each step's exit status into $OUT/steps.txt.
# A failing step does not stop the others.
set -uo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
bundle="${KDET_GPU_BUNDLE:-$repo/.gpu-bundle}"
out="${OUT:-$repo/exports/gpu-session}"
work="$(mktemp -d)"
mkdir -p "$out" "$work/models" "$work/cache"
tar -C "$work/models" -xJf "$bundle/models.tar.xz"
tar -C "$work/cache" -xJf "$bundle/cache.tar.xz"
export LD_LIBRARY_PATH="$bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export KDET_DATA_DIR="$work/models" KDET_CACHE_DIR="$work/cache"
kdet="$bundle/kdet"
tests="$bundle/kdet_tests"
part="${1:-}"
case "$part" in
checks | matrix | scaling) ;;
*)
  echo "usage: scripts/gpu-session.sh checks|matrix|scaling" >&2
  exit 2
  ;;
esac
sanitizer="$(command -v compute-sanitizer || ls /usr/local/cuda*/bin/compute-sanitizer 2>/dev/null | head -1)"

step() {
  local name="$1"
  shift
  local start=$SECONDS
  "$@" >"$work/$name.log" 2>&1
  local rc=$?
  echo "$name: exit $rc, $((SECONDS - start)) s" | tee -a "$out/steps.txt"
}

{
  nvidia-smi
  nvcc --version
  "$kdet" --version
} >"$work/device.txt" 2>&1
case "$part" in
checks)
  step tests "$tests" --gtest_filter='Cuda*'
  cuda_filter='CudaBackend.EveryMethodTestAndHashMatchesTheCpuOnSoups:CudaBackend.DevicePositions*'
  step memcheck "${sanitizer:-compute-sanitizer}" --tool memcheck --error-exitcode 1 "$tests" --gtest_filter="$cuda_filter"
  step racecheck "${sanitizer:-compute-sanitizer}" --tool racecheck --error-exitcode 1 "$tests" --gtest_filter="$cuda_filter"
  for method in kdet gpu gpu_no_loop; do
    step "brute-force-r4-$method" "$kdet" bench armadillos -r 4 -s yes -c "$method" -n 1 --frames 80:82 \
      --backend cuda --quiet -d "$work/brute-force-r4"
  done
  ;;
matrix)
  step matrix env KDET="$kdet" RUNS=3 BUDGET_MINUTES="${MATRIX_MINUTES:-8}" BENCH_FLAGS="--backend cuda" \
    "$repo/scripts/run-thesis-matrix.sh" "$work/matrix"
  ;;
scaling)
  for tets in 100000 300000 1000000 2000000 4000000; do
    for self in no yes; do
      step "scaling-$tets-$self" "$kdet" bench procedural --tets "$tets" -s "$self" -n 3 --frames 55:65 \
        --backend cuda --quiet -d "$work/scaling"
    done
  done
  ;;
esac
tar -C "$work" --exclude=models --exclude=cache -czf "$out/gpu-$part.tar.gz" .
