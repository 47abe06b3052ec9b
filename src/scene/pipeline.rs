//! Pipelines as plugins: the [`Pipeline`] trait and the [`Registry`] that `[simulation]
//! pipeline = "..."` is looked up in.
//!
//! A pipeline is one self-contained unit: the scene sections it owns and their validation,
//! spawning, its plugin group, its end-of-run condition, its summary, replay and (where it can)
//! resume. Shared code (the scene parser, the simulation driver, the recorder, replay and the
//! CLI) only calls these hooks; it never names a pipeline. The built-in pipelines are
//! registered in `magsep::pipelines` (one line each); a user's binary adds its own with
//! [`Registry::with_pipeline`] and hands the registry to `magsep::cli::main_with` (through
//! `magsep::cli::Extensions::pipeline`).

use std::any::Any;
use std::fmt;
use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use bevy_ecs::prelude::*;
use magsep_plugins::app::SimPlugin;
use magsep_plugins::group::PipelineGroup;
use magsep_plugins::record::{ParticleFrame, Recording, RecordingWriter};
use serde_json::Value;

use super::checks::{typed, typed_array};
use super::{FibreSpec, ParticleGroup, Scene, SceneError, SceneKind, SpawnError};
use crate::error::{ReplayError, SimError};

/// What a pipeline's [`Pipeline::parse`] sees: the scene's TOML table, the common parts
/// already typed, and the error list to push to (every error at its key path).
///
/// Section types are `Serialize` as well as `Deserialize`: the typed value is serialized
/// back to find keys serde skipped without an error (see [`typed`]).
pub struct ParseContext<'a> {
    /// The whole scene table (the pipeline reads its own keys, see [`Pipeline::sections`]).
    pub table: &'a toml::Table,
    /// `[[particles]]` typed, with their index in the file (entries with errors left out).
    pub particles: &'a mut Vec<(usize, ParticleGroup)>,
    /// `[[fibres]]` (and expanded `[[fibre_packings]]`).
    pub fibres: &'a [FibreSpec],
    /// Whether every `[[fibres]]` and `[[fibre_packings]]` entry is valid. When one is not
    /// (its errors are reported), indices into [`fibres`](Self::fibres) are unreliable:
    /// skip the checks of fibre references rather than report spurious ones.
    pub fibres_valid: bool,
    /// Errors found so far; push more.
    pub errors: &'a mut Vec<SceneError>,
}

impl ParseContext<'_> {
    /// The top-level table `key` typed as `T` (`None` if absent or invalid; invalid values
    /// push errors with their inner key path).
    pub fn section<T: serde::de::DeserializeOwned + serde::Serialize>(
        &mut self,
        key: &str,
    ) -> Option<T> {
        self.table
            .get(key)
            .and_then(|v| typed::<T>(v, key, self.errors))
    }

    /// The top-level array of tables `key` (`[[key]]`), each entry typed with its index.
    pub fn array<T: serde::de::DeserializeOwned + serde::Serialize>(
        &mut self,
        key: &str,
    ) -> Vec<(usize, T)> {
        self.table
            .get(key)
            .map(|v| typed_array::<T>(v, key, self.errors))
            .unwrap_or_default()
    }

    /// A required top-level table: an error if it is missing.
    pub fn required<T: serde::de::DeserializeOwned + serde::Serialize>(
        &mut self,
        key: &str,
        pipeline: &str,
    ) -> Option<T> {
        if !self.table.contains_key(key) {
            self.errors.push(SceneError::new(
                key,
                format!("missing required table [{key}] for pipeline = \"{pipeline}\""),
            ));
            return None;
        }
        self.section(key)
    }

    /// Push an error at `path`.
    pub fn error(&mut self, path: impl Into<String>, message: impl Into<String>) {
        self.errors.push(SceneError::new(path, message));
    }
}

/// A pipeline's validated scene data (what [`Pipeline::parse`] returns), read back with
/// [`Scene::section`].
#[derive(Clone)]
pub struct SceneSection(Arc<dyn Any + Send + Sync>);

