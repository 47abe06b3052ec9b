//! `magsep bench field` and `magsep chart field`: speed of the cylinder field kernel, and its
//! accuracy against cost next to the dipole and multipole far fields.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use magsep_systems::field::{CylinderSource, EXACT};
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

/// Points per second of `f` over `points` on `threads` threads (best of `reps`).
fn rate(points: &[DVec3], threads: usize, reps: usize, f: &(dyn Fn(DVec3) -> f64 + Sync)) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t = Instant::now();
        let s: f64 = pool.install(|| {
            points
                .par_chunks(4096)
                .map(|c| c.iter().map(|&p| f(black_box(p))).sum::<f64>())
                .sum()
        });
        black_box(s);
        best = best.min(t.elapsed().as_secs_f64());
    }
    points.len() as f64 / best
}

/// `magsep bench field [--json] [--quick]`: points per second, one thread and all threads.
///
/// # Errors
/// Never at present (kept for symmetry with the other benchmarks).
pub fn bench_field(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let n = if quick { 100_000 } else { 1_000_000 };
    let reps = if quick { 1 } else { 3 };
    let points = bench_points(n, 7);
    let all = rayon::current_num_threads();
    let mut rows = Vec::new();
    let mut threads_list = vec![1];
    if all > 1 {
        threads_list.push(all);
    }
    for (case, dir) in cases() {
        let src = CylinderSource::new(DVec3::ZERO, DVec3::Z, RADIUS, HALF_LENGTH, dir * 1e6);
        for &threads in &threads_list {
            let field = |p: DVec3| src.field(p, EXACT).b.x;
            let pps = rate(&points, threads, reps, &field);
            emit(
                &mut rows,
                as_json,
                json!({"name": "field", "case": case, "threads": threads, "points": n, "points_per_s": pps}),
            )?;
        }
        let grad = |p: DVec3| src.field_gradient(p, EXACT).grad_b.x_axis.x;
        let pps = rate(&points[..n / 4], 1, reps, &grad);
        emit(
            &mut rows,
            as_json,
            json!({"name": "field_gradient", "case": case, "threads": 1, "points": n / 4, "points_per_s": pps}),
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

/// `magsep chart field --out DIR`: error against distance and against cost.
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
