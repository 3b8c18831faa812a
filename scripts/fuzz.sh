#!/usr/bin/env bash
# libFuzzer campaign over the readers of untrusted input (tests/fuzz/libfuzzer):
#   bash scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
# Builds the harnesses in build-fuzz/ with clang (-DNAVIMPACT_FUZZ=ON:
# -fsanitize=fuzzer,address,undefined; only the libraries the readers need),
# makes a seed corpus from datasets/, config/, tests/data and
# tests/fuzz/regressions (build-fuzz/seeds/<target>, made anew each run) and
# runs each target for SECONDS_PER_TARGET seconds (default 20) with
# -rss_limit_mb=1024 (also the largest single allocation) and a 10 s timeout
# per input. The corpus libFuzzer grows is kept in build-fuzz/corpus/<target>
# (a later run goes on from it). Any crash, sanitizer report, leak, timeout or
# allocation above 1 GiB fails the script; the input is kept as
# build-fuzz/findings/<target>/crash-* (or leak-*, timeout-*, oom-*, or hang-* when a
# run had to be killed 2 x SECONDS_PER_TARGET + 120 s after it started): copy it
# to tests/fuzz/regressions/<target>/ (read by every CTest run) and fix it.
# Environment:
#   NAVIMPACT_FUZZ_RUNS=N    stop each target after N executions instead of a time
#   NAVIMPACT_FUZZ_JOBS=J    targets run side by side (default 2)
#   NAVIMPACT_FUZZ_CXX=...   clang++ to build with (default clang++-14)
#   NAVIMPACT_FUZZ_SANITIZERS=address,undefined   (e.g. "undefined" alone)
#   NAVIMPACT_FUZZ_SEED=N    libFuzzer's seed (default: a new one per run, printed as "INFO: Seed:")
#   NAVIMPACT_FUZZ_ARGS="..."  more libFuzzer flags (e.g. -dict=FILE)
set -euo pipefail
cd "$(dirname "$0")/.."
SECS=${1:-20}
shift || true
B=build-fuzz
CXXF=${NAVIMPACT_FUZZ_CXX:-clang++-14}
JOBS=${NAVIMPACT_FUZZ_JOBS:-2}
command -v "$CXXF" >/dev/null || { echo "fuzz: $CXXF not found (scripts/deps.sh installs clang-14 and libclang-rt-14-dev)"; exit 1; }

# -- build (only the harness and the libraries it links) --------------------
LAUNCH=()
command -v ccache >/dev/null && LAUNCH=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if [ ! -f $B/CMakeCache.txt ]; then
  cmake -S . -B $B -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$CXXF" \
    -DNAVIMPACT_FUZZ=ON -DNAVIMPACT_FUZZ_SANITIZERS="${NAVIMPACT_FUZZ_SANITIZERS:-address,undefined}" \
    "${LAUNCH[@]}" >/dev/null
fi
t0=$(date +%s)
cmake --build $B --target navimpact_fuzz -j "${JOBS_BUILD:-$(nproc)}" | tail -1
echo "fuzz: harness built in $(( $(date +%s) - t0 )) s"

# -- seed corpus --------------------------------------------------------------
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && read -r -a TARGETS < $B/fuzz_targets.txt
rm -rf $B/seeds
S=$B/seeds
for t in "${TARGETS[@]}"; do mkdir -p $S/$t $B/corpus/$t $B/findings/$t $B/logs; done
set +o pipefail   # (head closes its pipe early)
head_gz() { gzip -dc "$1" | head -n "$2"; }
plain() { if gzip -t "$1" 2>/dev/null; then gzip -dc "$1"; else cat "$1"; fi; }
seed() {  # seed TARGET NAME < bytes
  [ -d $S/$1 ] && cat > $S/$1/$2 || cat > /dev/null
}
head_gz datasets/adis16405_static_excerpt.csv.gz 150 | seed imu_csv adis16405.csv
head_gz datasets/uav_flight_260s_emulated/imu.csv.gz 150 | seed imu_csv uav_emulated_imu.csv
head_gz datasets/katwijk_rover/imu.csv.gz 150 | seed imu_csv katwijk_imu.csv
head_gz datasets/uav_flight_260s.csv.gz 150 | seed trajectory_csv uav_flight.csv
head_gz tests/data/uav_flight_600s_ellipsoidal.csv.gz 150 | seed trajectory_csv uav_flight_600s.csv
head -n 150 datasets/katwijk_rover/reference.csv | seed trajectory_csv katwijk_reference.csv
n=0
for f in config/models/*.yaml config/*/*.yaml; do
  grep -o '"[A-Z][A-Z0-9]*(.*)"' "$f" | tr -d '"' | while IFS= read -r m; do
    n=$((n + 1)); printf '%s' "$m" | seed model_text "$(basename "$f" .yaml)_$n.txt"
  done
