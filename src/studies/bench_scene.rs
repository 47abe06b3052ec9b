//! `magsep bench packing`'s sphere row through the scene pipeline users run.
//!
//! The row times the shipped scene `scenes/spheres_500.toml` (its text is compiled in) parsed,
//! spawned and run by `run_scene`, the driver of `magsep run`, with no recording and no
//! progress output; `--quick` only changes the particle count. A separate dense loop once
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaled_scene_parses_with_the_count() {
        let scene = parse_scene(&spheres_scene_text(40).unwrap(), &Registry::default()).unwrap();
        assert_eq!(scene.total_particles(), 40);
    }
}
