#!/usr/bin/env bash
# Detection limits of `navimpact diagnose --run` on the 240 s UAV run of its
# tests, measured with several seeds per size (README "Run diagnosis").
#   bash bench/run_diagnosis_limits.sh [SEEDS] [WORKDIR] [EFFECT ...]
# (EFFECT: null, gyro_scale, acc_scale, gyro_misalignment_rad, acc_misalignment_rad,
#  time_offset_s, lever_arm_error_m, gyro_motion_noise_factor, acc_motion_noise_factor,
#  acc_bias_rw; default all)
# For each effect and size, SEEDS runs (default 4): the first 240 s of
# datasets/uav_flight_260s.csv.gz emulated at 200 Hz with the NavChip Table 1
# Ref errors (`navimpact emulate`, GNSS 1 Hz 2 m / 4 m, baro, GT 10 Hz) plus the
# effect (`effects:` of the emulation configuration; every axis of a triad at
# that magnitude, signs drawn per axis from the seed; the accelerometer bias
# random walk as an RW term added to the sensor's model), then
#   navimpact diagnose --run RUN --model config/models/navchip_table1.yaml:ref
#     --durations 10 --reconverge 10 --realisations 8 --folds 3 --alpha 0.05 --seed S
# (the options of the tests). Prints, per effect and size, in how many runs the
# hidden cause was named and whether another cause was named; writes limits.tsv.
# Needs the build (build/bin/navimpact). Slow: about 10-20 s per run on 2 cores
# (all effects with 4 seeds: 128 runs).
set -euo pipefail
REPO=$(cd "$(dirname "$0")/.." && pwd)
SEEDS=${1:-4}
WORK=${2:-$REPO/build/run_diagnosis_limits}
shift $(( $# > 2 ? 2 : $# ))
ONLY=("$@")
NI=$REPO/build/bin/navimpact
MODEL=$REPO/config/models/navchip_table1.yaml
[ -x "$NI" ] || { echo "build first: $NI not found" >&2; exit 1; }
mkdir -p "$WORK"
OUT=$WORK/limits.tsv
printf 'effect\tsize\tseed\tnamed\tverdict\n' > "$OUT"

# effect  cause  sizes (around the smallest size named and the limit the tests assert);
# null: the sensor is the model (size 0: the NavChip Ref model; 1: that model with a
# slowly varying bias added to sensor and model alike, GM sigma 5e-3 m/s^2 and
# 2e-4 rad/s with T = 300 s, so consecutive outages share it): "named" counts
# the runs where nothing is named, "another cause named" the false alarms.
EFFECTS=(
  "null none 0 1"
  "gyro_scale scale_factor 2e-4 5e-4 2e-3"
  "acc_scale scale_factor 2e-4 5e-4 2e-3 5e-3 1e-2"
  "gyro_misalignment_rad misalignment 3e-4 1e-3 3e-3 1e-2"
  "acc_misalignment_rad misalignment 5e-4 1e-3 2e-3 5e-3 1e-2"
  "time_offset_s time_offset 2e-3 5e-3 1e-2"
  "lever_arm_error_m lever_arm 0.05 0.1 0.2 0.5"
  "gyro_motion_noise_factor in_motion_noise 3 10 30"
  "acc_motion_noise_factor in_motion_noise 10 30 100"
  "acc_bias_rw bias_instability 3e-4 1e-3 3e-3"
)

named_causes() {  # the causes of the top-level "findings" of run_diagnosis.json
  awk '/^ "findings": \[/ {f = 1; next} f && /^ \]/ {f = 0} f && /^   "cause": / {gsub(/[",]/, "", $2); print $2}' "$1" |
    sort -u | paste -sd, -
}

for line in "${EFFECTS[@]}"; do
  read -r effect cause sizes <<< "$line"
  if [ ${#ONLY[@]} -gt 0 ] && [[ ! " ${ONLY[*]} " == *" $effect "* ]]; then continue; fi
  for size in $sizes; do
    hits=0; wrong=0
    for s in $(seq 1 "$SEEDS"); do
      seed=$(( 81000 + 97 * s ))
      signs=$(awk -v s="$seed" 'BEGIN {srand(s); for (i = 0; i < 3; ++i) printf "%s%s", (i ? " " : ""), (rand() < 0.5 ? "-" : "")}')
      read -r s1 s2 s3 <<< "${signs:-}"
      model="$MODEL:ref"; effects=""
      case $effect in
        null)
          if [ "$size" = 1 ]; then
            awk '/^  ref:/ {r = 1} r && /accelerometer:/ {sub(/\)"/, ") + GM(sigma=5e-3, T=300)\"")}
                 r && /gyroscope:/ {sub(/\)"/, ") + GM(sigma=2e-4, T=300)\"")} {print}' "$MODEL" > "$WORK/model_slow_bias.yaml"
            model="$WORK/model_slow_bias.yaml:ref"
          fi ;;
        time_offset_s) effects="{time_offset_s: ${s1}$size, seed: $((seed + 13))}" ;;
        *_motion_noise_factor) effects="{$effect: $size, seed: $((seed + 13))}" ;;
        acc_bias_rw)
          gamma=$(awk -v q="$size" 'BEGIN {printf "%.6e", q / sqrt(200)}')
          awk -v g="$gamma" '/^  ref:/ {r = 1} r && /accelerometer:/ {sub(/\)"/, ") + RW(gamma=" g ")\"")} {print}' \
            "$MODEL" > "$WORK/model_rw.yaml"
          model="$WORK/model_rw.yaml:ref" ;;
        *) effects="{$effect: [${s1}$size, ${s2}$size, ${s3}$size], seed: $((seed + 13))}" ;;
      esac
      run=$WORK/${effect}_${size}_$s
      cat > "$run.yaml" <<YAML
