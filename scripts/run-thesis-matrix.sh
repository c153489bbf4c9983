#!/usr/bin/env bash
# Runs the benchmark matrix of the thesis's chapter 6 with `kdet bench` (scenes x resolutions x methods x
# self-collisions off/on), then writes OUT/summary.md (median and max frame time per case) and, when
# matplotlib is installed, the figures into OUT/plots.
#
# usage: scripts/run-thesis-matrix.sh [OUT]      (default OUT: exports/thesis_matrix)
#
# Settings (environment variables, defaults in brackets):
#   KDET                     the kdet program [build/kdet]
#   RUNS                     runs per benchmark of the grid methods [2] (the thesis used 10)
#   SCENES                   [armadillos buddha_and_armadillo bunny_and_planck pass_through_armadillos]
#   RESOLUTIONS              [1 2 3 4]; RESOLUTIONS_<scene> overrides it for one scene
#   SELF                     self-collision settings [no yes]; SELF_<scene> overrides it for one scene
#   METHODS                  grid methods, run on every case [kdet kdet_no_pairs]
#   BRUTE_FORCE_METHODS      [gpu gpu_no_loop], run only at BRUTE_FORCE_RESOLUTIONS [1] (a resolution 1
#                            frame with self-collisions takes 1-2 s on 2 cores), BRUTE_FORCE_RUNS [1] times;
#                            BRUTE_FORCE_RESOLUTIONS_<scene> overrides it for one scene
#   THREADS                  CPU threads [all]
#   BUDGET_MINUTES           no new benchmark starts after this [55]; what is left is listed as not run
#   BENCH_FLAGS              more flags for every `kdet bench` call [none], e.g. for a quick try on the
#                            procedural scene: SCENES=procedural RESOLUTIONS=1 BENCH_FLAGS="--tets 4000"
# As in the thesis, pass_through_armadillos exists at resolution 2 only and runs without self-collisions
# (RESOLUTIONS_pass_through_armadillos=2, SELF_pass_through_armadillos=no), and brute force runs on it
# too for the comparison of figure 6.10 (BRUTE_FORCE_RESOLUTIONS_pass_through_armadillos=2).
# A case that cannot run (a scene not prepared, an unknown name) is listed in OUT/skipped.txt with the
# one-line error of kdet, and in the summary; the other cases still run.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$repo/exports/thesis_matrix}"
kdet="${KDET:-$repo/build/kdet}"
runs="${RUNS:-2}"
scenes="${SCENES:-armadillos buddha_and_armadillo bunny_and_planck pass_through_armadillos}"
methods="${METHODS:-kdet kdet_no_pairs}"
brute_force_methods="${BRUTE_FORCE_METHODS:-gpu gpu_no_loop}"
BRUTE_FORCE_RESOLUTIONS="${BRUTE_FORCE_RESOLUTIONS:-1}"
brute_force_runs="${BRUTE_FORCE_RUNS:-1}"
budget_seconds=$((${BUDGET_MINUTES:-55} * 60))
: "${RESOLUTIONS_pass_through_armadillos:=2}"
: "${SELF_pass_through_armadillos:=no}"
: "${BRUTE_FORCE_RESOLUTIONS_pass_through_armadillos:=2}"

[[ -x "$kdet" ]] || { echo "run-thesis-matrix: $kdet not found; build first (scripts/build.sh) or set KDET" >&2; exit 1; }
mkdir -p "$out"
skipped="$out/skipped.txt"
: > "$skipped"

# The value of VARIABLE_<scene> when set, else the default.
per_scene() {
    local name="$1_$2"
    echo "${!name:-$3}"
}

done_count=0
run_case() { # scene resolution method self runs
    local label="$1 r$2 $3 self $4"
    if ((SECONDS > budget_seconds)); then
        echo "$label: not run, the time budget of $((budget_seconds / 60)) minutes was spent" >> "$skipped"
        return
    fi
    local started=$SECONDS error
    if error=$("$kdet" bench "$1" -r "$2" -c "$3" -s "$4" -n "$5" -d "$out" --quiet ${THREADS:+--threads "$THREADS"} \
               ${BENCH_FLAGS:-} 2>&1 >/dev/null); then
        done_count=$((done_count + 1))
        echo "done: $label ($((SECONDS - started)) s, $((SECONDS / 60)) min in all)"
    else
        echo "$label: $error" >> "$skipped"
        echo "not run: $label: $error"
    fi
}

# True when the word $1 is in the list $2.
listed() {
    [[ " $2 " == *" $1 "* ]]
}

run_methods() { # methods, runs, name of the variable of allowed resolutions ("": all)
    local resolution self method scene
    # Cheap cases first, so that a spent time budget cuts the most expensive ones.
    for resolution in 1 2 3 4; do
        for self in no yes; do
            for method in $1; do
                for scene in $scenes; do
                    listed "$resolution" "$(per_scene RESOLUTIONS "$scene" "${RESOLUTIONS:-1 2 3 4}")" || continue
                    [[ -z "$3" ]] || listed "$resolution" "$(per_scene "$3" "$scene" "${!3}")" || continue
                    listed "$self" "$(per_scene SELF "$scene" "${SELF:-no yes}")" || continue
                    run_case "$scene" "$resolution" "$method" "$self" "$2"
                done
            done
        done
    done
}

# Grid methods first: they are the subject of chapter 6; brute force only where it finishes.
run_methods "$methods" "$runs" ""
run_methods "$brute_force_methods" "$brute_force_runs" BRUTE_FORCE_RESOLUTIONS

echo "$done_count benchmarks in $((SECONDS / 60)) min; $(wc -l < "$skipped") not run (see $skipped)"
((done_count > 0)) || exit 1
python3 "$repo/python/kdet_summary.py" "$out"
if python3 -c "import matplotlib" 2>/dev/null; then
    python3 "$repo/python/kdet_plot.py" "$out" | tail -n 1
else
    echo "figures skipped: matplotlib is missing (pip install -r python/requirements.txt; then python3 python/kdet_plot.py $out)"
fi
