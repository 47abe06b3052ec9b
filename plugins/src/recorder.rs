//! Recording plugin: writes a frame to the MCAP recording every `every` steps (set
//! `SimSystems::Record`); the simulation driver also records step 0 and the final step with
//! [`record_now`]. The recorder knows no pipeline: a pipeline (or any plugin) adds what its
//! frames need beyond particles through [`FrameStatusProviders`] (keys of the frame's
//! `status_json`), [`ParticleColours`] or [`ColourProvider`], and writes channels of its own
//! through [`FrameWriters`]: each runs right after every frame the recorder writes (the
//! scheduled ones, step 0, the final step, and the last frame of an interrupted or failed run),
//! so a plugin's channel has one message per frame.
//!
//! A write error is never deferred: the first one is kept in [`Recorder::error`] (with the
//! file and the OS error), the writer is dropped (which closes the file best-effort, so what
//! was written stays readable), and the simulation driver checks [`recording_error`] after
//! every step and stops the run at once. A plugin writing a channel of its own reports its
//! errors the same way, through [`Recorder::fail`].
//!
//! | set | system | touches |
//! |---|---|---|
//! | `Record` | [`record_frame`] (exclusive; runs only if [`frame_due`]) | `Recorder`; reads particles, `StepClock`, `Container`, the providers |

use std::collections::BTreeMap;

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::rng::rng_state_words;
use magsep_systems::sets::SimSystems;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::app::{SimApp, SimPlugin};
use crate::record::{ParticleFrame, RecordingWriter};

/// The open recording (a resource). Without a writer, nothing is recorded.
#[derive(Resource, Default)]
pub struct Recorder {
    /// The writer, if recording. Plugins may add channels to it and write their messages
    /// (see `RecordingWriter::add_channel`), best from a [`FrameWriter`] so that the channel
    /// has a message for every frame.
    pub writer: Option<RecordingWriter>,
    /// Record every this many steps (>= 1).
    pub every: u64,
    /// First write error (recording stops after it, and the driver stops the run).
    pub error: Option<String>,
    /// Step of the last written frame.
    pub last_step: Option<u64>,
}

impl Recorder {
    /// Report a write error: the first one is kept, the file is marked interrupted with it
    /// (best effort), the writer is dropped (closing the file best-effort) and nothing more is
    /// recorded; the driver stops the run after this step.
    pub fn fail(&mut self, error: impl Into<String>) {
        let error = error.into();
        if let Some(w) = self.writer.as_mut() {
            // best effort (a full disk refuses it too): the file then says why it ends early
            let _ = w.write_interrupted(&format!("recording error: {error}"));
        }
        if self.error.is_none() {
            self.error = Some(error);
        }
        self.writer = None;
    }
}

/// The recording's first write error, if one happened (the driver polls it every step).
pub fn recording_error(world: &World) -> Option<&str> {
    world
        .get_resource::<Recorder>()
        .and_then(|r| r.error.as_deref())
}

/// Time spent writing frames (a resource, present only when a caller measures the
/// recording's cost, e.g. `magsep bench recording`): [`record_now`] adds the time it takes to
/// gather each frame and hand it to the writer.
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq)]
pub struct RecordTiming {
    /// Wall time spent in [`record_now`] writing frames \[s\].
    pub seconds: f64,
    /// The calling thread's CPU time in [`record_now`] \[s\] (Linux; elsewhere the wall
    /// time): unlike the wall time, not lengthened when a loaded machine preempts the thread.
    pub cpu_seconds: f64,
    /// Frames written.
    pub frames: u64,
    /// The longest single frame's time \[s\] (a stall shows here, not in a mean).
    pub max_seconds: f64,
    /// The step of that longest frame.
    pub max_step: u64,
}

/// A function giving one key of a frame's status (`None`: leave the key out).
pub type StatusFn = fn(&World) -> Option<Value>;

/// The keys of every frame's `status_json` beyond `container`, each with the function that
/// computes it (a resource; a pipeline registers what it needs to replay or resume a frame,
/// a plugin what it needs to restore its state, see `SimPlugin::restore`). The keys sit at the
/// top level of `status_json`; `container` and the pipeline's own keys (brownian: `brownian`;
/// packing: `packing`, `driver_rng`) are reserved: magsep's driver refuses a plugin's key of
/// one of those names when the recording opens.
#[derive(Resource, Default, Clone)]
pub struct FrameStatusProviders(pub Vec<(String, StatusFn)>);

impl FrameStatusProviders {
    /// Add (or replace) the provider of `key`.
    pub fn set(&mut self, key: impl Into<String>, f: StatusFn) {
        let key = key.into();
        self.0.retain(|(k, _)| *k != key);
        self.0.push((key, f));
    }
}

