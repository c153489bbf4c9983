#!/usr/bin/env bash
# `kdet bench --mpi` with two kdet builds side by side, interleaved (A, B, A, B, ...), one OpenMP
# thread per rank, slabs: per run the mean and median of the frames' total, local and exchange ms, and
# what must not differ between the builds (pairs, tets sent, ranks rebuilt). Load average before and
# after. bench/results/mpi-exchange.md has its results.
#   bench/run-mpi-ab.sh KDET_A KDET_B OUT_DIR RANKS RUNS BENCH_ARGS...
#   e.g. bench/run-mpi-ab.sh base/build/kdet build/kdet /tmp/ab 2 3 procedural --tets 20000 --frames 30:60
set -euo pipefail
a="$1" b="$2" out="$3" ranks="$4" runs="$5"
shift 5
mkdir -p "$out"
echo "before: $(uptime)" | tee "$out/load.txt"
for ((i = 1; i <= runs; ++i)); do
  for side in A B; do
    kdet="$a"
    [[ $side == B ]] && kdet="$b"
    OMP_NUM_THREADS=1 mpirun -np "$ranks" --oversubscribe --allow-run-as-root "$kdet" bench "$@" -n 1 --threads 1 \
      --mpi --partition slabs -d "$out/$side-run$i" --quiet >"$out/$side-run$i.log"
  done
done
echo "after:  $(uptime)" | tee -a "$out/load.txt"
python3 - "$out" <<'EOF'
import csv, glob, statistics, sys
print("| run | frames / s (mean total) | total ms mean / median | local ms mean | exchange ms mean / median | pairs | tets sent / frame | ranks rebuilt / frame |")
print("|---|---:|---:|---:|---:|---:|---:|---:|")
for path in sorted(glob.glob(sys.argv[1] + "/[AB]-run*/*.csv"), key=lambda p: (p.split("/")[-2][2:], p.split("/")[-2])):
    rows = list(csv.DictReader(open(path)))
    col = lambda name: [float(r[name]) for r in rows]
    total, local, exchange = col("total ms"), col("local ms"), col("exchange ms")
    print(f"| {path.split('/')[-2]} | {1000 / statistics.mean(total):.1f} | {statistics.mean(total):.1f} / {statistics.median(total):.1f} "
          f"| {statistics.mean(local):.1f} | {statistics.mean(exchange):.2f} / {statistics.median(exchange):.2f} "
          f"| {sum(map(int, col('pairs'))):,} | {statistics.mean(col('tets sent')):,.0f} | {statistics.mean(col('ranks rebuilt')):.2f} |")
EOF
