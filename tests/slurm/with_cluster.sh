#!/usr/bin/env bash
# Run a command against a private single-node Slurm cluster brought up from
# Debian's packages (slurm-wlm 22.05, munge), then shut the cluster down.
#
#   bash tests/slurm/with_cluster.sh DIR -- COMMAND [ARG...]
#
# Everything lives under DIR (created afresh): its own munged (own key and
# socket, so a munged already running on the machine, e.g. another test's or
# the system's, is neither used nor disturbed), a slurm.conf with free ports,
# the slurmctld state, the slurmd spool, logs and pid files. The daemons run
# in the foreground as children of this script (slurmctld -D, slurmd -D,
# munged -F) and are stopped by the process ids in their pid files on any
# exit, after cancelling the jobs still queued. COMMAND runs with SLURM_CONF
# exported and SLURM_TEST_PARTITION set.
#
# No cgroups are needed: ProctrackType=proctrack/linuxproc, TaskPlugin=task/none,
# SelectType=select/cons_tres, accounting and job completion 'none' (so there is
# no sacct: callers poll squeue / scontrol), ReturnToService=2.
#
# Exit status: COMMAND's, or 77 (CTest SKIP_RETURN_CODE) with one line saying
# why when the cluster cannot be brought up on this machine (packages missing,
# not root and the daemons refuse to run as this user, daemons not up in time).
set -uo pipefail

skip() { echo "SKIP slurm: $*" >&2; exit 77; }
die() { echo "slurm harness: $*" >&2; exit 1; }