/// A frame's `status_json`: the container (walls and box) and the keys the pipeline's
/// providers wrote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct FrameStatus {
    /// The container of the frame (walled containers only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub container: Option<Container>,
    /// The pipeline's keys.
    #[serde(flatten)]
    pub keys: BTreeMap<String, Value>,
}

impl FrameStatus {
    /// Key `key` typed as `T`: `None` if absent or null.
    ///
    /// # Errors
    /// The serde error when the key does not have the shape of `T`.
    pub fn get<T: DeserializeOwned>(&self, key: &str) -> Result<Option<T>, serde_json::Error> {
        match self.keys.get(key) {
            None | Some(Value::Null) => Ok(None),
            Some(v) => serde_json::from_value(v.clone()).map(Some),
        }
    }
}

/// A plugin's writer of its own channel, called by [`record_now`] right after each frame
/// (with the world at that frame's step). It finds the writer in [`Recorder::writer`] (adding
/// its channel at the first call, e.g. by keeping the `ChannelHandle` in a resource of its
/// own) and returns a write error as `Err`, which stops the recording and the run as a frame's
/// write error does.
pub type FrameWriter = std::sync::Arc<dyn Fn(&mut World) -> Result<(), String> + Send + Sync>;

/// The [`FrameWriter`]s of plugins, run in registration order after every frame (a resource).
///
/// ```
/// use magsep_plugins::recorder::FrameWriters;
/// let mut world = bevy_ecs::world::World::new();
/// FrameWriters::register(&mut world, "my_channel", |_world: &mut bevy_ecs::world::World| Ok(()));
/// assert_eq!(world.resource::<FrameWriters>().0[0].0, "my_channel");
/// ```
#[derive(Resource, Default, Clone)]
pub struct FrameWriters(pub Vec<(String, FrameWriter)>);

impl FrameWriters {
    /// Add `writer` under `name` (named in its errors) to the world's frame writers.
    pub fn register(
        world: &mut World,
        name: impl Into<String>,
        writer: impl Fn(&mut World) -> Result<(), String> + Send + Sync + 'static,
    ) {
        world
            .get_resource_or_init::<FrameWriters>()
            .0
            .push((name.into(), std::sync::Arc::new(writer)));
    }
}

/// Per-particle viewer colours in `ParticleId` order (a resource; e.g. the particle-fluid
/// pipeline colours by density).
#[derive(Resource, Debug, Clone, Default)]
pub struct ParticleColours(pub Vec<[f32; 4]>);

/// Colours computed per frame (a resource; e.g. the brownian pipeline colours captured
/// particles): the function gets the world and the frame's particle ids in order.
#[derive(Resource, Clone, Copy)]
pub struct ColourProvider(pub fn(&World, &[u64]) -> Vec<[f32; 4]>);

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
        app.world.init_resource::<FrameStatusProviders>();
        app.schedule
            .add_systems(record_frame.in_set(SimSystems::Record).run_if(frame_due));
    }
}

/// What [`gather_frame`] reads of each particle.
type FrameRow = (
    &'static ParticleId,
    &'static Position,
    &'static Orientation,
    &'static Shape,
    Option<&'static ParticleRng>,
);

/// The query of [`gather_frame`], kept between frames (a resource, added at the first
/// frame): building a `QueryState` matches it against every archetype and table of the world,
/// which cost a one-particle frame more than gathering it (~9 k instructions of ~14 k).
#[derive(Resource)]
struct FrameQuery(QueryState<FrameRow>);

/// Gather the lossless frame of the current state (particles in `ParticleId` order).
pub fn gather_frame(world: &mut World) -> ParticleFrame {
    let mut state = match world.remove_resource::<FrameQuery>() {
        Some(q) => q.0,
        None => world.query::<FrameRow>(),
    };
    let frame = frame_of_rows(world, state.iter(world).collect());
    world.insert_resource(FrameQuery(state));
    frame
}

/// [`gather_frame`] with a query built for this frame alone (the reference the cached query
/// is checked against in tests).
pub fn gather_frame_uncached(world: &mut World) -> ParticleFrame {
    let mut q = world.query::<FrameRow>();
    frame_of_rows(world, q.iter(world).collect())
}

