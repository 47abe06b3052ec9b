#!/usr/bin/env bash
# Two magsep binaries (say the previous release and this one) run the same scene one after
# the other, alternating, ROUNDS times per thread count, and the wall time, user time and the
# summary's attempts and packing fraction of each run printed (the machine is shared and
# noisy: compare the binaries within a round, never across hours).
#
# Usage: scripts/bench/releases_side_by_side.sh OLD_BIN NEW_BIN [SCENE] [-- magsep run options]
# Environment: ROUNDS (default 2), THREADS (default "2 1"),
#              STEPS (default 1800: packing.max_compression_steps)
# Example (the 750-superball row of the README):
#   scripts/bench/releases_side_by_side.sh /tmp/magsep-old target/release/magsep
set -euo pipefail
old=$1 new=$2
scene=${3:-scenes/superballs_750.toml}
shift $(( $# >= 3 ? 3 : 2 ))
[ "${1:-}" = "--" ] && shift
out=$(mktemp -d)
for t in ${THREADS:-2 1}; do
  for r in $(seq 1 "${ROUNDS:-2}"); do
    for which in old new; do
      bin=$old; [ "$which" = new ] && bin=$new
      /usr/bin/time -f "%e %U" -o "$out/time" "$bin" run "$scene" --quiet --threads "$t" \
        --set "packing.max_compression_steps=${STEPS:-1800}" "$@" > "$out/summary.json"
      python3 - "$which" "$t" "$r" "$out" <<'PY'
import json, sys
which, t, r, out = sys.argv[1:]
wall, user = open(f"{out}/time").read().split()[-2:]
s = json.load(open(f"{out}/summary.json"))
print(f"{which} threads={t} round={r} wall={wall}s user={user}s "
      f"attempts={s.get('attempts')} packing_fraction={s.get('packing_fraction')}")
PY
    done
  done
done
rm -rf "$out"
