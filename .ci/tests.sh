#!/usr/bin/env bash
# The whole test suite on an existing build: unit and end-to-end tests (CTest), then the
# hardening stages (docs/hardening.md), each in its own clang build folder beside $build:
#   sanitize  ASan + UBSan (+ libFuzzer coverage), tests labelled `sanitize`: every module's fast
#             tests, the fuzz corpus replays and the bad-input catalogue        -> ${build}-asan/
#   tsan      ThreadSanitizer (OpenMP via LLVM's Archer), tests labelled `tsan`  -> ${build}-tsan/
#   fuzz      every libFuzzer target of the sanitize build, CLUMPKIT_FUZZ_SECONDS of fuzzing in
#             total (40), shared equally, as many targets at once as there are cores
# Tests labelled `slow` stay out of both sanitizer builds. All stages run by default (CI); for
# quick local runs CLUMPKIT_CI_QUICK=1 skips the three, CLUMPKIT_CI_SKIP="tsan fuzz" some of them.
# Called by .ci/bootstrap test. Prints each stage's wall time at the end.
set -euo pipefail
build="$1"
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-2}"
# CTest runs two tests at once on the 2 cores, and a test whose OpenMP loops use both cores
# then shares them with the other test. OpenMP's default wait spins at every barrier (libgomp
# for some milliseconds, LLVM's libomp 200 ms) while the thread it waits for has no core: alone
# OptimalFill.BeatsEdtAcrossShapesAndCounts takes 4.6 s, beside the other tests 32-107 s, and
# the spinning took the CPU from the test beside it. Passive threads sleep at once (the CTest
# stage: 551-672 s -> 384 s, docs/hardening.md). Results do not depend on it; timings only.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
jobs="$(nproc)"
stage_times=()
timed() {
  local name="$1" t0
  shift
  t0=$(date +%s)
  "$@"
  stage_times+=("$(printf '%-10s %4d s' "$name" $(($(date +%s) - t0)))")
}
skipped() { [ "${CLUMPKIT_CI_QUICK:-0}" = 1 ] || [[ " ${CLUMPKIT_CI_SKIP:-} " == *" $1 "* ]]; }

# A clang build at -O1 with asserts on, without benchmarks; only the labelled tests get built.
# Unity (jumbo) build as in .ci/bootstrap: the ASan build took 328 s one file at a time, 224 s so.
configure_clang() {  # folder sanitizers fuzz(ON/OFF)
  cmake -S . -B "$1" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_CXX_FLAGS_DEBUG=-O1 -DCLUMPKIT_SANITIZE="$2" -DCLUMPKIT_FUZZ="$3" \
    -DCLUMPKIT_BUILD_BENCH=OFF -DCMAKE_UNITY_BUILD=ON >/dev/null
}

sanitize_stage() {
  local dir="${build}-asan"
  echo "== sanitizers: ASan + UBSan ($dir/, tests labelled 'sanitize')"
  configure_clang "$dir" address,undefined ON
  cmake --build "$dir" -j "$jobs" --target tests_sanitize fuzz_targets
  LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp" \
    ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_init_order=1" \
    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    ctest --test-dir "$dir" -L sanitize -LE slow --output-on-failure -j 2 --timeout 900
}

tsan_stage() {
  local dir="${build}-tsan"
  echo "== sanitizers: ThreadSanitizer ($dir/, tests labelled 'tsan')"
  configure_clang "$dir" thread OFF
  cmake --build "$dir" -j "$jobs" --target tests_tsan
  # Archer tells TSan about OpenMP's synchronisation (libomp itself is not instrumented).
  OMP_TOOL_LIBRARIES="$(ls /usr/lib/llvm-*/lib/libarcher.so | tail -1)" \
    TSAN_OPTIONS="halt_on_error=1:ignore_noninstrumented_modules=1" \
    ctest --test-dir "$dir" -L tsan -LE slow --output-on-failure -j 1 --timeout 900
}

fuzz_stage() {
  local dir="${build}-asan" total="${CLUMPKIT_FUZZ_SECONDS:-40}" n
  configure_clang "$dir" address,undefined ON  # up to date after the sanitize stage
  cmake --build "$dir" -j "$jobs" --target fuzz_targets >/dev/null
  n=$(wc -l < "$dir/tests/fuzz/targets.txt")
  echo "== bounded fuzzing: $n targets, $total s in total"
  bash tests/fuzz/run.sh "$dir" $((total / n > 5 ? total / n : 5))
}

timed ctest ctest --test-dir "$build" --output-on-failure -j 2 --timeout 900
skipped sanitize || timed sanitize sanitize_stage
skipped tsan || timed tsan tsan_stage
skipped fuzz || timed fuzz fuzz_stage
echo "== stage times"
printf '   %s\n' "${stage_times[@]}"
