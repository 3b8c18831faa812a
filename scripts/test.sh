#!/usr/bin/env bash
# Install dependencies, build, run the libFuzzer harnesses for a bounded time
# and every test (GoogleTest suites and CLI tests) through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
bash scripts/build.sh
# libFuzzer harnesses of the input readers, each for a bounded time
# (NAVIMPACT_FUZZ_SECONDS per target, default 20; 0 skips): scripts/fuzz.sh
fuzz_rc=0
if [ "${NAVIMPACT_FUZZ_SECONDS:-20}" != 0 ]; then
  bash scripts/fuzz.sh "${NAVIMPACT_FUZZ_SECONDS:-20}" || fuzz_rc=$?
fi
cd build
ctest --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
[ $fuzz_rc -eq 0 ] || { echo "test: the libFuzzer run found a failing input (see 'fuzz' lines above)"; exit 1; }
