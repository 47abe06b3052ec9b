//! `magsep bench overhead` and `magsep bench recording`: what the framework and the recorder
//! cost on top of the physics (timings, never assertions).
//!
//! * [`bench_overhead`]: wall time per step of a simple particle-fluid scene (N = 1, 10, 100,
//!   1000 PVC spheres of 5 mm on a 10 mm grid in the levitation rig of
//!   `scenes/levitation_single.toml`, history window 0.2 s, collisions on) through
//!   [`Simulation::step`], with the executor the driver picks (`auto`) and with bevy's
//!   multi-threaded executor for comparison. Rows `framework_step`: `particles`, `executor`,
//!   `steps`, `us_per_step`, `us_per_particle_step` (best of 3 repetitions).
//! * [`bench_recording`]: for each pipeline's representative shipped scene, the same steps with
//!   and without the scene's own recording (`record.every`, written to a temporary file), side
//!   by side in 5 rounds (quick: 1) that alternate which run goes first. Rows
//!   `recording_overhead`: `wall_ratio`, the median over the rounds of recorded / plain wall
//!   time (building the simulation, opening the file, the first and last frame and closing the
//!   file included; `build_s` the building alone; `wall_ratio_min`,
//!   `wall_ratio_max` its spread), the median wall times, the time spent writing frames
//!   (measured inside the recorder, [`RecordTiming`]; per frame the median over the rounds:
//!   `record_s_per_frame` in wall time, `record_cpu_s_per_frame` in the simulation thread's CPU
//!   time, which a loaded machine's preemptions do not lengthen; `record_s_max_frame` and
//!   `max_frame_step` the longest single frame) and closing the file, and
//!   `overhead_fraction`: that time over
//!   the time of the steps, extrapolated to the scene's full run (`frames_full_run` frames:
//!   one every `every` steps plus the first and the last) where the pipeline knows its length
//!   (else over the timed window): `frames_overhead_fraction` counts the frames only,
//!   `cpu_overhead_fraction` the frames' CPU time (on the thread that records) over the CPU
//!   time, all threads, that the same steps take in the rounds that do not record,
//!   `overhead_fraction` also the one-off closing of the file (`finish_s`: the summary
//!   record, the summary section and the footer).

use std::path::PathBuf;
use std::time::Instant;

use magsep_plugins::recorder::{RecordTiming, process_cpu_seconds, record_now};
use serde_json::json;

use crate::scene::{ExecutorChoice, RecordEvery, Registry, Scene, parse_scene};
use crate::sim::Simulation;
use crate::studies::bench::{BenchError, emit};

/// `n` (at most 1000) spheres of `scenes/levitation_single.toml` on a 10 mm grid in its tank.
pub fn sphere_grid_scene(n: usize) -> String {
    let k = (1..=10).find(|k| k * k * k >= n).unwrap_or(10);
    let points: Vec<String> = (0..n.min(1000))
        .map(|i| {
            let (a, b, c) = (i % k, (i / k) % k, i / (k * k));
            format!(
                "[{}, {}, {}]",
                0.03 + 0.01 * a as f64,
                0.03 + 0.01 * b as f64,
                0.0075 + 0.01 * c as f64
            )
        })
        .collect();
    format!(
        r#"
[simulation]
pipeline = "particle_fluid"
seed = 1
[particle_fluid]
time_step = 1e-3
duration = 1000.0
history = {{ kind = "window", window = 0.2 }}
observe_every = 10
[liquid]
density = 1403.0
viscosity = 5.54e-3
susceptibility = 7e-4
[magnet]
kind = "bottom"
surface_field = 422e3
pole_size = 0.1181
half_height = 0.075
[container]
kind = "tank"
edges = [0.15, 0.15, 0.15]
[[particles]]
count = {count}
shape = {{ kind = "sphere", radius = 2.5e-3 }}
density = 1434.0
placement = {{ kind = "points", positions = [{points}] }}
"#,
        count = n.min(1000),
        points = points.join(", ")
    )
}

