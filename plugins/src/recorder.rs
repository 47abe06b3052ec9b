//! Recording plugin: writes a frame to the MCAP recording every `every` steps and at the end
//! of a run (set `SimSystems::Record`).
//!
//! | set | system | touches |
//! |---|---|---|
//! | `Record` | [`record_frame`] | `Recorder`; reads particles, `StepClock`, `Container`, `PackingStatus`, `McmWorkspace` |

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
}

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
    ),
>;

/// Gather the lossless frame of the current state (particles in `ParticleId` order).
pub fn gather_frame(
    clock: &StepClock,
    container: &Container,
    status: Option<&PackingStatus>,
    ws: Option<&McmWorkspace>,
    q: &FrameQuery,
) -> ParticleFrame {
    let mut rows: Vec<_> = q.iter().collect();
    rows.sort_by_key(|r| *r.0);
    let fs = FrameStatus {
        packing: status.copied(),
        driver_rng: ws.map(|w| rng_state_words(&w.rng)),
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

/// Record: write a frame every `every` steps and when the run has stopped.
pub fn record_frame(
    mut rec: ResMut<Recorder>,
    clock: Res<StepClock>,
    container: Res<Container>,
    status: Option<Res<PackingStatus>>,
    ws: Option<Res<McmWorkspace>>,
    q: FrameQuery,
) {
    if rec.writer.is_none() || rec.last_step == Some(clock.step) {
        return;
    }
    let stopped = status
        .as_ref()
        .map(|s| s.stopped.is_some())
        .unwrap_or(false);
    if !(stopped || clock.step.is_multiple_of(rec.every.max(1))) {
        return;
    }
    let frame = gather_frame(&clock, &container, status.as_deref(), ws.as_deref(), &q);
    let result = rec.writer.as_mut().map(|w| w.write_frame(&frame, None));
    match result {
        Some(Err(e)) => {
            rec.error = Some(e.to_string());
            rec.writer = None;
        }
        _ => rec.last_step = Some(clock.step),
    }
}
