#!/usr/bin/env bash
# Replay soak: a long run (24 h by default) at 200 Hz replayed in bounded memory.
#
#   bash bench/soak_replay.sh [HOURS] [WORKDIR]        (default 24 h, build/soak_replay)
#
# 1. writes a turning-flight trajectory of HOURS hours (a lemniscate of 300 m, 2 min a
#    lap, 20 m up and down, coordinated turns; 10 Hz NED CSV made with awk);
# 2. `navimpact emulate`s it at 200 Hz with the NavChip Table 1 Ref IMU errors, GNSS at
#    1 Hz, baro and reference at 10 Hz (emulate streams the run into the rawlog block by
#    block: its memory does not grow with the run);
# 3. `navimpact replay`s it with 30 s GNSS outages every 120 s under GNU time, and checks
#    - peak resident memory of the replay <= LIMIT_MB (default 1024),
#    - exit 0 and the covariance positive definite all along: every predicted sigma in
#      solution.csv finite and > 0 and every NEES finite (its Cholesky factorisation
#      succeeded; the filter itself stops with an error naming the time if P is not
#      positive definite after an update), and in summary.json no null (a non-finite
#      number) and every outage's predicted sigma > 0.
# Prints the numbers and PASS or FAIL, writes WORKDIR/soak.json; exit 1 on FAIL.
# Needs build/bin/navimpact (bash scripts/build.sh) and /usr/bin/time (Debian: time).
# Runs at nice 10 (a 24 h run: about 10-15 min of CPU on one core, 1.2 GB of rawlog and
# 300 MB of solution.csv in WORKDIR).
set -euo pipefail
HOURS=${1:-24}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
WORK=${2:-$ROOT/build/soak_replay}
LIMIT_MB=${LIMIT_MB:-1024}
NI=$ROOT/build/bin/navimpact
[ -x "$NI" ] || { echo "soak: $NI not built (bash scripts/build.sh)" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "soak: /usr/bin/time (GNU time, Debian package 'time') is needed for the peak memory" >&2; exit 1; }
mkdir -p "$WORK"
DUR=$(awk -v h="$HOURS" 'BEGIN { printf "%d", h * 3600 }')

echo "== trajectory: $HOURS h ($DUR s) at 10 Hz"
awk -v dur="$DUR" 'BEGIN {
  A = 300.0; T = 120.0; pi = atan2(0, -1); w = 2 * pi / T; g = 9.80665; rate = 10.0
  print "time_s,x_N_m,x_E_m,x_D_m,roll_rad,pitch_rad,yaw_rad"
  n = int(dur * rate + 0.5); unwrap = 0; have = 0
  for (k = 0; k <= n; k++) {
    t = k / rate
    N = A * sin(w * t); E = A * sin(w * t) * cos(w * t); D = -20.0 * sin(0.5 * w * t)
    vN = A * w * cos(w * t); vE = A * w * cos(2 * w * t); vD = -10.0 * w * cos(0.5 * w * t)
    aN = -A * w * w * sin(w * t); aE = -2 * A * w * w * sin(2 * w * t)
    yaw = atan2(vE, vN)
    if (have) { d = yaw - prev; while (d > pi) d -= 2 * pi; while (d < -pi) d += 2 * pi; unwrap += d } else { unwrap = yaw; have = 1 }
    prev = yaw
    v2 = vN * vN + vE * vE; if (v2 < 1e-9) v2 = 1e-9
    turn = (vN * aE - vE * aN) / v2
    roll = atan2(sqrt(v2) * turn, g); pitch = atan2(-vD, sqrt(v2))
    printf "%.2f,%.6f,%.6f,%.6f,%.8f,%.8f,%.8f\n", t, N, E, D, roll, pitch, unwrap
  }
}' > "$WORK/trajectory.csv"

cat > "$WORK/emulation.yaml" <<EOF
# soak run written by bench/soak_replay.sh
trajectory:
  file: trajectory.csv
  system: ned
  columns: {time: time_s, north: x_N_m, east: x_E_m, down: x_D_m, roll: roll_rad, pitch: pitch_rad, yaw: yaw_rad}
  attitude_unit: rad
  time_unit: s
  origin: {lat_deg: 46.5, lon_deg: 6.5, height_m: 400}
