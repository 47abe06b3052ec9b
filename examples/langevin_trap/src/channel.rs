//! The recording channel [`ENERGY_TOPIC`] (`/langevin_trap/energy`): one protobuf message
//! [`EnergyMessage`] (`langevin_trap.Energy`) per recorded frame, with its schema embedded in
//! the file (a `FileDescriptorSet` with a comment on every field), so a reader decodes it
//! from the file alone (e.g. Python's `mcap-protobuf-support`, see
//! `tests/python/read_custom_channel.py`).
//!
//! | plugin | runs | function | touches |
//! |---|---|---|---|
//! | [`EnergyChannelPlugin`] | after every frame the recorder writes (a `FrameWriter`) | [`write_energy`] | `Recorder`, `EnergyChannel` |
//!
//! [`write_energy`] adds the channel at the first frame and writes one message per frame:
//! the scheduled ones, step 0, the last step and the last frame of an interrupted run alike.

use magsep::bevy_ecs;
use magsep::bevy_ecs::prelude::*;
use magsep::components::prelude::*;
use magsep::plugins::app::{SimApp, SimPlugin};
use magsep::plugins::record::{
    ChannelHandle, ProtoField, ProtoType, ProtobufSchema, RecordError, protobuf_schema,
};
use magsep::plugins::recorder::{FrameWriters, Recorder};
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

/// The channel of this run, once added (a resource).
#[derive(Resource, Debug, Clone, Copy)]
pub struct EnergyChannel(pub ChannelHandle);

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

/// A [`FrameWriter`](magsep::plugins::recorder::FrameWriter): the energy message of the frame
/// the recorder has just written, adding the channel at the first frame.
///
/// # Errors
/// The channel could not be added or the message not written (the recorder then stops the
/// run, as for a frame's write error).
pub fn write_energy(world: &mut World) -> Result<(), String> {
    let (Some(config), Some(clock)) = (
        world.get_resource::<TrapConfig>().copied(),
        world.get_resource::<StepClock>().copied(),
    ) else {
        return Ok(());
    };
    let m = energy_message(&config, &clock, &rows(world));
    let known = world.get_resource::<EnergyChannel>().map(|c| c.0);
    let mut recorder = world.resource_mut::<Recorder>();
    let Some(writer) = recorder.writer.as_mut() else {
        return Ok(());
    };
    let handle = match known {
        Some(h) => h,
        None => energy_schema()
            .and_then(|s| writer.add_protobuf_channel(ENERGY_TOPIC, &s))
            .map_err(|e| format!("{ENERGY_TOPIC}: {e}"))?,
    };
    writer
        .write_message(handle, log_time(m.step, m.time_s), &m.encode_to_vec())
        .map_err(|e| format!("{ENERGY_TOPIC}: {e}"))?;
    if known.is_none() {
        world.insert_resource(EnergyChannel(handle));
    }
    Ok(())
}

/// Writes [`ENERGY_TOPIC`] messages: registers [`write_energy`] as a frame writer, so the
/// channel has one message for every frame the recorder writes.
#[derive(Debug, Clone, Copy, Default)]
pub struct EnergyChannelPlugin;

impl SimPlugin for EnergyChannelPlugin {
    fn build(&self, app: &mut SimApp) {
        FrameWriters::register(&mut app.world, ENERGY_TOPIC, write_energy);
    }
}
