#!/usr/bin/env bash
# The time to the refusal of a frame the memory cannot hold (docs/memory.md), for one or more kdet
# binaries run in turn (A, B, A, B, ...) on the same cases, with the load average before and after:
#   bench/memory-refusal.sh ROUNDS KDET [KDET ...]
# e.g. bench/memory-refusal.sh 3 /tmp/kdet-before build/kdet
# The piles of identical tets (each with vertices of its own) are written to ~/.cache/kdet/piles.
set -euo pipefail
rounds=${1:?rounds}
shift
[ $# -ge 1 ] || { echo "usage: $0 ROUNDS KDET [KDET ...]" >&2; exit 2; }
cache=${XDG_CACHE_HOME:-$HOME/.cache}/kdet/piles
mkdir -p "$cache"
for n in 3000 10000 30000; do
  [ -f "$cache/ident$n.ele" ] && continue
  awk -v n="$n" 'BEGIN {
    split("0 0 0|1 0 0|0 1 0|0 0 1", c, "|");
    print 4 * n, 3, 0, 0 > "'"$cache"'/ident" n ".node";
    for (t = 0; t < n; ++t) for (k = 0; k < 4; ++k) print 4 * t + k, c[k + 1] > "'"$cache"'/ident" n ".node";
    print n, 4, 0 > "'"$cache"'/ident" n ".ele";
    for (t = 0; t < n; ++t) print t, 4 * t, 4 * t + 1, 4 * t + 2, 4 * t + 3 > "'"$cache"'/ident" n ".ele";
  }'
done
echo "load before: $(uptime)"
cases=("prlimit --as=6442450944 KDET collide $cache/ident30000 --self"
       "KDET collide $cache/ident10000 --self --memory-limit 900000000"
       "KDET collide $cache/ident3000 --self --json")
for ((r = 1; r <= rounds; ++r)); do
  for c in "${cases[@]}"; do
    for kdet in "$@"; do
      cmd=${c/KDET/$kdet}
      out=$( { /usr/bin/time -f "TIME %e s elapsed %U s user %M KB" $cmd 2>&1 || true; } | tr '\n' ' ')
      time=$(grep -o 'TIME.*' <<<"$out")
      what=$(grep -o 'the frame has [a-z ]*[0-9]* candidate pairs\|"candidates": [0-9]*\|"buffer_regrows": [0-9]*' <<<"$out" | tr '\n' ' ')
      echo "round $r | $cmd | ${time#TIME } | $what"
    done
  done
done
echo "load after: $(uptime)"
