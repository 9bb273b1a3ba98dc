#!/usr/bin/env bash
# Usage: rig_kill_and_resume.sh CLUMPKIT
# Kill and resume of a multi-repeat rig (issue #8): runs a tiny angle_of_repose rig with two
# repeats uninterrupted (A), then the same command (B) SIGKILLed at a random moment after the
# first checkpoint of repeat 1 and again after the first checkpoint of repeat 2, rerunning the
# same command each time to resume. Checks that
#   - every repeat's observables and details (final pill count, mass, heap fit, simulated time,
#     settle figures) agree with those of the uninterrupted run to 1e-3 relative (bit for bit
#     when the kill falls in a settle phase; see below), and the final snapshots exist;
#   - repeat 1, finished before the second kill, is neither recomputed nor lost: its result.json
#     keeps inode, mtime and content, and the rerun reports it as kept.
set -euo pipefail
ck="$1"
dir="$(mktemp -d)"
pid=""
cleanup() { [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$dir"; }
trap cleanup EXIT
# Checkpoints every 0.2 s of wall time so that short runs have several.
args=(rig angle_of_repose --scale tiny --set mass=0.008 --set lift_speed=12000
      --repeats 2 --seed 11 --rays 2000
      --threads 1 --vtk --checkpoint-interval 0.2)
RANDOM=$$

"$ck" "${args[@]}" --out "$dir/a" --json "$dir/a.json" > "$dir/a.log" 2>&1 ||
  { cat "$dir/a.log"; echo "FAIL: the uninterrupted run failed"; exit 1; }

# The random delay of a kill is bounded by the uninterrupted repeat's wall time after its first
# checkpoint (0.2 s): on an idle machine a tiny repeat takes ~0.7 s, and a fixed 0-500 ms delay
# after repeat 2's first checkpoint let it finish before the kill (a fresh-clone run failed so).
range_ms() {  # repeat index (0, 1) and cap in ms: 40 % of its time after the first checkpoint
  python3 - "$dir/a.json" "$1" "$2" <<'PY'
import json, sys
wall = json.load(open(sys.argv[1]))["repeats"][int(sys.argv[2])]["wall_seconds"]
print(max(1, min(int(sys.argv[3]), int(400 * (wall - 0.2)))))
PY
}

# Starts run B in the background; waits for FILE to appear, then sleeps a random 0-RANGE ms and
# SIGKILLs it. Fails if the run ends before it could be killed.
kill_after() {  # file range_ms
  "$ck" "${args[@]}" --out "$dir/b" --json "$dir/b.json" >> "$dir/b.log" 2>&1 &
  pid=$!
  while [ ! -f "$1" ]; do
    kill -0 "$pid" 2>/dev/null || { cat "$dir/b.log"; echo "FAIL: run ended before $1 appeared"; exit 1; }
    sleep 0.05
  done
  sleep "$(awk -v r=$((RANDOM % $2)) 'BEGIN { print r / 1000 }')"
  kill -0 "$pid" 2>/dev/null || { cat "$dir/b.log"; echo "FAIL: run ended before it was killed"; exit 1; }
  kill -9 "$pid"
  wait "$pid" 2>/dev/null || true
  pid=""
  echo "killed after $1: $(tr -d ' \n' < "$(dirname "$1")/state.json" | cut -c1-70)"
}

# 1. Inside repeat 1, after its first checkpoint.
kill_after "$dir/b/repeat_1/state.json" "$(range_ms 0 800)"
[ ! -f "$dir/b/repeat_1/result.json" ] || echo "note: repeat 1 had finished before the first kill"
# 2. Resumed; killed inside repeat 2, after its first checkpoint (repeat 1 has finished then).
kill_after "$dir/b/repeat_2/state.json" "$(range_ms 1 500)"
[ -f "$dir/b/repeat_1/result.json" ] || { echo "FAIL: repeat 2 began without repeat 1's result"; exit 1; }
[ ! -f "$dir/b/repeat_2/result.json" ] || { echo "FAIL: repeat 2 finished before the kill"; exit 1; }
before=$(stat -c '%i %Y.%y' "$dir/b/repeat_1/result.json"; sha256sum < "$dir/b/repeat_1/result.json")
# 3. Resumed to the end.
: > "$dir/b.log"
"$ck" "${args[@]}" --out "$dir/b" --json "$dir/b.json" > "$dir/b.log" 2>&1 ||
  { cat "$dir/b.log"; echo "FAIL: the resumed run failed"; exit 1; }
after=$(stat -c '%i %Y.%y' "$dir/b/repeat_1/result.json"; sha256sum < "$dir/b/repeat_1/result.json")
[ "$before" = "$after" ] || { echo "FAIL: repeat 1's result.json was rewritten"; exit 1; }
grep -q "repeat 1: kept from" "$dir/b.log" || { cat "$dir/b.log"; echo "FAIL: repeat 1 was not kept"; exit 1; }
grep -q "resumed" "$dir/b.log" || { cat "$dir/b.log"; echo "FAIL: repeat 2 did not resume from its checkpoint"; exit 1; }

# Observables and details, without wall-clock figures, the resumed flag and the engine profile
# (timings and step counts of the last session only). A resume inside a settle phase gives the
# uninterrupted run's state bit for bit; a resume in the middle of the angle-of-repose lift was
# seen to differ in the 4th-5th significant digit (26.3464 vs 26.3477 degrees), traced to the
# checkpoint and state.json being written as two separate steps (fixed: one commit; see
# docs/hardening.md, where the fix is argued but the interleaving was not reproduced on demand).
# So every number must still agree
# to 1e-3 relative (far below the repeat-to-repeat spread of several degrees), and the final
# particle snapshots and pictures must exist.
compare_json() {  # a b
  python3 - "$1" "$2" <<'PY'
import json, sys
skip = {"wall_seconds", "resumed", "profile"}
bad = []
def walk(a, b, path):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in set(a) | set(b):
            if k in skip:
                continue
            if k not in a or k not in b:
                bad.append(f"{path}/{k}: only in one run")
            else:
                walk(a[k], b[k], f"{path}/{k}")
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            bad.append(f"{path}: {len(a)} vs {len(b)} items")
        for i, (x, y) in enumerate(zip(a, b)):
            walk(x, y, f"{path}[{i}]")
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if abs(a - b) > 1e-3 * max(abs(a), abs(b), 1e-9):
            bad.append(f"{path}: {a} vs {b}")
    elif a != b:
        bad.append(f"{path}: {a!r} vs {b!r}")
a, b = (json.load(open(f)) for f in sys.argv[1:3])
walk(a, b, "")
for line in bad[:20]:
    print(line)
sys.exit(1 if bad else 0)
PY
}
fail=0
compare_json "$dir/a.json" "$dir/b.json" || { echo "FAIL: results differ"; fail=1; }
for k in 1 2; do
  compare_json "$dir/a/repeat_$k/result.json" "$dir/b/repeat_$k/result.json" ||
    { echo "FAIL: repeat $k: result.json differs"; fail=1; }
  for f in heap_spheres.vtp filled_spheres.vtp heap_wall_plate.vtp heap_wall_tube.vtp heap.png; do
    [ -s "$dir/b/repeat_$k/$f" ] || { echo "FAIL: repeat $k: $f missing"; fail=1; }
  done
  # The spheres as vertex cells (ParaView draws them), each with its radius; walls with wall_id.
  rep="$dir/b/repeat_$k"
  grep -q 'NumberOfPoints="\([1-9][0-9]*\)" NumberOfVerts="\1"' "$rep/heap_spheres.vtp" &&
    grep -q 'Name="radius"' "$rep/heap_spheres.vtp" &&
    grep -q 'Name="wall_id"' "$rep/heap_wall_plate.vtp" ||
    { echo "FAIL: repeat $k: the .vtp snapshots lack vertex cells or arrays"; fail=1; }
done
[ "$fail" = 0 ] || exit 1
grep -h '"angle"' -A1 "$dir/a.json" | head -2 | tr -d ' \n'; echo
echo "OK: killed twice (inside repeat 1 and repeat 2), resumed; results agree, repeat 1 kept"
