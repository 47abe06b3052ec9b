//! CLI commands (clap). Each command returns `Result<(), CliError>`; the error's code is the
//! process exit code.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

mod info;
mod run;

/// A CLI failure with its exit code (2 bad input, 1 runtime failure).
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
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Validate a scene: exit 0 if valid, 2 with every error (and its key path) if not.
    Validate {
        /// Scene file (TOML).
        scene: PathBuf,
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
    },
    /// Benchmarks (`magsep bench packing`).
    Bench {
        /// What to benchmark: packing.
        what: String,
        /// One JSON object per measurement on stdout.
        #[arg(long)]
        json: bool,
        /// Smaller sizes (for CI smoke runs).
        #[arg(long)]
        quick: bool,
    },
    /// Charts as SVG (`magsep chart packing --out DIR`).
    Chart {
        /// Which chart family: packing.
        what: String,
        /// Output directory.
        #[arg(long, default_value = "charts")]
        out: PathBuf,
        /// Smaller runs (for CI smoke runs).
        #[arg(long)]
        quick: bool,
    },
}

/// Parse arguments, run, print errors; returns the exit code.
pub fn main() -> i32 {
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
        } => run::run(&scene, record, seed, quiet, threads),
        Command::Validate { scene } => run::validate(&scene),
        Command::Info { recording, json } => info::info(&recording, json),
        Command::Replay { recording } => info::replay(&recording),
        Command::Bench { what, json, quick } => {
            magsep::bench::bench(&what, json, quick).map_err(to_cli)
        }
        Command::Chart { what, out, quick } => {
            magsep::bench::chart(&what, &out, quick).map_err(to_cli)
        }
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {}", e.message);
            e.code
        }
    }
}

fn to_cli(e: magsep::bench::BenchError) -> CliError {
    match e {
        magsep::bench::BenchError::Input(m) => CliError::input(m),
        magsep::bench::BenchError::Runtime(m) => CliError::runtime(m),
    }
}
