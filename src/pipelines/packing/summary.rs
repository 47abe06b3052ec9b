//! Machine-readable run summaries (JSON), shared by `run` and `replay`.

use bevy_ecs::prelude::*;
use magsep_components::packing::{OverlapRemovalScheme, VolumeStepRule};
use magsep_components::prelude::*;
use magsep_systems::packing::systems::PackingObservables;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Keys of a packing summary that a replay must reproduce exactly.
pub const PACKING_SUMMARY_KEYS: &[&str] = &[
    "pipeline",
    "particles",
    "packing_fraction",
    "mean_contact_number",
    "mean_contact_number_at_1e-4",
    "nematic_order",
    "max_overlap",
    "compression_steps",
    "failed_steps",
    "attempts",
    "stop_reason",
    "final_volume_step",
    "final_relative_strain",
    "seed",
];

/// Summary of a packing world: observables, driver counters, warnings, wall time.
pub fn packing_summary(world: &World, seed: u64, wall_time_s: f64) -> Value {
    let obs = world
        .get_resource::<PackingObservables>()
        .cloned()
        .unwrap_or_default();
    let status = world.get_resource::<PackingStatus>().copied();
    let config = world.get_resource::<PackingConfig>().copied();
    let container = world.get_resource::<Container>().copied();
    let n = world
        .iter_entities()
        .filter(|e| e.contains::<ParticleId>())
        .count();
    let mut warnings: Vec<String> = Vec::new();
    let (mut final_dv, mut strain) = (None, None);
    if let (Some(s), Some(c)) = (status, container) {
        let dv = s.volume_step.min(match config {
            Some(cfg) => cfg.volume_step / 2f64.powi(cfg.step_halvings as i32),
            None => s.volume_step,
        });
        final_dv = Some(dv);
        let e = dv / (3.0 * c.volume());
        strain = Some(e);
        if e > 1e-3 {
            warnings.push(format!(
                "the finest volume step is a linear strain of {e:.2e} (> 1e-3): the packing may not be jammed; use a smaller volume_step or more step_halvings"
            ));
        }
        if s.contact_fallbacks * 1000 > s.contact_evaluations {
            warnings.push(format!(
                "the superquadric contact solver fell back to GJK/EPA in {} of {} contacts (> 0.1 %)",
                s.contact_fallbacks, s.contact_evaluations
            ));
        }
        match s.stopped {
            Some(StopReason::BudgetTooSmall) => warnings.push(
                "no compression step succeeded: the volume step is too large for the attempt budget (max_attempts); the reported packing is the start configuration".into(),
            ),
            Some(StopReason::StepLimit) => warnings.push("stopped at max_compression_steps before jamming".into()),
            _ => {}
        }
    }
    let summary = PackingSummary {
        pipeline: "packing".into(),
        particles: n,
        packing_fraction: obs.packing_fraction,
        mean_contact_number: obs.mean_contact_number,
        mean_contact_number_at_1e_4: obs.mean_contact_number_1e_4,
        nematic_order: obs.nematic_order,
        max_overlap: obs.max_overlap,
        container,
        wall_aligned_fraction: obs.wall_aligned_fraction,
        cubatic_order: obs.cubatic_order,
        max_wall_penetration: obs.max_wall_penetration,
        contact_evaluations: status.map(|s| s.contact_evaluations),
        contact_fallbacks: status.map(|s| s.contact_fallbacks),
        compression_steps: status.map(|s| s.compression_steps),
        failed_steps: status.map(|s| s.failed_steps),
        attempts: status.map(|s| s.attempts),
        stop_reason: status.and_then(|s| s.stopped),
        scheme: config.map(|c| c.scheme),
        volume_step_rule: config.map(|c| c.volume_step_rule),
        final_volume_step: final_dv,
        final_relative_strain: strain,
        seed,
        warnings,
        wall_time_s,
    };
    serde_json::to_value(summary).unwrap_or(Value::Null)
}

/// The summary of a packing run (printed as JSON by `magsep run` and `magsep replay`).
/// Lengths in m, volumes in m³.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PackingSummary {
    /// Always `packing`.
    pub pipeline: String,
    /// Number of particles.
    pub particles: usize,
    /// Final packing fraction φ.
    pub packing_fraction: f64,
    /// Mean contact number ⟨C⟩ at the overlap tolerance.
    pub mean_contact_number: f64,
    /// Mean contact number counting gaps up to 1e-4 D.
    #[serde(rename = "mean_contact_number_at_1e-4")]
    pub mean_contact_number_at_1e_4: f64,
    /// Nematic order parameter S.
    pub nematic_order: f64,
    /// Largest overlap, in units of D.
    pub max_overlap: f64,
    /// The final container.
    pub container: Option<Container>,
    /// Fraction of rods aligned with a wall (walled containers).
    pub wall_aligned_fraction: Option<f64>,
    /// Cubatic order S₄ (superquadrics).
    pub cubatic_order: Option<f64>,
    /// Largest penetration of a wall, in units of D.
    pub max_wall_penetration: f64,
    /// Superquadric contact evaluations.
    pub contact_evaluations: Option<u64>,
    /// Of which fell back to GJK/EPA.
    pub contact_fallbacks: Option<u64>,
    /// Successful compression steps.
    pub compression_steps: Option<u64>,
    /// Failed compression steps.
    pub failed_steps: Option<u64>,
    /// Overlap-removal attempts.
    pub attempts: Option<u64>,
    /// Why the driver stopped.
    pub stop_reason: Option<StopReason>,
    /// Overlap-removal scheme.
    pub scheme: Option<OverlapRemovalScheme>,
    /// Volume step rule.
    pub volume_step_rule: Option<VolumeStepRule>,
    /// Finest volume step reached [m³].
    pub final_volume_step: Option<f64>,
    /// That step as a linear strain dV / (3 V).
    pub final_relative_strain: Option<f64>,
    /// Seed of the run.
    pub seed: u64,
    /// Warnings (unjammed, solver fallbacks, budget).
    pub warnings: Vec<String>,
    /// Wall time [s].
    pub wall_time_s: f64,
}
