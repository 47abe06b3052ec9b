//! The `magsep` command line (clap), also for a user's own binary: [`main_with`] gives it
//! `run`, `validate`, `info`, `replay` (and the rest) with its own pipelines and plugins.
//! Each command returns `Result<(), CliError>`; the error's code is the process exit code
//! (0 ok, 2 bad input, 1 runtime failure, 130/143 a run stopped by SIGINT/SIGTERM, see
//! [`signals`]). Output paths are checked before anything runs, and standard output is
//! written without panicking (module `output`).
//!
//! ```no_run
//! use magsep::cli::{Extensions, main_with};
//! use magsep::prelude::*;
//! // a binary with the built-in pipelines plus one of its own:
//! // let ext = Extensions::default().pipeline(MyPipeline);
//! let ext = Extensions::default();
//! std::process::exit(main_with(ext));
//! ```

use std::path::PathBuf;
use std::sync::Arc;

use magsep_plugins::app::SimPlugin;

use crate::scene::{Pipeline, Registry};

use clap::{Parser, Subcommand};

mod field;
mod info;
mod output;
pub mod progress;
mod run;
pub mod signals;
mod sweep;

/// The output-file rules of every command (also for the Python package's `record=`).
pub use output::{Input, check_file};

/// A CLI failure with its exit code (2 bad input, 1 runtime failure, 130/143 interrupted). An
/// empty message is not printed (a closed standard output ends the command quietly).
#[derive(Debug)]
pub struct CliError {
    /// Exit code.
    pub code: i32,
    /// Message for stderr.
    pub message: String,
}

impl CliError {
    /// Bad input (exit 2).
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            code: 2,
            message: message.into(),
        }
    }
    /// Runtime failure (exit 1).
    pub fn runtime(message: impl Into<String>) -> Self {
        Self {
            code: 1,
            message: message.into(),
        }
    }
}

#[derive(Parser)]
#[command(
    name = "magsep",
    version,
    about = "Particles in magnetic separation: packing, fields, Brownian capture, density separation"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene; JSON summary on stdout, progress on stderr.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Write an MCAP recording.
        #[arg(long)]
        record: Option<PathBuf>,
        /// Override the scene's seed.
        #[arg(long)]
        seed: Option<u64>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Worker threads (default: all cores; at most 1024).
        #[arg(long)]
        threads: Option<usize>,
        /// How the step's systems are scheduled: `auto` (the pipeline's choice, else by the
        /// scene's size), `single` (one system after the other; their per-particle loops still
        /// use every thread) or `multi` (bevy's multi-threaded executor). All give bitwise the
        /// same results.
        #[arg(long, value_enum, default_value = "auto")]
        executor: run::Executor,
        /// Memory budget [GiB] the scene's estimated memory must fit (default: 16 GiB or
        /// 3/4 of the machine's memory, whichever is smaller; or MAGSEP_MEMORY_BUDGET).
        #[arg(long, value_name = "GiB")]
        memory_budget: Option<f64>,
        /// Overwrite an existing --record file (never an input of the run).
        #[arg(long)]
        force: bool,
        /// Override a scene value: PATH=VALUE, e.g. `brownian.duration=2.0` or
        /// `particles[0].shape.radius=75e-9` (VALUE is TOML; repeatable; recorded).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<String>,
    },
    /// Validate a scene or a sweep file: exit 0 if valid, 2 with every error (and its key
    /// path) if not. A sweep file is checked point by point (every point's scene, each within
    /// the memory budget).
    Validate {
        /// Scene or sweep file (TOML).
        scene: PathBuf,
        /// Override a scene value: PATH=VALUE (as for `run`).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<String>,
        /// Memory budget [GiB] (as for `run`).
        #[arg(long, value_name = "GiB")]
        memory_budget: Option<f64>,
    },
    /// Channels, frame count and metadata of a recording.
    Info {
        /// MCAP recording.
        recording: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Re-run the Observe systems on a recording's frames and print the summary.
    Replay {
        /// MCAP recording.
        recording: PathBuf,
        /// Continue the run from the recording's last frame to the scene's end (brownian),
        /// bitwise as if never interrupted; prints the summary of the whole run.
        #[arg(long)]
        resume: bool,
        /// With --resume: record the continuation here.
        #[arg(long, requires = "resume")]
        record: Option<PathBuf>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Overwrite an existing --record file (never the recording being resumed).
        #[arg(long)]
        force: bool,
    },
    /// Magnetic field of a scene's fibres: CSV at points, or a map in a plane.
    ///
    /// `--points FILE.csv` (header `x,y,z` [m]) writes `x,y,z,bx,by,bz` [m, T] to stdout (or
    /// to `--out FILE.csv`), plus the nine `dbi_dj` [T/m] with `--gradient`. `--slice z=0
    /// --extent X0,X1,Y0,Y1 --out map.svg` draws |B|, or with `--moment` the attractive force
    /// on a particle with the capture contour at `--cutoff`. Options of the other mode are
    /// refused (exit 2).
    Field {
        /// Scene file (TOML) with [[fibres]] and/or [external_field].
        scene: PathBuf,
        /// Points CSV with header `x,y,z` [m].
        #[arg(long)]
        points: Option<PathBuf>,
        /// Also write the gradient of B (nine columns, T/m).
        #[arg(long)]
        gradient: bool,
        /// Map plane, e.g. `z=0` [m].
        #[arg(long)]
        slice: Option<String>,
        /// Map extent of the two in-plane axes: MIN1,MAX1,MIN2,MAX2 [m].
        #[arg(long, allow_hyphen_values = true)]
        extent: Option<String>,
        /// Map output (SVG); with --points, the CSV file (instead of stdout).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Cells per side of the map [default: 200].
        #[arg(long)]
        resolution: Option<usize>,
        /// Map the attractive force on a particle with this saturated moment [A m²].
        #[arg(long)]
        moment: Option<f64>,
        /// Capture cut-off force [N] of a force map (with --moment) [default: 0.5e-15 N, the
        /// thesis's].
        #[arg(long)]
        cutoff: Option<f64>,
        /// Worker threads (default: all cores; at most 1024).
        #[arg(long)]
        threads: Option<usize>,
        /// Overwrite an existing --out file (never an input).
        #[arg(long)]
        force: bool,
    },
    /// Parameter sweeps: `magsep sweep SWEEP.toml --out DIR [--jobs J] [--shard I/N]`,
    /// `magsep sweep merge DIR`, `magsep sweep slurm SWEEP.toml --out DIR --shards N`.
    Sweep(sweep::SweepCommand),
    /// Benchmarks (`magsep bench packing`, `magsep bench particle-fluid --json`).
    Bench {
        /// What to benchmark.
        #[arg(value_enum)]
        what: crate::studies::bench::BenchKind,
        /// One JSON object per measurement on stdout.
        #[arg(long)]
        json: bool,
        /// Smaller sizes (for CI smoke runs).
        #[arg(long)]
        quick: bool,
    },
    /// Charts as SVG (`magsep chart packing --out DIR`).
    Chart {
        /// Which chart family.
        #[arg(value_enum)]
        what: crate::studies::bench::ChartKind,
        /// Output directory.
        #[arg(long, default_value = "charts")]
        out: PathBuf,
        /// Smaller runs (for CI smoke runs).
        #[arg(long)]
        quick: bool,
    },
}