smoothing: {position_cutoff_hz: 1.0, attitude_cutoff_hz: 1.0, knot_step_s: 0.05, penalty_order: 3}
imu: {rate_hz: 200, errors: model, model: $ROOT/config/models/navchip_table1.yaml:ref, seed: 1}
gnss: {rate_hz: 1, sigma_pos_h_m: 2, sigma_pos_v_m: 4, sigma_vel_h_mps: 0.05, sigma_vel_v_mps: 0.10, seed: 2}
baro: {rate_hz: 10, sigma_m: 0.5, seed: 3}
ground_truth: {rate_hz: 10}
EOF

peak_mb() { awk '/Maximum resident set size/ { printf "%.0f", $NF / 1024 }' "$1"; }
wall_s() { awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, p, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + p[i]; printf "%.1f", s }' "$1"; }

echo "== emulate (streams)"
rm -f "$WORK/run.rawlog"
nice -n 10 /usr/bin/time -v "$NI" emulate --config "$WORK/emulation.yaml" --out "$WORK/run.rawlog" 2> "$WORK/emulate.time" | tail -2
echo "emulate: $(wall_s "$WORK/emulate.time") s wall, peak RSS $(peak_mb "$WORK/emulate.time") MB"

echo "== replay (streams)"
rm -rf "$WORK/replay"
set +e
nice -n 10 /usr/bin/time -v "$NI" replay --rawlog "$WORK/run.rawlog" --outages-every 120:30 --out "$WORK/replay" \
  > "$WORK/replay.log" 2> "$WORK/replay.time"
RC=$?
set -e
head -3 "$WORK/replay.log"
RSS=$(peak_mb "$WORK/replay.time")
WALL=$(wall_s "$WORK/replay.time")
echo "replay: exit $RC, $WALL s wall, peak RSS $RSS MB (limit $LIMIT_MB MB)"

FAIL=""
[ "$RC" -eq 0 ] || FAIL="$FAIL replay-exit-$RC"
[ "$RSS" -le "$LIMIT_MB" ] || FAIL="$FAIL memory-${RSS}MB"
ROWS=0; BAD=0
if [ "$RC" -eq 0 ]; then
  # columns 11-19: predicted sigmas; 29-32: NEES (position, velocity, attitude, all)
  read -r ROWS BAD < <(awk -F, 'NR > 1 {
      n++; ok = 1
      for (i = 11; i <= 19; i++) if (!($i + 0 > 0) || $i ~ /nan|inf/) ok = 0
      for (i = 29; i <= 32; i++) if ($i == "" || $i ~ /nan|inf/) ok = 0
      if (!ok) bad++
    } END { printf "%d %d\n", n, bad + 0 }' "$WORK/replay/solution.csv")
  [ "$BAD" -eq 0 ] || FAIL="$FAIL $BAD-epochs-not-positive-definite"
  NULLS=$(grep -c 'null' "$WORK/replay/summary.json" || true)
  [ "$NULLS" -eq 0 ] || FAIL="$FAIL summary-json-$NULLS-nulls"
  ZERO=$(grep -oE '"(horizontal|vertical)_sigma_m": [^,}]*' "$WORK/replay/summary.json" |
         awk -F': ' '!($2 + 0 > 0) { n++ } END { print n + 0 }')
  [ "$ZERO" -eq 0 ] || FAIL="$FAIL $ZERO-outage-sigmas-not-positive"
fi
OUTAGES=$(grep -c '"start_s"' "$WORK/replay/summary.json" 2>/dev/null || echo 0)
cat > "$WORK/soak.json" <<EOF
{"hours": $HOURS, "imu_rate_hz": 200, "replay_exit": $RC, "replay_wall_s": $WALL, "replay_peak_rss_mb": $RSS,
 "limit_mb": $LIMIT_MB, "epochs": $ROWS, "epochs_not_positive_definite": $BAD, "outages": $OUTAGES,
 "emulate_wall_s": $(wall_s "$WORK/emulate.time"), "emulate_peak_rss_mb": $(peak_mb "$WORK/emulate.time"),
 "rawlog_bytes": $(stat -c %s "$WORK/run.rawlog")}
EOF
if [ -z "$FAIL" ]; then
  echo "PASS: $HOURS h at 200 Hz replayed in $WALL s, peak RSS $RSS MB <= $LIMIT_MB MB; $ROWS epochs, covariance positive definite at every one ($WORK/soak.json)"
else
  echo "FAIL:$FAIL ($WORK/soak.json)"
  exit 1
fi
