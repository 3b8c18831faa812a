#!/usr/bin/env bash
# Soak: a 48 h static covariance run (the paper's static analysis, every
# Table 1 model) with memory and positive-definiteness checks.
#   bash bench/soak_covariance.sh [HOURS] [IMU_RATE_HZ] [PROPAGATE_EVERY] [OUT]
# defaults 48 h, 200 Hz, 1 (every IMU sample, as the paper's configuration).
# Runs `navimpact covariance` on config/paper/covariance_static.yaml with the
# horizon set to HOURS (--allow-large: the budget of a default run is an hour
# of work), then checks: exit 0; every sigma in covariance.csv finite; maximum
# resident memory (GNU time) under 1 GB; the covariance repairs per model
# (summary.json, filter::PdCheck). Prints one line per model and the totals.
set -euo pipefail
cd "$(dirname "$0")/.."
HOURS=${1:-48}
RATE=${2:-200}
EVERY=${3:-1}
OUT=${4:-out/soak_covariance}
BIN=${NAVIMPACT_BIN:-build/bin/navimpact}
[ -x $BIN ] || { echo "soak: build first (bash scripts/build.sh)"; exit 1; }
command -v /usr/bin/time >/dev/null || { echo "soak: needs GNU time (Debian package time)"; exit 1; }
DUR=$(python3 -c "print(int(round($HOURS * 3600)))")
mkdir -p "$(dirname "$OUT")"
CFG=$(mktemp --suffix=.yaml)
trap 'rm -f "$CFG"' EXIT
sed -e "s#^model_file: \.\./models/#model_file: $PWD/config/models/#" \
    -e "s/^duration_s: .*/duration_s: $DUR/" -e "s/^imu_rate_hz: .*/imu_rate_hz: $RATE/" \
    -e "s/^output_rate_hz: .*/output_rate_hz: 0.01/" \
    -e "s/^summary_times_s: .*/summary_times_s: [3600, 21600, 86400, $DUR]/" \
    -e "s/^  propagate_every: .*/  propagate_every: $EVERY/" config/paper/covariance_static.yaml > "$CFG"
echo "soak: covariance, static, ${HOURS} h at ${RATE} Hz, propagate_every ${EVERY}, Table 1 models -> $OUT"
rc=0
/usr/bin/time -f "%e %M" -o "$OUT.time" $BIN covariance --config "$CFG" --out "$OUT" --overwrite --allow-large || rc=$?
read -r WALL RSS_KB < "$OUT.time"
echo "soak: exit $rc, ${WALL} s wall, max RSS $((RSS_KB / 1024)) MB"
[ $rc -eq 0 ] || { echo "soak: FAILED (the run stopped)"; exit 1; }
python3 - "$OUT" "$RSS_KB" <<'PY'
import csv, json, math, sys
out, rss_kb = sys.argv[1], int(sys.argv[2])
ok = True
rows = list(csv.reader(open(out + "/covariance.csv")))
bad = [r for r in rows[1:] if not all(math.isfinite(float(v)) for v in r[3:])]
print(f"soak: covariance.csv {len(rows) - 1} rows, {len(bad)} with a non-finite sigma")
ok &= not bad
for r in json.load(open(out + "/summary.json"))["runs"]:
    last = r["at"][-1]
    extra = ""
    if r["covariance_repairs"]:
        extra = f", worst eigenvalue {r['covariance_repair_worst_eigenvalue']:.3g}, first at {r['covariance_first_repair_s']:.0f} s"
    print(f"soak: {r['model_set']:13s} {r['model']:11s} {r['filter_states']:2d} states: at {last['t_s']:.0f} s "
          f"sigma pos N {last['sigma_pos_N_m']:.4g} m, yaw {math.degrees(last['sigma_yaw_rad']):.4g} deg, "
          f"{r['covariance_repairs']} covariance repairs{extra}")
if rss_kb > 1024 * 1024:
    print("soak: FAILED: more than 1 GB resident"); ok = False
print("soak: ok" if ok else "soak: FAILED")
sys.exit(0 if ok else 1)
PY