/// What a program adds to the built-in CLI: pipelines, scene kinds, and plugins built into
/// every run (and expected by `replay --resume`).
#[derive(Clone, Default)]
pub struct Extensions {
    /// The pipelines and scene kinds (default: the built-in pipelines).
    pub registry: Registry,
    /// Plugins added after the pipeline's group in every run.
    pub plugins: Vec<Arc<dyn SimPlugin>>,
}

impl Extensions {
    /// Register `pipeline` too.
    pub fn pipeline(mut self, pipeline: impl Pipeline) -> Self {
        self.registry = self.registry.with_pipeline(pipeline);
        self
    }

    /// Register a plugin scene kind too (a top-level section any scene may hold, spawned
    /// with the scene; see [`crate::scene::SceneKind`]).
    pub fn kind(mut self, kind: impl crate::scene::SceneKind + 'static) -> Self {
        self.registry = self.registry.with_kind(kind);
        self
    }

    /// Build `plugin` into every run, of every pipeline. A plugin that applies only to some
    /// scenes decides in its `build`, e.g. from a resource its [`kind`](Self::kind) spawned
    /// (`build` runs after the scene is spawned): a force registered into a pipeline that
    /// cannot integrate it fails the schedule (exit 2, also from `magsep validate`).
    pub fn plugin(mut self, plugin: impl SimPlugin) -> Self {
        self.plugins.push(Arc::new(plugin));
        self
    }
}

/// The `magsep` CLI with the built-in pipelines; returns the exit code.
pub fn main() -> i32 {
    main_with(Extensions::default())
}

/// The CLI with `ext`'s pipelines and plugins; parses the process arguments, runs, prints
/// errors, and returns the exit code.
pub fn main_with(ext: Extensions) -> i32 {
    signals::survive_file_size_limit();
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return code;
        }
    };
    let result = match cli.command {
        Command::Run {
            scene,
            record,
            seed,
            quiet,
            threads,
            executor,
            memory_budget,
            force,
            set,
        } => run::run(
            &ext,
            run::RunArgs {
                scene,
                record,
                seed,
                quiet,
                threads,
                executor,
                force,
                memory_budget,
                set,
            },
        ),
        Command::Validate {
            scene,
            set,
            memory_budget,
        } => run::validate(&ext, &scene, &set, memory_budget),
        Command::Field {
            scene,
            points,
            gradient,
            slice,
            extent,
            out,
            resolution,
            moment,
            cutoff,
            threads,
            force,
        } => field::field(
            field::FieldArgs {
                scene,
                points,
                gradient,
                slice,
                extent,
                out,
                resolution,
                moment,
                cutoff,
                force,
            },
            threads,
        ),
        Command::Info { recording, json } => info::info(&recording, json, &ext.registry),
        Command::Replay {
            recording,
            resume,
            record,
            quiet,
            force,
        } => {
            if resume {
                info::resume(&ext, &recording, record, quiet, force)
            } else {
                info::replay(&ext, &recording)
            }
        }
        Command::Sweep(cmd) => sweep::sweep(&ext, cmd),
        Command::Bench { what, json, quick } => {
            crate::studies::bench::bench(what, json, quick).map_err(to_cli)
        }
        Command::Chart { what, out, quick } => output::check_dir("--out", &out)
            .and_then(|()| crate::studies::bench::chart(what, &out, quick).map_err(to_cli)),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            if !e.message.is_empty() {
                output::eprint(format!("error: {}", e.message));
            }
            e.code
        }
    }
}

fn to_cli(e: crate::studies::bench::BenchError) -> CliError {
    match e {
        crate::studies::bench::BenchError::Input(m) => CliError::input(m),
        crate::studies::bench::BenchError::Runtime(m) => CliError::runtime(m),
        crate::studies::bench::BenchError::Stdout(e) => output::stdout_error(e),
    }
}
