//! Replay: re-run the `Observe` systems on recorded frames.

use std::path::Path;

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::app::SimApp;
use magsep_plugins::packing::PackingObservePlugin;
use magsep_plugins::record::{ParticleFrame, RecordError, Recording, read_recording};
use magsep_plugins::recorder::FrameStatus;
use magsep_systems::rng::rng_from_state_words;
use serde_json::Value;

use crate::scene::{SceneErrors, parse_scene};
use crate::summary::packing_summary;

/// Why a replay failed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The recording could not be read.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// The recording has no `magsep` metadata record.
    #[error(
        "the recording has no `magsep` metadata record (scene text, seed): not written by magsep run"
    )]
    NoMetadata,
    /// The recorded scene does not parse with this version.
    #[error("the recorded scene is invalid:\n{0}")]
    Scene(#[from] SceneErrors),
    /// The recording holds no frame.
    #[error("the recording holds no frame{0}")]
    NoFrames(String),
    /// A frame is inconsistent.
    #[error("frame at step {step} is inconsistent: {detail}")]
    BadFrame {
        /// Step of the frame.
        step: u64,
        /// What is wrong.
        detail: String,
    },
}

/// Spawn the particles of `frame` into `world` and set the container, clock and status.
/// `shapes` (in id order, from the recorded scene) override the frame's radii and half
/// lengths, which cannot describe superquadrics.
///
/// # Errors
/// [`ReplayError::BadFrame`] for non-positive radii or a malformed status.
pub fn load_frame(
    world: &mut World,
    frame: &ParticleFrame,
    shapes: Option<&[Shape]>,
) -> Result<(), ReplayError> {
    let bad = |detail: String| ReplayError::BadFrame {
        step: frame.step,
        detail,
    };
    for (i, id) in frame.ids.iter().enumerate() {
        let (r, h) = (frame.radii[i], frame.half_lengths[i]);
        if !(r.is_finite() && r > 0.0 && h.is_finite() && h >= 0.0) {
            return Err(bad(format!("particle {id}: radius {r}, half length {h}")));
        }
        let scene_shape = shapes.filter(|s| s.len() == frame.ids.len()).map(|s| s[i]);
        let shape = if let Some(s) = scene_shape {
            s
        } else if h == 0.0 {
            Shape::Sphere { radius: r }
        } else {
            Shape::Spherocylinder {
                radius: r,
                half_length: h,
            }
        };
        world.spawn(ParticleBundle {
            id: ParticleId(*id),
            position: Position(frame.positions[i]),
            orientation: Orientation(frame.orientations[i]),
            shape,
            species: Species(0),
            rng: ParticleRng(rng_from_state_words(frame.rng_states[i])),
            net_force: NetForce::default(),
            net_torque: NetTorque::default(),
        });
    }
    let e = frame.box_edges;
    if !(e.is_finite() && e.min_element() > 0.0) {
        return Err(bad(format!("box edges {e}")));
    }
    let status: FrameStatus =
        serde_json::from_str(&frame.status_json).map_err(|e| bad(format!("status_json: {e}")))?;
    let container = match status.container {
        Some(Container::Walled { walls, .. }) => Container::Walled { walls, edges: e },
        _ => Container::PeriodicBox { edges: e },
    };
    world.insert_resource(container);
    world.insert_resource(StepClock {
        step: frame.step,
        dt: if frame.step > 0 {
            frame.time / frame.step as f64
        } else {
            0.0
        },
    });
    if let Some(s) = status.packing {
        world.insert_resource(s);
    }
    Ok(())
}

/// The last complete frame of `rec`, or why there is none.
///
/// # Errors
/// [`ReplayError::NoFrames`], with the truncation found.
pub fn last_frame(rec: &Recording) -> Result<&ParticleFrame, ReplayError> {
    rec.frames.last().ok_or_else(|| {
        ReplayError::NoFrames(
            rec.truncated
                .clone()
                .map(|t| format!(" ({t})"))
                .unwrap_or_default(),
        )
    })
}

/// The run's wall time [s] from the recorded summary (0 when absent).
pub fn recorded_wall_time(rec: &Recording) -> f64 {
    rec.summary_json
        .as_deref()
        .and_then(|s| serde_json::from_str::<Value>(s).ok())
        .and_then(|v| v.get("wall_time_s").and_then(Value::as_f64))
        .unwrap_or(0.0)
}

/// Replay a recording: the summary of its last frame (same keys as `magsep run`), and the
/// recording itself.
///
/// # Errors
/// [`ReplayError`].
pub fn replay(path: &Path) -> Result<(Value, Recording), ReplayError> {
    let rec = read_recording(path)?;
    let meta = rec.metadata.clone().ok_or(ReplayError::NoMetadata)?;
    let scene = parse_scene(&meta.scene_text, &Default::default())?;
    if scene.brownian_section().is_some() {
        let summary = crate::brownian::replay::replay_brownian(&rec, &scene, meta.seed)?;
        return Ok((summary, rec));
    }
    if scene.particle_fluid.is_some() {
        let summary =
            crate::particle_fluid::replay::replay_particle_fluid(&rec, &scene, meta.seed)?;
        return Ok((summary, rec));
    }
    let frame = last_frame(&rec)?;
    let mut app = SimApp::new();
    app.world.insert_resource(scene.packing_config());
    load_frame(&mut app.world, frame, Some(&scene.shapes()))?;
    app.add_plugin(&PackingObservePlugin);
    app.finish().map_err(|e| ReplayError::BadFrame {
        step: frame.step,
        detail: e.0,
    })?;
    app.observe_now();
    let wall = recorded_wall_time(&rec);
    let mut summary = packing_summary(&app.world, meta.seed, wall);
    if let Some(t) = &rec.truncated {
        summary["truncated"] = Value::String(t.clone());
    }
    Ok((summary, rec))
}