done
for s in "WN+GM+GM+DR" "WN+3GM+DR" "2*AR1+QN" "none" "QN+RW+SIN" "AR1(phi=0.999, sigma2=1e-6) + WN(sigma=1e-3)"; do
  n=$((n + 1)); printf '%s' "$s" | seed model_text "structure_$n.txt"
done
for f in config/models/*.yaml; do seed model_file "$(basename "$f")" < "$f"; done
for f in config/paper/covariance*.yaml; do seed covariance_config "$(basename "$f")" < "$f"; done
for f in config/replay/*.yaml; do seed replay_config "$(basename "$f")" < "$f"; done
for f in config/emulation/*.yaml; do seed emulation_config "$(basename "$f")" < "$f"; done
for f in config/paper/study*.yaml; do seed study_config "$(basename "$f")" < "$f"; done
for f in config/sweep/*.yaml tests/data/sweep_small.yaml; do seed sweep_config "$(basename "$f")" < "$f"; done
for t in covariance_config replay_config emulation_config study_config sweep_config; do  # every configuration to every loader
  for f in config/*/*.yaml; do seed $t "other_$(basename "$f")" < "$f"; done
done
seed import_manifest katwijk_7s.yaml < tests/fuzz/import_run/manifest.yaml
head_gz tests/fuzz/import_run/imu.csv.gz 150 | seed import_csv katwijk_imu.csv
seed import_csv katwijk_gnss.csv < tests/fuzz/import_run/gnss.csv
seed import_csv katwijk_reference.csv < tests/fuzz/import_run/reference.csv
for t in imu_rawlog rawlog; do
  plain tests/data/imu_label_xsens.rawlog | seed $t mrpt_sample_xsens.rawlog
  for f in tests/data/bad/*.rawlog; do plain "$f" | seed $t "bad_$(basename "$f")"; done
done
# a 2 s emulated rawlog with every label (IMU, GNSS, BARO, GT, comment), when the
# main build is there (scripts/build.sh)
if [ -x build/bin/navimpact ] && { [ -d $S/rawlog ] || [ -d $S/imu_rawlog ]; }; then
  tmp=$(mktemp -d)
  sed -e "s#\.\./\.\./datasets/#$PWD/datasets/#" -e "s#\.\./models/#$PWD/config/models/#" \
      -e 's/^  rate_hz: 200 .*/  rate_hz: 50/' -e 's/^  max_gap_s:/  end_s: 2.0\n  max_gap_s:/' \
      config/emulation/uav_flight_260s_ref.yaml > "$tmp/emu.yaml"
  if build/bin/navimpact emulate --config "$tmp/emu.yaml" --out "$tmp/emu.rawlog" --no-gzip >/dev/null 2>&1; then
    for t in imu_rawlog rawlog; do seed $t emulated_2s.rawlog < "$tmp/emu.rawlog"; done
  else
    echo "fuzz: could not emulate the 2 s rawlog seed (going on without it)"
  fi
  rm -rf "$tmp"