[ $# -ge 3 ] && [ "$2" = "--" ] || die "usage: with_cluster.sh DIR -- COMMAND [ARG...]"
DIR=$1
shift 2

for b in munged mungekey slurmctld slurmd sbatch squeue scontrol scancel sinfo; do
  command -v "$b" >/dev/null 2>&1 || [ -x "/usr/sbin/$b" ] ||
    skip "'$b' not found: install the Debian packages slurm-wlm and munge (scripts/deps.sh does)"
done
export PATH="$PATH:/usr/sbin"

ME=$(id -un)
if [ "$(id -u)" -eq 0 ]; then
  getent passwd munge >/dev/null || skip "no 'munge' user (the munge package creates it)"
  getent passwd slurm >/dev/null || skip "no 'slurm' user (the slurm-wlm package creates it)"
  MUNGE_USER=munge SLURM_USER=slurm
  as_munge() { runuser -u munge -- "$@"; }
else
  # Not root: everything runs as this user (SlurmUser = SlurmdUser = $ME);
  # jobs can then only run as this user, which is all the tests need.
  MUNGE_USER=$ME SLURM_USER=$ME
  as_munge() { "$@"; }
fi

rm -rf "$DIR"
mkdir -p "$DIR/munge/private" "$DIR/slurm/state" "$DIR/slurm/spool" "$DIR/slurm/log" "$DIR/slurm/run" "$DIR/work" ||
  die "cannot create $DIR"
chmod 755 "$DIR" "$DIR/munge" "$DIR/work"
chmod 700 "$DIR/munge/private"
if [ "$(id -u)" -eq 0 ]; then
  chown -R munge:munge "$DIR/munge"
  chown -R slurm:slurm "$DIR/slurm"
fi

PIDS=()          # foreground daemons started here (their runuser wrappers when root)
PIDFILES=()      # pid files written by the daemons themselves
JOBS_FILE="$DIR/work/submitted_jobs"   # callers append job ids here
: >"$JOBS_FILE"
stop_cluster() {
  if [ -n "${SLURM_CONF:-}" ] && [ -s "$JOBS_FILE" ]; then
    # shellcheck disable=SC2046
    scancel $(sort -u "$JOBS_FILE") >/dev/null 2>&1 || true
  fi
  local f p
  for f in "${PIDFILES[@]}"; do
    [ -s "$f" ] || continue
    p=$(cat "$f")
    case "$p" in '' | *[!0-9]*) continue ;; esac
    kill -TERM "$p" 2>/dev/null || true
  done
  for p in "${PIDS[@]}"; do
    # Our own children: wait for them (bounded), then make sure they are gone.
    for _ in $(seq 1 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$p" 2>/dev/null || true
    wait "$p" 2>/dev/null || true
  done
}
trap stop_cluster EXIT
trap 'exit 143' INT TERM

# --- munge: a private daemon with its own key and socket -------------------
MS="$DIR/munge/munge.socket"
as_munge mungekey -c -k "$DIR/munge/private/munge.key" >/dev/null 2>&1 ||
  skip "mungekey could not create a key as user $MUNGE_USER"
if [ "$(id -u)" -eq 0 ]; then
  runuser -u munge -- munged -F --socket="$MS" --key-file="$DIR/munge/private/munge.key" \
    --pid-file="$DIR/munge/munged.pid" --log-file="$DIR/munge/private/munged.log" \
    --seed-file="$DIR/munge/private/munged.seed" >"$DIR/munge/munged.out" 2>&1 &
else
  munged -F --socket="$MS" --key-file="$DIR/munge/private/munge.key" \
    --pid-file="$DIR/munge/munged.pid" --log-file="$DIR/munge/private/munged.log" \
    --seed-file="$DIR/munge/private/munged.seed" >"$DIR/munge/munged.out" 2>&1 &
fi
PIDS+=($!)
PIDFILES+=("$DIR/munge/munged.pid")
for _ in $(seq 1 50); do [ -S "$MS" ] && break; sleep 0.1; done
[ -S "$MS" ] || skip "munged did not start as user $MUNGE_USER: $(tail -n 1 "$DIR/munge/munged.out" 2>/dev/null)"

# --- slurm.conf with two free ports -----------------------------------------
port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
NODE_LINE=$(slurmd -C 2>/dev/null | head -n 1)
case "$NODE_LINE" in NodeName=*) ;; *) skip "slurmd -C did not describe this node: '$NODE_LINE'" ;; esac
NODE_NAME=${NODE_LINE%% *}
NODE_NAME=${NODE_NAME#NodeName=}
# The node's CPUs and memory as slurmd detects them; memory is not scheduled.
NODE_LINE=$(echo "$NODE_LINE" | sed -e 's/ RealMemory=[0-9]*//')
PORT=0
for cand in $(seq $((20000 + ($$ * 7) % 30000)) 7 62000) $(seq 20000 7 62000); do
  if port_free "$cand" && port_free $((cand + 1)); then PORT=$cand; break; fi
done
[ "$PORT" -gt 0 ] || skip "no two free TCP ports found on 127.0.0.1"
CONF="$DIR/slurm/slurm.conf"
S="$DIR/slurm"
cat >"$CONF" <<EOF
# Private single-node test cluster written by tests/slurm/with_cluster.sh
ClusterName=navimpacttest
SlurmctldHost=${NODE_NAME}(127.0.0.1)
SlurmUser=${SLURM_USER}
SlurmdUser=$( [ "$(id -u)" -eq 0 ] && echo root || echo "$ME")
SlurmctldPort=${PORT}
SlurmdPort=$((PORT + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=${MS}
StateSaveLocation=${S}/state
SlurmdSpoolDir=${S}/spool
SlurmctldPidFile=${S}/run/slurmctld.pid
SlurmdPidFile=${S}/run/slurmd.pid
SlurmctldLogFile=${S}/log/slurmctld.log
SlurmdLogFile=${S}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
ReturnToService=2
MpiDefault=none
SchedulerType=sched/backfill
MinJobAge=600
${NODE_LINE} NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$CONF"
export SLURM_TEST_PARTITION=test
export SLURM_TEST_JOBS_FILE="$JOBS_FILE"

slurmctld -D -f "$CONF" >"$S/log/slurmctld.out" 2>&1 &
PIDS+=($!)
PIDFILES+=("$S/run/slurmctld.pid")
slurmd -D -f "$CONF" >"$S/log/slurmd.out" 2>&1 &
PIDS+=($!)
PIDFILES+=("$S/run/slurmd.pid")

state=""
for _ in $(seq 1 150); do  # up to 30 s
  state=$(sinfo -h -n "$NODE_NAME" -o %T 2>/dev/null | head -n 1)
  [ "$state" = idle ] && break
  sleep 0.2
done
if [ "$state" != idle ]; then
  why=$(tail -n 2 "$S/log/slurmctld.log" "$S/log/slurmd.log" "$S/log/slurmctld.out" "$S/log/slurmd.out" 2>/dev/null |
        grep -v '^==>' | grep -v '^$' | tail -n 3 | tr '\n' ' ')
  skip "the node did not become idle within 30 s (state '${state:-none}'); daemon logs: $why"
fi
echo "slurm: single-node cluster up (node $NODE_NAME, ports $PORT/$((PORT + 1)), conf $CONF)"

"$@"
