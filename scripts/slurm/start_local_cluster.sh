#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the sweep test in CI and for trying
# `magsep sweep slurm` by hand. Idempotent: a second call with the cluster up changes nothing.
#
# What it does (as root, Debian 12, no systemd):
#   1. installs Debian's `slurm-wlm` and `munge` with apt-get if `slurmctld` is missing;
#   2. creates the munge key if absent and starts `munged` as the munge user;
#   3. writes /etc/slurm/slurm.conf for one node (this host's short name, `nproc` CPUs, its
#      memory) with process tracking by /proc (proctrack/linuxproc), no task plugin, no cgroups,
#      no accounting; state, spool and logs under $MAGSEP_SLURM_DIR (default /var/spool/magsep-slurm);
#   4. starts slurmctld and slurmd as daemons and waits until `sinfo` shows the node idle.
# On failure it prints the daemons' logs and exits non-zero. Stop with stop_local_cluster.sh.
#
# Environment: MAGSEP_SLURM_DIR (state directory), MAGSEP_SLURM_TIMEOUT (seconds to wait for
# the node, default 60).
set -euo pipefail

STATE_DIR="${MAGSEP_SLURM_DIR:-/var/spool/magsep-slurm}"
TIMEOUT="${MAGSEP_SLURM_TIMEOUT:-60}"
CONF=/etc/slurm/slurm.conf
MARKER="# written by magsep scripts/slurm/start_local_cluster.sh"
NODE="$(hostname -s)"

die() {
  echo "start_local_cluster: $*" >&2
  for log in "$STATE_DIR"/log/*.log; do
    [ -f "$log" ] || continue
    echo "---- $log (last 40 lines)" >&2
    tail -n 40 "$log" >&2
  done
  exit 1
}

[ "$(id -u)" -eq 0 ] || die "must run as root (installs packages and starts daemons)"

# 1. packages
if ! command -v slurmctld > /dev/null || ! command -v slurmd > /dev/null \
  || ! command -v sbatch > /dev/null || ! command -v munged > /dev/null; then
  echo "start_local_cluster: installing slurm-wlm and munge"
  export DEBIAN_FRONTEND=noninteractive
  if ! apt-get install -y --no-install-recommends slurm-wlm munge > /tmp/magsep-slurm-apt.log 2>&1; then
    apt-get update > /tmp/magsep-slurm-apt.log 2>&1 || { cat /tmp/magsep-slurm-apt.log >&2; die "apt-get update failed"; }
    apt-get install -y --no-install-recommends slurm-wlm munge >> /tmp/magsep-slurm-apt.log 2>&1 \
      || { tail -n 40 /tmp/magsep-slurm-apt.log >&2; die "apt-get install slurm-wlm munge failed"; }
  fi
fi

mkdir -p "$STATE_DIR"/ctld "$STATE_DIR"/d "$STATE_DIR"/log "$STATE_DIR"/run

# 2. munge: the key, then the daemon as the munge user
if [ ! -s /etc/munge/munge.key ]; then
  echo "start_local_cluster: creating the munge key"
  if command -v mungekey > /dev/null; then
    mungekey --create --keyfile /etc/munge/munge.key
  else
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=128 status=none
  fi
fi
chown munge:munge /etc/munge/munge.key
chmod 0400 /etc/munge/munge.key
mkdir -p /run/munge /var/log/munge /var/lib/munge
chown munge:munge /run/munge /var/log/munge /var/lib/munge
chmod 0755 /run/munge
if ! munge -n 2> /dev/null | unmunge > /dev/null 2>&1; then
  echo "start_local_cluster: starting munged"
  runuser -u munge -- /usr/sbin/munged --force \
    || die "munged did not start (see /var/log/munge/munged.log)"
  for _ in $(seq 1 20); do
    munge -n 2> /dev/null | unmunge > /dev/null 2>&1 && break
    sleep 0.25
  done
  munge -n | unmunge > /dev/null || die "munge credentials do not round-trip"
fi

# 3. slurm.conf for one node
cpus="$(nproc)"
# slurmd's own reading of the memory [MiB]; the node offers 95 % of it to jobs
mem_mib="$(slurmd -C | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' | head -n 1)"
[ -n "$mem_mib" ] || mem_mib="$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 ))"
mem_mib="$(( mem_mib * 95 / 100 ))"
new_conf="$(cat <<CONF
$MARKER
ClusterName=magsep
SlurmctldHost=$NODE(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
ReturnToService=2
SchedulerType=sched/backfill
SlurmctldPort=6817
SlurmdPort=6818
StateSaveLocation=$STATE_DIR/ctld
SlurmdSpoolDir=$STATE_DIR/d
SlurmctldPidFile=$STATE_DIR/run/slurmctld.pid
SlurmdPidFile=$STATE_DIR/run/slurmd.pid
SlurmctldLogFile=$STATE_DIR/log/slurmctld.log
SlurmdLogFile=$STATE_DIR/log/slurmd.log
SlurmctldTimeout=30
SlurmdTimeout=60
InactiveLimit=0
MinJobAge=300
KillWait=5
Waittime=0
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mib State=UNKNOWN
PartitionName=local Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
CONF
)"
if [ -f "$CONF" ] && ! grep -qF "$MARKER" "$CONF"; then
  die "$CONF exists and was not written by this script; not overwriting it"
fi
conf_changed=0
if [ ! -f "$CONF" ] || [ "$(cat "$CONF")" != "$new_conf" ]; then
  mkdir -p /etc/slurm
  printf '%s\n' "$new_conf" > "$CONF"
  conf_changed=1
fi

alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2> /dev/null; }

# 4. the daemons
if [ "$conf_changed" = 1 ]; then
  for d in slurmd slurmctld; do
    if alive "$STATE_DIR/run/$d.pid"; then
      echo "start_local_cluster: slurm.conf changed, restarting $d"
      kill "$(cat "$STATE_DIR/run/$d.pid")"
      for _ in $(seq 1 40); do alive "$STATE_DIR/run/$d.pid" || break; sleep 0.25; done
    fi
  done
fi
if ! alive "$STATE_DIR/run/slurmctld.pid"; then
  echo "start_local_cluster: starting slurmctld"
  slurmctld || die "slurmctld did not start"
fi
if ! alive "$STATE_DIR/run/slurmd.pid"; then
  echo "start_local_cluster: starting slurmd"
  slurmd || die "slurmd did not start"
fi

# wait for the node to be idle (or mixed/allocated: jobs already running on it)
deadline=$(( $(date +%s) + TIMEOUT ))
state=""
while :; do
  state="$(sinfo -h -n "$NODE" -o '%T' 2> /dev/null | head -n 1 || true)"
  case "$state" in
    idle|mixed|allocated|completing) break ;;
    down*|drain*)
      # a node left down by an earlier run comes back once its slurmd has registered
      scontrol update NodeName="$NODE" State=RESUME > /dev/null 2>&1 || true ;;
  esac
  if [ "$(date +%s)" -ge "$deadline" ]; then
    sinfo -N -l >&2 || true
    die "node $NODE not idle after ${TIMEOUT}s (state: '${state:-none}')"
  fi
  sleep 1
done
echo "start_local_cluster: node $NODE is $state ($cpus CPUs, $mem_mib MiB); logs in $STATE_DIR/log"
