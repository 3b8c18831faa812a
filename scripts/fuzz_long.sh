#!/usr/bin/env bash
# Longer mutation-fuzzing campaign over every reader (see tests/fuzz/):
#   bash scripts/fuzz_long.sh [ITERATIONS_PER_READER] [SEED]
# Runs the CTest fuzz driver with more iterations under a 2 GiB address-space
# limit (no single allocation may exceed 1 GiB inside the driver). Inputs that
# fail are kept under build/test_tmp/fuzz_findings/: copy each into
# tests/fuzz/regressions/<reader>/ so that it is checked on every run.
set -euo pipefail
cd "$(dirname "$0")/.."
ITERS=${1:-100000}
SEED=${2:-$(date +%s)}
BIN=build/bin/test_fuzz_readers
[ -x "$BIN" ] || { echo "build first: cmake -S . -B build -G Ninja && ninja -C build test_fuzz_readers"; exit 1; }
echo "fuzz_long: $ITERS iterations per reader, seed $SEED"
NAVIMPACT_FUZZ_ITERS=$ITERS NAVIMPACT_FUZZ_SEED=$SEED \
  /usr/bin/time -f "fuzz_long: %e s wall, max RSS %M KB" \
  prlimit --as=$((2 * 1024 * 1024 * 1024)) "$BIN" --gtest_filter='FuzzReaders.*' 2>&1 | grep -E "^fuzz|FAILED|Failure|PASSED|kept as"