fn runtime(what: &str) -> impl Fn(String) -> BenchError + '_ {
    move |e| BenchError::Runtime(format!("{what}: {e}"))
}

fn threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Best wall time per step over `reps` runs of `steps` steps (after 20 untimed steps).
fn step_time(scene: &Scene, executor: ExecutorChoice, steps: u64) -> Result<f64, BenchError> {
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let mut sim = Simulation::builder(scene)
            .executor(executor)
            .build()
            .map_err(|e| runtime("overhead scene")(e.to_string()))?;
        for _ in 0..20 {
            sim.step();
        }
        let t0 = Instant::now();
        for _ in 0..steps {
            sim.step();
        }
        best = best.min(t0.elapsed().as_secs_f64() / steps as f64);
    }
    Ok(best)
}

/// `magsep bench overhead [--json] [--quick]`: rows `framework_step` (module docs).
///
/// # Errors
/// [`BenchError`] when a scene cannot be built or a row not written.
pub fn bench_overhead(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let mut rows = Vec::new();
    let budget: u64 = if quick { 20_000 } else { 200_000 };
    for n in [1usize, 10, 100, 1000] {
        let scene = parse_scene(&sphere_grid_scene(n), &Registry::default())
            .map_err(|e| runtime("overhead scene")(e.to_string()))?;
        let steps = (budget / n as u64).clamp(200, 20_000);
        for (name, executor) in [
            ("auto", ExecutorChoice::Auto),
            ("multi_threaded", ExecutorChoice::MultiThreaded),
        ] {
            let picked = if executor.multi_threaded(n) {
                "multi_threaded"
            } else {
                "single_threaded"
            };
            let t = step_time(&scene, executor, steps)?;
            emit(
                &mut rows,
                as_json,
                json!({"name": "framework_step", "particles": n, "executor": name,
                       "executor_used": picked, "threads": threads(), "steps": steps,
                       "us_per_step": t * 1e6, "us_per_particle_step": t * 1e6 / n as f64,
                       "steps_per_s": 1.0 / t}),
            )?;
        }
    }
    Ok(())
}

/// The representative shipped scene of each pipeline and the steps timed (quick: fewer).
const RECORDING_SCENES: &[(&str, &str, u64, u64)] = &[
    (
        "scenes/levitation_single.toml",
        include_str!("../../scenes/levitation_single.toml"),
        8000,
        2000,
    ),
    (
        "scenes/mds_case1a.toml",
        include_str!("../../scenes/mds_case1a.toml"),
        100,
        0,
    ),
    (
        "scenes/brownian_concentrated.toml",
        include_str!("../../scenes/brownian_concentrated.toml"),
        300,
        100,
    ),
    (
        "scenes/spheres_500.toml",
        include_str!("../../scenes/spheres_500.toml"),
        200,
        100,
    ),
];

/// One timed window: wall time of building the simulation and `steps` steps (with opening the
/// recording, the first and last frame and closing the recording when `record` is set), and
/// the recorder's own time.
struct Window {
    wall_s: f64,
    /// Building the simulation (in `wall_s`).
    build_s: f64,
    steps: u64,
    record_s: f64,
    /// The recording thread's CPU time in the recorder (in `record_s`'s stead where the
    /// platform does not say).
    record_cpu_s: f64,
    /// The process's CPU time over the steps and frames (the wall time where the platform
    /// does not say).
    stepping_cpu_s: f64,
    frames: u64,
    /// The longest frame \[s\] and its step.
    max_frame: (f64, u64),
    finish_s: f64,
    bytes: u64,
}

