//! Cost of one step's hydrodynamic work: `Mobility::new` (dense RPY matrix plus the
//! method's preparation), one correlated noise draw and one mobility product, on random
//! non-overlapping configurations.

use std::hint::black_box;
use std::time::Instant;

use glam::DVec3;
use magsep_systems::brownian::hydro::{
    EwaldSummary, Mobility, MobilityMethod, MobilityOptions, rpy_block,
};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;

use crate::studies::bench::BenchError;

/// `n` non-overlapping spheres of `radius` uniform in a cube sized for volume fraction `phi`
/// (rejection sampling; `phi` well below jamming).
pub fn random_configuration(n: usize, radius: f64, phi: f64, seed: u64) -> Vec<DVec3> {
    let edge = super::pipeline::box_edge(n, radius, phi);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut x: Vec<DVec3> = Vec::with_capacity(n);
    let d2 = (2.0 * radius).powi(2);
    while x.len() < n {
        let p = DVec3::new(
            rng.random_range(0.0..edge),
            rng.random_range(0.0..edge),
            rng.random_range(0.0..edge),
        );
        if x.iter().all(|q| (p - *q).length_squared() >= d2) {
            x.push(p);
        }
    }
    x
}

/// `n` standard-normal vectors (Box-Muller).
pub fn normal_vectors(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut g = || {
        let u: f64 = 1.0 - rng.random::<f64>();
        let v: f64 = rng.random::<f64>();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    (0..n).map(|_| DVec3::new(g(), g(), g())).collect()
}

/// Timing of one step's mobility work (the fastest of the repetitions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MobilityStepTime {
    /// `Mobility::new` \[s\].
    pub prepare_s: f64,
    /// One `noise` \[s\].
    pub noise_s: f64,
    /// One `apply` \[s\].
    pub apply_s: f64,
    /// Sum \[s\].
    pub total_s: f64,
    /// Krylov iterations of the noise draw (0 for the other methods).
    pub krylov_iterations: usize,
    /// Parameters of the spectral Ewald operator (None for the other methods).
    pub ewald: Option<EwaldSummary>,
}

impl MobilityStepTime {
    /// The row's timing keys (`prepare_s`, `noise_s`, `apply_s`, `s_per_step`, `steps_per_s`,
    /// `krylov_iterations`) and `repetitions`, merged into `row` (a JSON object).
    pub fn with_fields(&self, mut row: serde_json::Value, repetitions: usize) -> serde_json::Value {
        if let Some(map) = row.as_object_mut() {
            for (k, v) in [
                ("repetitions", serde_json::json!(repetitions)),
                ("prepare_s", serde_json::json!(self.prepare_s)),
                ("noise_s", serde_json::json!(self.noise_s)),
                ("apply_s", serde_json::json!(self.apply_s)),
                ("s_per_step", serde_json::json!(self.total_s)),
                ("steps_per_s", serde_json::json!(1.0 / self.total_s)),
                (
                    "krylov_iterations",
                    serde_json::json!(self.krylov_iterations),
                ),
            ] {
                map.insert(k.into(), v);
            }
        }
        row
    }
}

/// Prepare `method` at `x` with the given options and time it with one noise draw; returns
/// the mobility, the preparation and the noise time [s].
///
/// # Errors
/// [`BenchError::Runtime`] when the mobility fails.
pub fn prepare_and_draw(
    method: MobilityMethod,
    x: &[DVec3],
    radii: &[f64],
    viscosity: f64,
    options: MobilityOptions,
    w: &[DVec3],
) -> Result<(Mobility, f64, f64), BenchError> {
    let fail = |e: magsep_systems::brownian::hydro::HydroError| {
        BenchError::Runtime(format!("{method:?} mobility at N = {}: {e}", x.len()))
    };
    let mut y = vec![DVec3::ZERO; x.len()];
    let t = Instant::now();
    let mob = Mobility::new_with(method, x, radii, viscosity, options).map_err(fail)?;
    let prepare = t.elapsed().as_secs_f64();
    let t = Instant::now();
    mob.noise(w, &mut y).map_err(fail)?;
    let noise = t.elapsed().as_secs_f64();
    black_box(&y);
    Ok((mob, prepare, noise))
}

