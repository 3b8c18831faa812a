#!/usr/bin/env bash
# Install dependencies, build, and run navimpact's main job on the bundled data
# (datasets/): model the bundled ADIS16405 static excerpt with GMWM, run the
# paper's static covariance study, replay the bundled emulated UAV rawlog with
# a 60 s GNSS outage after 200 s of GNSS, and run the paper's Monte Carlo
# model comparison with a modest run count; then diagnose what a white-noise
# simulation of the excerpt gets wrong, and what fixing it gains in navigation;
# finally import a real rover run (ESA Katwijk: IMU + RTK GNSS CSV) through its
# manifest into an MRPT rawlog and replay it with GNSS outages all along the
# run, scored against its RTK track.
# Re-running replaces the earlier outputs (--overwrite).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
bash scripts/build.sh
OUT=${OUT:-out/demo}
RUNS=${RUNS:-20}
NI=build/bin/navimpact
mkdir -p "$OUT"

echo
echo "== 1/8 GMWM model of the bundled ADIS16405 static excerpt (navimpact fit) =="
"$NI" fit --input datasets/adis16405_static_excerpt.csv.gz --rate 100 \
  --gyro-unit deg/s --acc-unit g --structure auto --out "$OUT/fit" --overwrite

echo
echo "== 2/8 static covariance analysis, paper Figs. 5-6 (navimpact covariance) =="
"$NI" covariance --config config/paper/covariance_static.yaml --out "$OUT/covariance" --overwrite

echo
echo "== 3/8 replay of the emulated UAV rawlog with a 60 s GNSS outage (navimpact replay) =="
"$NI" replay --config config/replay/default.yaml --out "$OUT/replay" --overwrite

echo
echo "== 4/8 Monte Carlo model comparison, paper Figs. 8-9 (navimpact study, $RUNS runs) =="
"$NI" study --config config/paper/study_navchip_uav.yaml --runs "$RUNS" --out "$OUT/study" --overwrite

echo
echo "== 5/8 what a white-noise simulation of the excerpt gets wrong, and the navigation gain (navimpact diagnose) =="
"$NI" diagnose --input datasets/adis16405_static_excerpt.csv.gz --rate 100 \
  --gyro-unit deg/s --acc-unit g --model fit:WN \
  --trajectory datasets/uav_flight_260s.csv.gz --outage 200:60 --out "$OUT/diagnose" --overwrite

echo
echo "== 6/8 import of a real rover run, ESA Katwijk IMU + RTK GNSS (navimpact import) =="
"$NI" import --manifest datasets/katwijk_rover/manifest.yaml --out "$OUT/katwijk_rover.rawlog" --overwrite
echo
echo "== 7/8 replay of the Katwijk run, outages of 20 s every 40 s, scored against the RTK track (navimpact replay) =="
"$NI" replay --config config/replay/katwijk.yaml --rawlog "$OUT/katwijk_rover.rawlog" --outages-every 40:20 \
  --out "$OUT/katwijk_replay" --overwrite

echo "== 8/8 what the simulation of the model gets wrong on the Katwijk run, and why (navimpact diagnose --run) =="
"$NI" diagnose --run "$OUT/katwijk_rover.rawlog" --model config/models/navchip_table1.yaml:ref \
  --config config/replay/katwijk.yaml --out "$OUT/katwijk_run_diagnosis" --overwrite

echo
echo "demo outputs in $OUT/:"
echo "  $OUT/fit/fit.json, model.yaml, fit_*.png"
echo "  $OUT/covariance/summary.json, covariance_*.png"
echo "  $OUT/replay/summary.json, *.png"
echo "  $OUT/study/report.md   <- read this first"
echo "  $OUT/diagnose/report.md, diagnosis.json, model_extended.yaml, *.png"
echo "  $OUT/katwijk_rover.rawlog   (rawlog-edit --info -i ...; RawLogViewer)"
echo "  $OUT/katwijk_replay/summary.json, trajectory.png, outage_end_error.png"
echo "  $OUT/katwijk_run_diagnosis/report.md, run_diagnosis.json, predicted_vs_measured.png"
