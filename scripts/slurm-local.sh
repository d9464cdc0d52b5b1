#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, for the tests of docs/scale-out.md (issue 28).
#
#   bash scripts/slurm-local.sh run -- COMMAND [ARGS...]
#
# installs slurm-wlm and munge (Debian, idempotent, as root), writes a munge key and a
# slurm.conf for this host into a new temporary directory (state, spool, logs and pid files
# there too), starts munged, slurmctld and slurmd, waits until `sinfo` shows the node idle, runs
# COMMAND with SLURM_CONF (and SCATTERLOC_SLURM_DIR) exported, and on exit — also on failure or
# Ctrl-C — stops exactly the daemons it started, by their pid files, and removes the directory.
# The exit status is COMMAND's. Root is needed (Slurm runs its jobs as the submitting user, and
# slurmd starts them); ports: SLURMCTLD_PORT (default 6817) and SLURMD_PORT (6818).
set -euo pipefail

if [ "${1:-}" != "run" ] || [ "${2:-}" != "--" ] || [ $# -lt 3 ]; then
  echo "usage: bash scripts/slurm-local.sh run -- COMMAND [ARGS...]" >&2
  exit 2
fi
shift 2

if [ "$(id -u)" -ne 0 ]; then
  echo "slurm-local: the local cluster runs as root (slurmd starts the jobs)" >&2
  exit 1
fi

# Debian's slurm-wlm (slurmctld, slurmd, sbatch, srun, squeue, sinfo, scontrol) and munge.
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
  || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  t0=$SECONDS
  if ! DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null 2>&1; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
  fi
  echo "slurm-local: installed slurm-wlm and munge in $((SECONDS - t0)) s"
fi

dir=$(mktemp -d /tmp/scatterloc-slurm.XXXXXX)
chmod 755 "$dir"
mkdir -p "$dir/state" "$dir/spool" "$dir/log" "$dir/run" "$dir/munge"
chmod 755 "$dir/munge"

stop() {
  local status=$? stopped=""
  # Exactly the daemons started here, newest first, by their pid files.
  for pidfile in "$dir/run/slurmd.pid" "$dir/run/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -s "$pidfile" ] || continue
    pid=$(cat "$pidfile")
    kill "$pid" 2>/dev/null || continue
    for _ in $(seq 50); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -9 "$pid" 2>/dev/null || true
    if kill -0 "$pid" 2>/dev/null; then
      echo "slurm-local: $(basename "$pidfile" .pid) (pid $pid) did not stop" >&2
      status=1
    else
      stopped="$stopped $(basename "$pidfile" .pid)"
    fi
  done
  echo "slurm-local: stopped${stopped:- nothing}"
  if [ "$status" -ne 0 ] && [ -d "$dir/log" ]; then
    for f in "$dir"/log/*.log; do
      [ -s "$f" ] || continue
      echo "---- $f (last lines)" >&2
      tail -n 15 "$f" >&2
    done
  fi
  rm -rf "$dir"
  exit "$status"
}
trap stop EXIT
trap 'exit 130' INT TERM

# munge: a fresh key for this cluster only, the socket in the temporary directory.
head -c 1024 /dev/urandom >"$dir/munge/munge.key"
chmod 400 "$dir/munge/munge.key"
munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
  --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
  --seed-file="$dir/munge/munged.seed"

host=$(hostname -s)
mem_mb=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
cat >"$dir/slurm.conf" <<EOF
# A single-node cluster of scripts/slurm-local.sh (generated; removed on exit).
ClusterName=scatterloc-local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SwitchType=switch/none
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldPort=${SLURMCTLD_PORT:-6817}
SlurmdPort=${SLURMD_PORT:-6818}
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
# Finished jobs stay visible to scontrol for 10 min (no accounting database here).
MinJobAge=600
NodeName=$host CPUs=$(nproc) RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$dir/slurm.conf" SCATTERLOC_SLURM_DIR="$dir"

t0=$SECONDS
slurmctld
slurmd
# Until the node reports idle (a minute at most).
for _ in $(seq 120); do
  state=$(sinfo -h -o '%T' 2>/dev/null || true)
  [ "$state" = "idle" ] && break
  sleep 0.5
done
if [ "$state" != "idle" ]; then
  echo "slurm-local: the node is '$state', not idle, after 60 s" >&2
  exit 1
fi
echo "slurm-local: $host idle ($(nproc) CPUs) after $((SECONDS - t0)) s; SLURM_CONF=$SLURM_CONF"

"$@"
