//! Replay of particle-fluid recordings: the recorded scene is spawned again (densities and
//! equilibrium heights follow from it and the seed), then every recorded frame's positions
//! and clock are put into the world and the `Observe` systems re-run, which rebuilds the
//! separation-error curve e_m(t) at the frame times.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::app::SimApp;
use magsep_plugins::particle_fluid::SeparationObservePlugin;
use magsep_plugins::record::Recording;
use serde_json::Value;
use std::collections::HashMap;

use crate::error::ReplayError;
use crate::replay::{last_frame, recorded_wall_time};
use crate::scene::{Scene, spawn_scene};

/// Recompute the separation curve of a recording of `scene` (seed `seed`) from all its
/// complete frames; the summary has the keys of `magsep run` (levitation times at the
/// recording's frame resolution are not recomputed).
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
        *app.world.resource_mut::<StepClock>() = StepClock {
            step: frame.step,
            dt,
        };
        app.observe_now();
    }
    let mut summary = super::run_summary(&app.world, seed, recorded_wall_time(rec));
    summary["frames_replayed"] = Value::from(frames.len());
    if let Some(t) = &rec.truncated {
        summary["truncated"] = Value::String(t.clone());
    }
    Ok(summary)
}