/// Time `Mobility::new` + one `noise` + one `apply` of `method` at `x`, best of `reps`
/// (at least one). At most one mobility is alive at a time.
///
/// # Errors
/// [`BenchError::Runtime`] when the mobility fails (e.g. Krylov not converged).
pub fn time_mobility_step(
    method: MobilityMethod,
    x: &[DVec3],
    radii: &[f64],
    viscosity: f64,
    krylov_tolerance: f64,
    reps: usize,
) -> Result<MobilityStepTime, BenchError> {
    let options = MobilityOptions {
        krylov_tolerance,
        ..MobilityOptions::default()
    };
    time_mobility_step_with(method, x, radii, viscosity, options, reps)
}

/// As [`time_mobility_step`] with all mobility options.
///
/// # Errors
/// As [`time_mobility_step`].
pub fn time_mobility_step_with(
    method: MobilityMethod,
    x: &[DVec3],
    radii: &[f64],
    viscosity: f64,
    options: MobilityOptions,
    reps: usize,
) -> Result<MobilityStepTime, BenchError> {
    let n = x.len();
    let w = normal_vectors(n, 3);
    // forces of order k_B T / R
    let f: Vec<DVec3> = normal_vectors(n, 4)
        .into_iter()
        .map(|v| v * 4e-21 / radii.first().copied().unwrap_or(1.0))
        .collect();
    let mut best: Option<MobilityStepTime> = None;
    for _ in 0..reps.max(1) {
        let (mob, prepare_s, noise_s) = prepare_and_draw(method, x, radii, viscosity, options, &w)?;
        let mut v = vec![DVec3::ZERO; n];
        let t = Instant::now();
        mob.apply(&f, &mut v);
        let apply_s = t.elapsed().as_secs_f64();
        black_box(&v);
        let r = MobilityStepTime {
            prepare_s,
            noise_s,
            apply_s,
            total_s: prepare_s + noise_s + apply_s,
            krylov_iterations: mob.krylov_iterations(),
            ewald: mob.ewald_summary(),
        };
        drop(mob);
        if best.is_none_or(|b| r.total_s < b.total_s) {
            best = Some(r);
        }
    }
    best.ok_or_else(|| BenchError::Runtime("no repetition".into()))
}

/// Relative error ‖v − μF‖/‖μF‖ of `method`'s product `v` against the RPY product μF summed
/// directly (O(N²) pair blocks, never stored), for standard-normal forces.
///
/// # Errors
/// [`BenchError::Runtime`] when the mobility fails.
pub fn product_error(
    method: MobilityMethod,
    x: &[DVec3],
    radii: &[f64],
    viscosity: f64,
    options: MobilityOptions,
) -> Result<f64, BenchError> {
    let n = x.len();
    let f = normal_vectors(n, 6);
    let mob = Mobility::new_with(method, x, radii, viscosity, options)
        .map_err(|e| BenchError::Runtime(format!("{method:?} mobility at N = {n}: {e}")))?;
    let mut v = vec![DVec3::ZERO; n];
    mob.apply(&f, &mut v);
    let exact: Vec<DVec3> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut acc = f[i] / (6.0 * std::f64::consts::PI * viscosity * radii[i]);
            for j in (0..n).filter(|&j| j != i) {
                acc += rpy_block(x[i] - x[j], radii[i], radii[j], viscosity) * f[j];
            }
            acc
        })
        .collect();
    let num: f64 = v
        .iter()
        .zip(&exact)
        .map(|(a, b)| (*a - *b).length_squared())
        .sum();
    let den: f64 = exact.iter().map(|b| b.length_squared()).sum();
    Ok((num / den).sqrt())
}