fn window(scene: &Scene, steps: u64, record: Option<&PathBuf>) -> Result<Window, BenchError> {
    // the window opens with building the simulation, which opens the recording
    let t0 = Instant::now();
    // as `magsep run` does
    let mut b = Simulation::builder(scene).forces_unread(true);
    if let Some(path) = record {
        b = b.record(path.clone());
    }
    let mut sim = b
        .build()
        .map_err(|e| runtime("recording scene")(e.to_string()))?;
    let build_s = t0.elapsed().as_secs_f64();
    sim.app.world.insert_resource(RecordTiming::default());
    let (w0, c0) = (Instant::now(), process_cpu_seconds());
    record_now(&mut sim.app.world);
    let mut done = 0;
    while done < steps && !sim.is_finished() {
        sim.step();
        done += 1;
    }
    record_now(&mut sim.app.world);
    let stepping_cpu_s = match (c0, process_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => w0.elapsed().as_secs_f64(),
    };
    let t1 = Instant::now();
    let summary = sim.summary();
    sim.finish_recording(&summary)
        .map_err(|e| runtime("closing the recording")(e.to_string()))?;
    let finish_s = t1.elapsed().as_secs_f64();
    let timing = sim
        .app
        .world
        .get_resource::<RecordTiming>()
        .copied()
        .unwrap_or_default();
    let bytes = record
        .and_then(|p| std::fs::metadata(p).ok())
        .map_or(0, |m| m.len());
    Ok(Window {
        wall_s: t0.elapsed().as_secs_f64(),
        build_s,
        steps: done,
        record_s: timing.seconds,
        record_cpu_s: timing.cpu_seconds,
        stepping_cpu_s,
        frames: timing.frames,
        max_frame: (timing.max_seconds, timing.max_step),
        finish_s: if record.is_some() { finish_s } else { 0.0 },
        bytes,
    })
}

/// Median of `v` (not empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Rounds of the side-by-side comparison (quick: one).
fn recording_rounds(quick: bool) -> usize {
    if quick { 1 } else { 5 }
}

