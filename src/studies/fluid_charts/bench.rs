//! `magsep bench particle-fluid`: timings of the particle-fluid pipeline (never assertions).
//!
//! One `fn` per measurement, each printing its rows through [`emit`] (one JSON object per
//! line with `--json`: keys `name`, `threads` and the figures; a readable line otherwise):
//!
//! * [`history_rows`]: seconds per particle-step of the Basset history (one
//!   `past_integral` + one `push`, i.e. what a step costs) at step n = 10³, 10⁴, 10⁵ for full
//!   memory and for the thesis's window (0.35 s at Δt = 0.9 ms = 389 steps, with the
//!   exponential tail), for one particle and per particle for 1000 particles sharing a plan;
//! * [`pipeline_row`]: particle-steps per second of the whole pipeline on
//!   `scenes/levitation_single.toml` (`load_scene` + [`Simulation`], default executor);
//! * [`collision_bed_row`]: particle-steps per second of the pipeline with collisions in a
//!   dense settling bed of 10⁴ glass spheres (1 mm, in water, no magnet) on the floor of a
//!   periodic channel: first while the bed forms, then once it rests (every particle in
//!   sustained contact);
//! * the spheroid rows of [`super::bench_spheroids`]: flakes of w = 0.5 and 0.1 against
//!   spheres in the thesis's channel, with and without collisions, and the cost of one
//!   spheroid contact query.
//!
//! History timings are minima over repetitions (the machine is shared), single-threaded.

use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
use serde_json::{Value, json};

use super::levitation::runtime;
use crate::scene::{Registry, load_scene, parse_scene};
use crate::sim::{RunOptions, Simulation};
use crate::studies::bench::{BenchError, emit};

/// Time step of the history timings (the thesis's many-particle runs) [s].
pub(crate) const BENCH_DT: f64 = 0.9e-3;
/// Window of the history timings: 0.35 s at 0.9 ms = 389 steps ([T002 §2.5.3]).
pub(crate) const BENCH_WINDOW: HistoryKernel = HistoryKernel::Window {
    steps: 389,
    tail: true,
};
/// Largest particles × stored intervals held in memory by a full-memory timing (24 bytes
/// each, doubled by the buffer's growth: ~500 MB).
const MAX_STORED: usize = 10_000_000;

/// One history timing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HistoryTiming {
    /// Wall time per particle-step at step n [s] (minimum over repetitions).
    pub(crate) seconds_per_particle_step: f64,
    /// Timed steps per repetition.
    pub(crate) timed_steps: usize,
    /// Repetitions.
    pub(crate) repetitions: usize,
}

/// A smooth synthetic slip sample at step `k` [m/s].
fn slip(k: usize) -> DVec3 {
    let t = k as f64 * BENCH_DT;
    DVec3::new((3.0 * t).sin(), (1.7 * t).cos() - 1.0, 0.1 * t)
}

/// Wall time of one history step (`past_integral` + `push`) at step `n` for `particles`
/// particles sharing one plan (`kernel` at [`BENCH_DT`]): the states are filled with n − m
/// pushes, then m evaluated steps are timed (m ≈ n/10, fewer when the work would exceed
/// `budget` kernel terms), repeated for at least `min_time` [s]; the minimum is kept.
///
/// # Errors
/// An invalid kernel.
pub(crate) fn history_step_time(
    kernel: HistoryKernel,
    n: usize,
    particles: usize,
    budget: f64,
    min_time: f64,
) -> Result<HistoryTiming, BenchError> {
    let plan = HistoryPlan::new(BENCH_DT, kernel).map_err(runtime)?;
    let terms = match kernel {
        HistoryKernel::Full => n as f64,
        HistoryKernel::Window { steps, .. } => (steps + 10) as f64,
    };
    let by_budget = (budget / (terms * particles.max(1) as f64)).floor() as usize;
    let m = (n / 10).min(by_budget).clamp(1, 1000).min(n.max(1));
    let mut states: Vec<HistoryState> = (0..particles.max(1))
        .map(|p| HistoryState::new(DVec3::splat(p as f64 * 1e-3), 0.0))
        .collect();
    for k in 1..=n - m {
        let w = slip(k);
        for (p, s) in states.iter_mut().enumerate() {
            s.push(&plan, w + DVec3::splat(p as f64 * 1e-3));
        }
    }
    let t_next = (n - m + 1) as f64 * BENCH_DT;
    let (mut best, mut total, mut reps) = (f64::INFINITY, 0.0, 0usize);
    while reps < 2 || total < min_time {
        let mut work = states.clone();
        let start = Instant::now();
        let mut acc = DVec3::ZERO;
        for j in 0..m {
            let w = slip(n - m + 1 + j);
            let t = t_next + j as f64 * BENCH_DT;
            for s in work.iter_mut() {
                acc += s.past_integral(&plan, t);
                s.push(&plan, w);
            }
        }
        std::hint::black_box(acc);
        let el = start.elapsed().as_secs_f64();
        best = best.min(el);
        total += el;
        reps += 1;
        if reps >= 50 {
            break;
        }
    }
    Ok(HistoryTiming {
        seconds_per_particle_step: best / (m * particles.max(1)) as f64,
        timed_steps: m,
        repetitions: reps,
    })
}

