//! Replay and resume of brownian recordings.
//!
//! Every frame of a brownian recording holds, besides positions and random streams, the
//! capture events (step and fibre per particle), the start positions and the stepper counters
//! (`status_json.brownian`). That is the whole state of a run: **replay** recomputes the capture
//! curves and the summary from the last frame, and **resume** spawns the recorded scene, puts
//! the last frame's state into it and runs on to the end, bitwise as if never interrupted.

use std::path::{Path, PathBuf};

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;
use magsep_plugins::record::{ParticleFrame, Recording, read_recording};
use magsep_plugins::recorder::FrameStatus;
use magsep_systems::rng::rng_from_state_words;
use serde_json::Value;

use super::summary::{RunResult, StartRegions, is_brownian, summary_of};
use crate::replay::{ReplayError, last_frame, recorded_wall_time};
use crate::scene::{Scene, parse_scene};
use crate::sim::{RunOptions, SimError, Simulation};

fn bad(frame: &ParticleFrame, detail: impl Into<String>) -> ReplayError {
    ReplayError::BadFrame {
        step: frame.step,
        detail: detail.into(),
    }
}

fn status(frame: &ParticleFrame) -> Result<FrameStatus, ReplayError> {
    let s: FrameStatus = serde_json::from_str(&frame.status_json)
        .map_err(|e| bad(frame, format!("status_json: {e}")))?;
    let n = frame.ids.len();
    match &s.brownian {
        None => Err(bad(frame, "no brownian state in status_json")),
        Some(b) if b.captured.len() != n || b.initial_positions.len() != n => Err(bad(
            frame,
            format!(
                "brownian state has {} capture flags and {} start positions for {n} particles",
                b.captured.len(),
                b.initial_positions.len()
            ),
        )),
        Some(_) => Ok(s),
    }
}

/// The [`RunResult`] of a recorded frame of `scene`.
///
/// # Errors
/// [`ReplayError::BadFrame`] for a frame without brownian state or of the wrong size.
pub fn frame_result(
    scene: &Scene,
    frame: &ParticleFrame,
    seed: u64,
) -> Result<RunResult, ReplayError> {
    let st = status(frame)?;
    let b = st.brownian.unwrap_or_default();
    let section = scene
        .brownian_section()
        .ok_or_else(|| bad(frame, "the recorded scene is not a brownian scene"))?;
    let config = section.config();
    let species = scene.species_ids();
    if species.len() != frame.ids.len() {
        return Err(bad(
            frame,
            format!(
                "{} particles, the scene has {}",
                frame.ids.len(),
                species.len()
            ),
        ));
    }
    let t = frame.time;
    let brownian = (0..frame.ids.len())
        .map(|i| {
            let x0 = DVec3::from_array(b.initial_positions[i]);
            let d2 = (frame.positions[i] - x0).length_squared();
            is_brownian(&config, frame.radii[i], d2, t, b.captured[i].is_some())
        })
        .collect();
    Ok(RunResult {
        seed,
        steps: frame.step,
        dt: if frame.step > 0 {
            frame.time / frame.step as f64
        } else {
            section.time_step
        },
        species,
        capture_steps: b.captured.iter().map(|c| c.map(|c| c.step)).collect(),
        brownian,
        stats: b.stats,
    })
}

/// Start-region volumes of a scene's groups.
pub fn start_regions(scene: &Scene) -> StartRegions {
    StartRegions(
        scene
            .particles
            .iter()
            .map(|g| g.placement.as_ref().and_then(|p| p.volume(&scene.fibres)))
            .collect(),
    )
}

/// Summary of a brownian recording recomputed from its last frame.
///
/// # Errors
/// [`ReplayError`] when the recording has no frame or its state is malformed.
pub fn replay_brownian(rec: &Recording, scene: &Scene, seed: u64) -> Result<Value, ReplayError> {
    let frame = last_frame(rec)?;
    let result = frame_result(scene, frame, seed)?;
    let config = scene
        .brownian_section()
        .map(|s| s.config())
        .unwrap_or_else(|| unreachable!("frame_result checked the scene is brownian"));
    let wall = recorded_wall_time(rec);
    let mut summary = summary_of(&[result], &start_regions(scene), &config, wall);
    summary["frames"] = rec.frames.len().into();
    if let Some(t) = &rec.truncated {
        summary["truncated"] = Value::String(t.clone());
    }
    Ok(summary)
}

/// Put the state of `frame` into a freshly spawned brownian world (before the pipeline's
/// `finish` gathers it).
///
/// # Errors
/// [`ReplayError::BadFrame`] when the frame does not fit the spawned scene.
pub fn apply_frame(world: &mut World, frame: &ParticleFrame) -> Result<(), ReplayError> {
    let st = status(frame)?;
    let b = st.brownian.unwrap_or_default();
    let mut q = world.query::<(
        &ParticleId,
        &mut Position,
        &mut ParticleRng,
        &mut Captured,
        &mut InitialPosition,
        &Shape,
    )>();
    let mut count = 0;
    for (id, mut p, mut r, mut c, mut x0, shape) in q.iter_mut(world) {
        let Some(k) = frame.ids.iter().position(|i| *i == id.0) else {
            return Err(bad(
                frame,
                format!("particle {} of the scene is not in the frame", id.0),
            ));
        };
        if frame.radii[k] != shape.radius() {
            return Err(bad(
                frame,
                format!("particle {}: radius differs from the scene", id.0),
            ));
        }
        p.0 = frame.positions[k];
        r.0 = rng_from_state_words(frame.rng_states[k]);
        c.0 = b.captured[k];
        x0.0 = DVec3::from_array(b.initial_positions[k]);
        count += 1;
    }
    if count != frame.ids.len() {
        return Err(bad(
            frame,
            format!("{} particles, the scene spawns {count}", frame.ids.len()),
        ));
    }
    world.resource_mut::<StepClock>().step = frame.step;
    world.insert_resource(b.stats);
    Ok(())
}

/// Why a resume failed.
#[derive(Debug, thiserror::Error)]
pub enum ResumeError {
    /// The recording or its last frame is unusable.
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// The continued run failed.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// Continue the run recorded in `path` from its last frame to the end of the scene's duration,
/// optionally recording the continuation to `record`. Returns the summary of the whole run.
///
/// # Errors
/// [`ResumeError`].
pub fn resume(
    path: &Path,
    record: Option<PathBuf>,
    on_step: impl FnMut(&World),
) -> Result<Value, ResumeError> {
    let rec = read_recording(path).map_err(ReplayError::from)?;
    let meta = rec.metadata.clone().ok_or(ReplayError::NoMetadata)?;
    let scene = parse_scene(&meta.scene_text, &Default::default()).map_err(ReplayError::from)?;
    if scene.brownian_section().is_none() {
        return Err(ReplayError::BadFrame {
            step: 0,
            detail: "resume is implemented for brownian recordings".into(),
        }
        .into());
    }
    let frame = last_frame(&rec)?.clone();
    let options = RunOptions {
        seed: Some(meta.seed),
        record,
        resume_from: Some(frame),
        ..Default::default()
    };
    let mut sim = Simulation::from_scene(&scene, options)?;
    Ok(sim.run(on_step)?)
}
