//! Replay and resume of brownian recordings.
//!
//! Every frame of a brownian recording holds, besides positions and random streams, the
//! capture events (step and fibre per particle), the start positions and the stepper counters
//! (`status_json.brownian`). That is the whole state of a run: **replay** recomputes the capture
//! curves and the summary from the last frame, and **resume** spawns the recorded scene, puts
//! the last frame's state into it and runs on to the end, bitwise as if never interrupted.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;
use magsep_plugins::record::{ParticleFrame, Recording};
use magsep_plugins::recorder::FrameStatus;
use magsep_systems::rng::rng_from_state_words;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::summary::{RunResult, StartRegions, is_brownian, summary_of};
use crate::error::ReplayError;
use crate::replay::{last_frame, recorded_wall_time};
use crate::scene::Scene;

fn bad(frame: &ParticleFrame, detail: impl Into<String>) -> ReplayError {
    ReplayError::BadFrame {
        step: frame.step,
        detail: detail.into(),
    }
}

/// Brownian state of a frame (with the positions and streams of the frame: a lossless
/// checkpoint for `--resume`), the `brownian` key of its status. Arrays in `ParticleId`
/// order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct BrownianFrameStatus {
    /// Capture of each particle (step and fibre), `null` while free.
    pub captured: Vec<Option<CaptureEvent>>,
    /// Start positions \[m\] (for displacements and the Brownian criterion).
    pub initial_positions: Vec<[f64; 3]>,
    /// Stepper counters so far.
    pub stats: BrownianStats,
}

/// Colour of a free particle in the viewer (RGBA).
pub const FREE_COLOUR: [f32; 4] = [0.35, 0.55, 0.85, 1.0];
/// Colour of a captured particle in the viewer (RGBA).
pub const CAPTURED_COLOUR: [f32; 4] = [0.9, 0.25, 0.15, 1.0];

fn capture_rows(world: &World) -> Vec<(ParticleId, Option<CaptureEvent>, [f64; 3])> {
    let mut rows: Vec<_> = world
        .try_query::<(&ParticleId, Option<&Captured>, Option<&InitialPosition>)>()
        .map(|mut q| {
            q.iter(world)
                .map(|(id, c, p)| {
                    (
                        *id,
                        c.and_then(|c| c.0),
                        p.map(|p| p.0.to_array()).unwrap_or_default(),
                    )
                })
                .collect()
        })
        .unwrap_or_default();
    rows.sort_by_key(|r| r.0);
    rows
}

/// The `brownian` key of a frame's status (a recorder status provider).
pub fn frame_status(world: &World) -> Option<Value> {
    let stats = world
        .get_resource::<BrownianStats>()
        .cloned()
        .unwrap_or_default();
    let rows = capture_rows(world);
    serde_json::to_value(BrownianFrameStatus {
        captured: rows.iter().map(|r| r.1).collect(),
        initial_positions: rows.iter().map(|r| r.2).collect(),
        stats,
    })
    .ok()
}

/// Viewer colours: captured particles red, free ones blue (a recorder colour provider).
pub fn capture_colours(world: &World, _ids: &[u64]) -> Vec<[f32; 4]> {
    capture_rows(world)
        .iter()
        .map(|r| {
            if r.1.is_some() {
                CAPTURED_COLOUR
            } else {
                FREE_COLOUR
            }
        })
        .collect()
}

struct Status {
    brownian: Option<BrownianFrameStatus>,
}

fn status(frame: &ParticleFrame) -> Result<Status, ReplayError> {
    let fs: FrameStatus = serde_json::from_str(&frame.status_json)
        .map_err(|e| bad(frame, format!("status_json: {e}")))?;
    let s = Status {
        brownian: fs
            .get::<BrownianFrameStatus>("brownian")
            .map_err(|e| bad(frame, format!("status_json.brownian: {e}")))?,
    };
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
        .section::<super::BrownianSection>()
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
            let dx = frame.positions[i] - x0;
            is_brownian(&config, frame.radii[i], dx, t, b.captured[i].is_some())
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

/// Summary of a brownian recording recomputed from its last frame (of replicate 0, the one
/// recorded: with `runs > 1` the summary says so in `runs_in_scene` and `note`).
///
/// # Errors
/// [`ReplayError`] when the recording has no frame or its state is malformed.
pub fn replay_brownian(rec: &Recording, scene: &Scene, seed: u64) -> Result<Value, ReplayError> {
    let frame = last_frame(rec)?;
    let result = frame_result(scene, frame, seed)?;
    let config = scene
        .section::<super::BrownianSection>()
        .map(|s| s.config())
        .unwrap_or_else(|| unreachable!("frame_result checked the scene is brownian"));
    let wall = recorded_wall_time(rec);
    let mut summary = summary_of(&[result], &start_regions(scene), &config, wall);
    summary["frames"] = rec.frames.len().into();
    let runs = scene
        .section::<super::BrownianSection>()
        .map_or(1, |s| s.runs());
    if runs > 1 {
        // only replicate 0 is recorded: say so rather than pass one replicate off as the run
        summary["runs_in_scene"] = runs.into();
        summary["note"] = format!(
            "the recording holds replicate 0 of the scene's {runs} runs: this summary is that \
             replicate's; `replay --resume` runs the others again for the whole ensemble"
        )
        .into();
    }
    // a cost counter, not state: frames do not hold it (see `BrownianStats`)
    crate::replay::not_recomputed(&mut summary, &["stepper.neighbour_list_builds"]);
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
