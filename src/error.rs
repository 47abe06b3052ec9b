//! The error types of scenes, runs and replays (a leaf module: every other module of the crate
//! may use it, it uses none of them).

use std::fmt;

use magsep_plugins::record::RecordError;

/// One problem in a scene: where (a key path such as `particles[2].shape.radius`) and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// Key path, `(syntax)` for TOML syntax errors, `(file)` for I/O.
    pub path: String,
    /// What is wrong, with the offending value.
    pub message: String,
}

impl SceneError {
    /// A new error at `path`.
    pub fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path, self.message)
    }
}

/// All problems found in a scene (never empty when returned as an error).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneErrors(pub Vec<SceneError>);

impl fmt::Display for SceneErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for SceneErrors {}

/// Why spawning failed (after validation only run-time failures remain).
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    /// Random insertion could not place a particle.
    #[error(transparent)]
    Insertion(#[from] magsep_systems::packing::insert::InsertionError),
    /// A pipeline or a plugin kind failed.
    #[error("{0}")]
    Other(String),
}

/// Errors while building or running a simulation.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scene could not be spawned (e.g. random insertion failed).
    #[error("spawning the scene failed: {0}")]
    Spawn(#[from] SpawnError),
    /// The schedule could not be built (ambiguity, cycle, a force no plugin consumes).
    #[error("building the schedule failed: {0}")]
    Schedule(String),
    /// The recording could not be written.
    #[error("recording failed: {0}")]
    Record(#[from] RecordError),
    /// The scene has no `[simulation]` (a field-only scene: use `magsep field`).
    #[error("the scene has no [simulation] to run (a field-only scene: use `magsep field`)")]
    NothingToRun,
    /// The frame to resume from does not fit the scene.
    #[error("cannot resume: {0}")]
    Resume(String),
    /// A numerical failure was reported.
    #[error("numerical failure: {0}")]
    Health(String),
}

/// Why a replay or a resume failed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The recording could not be read.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// The recording has no `magsep` metadata record.
    #[error(
        "the recording has no `magsep` metadata record (scene text, seed): not written by magsep run"
    )]
    NoMetadata,
    /// The recorded scene does not parse with this program.
    #[error("the recorded scene is invalid:\n{0}")]
    Scene(#[from] SceneErrors),
    /// The recording holds no frame.
    #[error("the recording holds no frame{0}")]
    NoFrames(String),
    /// A frame is inconsistent.
    #[error("frame at step {step} is inconsistent: {detail}")]
    BadFrame {
        /// Step of the frame.
        step: u64,
        /// What is wrong.
        detail: String,
    },
    /// The recorded run used plugins this program does not have.
    #[error(
        "the recording was made with plugins this program lacks: {0}; continuing without them would silently change the run (build a binary with them, e.g. through magsep::cli::main_with)"
    )]
    MissingPlugins(String),
    /// The pipeline cannot do this (e.g. resume).
    #[error("{0}")]
    Unsupported(String),
    /// The continued run failed.
    #[error(transparent)]
    Sim(#[from] SimError),
}
