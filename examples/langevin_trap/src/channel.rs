//! The recording channel [`ENERGY_TOPIC`] (`/langevin_trap/energy`): one protobuf message
//! [`EnergyMessage`] (`langevin_trap.Energy`) per recorded frame, with its schema embedded in
//! the file (a `FileDescriptorSet` with a comment on every field), so a reader decodes it
//! from the file alone (e.g. Python's `mcap-protobuf-support`, see
//! `tests/python/read_custom_channel.py`).
//!
//! | plugin | set | system | touches |
//! |---|---|---|---|
//! | [`EnergyChannelPlugin`] | `Record` (after `record_frame`) | [`write_energy`] | `Recorder`, `EnergyChannel` |
//!
//! The channel is added by [`Pipeline::prepare_recording`](magsep::scene::Pipeline), which
//! also writes the message of the first frame; [`write_energy`] writes one at every step the
//! recorder writes a frame (`step % every == 0`) and at the last step of the run.

use magsep::bevy_ecs;
use magsep::bevy_ecs::prelude::*;
use magsep::components::prelude::*;
use magsep::plugins::app::{SimApp, SimPlugin};
use magsep::plugins::record::{
    ChannelHandle, ProtoField, ProtoType, ProtobufSchema, RecordError, RecordingWriter,
    protobuf_schema,
};
use magsep::plugins::recorder::{Recorder, record_frame};
use magsep::systems::sets::SimSystems;
use prost::Message as _;

use crate::dynamics::{TrapConfig, displacements};

/// Topic of the channel.
pub const ENERGY_TOPIC: &str = "/langevin_trap/energy";

/// One message of [`ENERGY_TOPIC`]: the ensemble averages of one recorded frame. Field
/// numbers and types match [`energy_schema`].
#[derive(Clone, Copy, PartialEq, prost::Message)]
pub struct EnergyMessage {
    /// Schedule step of the frame.
    #[prost(uint64, tag = "1")]
    pub step: u64,
    /// Simulated time `step * Δt` \[s\].
    #[prost(double, tag = "2")]
    pub time_s: f64,
    /// Mean potential energy per particle ⟨k |x - x0|² / 2⟩ \[J\] (equilibrium: 3 k_B T / 2).
    #[prost(double, tag = "3")]
    pub mean_potential_energy_j: f64,
    /// Mean square displacement from the centre ⟨|x - x0|²⟩ \[m²\] (equilibrium: 3 k_B T / k).
    #[prost(double, tag = "4")]
    pub msd_m2: f64,
}

/// The self-describing schema of [`EnergyMessage`] (`langevin_trap.Energy`).
///
/// # Errors
/// [`RecordError::InvalidInput`] if the schema were malformed (it is not).
pub fn energy_schema() -> Result<ProtobufSchema, RecordError> {
    protobuf_schema(
        "langevin_trap",
        "Energy",
        "Ensemble averages of one recorded frame of the langevin_trap pipeline.",
        &[
            ProtoField::new("step", 1, ProtoType::Uint64, "schedule step of the frame"),
            ProtoField::new("time_s", 2, ProtoType::Double, "simulated time [s]"),
            ProtoField::new(
                "mean_potential_energy_j",
                3,
                ProtoType::Double,
                "mean potential energy per particle <k |x - x0|^2 / 2> [J]",
            ),
            ProtoField::new(
                "msd_m2",
                4,
                ProtoType::Double,
                "mean square displacement from the trap centre <|x - x0|^2> [m^2]",
            ),
        ],
    )
}

/// The channel of this run (a resource): its handle, or why it could not be added (reported
/// by [`write_energy`] as the recorder's error, which fails the run).
#[derive(Resource, Debug, Clone)]
pub struct EnergyChannel(pub Result<ChannelHandle, String>);