impl SceneSection {
    /// Wrap `value`.
    pub fn new<T: Any + Send + Sync>(value: T) -> Self {
        Self(Arc::new(value))
    }

    /// The value as `T`, if it is one.
    pub fn get<T: Any>(&self) -> Option<&T> {
        self.0.downcast_ref::<T>()
    }
}

impl fmt::Debug for SceneSection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("SceneSection(..)")
    }
}

/// Progress of a run, reported by the driver (a CLI progress bar, or nothing).
pub trait Progress: Sync {
    /// The total number of steps, when known (all replicates together).
    fn set_total(&self, _steps: u64) {}
    /// `steps` more steps are done.
    fn advance(&self, _steps: u64) {}
    /// A status line (e.g. the packing fraction so far).
    fn message(&self, _text: String) {}
}

/// No progress report.
pub struct NoProgress;

impl Progress for NoProgress {}

/// How the per-step schedule runs its systems. The schedule has no ambiguities (every pair of
/// conflicting systems is ordered), so all choices give bitwise the same results; systems
/// split their own per-particle work across threads either way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExecutorChoice {
    /// Single-threaded below [`SMALL_SCENE_PARTICLES`] particles, multi-threaded from there on.
    #[default]
    Auto,
    /// One system after the other on the calling thread (no per-system task hand-off: a few
    /// tens of nanoseconds per system instead of microseconds).
    SingleThreaded,
    /// bevy's multi-threaded executor (independent systems may run at the same time).
    MultiThreaded,
}

/// Particle count from which [`ExecutorChoice::Auto`] uses the multi-threaded executor: the
/// count from which per-particle loops go parallel too (`magsep_systems::par`). Below it a
/// step's work is a few microseconds, less than handing each system to a worker costs; at
/// 1000 spheres both executors take the same time (`magsep bench overhead`).
pub const SMALL_SCENE_PARTICLES: usize = 256;

impl ExecutorChoice {
    /// Whether a scene of `particles` particles runs multi-threaded.
    pub fn multi_threaded(self, particles: usize) -> bool {
        match self {
            Self::Auto => particles >= SMALL_SCENE_PARTICLES,
            Self::SingleThreaded => false,
            Self::MultiThreaded => true,
        }
    }
}

/// Options of a run beyond the scene.
#[derive(Clone, Default)]
pub struct RunOptions {
    /// Seed overriding `simulation.seed`.
    pub seed: Option<u64>,
    /// Write an MCAP recording here.
    pub record: Option<PathBuf>,
    /// Use this plugin group instead of the pipeline's own (a user's edited group).
    pub pipeline: Option<PipelineGroup>,
    /// Run the schedule on one thread (overrides [`Self::executor`]).
    pub single_threaded: bool,
    /// How the schedule's systems are run (default: chosen by the scene's size).
    pub executor: ExecutorChoice,
    /// Continue from this recorded frame (see `magsep replay --resume`).
    pub resume_from: Option<ParticleFrame>,
    /// Plugins built after the pipeline's group (a user's forces, observers, channels).
    pub plugins: Vec<Arc<dyn SimPlugin>>,
    /// Stop the run early when this flag is set (polled between steps; `magsep run` sets it on
    /// SIGINT/SIGTERM).
    pub stop: Option<StopFlag>,
    /// The caller reads no force component (`NetForce`, `DipoleForce`, `FieldForce`, ...)
    /// during the run (neither in `on_step` nor in systems added after the build), so a
    /// pipeline that keeps its forces in a dense workspace (the brownian one) may skip
    /// writing them; the trajectory is bitwise the same. Honoured only when no plugin besides
    /// the pipeline's own runs ([`Self::plugins`] empty, no [`Self::pipeline`]). Default
    /// false (the components are written); `magsep run`, `replay --resume`, sweeps and the
    /// benches set it.
    pub forces_unread: bool,
}

