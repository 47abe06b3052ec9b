//! Superquadric contact study: robustness, cost and accuracy of the common-normal solver
//! (`magsep_systems::geometry::superquadric::contact`) on random near-contact pairs.
//!
//! * Convergence and cost against the shape exponent g = 2..10 for superball pairs (a = 0.5)
//!   and supercuboid pairs (a = (0.5, 0.35, 0.7)): the Newton non-convergence (fallback) rate
//!   and the mean wall time per call, cold (GJK/EPA seed + Newton), warm (the cached surface
//!   points of the same pair after a 1e-3 move, as in an MCM sweep) and GJK/EPA alone.
//! * Accuracy against cost: error of the overlap depth and of the normal direction against a
//!   tightly converged reference (tolerance 1e-14) for parry's raw GJK/EPA, GJK/EPA projected
//!   onto the surfaces by the support maps (`polish = false`), and GJK/EPA + Newton at
//!   tolerances 1e-2..1e-12, cold and warm. parry3d-f64 0.31 exposes no GJK/EPA tolerance
//!   (GJK stops at sqrt(10 eps) relative, EPA at 100 eps), so GJK/EPA is a single point each.
//!
//! Times come from `std::time::Instant` over many calls (a benchmark, not a unit test).
//!
//! ```no_run
//! let r = magsep::studies::sq_study::run_sq_contact_study(true);
//! let summary = magsep::studies::sq_study::write_sq_study(&r, "out".as_ref()).unwrap();
//! println!("{summary}");
//! ```

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use glam::{DQuat, DVec3};
use magsep_systems::geometry::superquadric::{
    ContactOptions, ContactResult, ContactStatus, Superquadric, WarmStart, contact, gjk_epa_contact,
};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Serialize;
use serde_json::{Value, json};

use crate::chart::{Chart, Figure, Line, Series, Style, write_svg};

/// Errors drawn on log axes are clamped to this.
pub const ERROR_FLOOR: f64 = 1e-17;

/// One shape family at one exponent of the convergence/cost sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExponentPoint {
    /// `superball` or `supercuboid`.
    pub family: String,
    /// Shape exponent g (all three equal).
    pub exponent: f64,
    /// Random pairs solved cold for the failure rate.
    pub pairs: usize,
    /// Of which reached Newton (not rejected by bounding spheres or the GJK band).
    pub newton_runs: usize,
    /// Of which Newton failed (fallback to the GJK/EPA answer).
    pub fallbacks: usize,
    /// fallbacks / newton_runs.
    pub failure_rate: f64,
    /// Warm-started calls that fell back.
    pub warm_fallbacks: usize,
    /// Mean time per cold call \[ns\].
    pub cold_ns: f64,
    /// Mean time per warm-started call \[ns\].
    pub warm_ns: f64,
    /// Mean time per GJK/EPA-only call (`polish = false`) \[ns\].
    pub gjk_epa_ns: f64,
    /// Mean Newton evaluations per cold call that reached Newton.
    pub cold_iterations: f64,
    /// Mean Newton evaluations per call given a warm start.
    pub warm_iterations: f64,
}

/// One method of the accuracy-against-cost comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AccuracyPoint {
    /// Method: `parry GJK/EPA (raw)`, `GJK/EPA + projection` (`polish = false`),
    /// `GJK/EPA+Newton` (cold) or `warm Newton` (warm start after a 1e-3 move).
    pub method: String,
    /// Newton tolerance (None for GJK/EPA alone).
    pub tolerance: Option<f64>,
    /// Mean time per call \[ns\].
    pub cost_ns: f64,
    /// Mean |overlap - reference| [m, a = 0.5 scale].
    pub overlap_error_mean: f64,
    /// Max |overlap - reference|.
    pub overlap_error_max: f64,
    /// Mean angle between normal and reference normal \[rad\].
    pub normal_error_mean: f64,
    /// Max angle \[rad\].
    pub normal_error_max: f64,
    /// Calls that failed (fallback, or no parry answer).
    pub failures: usize,
}

/// Everything the study measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudyResult {
    /// Reduced sizes (a smoke run).
    pub quick: bool,
    /// Convergence/cost sweep over g.
    pub exponents: Vec<ExponentPoint>,
    /// Accuracy against cost.
    pub accuracy: Vec<AccuracyPoint>,
}

