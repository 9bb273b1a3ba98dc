#!/usr/bin/env bash
# The whole test suite on an existing build: unit and end-to-end tests (CTest), then the
# sanitizer and fuzzing stages when present. Called by .ci/bootstrap test.
set -euo pipefail
build="$1"
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-2}"
ctest --test-dir "$build" --output-on-failure -j 2 --timeout 900
