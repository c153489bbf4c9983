#!/usr/bin/env bash
# Soak test (issue 48), outside the test command: one Detector over many frames of a small procedural
# scene while objects are switched on and off, moved far apart and back and stacked (bench/soak.cpp),
# built under the `asan` preset so that LeakSanitizer checks the process at exit. Prints a markdown
# report (machine, commit, command, the sampled comparisons, peak and last RSS) to stdout.
#   scripts/soak.sh [kdet_soak flags]     e.g. scripts/soak.sh --frames 100000 --tets 600
# Exit status: kdet_soak's (non-zero for a differing pair set, unbounded memory or a leak).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/compiler-cache.sh
# The preset leaves the benchmark programs out; kdet_soak is one of them.
cmake --preset asan -DKDET_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build-sanitize -j2 --target kdet_soak >/dev/null
echo "# Soak test"
echo
echo "- machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(free -g | awk '/Mem:/ {print $2}') GB"
echo "- commit: $(git rev-parse --short HEAD)$(git diff --quiet || echo ' (with uncommitted changes)')"
echo "- command: scripts/soak.sh $*  (build-sanitize/bench/kdet_soak, AddressSanitizer with LeakSanitizer)"
echo "- started: $(date -u '+%Y-%m-%d %H:%M UTC')"
echo
status=0
# A small quarantine: AddressSanitizer's default holds 256 MB of freed memory, which would hide the
# program's own resident memory behind its ramp.
ASAN_OPTIONS=detect_leaks=1:quarantine_size_mb=8 nice build-sanitize/bench/kdet_soak "$@" || status=$?
echo
echo "exit status: $status (LeakSanitizer reports a leak on stderr and exits non-zero)"
exit $status
