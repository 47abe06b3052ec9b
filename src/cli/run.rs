//! `magsep run` and `magsep validate`.

use std::path::{Path, PathBuf};

use crate::input::{named_inputs, read_scene_text};
use crate::scene::memory::{self, MemoryEstimate};
use crate::scene::overrides::{Override, apply_overrides};
use crate::scene::{ExecutorChoice, RunOptions, Scene, SpawnError, parse_scene};
use crate::sim::{SimError, Simulation, StopFlag, run_scene};
use indicatif::ProgressStyle;

use super::output::{Input, check_file, print};
use super::progress::StderrProgress;
use super::{CliError, Extensions, signals};

/// Most worker threads `--threads` accepts: more than any machine has cores, and cheap to
/// refuse (asking for 100000 threads once spent 10-16 s spawning them before failing).
pub const MAX_THREADS: usize = 1024;

/// Set the worker thread count of rayon (kernels) for this process; `--threads` must be in
/// 1..=[`MAX_THREADS`] (else bad input, exit 2).
pub fn set_threads(threads: Option<usize>) -> Result<bool, CliError> {
    if let Some(n) = threads {
        if n == 0 || n > MAX_THREADS {
            return Err(CliError::input(format!(
                "--threads must be in 1..={MAX_THREADS}, got {n}"
            )));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| CliError::runtime(format!("thread pool: {e}")))?;
        return Ok(n == 1);
    }
    Ok(false)
}

/// The text of the scene file at `path` (a regular file of at most 16 MiB).
pub fn scene_text(path: &Path) -> Result<String, CliError> {
    read_scene_text(path)
        .map_err(|e| CliError::input(format!("{} is invalid:\n(file): {e}", path.display())))
}

/// The scene file at `path` and the files it names, as inputs no output may overwrite.
pub fn scene_inputs(path: &Path, text: &str) -> Vec<Input> {
    let mut inputs = vec![Input::new("scene", path)];
    inputs.extend(
        named_inputs(text)
            .into_iter()
            .map(|p| Input::new("recording named in the scene", p)),
    );
    inputs
}

/// The text of the scene file `path` with the `--set` overrides `set` applied, and the
/// overrides as recorded (`PATH=VALUE`); bad overrides are bad input at their key path.
pub fn text_with_overrides(path: &Path, set: &[String]) -> Result<(String, Vec<String>), CliError> {
    let text = scene_text(path)?;
    let invalid = |e: crate::scene::SceneErrors| {
        CliError::input(format!("{} with --set is invalid:\n{e}", path.display()))
    };
    let mut overrides = Vec::new();
    let mut errors = Vec::new();
    for arg in set {
        match Override::parse(arg) {
            Ok(o) => overrides.push(o),
            Err(e) => errors.push(e),
        }
    }
    if !errors.is_empty() {
        return Err(invalid(crate::scene::SceneErrors(errors)));
    }
    let text = apply_overrides(&text, &overrides).map_err(invalid)?;
    Ok((text, overrides.iter().map(Override::to_string).collect()))
}

/// Parse the scene file `path` with the overrides `set` applied (see [`text_with_overrides`]).
fn parse_with_overrides(
    ext: &Extensions,
    path: &Path,
    text: &str,
    overrides: Vec<String>,
) -> Result<Scene, CliError> {
    let what = if overrides.is_empty() {
        ""
    } else {
        " with --set"
    };
    let mut scene = parse_scene(text, &ext.registry)
        .map_err(|e| CliError::input(format!("{}{what} is invalid:\n{e}", path.display())))?;
    scene.overrides = overrides;
    Ok(scene)
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

/// Whether `text` is a sweep file rather than a scene: a top-level `scene` string and no
/// `[simulation]` table (a scene's `simulation` is required, so nothing is misread).
fn is_sweep_file(text: &str) -> bool {
    match text.parse::<toml::Table>() {
        Ok(t) => t.get("scene").is_some_and(toml::Value::is_str) && !t.contains_key("simulation"),
        Err(_) => false,
    }
}

/// `magsep validate`: a scene (with its overrides and memory estimate), or a sweep file (every
/// point's scene, see [`super::sweep::validate`]).
pub fn validate(
    ext: &Extensions,
    path: &Path,
    set: &[String],
    budget_gib: Option<f64>,
) -> Result<(), CliError> {
    if is_sweep_file(&scene_text(path)?) {
        if !set.is_empty() {
            return Err(CliError::input(format!(
                "{}: --set applies to scenes; a sweep file sets values with its axes",
                path.display()
            )));
        }
        return super::sweep::validate(ext, path, budget_gib);
    }
    let (text, overrides) = text_with_overrides(path, set)?;
    let scene = parse_with_overrides(ext, path, &text, overrides)?;
    let (estimate, budget) = memory(&scene, path, budget_gib)?;
    if scene.pipeline.is_some() {
        // spawn and build the schedule with this program's plugins, recording nothing: what
        // `run` would refuse before its first step (a start region too small, a force the
        // integrator cannot use) is refused here too
        let options = RunOptions {
            plugins: ext.plugins.clone(),
            ..Default::default()
        };
        Simulation::from_scene(&scene, options)
            .map_err(|e| CliError::input(format!("{} is invalid: {e}", path.display())))?;
    }
    print(serde_json::json!({
        "valid": true,
        "scene": path.display().to_string(),
        "pipeline": scene.pipeline_name(),
        "particles": scene.total_particles(),
        "fibres": scene.fibres.len(),
        "memory_estimate_bytes": estimate.bytes.round() as u64,
        "memory_estimate": estimate.detail,
        "memory_budget_bytes": budget,
        "overrides": scene.overrides,
    }))
}

/// `magsep run --executor`: how the step's systems are scheduled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Executor {
    /// The pipeline's choice, else single-threaded below 256 particles.
    Auto,
    /// One system after the other.
    Single,
    /// bevy's multi-threaded executor.
    Multi,
}

