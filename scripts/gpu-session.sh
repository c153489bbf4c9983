#!/usr/bin/env bash
# The GPU checks of the CUDA backend on the `device` machine (bundle: scripts/gpu-bundle.sh). One call
# runs the parts it is given, in order, under one deadline:
#   tests       the CUDA tests (GPU pairs, flags, contacts, distances and point location against the
#               CPU backend's)
#   sanitizers  compute-sanitizer memcheck, racecheck, synccheck and initcheck on the smaller of them
#   r4       the thesis scenes at resolution 4 with --backend cuda, self-collision off and on, and GPU
#            brute force on armadillos r4 at the frames where they touch
#   scaling  the procedural scene from 100k to 4M tets (and 8M), frames around the deepest one (60)
#   peer     kdet against a CUB sort-and-sweep + sat peer on the same frames (bench/gpu_vs_sweep.cu)
#   cubql    kdet against a cuBQL BVH + exact test peer (bench/gpu_vs_cubql.cu): the thesis scenes at
#            resolution 4 and the procedural scene at 1M and 4M tets, self-collision off and on; its
#            CSV also comes back as $OUT/cubql.csv (for bench/results/gpu-DEVICE/cubql-COMMIT.csv)
#   scenes   issue 46's scenes (heap, drape, graded at resolution 1 and 4, pass_through_deep, tearing),
#            self-collision off and on, heap r4 without its collision filters, and a body on a 1M-tet
#            static floor against a 20k-tet one (bench/static_environment.cpp)
#   margin   pairs within a margin (bench/margin_vs_cgal.cpp --backend cuda): the thesis scenes at
#            resolution 4, self-collision off and on, kdet at margin 0, 1 % and 10 % of the median edge
#            side by side, frames 60-64; the CGAL peer checks every frame's pairs once (untimed); its CSV
#            also comes back as $OUT/margin.csv (for bench/results/gpu-DEVICE/margin-COMMIT.csv)
#   mpi      the distributed detector's tests on two ranks, one of them on the CUDA backend of every
#            rank (kdet_mpi_tests under the bundle's Open MPI runtime, TCP between the ranks)
#   locate   point location on the CPU and the GPU in one process, answers compared bit for bit
#            (bench/locate_profile.cpp --backend both): 1M points in a 998,250-tet mesh, all held, and
#            in a box 1.2 times the mesh's with `within` a tet's size and ten
#   profile  each kernel's GPU time in two frames of five cases (Nsight Compute), the heaviest case's
#            occupancy, divergence and cache hits, and the bucket
#            capacity and block size against the automatic choice on armadillos r4
#   compare  the bundle's kdet against the other builds it holds as kdet-NAME (scripts/gpu-bundle.sh
#            COMMIT ... puts them there), two alternating rounds on eleven cases
#   matrix   the thesis benchmark matrix (scripts/run-thesis-matrix.sh) until the deadline
# usage: scripts/gpu-session.sh PART [PART ...]   (e.g. tests r4 sanitizers scaling)
# Settings: KDET_GPU_DEADLINE, seconds after which no step starts and running ones are stopped [500].
# Everything goes into $OUT/gpu-session.tar.gz, each step's exit status and seconds into $OUT/steps.txt,
# and the benchmark summaries are printed last.
set -uo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
bundle="${KDET_GPU_BUNDLE:-$repo/.gpu-bundle}"
out="${OUT:-$repo/exports/gpu-session}"
deadline="${KDET_GPU_DEADLINE:-500}"
(($# > 0)) || { echo "usage: scripts/gpu-session.sh tests|sanitizers|r4|scaling|peer|cubql|scenes|margin|mpi|locate|profile|compare|matrix ..." >&2; exit 2; }
for part in "$@"; do
  case "$part" in
  tests | sanitizers | r4 | scaling | peer | cubql | scenes | margin | mpi | locate | profile | compare | matrix) ;;
  *) echo "gpu-session: unknown part '$part' (tests, sanitizers, r4, scaling, peer, cubql, scenes, margin, mpi, locate, profile, compare, matrix)" >&2; exit 2 ;;
  esac
