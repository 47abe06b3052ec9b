//! Replay of particle-fluid recordings: the recorded scene is spawned again (densities and
//! equilibrium heights follow from it and the seed), then every recorded frame's positions
//! and clock are put into the world and the `Observe` systems re-run, which rebuilds the
//! separation-error curve e_m(t) at the frame times. Levitation times are tracked at the
//! frames (the last frame a particle was outside its band: at most one frame interval,
//! `levitation_time_resolution_s`, before the run's value). A frame holds no velocities, no
//! collision counters and no liquid: `velocity`, `max_reynolds`, `collisions` and
//! `liquid_solver` are `null` and listed in `not_recomputed`.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::app::SimApp;
use magsep_plugins::particle_fluid::SeparationObservePlugin;
use magsep_plugins::record::Recording;
use magsep_systems::fluid::config::ParticleFluidConfig;
use serde_json::Value;
use std::collections::HashMap;

use crate::error::ReplayError;
use crate::replay::{last_frame, recorded_wall_time};
use crate::scene::{Scene, spawn_scene};

/// Recompute the separation curve and the levitation times (at frame resolution) of a
/// recording of `scene` (seed `seed`) from all its complete frames; the summary has the keys
/// of `magsep run`, those a frame cannot give `null` (see the module docs).
///
/// # Errors
/// [`ReplayError`] when the scene cannot be spawned or a frame does not fit it.
pub fn replay_particle_fluid(
    rec: &Recording,
    scene: &Scene,
    seed: u64,
) -> Result<Value, ReplayError> {
    let last = last_frame(rec)?;
    let mut app = SimApp::new();
    spawn_scene(scene, &mut app.world, seed).map_err(|e| ReplayError::BadFrame {
        step: last.step,
        detail: format!("the recorded scene does not spawn: {e}"),
    })?;
    app.add_plugin(&SeparationObservePlugin);
    app.finish().map_err(|e| ReplayError::BadFrame {
        step: last.step,
        detail: e.0,
    })?;
    let entities: HashMap<u64, Entity> = app
        .world
        .query::<(Entity, &ParticleId)>()
        .iter(&app.world)
        .map(|(e, id)| (id.0, e))
        .collect();
    let dt = app.world.resource::<StepClock>().dt;
    // the run observes after each step, never at step 0: the recorded start frame is skipped
    let frames: Vec<_> = rec.frames.iter().filter(|f| f.step > 0).collect();
    for frame in &frames {
        if frame.ids.len() != entities.len() {
            return Err(ReplayError::BadFrame {
                step: frame.step,
                detail: format!(
                    "{} particles, the scene has {}",
                    frame.ids.len(),
                    entities.len()
                ),
            });
        }
        for (k, id) in frame.ids.iter().enumerate() {
            let Some(&e) = entities.get(id) else {
                return Err(ReplayError::BadFrame {
                    step: frame.step,
                    detail: format!("particle id {id} is not in the scene"),
                });
            };
            app.world.entity_mut(e).insert(Position(frame.positions[k]));
        }
        track_levitation_at(&mut app.world, frame.time);
        *app.world.resource_mut::<StepClock>() = StepClock {
            step: frame.step,
            dt,
        };
        app.observe_now();
    }
    let mut summary = super::run_summary(&app.world, seed, recorded_wall_time(rec));
    summary["frames_replayed"] = Value::from(frames.len());
    not_recomputed(&mut summary);
    let resolution = frames
        .windows(2)
        .map(|w| w[1].time - w[0].time)
        .fold(frames.first().map_or(0.0, |f| f.time), f64::max);
    summary["levitation_time_resolution_s"] = Value::from(resolution);
    Ok(summary)
}

/// The run's levitation bookkeeping at a frame: a particle farther than the tolerance from
/// its equilibrium height was outside at `time`.
fn track_levitation_at(world: &mut World, time: f64) {
    let tol = world.resource::<ParticleFluidConfig>().levitation_tolerance;
    let mut q = world.query::<(&Position, &mut Levitation)>();
    for (x, mut l) in q.iter_mut(world) {
        let gap = (x.0.z - l.equilibrium_height).abs();
        if gap.is_nan() || gap > tol {
            l.last_outside = time;
        }
    }
}

/// The keys of a replayed summary that frames cannot give.
const NOT_RECOMPUTED: [&str; 4] = ["velocity", "max_reynolds", "collisions", "liquid_solver"];

fn not_recomputed(summary: &mut Value) {
    for key in &NOT_RECOMPUTED[1..] {
        summary[*key] = Value::Null;
    }
    if let Some(rows) = summary["particle_details"].as_array_mut() {
        for row in rows {
            row["velocity"] = Value::Null;
        }
    }
    summary["not_recomputed"] = Value::from(NOT_RECOMPUTED.to_vec());
}
