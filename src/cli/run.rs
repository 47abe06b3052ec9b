//! `magsep run` and `magsep validate`.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use magsep::prelude::*;
use magsep::scene::load_scene;

use super::CliError;

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

pub fn validate(path: &Path) -> Result<(), CliError> {
    let scene = load_scene(path, &Default::default())
        .map_err(|e| CliError::input(format!("{} is invalid:\n{e}", path.display())))?;
    println!(
        "{}",
        serde_json::json!({
            "valid": true,
            "scene": path.display().to_string(),
            "pipeline": scene.simulation.as_ref().map(|s| s.pipeline),
            "particles": scene.total_particles(),
            "fibres": scene.fibres.len(),
        })
    );
    Ok(())
}

pub fn run(
    path: &Path,
    record: Option<PathBuf>,
    seed: Option<u64>,
    quiet: bool,
    threads: Option<usize>,
) -> Result<(), CliError> {
    let single = set_threads(threads)?;
    let scene = load_scene(path, &Default::default())
        .map_err(|e| CliError::input(format!("{} is invalid:\n{e}", path.display())))?;
    let options = RunOptions {
        seed,
        record,
        pipeline: None,
        single_threaded: single,
        resume_from: None,
    };
    if let Some(section) = scene.brownian_section() {
        return run_brownian(&scene, section, &options, quiet);
    }
    let mut sim = Simulation::from_scene(&scene, options).map_err(|e| match e {
        magsep::sim::SimError::NothingToRun => CliError::input(e.to_string()),
        e => CliError::runtime(e.to_string()),
    })?;
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new_spinner()
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    let summary = sim
        .run(|w| {
            if let Some(s) = w.get_resource::<PackingStatus>() {
                bar.set_message(format!(
                    "phi {:.4}  steps {}  failed {}  moves {}",
                    s.packing_fraction, s.compression_steps, s.failed_steps, s.attempts
                ));
                bar.tick();
            }
        })
        .map_err(|e| CliError::runtime(e.to_string()))?;
    bar.finish_and_clear();
    println!(
        "{}",
        serde_json::to_string_pretty(&summary).unwrap_or_default()
    );
    if summary["stop_reason"] == "budget_too_small" {
        return Err(CliError::runtime(
            "no compression step succeeded: the volume step is too large for the attempt budget (see warnings)",
        ));
    }
    Ok(())
}

/// A brownian scene: `runs` replicates in parallel with one progress bar over all steps.
fn run_brownian(
    scene: &magsep::scene::Scene,
    section: &magsep::scene::BrownianSection,
    options: &RunOptions,
    quiet: bool,
) -> Result<(), CliError> {
    let runs = section.runs();
    let total = section.steps() * runs;
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(total)
    };
    bar.set_style(
        ProgressStyle::with_template(
            "[{elapsed_precise}] {bar:40} {pos}/{len} steps ({eta} left) {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(format!("{runs} run(s)"));
    let summary = magsep::brownian::run_ensemble(scene, runs, options, &|n| bar.inc(n))
        .map_err(|e| CliError::runtime(e.to_string()))?;
    bar.finish_and_clear();
    println!(
        "{}",
        serde_json::to_string_pretty(&summary).unwrap_or_default()
    );
    Ok(())
}