/// MCAP log time \[ns\] of a frame at `step` and `time` \[s\]: the rule of the `/state` frames
/// (`magsep::plugins::record::log_time_ns`), so a message and its frame share a log time.
pub fn log_time(step: u64, time: f64) -> u64 {
    if time == 0.0 {
        step
    } else {
        (time * 1e9).round() as u64
    }
}

/// The message of the current state of `rows` (particle id, position).
pub fn energy_message(
    config: &TrapConfig,
    clock: &StepClock,
    rows: &[(ParticleId, magsep::glam::DVec3)],
) -> EnergyMessage {
    let d = displacements(rows, config.0.centre);
    let msd = d.iter().map(|v| v.length_squared()).sum::<f64>() / d.len().max(1) as f64;
    EnergyMessage {
        step: clock.step,
        time_s: clock.time(),
        mean_potential_energy_j: 0.5 * config.0.stiffness * msd,
        msd_m2: msd,
    }
}

fn rows(world: &mut World) -> Vec<(ParticleId, magsep::glam::DVec3)> {
    let mut q = world.query::<(&ParticleId, &Position)>();
    q.iter(world).map(|(id, p)| (*id, p.0)).collect()
}

/// Add the channel to `writer`, store its handle in [`EnergyChannel`] and write the message
/// of the current state (the first frame). Called by `Pipeline::prepare_recording`.
pub fn open_energy_channel(world: &mut World, writer: &mut RecordingWriter) {
    let handle = energy_schema()
        .and_then(|s| writer.add_protobuf_channel(ENERGY_TOPIC, &s))
        .map_err(|e| format!("{ENERGY_TOPIC}: {e}"));
    let first = match (
        &handle,
        world.get_resource::<TrapConfig>().copied(),
        world.get_resource::<StepClock>().copied(),
    ) {
        (Ok(h), Some(config), Some(clock)) => {
            let m = energy_message(&config, &clock, &rows(world));
            writer
                .write_message(*h, log_time(m.step, m.time_s), &m.encode_to_vec())
                .map_err(|e| format!("{ENERGY_TOPIC}: {e}"))
        }
        _ => Ok(()),
    };
    world.insert_resource(EnergyChannel(first.and(handle)));
}

/// Record: after the recorder's frame, write the energy message when a frame is due
/// (`step % every == 0`, and the last step of the run, which the driver records).
pub fn write_energy(
    config: Res<TrapConfig>,
    clock: Res<StepClock>,
    channel: Option<Res<EnergyChannel>>,
    recorder: Option<ResMut<Recorder>>,
    q: Query<(&ParticleId, &Position)>,
) {
    let (Some(channel), Some(mut recorder)) = (channel, recorder) else {
        return;
    };
    if recorder.writer.is_none() || recorder.error.is_some() {
        return;
    }
    let handle = match &channel.0 {
        Ok(h) => *h,
        Err(e) => {
            recorder.error = Some(e.clone());
            recorder.writer = None;
            return;
        }
    };
    let due = clock.step.is_multiple_of(recorder.every.max(1)) || clock.step >= config.0.steps;
    if !due {
        return;
    }
    let rows: Vec<_> = q.iter().map(|(id, p)| (*id, p.0)).collect();
    let m = energy_message(&config, &clock, &rows);
    let result = recorder
        .writer
        .as_mut()
        .map(|w| w.write_message(handle, log_time(m.step, m.time_s), &m.encode_to_vec()));
    if let Some(Err(e)) = result {
        recorder.error = Some(format!("{ENERGY_TOPIC}: {e}"));
        recorder.writer = None;
    }
}

/// Writes [`ENERGY_TOPIC`] messages (needs the `RecordPlugin` for the `Recorder` and its
/// `record_frame` system).
#[derive(Debug, Clone, Copy, Default)]
pub struct EnergyChannelPlugin;

impl SimPlugin for EnergyChannelPlugin {
    fn build(&self, app: &mut SimApp) {
        app.schedule
            .add_systems(write_energy.after(record_frame).in_set(SimSystems::Record));
    }
}
