//! `magsep sweep SWEEP.toml --out DIR`, `magsep sweep merge DIR`, `magsep sweep slurm
//! SWEEP.toml --out DIR` (see `crate::studies::sweep`).

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use indicatif::ProgressStyle;

use super::output::{check_dir, print};
use super::progress::StderrProgress;
use super::{CliError, Extensions};
use crate::studies::sweep::{self, SweepError, slurm::SlurmOptions};

/// `magsep sweep`: run a sweep file, or `merge` / `slurm`.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SweepCommand {
    #[command(subcommand)]
    command: Option<SweepSub>,
    /// Sweep file (TOML).
    #[arg(required = true)]
    sweep: Option<PathBuf>,
    /// Sweep directory (created; a restarted sweep skips its finished points).
    #[arg(long, required = true)]
    out: Option<PathBuf>,
    /// Points run at once (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Write each point's recording (points/<index>/recording.mcap).
    #[arg(long)]
    record: bool,
    /// Run only shard I of N (1-based): the points whose index % N == I - 1.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    /// Run failed points again (finished points are otherwise never redone).
    #[arg(long)]
    retry_failed: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Memory budget [GiB] of the points running at once (default: 16 GiB or 3/4 of the
    /// machine's memory, whichever is smaller; or MAGSEP_MEMORY_BUDGET): fewer points run at
    /// once when their estimates exceed it, and a point that alone exceeds it is an error
    #[arg(long, value_name = "GiB")]
    memory_budget: Option<f64>,
}

#[derive(Subcommand)]
enum SweepSub {
    /// Build results.csv and the charts from the points finished so far (partial results
    /// allowed: missing points are counted and left empty).
    Merge {
        /// Sweep directory.
        dir: PathBuf,
    },
    /// Write a Slurm job array (one task per shard) and a merge job into DIR.
    Slurm {
        /// Sweep file (TOML).
        sweep: PathBuf,
        /// Sweep directory (scripts, logs and results).
        #[arg(long)]
        out: PathBuf,
        /// Number of shards = array tasks.
        #[arg(long, default_value_t = 1)]
        shards: usize,
        /// Slurm partition.
        #[arg(long)]
        partition: Option<String>,
        /// Time limit per task (Slurm format, e.g. 01:00:00).
        #[arg(long)]
        time: Option<String>,
        /// CPUs per task (each task runs this many points at once).
        #[arg(long, default_value_t = 1)]
        cpus_per_task: usize,
        /// Write each point's recording.
        #[arg(long)]
        record: bool,
    },
}

fn to_cli(e: SweepError) -> CliError {
    match e {
        SweepError::Input(m) => CliError::input(m),
        SweepError::Runtime(m) => CliError::runtime(m),
    }
}

fn pretty(v: &serde_json::Value) -> String {
    serde_json::to_string_pretty(v).unwrap_or_default()
}

/// `magsep validate SWEEP.toml`: the sweep file and every point's scene, each point within the
/// memory budget alone and spawned with its schedule built (exit 2 with the failing points'
/// key paths or refusals otherwise).
pub fn validate(ext: &Extensions, path: &Path, budget_gib: Option<f64>) -> Result<(), CliError> {
    let budget = crate::scene::memory::budget(budget_gib).map_err(CliError::input)?;
    let (sweep, memory) = sweep::load_checked(path, &ext.registry).map_err(to_cli)?;
    let all: Vec<usize> = (0..sweep.len()).collect();
    let (_, largest) =
        sweep::run::jobs_within_budget(&sweep, &memory, &all, 1, budget).map_err(|e| {
            CliError::input(format!(
                "{}: a point's scene needs more memory than the budget:\n{e}",
                path.display()
            ))
        })?;
    // spawn every point and build its schedule, as `magsep validate SCENE` does, so what a
    // run would refuse before its first step fails here
    let progress = StderrProgress::new(false, "points");
    progress.bar().set_length(all.len() as u64);
    let built = sweep::run::build_points(&sweep, &ext.registry, &ext.plugins, &all, &|| {
        progress.bar().inc(1)
    });
    drop(progress);
    built.map_err(|e| {
        CliError::input(format!(
            "{}: a point's scene is refused before its first step:\n{e}",
            path.display()
        ))
    })?;
    print(pretty(&serde_json::json!({
        "valid": true,
        "sweep": path.display().to_string(),
        "scene": sweep.scene_path.display().to_string(),
        "points": sweep.len(),
        "axes": sweep.axes.iter().map(|a| a.name.clone()).collect::<Vec<_>>(),
        "replicates": sweep.replicates,
        "largest_memory_estimate_bytes": largest.round() as u64,
        "memory_budget_bytes": budget,
    })))
}

