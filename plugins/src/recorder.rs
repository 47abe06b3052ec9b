//! Recording plugin: writes a frame to the MCAP recording every `every` steps and at the end
//! of a run (set `SimSystems::Record`).
//!
//! | set | system | touches |
//! |---|---|---|
//! | `Record` | [`record_frame`] | `Recorder`; reads particles, `StepClock`, `Container`, `PackingStatus`, `McmWorkspace`, `BrownianConfig`, `BrownianStats` |
//!
//! Brownian runs colour captured particles [`CAPTURED_COLOUR`] and free ones [`FREE_COLOUR`].

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::packing::systems::McmWorkspace;
use magsep_systems::rng::rng_state_words;
use magsep_systems::sets::SimSystems;
use serde::{Deserialize, Serialize};

use crate::app::{SimApp, SimPlugin};
use crate::record::{ParticleFrame, RecordingWriter};

/// The open recording (a resource). Without a writer, nothing is recorded.
#[derive(Resource, Default)]
pub struct Recorder {
    /// The writer, if recording.
    pub writer: Option<RecordingWriter>,
    /// Record every this many steps (>= 1).
    pub every: u64,
    /// First write error (recording stops after it).
    pub error: Option<String>,
    /// Step of the last written frame.
    pub last_step: Option<u64>,
}

/// Pipeline status stored in every frame's `status_json` (for replay and resume).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct FrameStatus {
    /// Packing driver status.
    pub packing: Option<PackingStatus>,
    /// Packing driver random stream (xoshiro256++ words).
    pub driver_rng: Option<[u64; 4]>,
    /// The container (walls and box) of the frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub container: Option<Container>,
    /// Brownian pipeline state beyond positions and random streams.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub brownian: Option<BrownianFrameStatus>,
}

/// Brownian state of a frame (with the positions and streams of the frame: a lossless
/// checkpoint for `--resume`). Arrays in `ParticleId` order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct BrownianFrameStatus {
    /// Capture of each particle (step and fibre), `null` while free.
    pub captured: Vec<Option<CaptureEvent>>,
    /// Start positions [m] (for displacements and the Brownian criterion).
    pub initial_positions: Vec<[f64; 3]>,
    /// Stepper counters so far.
    pub stats: BrownianStats,
}

/// Per-particle viewer colours in `ParticleId` order (a resource; e.g. the particle-fluid
/// pipeline colours by density). Brownian runs colour by capture instead.
#[derive(Resource, Debug, Clone, Default)]
pub struct ParticleColours(pub Vec<[f32; 4]>);

/// Colour of a free particle in the viewer (RGBA).
pub const FREE_COLOUR: [f32; 4] = [0.35, 0.55, 0.85, 1.0];
/// Colour of a captured particle in the viewer (RGBA).
pub const CAPTURED_COLOUR: [f32; 4] = [0.9, 0.25, 0.15, 1.0];

/// Writes frames.
#[derive(Debug, Clone, Copy, Default)]
pub struct RecordPlugin;

impl SimPlugin for RecordPlugin {
    fn build(&self, app: &mut SimApp) {
        if !app.world.contains_resource::<Recorder>() {
            app.world.insert_resource(Recorder {
                every: 100,
                ..Default::default()
            });
        }
        app.schedule
            .add_systems(record_frame.in_set(SimSystems::Record));
    }
}

type FrameQuery<'w, 's> = Query<
    'w,
    's,
    (
        &'static ParticleId,
        &'static Position,
        &'static Orientation,
        &'static Shape,
        &'static ParticleRng,
        Option<&'static Captured>,
        Option<&'static InitialPosition>,
    ),
>;

/// Gather the lossless frame of the current state (particles in `ParticleId` order).
pub fn gather_frame(
    clock: &StepClock,
    container: &Container,
    status: Option<&PackingStatus>,
    ws: Option<&McmWorkspace>,
    brownian: Option<&BrownianStats>,
    q: &FrameQuery,
) -> ParticleFrame {
    let mut rows: Vec<_> = q.iter().collect();
    rows.sort_by_key(|r| *r.0);
    let fs = FrameStatus {
        packing: status.copied(),
        driver_rng: ws.map(|w| rng_state_words(&w.rng)),
        container: container.walls().map(|_| *container),
        brownian: brownian.map(|stats| BrownianFrameStatus {
            captured: rows.iter().map(|r| r.5.and_then(|c| c.0)).collect(),
            initial_positions: rows
                .iter()
                .map(|r| r.6.map(|p| p.0.to_array()).unwrap_or_default())
                .collect(),
            stats: stats.clone(),
        }),
    };
    ParticleFrame {
        step: clock.step,
        time: clock.time(),
        box_edges: container.edges(),
        ids: rows.iter().map(|r| r.0.0).collect(),
        positions: rows.iter().map(|r| r.1.0).collect(),
        orientations: rows.iter().map(|r| r.2.0).collect(),
        radii: rows.iter().map(|r| r.3.radius()).collect(),
        half_lengths: rows.iter().map(|r| r.3.half_length()).collect(),
        rng_states: rows.iter().map(|r| rng_state_words(&r.4.0)).collect(),
        status_json: serde_json::to_string(&fs).unwrap_or_else(|_| "{}".into()),
    }
}

/// What the recorder reads of the brownian and particle-fluid pipelines, if present.
type PipelineViews<'w> = (
    Option<Res<'w, BrownianConfig>>,
    Option<Res<'w, BrownianStats>>,
    Option<Res<'w, ParticleColours>>,
);

/// Record: write a frame every `every` steps and when the run has stopped.
pub fn record_frame(
    mut rec: ResMut<Recorder>,
    clock: Res<StepClock>,
    container: Res<Container>,
    status: Option<Res<PackingStatus>>,
    ws: Option<Res<McmWorkspace>>,
    (brownian, stats, fixed_colours): PipelineViews,
    q: FrameQuery,
) {
    if rec.writer.is_none() || rec.last_step == Some(clock.step) {
        return;
    }
    let stopped = status
        .as_ref()
        .map(|s| s.stopped.is_some())
        .unwrap_or(false)
        || brownian.as_ref().is_some_and(|c| clock.step >= c.steps);
    if !(stopped || clock.step.is_multiple_of(rec.every.max(1))) {
        return;
    }
    let stats = brownian
        .as_ref()
        .map(|_| stats.as_deref().cloned().unwrap_or_default());
    let frame = gather_frame(
        &clock,
        &container,
        status.as_deref(),
        ws.as_deref(),
        stats.as_ref(),
        &q,
    );
    let fixed = fixed_colours
        .as_ref()
        .filter(|c| c.0.len() == frame.ids.len())
        .map(|c| c.0.clone());
    let colours: Option<Vec<[f32; 4]>> = fixed.or_else(|| {
        brownian.as_ref().map(|_| {
            let mut rows: Vec<_> = q.iter().map(|r| (*r.0, r.5.and_then(|c| c.0))).collect();
            rows.sort_by_key(|r| r.0);
            rows.iter()
                .map(|r| {
                    if r.1.is_some() {
                        CAPTURED_COLOUR
                    } else {
                        FREE_COLOUR
                    }
                })
                .collect()
        })
    });
    let result = rec
        .writer
        .as_mut()
        .map(|w| w.write_frame(&frame, colours.as_deref()));
    match result {
        Some(Err(e)) => {
            rec.error = Some(e.to_string());
            rec.writer = None;
        }
        _ => rec.last_step = Some(clock.step),
    }
}
