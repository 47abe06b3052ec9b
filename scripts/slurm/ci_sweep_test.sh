#!/usr/bin/env bash
# The Slurm sweep test of CI: a small sweep run locally and as a Slurm job array on the one-node
# cluster of start_local_cluster.sh must give byte-identical results tables.
#
# Usage: scripts/slurm/ci_sweep_test.sh [MAGSEP_BINARY] [SWEEP_FILE]
#   MAGSEP_BINARY  default target/release/magsep (this script builds nothing)
#   SWEEP_FILE     default tests/data/sweep_slurm.toml
# Environment: MAGSEP_SLURM_SHARDS (default 3), MAGSEP_SLURM_JOB_TIMEOUT (seconds, default 900).
#
# Steps, each failing loudly:
#   0. start the cluster (installs slurm-wlm and munge if missing);
#   1. a job array of SHARDS tasks runs `MAGSEP_BINARY --version` on the node, each task's output
#      checked (the cluster runs this binary from every array task);
#   2. `magsep sweep SWEEP --out L` locally;
#   3. `magsep sweep slurm SWEEP --out S --shards SHARDS`, `sbatch --wait S/sweep.sbatch`,
#      `magsep sweep merge S`;
#   4. `cmp L/results.csv S/results.csv`.
set -euo pipefail
cd "$(dirname "$0")/../.."

bin="${1:-target/release/magsep}"
sweep="${2:-tests/data/sweep_slurm.toml}"
shards="${MAGSEP_SLURM_SHARDS:-3}"
job_timeout="${MAGSEP_SLURM_JOB_TIMEOUT:-900}"

fail() { echo "ci_sweep_test: FAILED: $*" >&2; exit 1; }

[ -x "$bin" ] || fail "no magsep binary at $bin (build it first: cargo build --release)"
[ -f "$sweep" ] || fail "no sweep file at $sweep"
bin="$(realpath "$bin")"
sweep="$(realpath "$sweep")"

echo "== ci_sweep_test: starting the one-node cluster"
t0=$(date +%s)
scripts/slurm/start_local_cluster.sh || fail "the Slurm cluster could not be installed or started"
echo "ci_sweep_test: cluster up in $(( $(date +%s) - t0 )) s"

work="$(mktemp -d /tmp/magsep-slurm-test.XXXXXX)"

# Runs `sbatch --wait ARGS...` within the time limit; on failure prints the tasks' output
# files under $work and cancels the job.
run_job() { # label, sbatch args...
  local label="$1" id rc=0
  shift
  id="$(sbatch --parsable "$@")" || fail "$label: sbatch refused the job"
  id="${id%%;*}"
  local deadline=$(( $(date +%s) + job_timeout ))
  while squeue -h -j "$id" 2> /dev/null | grep -q .; do
    if [ "$(date +%s)" -ge "$deadline" ]; then
      scancel "$id" || true
      fail "$label: job $id not finished after ${job_timeout}s"
    fi
    sleep 1
  done
  # every array task must have completed with exit code 0
  local states
  states="$(scontrol -o show job "$id" 2> /dev/null | grep -o 'JobState=[A-Z_]* .*ExitCode=[0-9:]*' || true)"
  if [ -z "$states" ]; then
    # the job record is gone (MinJobAge passed): rely on the output check below
    return 0
  fi
  if echo "$states" | grep -v 'JobState=COMPLETED' | grep -q .; then
    rc=1
  fi
  if echo "$states" | grep -o 'ExitCode=[0-9:]*' | grep -vq 'ExitCode=0:0'; then
    rc=1
  fi
  if [ "$rc" != 0 ]; then
    echo "$states" | sed 's/^/  /' >&2
    for f in "$work"/*.out "$work"/*/*.out "$work"/*/slurm/*.out; do
      [ -f "$f" ] && { echo "---- $f" >&2; tail -n 30 "$f" >&2; }
    done
    fail "$label: job $id had a failed array task"
  fi
}

echo "== ci_sweep_test: the binary runs in each of $shards array tasks"
expected="$("$bin" --version)"
run_job "version array" --array=1-"$shards" -o "$work/version-%a.out" -D "$work" \
  --wrap "\"$bin\" --version > \"$work/version.\$SLURM_ARRAY_TASK_ID\""
for i in $(seq 1 "$shards"); do
  [ -f "$work/version.$i" ] || fail "array task $i wrote nothing"
  [ "$(cat "$work/version.$i")" = "$expected" ] \
    || fail "array task $i printed '$(cat "$work/version.$i")', expected '$expected'"
done
echo "ci_sweep_test: $shards array tasks ran $expected"

echo "== ci_sweep_test: local sweep"
t0=$(date +%s)
"$bin" sweep "$sweep" --out "$work/local" || fail "local sweep failed"
echo "ci_sweep_test: local sweep in $(( $(date +%s) - t0 )) s"

echo "== ci_sweep_test: the same sweep as a Slurm job array of $shards shards"
t0=$(date +%s)
"$bin" sweep slurm "$sweep" --out "$work/slurm" --shards "$shards" || fail "magsep sweep slurm failed"
[ -f "$work/slurm/sweep.sbatch" ] || fail "magsep sweep slurm wrote no $work/slurm/sweep.sbatch"
grep -q -- "--array=1-$shards" "$work/slurm/sweep.sbatch" \
  || fail "sweep.sbatch has no --array=1-$shards directive"
run_job "sweep array" -D "$work/slurm" "$work/slurm/sweep.sbatch"
"$bin" sweep merge "$work/slurm" || fail "magsep sweep merge failed"
echo "ci_sweep_test: Slurm sweep and merge in $(( $(date +%s) - t0 )) s"

echo "== ci_sweep_test: results compared byte for byte"
[ -s "$work/local/results.csv" ] || fail "no local results.csv"
[ -s "$work/slurm/results.csv" ] || fail "no merged results.csv"
if ! cmp "$work/local/results.csv" "$work/slurm/results.csv"; then
  diff "$work/local/results.csv" "$work/slurm/results.csv" | head -n 20 >&2 || true
  fail "the merged Slurm results differ from the local sweep's"
fi
rows=$(( $(wc -l < "$work/local/results.csv") - 1 ))
rm -rf "$work"
echo "ci_sweep_test: passed ($rows result rows identical)"
