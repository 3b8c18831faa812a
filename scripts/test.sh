#!/usr/bin/env bash
# Install dependencies, build, run the libFuzzer harnesses for a bounded time
# and every test (GoogleTest suites and CLI tests) through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
bash scripts/build.sh
# libFuzzer harnesses of the input readers, each for a bounded time
# (NAVIMPACT_FUZZ_SECONDS per target, default 20; 0 skips): scripts/fuzz.sh.
# Seeded (NAVIMPACT_FUZZ_SEED, default 1): from a clean clone every run tries
# the same inputs in the same order, as far as its time reaches, so a finding
# is reproducible from the log; longer campaigns (README) draw new seeds.
# (its report is printed again after the tests, where a log's tail shows it)
fuzz_rc=0
fuzz_log=build-fuzz/fuzz-report.txt
if [ "${NAVIMPACT_FUZZ_SECONDS:-20}" != 0 ]; then
  mkdir -p build-fuzz
  NAVIMPACT_FUZZ_SEED=${NAVIMPACT_FUZZ_SEED:-1} bash scripts/fuzz.sh "${NAVIMPACT_FUZZ_SECONDS:-20}" 2>&1 | tee "$fuzz_log" || fuzz_rc=$?
fi
cd build
ctest --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
if [ $fuzz_rc -ne 0 ]; then
  echo "test: the libFuzzer run found a failing input; its report again:"
  grep -v -E "^fuzz [a-z_]+ +ok:" "../$fuzz_log" | tail -40
  exit 1
fi
