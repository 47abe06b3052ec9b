//! # langevin-trap
//!
//! A magsep pipeline written outside the magsep crate, as a user would: overdamped Langevin
//! (Brownian) spheres in a three-dimensional harmonic trap F = -k (x - x0), integrated with
//! the exact Ornstein-Uhlenbeck update. Its equilibrium position variance per axis is
//! k_B T / k, which the summary compares with the measured one.
//!
//! * [`scene`]: the `[trap]` section and the `start` particle key, validated at key paths;
//! * [`dynamics`]: spawning, the step and the statistics as ECS systems ([`LangevinTrapPlugin`]);
//! * [`summary`]: the typed summary, from a run or recomputed from a recording;
//! * [`channel`]: the recording channel `/langevin_trap/energy` ([`EnergyChannelPlugin`]);
//! * [`LangevinTrapPipeline`]: the [`Pipeline`] hooks tying them together.
//!
//! ```no_run
//! use langevin_trap::LangevinTrapPipeline;
//! std::process::exit(magsep::cli::main_with(
//!     magsep::cli::Extensions::default().pipeline(LangevinTrapPipeline),
//! ));
//! ```

#![warn(missing_docs)]

pub mod channel;
pub mod dynamics;
pub mod scene;
pub mod summary;

use magsep::bevy_ecs::prelude::*;
use magsep::components::prelude::*;
use magsep::error::{ReplayError, SpawnError};
use magsep::plugins::core::CorePlugin;
use magsep::plugins::group::PipelineGroup;
use magsep::plugins::record::{ParticleFrame, Recording, RecordingWriter};
use magsep::plugins::recorder::{FrameStatus, FrameStatusProviders, RecordPlugin};
use magsep::scene::{ParseContext, Pipeline, Registry, RunInfo, Scene, SceneSection};
use magsep::serde_json::{self, Value};
use magsep::systems::rng::rng_from_state_words;

pub use channel::{ENERGY_TOPIC, EnergyChannelPlugin, EnergyMessage};
pub use dynamics::{LangevinTrapPlugin, TrapConfig};
pub use scene::{TrapParams, TrapScene, TrapSection};
pub use summary::{TrapStats, TrapSummary};

/// The `langevin_trap` pipeline.
#[derive(Debug, Clone, Copy, Default)]
pub struct LangevinTrapPipeline;

/// The built-in pipelines and this one (what the `langevin-trap` binary knows).
pub fn registry() -> Registry {
    Registry::default().with_pipeline(LangevinTrapPipeline)
}

/// Key of the frames' `status_json` holding [`TrapStats`] (for resume).
pub const STATUS_KEY: &str = "langevin_trap";

impl Pipeline for LangevinTrapPipeline {
    fn name(&self) -> &'static str {
        scene::PIPELINE
    }

    fn description(&self) -> &'static str {
        "overdamped Langevin spheres in a harmonic trap (exact Ornstein-Uhlenbeck step)"
    }

    fn sections(&self) -> &'static [&'static str] {
        &[scene::SECTION]
    }

    fn particle_keys(&self) -> &'static [&'static str] {
        &[scene::START_KEY]
    }

    fn parse(&self, cx: &mut ParseContext<'_>) -> Option<SceneSection> {
        scene::parse(cx).map(SceneSection::new)
    }

    fn spawn(&self, scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError> {
        dynamics::spawn(scene, world, seed)
    }

    fn plugins(&self, _scene: &Scene) -> PipelineGroup {
        PipelineGroup::new()
            .add(CorePlugin)
            .add(LangevinTrapPlugin)
            .add(RecordPlugin)
            .add(EnergyChannelPlugin)
    }

    fn is_finished(&self, world: &World) -> bool {
        match (
            world.get_resource::<TrapConfig>(),
            world.get_resource::<StepClock>(),
        ) {
            (Some(c), Some(clock)) => clock.step >= c.0.steps,
            _ => true,
        }
    }

    fn total_steps(&self, scene: &Scene) -> Option<u64> {
        TrapParams::of_scene(scene).map(|p| p.steps)
    }

    fn progress(&self, world: &World) -> Option<String> {
        let s = world.get_resource::<TrapStats>()?;
        (s.samples > 0).then(|| {
            let v = s.variance();
            format!(
                "samples {}  variance [{:.3e} {:.3e} {:.3e}] m²",
                s.samples, v[0], v[1], v[2]
            )
        })
    }

    fn summary(&self, world: &World, run: &RunInfo) -> Value {
        summary::summary_of(world, run.seed, run.wall_time_s)
    }

    fn prepare_recording(&self, world: &mut World, _writer: &mut RecordingWriter) {
        world
            .get_resource_or_init::<FrameStatusProviders>()
            .set(STATUS_KEY, |w| {
                w.get_resource::<TrapStats>()
                    .and_then(|s| serde_json::to_value(s).ok())
            });
    }

    fn replay(&self, rec: &Recording, scene: &Scene, seed: u64) -> Result<Value, ReplayError> {
        summary::replay(rec, scene, seed)
    }

    fn apply_frame(&self, world: &mut World, frame: &ParticleFrame) -> Result<(), ReplayError> {
        apply_frame(world, frame)
    }
}

/// Restore a recorded frame into a freshly spawned world: positions and random streams by
/// particle id, the step and the statistics, so a resumed run continues bit for bit.
///
/// # Errors
/// [`ReplayError::BadFrame`] when the frame's particles or status do not fit the world.
pub fn apply_frame(world: &mut World, frame: &ParticleFrame) -> Result<(), ReplayError> {
    let bad = |detail: String| ReplayError::BadFrame {
        step: frame.step,
        detail,
    };
    let n = frame.ids.len();
    if frame.positions.len() != n || frame.rng_states.len() != n {
        return Err(bad("arrays of different lengths".into()));
    }
    let status: FrameStatus =
        serde_json::from_str(&frame.status_json).map_err(|e| bad(format!("status_json: {e}")))?;
    let stats = status
        .get::<TrapStats>(STATUS_KEY)
        .map_err(|e| bad(format!("status_json.{STATUS_KEY}: {e}")))?
        .ok_or_else(|| bad(format!("status_json has no `{STATUS_KEY}` statistics")))?;
    let mut q = world.query::<(&ParticleId, &mut Position, &mut ParticleRng)>();
    let mut index: std::collections::HashMap<u64, usize> = frame
        .ids
        .iter()
        .enumerate()
        .map(|(i, id)| (*id, i))
        .collect();
    let mut count = 0;
    for (id, mut pos, mut rng) in q.iter_mut(world) {
        let Some(i) = index.remove(&id.0) else {
            return Err(bad(format!("particle {} is not in the frame", id.0)));
        };
        pos.0 = frame.positions[i];
        rng.0 = rng_from_state_words(frame.rng_states[i]);
        count += 1;
    }
    if count != n {
        return Err(bad(format!(
            "{n} particles in the frame, {count} in the scene"
        )));
    }
    world.resource_mut::<StepClock>().step = frame.step;
    world.insert_resource(stats);
    Ok(())
}

/// The plugin guide's snippets (`docs/writing-a-plugin.md`), compiled and run as doctests of
/// this crate, which depends on `magsep` alone: they compile in a user's crate as written.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/writing-a-plugin.md")]
pub struct PluginGuideDoctests;
