#!/usr/bin/env bash
# The paper's study (issue 6 item 5, SPEC §7): the nine single-type variants through bulk
# density and angle of repose, the production model through discharge at 10, 15 and 30 rpm.
# Writes one table (study.md, study.csv) from the runs' JSON with mean ± std over the repeats.
#
#   examples/rig_study.sh [--scale mini|small|paper] [--repeats K] [--out DIR] [--clumpkit BIN]
#                         [--jobs J] [--threads T] [--rigs "bulk_density angle_of_repose discharge"]
#
# Runs are resumable: rerunning the same command keeps finished repeats (clumpkit rig --out).
# By default two runs go side by side with one engine thread each (--jobs 2 --threads 1): the
# rig-sized runs use two cores better that way than one run on two threads.
set -euo pipefail
scale=mini repeats=2 out=study clumpkit=clumpkit threads=1 jobs=2
rigs="bulk_density angle_of_repose discharge"
while [ $# -gt 0 ]; do
  case "$1" in
    --scale) scale=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --clumpkit) clumpkit=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --rigs) rigs=$2; shift 2 ;;  # a subset, e.g. "angle_of_repose"
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
# Runs side by side on one thread each wait for nothing, so libgomp's waiting policy does not
# matter to them; a run on several threads needs libgomp's default spinning: with passive
# waiting a fork-join cost 80 µs on the 2-core VM (3 µs spinning) and a 2-thread pour took
# 3.5x as long (docs/dem.md).
if [ "$threads" = 1 ]; then export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}; fi
want() { case " $rigs " in *" $1 "*) return 0 ;; *) return 1 ;; esac; }
run() {  # name rig model [--set ...]
  local name=$1; shift
  [ -f "$out/$name.json" ] && return 0
  local t0=$SECONDS
  "$clumpkit" rig "$@" --scale "$scale" --repeats "$repeats" --threads "$threads" \
      --out "$out/$name" --json "$out/$name.json" 2> "$out/$name.log" > /dev/null ||
    echo "FAILED: $name (see $out/$name.log)" >&2
  echo "$name: $((SECONDS - t0)) s" >&2
}
# A small job pool: at most $jobs runs at once, in the order below.
pool() {
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  run "$@" &
}
# The discharger as the paper ran it: one bed per repeat, filled once (at 10 rpm's run) and
# turned at 15 and 30 rpm too (--bed-from; the same bits as filling it again, docs/rigs.md).
dis10=""
if want discharge; then pool dis_10 discharge --model production --set rpm=10; dis10=$!; fi
for m in paper_A4 paper_A12 paper_A20 paper_B4 paper_B12 paper_B20 paper_C2 paper_C12 paper_C18; do
  if want bulk_density; then pool "bd_$m" bulk_density --model "$m"; fi
  if want angle_of_repose; then pool "aor_$m" angle_of_repose --model "$m"; fi
done
if want discharge; then
  [ -n "$dis10" ] && { wait "$dis10" || true; }
  bed=()  # a study folder from before session 33 has no beds: then each speed fills its own
  [ -f "$out/dis_10/repeat_1/bed/bed.json" ] && bed=(--bed-from "$out/dis_10")
  for rpm in 15 30; do
    pool "dis_$rpm" discharge --model production --set "rpm=$rpm" "${bed[@]}"
  done
fi
wait
python3 "$(dirname "$0")/rig_study_table.py" "$out"