/// Name of a history kernel in rows.
pub(crate) fn kernel_name(kernel: HistoryKernel) -> String {
    match kernel {
        HistoryKernel::Full => "full".into(),
        HistoryKernel::Window { steps, tail: true } => format!("window_{steps}_tail"),
        HistoryKernel::Window { steps, tail: false } => format!("window_{steps}_no_tail"),
    }
}

/// `magsep bench particle-fluid [--json] [--quick]`: the rows listed in the module docs.
///
/// # Errors
/// [`BenchError::Runtime`] when the scene cannot be loaded or run.
pub fn bench_particle_fluid(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let mut rows = Vec::new();
    history_rows(&mut rows, as_json, quick)?;
    pipeline_row(&mut rows, as_json, quick)?;
    collision_bed_row(&mut rows, as_json, quick)?;
    super::bench_spheroids::flake_rows(&mut rows, as_json, quick)?;
    super::bench_spheroids::contact_rows(&mut rows, as_json, quick)?;
    Ok(())
}

/// `magsep bench settling-bed [--json] [--quick]`: only the settling-bed rows.
///
/// # Errors
/// [`BenchError::Runtime`] when the scene cannot be built.
pub fn bench_settling_bed(as_json: bool, quick: bool) -> Result<(), BenchError> {
    collision_bed_row(&mut Vec::new(), as_json, quick)
}

/// History cost per particle-step for full memory and the 389-step window + tail.
fn history_rows(rows: &mut Vec<Value>, as_json: bool, quick: bool) -> Result<(), BenchError> {
    let (sizes, many): (&[usize], usize) = if quick {
        (&[100, 1_000], 100)
    } else {
        (&[1_000, 10_000, 100_000], 1000)
    };
    let (budget, min_time) = if quick { (2e6, 0.005) } else { (2e8, 0.2) };
    for particles in [1usize, many] {
        for kernel in [HistoryKernel::Full, BENCH_WINDOW] {
            for &n in sizes {
                let name = format!("history_step_{}", kernel_name(kernel));
                if kernel == HistoryKernel::Full && particles * n > MAX_STORED {
                    emit(
                        rows,
                        as_json,
                        json!({"name": name, "threads": 1, "particles": particles, "n": n,
                               "skipped": format!("{} stored intervals exceed the {MAX_STORED} memory cap", particles * n)}),
                    )?;
                    continue;
                }
                let t = history_step_time(kernel, n, particles, budget, min_time)?;
                emit(
                    rows,
                    as_json,
                    json!({"name": name, "threads": 1, "particles": particles, "n": n,
                           "dt": BENCH_DT,
                           "seconds_per_particle_step": t.seconds_per_particle_step,
                           "particle_steps_per_s": 1.0 / t.seconds_per_particle_step,
                           "timed_steps": t.timed_steps, "repetitions": t.repetitions}),
                )?;
            }
        }
    }
    Ok(())
}

