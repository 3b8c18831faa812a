#!/usr/bin/env bash
# Install dependencies, build, and run every test (GoogleTest suites and CLI
# tests) through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
bash scripts/build.sh
cd build
ctest --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
