#!/usr/bin/env bash
# Fuzzes every target of a CLUMPKIT_FUZZ=ON build, each for a time budget, as many at once as the
# machine has cores ($CLUMPKIT_FUZZ_JOBS to change it; libFuzzer runs one process each), starting
# from the committed seed corpus (which is never modified: new inputs go to a scratch
# folder). Prints one line per target (executions, crashes) and exits 1 if any target crashed,
# leaked, timed out or ran out of memory; the offending input is kept in <build>/fuzz-artifacts/.
#   bash tests/fuzz/run.sh BUILD SECONDS_PER_TARGET [TARGET...]
# e.g. the local long run (docs/hardening.md):  bash tests/fuzz/run.sh build-fuzz 1200
set -uo pipefail
build="${1:?usage: run.sh BUILD SECONDS_PER_TARGET [TARGET...]}"
seconds="${2:?usage: run.sh BUILD SECONDS_PER_TARGET [TARGET...]}"
shift 2
at_once="${CLUMPKIT_FUZZ_JOBS:-$(nproc)}"
if ! [[ "$at_once" =~ ^[1-9][0-9]*$ ]]; then
  echo "run.sh: CLUMPKIT_FUZZ_JOBS must be a whole number >= 1 (got '$at_once')" >&2
  exit 2
fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [ "$#" -gt 0 ]; then targets=("$@"); else mapfile -t targets < "$build/tests/fuzz/targets.txt"; fi
artifacts="$build/fuzz-artifacts"
mkdir -p "$artifacts"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
dict_for() {
  case "$1" in
    units) echo "$here/dict/units.dict" ;;
    mesh_file) echo "$here/dict/mesh.dict" ;;
    measurements_csv) echo "$here/dict/csv.dict" ;;
    *_json) echo "$here/dict/json.dict" ;;
    *_file) echo "$here/dict/toml.dict" ;;
    *) echo "" ;;
  esac
}
# Leaks inside third-party libraries (assimp) are suppressed, ours are not (lsan.supp).
export LSAN_OPTIONS="suppressions=$here/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
fuzz_one() {  # target: fuzzes it, then writes its one-line result to $scratch/<target>.result
  local t="$1" bin="$build/tests/fuzz/fuzz_$1" dict log start rc runs status
  local args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192
              -print_final_stats=1 -artifact_prefix="$artifacts/$t-")
  if [ ! -x "$bin" ]; then
    echo "fuzz $t: missing $bin, FAILED" > "$scratch/$t.result"
    return
  fi
  mkdir -p "$scratch/$t"
  dict="$(dict_for "$t")"
  [ -n "$dict" ] && [ -f "$dict" ] && args+=(-dict="$dict")
  log="$artifacts/$t.log"
  start=$(date +%s)
  # Corpus folders that exist (git does not keep an empty regressions/<target>/).
  local dirs=("$scratch/$t")
  for d in "$here/corpus/$t" "$here/regressions/$t"; do [ -d "$d" ] && dirs+=("$d"); done
  "$bin" "${args[@]}" "${dirs[@]}" >"$log" 2>&1
  rc=$?
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  status=ok
  if [ "$rc" -ne 0 ]; then
    status="FAILED (exit $rc, see $log)"
    grep -E 'ERROR|invariant|what\(\)|SUMMARY' "$log" | head -5 >&2
  fi
  echo "fuzz $t: ${runs:-?} executions in $(( $(date +%s) - start )) s, $status" \
    > "$scratch/$t.result"
}

for t in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$at_once" ]; do wait -n; done
  fuzz_one "$t" &
done
wait
failed=0
for t in "${targets[@]}"; do
  if [ -f "$scratch/$t.result" ]; then
    cat "$scratch/$t.result"
    grep -q "FAILED" "$scratch/$t.result" && failed=1
  else
    echo "fuzz $t: no result, FAILED"
    failed=1
  fi
done
exit "$failed"
