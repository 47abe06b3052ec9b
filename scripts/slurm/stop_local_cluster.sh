#!/usr/bin/env bash
# Stops the one-node cluster started by start_local_cluster.sh: slurmd and slurmctld by their
# pid files, and munged by its own pid file. Leaves the packages, the configuration and the
# state directory in place (a later start reuses them). Safe to call when nothing runs.
set -euo pipefail
STATE_DIR="${MAGSEP_SLURM_DIR:-/var/spool/magsep-slurm}"

stop() { # name pidfile
  local pid
  [ -f "$2" ] || return 0
  pid="$(cat "$2")"
  if kill -0 "$pid" 2> /dev/null; then
    echo "stop_local_cluster: stopping $1 ($pid)"
    kill "$pid"
    for _ in $(seq 1 40); do kill -0 "$pid" 2> /dev/null || break; sleep 0.25; done
    if kill -0 "$pid" 2> /dev/null; then
      echo "stop_local_cluster: $1 ($pid) still running after 10 s" >&2
      return 1
    fi
  fi
  rm -f "$2"
}

stop slurmd "$STATE_DIR/run/slurmd.pid"
stop slurmctld "$STATE_DIR/run/slurmctld.pid"
if [ "${1:-}" = "--munge" ]; then
  stop munged /run/munge/munged.pid
fi
