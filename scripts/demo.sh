#!/usr/bin/env bash
# Install dependencies, build, and run navimpact's main job on the bundled data.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
bash scripts/build.sh
OUT=${OUT:-out/demo}
mkdir -p "$OUT"
NI=build/bin/navimpact
echo "== navimpact wv + fit on the bundled ADIS16405 excerpt (datasets/) =="
"$NI" wv --input datasets/adis16405_static_excerpt.csv.gz --rate 100 --gyro-unit deg/s --acc-unit g --out "$OUT/wv"
"$NI" fit --input datasets/adis16405_static_excerpt.csv.gz --rate 100 --gyro-unit deg/s --acc-unit g \
  --structure auto --out "$OUT/fit"
echo "demo outputs in $OUT/"
