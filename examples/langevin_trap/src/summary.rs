//! The statistics of a run and its typed summary, from the world (`run`) or from the frames
//! of a recording (`replay`): both add the same displacements in the same order, so a replay
//! reproduces the run's numbers bit for bit.

use magsep::bevy_ecs;
use magsep::bevy_ecs::prelude::*;
use magsep::components::prelude::*;
use magsep::error::ReplayError;
use magsep::glam::DVec3;
use magsep::plugins::record::Recording;
use magsep::replay::recorded_wall_time;
use magsep::scene::Scene;
use magsep::serde_json;
use serde::{Deserialize, Serialize};

use crate::dynamics::{TrapConfig, displacements};
use crate::scene::TrapParams;

/// Sums over every sampled (particle, step) of the displacement from the centre (a
/// resource).
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TrapStats {
    /// Number of sampled steps.
    pub samples: u64,
    /// Number of (particle, step) values per axis.
    pub values: u64,
    /// Σ (x - x0) per axis \[m\].
    pub sum: [f64; 3],
    /// Σ (x - x0)² per axis \[m²\].
    pub sum_sq: [f64; 3],
}

impl TrapStats {
    /// Add one sampled step: the displacements of every particle, in `ParticleId` order.
    pub fn add_sample(&mut self, d: &[DVec3]) {
        self.samples += 1;
        self.values += d.len() as u64;
        for v in d {
            for (a, x) in v.to_array().into_iter().enumerate() {
                self.sum[a] += x;
                self.sum_sq[a] += x * x;
            }
        }
    }

    /// Mean displacement per axis \[m\] (NaN without samples).
    pub fn mean(&self) -> [f64; 3] {
        let n = self.values as f64;
        self.sum.map(|s| s / n)
    }

    /// Variance per axis about the sample mean \[m²\] (NaN without samples).
    pub fn variance(&self) -> [f64; 3] {
        let n = self.values as f64;
        let m = self.mean();
        std::array::from_fn(|a| self.sum_sq[a] / n - m[a] * m[a])
    }

    /// Mean square displacement from the centre ⟨|x - x0|²⟩ \[m²\] (theory 3 k_B T / k).
    pub fn msd(&self) -> f64 {
        self.sum_sq.iter().sum::<f64>() / self.values as f64
    }
}

/// The summary of a run (printed as JSON by `langevin-trap run`). Statistics are over every
/// particle at every sampled step (`particles * samples` values per axis).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrapSummary {
    /// Always `langevin_trap`.
    pub pipeline: String,
    /// Number of particles.
    pub particles: u64,
    /// Steps done.
    pub steps: u64,
    /// Simulated time \[s\].
    pub time_s: f64,
    /// Steps sampled (after the equilibration, every `sample_every` steps).
    pub samples: u64,
    /// Steps between samples.
    pub sample_every: u64,
    /// Mean displacement from the centre per axis \[m\] (theory 0).
    pub mean_displacement_m: [f64; 3],
    /// Variance of the position per axis \[m²\] (theory k_B T / k).
    pub variance_m2: [f64; 3],
    /// Mean square displacement from the centre ⟨|x - x0|²⟩ \[m²\] (theory 3 k_B T / k).
    pub msd_m2: f64,
    /// The equilibrium variance per axis k_B T / k \[m²\].
    pub theory_variance_m2: f64,
    /// (variance - k_B T / k) / (k_B T / k) per axis.
    pub relative_error: [f64; 3],
    /// Largest |relative error| over the axes.
    pub max_relative_error: f64,
    /// Seed of the run.
    pub seed: u64,
    /// Wall time of the run \[s\].
    pub wall_time_s: f64,
}

impl TrapSummary {
    /// The summary of `stats` after `steps` steps of `particles` particles under `p`.
    pub fn new(
        p: &TrapParams,
        stats: &TrapStats,
        particles: u64,
        steps: u64,
        seed: u64,
        wall_time_s: f64,
    ) -> Self {
        let theory = p.variance();
        let variance = stats.variance();
        let relative_error = variance.map(|v| (v - theory) / theory);
        Self {
            pipeline: crate::scene::PIPELINE.into(),
            particles,
            steps,
            time_s: steps as f64 * p.dt,
            samples: stats.samples,
            sample_every: p.sample_every,
            mean_displacement_m: stats.mean(),
            variance_m2: variance,
            msd_m2: stats.msd(),
            theory_variance_m2: theory,
            relative_error,
            max_relative_error: relative_error.iter().fold(0.0, |m, e| m.max(e.abs())),
            seed,
            wall_time_s,
        }
    }

    /// As JSON (non-finite numbers, e.g. a variance without samples, become `null`).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
}

/// The summary of the world's current state.
pub fn summary_of(world: &World, seed: u64, wall_time_s: f64) -> serde_json::Value {
    let Some(config) = world.get_resource::<TrapConfig>() else {
        return serde_json::json!({ "error": "not a langevin_trap world" });
    };
    let stats = world
        .get_resource::<TrapStats>()
        .copied()
        .unwrap_or_default();
    let step = world.get_resource::<StepClock>().map_or(0, |c| c.step);
    let particles = world
        .iter_entities()
        .filter(|e| e.contains::<ParticleId>())
        .count() as u64;
    TrapSummary::new(&config.0, &stats, particles, step, seed, wall_time_s).to_json()
}

/// The summary recomputed from the frames of `rec` (every recorded sample step), with the
/// recorded wall time; `truncated` is added for a damaged file.
///
/// # Errors
/// [`ReplayError::NoFrames`] without frames, [`ReplayError::BadFrame`] for a frame whose
/// particles differ from the scene's.
pub fn replay(rec: &Recording, scene: &Scene, seed: u64) -> Result<serde_json::Value, ReplayError> {
    let p = TrapParams::of_scene(scene)
        .ok_or_else(|| ReplayError::Unsupported("not a langevin_trap scene".into()))?;
    let last = magsep::replay::last_frame(rec)?;
    let n = scene.total_particles();
    let mut stats = TrapStats::default();
    for f in &rec.frames {
        if f.ids.len() as u64 != n || f.positions.len() != f.ids.len() {
            return Err(ReplayError::BadFrame {
                step: f.step,
                detail: format!(
                    "{} ids and {} positions, the scene has {n} particles",
                    f.ids.len(),
                    f.positions.len()
                ),
            });
        }
        if p.is_sample_step(f.step) {
            let rows: Vec<_> = f
                .ids
                .iter()
                .zip(&f.positions)
                .map(|(id, x)| (ParticleId(*id), *x))
                .collect();
            stats.add_sample(&displacements(&rows, p.centre));
        }
    }
    // `first_sample` is a multiple of `sample_every`
    let expected = if last.step < p.first_sample {
        0
    } else {
        (last.step - p.first_sample) / p.sample_every + 1
    };
    if stats.samples != expected {
        return Err(ReplayError::Unsupported(format!(
            "the recording holds {} of the {expected} sample frames up to step {} (one every {} steps): \
             it was not recorded at the sample interval",
            stats.samples, last.step, p.sample_every
        )));
    }
    let mut summary =
        TrapSummary::new(&p, &stats, n, last.step, seed, recorded_wall_time(rec)).to_json();
    if let Some(t) = &rec.truncated {
        summary["truncated"] = serde_json::Value::String(t.clone());
    }
    Ok(summary)
}
