//! Machine-readable run summaries (JSON), shared by `run` and `replay`.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::packing::systems::PackingObservables;
use serde_json::{Value, json};

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
    let (mut final_dv, mut strain) = (Value::Null, Value::Null);
    if let (Some(s), Some(c)) = (status, container) {
        let dv = s.volume_step.min(match config {
            Some(cfg) => cfg.volume_step / 2f64.powi(cfg.step_halvings as i32),
            None => s.volume_step,
        });
        final_dv = json!(dv);
        let e = dv / (3.0 * c.volume());
        strain = json!(e);
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
    json!({
        "pipeline": "packing",
        "particles": n,
        "packing_fraction": obs.packing_fraction,
        "mean_contact_number": obs.mean_contact_number,
        "mean_contact_number_at_1e-4": obs.mean_contact_number_1e_4,
        "nematic_order": obs.nematic_order,
        "max_overlap": obs.max_overlap,
        "container": container.map(|c| serde_json::to_value(c).unwrap_or(Value::Null)),
        "wall_aligned_fraction": obs.wall_aligned_fraction,
        "cubatic_order": obs.cubatic_order,
        "max_wall_penetration": obs.max_wall_penetration,
        "contact_evaluations": status.map(|s| s.contact_evaluations),
        "contact_fallbacks": status.map(|s| s.contact_fallbacks),
        "compression_steps": status.map(|s| s.compression_steps),
        "failed_steps": status.map(|s| s.failed_steps),
        "attempts": status.map(|s| s.attempts),
        "stop_reason": status.and_then(|s| s.stopped).map(|r| serde_json::to_value(r).unwrap_or(Value::Null)),
        "scheme": config.map(|c| serde_json::to_value(c.scheme).unwrap_or(Value::Null)),
        "volume_step_rule": config.map(|c| serde_json::to_value(c.volume_step_rule).unwrap_or(Value::Null)),
        "final_volume_step": final_dv,
        "final_relative_strain": strain,
        "seed": seed,
        "warnings": warnings,
        "wall_time_s": wall_time_s,
    })
}
