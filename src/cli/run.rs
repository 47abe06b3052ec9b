//! `magsep run` and `magsep validate`.

use std::path::{Path, PathBuf};

use crate::scene::memory::{self, MemoryEstimate};
use crate::scene::{Progress, RunOptions, Scene, load_scene};
use crate::sim::{SimError, run_scene};
use indicatif::{ProgressBar, ProgressStyle};

use super::{CliError, Extensions};

/// Set the worker thread count of rayon (kernels) for this process.
pub fn set_threads(threads: Option<usize>) -> Result<bool, CliError> {
    if let Some(n) = threads {
        if n == 0 {
            return Err(CliError::input("--threads must be >= 1"));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| CliError::runtime(format!("thread pool: {e}")))?;
        return Ok(n == 1);
    }
    Ok(false)
}

fn load(ext: &Extensions, path: &Path) -> Result<Scene, CliError> {
    load_scene(path, &ext.registry)
        .map_err(|e| CliError::input(format!("{} is invalid:\n{e}", path.display())))
}

/// The scene's memory estimate, checked against the budget (exit 2 when over).
fn memory(
    scene: &Scene,
    path: &Path,
    budget_gib: Option<f64>,
) -> Result<(MemoryEstimate, u64), CliError> {
    let budget = memory::budget(budget_gib).map_err(CliError::input)?;
    let estimate = memory::check(scene, budget)
        .map_err(|e| CliError::input(format!("{} is invalid:\n{e}", path.display())))?;
    Ok((estimate, budget))
}

pub fn validate(ext: &Extensions, path: &Path, budget_gib: Option<f64>) -> Result<(), CliError> {
    let scene = load(ext, path)?;
    let (estimate, budget) = memory(&scene, path, budget_gib)?;
    println!(
        "{}",
        serde_json::json!({
            "valid": true,
            "scene": path.display().to_string(),
            "pipeline": scene.pipeline_name(),
            "particles": scene.total_particles(),
            "fibres": scene.fibres.len(),
            "memory_estimate_bytes": estimate.bytes.round() as u64,
            "memory_estimate": estimate.detail,
            "memory_budget_bytes": budget,
        })
    );
    Ok(())
}

/// A progress bar on stderr (a spinner until the total is known).
struct Bar(ProgressBar);

impl Progress for Bar {
    fn set_total(&self, steps: u64) {
        self.0.set_length(steps);
        self.0.set_style(
            ProgressStyle::with_template(
                "[{elapsed_precise}] {bar:40} {pos}/{len} steps ({eta} left) {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
    }
    fn advance(&self, steps: u64) {
        self.0.inc(steps);
    }
    fn message(&self, text: String) {
        self.0.set_message(text);
    }
}

pub fn run(
    ext: &Extensions,
    path: &Path,
    record: Option<PathBuf>,
    seed: Option<u64>,
    quiet: bool,
    threads: Option<usize>,
    budget_gib: Option<f64>,
) -> Result<(), CliError> {
    let single = set_threads(threads)?;
    let scene = load(ext, path)?;
    memory(&scene, path, budget_gib)?;
    let options = RunOptions {
        seed,
        record,
        single_threaded: single,
        plugins: ext.plugins.clone(),
        ..Default::default()
    };
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new_spinner()
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    let summary = run_scene(&scene, &options, &Bar(bar.clone())).map_err(|e| match e {
        // a scene that validates but cannot be spawned (a start region too small for its
        // particles, a start box inside a fibre) is bad input too
        SimError::NothingToRun | SimError::Spawn(_) => CliError::input(e.to_string()),
        e => CliError::runtime(e.to_string()),
    })?;
    bar.finish_and_clear();
    println!(
        "{}",
        serde_json::to_string_pretty(&summary).unwrap_or_default()
    );
    if let Some(why) = scene.pipeline.as_ref().and_then(|p| p.failure(&summary)) {
        return Err(CliError::runtime(why));
    }
    Ok(())
}