/// Particle-steps per second of the whole pipeline on `scenes/levitation_single.toml`.
fn pipeline_row(rows: &mut Vec<Value>, as_json: bool, quick: bool) -> Result<(), BenchError> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/levitation_single.toml");
    let registry = Registry::default();
    let scene = if path.exists() {
        load_scene(&path, &registry)
    } else {
        parse_scene(
            include_str!("../../../scenes/levitation_single.toml"),
            &registry,
        )
    }
    .map_err(|e| BenchError::Runtime(format!("{}: {e}", path.display())))?;
    // the default (multi-threaded) executor: the pipeline's parallel queries need bevy's
    // compute task pool, which the single-threaded executor does not set up
    let mut sim = Simulation::from_scene(&scene, RunOptions::default())
        .map_err(|e| BenchError::Runtime(format!("bench simulation: {e}")))?;
    let max_steps: u64 = if quick { 300 } else { u64::MAX };
    let start = Instant::now();
    let mut steps = 0u64;
    while !sim.is_finished() && steps < max_steps {
        sim.step();
        steps += 1;
    }
    let wall = start.elapsed().as_secs_f64();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let summary = sim.summary();
    let particles = summary["particles"].as_u64().unwrap_or(1);
    // context, not an assertion: the pipeline's levitation time of the sphere (null if the run
    // was cut short before it settled)
    let levitation_time = summary["particle_details"][0]["levitation_time"].clone();
    emit(
        rows,
        as_json,
        json!({"name": "particle_fluid_pipeline_levitation_single", "threads": threads,
               "executor": "multi_threaded (bevy default pool)",
               "scene": "scenes/levitation_single.toml", "particles": particles,
               "steps": steps, "wall_time_s": wall,
               "particle_steps_per_s": (particles * steps) as f64 / wall.max(1e-12),
               "seconds_per_step": wall / steps.max(1) as f64,
               "levitation_time_s": levitation_time}),
    )?;
    Ok(())
}

/// A dense settling bed: `n` 1 mm glass spheres (2500 kg/m³) in water, dropped from a box of
/// volume fraction 0.3 onto the floor of a channel periodic in x and y, all terms on (history
/// window 0.05 s), collisions with the thesis's wet restitution.
fn settling_bed_scene(n: u64) -> String {
    // about 10 layers: side² · 10 d · 0.6 = n V_p
    let d: f64 = 1e-3;
    let side = ((n as f64) * std::f64::consts::PI * d.powi(3) / 6.0 / (0.6 * 10.0 * d)).sqrt();
    let top = (n as f64) * std::f64::consts::PI * d.powi(3) / 6.0 / (0.3 * side * side);
    format!(
        r#"
[simulation]
pipeline = "particle_fluid"
[particle_fluid]
time_step = 1e-3
duration = 100.0
history = {{ kind = "window", window = 0.05 }}
observe_every = 1000000
[liquid]
density = 1000.0
viscosity = 1e-3
[container]
kind = "channel"
side = [{side}, {side}]
height = {height}
[[particles]]
count = {n}
shape = {{ kind = "sphere", radius = 0.5e-3 }}
density = 2500.0
placement = {{ kind = "box", min = [0.0005, 0.0005, 0.0005], max = [{m}, {m}, {top}] }}
"#,
        height = top + 2.0 * d,
        m = side - 0.0005,
        top = top + 0.0005,
    )
}

/// Particle-steps per second with collisions in a dense settling bed (10⁴ spheres; quick:
/// 10³), over the first steps (the bed forming) and over later steps (resting contacts).
fn collision_bed_row(rows: &mut Vec<Value>, as_json: bool, quick: bool) -> Result<(), BenchError> {
    let n: u64 = if quick { 1_000 } else { 10_000 };
    let scene = parse_scene(&settling_bed_scene(n), &Registry::default())
        .map_err(|e| BenchError::Runtime(format!("settling bed scene: {e}")))?;
    let mut sim = Simulation::from_scene(&scene, RunOptions::default())
        .map_err(|e| BenchError::Runtime(format!("bench simulation: {e}")))?;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let phases: &[(&str, u64)] = if quick {
        &[("forming", 50), ("resting", 50)]
    } else {
        &[("forming", 300), ("settling", 700), ("resting", 300)]
    };
    for (phase, steps) in phases {
        let start = Instant::now();
        for _ in 0..*steps {
            sim.step();
        }
        let wall = start.elapsed().as_secs_f64();
        let s = sim.summary();
        emit(
            rows,
            as_json,
            json!({"name": "particle_fluid_settling_bed", "phase": phase, "threads": threads,
                   "particles": n, "steps": steps, "simulated_time_s": s["simulated_time"],
                   "wall_time_s": wall,
                   "particle_steps_per_s": (n * steps) as f64 / wall.max(1e-12),
                   "collisions_so_far": s["collisions"]}),
        )?;
    }
    Ok(())
}
