#!/usr/bin/env python3
"""Recording overhead of whole `magsep run` processes: each scene run with and without
`--record` (at the scene's own `record.every`), alternating which goes first, and the ratios.

For every case it prints one JSON line

    {"case": ..., "command": ..., "rounds": n, "cpu_plain_s": ..., "cpu_recorded_s": ...,
     "cpu_ratio": ..., "cpu_ratio_min": ..., "cpu_ratio_max": ..., "wall_ratio": ...,
     "date_utc": ..., "load_average_1min": ...}

where the times are medians over the rounds, `cpu` is the process's user + system time (less
sensitive to a busy machine than wall time) and each ratio is the median (min, max) over the
rounds of recorded / plain. The process's start (~5 ms) is in both runs. `magsep bench
recording --json` measures the same inside one process, without the start; `valgrind
--tool=callgrind` instruction counts of the two runs give a repeatable ratio under any load.

Usage (from the repository root): scripts/recording_overhead.py [--rounds N] [--threads T]
[CASE ...] with CASE among levitation, mds, brownian, packing (default: all) and T the
`--threads` of the runs (default 1; `default`: no `--threads`, the machine's cores). magsep is taken from
$MAGSEP (default target/release/magsep). Exit code 1 if a run fails.
"""

import datetime
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

# case -> scene and overrides (shortened where a full run takes minutes; `record.every` is the
# scene's own)
CASES = {
    "levitation": ["scenes/levitation_single.toml"],
    "mds": ["scenes/mds_case1a.toml", "--set", "particle_fluid.duration=0.18"],
    # a 10 ms run of 4 particles (the CI scene): the recording's fixed cost (opening and
    # closing the file, ~2 M instructions) against almost nothing; `magsep bench recording`
    # times the 500-particle `scenes/brownian_concentrated.toml`
    "brownian": ["tests/data/brownian_short.toml"],
    "packing": ["scenes/spheres_500.toml"],
}


def run(cmd):
    """CPU (user + system) and wall time of one run of `cmd`."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    err = p.stderr.read().decode(errors="replace")
    p.stderr.close()
    if status != 0:
        sys.exit(f"failed ({status}): {' '.join(cmd)}\n{err}")
    return usage.ru_utime + usage.ru_stime, wall


def main(argv):
    rounds = 10
    if "--rounds" in argv:
        i = argv.index("--rounds")
        rounds = int(argv[i + 1])
        del argv[i : i + 2]
    threads = ["--threads", "1"]
    if "--threads" in argv:
        i = argv.index("--threads")
        threads = [] if argv[i + 1] == "default" else ["--threads", argv[i + 1]]
        del argv[i : i + 2]
    cases = argv or list(CASES)
    magsep = os.environ.get("MAGSEP", "target/release/magsep")
    out = os.path.join(tempfile.gettempdir(), f"magsep-recording-overhead-{os.getpid()}.mcap")
    for case in cases:
        if case not in CASES:
            sys.exit(f"unknown case {case!r}; expected one of {', '.join(CASES)}")
        plain_cmd = [magsep, "run", "--quiet", *threads, *CASES[case]]
        rec_cmd = plain_cmd + ["--force", "--record", out]
        plain, rec = [], []
        for r in range(rounds):
            order = [(plain_cmd, plain), (rec_cmd, rec)]
            for cmd, into in order if r % 2 == 0 else order[::-1]:
                into.append(run(cmd))
        if os.path.exists(out):
            os.remove(out)
        cpu = [b[0] / a[0] for a, b in zip(plain, rec)]
        wall = [b[1] / a[1] for a, b in zip(plain, rec)]
        print(
            json.dumps(
                {
                    "case": case,
                    "command": " ".join(rec_cmd),
                    "rounds": rounds,
                    "cpu_plain_s": statistics.median(a[0] for a in plain),
                    "cpu_recorded_s": statistics.median(b[0] for b in rec),
                    "cpu_ratio": statistics.median(cpu),
                    "cpu_ratio_min": min(cpu),
                    "cpu_ratio_max": max(cpu),
                    "wall_plain_s": statistics.median(a[1] for a in plain),
                    "wall_recorded_s": statistics.median(b[1] for b in rec),
                    "wall_ratio": statistics.median(wall),
                    "wall_ratio_min": min(wall),
                    "wall_ratio_max": max(wall),
                    "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(
                        timespec="seconds"
                    ),
                    "load_average_1min": os.getloadavg()[0],
                }
            ),
            flush=True,
        )


if __name__ == "__main__":
    main(sys.argv[1:])
