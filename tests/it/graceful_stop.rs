//! The library side of a graceful stop: a [`StopFlag`] ends a run after the current step with
//! a complete recording marked interrupted (single simulations and every replicate of a
//! brownian ensemble), and a recording write failure (a sink that fails like a full disk)
//! stops the run at that very step with the summary of what ran.

use magsep::plugins::record::testing::FullDisk;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use magsep::bevy_ecs::world::World;
use magsep::plugins::record::{
    INTERRUPTED_METADATA_NAME, RecordingMetadata, RecordingWriter, read_recording,
    read_recording_bytes,
};
use magsep::plugins::recorder::Recorder;
use magsep::prelude::*;
use magsep::scene::{NoProgress, Scene, load_scene, parse_scene};
use magsep::sim::run_scene;
use serde_json::Value;

const PACKING: &str = r#"
[simulation]
pipeline = "packing"
seed = 4
[container]
kind = "periodic_box"
[[particles]]
count = 60
shape = { kind = "sphere", radius = 0.5 }
[record]
every = 1
"#;

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("graceful_stop");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn packing() -> Scene {
    parse_scene(PACKING, &Default::default()).unwrap()
}

fn step(w: &World) -> u64 {
    w.resource::<StepClock>().step
}

#[test]
fn a_stop_request_ends_the_run_after_the_current_step_with_a_complete_recording() {
    let path = tmp("stopped.mcap");
    let stop = StopFlag::new();
    let mut sim = Simulation::builder(&packing())
        .record(&path)
        .stop_flag(stop.clone())
        .build()
        .unwrap();
    let mut steps = 0;
    let summary = sim
        .run(|w| {
            steps += 1;
            if step(w) == 5 {
                stop.request_stop("test");
            }
        })
        .unwrap();
    assert_eq!(steps, 5, "no step after the request");
    assert_eq!(summary["interrupted"], true, "{summary}");
    assert_eq!(summary["interrupted_by"], "test", "{summary}");

    let rec = read_recording(&path).unwrap();
    assert!(rec.truncated.is_none(), "{:?}", rec.truncated);
    let steps: Vec<u64> = rec.frames.iter().map(|f| f.step).collect();
    assert_eq!(steps, [0, 1, 2, 3, 4, 5]);
    let record = rec
        .metadata_records
        .iter()
        .find(|m| m.name == INTERRUPTED_METADATA_NAME)
        .expect("interrupted record");
    assert_eq!(record.entries["reason"], "test");
    let recorded: Value = serde_json::from_str(rec.summary_json.as_deref().unwrap()).unwrap();
    assert_eq!(recorded["interrupted"], true);
}

#[test]
fn a_run_that_ends_normally_is_not_marked_interrupted() {
    let path = tmp("complete.mcap");
    let stop = StopFlag::new();
    let options = RunOptions {
        record: Some(path.clone()),
        stop: Some(stop.clone()),
        ..Default::default()
    };
    let summary = run_scene(&packing(), &options, &NoProgress).unwrap();
    assert_eq!(summary.get("interrupted"), None, "{summary}");
    // a request after the end changes nothing
    stop.request_stop("late");
    let rec = read_recording(&path).unwrap();
    assert!(rec.truncated.is_none());
    assert!(
        rec.metadata_records
            .iter()
            .all(|m| m.name != INTERRUPTED_METADATA_NAME)
    );
}

fn brownian_long() -> Scene {
    let path = format!(
        "{}/tests/data/brownian_long.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    load_scene(path.as_ref(), &Default::default()).unwrap()
}

#[test]
fn a_stop_before_the_run_leaves_replicate_0_at_step_0_and_starts_no_other() {
    let stop = StopFlag::new();
    stop.request_stop("before");
    let options = RunOptions {
        stop: Some(stop),
        ..Default::default()
    };
    let summary = run_scene(&brownian_long(), &options, &NoProgress).unwrap();
    assert_eq!(summary["interrupted_by"], "before", "{summary}");
    assert_eq!(summary["runs"], 1, "{summary}");
    assert_eq!(summary["runs_requested"], 4, "{summary}");
    assert_eq!(summary["steps"], 0, "{summary}");
}

#[test]
fn a_stop_during_an_ensemble_stops_every_replicate() {
    let path = tmp("ensemble.mcap");
    let stop = StopFlag::new();
    let options = RunOptions {
        record: Some(path.clone()),
        stop: Some(stop.clone()),
        ..Default::default()
    };
    let timer = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(500));
            stop.request_stop("timer");
        })
    };
    let start = Instant::now();
    // 4 replicates of 10^7 steps each: minutes, unless every replicate stops
    let summary = run_scene(&brownian_long(), &options, &NoProgress).unwrap();
    timer.join().unwrap();
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "{:?}",
        start.elapsed()
    );
    assert_eq!(summary["interrupted_by"], "timer", "{summary}");
    assert!(summary["steps"].as_u64().unwrap() < 10_000_000, "{summary}");
    let rec = read_recording(&path).unwrap();
    assert!(rec.truncated.is_none());
    let recorded: Value = serde_json::from_str(rec.summary_json.as_deref().unwrap()).unwrap();
    assert_eq!(recorded["interrupted_by"], "timer");
}

#[test]
fn a_write_failure_stops_the_run_at_that_step_and_keeps_what_was_written_readable() {
    let data = Arc::new(Mutex::new(Cursor::new(Vec::new())));
    let sink = FullDisk {
        data: data.clone(),
        limit: 40_000,
    };
    let name = Path::new("/full/disk.mcap");
    let writer =
        RecordingWriter::from_sink(name, Box::new(sink), &RecordingMetadata::default()).unwrap();
    let mut sim = Simulation::from_scene(&packing(), RunOptions::default()).unwrap();
    sim.app.world.insert_resource(Recorder {
        writer: Some(writer),
        every: 1,
        error: None,
        last_step: None,
    });
    let mut last = 0;
    let err = sim.run(|w| last = step(w)).unwrap_err();
    let message = err.to_string();
    assert!(message.contains("/full/disk.mcap"), "{message}");
    assert!(message.contains("No space left on device"), "{message}");
    assert!(
        message.contains(&format!("frame at step {last}")),
        "stopped at step {last}, after the failing frame: {message}"
    );
    assert!(matches!(err.cause(), SimError::RecordWrite(_)), "{err:?}");
    let summary = err.partial_summary().expect("partial summary").clone();
    assert_eq!(summary["interrupted"], true, "{summary}");
    let steps =
        summary["compression_steps"].as_u64().unwrap() + summary["failed_steps"].as_u64().unwrap();
    assert_eq!(steps, last, "{summary}");
    assert!(
        summary["run_error"]
            .as_str()
            .is_some_and(|e| e.contains("No space left")),
        "{summary}"
    );
    assert!(last >= 1, "the limit leaves room for a few frames");

    let bytes = data.lock().unwrap().get_ref().clone();
    assert!(bytes.len() as u64 <= 40_000);
    let rec = read_recording_bytes(&bytes).unwrap();
    assert!(!rec.frames.is_empty());
    assert!(rec.frames.last().unwrap().step < last);
}
