#!/usr/bin/env bash
# DEM speed benchmark (issue 5 "Speed"; figures in docs/dem.md): the pour of tests/peer
# (N 12-sphere pill-B clumps into a 40 mm cup, dt 5e-6 s, Hertz-Mindlin + CDT rolling) timed in
#   1. clumpkit and LIGGGHTS 3.8 back to back, the same pour and dt: on 2 cores (clumpkit
#      --threads 2; mpirun -np 2 liggghts with 'processors 2 1 1', so both processes hold half
#      of the cup) and on 1 core (--threads 1; liggghts without mpirun);
#   2. clumpkit at 1x, 4x and 16x the pill count (cup radius x sqrt(scale), same bed height),
#      for the cost per sphere-step, on 1 and 2 threads.
# Usage: bench/dem_pour_bench.sh CLUMPKIT
# Environment (defaults for an idle machine; on a loaded one shorten the 2-core runs):
#   PILLS=200  T2=0.4 (s simulated, 2-core pair)  T1=0.4 (1-core pair)  TS=0.1 (scaling)
#   SCALES="1 4 16"  SCALE_THREADS="2 1"  BENCH_WORK=dem_pour_bench
# Prints the load average before every run. Loop times are the codes' own: LIGGGHTS's "Loop
# time", the wall time `clumpkit sim` reports (includes its two VTK frames and checkpoints).
set -euo pipefail
ck="$(realpath "$1")"
pills="${PILLS:-200}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cmp="$here/../tests/peer/pour_compare.py"
work="${BENCH_WORK:-dem_pour_bench}"
mkdir -p "$work"
echo "# $(date -u +%FT%TZ) $(nproc) cores; load: $(cut -d' ' -f1-3 /proc/loadavg)"
run() { python3 "$cmp" --clumpkit "$ck" --pills "$pills" --seeds 1 --no-analysis "$@"; }
echo "## same pour, same dt, 2 cores: clumpkit --threads 2 vs mpirun -np 2 liggghts (${T2:-0.4} s)"
run --time "${T2:-0.4}" --only clumpkit --threads 2 --work "$work/c2"
run --time "${T2:-0.4}" --only liggghts --np 2 --processors "2 1 1" --work "$work/l2"
echo "## 1 core: clumpkit --threads 1 vs liggghts (${T1:-0.4} s)"
run --time "${T1:-0.4}" --only clumpkit --threads 1 --work "$work/c1"
run --time "${T1:-0.4}" --only liggghts --np 1 --work "$work/l1"
echo "## clumpkit per-stage profile (1 thread, ${T1:-0.4} s)"
sed -n '/time per stage/,/neighbour rebuilds/p' "$work/c1/clumpkit_seed1/stdout.txt"
echo "## scaling (clumpkit, ${TS:-0.1} s simulated)"
for s in ${SCALES:-1 4 16}; do
  for th in ${SCALE_THREADS:-2 1}; do
    run --time "${TS:-0.1}" --only clumpkit --threads "$th" --scale "$s" \
      --work "$work/scale${s}_t${th}"
  done
done
echo "# done $(date -u +%FT%TZ); load: $(cut -d' ' -f1-3 /proc/loadavg)"
