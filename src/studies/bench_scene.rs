//! `magsep bench packing`'s scene rows through the scene pipeline users run.
//!
//! The rows time the shipped scenes `scenes/spheres_500.toml` and `scenes/superballs_750.toml`
//! (their texts are compiled in) parsed, spawned and run by `run_scene`, the driver of
//! `magsep run`, with no recording and no progress output; `--quick` only changes the particle
//! count (and the superballs' step limit). The superball row runs a fixed number of
//! compression steps (the whole run to jamming takes minutes) on 1 and 2 rayon threads. A separate dense loop once
//! drifted from what users run; timing the scene itself keeps the bench and `magsep run` on
//! one code path.

use std::time::Instant;

use serde_json::Value;

use super::bench::BenchError;
use crate::scene::{NoProgress, Registry, RunOptions, parse_scene};
use crate::sim::run_scene;

/// The text of the shipped scene `scenes/spheres_500.toml`.
pub const SPHERES_500: &str = include_str!("../../scenes/spheres_500.toml");

/// The shipped sphere scene with `n` particles instead of 500.
///
/// # Errors
/// [`BenchError::Runtime`] when the scene no longer names its count as `count = 500`.
pub fn spheres_scene_text(n: usize) -> Result<String, BenchError> {
    let key = "count = 500";
    if !SPHERES_500.contains(key) {
        return Err(BenchError::Runtime(format!(
            "scenes/spheres_500.toml has no `{key}` line to scale"
        )));
    }
    Ok(SPHERES_500.replacen(key, &format!("count = {n}"), 1))
}

/// Run the sphere scene with `n` particles as `magsep run --threads 1` does; returns the
/// run's summary and the wall time of spawning and running \[s\].
///
/// # Errors
/// [`BenchError::Runtime`] for a scene or run error.
pub fn spheres_scene_run(n: usize) -> Result<(Value, f64), BenchError> {
    let text = spheres_scene_text(n)?;
    let scene = parse_scene(&text, &Registry::default())
        .map_err(|e| BenchError::Runtime(format!("spheres scene: {e}")))?;
    let options = RunOptions {
        single_threaded: true,
        ..Default::default()
    };
    let t0 = Instant::now();
    let summary = run_scene(&scene, &options, &NoProgress)
        .map_err(|e| BenchError::Runtime(format!("spheres scene: {e}")))?;
    Ok((summary, t0.elapsed().as_secs_f64()))
}

/// The text of the shipped scene `scenes/superballs_750.toml`.
pub const SUPERBALLS_750: &str = include_str!("../../scenes/superballs_750.toml");

/// The shipped superball scene with `n` particles, stopped after `steps` compression steps.
///
/// # Errors
/// [`BenchError::Runtime`] when the scene no longer names its count as `count = 750` or has no
/// `[packing]` section.
pub fn superballs_scene_text(n: usize, steps: u64) -> Result<String, BenchError> {
    let (key, section) = ("count = 750", "[packing]");
    if !SUPERBALLS_750.contains(key) || !SUPERBALLS_750.contains(section) {
        return Err(BenchError::Runtime(format!(
            "scenes/superballs_750.toml has no `{key}` line or `{section}` section"
        )));
    }
    Ok(SUPERBALLS_750
        .replacen(key, &format!("count = {n}"), 1)
        .replacen(
            section,
            &format!("{section}\nmax_compression_steps = {steps}"),
            1,
        ))
}

/// Run the superball scene (`n` particles, `steps` compression steps) as `magsep run
/// --threads <threads>` does; returns the summary and the wall time \[s\].
///
/// # Errors
/// [`BenchError::Runtime`] for a scene, thread-pool or run error.
pub fn superballs_scene_run(
    n: usize,
    steps: u64,
    threads: usize,
) -> Result<(Value, f64), BenchError> {
    let text = superballs_scene_text(n, steps)?;
    let scene = parse_scene(&text, &Registry::default())
        .map_err(|e| BenchError::Runtime(format!("superball scene: {e}")))?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| BenchError::Runtime(format!("thread pool: {e}")))?;
    let options = RunOptions {
        single_threaded: true,
        ..Default::default()
    };
    let t0 = Instant::now();
    let summary = pool
        .install(|| run_scene(&scene, &options, &NoProgress))
        .map_err(|e| BenchError::Runtime(format!("superball scene: {e}")))?;
    Ok((summary, t0.elapsed().as_secs_f64()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaled_scene_parses_with_the_count() {
        let scene = parse_scene(&spheres_scene_text(40).unwrap(), &Registry::default()).unwrap();
        assert_eq!(scene.total_particles(), 40);
    }

    #[test]
    fn superball_rows_run_the_same_on_one_and_two_threads() {
        let (one, _) = superballs_scene_run(30, 20, 1).unwrap();
        let (two, _) = superballs_scene_run(30, 20, 2).unwrap();
        assert_eq!(one["compression_steps"], 20);
        assert!(one["attempts"].as_u64().unwrap() > 0);
        for key in ["packing_fraction", "attempts", "contact_evaluations"] {
            assert_eq!(one[key], two[key], "{key}");
        }
    }
}
