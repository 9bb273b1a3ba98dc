#!/usr/bin/env bash
# Counts the instructions of a fixed number of engine steps from a rig checkpoint, by stage, with
# valgrind's callgrind: a measure of the engine's work that does not depend on the load of this
# shared VM (the same binary, checkpoint and step count give the same counts), to go beside the
# wall times of bench/segment_bench.sh, which do.
#
#   bench/callgrind_segment.sh SNAPSHOT STEPS REV -- RIG ARGS
#
# SNAPSHOT, STEPS and RIG ARGS as for bench/segment_bench.sh (e.g. a copy of the paper angle of
# repose's --out folder taken during the lift, and "angle_of_repose --model production --scale
# paper"). REV is built in a temporary worktree with bench/segment_stop.py's stop (timing loops
# off), RelWithDebInfo at the Release flags (-O3 -g -DNDEBUG: the same code, with symbols), and run
# on one thread under callgrind, counting only inside World::step. Prints instructions per step
# in all and per stage (inclusive), and the calls that make them up. Takes about 50 times the
# steps' wall time (2 000 paper-lift steps: ~3 min) plus the build.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/.." && pwd)
[ "$#" -ge 5 ] && [ "$4" = "--" ] ||
  { echo "usage: $0 SNAPSHOT STEPS REV -- RIG ARGS" >&2; exit 2; }
snap=$1 steps=$2 rev=$3
shift 4
ckpt=$(ls "$snap"/repeat_1/phase*.ckpt 2>/dev/null | head -1)
[ -n "$ckpt" ] && [ -f "$snap/repeat_1/state.json" ] ||
  { echo "$snap/repeat_1: no checkpoint and state.json to resume" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "valgrind is not installed" >&2; exit 2; }
work=$(mktemp -d)
cleanup() { git -C "$repo" worktree remove --force "$work/src" 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT
git -C "$repo" worktree add -q --detach "$work/src" "$rev"
python3 "$here/segment_stop.py" "$work/src/lib/src/dem/step.cpp"
cmake -S "$work/src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O3 -g -DNDEBUG" -DCMAKE_UNITY_BUILD=ON >/dev/null
cmake --build "$work/build" -j2 --target clumpkit >/dev/null
echo "built $rev" >&2
mkdir -p "$work/run/repeat_1"
cp "$ckpt" "$snap/repeat_1/state.json" "$work/run/repeat_1/"
CLUMPKIT_SEGMENT_STEPS=$steps CLUMPKIT_SEGMENT_NO_TIMING=1 valgrind --tool=callgrind \
  --callgrind-out-file="$work/cg.out" --toggle-collect='clumpkit::dem::World::step()' \
  "$work/build/apps/clumpkit/clumpkit" rig "$@" --threads 1 --out "$work/run" \
  --json "$work/r.json" 2>"$work/log" >/dev/null || true
grep -q '^SEGMENT' "$work/log" || { cat "$work/log" >&2; echo "the run did not reach its stop" >&2; exit 1; }
sed -n '/^SEGMENT/,$p' "$work/log" | grep -v '^=='
callgrind_annotate --inclusive=yes --tree=calling "$work/cg.out" >"$work/tree.txt" 2>/dev/null
python3 - "$work/tree.txt" "$steps" "$rev" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
steps, rev = int(sys.argv[2]), sys.argv[3]
# Inclusive count of a function and its calls, from callgrind_annotate's "calling" tree:
# "N (p%)  * file:function [binary]" heads each function's entry; its callees follow as
# "N (p%)  >   file:callee (Kx) [binary]".
def head(name):
    best = 0
    for m in re.finditer(r"^\s*([\d,]+) \([^)]*\)\s+\*\s+\S*?:(.*)$", text, re.M):
        if m.group(2).split(" [")[0].endswith(name):
            best = max(best, int(m.group(1).replace(",", "")))
    return best
def calls(name):
    n = 0
    for m in re.finditer(r"^\s*[\d,]+ \([^)]*\)\s+>\s+\S*?:(.*?) \(([\d,]+)x\)", text, re.M):
        if m.group(1).endswith(name):
            n += int(m.group(2).replace(",", ""))
    return n
total = head("clumpkit::dem::World::step()")
print(f"{rev}: {steps} steps, {total / steps / 1e6:.3f} M instructions per step (callgrind, one thread)")
for stage in ["detect_contacts()", "compute_forces(double)", "kick_and_drift()",
              "rebuild_neighbours()", "evaluate_contact(clumpkit::dem::ResolvedContact const&, "
              "clumpkit::dem::ContactKinematics const&, double, clumpkit::dem::ContactHistory&, "
              "clumpkit::dem::ContactForce&)", "damp_implicitly(int)"]:
    n = head(stage)
    c = calls(stage)
    short = stage.split("(")[0]
    per_call = f", {n / c:.0f} per call ({c} calls)" if c else ""
    print(f"  {short:<20} {n / steps / 1e6:7.3f} M per step ({100 * n / max(total, 1):5.1f} %){per_call}")
PY