/// A request to end a run early, shared between threads (its clones are one flag).
///
/// The driver ([`Simulation::run`](crate::sim::Simulation::run), `run_scene` and every
/// pipeline's own [`Pipeline::run`]) polls it between steps. Once it is set, the current step
/// ends, the final frame is recorded, the recording is closed with its footer and a metadata
/// record `magsep.interrupted` (key `reason`), and the run returns the summary of what ran,
/// marked `"interrupted": true` and `"interrupted_by": reason`. `magsep run` sets it on
/// SIGINT and SIGTERM; a library user sets it from any thread (a timeout, a UI button).
///
/// ```
/// use magsep::prelude::*;
/// use magsep::sim::StopFlag;
/// let scene = magsep::scene::parse_scene(
///     r#"
/// [simulation]
/// pipeline = "packing"
/// [container]
/// kind = "periodic_box"
/// [[particles]]
/// count = 20
/// shape = { kind = "sphere", radius = 0.5 }
/// "#,
///     &Default::default(),
/// )
/// .unwrap();
/// let stop = StopFlag::new();
/// let options = RunOptions { stop: Some(stop.clone()), ..Default::default() };
/// let mut sim = Simulation::from_scene(&scene, options).unwrap();
/// let summary = sim
///     .run(|world| {
///         if world.resource::<StepClock>().step == 3 {
///             stop.request_stop("enough steps");
///         }
///     })
///     .unwrap();
/// assert_eq!(summary["interrupted"], true);
/// assert_eq!(summary["interrupted_by"], "enough steps");
/// let steps = summary["compression_steps"].as_u64().unwrap()
///     + summary["failed_steps"].as_u64().unwrap();
/// assert_eq!(steps, 3);
/// ```
#[derive(Clone, Debug, Default)]
pub struct StopFlag(Arc<StopState>);

#[derive(Debug, Default)]
struct StopState {
    reason: OnceLock<String>,
    parent: Option<StopFlag>,
}

impl StopFlag {
    /// A flag not yet set.
    pub fn new() -> Self {
        Self::default()
    }

    /// A flag that is set when `self` is, and can also be set on its own without setting
    /// `self` (e.g. one replicate's failure stopping its siblings).
    pub fn child(&self) -> Self {
        Self(Arc::new(StopState {
            reason: OnceLock::new(),
            parent: Some(self.clone()),
        }))
    }

    /// Ask the run to stop, saying why (e.g. `SIGINT`); the first reason given is kept.
    pub fn request_stop(&self, reason: impl Into<String>) {
        let _ = self.0.reason.set(reason.into());
    }

    /// Whether a stop was requested (of this flag or of its parent).
    pub fn is_stopped(&self) -> bool {
        self.0.reason.get().is_some() || self.0.parent.as_ref().is_some_and(Self::is_stopped)
    }

    /// Why the stop was requested, if it was.
    pub fn reason(&self) -> Option<String> {
        self.0
            .reason
            .get()
            .cloned()
            .or_else(|| self.0.parent.as_ref().and_then(Self::reason))
    }
}

/// The run's [`StopFlag`] as a resource: in the world from before the pipeline spawns (when
/// the run has a flag), so that a long spawn can end at a request too. The packing pipeline's
/// random insertion polls it and then fails with [`SpawnError::Interrupted`].
#[derive(Resource, Debug, Clone)]
pub struct StopRequest(pub StopFlag);

/// What a summary knows of the run beyond the world.
#[derive(Debug, Clone, Copy)]
pub struct RunInfo {
    /// Seed of the run.
    pub seed: u64,
    /// Wall time of the run so far \[s\].
    pub wall_time_s: f64,
}