fi
for t in "${TARGETS[@]}"; do
  [ -d tests/fuzz/regressions/$t ] && for f in tests/fuzz/regressions/$t/*; do
    if [[ $t == *rawlog ]]; then plain "$f"; else cat "$f"; fi | seed $t "regression_$(basename "$f")"
  done
done
set -o pipefail

# -- run ----------------------------------------------------------------------
LIMIT=(-max_total_time="$SECS")
[ -n "${NAVIMPACT_FUZZ_RUNS:-}" ] && LIMIT=(-runs="$NAVIMPACT_FUZZ_RUNS")
[ -n "${NAVIMPACT_FUZZ_SEED:-}" ] && LIMIT+=(-seed="$NAVIMPACT_FUZZ_SEED")
# wall-clock bound of one target: its time, the corpus load, one 10 s timeout
# and its report (NAVIMPACT_FUZZ_WALL overrides; with NAVIMPACT_FUZZ_RUNS, 30 min more)
WALL=${NAVIMPACT_FUZZ_WALL:-$(( ${NAVIMPACT_FUZZ_RUNS:+1800 + }SECS * 2 + 120 ))}
# ASan: smaller quarantine so that RSS stays a measure of the readers' memory
export ASAN_OPTIONS=${ASAN_OPTIONS:-quarantine_size_mb=64:malloc_context_size=20}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/fuzz/libfuzzer/lsan.supp:print_suppressions=0}
echo "fuzz: ${#TARGETS[@]} targets, ${LIMIT[*]} each, $JOBS at a time; corpus $B/corpus, findings $B/findings"
run_one() {
  local t=$1 log=$B/logs/$1.log rc=0
  # shellcheck disable=SC2086
  # libFuzzer's own limits end a slow or large input, but its handlers can
  # hang (an out-of-memory report stopped the process for good): the run is
  # killed WALL seconds after it should have ended and the input it was
  # reading kept as hang-<sha1>.
  timeout -k 10 "$WALL" $B/bin/fuzz_$t "${LIMIT[@]}" -rss_limit_mb=1024 -malloc_limit_mb=1024 -timeout=10 \
    -print_final_stats=1 -artifact_prefix=$B/findings/$t/ ${NAVIMPACT_FUZZ_ARGS:-} $B/corpus/$t $S/$t \
    > "$log" 2>&1 || rc=$?
  local input
  input=$(sed -n 's/^navimpact fuzz: each input is written to //p' "$log" | head -1)
  if [ $rc -eq 124 ] || [ $rc -eq 137 ]; then
    if [ -n "$input" ] && [ -f "$input" ]; then
      local kept
      kept=$B/findings/$t/hang-$(sha1sum < "$input" | cut -c1-40)
      cp "$input" "$kept"
      echo "Test unit written to $kept" >> "$log"
    fi
    echo "navimpact fuzz: SUMMARY: the run did not end and was killed after $WALL s" >> "$log"
  fi
  # the driver's folder of inputs (its exit handler does not run when
  # libFuzzer ends a run or aborts on a finding: one was left per run)
  if [ -n "$input" ]; then
    local dir=${input%%/root/config/case/*}
    if [[ $dir == */navimpact-fuzz-* ]]; then rm -rf "$dir"; fi
  fi
  local execs rate rss
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)
  if [ $rc -eq 0 ]; then
    printf 'fuzz %-18s ok: %s executions, %s exec/s, peak RSS %s MB, corpus %s inputs\n' "$t" "${execs:-?}" \
      "${rate:-?}" "${rss:-?}" "$(ls $B/corpus/$t | wc -l)"
  else
    printf 'fuzz %-18s FAILED (exit %s) after %s executions: see %s\n' "$t" "$rc" "${execs:-?}" "$log"
    # the seed and (for inputs up to a few KB) libFuzzer's Base64 of the input:
    # enough to reproduce a finding from a CI log alone
    grep -E "INFO: Seed:|ERROR|navimpact fuzz|SUMMARY|Test unit written|runtime error|^Base64:" "$log" \
      | grep -v "each input is written to" | head -10 | cut -c1-6000
    echo "  keep the input: cp $B/findings/$t/<file> tests/fuzz/regressions/$t/ (and fix the reader)"
  fi
  return $rc
}
fail=0
pids=()
for t in "${TARGETS[@]}"; do
  [ -x $B/bin/fuzz_$t ] || { echo "fuzz: unknown target $t (targets: $(cat $B/fuzz_targets.txt))"; exit 1; }
  run_one "$t" &
  pids+=($!)
  if [ ${#pids[@]} -ge "$JOBS" ]; then wait "${pids[0]}" || fail=1; pids=("${pids[@]:1}"); fi
done
for p in "${pids[@]}"; do wait "$p" || fail=1; done
[ $fail -eq 0 ] && echo "fuzz: no finding" || { echo "fuzz: FINDINGS (see above)"; exit 1; }
