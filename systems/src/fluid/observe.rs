//! The separation error of magnetic density separation (thesis 002, eq. 2.51):
//! `e_m(t) = (1/L) sqrt((1/N) Σ_i (y_i(t) − y_{e,i})²)` over all particles that have an
//! equilibrium height, and per density group. Sampled in `Observe` into [`SeparationCurve`];
//! replay recomputes it from recorded frames with the same kernel.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use serde::{Deserialize, Serialize};

use super::config::ParticleFluidConfig;

/// e_m of `heights` against `equilibria` \[m\], divided by `scale` L \[m\]; particles without an
/// equilibrium (NaN) are left out. NaN when none is left.
///
/// ```
/// use magsep_systems::fluid::observe::separation_error;
/// let e = separation_error(&[0.1, -0.1, 5.0], &[0.0, 0.0, f64::NAN], 0.5);
/// assert!((e - 0.2).abs() < 1e-15);
/// ```
pub fn separation_error(heights: &[f64], equilibria: &[f64], scale: f64) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (y, ye) in heights.iter().zip(equilibria) {
        if ye.is_finite() {
            sum += (y - ye).powi(2);
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        (sum / n as f64).sqrt() / scale
    }
}

/// Separation error against time, overall and per density group.
#[derive(Resource, Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SeparationCurve {
    /// Sample times \[s\].
    pub times: Vec<f64>,
    /// e_m over all levitating particles.
    pub total: Vec<f64>,
    /// Particle densities of the groups [kg/m³], ascending.
    pub group_densities: Vec<f64>,
    /// e_m per group (outer: group, inner: sample).
    pub groups: Vec<Vec<f64>>,
}

impl SeparationCurve {
    /// Append one sample from particle rows (density, height, equilibrium) in a stable order.
    pub fn sample(&mut self, time: f64, rows: &[(f64, f64, f64)], scale: f64) {
        let heights: Vec<f64> = rows.iter().map(|r| r.1).collect();
        let eq: Vec<f64> = rows.iter().map(|r| r.2).collect();
        if self.group_densities.is_empty() {
            let mut d: Vec<f64> = rows.iter().map(|r| r.0).collect();
            d.sort_by(f64::total_cmp);
            d.dedup();
            self.groups = vec![Vec::new(); d.len()];
            self.group_densities = d;
        }
        self.times.push(time);
        self.total.push(separation_error(&heights, &eq, scale));
        for (g, &rho) in self.group_densities.iter().enumerate() {
            let (h, e): (Vec<f64>, Vec<f64>) = rows
                .iter()
                .filter(|r| r.0 == rho)
                .map(|r| (r.1, r.2))
                .unzip();
            self.groups[g].push(separation_error(&h, &e, scale));
        }
    }

    /// The time at which e_m falls to `level` for good (it stays at or below `level` to the
    /// end), interpolated linearly between the two samples that bracket the last crossing; the
    /// first sample time if e_m starts there, NaN if it never does.
    ///
    /// ```
    /// use magsep_systems::fluid::observe::SeparationCurve;
    /// let c = SeparationCurve { times: vec![0.0, 1.0, 2.0, 3.0], total: vec![1.0, 0.01, 0.05, 0.01], ..Default::default() };
    /// assert!((c.time_to(0.02) - 2.75).abs() < 1e-12);
    /// assert!(c.time_to(0.001).is_nan());
    /// ```
    pub fn time_to(&self, level: f64) -> f64 {
        match self.total.iter().rposition(|&e| e.is_nan() || e > level) {
            None => self.times.first().copied().unwrap_or(f64::NAN),
            Some(k) if k + 1 < self.times.len() => {
                let (e0, e1) = (self.total[k], self.total[k + 1]);
                let (t0, t1) = (self.times[k], self.times[k + 1]);
                if e0.is_finite() && e0 > e1 {
                    t0 + (t1 - t0) * (e0 - level) / (e0 - e1)
                } else {
                    t1
                }
            }
            Some(_) => f64::NAN,
        }
    }
}

/// The length scale L of e_m: the magnet's half height (1 m without a magnet).
pub fn separation_scale(cfg: &ParticleFluidConfig) -> f64 {
    use super::magnet::MagnetModel::*;
    match cfg.magnet {
        None => 1.0,
        Bottom { half_height, .. } | Top { half_height, .. } | Two { half_height, .. } => {
            half_height
        }
    }
}

/// Whether this step is a sampling step (run condition): every `observe_every` steps and
/// the last one.
pub fn should_observe_separation(cfg: Res<ParticleFluidConfig>, clock: Res<StepClock>) -> bool {
    // Observe runs after Finalize has advanced the clock: `step` counts completed steps
    let done = clock.step;
    done.is_multiple_of(cfg.observe_every.max(1)) || done >= cfg.steps
}

/// Sample e_m at the end of the step (`Observe`).
pub fn observe_separation(
    cfg: Res<ParticleFluidConfig>,
    clock: Res<StepClock>,
    mut curve: ResMut<SeparationCurve>,
    q: Query<(&ParticleId, &Position, &InertialBody, &Levitation)>,
) {
    let mut rows: Vec<_> = q
        .iter()
        .map(|(id, x, b, l)| (*id, (b.density, x.0.z, l.equilibrium_height)))
        .collect();
    rows.sort_by_key(|r| r.0);
    let rows: Vec<_> = rows.into_iter().map(|r| r.1).collect();
    curve.sample(clock.time(), &rows, separation_scale(&cfg));
}
