//! Shared helpers of the tests: scene texts and runs.

#![allow(dead_code)]

use langevin_trap::registry;
use magsep::scene::{Scene, parse_scene};
use magsep::serde_json::Value;
use magsep::{RunOptions, Simulation};

/// A `langevin_trap` scene: `count` spheres of radius 0.5 µm, k = 1e-6 N/m, water at
/// 293 K (γ/k = 9.4 ms), `steps` steps of `dt` [s], samples every `every` steps; `extra` is
/// appended to `[trap]`.
pub fn trap_scene(count: u64, dt: f64, steps: u64, every: u64, extra: &str) -> String {
    format!(
        r#"
[simulation]
pipeline = "langevin_trap"
seed = 7

[trap]
stiffness = 1e-6
centre = [1e-6, -2e-6, 0.5e-6]
temperature = 293.0
viscosity = 1.0e-3
time_step = {dt:e}
duration = {duration:e}
record_every = {every}
{extra}

[[particles]]
count = {count}
shape = {{ kind = "sphere", radius = 0.5e-6 }}
start = [1.2e-6, -2e-6, 0.5e-6]
"#,
        duration = dt * steps as f64
    )
}

/// Parse `text` with the built-in pipelines and `langevin_trap`.
pub fn parse(text: &str) -> Scene {
    parse_scene(text, &registry()).unwrap_or_else(|e| panic!("scene invalid:\n{e}"))
}

/// Run `scene` with `options` to the end; the summary.
pub fn run(scene: &Scene, options: RunOptions) -> Value {
    Simulation::from_scene(scene, options)
        .and_then(|mut s| s.run(|_| {}))
        .unwrap_or_else(|e| panic!("run failed: {e}"))
}

/// `summary` without its wall time (which differs between runs).
pub fn without_wall_time(mut summary: Value) -> Value {
    if let Some(m) = summary.as_object_mut() {
        m.remove("wall_time_s");
    }
    summary
}

/// A fresh directory under the target's test directory.
pub fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("langevin_trap")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}
