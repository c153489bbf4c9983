#!/usr/bin/env bash
# Compares what two kdet programs answer, for a change that must not alter results (a refactor): the
# pairs and contacts files of `kdet collide` on the models (every narrow-phase test; brute force on the
# small octopus only), and every column of `kdet bench`'s CSV but times and memory on the thesis scenes
# at resolution 1 (kdet and kdet_no_pairs, with and without self-collision) and the pass-through at 2.
# One thread, so that kdet_no_pairs's counts do not depend on timing. Needs `kdet prepare -r 1` and
# `kdet prepare armadillo -r 2` once.
#
# usage: scripts/compare-outputs.sh BEFORE AFTER     (two kdet programs; exits 1 when anything differs)
set -u
[[ $# -eq 2 ]] || { echo "usage: scripts/compare-outputs.sh BEFORE AFTER" >&2; exit 2; }
B="$(realpath "$1")" A="$(realpath "$2")"
M="${KDET_DATA_DIR:-$(cd "$(dirname "$0")/../.." && pwd)/shared/models}"
export KDET_DATA_DIR="$M"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
fail=0
for test in exact sat sat_mtv gjk fast sat_no_edges; do
  for args in "$M/bunny.mesh $M/hand.mesh" "$M/octopus-low.mesh --self" "$M/bunny.mesh --self" "$M/hand.mesh $M/hand.msh"; do
    for method in kdet brute_force_pairs; do
      [[ $method != kdet && $args != *octopus* ]] && continue
      $B collide $args --test $test --method $method --threads 1 --pairs b.pairs --contacts b.contacts >/dev/null 2>b.err; rb=$?
      $A collide $args --test $test --method $method --threads 1 --pairs a.pairs --contacts a.contacts >/dev/null 2>a.err; ra=$?
      if [[ $rb != $ra ]] || ! cmp -s b.pairs a.pairs || ! cmp -s b.contacts a.contacts; then echo "DIFF collide $args $test $method ($rb/$ra)"; fail=1; fi
    done
  done
done
for scene in armadillos buddha_and_armadillo bunny_and_planck; do
  for s in yes no; do
    for method in kdet kdet_no_pairs; do
      rm -rf b a
      $B bench $scene -r 1 -n 1 -s $s -c $method --threads 1 -d b --quiet >/dev/null
      $A bench $scene -r 1 -n 1 -s $s -c $method --threads 1 -d a --quiet >/dev/null
      fb=$(ls b/*.csv | grep -v _runs); fa=$(ls a/*.csv | grep -v _runs)
      # columns: keep counts (pairs, tets, candidates, colliding, regrows, overlap), drop times and memory
      python3 - "$fb" "$fa" "$method" <<'PY' || fail=1
import sys
def rows(p):
    lines=open(p).read().splitlines(); i=[k for k,l in enumerate(lines) if l.startswith('frame,')][0]
    cols=[c.strip() for c in lines[i].split(',')]
    keep=[j for j,c in enumerate(cols) if 'time' not in c and 'memory' not in c]
    if sys.argv[3]=='kdet_no_pairs': keep=[j for j in keep if 'candidates' not in cols[j]]
    return [cols[j] for j in keep], [[l.split(',')[j].strip() for j in keep] for l in lines[i+1:]]
cb,rb=rows(sys.argv[1]); ca,ra=rows(sys.argv[2])
if cb!=ca or rb!=ra: print('DIFF', sys.argv[1], sys.argv[2]); sys.exit(1)
PY
    done
  done
done
rm -rf b a
$B bench pass_through_armadillos -r 2 -n 1 --threads 1 -d b --quiet >/dev/null; $A bench pass_through_armadillos -r 2 -n 1 --threads 1 -d a --quiet > /dev/null
python3 -c "
import glob
def body(d):
    p=[x for x in glob.glob(d+'/*.csv') if not x.endswith('_runs.csv')][0]; L=open(p).read().splitlines(); i=[k for k,l in enumerate(L) if l.startswith('frame,')][0]
    c=[x.strip() for x in L[i].split(',')]; keep=[j for j,x in enumerate(c) if 'time' not in x and 'memory' not in x]
    return [[l.split(',')[j] for j in keep] for l in L[i+1:]]
import sys; sys.exit(0 if body('b')==body('a') else 1)" || { echo DIFF pass_through; fail=1; }
echo "compare-outputs: $([[ $fail == 0 ]] && echo same || echo DIFFERENT)"
exit $fail