done
work="$(mktemp -d)"
bin="$work/bin" # the bundle's programs, unpacked
mkdir -p "$out" "$work/models" "$work/cache" "$work/bench" "$bin"
tar -C "$work/models" -xJf "$bundle/models.tar.xz"
tar -C "$work/cache" -xJf "$bundle/cache.tar.xz"
tar -C "$bin" -xJf "$bundle/programs.tar.xz"
[[ ! -f "$bundle/lib.tar.xz" ]] || tar -C "$work" -xJf "$bundle/lib.tar.xz"
export LD_LIBRARY_PATH="$work/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export KDET_DATA_DIR="$work/models" KDET_CACHE_DIR="$work/cache"
kdet="$bin/kdet"
tests="$bin/kdet_tests"
sanitizer="$(command -v compute-sanitizer || ls /usr/local/cuda*/bin/compute-sanitizer 2>/dev/null | head -1)"
nsight_compute="$(command -v ncu || ls /usr/local/cuda*/bin/ncu /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)"

# step NAME LIMIT COMMAND...: runs COMMAND for at most LIMIT seconds (less when the deadline is nearer),
# its output into NAME.log; skipped once the deadline has passed.
step() {
  local name="$1" limit="$2"
  shift 2
  local left=$((deadline - SECONDS))
  if ((left < 5)); then
    echo "$name: not run, deadline" | tee -a "$out/steps.txt"
    return
  fi
  ((limit < left)) || limit=$left
  local start=$SECONDS
  timeout --kill-after=5 "$limit" "$@" >"$work/$name.log" 2>&1
  local rc=$?
  echo "$name: exit $rc, $((SECONDS - start)) s$( ((rc == 124)) && echo " (stopped at $limit s)")" | tee -a "$out/steps.txt"
}

{
  nvidia-smi
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
  nvcc --version
  "$kdet" --version
  cat "$bundle/commit.txt"
} >"$work/device.txt" 2>&1
head -20 "$work/device.txt"

bench() { # NAME LIMIT ARGS...: one kdet bench into bench/
  local name="$1" limit="$2"
  shift 2
  step "$name" "$limit" "$kdet" bench "$@" --backend cuda --quiet -d "$work/bench"
}

