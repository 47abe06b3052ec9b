//! `magsep bench field` and `magsep chart field`: speed of the cylinder field kernel, and its
//! accuracy against cost next to the dipole and multipole far fields.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use magsep_systems::field::{CylinderSource, EXACT, FieldValue, MU0};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;
use serde_json::{Value, json};

use crate::chart::{Chart, Figure, Series, Style, write_svg};
use crate::studies::bench::{BenchError, emit};

/// Radius and half length of the benchmark fibre (aspect ratio L/D = 5).
const RADIUS: f64 = 1.0;
const HALF_LENGTH: f64 = 5.0;

/// The benchmark cases: name and magnetisation direction.
pub fn cases() -> Vec<(&'static str, DVec3)> {
    vec![
        ("axial", DVec3::Z),
        ("transverse", DVec3::X),
        ("oblique", DVec3::new(1.0, 0.5, 1.0).normalize()),
    ]
}

/// `n` random points around the fibre: uniform in the box `|x|, |y| <= 3R`, `|z| <= L + 3R`.
pub fn bench_points(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            DVec3::new(
                rng.random_range(-3.0..3.0) * RADIUS,
                rng.random_range(-3.0..3.0) * RADIUS,
                rng.random_range(-1.0..1.0) * (HALF_LENGTH + 3.0 * RADIUS),
            )
        })
        .collect()
}

/// Best-of-`reps` points per second of `run` (which evaluates `n` points) on `threads` threads.
fn rate(n: usize, threads: usize, reps: usize, run: &mut (dyn FnMut() -> f64 + Send)) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t = Instant::now();
        black_box(pool.install(&mut *run));
        best = best.min(t.elapsed().as_secs_f64());
    }
    n as f64 / best
}

/// `B` \[T\] of `src` at every point through [`CylinderSource::field_batch`] (in parallel
/// chunks).
fn field_map(src: &CylinderSource, points: &[DVec3], out: &mut [FieldValue]) {
    out.par_chunks_mut(4096)
        .zip(points.par_chunks(4096))
        .for_each(|(o, p)| src.field_batch(p, EXACT, o));
}

/// Best-of-`reps` points per second of [`field_map`] on `threads` threads, and the checksum.
fn timed_map(
    src: &CylinderSource,
    points: &[DVec3],
    threads: usize,
    reps: usize,
    out: &mut [FieldValue],
) -> (f64, f64) {
    let pps = rate(points.len(), threads, reps, &mut || {
        field_map(src, points, out);
        0.0
    });
    // the anchor's checksum: Σ|B| over the finite values, outside the timed region
    let checksum = out[..points.len()]
        .iter()
        .map(|f| f.b.length())
        .filter(|v| v.is_finite())
        .sum();
    (pps, checksum)
}

/// SplitMix64, as the anchor benchmark's README defines it (its observer points).
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// The anchor's point set: `n` points uniform in `[-3, 3]³` from SplitMix64 seeded with 42
/// (x, y, z drawn in that order per point).
pub fn anchor_points(n: usize) -> Vec<DVec3> {
    let mut rng = SplitMix64(42);
    (0..n)
        .map(|_| {
            let x = -3.0 + 6.0 * rng.unit();
            let y = -3.0 + 6.0 * rng.unit();
            let z = -3.0 + 6.0 * rng.unit();
            DVec3::new(x, y, z)
        })
        .collect()
}

/// The anchor's cases: name and polarisation μ0 M \[T\] of a cylinder of radius 1 and half
/// height 1 at the origin, axis z.
pub fn anchor_cases() -> Vec<(&'static str, DVec3)> {
    vec![
        ("axial", DVec3::Z),
        ("diametral", DVec3::X),
        ("oblique", DVec3::new(0.6, 0.0, 0.8)),
    ]
}

/// `magsep bench field [--json] [--quick]`: points per second, one thread and all threads, of
/// the field map of one fibre (L/D = 5, the `field` rows) and of the anchor benchmark's
/// cylinder and points (`field_anchor` rows, with the anchor's checksum `Σ|B|` \[T\]), and of
/// the gradient.
///
/// # Errors
/// When stdout fails.
pub fn bench_field(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let n = if quick { 100_000 } else { 1_000_000 };
    let reps = if quick { 1 } else { 5 };
    let all = rayon::current_num_threads();
    let mut rows = Vec::new();
    let mut threads_list = vec![1];
    if all > 1 {
        threads_list.push(all);
    }
    let mut out = vec![FieldValue::default(); n];
    let anchor = anchor_points(n);
    for (case, pol) in anchor_cases() {
        let src = CylinderSource::new(DVec3::ZERO, DVec3::Z, 1.0, 1.0, pol / MU0);
        for &threads in &threads_list {
            let (pps, checksum) = timed_map(&src, &anchor, threads, reps, &mut out);
            emit(
                &mut rows,
                as_json,
                json!({"name": "field_anchor", "case": case, "threads": threads, "points": n, "points_per_s": pps, "checksum": checksum,
                        "peer": {"impl": "magba", "case": case, "threads": threads, "metric": "points_per_s_best"}}),
            )?;
        }
    }
    let points = bench_points(n, 7);
    for (case, dir) in cases() {
        let src = CylinderSource::new(DVec3::ZERO, DVec3::Z, RADIUS, HALF_LENGTH, dir * 1e6);
        for &threads in &threads_list {
            let (pps, _) = timed_map(&src, &points, threads, reps, &mut out);
            emit(
                &mut rows,
                as_json,
                json!({"name": "field", "case": case, "threads": threads, "points": n, "points_per_s": pps}),
            )?;
        }
        let m = n / 4;
        let grad = &points[..m];
        let pps = rate(m, 1, reps, &mut || {
            grad.iter()
                .map(|&p| src.field_gradient(black_box(p), EXACT).grad_b.x_axis.x)
                .sum()
        });
        emit(
            &mut rows,
            as_json,
            json!({"name": "field_gradient", "case": case, "threads": 1, "points": m, "points_per_s": pps}),
        )?;
    }
    Ok(())
}