/// One pipeline. Implement it (and register it in a [`Registry`]) to add a simulation kind
/// that runs from scenes through `magsep run`, `validate`, `info`, `replay` and the builder.
///
/// Only [`name`](Self::name), [`parse`](Self::parse), [`spawn`](Self::spawn),
/// [`plugins`](Self::plugins), [`is_finished`](Self::is_finished),
/// [`summary`](Self::summary) and [`replay`](Self::replay) are required; see `examples/langevin_trap` for a complete
/// pipeline written outside the crate.
pub trait Pipeline: Send + Sync + 'static {
    /// The name in `[simulation] pipeline = "..."` (and in recordings).
    fn name(&self) -> &'static str;

    /// One line on what it simulates (for `magsep validate` and help texts).
    fn description(&self) -> &'static str {
        ""
    }

    /// The top-level scene keys this pipeline owns besides the common ones (`simulation`,
    /// `particles`, `record`, `fibres`, `fibre_packings`, `external_field`). A key owned by
    /// another pipeline is an error "only for pipeline = ..." in this pipeline's scenes.
    fn sections(&self) -> &'static [&'static str] {
        &[]
    }

    /// Whether the pipeline's physics uses `[[fibres]]`, `[[fibre_packings]]` and
    /// `[external_field]`. A scene giving them to a pipeline that does not is refused at those
    /// keys (exit 2), not run without them. Default `true` (a plugin may read them).
    fn uses_fibres(&self) -> bool {
        true
    }

    /// `[[particles]]` keys this pipeline reads beyond `count` and `shape` (a plugin
    /// pipeline's own keys arrive in [`ParticleGroup::extra`]).
    fn particle_keys(&self) -> &'static [&'static str] {
        &[]
    }

    /// The scene's peak memory, estimated before anything is allocated (checked against
    /// the memory budget by `magsep run` and printed by `magsep validate`). Default:
    /// [`memory::default_estimate`](super::memory::default_estimate), 4 KiB per particle.
    fn memory_estimate(&self, scene: &Scene) -> super::memory::MemoryEstimate {
        super::memory::default_estimate(scene)
    }

    /// Whether a scene of this pipeline needs at least one `[[particles]]` entry.
    fn needs_particles(&self) -> bool {
        true
    }

    /// How the schedule runs when the run leaves the choice to the scene
    /// ([`ExecutorChoice::Auto`]). Default: `Auto` (by the scene's size). A pipeline whose
    /// systems form one chain, each splitting its own work among threads, gains nothing from
    /// bevy's multi-threaded executor and pays its hand-offs: it answers `SingleThreaded`
    /// (the steps then run inside rayon's pool from [`SMALL_SCENE_PARTICLES`] particles).
    fn executor(&self) -> ExecutorChoice {
        ExecutorChoice::Auto
    }

    /// Type and check this pipeline's sections and particle keys, pushing every problem at
    /// its key path; the returned data is kept in the [`Scene`].
    fn parse(&self, cx: &mut ParseContext<'_>) -> Option<SceneSection>;

    /// Spawn the scene's particles and the resources the pipeline's plugins need (the
    /// driver adds the common ones: fibres, external field, seed, health, record interval).
    ///
    /// # Errors
    /// [`SpawnError`] when placing particles fails.
    fn spawn(&self, scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError>;

    /// The pipeline's plugin group for this scene.
    fn plugins(&self, scene: &Scene) -> PipelineGroup;

    /// Whether the run has ended.
    fn is_finished(&self, world: &World) -> bool;

    /// The number of steps of one run, when known in advance (for progress bars).
    fn total_steps(&self, _scene: &Scene) -> Option<u64> {
        None
    }

    /// A status line for progress bars.
    fn progress(&self, _world: &World) -> Option<String> {
        None
    }

    /// The summary of the current state (printed as JSON by `magsep run`).
    fn summary(&self, world: &World, run: &RunInfo) -> Value;

    /// Why a finished run counts as failed (exit code 1), judged from its summary.
    fn failure(&self, _summary: &Value) -> Option<String> {
        None
    }

    /// Called once after the schedule is built and before the first step, when recording:
    /// add what the viewer needs beyond particles (backdrops, colours) to the world or writer.
    fn prepare_recording(&self, _world: &mut World, _writer: &mut RecordingWriter) {}

    /// Run the scene in a way of the pipeline's own (e.g. replicates in parallel);
    /// `None` lets the driver run one simulation. It must honour [`RunOptions::stop`] as the
    /// driver does: pass it to every simulation it runs (each polls it between steps), start
    /// no more work once it is set, and return the summary of what ran, marked
    /// `"interrupted": true` and `"interrupted_by"` (`crate::sim::mark_interrupted`). A summary
    /// it computes itself should carry the keys [`Simulation::summary`](crate::sim::Simulation::summary)
    /// adds: the forces that acted (`crate::sim::force_keys`) and the plugins' keys
    /// (`crate::sim::summary_extras`).
    ///
    /// # Errors
    /// [`SimError`] of the run.
    fn run(
        &self,
        _scene: &Scene,
        _options: &RunOptions,
        _progress: &dyn Progress,
    ) -> Option<Result<Value, SimError>> {
        None
    }

    /// The summary recomputed from a recording (`magsep replay`).
    ///
    /// # Errors
    /// [`ReplayError`] when the recording does not fit.
    fn replay(&self, rec: &Recording, scene: &Scene, seed: u64) -> Result<Value, ReplayError>;

    /// Restore the dynamic state of a recorded frame into a freshly spawned world, bitwise,
    /// so that the run continues as if never interrupted (`magsep replay --resume`).
    ///
    /// # Errors
    /// [`ReplayError::Unsupported`] when the pipeline cannot resume (the default).
    fn apply_frame(&self, _world: &mut World, _frame: &ParticleFrame) -> Result<(), ReplayError> {
        Err(ReplayError::Unsupported(format!(
            "the {} pipeline does not record enough state to resume a run",
            self.name()
        )))
    }
}

/// The pipelines and plugin scene kinds a program knows. `Registry::default()` holds the
/// built-in pipelines (`packing`, `brownian`, `particle_fluid`).
///
/// ```
/// let registry = magsep::scene::Registry::default();
/// assert!(registry.pipeline("packing").is_some());
/// assert!(registry.pipeline("no_such_pipeline").is_none());
/// ```
#[derive(Clone)]
pub struct Registry {
    pipelines: Vec<Arc<dyn Pipeline>>,
    kinds: Vec<Arc<dyn SceneKind>>,
}

impl Registry {
    /// A registry with nothing in it.
    pub fn empty() -> Self {
        Self {
            pipelines: Vec::new(),
            kinds: Vec::new(),
        }
    }

    /// Add `pipeline` (replacing one of the same name).
    pub fn with_pipeline(mut self, pipeline: impl Pipeline) -> Self {
        self.register(Arc::new(pipeline));
        self
    }

    /// Add `pipeline` (replacing one of the same name).
    pub fn register(&mut self, pipeline: Arc<dyn Pipeline>) {
        self.pipelines.retain(|p| p.name() != pipeline.name());
        self.pipelines.push(pipeline);
    }

    /// Add a plugin scene kind (a top-level key any pipeline's scene may hold).
    pub fn with_kind(mut self, kind: impl SceneKind + 'static) -> Self {
        self.kinds.push(Arc::new(kind));
        self
    }

    /// The pipeline named `name`.
    pub fn pipeline(&self, name: &str) -> Option<&Arc<dyn Pipeline>> {
        self.pipelines.iter().find(|p| p.name() == name)
    }

    /// The registered pipelines, in registration order.
    pub fn pipelines(&self) -> impl Iterator<Item = &Arc<dyn Pipeline>> {
        self.pipelines.iter()
    }

    /// Names of the registered pipelines.
    pub fn names(&self) -> Vec<&'static str> {
        self.pipelines.iter().map(|p| p.name()).collect()
    }

    /// The scene kind registered for `key`.
    pub fn kind(&self, key: &str) -> Option<&Arc<dyn SceneKind>> {
        self.kinds.iter().find(|k| k.key() == key)
    }

    /// Keys of the registered scene kinds.
    pub fn kind_keys(&self) -> Vec<String> {
        self.kinds.iter().map(|k| k.key().to_string()).collect()
    }
}