for part in "$@"; do
  case "$part" in
  tests)
    # Every test that runs the CUDA backend (a suite or a test named Cuda..., the parameterised
    # cuda_ methods, device positions); not the CLI's, whose program path names this machine's build.
    step tests 200 "$tests" --gtest_filter='Cuda*:*.Cuda*:*/cuda_*:Positions.EveryLayoutInDeviceMemory*:-BenchEndToEnd.*'
    ;;
  sanitizers)
    # The detection frame's kernels, then those of this round's features (proximity, point location,
    # filters, static objects, topology changes), each under its own limit.
    frame='CudaBackend.RealMeshes*:Positions.EveryLayoutInDeviceMemory*'
    features='Locate.Cuda*:Margin.Cuda*:CudaFilters.*:Static.Cuda*:CudaTopology.*'
    for tool in memcheck racecheck synccheck initcheck; do
      step "$tool-frame" 60 "${sanitizer:-compute-sanitizer}" --tool "$tool" --error-exitcode 1 "$tests" --gtest_filter="$frame"
      step "$tool-features" 60 "${sanitizer:-compute-sanitizer}" --tool "$tool" --error-exitcode 1 "$tests" --gtest_filter="$features"
    done
    ;;
  r4)
    for scene in armadillos buddha_and_armadillo bunny_and_planck; do
      for self in no yes; do
        bench "r4-$scene-self-$self" 60 "$scene" -r 4 -s "$self" -n 3
      done
    done
    bench r2-pass_through_armadillos 60 pass_through_armadillos -r 2 -s no -n 3
    for method in gpu gpu_no_loop; do
      bench "r4-armadillos-brute-force-$method" 90 armadillos -r 4 -s yes -c "$method" -n 1 --frames 80:82
    done
    ;;
  scaling)
    for tets in 100000 300000 1000000 2000000 4000000 8000000; do
      for self in no yes; do
        bench "scaling-$tets-$self" 90 procedural --tets "$tets" -s "$self" -n 3 --frames 55:65
      done
    done
    ;;
  scenes)
    for scene in heap drape graded; do
      for r in 1 4; do
        for self in no yes; do
          bench "scenes-$scene-r$r-self-$self" 90 "$scene" -r "$r" -s "$self" -n 3
        done
      done
    done
    for self in no yes; do
      bench "scenes-pass_through_deep-self-$self" 90 pass_through_deep -r 2 -s "$self" -n 3
      bench "scenes-tearing-self-$self" 90 tearing -s "$self" -n 3
    done
    bench "scenes-heap-r4-filters-off" 90 heap -r 4 -s no -n 3 --filters off
    step static-environment 120 "$bin/kdet_static_environment" 24 cuda
    ;;
  peer)
    step peer 150 "$bin/kdet_gpu_vs_sweep" --csv "$work/peer.csv"
    ;;
  cubql)
    step cubql 400 "$bin/kdet_gpu_vs_cubql" --csv "$work/cubql.csv"
    [[ ! -f "$work/cubql.csv" ]] || cp "$work/cubql.csv" "$out/cubql.csv"
    ;;
  margin)
    step margin 300 "$bin/kdet_margin_vs_cgal" --backend cuda --peer-runs 0 --frames 60:64 --runs 3 --csv "$work/margin.csv"
    [[ ! -f "$work/margin.csv" ]] || cp "$work/margin.csv" "$out/margin.csv"
    ;;
  mpi)
    if [[ ! -f "$bundle/openmpi.tar.xz" || ! -x "$bin/kdet_mpi_tests" ]]; then
      echo "mpi: not run, the bundle has no MPI tests or no Open MPI runtime" | tee -a "$out/steps.txt"
    else
      runtime="$work/openmpi"
      mkdir -p "$runtime" && tar -C "$runtime" -xJf "$bundle/openmpi.tar.xz"
      step mpi 90 env LD_LIBRARY_PATH="$runtime/lib:$LD_LIBRARY_PATH" "$runtime/bin/mpirun" --allow-run-as-root --oversubscribe \
        --mca pml ob1 --mca btl self,tcp -np 2 "$bin/kdet_mpi_tests"
    fi
    ;;
  locate)
    for case in "held 55 1000000 10 0 0" "within-0.02 55 1000000 10 0.02 0.1" "within-0.2 55 1000000 3 0.2 0.1"; do
      read -r name arguments <<<"$case"
      step "locate-$name" 120 "$bin/kdet_locate_profile" $arguments --backend both
    done
    ;;
  profile)
    for case in "armadillos-r4-self-yes armadillos -r 4 -s yes --frames 80:81" \
      "armadillos-r4-self-no armadillos -r 4 -s no --frames 80:81" \
      "pass_through-r2 pass_through_armadillos -r 2 -s no --frames 40:41" \
      "pass_through-r2-deepest pass_through_armadillos -r 2 -s no --frames 78:79" \
      "procedural-100k procedural --tets 100000 -s no --frames 59:60"; do
      read -r name arguments <<<"$case"
      step "ncu-$name" 90 "${nsight_compute:-ncu}" --clock-control none --metrics gpu__time_duration.sum --csv \
        --log-file "$work/ncu-$name.csv" "$kdet" bench $arguments -n 1 --backend cuda --quiet -d "$work/ncu-bench"
    done
    # Why the longest kernels take their time: occupancy, divergence, cache hits and memory throughput
    # of the heaviest frame's kernels (each metric group replays the kernel).
    step ncu-detail-armadillos-r4-self-yes 90 "${nsight_compute:-ncu}" --clock-control none --csv \
      --metrics gpu__time_duration.sum,launch__registers_per_thread,launch__occupancy_limit_registers,sm__warps_active.avg.pct_of_peak_sustained_active,smsp__thread_inst_executed_per_inst_executed.ratio,l1tex__t_sector_hit_rate.pct,lts__t_sector_hit_rate.pct,dram__throughput.avg.pct_of_peak_sustained_elapsed,sm__throughput.avg.pct_of_peak_sustained_elapsed \
      --log-file "$work/ncu-detail-armadillos-r4-self-yes.csv" "$kdet" bench armadillos -r 4 -s yes --frames 80:81 -n 1 \
      --backend cuda --quiet -d "$work/ncu-bench"
    # The bench files do not name the bucket capacity: one folder per variant.
    for variant in "automatic" "buckets-8 --bucket-capacity 8" "buckets-32 --bucket-capacity 32" "block-64 -g 64" \
      "block-256 -g 256"; do
      read -r name flags <<<"$variant"
      step "variant-$name" 30 "$kdet" bench armadillos -r 4 -s yes -n 3 --frames 70:99 $flags --backend cuda --quiet \
        -d "$work/variants/$name"
    done
    ;;
  compare)
    others=$(cd "$bin" && ls kdet-* 2>/dev/null)
    for round in 1 2; do
      for program in $others kdet; do
        for case in "procedural-100k procedural --tets 100000 -s no --frames 55:65" \
          "armadillos-r4-self armadillos -r 4 -s yes --frames 70:99" \
          "buddha_and_armadillo-r4-self buddha_and_armadillo -r 4 -s yes --frames 70:99" \
          "bunny_and_planck-r4-self bunny_and_planck -r 4 -s yes --frames 70:99" \
          "procedural-100k-self procedural --tets 100000 -s yes --frames 55:65" \
          "armadillos-r4 armadillos -r 4 -s no --frames 70:99" \
          "buddha_and_armadillo-r4 buddha_and_armadillo -r 4 -s no --frames 70:99" \
          "bunny_and_planck-r4 bunny_and_planck -r 4 -s no --frames 70:99" \
          "pass_through-r2 pass_through_armadillos -r 2 -s no --frames 20:59" \
          "procedural-1m procedural --tets 1000000 -s no --frames 59:61" \
          "procedural-4m procedural --tets 4000000 -s no --frames 59:61"; do
          read -r name arguments <<<"$case"
          step "compare-$round-$program-$name" 30 "$bin/$program" bench $arguments -n 3 --backend cuda --quiet \
            -d "$work/compare/$program-$round"
        done
      done
    done
    ;;
  matrix)
    step matrix $((deadline - SECONDS)) env KDET="$kdet" RUNS=3 BUDGET_MINUTES=$(((deadline - SECONDS) / 60)) \
      BENCH_FLAGS="--backend cuda" "$repo/scripts/run-thesis-matrix.sh" "$work/matrix"
    ;;
  esac