impl Executor {
    /// The driver's choice for this option.
    pub fn choice(self) -> ExecutorChoice {
        match self {
            Self::Auto => ExecutorChoice::Auto,
            Self::Single => ExecutorChoice::SingleThreaded,
            Self::Multi => ExecutorChoice::MultiThreaded,
        }
    }
}

/// The options of `magsep run`.
pub struct RunArgs {
    pub scene: PathBuf,
    pub record: Option<PathBuf>,
    pub seed: Option<u64>,
    pub quiet: bool,
    pub threads: Option<usize>,
    pub executor: Executor,
    pub force: bool,
    pub memory_budget: Option<f64>,
    /// `--set PATH=VALUE` overrides, in order.
    pub set: Vec<String>,
}

/// `magsep run`: the output path is checked before anything runs (see `output`).
pub fn run(ext: &Extensions, args: RunArgs) -> Result<(), CliError> {
    let RunArgs {
        scene: path,
        record,
        seed,
        quiet,
        threads,
        executor,
        force,
        memory_budget,
        set,
    } = args;
    let path = path.as_path();
    let (text, overrides) = text_with_overrides(path, &set)?;
    if let Some(out) = &record {
        check_file("--record", out, &scene_inputs(path, &text), force)?;
    }
    let single = set_threads(threads)?;
    let scene = parse_with_overrides(ext, path, &text, overrides)?;
    memory(&scene, path, memory_budget)?;
    let stop = StopFlag::new();
    let signals = signals::install(&stop)
        .map_err(|e| CliError::runtime(format!("cannot install the signal handlers: {e}")))?;
    let options = RunOptions {
        seed,
        record,
        single_threaded: single,
        executor: executor.choice(),
        plugins: ext.plugins.clone(),
        stop: Some(stop),
        // the CLI reads the summary and the clock only
        forces_unread: true,
        ..Default::default()
    };
    let progress = StderrProgress::new(quiet, "steps");
    progress.bar().set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    let result = run_scene(&scene, &options, &progress);
    drop(progress);
    if let Some(partial) = result.as_ref().err().and_then(SimError::partial_summary) {
        // the run's error matters more than a failing stdout
        let _ = print(serde_json::to_string_pretty(partial).unwrap_or_default());
    }
    let summary = result.map_err(|e| match e.cause() {
        // a signal during a long spawn (packing's random insertion): nothing ran
        SimError::Spawn(SpawnError::Interrupted(_)) => CliError {
            code: signals.exit_code().unwrap_or(130),
            message: e.to_string(),
        },
        // a scene that validates but cannot be spawned (a start region too small for its
        // particles, a start box inside a fibre) is bad input too
        // (and a schedule refused before the first step: e.g. a plugin's force the scene's
        // integrator cannot use)
        SimError::NothingToRun | SimError::Spawn(_) | SimError::Schedule(_) => {
            CliError::input(e.to_string())
        }
        _ => CliError::runtime(e.to_string()),
    })?;
    print(serde_json::to_string_pretty(&summary).unwrap_or_default())?;
    if summary["interrupted"] == true
        && let Some(code) = signals.exit_code()
    {
        return Err(CliError {
            code,
            message: format!(
                "interrupted by {}: the summary above is of the steps that ran{}",
                summary["interrupted_by"].as_str().unwrap_or("a signal"),
                if options.record.is_some() {
                    "; the recording is closed and complete"
                } else {
                    ""
                }
            ),
        });
    }
    if let Some(why) = scene.pipeline.as_ref().and_then(|p| p.failure(&summary)) {
        return Err(CliError::runtime(why));
    }
    Ok(())
}
