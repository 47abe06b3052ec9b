"""Field speed from Python: magsep.field on 1e6 numpy points against the Rust benchmark
(`magsep bench field`) and against magpylib's getB, for the same cylinder and points.

    python python/examples/bench_field.py [--magsep target/release/magsep] [--n 1000000]
    RAYON_NUM_THREADS=1 python python/examples/bench_field.py     # one thread, as magpylib

The case is the benchmark's `field_anchor` axial case: a cylinder of radius 1 m and half
height 1 m at the origin, axis z, polarisation mu0 M = 1 T along z, at n points uniform in
[-3, 3]^3 m drawn by SplitMix64 seeded with 42 (as `magsep bench field` draws them). Best of
`--reps` runs each; points per second.
"""

import argparse
import json
import subprocess
import time

import numpy as np

import magsep

MU0 = 1.25663706212e-6  # the library's MU0 [T m/A]


def splitmix_points(n: int) -> np.ndarray:
    """n points uniform in [-3, 3]^3 from SplitMix64(42), x, y, z per point in that order."""
    with np.errstate(over="ignore"):
        k = np.arange(1, 3 * n + 1, dtype=np.uint64)
        z = np.uint64(42) + k * np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    u = (z >> np.uint64(11)).astype(np.float64) * (1.0 / (1 << 53))
    return (-3.0 + 6.0 * u).reshape(n, 3)


def best(f, reps: int) -> float:
    t = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        t = min(t, time.perf_counter() - t0)
    return t


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--magsep", default="target/release/magsep", help="the CLI, for `bench field --json` ('' to skip)")
    p.add_argument("--n", type=int, default=1_000_000)
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--no-magpylib", action="store_true", help="skip the magpylib comparison")
    args = p.parse_args()

    pts = splitmix_points(args.n)
    fibre = magsep.Cylinder(radius=1.0, half_length=1.0, magnetisation=(0.0, 0.0, 1.0 / MU0))
    b = magsep.field([fibre], pts)
    fresh = args.n / best(lambda: magsep.field([fibre], pts), args.reps)
    # the Rust bench writes into one buffer for all its runs: out= does the same
    out = np.empty_like(pts)
    py_rate = args.n / best(lambda: magsep.field([fibre], pts, out=out), args.reps)
    print(json.dumps({"name": "python_field", "points": args.n, "points_per_s": py_rate, "points_per_s_new_array": fresh}))

    if args.magsep:
        out = subprocess.run([args.magsep, "bench", "field", "--json"], capture_output=True, text=True, check=True).stdout
        rows = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
        for r in rows:
            if r.get("name") == "field_anchor" and r.get("case") == "axial":
                print(json.dumps({"rust_threads": r["threads"], "rust_points_per_s": r["points_per_s"], "python_over_rust": py_rate / r["points_per_s"]}))

    if args.no_magpylib:
        return
    try:
        import magpylib
    except ImportError:
        print("magpylib is not installed: pip install magpylib")
        return
    cyl = magpylib.magnet.Cylinder(polarization=(0.0, 0.0, 1.0), dimension=(2.0, 2.0))
    ref = cyl.getB(pts)
    tm = best(lambda: cyl.getB(pts), max(1, args.reps // 2))
    outside = np.linalg.norm(ref, axis=1) > 0
    rel = np.abs(np.linalg.norm(b - ref, axis=1))[outside] / np.linalg.norm(ref, axis=1)[outside]
    print(json.dumps({
        "magpylib": magpylib.__version__,
        "magpylib_points_per_s": args.n / tm,
        "magsep_over_magpylib": py_rate / (args.n / tm),
        "median_relative_difference": float(np.median(rel)),
        "max_relative_difference": float(rel.max()),
    }))


if __name__ == "__main__":
    main()
