#!/usr/bin/env bash
# Compares the frame times of two kdet programs side by side, the way docs/performance.md says to measure on
# a shared VM: the two run in alternating rounds, each round from a fresh copy of each binary (a binary's
# speed depends on where its file's pages land), and the per-frame pair counts of both must be identical.
#
# usage: scripts/compare-frames.sh BEFORE AFTER [OUT]     (two kdet programs; OUT default exports/compare)
#
# Settings (environment variables, defaults in brackets):
#   SCENES      [armadillos buddha_and_armadillo bunny_and_planck]
#   RESOLUTION  [4]
#   SELF        self-collision yes|no [yes]
#   ROUNDS      alternating rounds [3]
#   FRAMES      frames A:B of each scene [all]
#   BENCH_FLAGS more flags for every `kdet bench` call [none]
# Prints, per scene, the median frame time (device time column) of each program over all rounds and frames,
# and their ratio; exits 1 when any frame's pair count differs.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
[[ $# -ge 2 ]] || { echo "usage: scripts/compare-frames.sh BEFORE AFTER [OUT]" >&2; exit 2; }
before="$(realpath "$1")" after="$(realpath "$2")"
out="$(realpath -m "${3:-exports/compare}")"
scenes="${SCENES:-armadillos buddha_and_armadillo bunny_and_planck}"
rounds="${ROUNDS:-3}"
frames=()
[[ -n "${FRAMES:-}" ]] && frames=(--frames "$FRAMES")
rm -rf "$out" && mkdir -p "$out/bin"

for ((round = 1; round <= rounds; ++round)); do
  for scene in $scenes; do
    for side in before after; do
      program="${!side}"
      cp "$program" "$out/bin/kdet-$side"   # a fresh copy per round
      # shellcheck disable=SC2086
      "$out/bin/kdet-$side" bench "$scene" -r "${RESOLUTION:-4}" -s "${SELF:-yes}" -n 1 "${frames[@]}" --quiet \
        -d "$out/$side/round$round" ${BENCH_FLAGS:-} > /dev/null
    done
  done
done

PYTHONPATH="$repo/python" python3 - "$out" "$rounds" $scenes <<'EOF'
import glob, os, statistics, sys
from kdet_csv import read_bench_file

out, rounds, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
differ = False
print(f"{'scene':26} {'before ms':>10} {'after ms':>10} {'after/before':>13}  pairs")
for scene in scenes:
    times, pairs = {}, {}
    for side in ("before", "after"):
        times[side], pairs[side] = [], []
        for r in range(1, rounds + 1):
            (path,) = [p for p in glob.glob(f"{out}/{side}/round{r}/{scene}_*.csv") if not p.endswith("_runs.csv")]
            bench = read_bench_file(path)
            times[side] += bench.column("device time")
            pairs[side].append(bench.column("collision pairs"))
    same = all(p == pairs["before"][0] for side in pairs for p in pairs[side])
    differ |= not same
    b, a = statistics.median(times["before"]), statistics.median(times["after"])
    print(f"{scene:26} {b:10.2f} {a:10.2f} {a / b:13.3f}  {'same' if same else 'DIFFER'}")
sys.exit(1 if differ else 0)
EOF
