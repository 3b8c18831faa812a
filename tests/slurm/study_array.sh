#!/usr/bin/env bash
# Run inside tests/slurm/with_cluster.sh: a small `navimpact study` as a Slurm
# job array of 4 shards (sbatch --array=1-4) plus a dependent merge job
# (--dependency=afterok), then the same study unsharded on this machine; the
# merged result must equal the unsharded one byte for byte (timeseries.csv
# and the metrics of study.json; the cost figures are wall-clock times).
#
#   bash study_array.sh NAVIMPACT CONFIG WORKDIR
set -euo pipefail
NI=$1 CONFIG=$2 W=$3
mkdir -p "$W/logs"
cd "$W"

cat >array.sbatch <<EOF
#!/bin/bash
#SBATCH --job-name=ni-study-shard
#SBATCH --array=1-4
#SBATCH --ntasks=1
#SBATCH --cpus-per-task=1
#SBATCH --time=00:10:00
#SBATCH --output=$W/logs/shard_%A_%a.out
set -euo pipefail
"$NI" study --config "$CONFIG" --threads 1 --shard \${SLURM_ARRAY_TASK_ID}/4 --out "$W/shards/s\${SLURM_ARRAY_TASK_ID}"
EOF
cat >merge.sbatch <<EOF
#!/bin/bash
#SBATCH --job-name=ni-study-merge
#SBATCH --ntasks=1
#SBATCH --time=00:10:00
#SBATCH --output=$W/logs/merge_%j.out
set -euo pipefail
"$NI" study-merge "$W"/shards/s1 "$W"/shards/s2 "$W"/shards/s3 "$W"/shards/s4 --out "$W/merged"
EOF

t0=$(date +%s)
A=$(sbatch --parsable -p "$SLURM_TEST_PARTITION" array.sbatch)
echo "$A" >>"$SLURM_TEST_JOBS_FILE"
M=$(sbatch --parsable -p "$SLURM_TEST_PARTITION" --dependency=afterok:"$A" --kill-on-invalid-dep=yes merge.sbatch)
echo "$M" >>"$SLURM_TEST_JOBS_FILE"
echo "submitted array job $A (4 tasks) and merge job $M (afterok:$A)"

deadline=$((t0 + 240))
while squeue -h -j "$A,$M" 2>/dev/null | grep -q .; do
  [ "$(date +%s)" -lt "$deadline" ] || { echo "jobs not finished after 240 s:"; squeue; exit 1; }
  sleep 0.5
done
echo "array and merge finished in $(( $(date +%s) - t0 )) s"
for j in "$A" "$M"; do
  states=$(scontrol show job "$j" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | sort | uniq -c | tr '\n' ' ')
  echo "job $j: $states"
  if echo "$states" | grep -qv COMPLETED || [ -z "$states" ]; then
    echo "job $j did not complete; logs:"; tail -n 5 "$W"/logs/* || true
    exit 1
  fi
done

"$NI" study --config "$CONFIG" --threads 2 --out "$W/single" >/dev/null
cmp "$W/single/timeseries.csv" "$W/merged/timeseries.csv"
strip_cost() { grep -v -E '"(us_per_step|wall_s_per_run)"' "$1"; }
diff <(strip_cost "$W/single/study.json") <(strip_cost "$W/merged/study.json") >/dev/null ||
  { echo "study.json differs between the Slurm merge and the unsharded run"; exit 1; }
echo "merged result of the 4-task Slurm array equals the unsharded study byte for byte"
