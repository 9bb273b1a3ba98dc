#!/usr/bin/env bash
# Times a fixed number of engine steps from a rig checkpoint, for two or more commits of
# clumpkit, side by side (one thread each, so both see the same load on a shared machine) or
# one after another with more threads.
#
#   bench/segment_bench.sh SNAPSHOT STEPS ROUNDS REV [REV ...] -- RIG ARGS
#
# SNAPSHOT is a copy of a rig's --out folder taken while it ran (repeat_1/ with its phase*.ckpt
# and state.json), e.g. of
#   clumpkit rig angle_of_repose --model production --scale paper --threads 2 --json aor.json --out aor_run
# copied during the lift. RIG ARGS are that run's arguments without --out/--json/--threads,
# e.g. "angle_of_repose --model production --scale paper".
#
# Each REV is built (Release, as bench/../CMakeLists.txt builds it) in a temporary worktree
# with one addition, bench/segment_stop.py, and run by bench/resume_bench.sh: after STEPS steps of a World, print the stage
# times and the state hash, time each stage 300 more times on that state (minimum, quartile,
# median per call) and exit. Same STEPS from the same checkpoint give the same hash for any
# commit that keeps the engine's bits. THREADS (default 1) sets --threads, or several in turn
# ("1 2": each round runs every commit on one thread, then on two); SIDE_BY_SIDE=0
# runs the commits one after another; THREAD_TIMERS=1 adds bench/thread_timers.py's per-thread
# times of the contacts' and forces' parts (a little slower: each timer is a clock read).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/.." && pwd)
snap=$1 steps=$2 rounds=$3
shift 3
revs=()
while [ "$#" -gt 0 ] && [ "$1" != "--" ]; do revs+=("$1"); shift; done
[ "$#" -gt 0 ] && [ "${#revs[@]}" -gt 0 ] ||
  { echo "usage: $0 SNAPSHOT STEPS ROUNDS REV [REV ...] -- RIG ARGS" >&2; exit 2; }
shift
[ -d "$snap/repeat_1" ] || { echo "$snap: no repeat_1/ with a checkpoint" >&2; exit 2; }
work=$(mktemp -d)
cleanup() {
  for k in "${!revs[@]}"; do git -C "$repo" worktree remove --force "$work/src$k" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
bins=()
for k in "${!revs[@]}"; do
  git -C "$repo" worktree add -q --detach "$work/src$k" "${revs[$k]}"
  python3 "$here/segment_stop.py" "$work/src$k/lib/src/dem/step.cpp"
  if [ "${THREAD_TIMERS:-0}" = 1 ]; then python3 "$here/thread_timers.py" "$work/src$k/lib/src/dem/step.cpp"; fi
  cmake -S "$work/src$k" -B "$work/build$k" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_UNITY_BUILD=ON >/dev/null
  cmake --build "$work/build$k" -j2 --target clumpkit >/dev/null
  mkdir -p "$work/bin$k"
  ln -s "$work/build$k/apps/clumpkit/clumpkit" "$work/bin$k/${revs[$k]}"  # labels the output
  bins+=("$work/bin$k/${revs[$k]}")
  echo "built ${revs[$k]}" >&2
done
# The runs themselves are bench/resume_bench.sh's, with the stop switched on.
export CLUMPKIT_SEGMENT_STEPS=$steps SIDE_BY_SIDE=${SIDE_BY_SIDE:-1}
for r in $(seq "$rounds"); do
  for th in ${THREADS:-1}; do
    echo "round $r, --threads $th"
    "$here/resume_bench.sh" "$snap" "$th" "${bins[@]}" -- "$@"
  done
done
