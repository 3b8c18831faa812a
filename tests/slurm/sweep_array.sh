#!/usr/bin/env bash
# Run inside tests/slurm/with_cluster.sh. A small sweep goes to Slurm the way a
# user sends it: `navimpact sweep --emit-slurm DIR --shards 4`, then
# `bash DIR/submit.sh` (a 4-task job array plus a merge job with
# --dependency=afterok). The merged map must equal the unsharded run on this
# machine byte for byte (sweep.json, report.md, every heat map). Then a failed
# task is simulated (its shard removed): the merge names the missing shard,
# `bash DIR/submit.sh 3` reruns only array index 3 (the other shards are not
# touched) and the new merge is again identical.
#
#   bash sweep_array.sh NAVIMPACT CONFIG WORKDIR
set -euo pipefail
NI=$1 CONFIG=$2 W=$3
mkdir -p "$W"
cd "$W"

wait_jobs() {  # poll squeue until the jobs are gone (no accounting: no sacct), then check their states
  local t0 deadline j states
  t0=$(date +%s)
  deadline=$((t0 + 240))
  while squeue -h -j "$1,$2" 2>/dev/null | grep -q .; do
    [ "$(date +%s)" -lt "$deadline" ] || { echo "jobs $1 $2 not finished after 240 s:"; squeue; exit 1; }
    sleep 0.5
  done
  echo "array job $1 and merge job $2 finished in $(( $(date +%s) - t0 )) s"
  for j in "$1" "$2"; do
    states=$(scontrol show job "$j" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | sort | uniq -c | tr '\n' ' ')
    echo "job $j: $states"
    if [ -z "$states" ] || echo "$states" | grep -qv COMPLETED; then
      echo "job $j did not complete; logs:"; tail -n 5 "$W"/slurm/logs/* || true
      exit 1
    fi
  done
}
same_outputs() {
  local f
  for f in sweep.json report.md $(cd "$W/single" && ls map_*.png); do
    cmp "$W/single/$f" "$1/$f" || { echo "$f differs between the Slurm merge and the unsharded sweep"; exit 1; }
  done
}

"$NI" sweep --config "$CONFIG" --emit-slurm "$W/slurm" --shards 4 --partition "$SLURM_TEST_PARTITION" \
  --time 00:10:00 --merge-time 00:05:00 --cpus-per-task 1 --work "$W/shards" --result "$W/result"
out=$(bash "$W/slurm/submit.sh")
echo "$out"
read -r A M < <(tail -n 1 "$W/slurm/jobs.txt")
echo "$A $M" | tr ' ' '\n' >>"$SLURM_TEST_JOBS_FILE"
wait_jobs "$A" "$M"

"$NI" sweep --config "$CONFIG" --threads 2 --out "$W/single" >/dev/null
same_outputs "$W/result"
echo "merged map of the 4-task Slurm array equals the unsharded sweep byte for byte"

# A failed task: its shard is missing; the merge names it.
rm -rf "$W/shards/shard_3"
if "$NI" sweep-merge "$W"/shards/shard_{1..4} --out "$W/partial" 2>"$W/merge_err.txt"; then
  echo "merge with a missing shard succeeded"; exit 1
fi
grep -q "shard_3" "$W/merge_err.txt" || { echo "merge did not name the missing shard:"; cat "$W/merge_err.txt"; exit 1; }
[ ! -e "$W/partial" ] || { echo "a failing merge left $W/partial behind"; exit 1; }
echo "merge without shard 3: $(cat "$W/merge_err.txt")"
before=$(stat -c %Y "$W"/shards/shard_{1,2,4}/sweep_runs.bin | tr '\n' ' ')
bash "$W/slurm/submit.sh" 3
read -r A M < <(tail -n 1 "$W/slurm/jobs.txt")
echo "$A $M" | tr ' ' '\n' >>"$SLURM_TEST_JOBS_FILE"
wait_jobs "$A" "$M"
after=$(stat -c %Y "$W"/shards/shard_{1,2,4}/sweep_runs.bin | tr '\n' ' ')
[ "$before" = "$after" ] || { echo "shards 1, 2, 4 were redone ($before -> $after)"; exit 1; }
same_outputs "$W/result"
echo "array index 3 rerun alone; the new merge equals the unsharded sweep byte for byte"