done

ls "$work/bench"/*.csv >/dev/null 2>&1 && python3 "$repo/python/kdet_summary.py" "$work/bench" >/dev/null 2>&1
tar -C "$work" --exclude=models --exclude=cache --exclude=bin --exclude=openmpi --exclude=lib -czf "$out/gpu-session.tar.gz" .
[[ -f "$work/peer.log" ]] && tail -15 "$work/peer.log"
[[ -f "$work/cubql.log" ]] && tail -15 "$work/cubql.log"
[[ -f "$work/margin.log" ]] && grep '^|' "$work/margin.log"
for log in "$work"/locate-*.log; do
  [[ -f "$log" ]] && sed "s|^|$(basename "$log" .log): |" "$log"
done
grep -h "FAILED\|PASSED\|ERROR SUMMARY\|RACECHECK SUMMARY" "$work"/*.log 2>/dev/null | sort | uniq -c | head -40
cat "$out/steps.txt"
[[ -f "$work/bench/summary.md" ]] && grep '^|' "$work/bench/summary.md"
for variant in "$work"/variants/*/ "$work"/compare/*/; do
  [[ -d "$variant" ]] || continue
  python3 "$repo/python/kdet_summary.py" "$variant" >/dev/null 2>&1 &&
    grep '^| [a-z]' "$variant/summary.md" | sed "s|^|$(basename "$variant"): |"
done
exit 0