/// `magsep bench recording [--json] [--quick]`: rows `recording_overhead` (module docs).
///
/// # Errors
/// [`BenchError`] when a scene cannot be run or recorded.
pub fn bench_recording(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let mut rows = Vec::new();
    let registry = Registry::default();
    let path = std::env::temp_dir().join(format!(
        "magsep-bench-recording-{}.mcap",
        std::process::id()
    ));
    for &(name, text, full, short) in RECORDING_SCENES {
        let steps = if quick { short } else { full };
        if steps == 0 {
            continue;
        }
        let scene = parse_scene(text, &registry).map_err(|e| runtime(name)(e.to_string()))?;
        // rounds alternate which run goes first, so that a drift of the machine's load
        // weighs on both
        let mut pairs = Vec::new();
        for round in 0..recording_rounds(quick) {
            let (plain, rec) = if round % 2 == 0 {
                let plain = window(&scene, steps, None)?;
                (plain, window(&scene, steps, Some(&path))?)
            } else {
                let rec = window(&scene, steps, Some(&path))?;
                (window(&scene, steps, None)?, rec)
            };
            let _ = std::fs::remove_file(&path);
            pairs.push((plain, rec));
        }
        let ratios: Vec<f64> = pairs
            .iter()
            .map(|(p, r)| r.wall_s / p.wall_s.max(1e-12))
            .collect();
        let wall_ratio = median(ratios.clone());
        let sum = |f: fn(&Window) -> f64| pairs.iter().map(|(_, r)| f(r)).sum::<f64>();
        let rec = Window {
            wall_s: sum(|w| w.wall_s),
            build_s: sum(|w| w.build_s),
            steps: pairs.iter().map(|(_, r)| r.steps).sum(),
            record_s: sum(|w| w.record_s),
            record_cpu_s: sum(|w| w.record_cpu_s),
            stepping_cpu_s: sum(|w| w.stepping_cpu_s),
            frames: pairs.iter().map(|(_, r)| r.frames).sum(),
            max_frame: pairs
                .iter()
                .map(|(_, r)| r.max_frame)
                .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a }),
            finish_s: sum(|w| w.finish_s) / pairs.len() as f64,
            bytes: pairs.last().map_or(0, |(_, r)| r.bytes),
        };
        let plain_s = median(pairs.iter().map(|(p, _)| p.wall_s).collect());
        let rec_s = median(pairs.iter().map(|(_, r)| r.wall_s).collect());
        let every = {
            let sim = Simulation::builder(&scene)
                .build()
                .map_err(|e| runtime(name)(e.to_string()))?;
            sim.app
                .world
                .get_resource::<RecordEvery>()
                .map_or(100, |r| r.0)
        };
        let rounds = pairs.len() as f64;
        let recording_s = rec.record_s + rec.finish_s * rounds;
        let stepping_s = (rec.wall_s - rec.build_s - recording_s).max(1e-12);
        let step_s = stepping_s / rec.steps.max(1) as f64;
        // per frame: the median over the rounds, so that one round's preemption on a loaded
        // machine does not carry the figure (the longest frame is reported apart)
        let per_frame = |f: fn(&Window) -> f64| {
            median(
                pairs
                    .iter()
                    .map(|(_, r)| f(r) / r.frames.max(1) as f64)
                    .collect(),
            )
        };
        let frame_s = per_frame(|w| w.record_s);
        let frame_cpu_s = per_frame(|w| w.record_cpu_s);
        let total = scene.pipeline.as_ref().and_then(|p| p.total_steps(&scene));
        let window_fraction = recording_s / stepping_s;
        let frames_per_window = rec.frames as f64 / rounds;
        let window_steps = (rec.steps as f64 / rounds).max(1.0);
        // (frames over the scene's full run, their cost, that cost's CPU time) over the run
        let (frames_full, run_s) = match total {
            Some(t) if t > 0 => (t / every.max(1) + 2, t as f64 * step_s),
            _ => (frames_per_window as u64, window_steps * step_s),
        };
        let frames_fraction = frames_full as f64 * frame_s / run_s;
        // the frames' CPU time against the CPU time per step of the runs that do not record
        // (all their threads: a recorded run's would include the writer thread's)
        let plain_steps: u64 = pairs.iter().map(|(p, _)| p.steps).sum();
        let plain_cpu: f64 = pairs.iter().map(|(p, _)| p.stepping_cpu_s).sum();
        let run_cpu_s = run_s / step_s * plain_cpu.max(1e-12) / plain_steps.max(1) as f64;
        let cpu_fraction = frames_full as f64 * frame_cpu_s / run_cpu_s;
        let fraction_full = (frames_full as f64 * frame_s + rec.finish_s) / run_s;
        emit(
            &mut rows,
            as_json,
            json!({"name": "recording_overhead", "scene": name,
                   "pipeline": scene.pipeline.as_ref().map(|p| p.name()),
                   "threads": threads(), "every": every,
                   "steps": rec.steps / pairs.len() as u64, "rounds": pairs.len(),
                   "wall_plain_s": plain_s, "wall_recorded_s": rec_s,
                   "build_s": rec.build_s / rounds,
                   "wall_ratio": wall_ratio,
                   "wall_ratio_min": ratios.iter().copied().fold(f64::INFINITY, f64::min),
                   "wall_ratio_max": ratios.iter().copied().fold(0.0, f64::max),
                   "frames": rec.frames / pairs.len() as u64, "bytes": rec.bytes,
                   "record_s_per_frame": frame_s,
                   "record_cpu_s_per_frame": frame_cpu_s,
                   "record_s_max_frame": rec.max_frame.0, "max_frame_step": rec.max_frame.1,
                   "finish_s": rec.finish_s,
                   "step_s": step_s,
                   "window_overhead_fraction": window_fraction,
                   "full_run_steps": total, "frames_full_run": frames_full,
                   "frames_overhead_fraction": frames_fraction,
                   "cpu_overhead_fraction": cpu_fraction,
                   "overhead_fraction": fraction_full}),
        )?;
    }
    Ok(())
}