/// Relative error and cost [ns/point] of a far-field method at distance `d` radii.
#[derive(Debug, Clone, Copy)]
pub struct FarFieldPoint {
    /// Distance from the centre in fibre radii.
    pub distance: f64,
    /// Median relative error of |H - H_ref| / |H_ref|.
    pub error: f64,
    /// Cost per point \[ns\].
    pub ns: f64,
}

/// Error and cost of `method` over random directions at each distance; the reference is the
/// kernel at [`EXACT`] (closed form inside two circumradii, a converged multipole beyond).
pub fn far_field_curve(
    method: &dyn Fn(&CylinderSource, DVec3) -> DVec3,
    distances: &[f64],
    samples: usize,
) -> Vec<FarFieldPoint> {
    let m = DVec3::new(1.0, 0.5, 1.0).normalize() * 1e6;
    let src = CylinderSource::new(DVec3::ZERO, DVec3::Z, RADIUS, 3.0, m);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    distances
        .iter()
        .map(|&d| {
            let pts: Vec<DVec3> = (0..samples)
                .map(|_| {
                    let v = DVec3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    );
                    v.normalize_or(DVec3::X) * d * RADIUS
                })
                // outside the body
                .filter(|p| src.distance(*p) > 0.0)
                .collect();
            let mut errs: Vec<f64> = pts
                .iter()
                .map(|&p| {
                    let r = src.field(p, EXACT).h;
                    (method(&src, p) - r).length() / r.length()
                })
                .collect();
            errs.sort_by(f64::total_cmp);
            let t = Instant::now();
            let mut acc = DVec3::ZERO;
            for _ in 0..20 {
                for &p in &pts {
                    acc += method(&src, black_box(p));
                }
            }
            black_box(acc);
            let ns = t.elapsed().as_secs_f64() * 1e9 / (20 * pts.len().max(1)) as f64;
            FarFieldPoint {
                distance: d,
                error: errs
                    .get(errs.len() / 2)
                    .copied()
                    .unwrap_or(f64::NAN)
                    .max(1e-17),
                ns,
            }
        })
        .collect()
}

/// `magsep chart field --out DIR [--quick]`: error against distance and against cost (quick:
/// 3 distances and 50 samples instead of 9 and 400).
///
/// # Errors
/// [`BenchError::Runtime`] when the SVG cannot be written.
pub fn chart_field(out: &Path, quick: bool) -> Result<Vec<Value>, BenchError> {
    let distances: Vec<f64> = if quick {
        vec![4.0, 30.0, 1000.0]
    } else {
        vec![3.5, 5.0, 7.0, 10.0, 20.0, 50.0, 100.0, 300.0, 1000.0]
    };
    let samples = if quick { 50 } else { 400 };
    type Method = Box<dyn Fn(&CylinderSource, DVec3) -> DVec3>;
    let methods: Vec<(String, Method)> = vec![
        (
            "exact closed form".into(),
            Box::new(|s, p| s.field_with(p, None).h),
        ),
        ("dipole".into(), Box::new(|s, p| s.field_with(p, Some(0)).h)),
        (
            "multipole N=2".into(),
            Box::new(|s, p| s.field_with(p, Some(2)).h),
        ),
        (
            "multipole N=6".into(),
            Box::new(|s, p| s.field_with(p, Some(6)).h),
        ),
        (
            "multipole N=16".into(),
            Box::new(|s, p| s.field_with(p, Some(16)).h),
        ),
        (
            "auto, tolerance 1e-6".into(),
            Box::new(|s, p| s.field(p, 1e-6).h),
        ),
    ];
    let mut by_distance = Chart::new("Far field: error against distance (L/D = 3, oblique M)")
        .x_label("distance from the centre [fibre radii]")
        .y_label("median relative error of H")
        .x_log(true)
        .y_log(true);
    let mut by_cost = Chart::new("Error against cost (one point per distance)")
        .x_label("cost [ns per point]")
        .y_label("median relative error of H")
        .x_log(true)
        .y_log(true);
    let mut rows = Vec::new();
    for (name, f) in &methods {
        let curve = far_field_curve(f.as_ref(), &distances, samples);
        by_distance = by_distance.series(
            Series::new(name.clone(), curve.iter().map(|c| (c.distance, c.error)))
                .style(Style::LineMarkers),
        );
        by_cost = by_cost.series(
            Series::new(name.clone(), curve.iter().map(|c| (c.ns, c.error))).style(Style::Markers),
        );
        for c in curve {
            rows.push(json!({"method": name, "distance_radii": c.distance, "median_relative_error": c.error, "ns_per_point": c.ns}));
        }
    }
    let fig = Figure::new("Cylinder field: exact kernel, dipole and multipole", 2)
        .panel(by_distance)
        .panel(by_cost);
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let path = out.join("field_error_vs_cost.svg");
    write_svg(&path, &fig.to_svg(640.0, 440.0))
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", path.display())))?;
    Ok(rows)
}
