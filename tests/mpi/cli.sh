#!/usr/bin/env bash
# `kdet collide --mpi` under mpirun writes exactly the pairs `kdet collide` writes, with both partitions,
# kdet bench --mpi finds the same pairs per frame on 1 and 2 ranks and as without --mpi on a scene of
# filters and a static object, refuses a scene whose tets change,
# a file missing on rank 0 fails on every rank with one message, so does a bad flag, and --partition
# alone is a usage error.
#   cli.sh KDET MPIEXEC DATA_DIR WORK
set -euo pipefail
kdet="$1" mpiexec="$2" data="${KDET_DATA_DIR:-$3}" work="$4"
rm -rf "$work" && mkdir -p "$work"
run() { OMP_NUM_THREADS=1 "$mpiexec" -np 3 --oversubscribe --allow-run-as-root "$kdet" "$@"; }
"$kdet" collide "$data/bunny.mesh" "$data/hand.mesh" --pairs "$work/expected.txt" >/dev/null
[[ -s "$work/expected.txt" ]] || { echo "no pairs: the meshes were meant to overlap" >&2; exit 1; }
for partition in slabs random; do
  run collide "$data/bunny.mesh" "$data/hand.mesh" --mpi --partition "$partition" --pairs "$work/$partition.txt" \
    >"$work/$partition.out"
  cmp "$work/expected.txt" "$work/$partition.txt" || { echo "--partition $partition: other pairs" >&2; exit 1; }
  grep -q "^ranks             3, partition $partition$" "$work/$partition.out"
done
if run collide "$work/missing.mesh" --self --mpi >"$work/missing.out" 2>&1; then
  echo "a missing file did not fail" >&2
  exit 1
fi
[[ "$(grep -c "missing.mesh: cannot open file" "$work/missing.out")" == 1 ]] || { cat "$work/missing.out" >&2; exit 1; }
# kdet bench --mpi: one row per frame, the same pairs on 2 ranks as on 1.
for np in 1 2; do
  OMP_NUM_THREADS=1 "$mpiexec" -np $np --oversubscribe --allow-run-as-root "$kdet" bench --tets 2000 --frames 58:61 -n 1 \
    --mpi -d "$work/bench$np" --quiet >/dev/null
done
rows() { cut -d, -f1,3 "$1"/*.csv; }
[[ "$(rows "$work/bench1" | wc -l)" == 5 && "$(rows "$work/bench1")" == "$(rows "$work/bench2")" ]] ||
  { echo "kdet bench --mpi: other rows on 2 ranks" >&2; rows "$work/bench1" >&2; rows "$work/bench2" >&2; exit 1; }
# A scene of collision groups and a static floor (heap), and a scene whose tets change (refused).
"$kdet" bench heap --frames 100:101 -n 1 --threads 1 -d "$work/heap" --quiet >/dev/null
OMP_NUM_THREADS=1 "$mpiexec" -np 2 --oversubscribe --allow-run-as-root "$kdet" bench heap --frames 100:101 -n 1 --mpi \
  -d "$work/heap_mpi" --quiet >/dev/null
plain=$(sed -n '/^frame,/,$p' "$work"/heap/heap_*[0-9].csv | tail -n +2 | cut -d, -f1,8 | tr -d ' ')
split=$(tail -n +2 "$work"/heap_mpi/*.csv | cut -d, -f1,3)
[[ -n "$plain" && "$plain" == "$split" ]] || { echo "kdet bench heap --mpi: other pairs" >&2; echo "$plain" "$split" >&2; exit 1; }
if OMP_NUM_THREADS=1 "$mpiexec" -np 2 --oversubscribe --allow-run-as-root "$kdet" bench tearing --frames 0:1 -n 1 --mpi \
  -d "$work/tearing" --quiet >"$work/tearing.out" 2>&1; then
  echo "kdet bench tearing --mpi did not refuse the changing tets" >&2
  exit 1
fi
grep -q "changes its tets from frame to frame, which --mpi does not follow" "$work/tearing.out"
set +e
"$kdet" collide "$data/bunny.mesh" --self --partition random 2>"$work/usage.out"
status=$?
set -e
[[ $status == 2 && "$(cat "$work/usage.out")" == "kdet collide: --partition needs --mpi" ]] || { echo "exit $status" >&2; exit 1; }
# A bad flag, found before MPI starts, is printed once, not once per rank.
if run collide "$data/bunny.mesh" --self --mpi --margin -1 >"$work/flag.out" 2>&1; then
  echo "a negative margin did not fail under mpirun" >&2
  exit 1
fi
[[ "$(grep -c "margin" "$work/flag.out")" == 1 ]] || { echo "a usage error not printed once:" >&2; cat "$work/flag.out" >&2; exit 1; }
echo "kdet collide --mpi on 3 ranks: $(wc -l <"$work/expected.txt") pairs, the same as without --mpi"