impl StudyResult {
    /// The data as JSON (a machine summary).
    ///
    /// ```
    /// let r = magsep::studies::sq_study::StudyResult { quick: true, exponents: vec![], accuracy: vec![] };
    /// assert_eq!(r.to_json()["quick"], true);
    /// ```
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }
}

/// A pair configuration: a at the origin with `qa`, b at `xb` with `qb`.
#[derive(Debug, Clone, Copy)]
struct Pair {
    a: Superquadric,
    b: Superquadric,
    qa: DQuat,
    xb: DVec3,
    qb: DQuat,
}

fn unit(r: &mut Xoshiro256PlusPlus) -> DVec3 {
    loop {
        let v = DVec3::new(r.random::<f64>(), r.random::<f64>(), r.random::<f64>()) * 2.0 - 1.0;
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

fn quat(r: &mut Xoshiro256PlusPlus) -> DQuat {
    loop {
        let v = [0; 4].map(|_| r.random::<f64>() * 2.0 - 1.0);
        let q = DQuat::from_xyzw(v[0], v[1], v[2], v[3]);
        let l = q.length();
        if l > 0.1 && l <= 1.0 {
            return q / l;
        }
    }
}

/// Random pairs of `shape` with overlap depths roughly in [-0.1, 0.15] x smallest semi-axis.
fn near_contact_pairs(shape: Superquadric, n: usize, seed: u64) -> Vec<Pair> {
    let mut r = Xoshiro256PlusPlus::seed_from_u64(seed);
    let scale = shape.semi_axes.min_element();
    (0..n)
        .map(|_| {
            let (qa, qb) = (quat(&mut r), quat(&mut r));
            let u = unit(&mut r);
            let reach =
                shape.support_value(qa.conjugate() * u) + shape.support_value(qb.conjugate() * u);
            let xb = u * (reach - scale * (0.25 * r.random::<f64>() - 0.1));
            Pair {
                a: shape,
                b: shape,
                qa,
                xb,
                qb,
            }
        })
        .collect()
}

/// The pair after a small MCM-like move of b (translation and rotation `step`).
fn moved(p: &Pair, r: &mut Xoshiro256PlusPlus, step: f64) -> Pair {
    let dq = DQuat::from_scaled_axis(unit(r) * step);
    Pair {
        xb: p.xb + unit(r) * step * p.a.semi_axes.min_element(),
        qb: (dq * p.qb).normalize(),
        ..*p
    }
}

fn call(p: &Pair, opts: &ContactOptions, warm: Option<&WarmStart>) -> ContactResult {
    contact(&p.a, DVec3::ZERO, p.qa, &p.b, p.xb, p.qb, opts, warm)
}

/// Seconds per call of `f` over `0..n`: the fastest of repeated rounds over all `n` calls
/// (at least three, for at least `min_time` in total), which filters out interference from
/// other processes.
fn time_per_call(n: usize, min_time: f64, mut f: impl FnMut(usize)) -> f64 {
    let start = Instant::now();
    let mut best = f64::INFINITY;
    let mut rounds = 0;
    while rounds < 3 || (start.elapsed().as_secs_f64() < min_time && rounds < 10_000) {
        let t = Instant::now();
        for i in 0..n {
            f(i);
        }
        best = best.min(t.elapsed().as_secs_f64());
        rounds += 1;
    }
    best / n.max(1) as f64
}

fn sweep_point(
    family: &str,
    shape: Superquadric,
    g: f64,
    pairs: usize,
    timed: usize,
    min_time: f64,
) -> ExponentPoint {
    let seed = (g * 1000.0) as u64 + if family == "superball" { 0 } else { 1 << 32 };
    let set = near_contact_pairs(shape, pairs, seed);
    let opts = ContactOptions::default();
    let (mut newton_runs, mut fallbacks, mut cold_it) = (0usize, 0usize, 0u64);
    let mut firsts = Vec::with_capacity(pairs);
    for p in &set {
        let c = call(p, &opts, None);
        cold_it += u64::from(c.iterations);
        if matches!(c.status, ContactStatus::Converged | ContactStatus::Fallback) {
            newton_runs += 1;
        }
        fallbacks += usize::from(c.status == ContactStatus::Fallback);
        firsts.push(c.warm);
    }
    let mut r = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0xABCD);
    let next: Vec<Pair> = set.iter().map(|p| moved(p, &mut r, 1e-3)).collect();
    let (mut warm_fallbacks, mut warm_it, mut warm_calls) = (0usize, 0u64, 0usize);
    for (p, w) in next.iter().zip(&firsts) {
        let c = call(p, &opts, w.as_ref());
        if w.is_some() {
            warm_it += u64::from(c.iterations);
            warm_calls += 1;
        }
        warm_fallbacks += usize::from(c.status == ContactStatus::Fallback);
    }
    let timed = timed.min(pairs);
    let cold = time_per_call(timed, min_time, |i| {
        black_box(call(&next[i], &opts, None));
    });
    let warm = time_per_call(timed, min_time, |i| {
        black_box(call(&next[i], &opts, firsts[i].as_ref()));
    });
    let rough = ContactOptions {
        polish: false,
        ..opts
    };
    let gjk = time_per_call(timed, min_time, |i| {
        black_box(call(&next[i], &rough, None));
    });
    ExponentPoint {
        family: family.into(),
        exponent: g,
        pairs,
        newton_runs,
        fallbacks,
        failure_rate: fallbacks as f64 / newton_runs.max(1) as f64,
        warm_fallbacks,
        cold_ns: cold * 1e9,
        warm_ns: warm * 1e9,
        gjk_epa_ns: gjk * 1e9,
        cold_iterations: cold_it as f64 / newton_runs.max(1) as f64,
        warm_iterations: warm_it as f64 / warm_calls.max(1) as f64,
    }
}

/// Angle between unit vectors, accurate for small angles.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

struct Errors {
    overlap: Vec<f64>,
    normal: Vec<f64>,
    failures: usize,
}

impl Errors {
    fn point(&self, method: &str, tolerance: Option<f64>, cost: f64) -> AccuracyPoint {
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        AccuracyPoint {
            method: method.into(),
            tolerance,
            cost_ns: cost * 1e9,
            overlap_error_mean: mean(&self.overlap),
            overlap_error_max: max(&self.overlap),
            normal_error_mean: mean(&self.normal),
            normal_error_max: max(&self.normal),
            failures: self.failures,
        }
    }
}

fn accuracy_points(pairs: usize, timed: usize, min_time: f64) -> Vec<AccuracyPoint> {
    let mut r = Xoshiro256PlusPlus::seed_from_u64(77);
    let mut set = Vec::with_capacity(pairs);
    for i in 0..pairs {
        let g = 2.0 + 6.0 * r.random::<f64>();
        let shape = if i % 2 == 0 {
            Superquadric::superball(0.5, g)
        } else {
            Superquadric {
                semi_axes: DVec3::new(0.5, 0.35, 0.7),
                exponents: DVec3::splat(g),
            }
        };
        set.extend(near_contact_pairs(shape, 1, r.random::<u64>()));
    }
    let all = ContactOptions {
        newton_band: f64::INFINITY,
        ..ContactOptions::default()
    };
    let exact = ContactOptions {
        tolerance: 1e-14,
        ..all
    };
    let reference: Vec<ContactResult> = set.iter().map(|p| call(p, &exact, None)).collect();
    let keep: Vec<usize> = (0..set.len())
        .filter(|&i| reference[i].status == ContactStatus::Converged)
        .collect();
    let timed = timed.min(keep.len());
    let mut moved_set = Vec::new();
    let mut warm_from = Vec::new();
    let mut rm = Xoshiro256PlusPlus::seed_from_u64(78);
    for &i in &keep {
        let m = moved(&set[i], &mut rm, 1e-3);
        moved_set.push((m, call(&m, &exact, None)));
        warm_from.push(reference[i].warm);
    }
    let errors = |results: &[ContactResult], refs: &[&ContactResult]| {
        let mut e = Errors {
            overlap: vec![],
            normal: vec![],
            failures: 0,
        };
        for (c, r) in results.iter().zip(refs) {
            if c.is_fallback() {
                e.failures += 1;
                continue;
            }
            e.overlap.push((c.overlap - r.overlap).abs());
            e.normal.push(angle(c.normal, r.normal));
        }
        e
    };
    let refs: Vec<&ContactResult> = keep.iter().map(|&i| &reference[i]).collect();
    let mut out = Vec::new();
    // parry raw
    let mut e = Errors {
        overlap: vec![],
        normal: vec![],
        failures: 0,
    };
    for &i in &keep {
        let p = &set[i];
        match gjk_epa_contact(&p.a, DVec3::ZERO, p.qa, &p.b, p.xb, p.qb) {
            Some(c) => {
                e.overlap.push((c.overlap - reference[i].overlap).abs());
                e.normal.push(angle(c.normal, reference[i].normal));
            }
            None => e.failures += 1,
        }
    }
    let cost = time_per_call(timed, min_time, |k| {
        let p = &set[keep[k]];
        black_box(gjk_epa_contact(&p.a, DVec3::ZERO, p.qa, &p.b, p.xb, p.qb));
    });
    out.push(e.point("parry GJK/EPA (raw)", None, cost));
    // projected onto the surfaces by the support maps
    let rough = ContactOptions {
        polish: false,
        ..all
    };
    let results: Vec<ContactResult> = keep.iter().map(|&i| call(&set[i], &rough, None)).collect();
    let cost = time_per_call(timed, min_time, |k| {
        black_box(call(&set[keep[k]], &rough, None));
    });
    out.push(errors(&results, &refs).point("GJK/EPA + projection", None, cost));
    let mrefs: Vec<&ContactResult> = moved_set.iter().map(|(_, r)| r).collect();
    for tol in [1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
        let o = ContactOptions {
            tolerance: tol,
            ..all
        };
        let results: Vec<ContactResult> = keep.iter().map(|&i| call(&set[i], &o, None)).collect();
        let cost = time_per_call(timed, min_time, |k| {
            black_box(call(&set[keep[k]], &o, None));
        });
        out.push(errors(&results, &refs).point("GJK/EPA+Newton", Some(tol), cost));
        let results: Vec<ContactResult> = moved_set
            .iter()
            .zip(&warm_from)
            .map(|((m, _), w)| call(m, &o, w.as_ref()))
            .collect();
        let cost = time_per_call(timed, min_time, |k| {
            black_box(call(&moved_set[k].0, &o, warm_from[k].as_ref()));
        });
        out.push(errors(&results, &mrefs).point("warm Newton", Some(tol), cost));
    }
    out
}

/// Runs the study. `quick` uses few pairs and short timings (seconds instead of about a
/// minute in release).
///
/// ```no_run
/// let r = magsep::studies::sq_study::run_sq_contact_study(true);
/// assert!(r.exponents.iter().all(|p| p.failure_rate < 1e-2));
/// ```
pub fn run_sq_contact_study(quick: bool) -> StudyResult {
    let (pairs, timed, min_time) = if quick {
        (300, 100, 0.02)
    } else {
        (20_000, 2000, 0.3)
    };
    let mut exponents = Vec::new();
    for k in 0..=16 {
        let g = 2.0 + 0.5 * k as f64;
        if quick && k % 4 != 0 {
            continue;
        }
        let ball = Superquadric::superball(0.5, g);
        let cuboid = Superquadric {
            semi_axes: DVec3::new(0.5, 0.35, 0.7),
            exponents: DVec3::splat(g),
        };
        exponents.push(sweep_point("superball", ball, g, pairs, timed, min_time));
        exponents.push(sweep_point(
            "supercuboid",
            cuboid,
            g,
            pairs,
            timed,
            min_time,
        ));
    }
    let accuracy = accuracy_points(
        if quick { 200 } else { 4000 },
        if quick { 100 } else { 2000 },
        min_time,
    );
    StudyResult {
        quick,
        exponents,
        accuracy,
    }
}

fn family_series(
    r: &StudyResult,
    family: &str,
    name: &str,
    y: impl Fn(&ExponentPoint) -> f64,
) -> Series {
    Series::new(
        name,
        r.exponents
            .iter()
            .filter(|p| p.family == family)
            .map(|p| (p.exponent, y(p))),
    )
}

/// The two charts as SVG documents: (convergence and cost against g, accuracy against cost).
///
/// ```
/// use magsep::studies::sq_study::{StudyResult, render_sq_study_charts};
/// let r = StudyResult { quick: true, exponents: vec![], accuracy: vec![] };
/// let (a, b) = render_sq_study_charts(&r);
/// assert!(a.starts_with("<svg") && b.ends_with("</svg>\n"));
/// ```
pub fn render_sq_study_charts(r: &StudyResult) -> (String, String) {
    let pct = |p: &ExponentPoint| 100.0 * p.failure_rate;
    let runs: usize = r.exponents.iter().map(|p| p.newton_runs).sum();
    let fails: usize = r.exponents.iter().map(|p| p.fallbacks).sum();
    let warm_fails: usize = r.exponents.iter().map(|p| p.warm_fallbacks).sum();
    let rate = Chart::new(format!(
        "Newton fallbacks: {fails} of {runs} cold solves, {warm_fails} warm"
    ))
    .x_label("shape exponent g [-]")
    .y_label("fallback rate [% of Newton solves]")
    .series(family_series(r, "superball", "superballs a = 0.5", pct))
    .series(family_series(
        r,
        "supercuboid",
        "supercuboids a = (0.5, 0.35, 0.7)",
        pct,
    ))
    .line(Line::new("target V-PK-5: 0.1 %", [(2.0, 0.1), (10.0, 0.1)]).dashed(true))
    .y_range(0.0, f64::NAN);
    let mut cost = Chart::new("Cost of one contact call (release, one thread)")
        .x_label("shape exponent g [-]")
        .y_label("time per call [ns]")
        .y_log(true);
    for (family, label) in [("superball", "ball"), ("supercuboid", "cuboid")] {
        cost = cost
            .series(family_series(r, family, &format!("{label}: cold"), |p| {
                p.cold_ns
            }))
            .series(family_series(r, family, &format!("{label}: warm"), |p| {
                p.warm_ns
            }))
            .series(
                family_series(r, family, &format!("{label}: exact GJK/EPA only"), |p| {
                    p.gjk_epa_ns
                })
                .style(Style::Dashed),
            );
    }
    let fig_a = Figure::new(
        "Superquadric contact: robustness and cost against the exponent",
        2,
    )
    .panel(rate)
    .panel(cost);
    let acc = |y: &dyn Fn(&AccuracyPoint) -> f64, title: &str, label: &str| {
        let mut c = Chart::new(title)
            .x_label("time per call [ns]")
            .y_label(label)
            .x_log(true)
            .y_log(true);
        let methods = [
            ("parry GJK/EPA (raw)", Style::Markers),
            ("GJK/EPA + projection", Style::Markers),
            ("GJK/EPA+Newton", Style::LineMarkers),
            ("warm Newton", Style::LineMarkers),
        ];
        for (m, style) in methods {
            let pts = r
                .accuracy
                .iter()
                .filter(|p| p.method == m)
                .map(|p| (p.cost_ns, y(p).max(ERROR_FLOOR)));
            let name = if style == Style::LineMarkers {
                format!("{m}, tol 1e-2..1e-12")
            } else {
                m.to_string()
            };
            c = c.series(Series::new(name, pts).style(style));
        }
        c
    };
    let fig_b = Figure::new(
        format!("Accuracy against cost (superballs and supercuboids, g = 2..8; errors drawn at >= {ERROR_FLOOR:.0e})"),
        2,
    )
    .panel(acc(&|p| p.overlap_error_mean, "Overlap depth (mean error)", "|overlap - reference| [D, superball diameter 1]"))
    .panel(acc(&|p| p.normal_error_mean, "Normal direction (mean error)", "angle to reference normal [rad]"));
    (fig_a.to_svg(620.0, 440.0), fig_b.to_svg(620.0, 440.0))
}

/// Writes `sq_contact_convergence.svg`, `sq_contact_accuracy.svg` and `sq_contact_study.json`
/// under `out` and returns a summary (file names and the data).
///
/// # Errors
/// Any I/O error from creating `out` or writing the files.
///
/// ```no_run
/// use magsep::studies::sq_study::{run_sq_contact_study, write_sq_study};
/// let summary = write_sq_study(&run_sq_contact_study(true), "target/sq".as_ref()).unwrap();
/// assert!(summary["charts"].is_array());
/// ```
pub fn write_sq_study(r: &StudyResult, out: &Path) -> std::io::Result<Value> {
    std::fs::create_dir_all(out)?;
    let (a, b) = render_sq_study_charts(r);
    let pa = out.join("sq_contact_convergence.svg");
    let pb = out.join("sq_contact_accuracy.svg");
    write_svg(&pa, &a)?;
    write_svg(&pb, &b)?;
    let data = r.to_json();
    let pj = out.join("sq_contact_study.json");
    std::fs::write(&pj, serde_json::to_string_pretty(&data).unwrap_or_default())?;
    Ok(json!({
        "charts": [pa.display().to_string(), pb.display().to_string()],
        "data": pj.display().to_string(),
        "study": data,
    }))
}