trajectory:
  file: $REPO/datasets/uav_flight_260s.csv.gz
  system: geodetic
  columns: {time: time_s, lat: lat_rad, lon: lon_rad, height: alt_m, roll: roll_rad, pitch: pitch_rad, yaw: yaw_rad}
  latlon_unit: rad
  attitude_unit: rad
  time_unit: s
  max_gap_s: 0.25
  end_s: 240
imu: {rate_hz: 200, errors: model, model: $model, seed: $seed}
gnss: {rate_hz: 1, sigma_pos_h_m: 2.0, sigma_pos_v_m: 4.0, sigma_vel_h_mps: 0.05, sigma_vel_v_mps: 0.10, seed: $((seed + 11))}
baro: {rate_hz: 10, sigma_m: 0.5, seed: $((seed + 12))}
ground_truth: {rate_hz: 10}
YAML
      [ -n "$effects" ] && echo "effects: $effects" >> "$run.yaml"
      "$NI" emulate --config "$run.yaml" --out "$run.rawlog" --overwrite > "$run.emulate.log"
      dmodel="$MODEL:ref"
      [ "$effect" = null ] && dmodel=$model  # a null run: the diagnosis is told the sensor's model
      "$NI" diagnose --run "$run.rawlog" --model "$dmodel" --durations 10 --reconverge 10 --realisations 8 \
        --folds 3 --alpha 0.05 --seed $((seed + 1)) --out "$run.diag" --overwrite > "$run.diag.log" 2>&1
      named=$(named_causes "$run.diag/run_diagnosis.json")
      verdict=$(awk -F'"' '/^ "verdict": / {print $4}' "$run.diag/run_diagnosis.json")
      printf '%s\t%s\t%s\t%s\t%s\n' "$effect" "$size" "$seed" "${named:-none}" "$verdict" >> "$OUT"
      if [ "$cause" = none ]; then
        [ -z "$named" ] && hits=$((hits + 1))
        [ -n "$named" ] && wrong=$((wrong + 1))
      else
        [[ ",$named," == *",$cause,"* ]] && hits=$((hits + 1))
        [ -n "$named" ] && [ "$named" != "$cause" ] && wrong=$((wrong + 1))
      fi
      rm -f "$run.rawlog"
    done
    if [ "$cause" = none ]; then
      printf '%-26s %-8s nothing named %d/%d  a cause named %d/%d\n' "$effect" "$size" "$hits" "$SEEDS" "$wrong" "$SEEDS"
    else
      printf '%-26s %-8s named %d/%d  another cause named %d/%d\n' "$effect" "$size" "$hits" "$SEEDS" "$wrong" "$SEEDS"
    fi
  done
done
echo "per run: $OUT"