/// Run `magsep sweep ...`.
pub fn sweep(ext: &Extensions, cmd: SweepCommand) -> Result<(), CliError> {
    match cmd.command {
        Some(SweepSub::Merge { dir }) => {
            let result = sweep::merge(&dir).map_err(to_cli)?;
            print(pretty(&result))?;
            let missing = result["missing"].as_u64().unwrap_or(0);
            if missing > 0 {
                super::output::eprint(format!(
                    "note: {missing} of {} points are not finished (status `missing` in \
                     results.csv)",
                    result["points"]
                ));
            }
            Ok(())
        }
        Some(SweepSub::Slurm {
            sweep: path,
            out,
            shards,
            partition,
            time,
            cpus_per_task,
            record,
        }) => {
            check_dir("--out", &out)?;
            let exe = std::env::current_exe()
                .map_err(|e| CliError::runtime(format!("cannot find the magsep binary: {e}")))?;
            let options = SlurmOptions {
                shards,
                partition,
                time,
                cpus_per_task,
                record,
            };
            let result =
                sweep::write_slurm(&path, &out, &exe, &options, &ext.registry).map_err(to_cli)?;
            print(pretty(&result))
        }
        None => {
            let (Some(path), Some(out)) = (cmd.sweep, cmd.out) else {
                return Err(CliError::input(
                    "magsep sweep needs SWEEP.toml and --out DIR",
                ));
            };
            check_dir("--out", &out)?;
            let shard = cmd
                .shard
                .as_deref()
                .map(sweep::run::parse_shard)
                .transpose()
                .map_err(CliError::input)?;
            let jobs = match cmd.jobs {
                Some(0) => return Err(CliError::input("--jobs must be at least 1")),
                Some(j) => j.min(super::run::MAX_THREADS),
                None => std::thread::available_parallelism().map_or(1, |n| n.get()),
            };
            let stop = crate::sim::StopFlag::new();
            let signals = super::signals::install(&stop).map_err(|e| {
                CliError::runtime(format!("cannot install the signal handlers: {e}"))
            })?;
            let progress = StderrProgress::new(cmd.quiet, "points");
            let bar = progress.bar();
            bar.set_style(
                ProgressStyle::with_template(
                    "[{elapsed_precise}] {bar:40} {pos}/{len} points ({eta} left)",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            let args = sweep::SweepRun {
                sweep: path,
                out,
                jobs,
                record: cmd.record,
                shard,
                retry_failed: cmd.retry_failed,
                memory_budget: crate::scene::memory::budget(cmd.memory_budget)
                    .map_err(CliError::input)?,
                stop: Some(stop),
            };
            let result = sweep::run_sweep(&args, &ext.registry, ext.plugins.clone(), bar);
            drop(progress);
            let result = result.map_err(to_cli)?;
            print(pretty(&result))?;
            if result["interrupted"] == true
                && let Some(code) = signals.exit_code()
            {
                return Err(CliError {
                    code,
                    message: format!(
                        "interrupted by {}: {}",
                        result["interrupted_by"].as_str().unwrap_or("a signal"),
                        result["resume"].as_str().unwrap_or_default()
                    ),
                });
            }
            let failed = result["failed"]
                .as_u64()
                .unwrap_or(result["failed_now"].as_u64().unwrap_or(0));
            if failed > 0 {
                return Err(CliError::runtime(format!(
                    "{failed} points failed: see the status and error columns of results.csv \
                     (or points/<index>/error.json)"
                )));
            }
            Ok(())
        }
    }
}