/// The frame of `rows` (any order) and the world's clock, container and status providers.
fn frame_of_rows(
    world: &World,
    mut rows: Vec<(
        &ParticleId,
        &Position,
        &Orientation,
        &Shape,
        Option<&ParticleRng>,
    )>,
) -> ParticleFrame {
    rows.sort_by_key(|r| *r.0);
    let container = world.get_resource::<Container>().copied();
    let mut fs = FrameStatus {
        container: container.filter(|c| c.walls().is_some()),
        keys: BTreeMap::new(),
    };
    if let Some(p) = world.get_resource::<FrameStatusProviders>() {
        for (key, f) in &p.0 {
            fs.keys.insert(key.clone(), f(world).unwrap_or(Value::Null));
        }
    }
    let clock = world
        .get_resource::<StepClock>()
        .copied()
        .unwrap_or_default();
    ParticleFrame {
        step: clock.step,
        time: clock.time(),
        box_edges: container
            .map(|c| c.edges())
            .unwrap_or(glam::DVec3::splat(f64::INFINITY)),
        ids: rows.iter().map(|r| r.0.0).collect(),
        positions: rows.iter().map(|r| r.1.0).collect(),
        orientations: rows.iter().map(|r| r.2.0).collect(),
        radii: rows.iter().map(|r| r.3.radius()).collect(),
        half_lengths: rows.iter().map(|r| r.3.half_length()).collect(),
        rng_states: rows
            .iter()
            .map(|r| r.4.map(|g| rng_state_words(&g.0)).unwrap_or([0; 4]))
            .collect(),
        status_json: serde_json::to_string(&fs).unwrap_or_else(|_| "{}".into()),
    }
}

/// Write a frame of the current state now, unless this step was written already (the
/// driver calls it for step 0 and for the final step).
pub fn record_now(world: &mut World) {
    let step = world.get_resource::<StepClock>().map(|c| c.step);
    let Some(rec) = world.get_resource::<Recorder>() else {
        return;
    };
    if rec.writer.is_none() || rec.last_step == step {
        return;
    }
    let started = std::time::Instant::now();
    let cpu_started = thread_cpu_seconds();
    let frame = gather_frame(world);
    let colours: Option<Vec<[f32; 4]>> = world
        .get_resource::<ColourProvider>()
        .map(|p| (p.0)(world, &frame.ids))
        .or_else(|| {
            world
                .get_resource::<ParticleColours>()
                .filter(|c| c.0.len() == frame.ids.len())
                .map(|c| c.0.clone())
        });
    let mut rec = world.resource_mut::<Recorder>();
    let step = frame.step;
    let result = rec
        .writer
        .as_mut()
        .map(|w| w.write_frame_owned(frame, colours));
    match result {
        Some(Err(e)) => rec.fail(format!("frame at step {step}: {e}")),
        _ => rec.last_step = Some(step),
    }
    if let Some(writers) = world.get_resource::<FrameWriters>().cloned() {
        for (name, write) in &writers.0 {
            if world.resource::<Recorder>().writer.is_none() {
                break;
            }
            if let Err(e) = write(world) {
                let mut rec = world.resource_mut::<Recorder>();
                rec.fail(format!("{name} at step {step}: {e}"));
            }
        }
    }
    if let Some(mut t) = world.get_resource_mut::<RecordTiming>() {
        let dt = started.elapsed().as_secs_f64();
        t.seconds += dt;
        t.cpu_seconds += match (cpu_started, thread_cpu_seconds()) {
            (Some(a), Some(b)) => b - a,
            _ => dt,
        };
        t.frames += 1;
        if dt > t.max_seconds {
            t.max_seconds = dt;
            t.max_step = step;
        }
    }
}

/// The calling thread's CPU time \[s\] (`None` where the platform does not say).
pub fn thread_cpu_seconds() -> Option<f64> {
    #[cfg(target_os = "linux")]
    return cpu_clock(libc::CLOCK_THREAD_CPUTIME_ID);
    #[cfg(not(target_os = "linux"))]
    None
}

/// The process's CPU time, all its threads \[s\] (`None` where the platform does not say).
pub fn process_cpu_seconds() -> Option<f64> {
    #[cfg(target_os = "linux")]
    return cpu_clock(libc::CLOCK_PROCESS_CPUTIME_ID);
    #[cfg(not(target_os = "linux"))]
    None
}

#[cfg(target_os = "linux")]
fn cpu_clock(clock: libc::clockid_t) -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec for the call to fill
    let rc = unsafe { libc::clock_gettime(clock, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
}

/// Whether this step's frame is due (the run condition of [`record_frame`], which as an
/// exclusive system would otherwise take the whole world at every step just to find out).
pub fn frame_due(clock: Option<Res<StepClock>>, recorder: Option<Res<Recorder>>) -> bool {
    recorder.is_some_and(|r| {
        r.writer.is_some() && clock.is_some_and(|c| c.step.is_multiple_of(r.every.max(1)))
    })
}

/// Record: write a frame every `every` steps.
pub fn record_frame(world: &mut World) {
    let step = world.get_resource::<StepClock>().map(|c| c.step);
    let due = world.get_resource::<Recorder>().is_some_and(|r| {
        r.writer.is_some() && step.is_some_and(|s| s.is_multiple_of(r.every.max(1)))
    });
    if due {
        record_now(world);
    }
}
