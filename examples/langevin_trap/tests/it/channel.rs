//! The recording channel `/langevin_trap/energy`: one message per frame, at the frame's step
//! and log time, with the frame's ensemble averages, decodable with the embedded schema.

use crate::common;

use common::{parse, run, temp_dir, trap_scene};
use langevin_trap::channel::{energy_message, energy_schema, log_time};
use langevin_trap::{ENERGY_TOPIC, EnergyMessage, TrapConfig, TrapParams};
use magsep::RunOptions;
use magsep::components::brownian::BOLTZMANN;
use magsep::components::prelude::*;
use magsep::plugins::record::{RecordingReader, log_time_ns, read_recording};
use prost::Message as _;

#[test]
fn one_energy_message_per_frame() {
    let dir = temp_dir("channel");
    let path = dir.join("run.mcap");
    // 403 steps: the last step is not a multiple of `every` and is recorded by the driver
    let scene = parse(&trap_scene(400, 2e-3, 403, 10, ""));
    run(
        &scene,
        RunOptions {
            record: Some(path.clone()),
            ..Default::default()
        },
    );
    let rec = read_recording(&path).unwrap();
    let info = rec
        .channels
        .iter()
        .find(|c| c.topic == ENERGY_TOPIC)
        .expect("energy channel");
    assert_eq!(info.schema_name, "langevin_trap.Energy");
    assert_eq!(info.schema_encoding, "protobuf");
    assert_eq!(info.message_encoding, "protobuf");
    assert_eq!(info.message_count, rec.frames.len() as u64);

    let mut reader = RecordingReader::open(&path).unwrap();
    let schema = reader.schema(ENERGY_TOPIC).expect("schema");
    assert_eq!(schema.data, energy_schema().unwrap().data);
    let messages: Vec<_> = reader
        .messages(Some(ENERGY_TOPIC))
        .map(|m| m.expect("message"))
        .collect();
    assert_eq!(messages.len(), rec.frames.len());
    let params = TrapParams::of_scene(&scene).unwrap();
    let config = TrapConfig(params);
    let mut late = Vec::new();
    for (raw, frame) in messages.iter().zip(&rec.frames) {
        let m = EnergyMessage::decode(raw.data.as_slice()).expect("decode");
        assert_eq!(m.step, frame.step);
        assert_eq!(raw.log_time_ns, log_time_ns(frame));
        assert_eq!(raw.log_time_ns, log_time(m.step, m.time_s));
        // the message holds the averages of its frame's positions
        let rows: Vec<_> = frame
            .ids
            .iter()
            .zip(&frame.positions)
            .map(|(id, x)| (ParticleId(*id), *x))
            .collect();
        let clock = StepClock {
            step: frame.step,
            dt: params.dt,
        };
        assert_eq!(m, energy_message(&config, &clock, &rows));
        if frame.step >= params.first_sample {
            late.push(m);
        }
    }
    assert_eq!(rec.frames.last().unwrap().step, 403);
    // equilibrium: <U> = 3/2 k_B T per particle (≈ 36 frames × 400 particles)
    let kt = BOLTZMANN * 293.0;
    let u = late.iter().map(|m| m.mean_potential_energy_j).sum::<f64>() / late.len() as f64;
    eprintln!("<U> = {u:.4e} J, 3/2 kT = {:.4e} J", 1.5 * kt);
    assert!((u / (1.5 * kt) - 1.0).abs() < 0.05);
}
