#!/usr/bin/env bash
# Times the engine on the end of a real rig run: resumes the last checkpoint of a finished (or
# killed) repeat with one or more clumpkit binaries and prints each run's stage profile.
# Same checkpoint, same work: binaries can be compared side by side (SIDE_BY_SIDE=1, one run
# per core, as docs/dem.md's session-11 figures were taken) or one after another.
#
#   bench/resume_bench.sh RUN_DIR THREADS BIN [BIN ...] -- RIG ARGS
#
# RUN_DIR is the --out folder of the run that made the checkpoint (its repeat_1/ holds a
# phase*.ckpt and state.json); RIG ARGS are that run's arguments without --out/--json, e.g.
#   clumpkit rig bulk_density --model production --scale paper --threads 2 --json bd.json --out bd_run
#   SIDE_BY_SIDE=1 bench/resume_bench.sh bd_run 1 old/clumpkit build/apps/clumpkit/clumpkit \
#       -- bulk_density --model production --scale paper
set -euo pipefail
run_dir=$1 threads=$2
shift 2
bins=()
while [ "$#" -gt 0 ] && [ "$1" != "--" ]; do bins+=("$1"); shift; done
[ "$#" -gt 0 ] || { echo "usage: $0 RUN_DIR THREADS BIN [BIN ...] -- RIG ARGS" >&2; exit 2; }
shift
ckpt=$(ls "$run_dir"/repeat_1/phase*.ckpt 2>/dev/null | head -1)
[ -n "$ckpt" ] && [ -f "$run_dir/repeat_1/state.json" ] ||
  { echo "$run_dir/repeat_1: no checkpoint and state.json to resume" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
one() {
  local k=$1 bin=$2 d="$work/run$1"
  shift 2
  mkdir -p "$d/repeat_1"
  cp "$ckpt" "$run_dir/repeat_1/state.json" "$d/repeat_1/"
  "$bin" rig "$@" --threads "$threads" --out "$d" --json "$d.json" >/dev/null 2>"$d.log" || {
    echo "$bin failed: see $d.log" >&2; return 1; }
  # A binary built by bench/segment_bench.sh stops after a number of steps and prints its
  # stage times instead of finishing the run.
  if grep -q '^SEGMENT' "$d.log"; then
    sed -n '/^SEGMENT/,$p' "$d.log" | sed "s|^|$bin: |"
    return
  fi
  python3 - "$d.json" "$bin" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
p = d["repeats"][0]["details"]["profile"]
q = {k: round(v["mean"], 6) for k, v in d["quantities"].items()}
stages = {k[:-2]: round(v, 2) for k, v in p.items() if k.endswith("_s") and k != "sphere_steps_per_s"}
print(f"{sys.argv[2]}: engine {p['engine_seconds']:.2f} s, {p['steps']} steps, {q}, stages (s) {stages}")
PY
}
pids=()
for k in "${!bins[@]}"; do
  if [ "${SIDE_BY_SIDE:-0}" = 1 ]; then
    one "$k" "${bins[$k]}" "$@" &
    pids+=($!)
  else
    one "$k" "${bins[$k]}" "$@"
  fi
done
for p in "${pids[@]}"; do wait "$p"; done
