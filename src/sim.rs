//! The simulation driver: scene -> world -> the scene's pipeline -> run, with optional
//! recording. It knows no pipeline by name: every pipeline-specific step is a hook of the
//! scene's [`Pipeline`].

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::app::{SimApp, SimPlugin};
use magsep_plugins::group::PipelineGroup;
use magsep_plugins::record::{
    FibreShape, FrameBuffering, PluginInfo, RecordingMetadata, RecordingWriter,
};
use magsep_plugins::recorder::{FrameStatusProviders, Recorder, record_now, recording_error};
use magsep_systems::forces::{ExternalForces, ForceComponents, ForceRegistry};
use serde_json::Value;

pub use crate::error::SimError;
use crate::names::short_name;
pub use crate::scene::pipeline::{StopFlag, StopRequest};
pub use crate::scene::{ExecutorChoice, RunOptions};
use crate::scene::{NoProgress, Pipeline, Progress, RecordEvery, RunInfo, Scene, spawn_scene};

/// A simulation built from a scene.
///
/// ```no_run
/// use magsep::prelude::*;
/// let scene = magsep::scene::load_scene("scenes/spheres_500.toml".as_ref(), &Default::default()).unwrap();
/// let mut sim = Simulation::from_scene(&scene, RunOptions::default()).unwrap();
/// let summary = sim.run(|_| {}).unwrap();
/// println!("{summary}");
/// ```
pub struct Simulation {
    /// World and schedules.
    pub app: SimApp,
    /// The pipeline that runs the scene.
    pub pipeline: Arc<dyn Pipeline>,
    /// Seed of the run.
    pub seed: u64,
    /// Polled between steps: once set, [`run`](Self::run) ends after the current step.
    pub stop: Option<StopFlag>,
    started: Instant,
}

/// Build a [`Simulation`] step by step: extra plugins, a recording, a seed.
///
/// ```no_run
/// use magsep::prelude::*;
/// let scene = magsep::scene::load_scene("scenes/spheres_500.toml".as_ref(), &Default::default()).unwrap();
/// let summary = Simulation::builder(&scene)
///     .seed(3)
///     .record("out.mcap")
///     .build()
///     .unwrap()
///     .run(|_| {})
///     .unwrap();
/// ```
pub struct SimulationBuilder<'a> {
    scene: &'a Scene,
    options: RunOptions,
}

impl SimulationBuilder<'_> {
    /// Add `plugin` after the pipeline's own plugins.
    pub fn add_plugin(mut self, plugin: impl SimPlugin) -> Self {
        self.options.plugins.push(Arc::new(plugin));
        self
    }

    /// Use `group` instead of the pipeline's plugin group.
    pub fn plugins(mut self, group: PipelineGroup) -> Self {
        self.options.pipeline = Some(group);
        self
    }

    /// Record the run to `path` (MCAP).
    pub fn record(mut self, path: impl Into<PathBuf>) -> Self {
        self.options.record = Some(path.into());
        self
    }

    /// Override the scene's seed.
    pub fn seed(mut self, seed: u64) -> Self {
        self.options.seed = Some(seed);
        self
    }

    /// Stop the run early when `stop` is set (see [`StopFlag`]).
    pub fn stop_flag(mut self, stop: StopFlag) -> Self {
        self.options.stop = Some(stop);
        self
    }

    /// Run the schedule on one thread.
    pub fn single_threaded(mut self, yes: bool) -> Self {
        self.options.single_threaded = yes;
        self
    }

    /// How the schedule runs its systems (default: by the scene's size, see
    /// [`ExecutorChoice`]).
    pub fn executor(mut self, executor: ExecutorChoice) -> Self {
        self.options.executor = executor;
        self
    }

    /// Promise that nothing reads the force components during the run (see
    /// [`RunOptions::forces_unread`]).
    pub fn forces_unread(mut self, yes: bool) -> Self {
        self.options.forces_unread = yes;
        self
    }

    /// Spawn the scene, build the schedule, open the recording.
    ///
    /// # Errors
    /// As [`Simulation::from_scene`].
    pub fn build(self) -> Result<Simulation, SimError> {
        let scene = self.scene;
        Simulation::from_scene(scene, self.options)
    }
}

impl Simulation {
    /// A builder for `scene`.
    pub fn builder(scene: &Scene) -> SimulationBuilder<'_> {
        SimulationBuilder {
            scene,
            options: RunOptions::default(),
        }
    }

    /// Spawn `scene`, build its pipeline and open the recording.
    ///
    /// # Errors
    /// [`SimError`] when spawning, building the schedule or opening the recording fails.
    pub fn from_scene(scene: &Scene, options: RunOptions) -> Result<Self, SimError> {
        let (Some(simulation), Some(pipeline)) = (&scene.simulation, &scene.pipeline) else {
            return Err(SimError::NothingToRun);
        };
        let seed = options.seed.unwrap_or(simulation.seed);
        let mut app = SimApp::new();
        if let Some(stop) = &options.stop {
            app.world
                .insert_resource(crate::scene::pipeline::StopRequest(stop.clone()));
        }
        spawn_scene(scene, &mut app.world, seed)?;
        let particles = app
            .world
            .query_filtered::<(), With<ParticleId>>()
            .iter(&app.world)
            .count();
        let executor = match options.executor {
            ExecutorChoice::Auto => pipeline.executor(),
            chosen => chosen,
        };
        if options.single_threaded || !executor.multi_threaded(particles) {
            // steps inside rayon's pool where per-particle loops go parallel
            app.set_single_threaded(particles >= crate::scene::pipeline::SMALL_SCENE_PARTICLES);
        }
        if let Some(frame) = &options.resume_from {
            pipeline
                .apply_frame(&mut app.world, frame)
                .map_err(|e| SimError::Resume(e.to_string()))?;
        }
        let group = options
            .pipeline
            .clone()
            .unwrap_or_else(|| pipeline.plugins(scene));
        group.build(&mut app);
        for p in &options.plugins {
            app.add_boxed_plugin(p.clone());
        }
        if options.forces_unread && options.plugins.is_empty() && options.pipeline.is_none() {
            // only the pipeline's own systems run and the caller reads no force component
            app.world.insert_resource(ForceComponents::WorkspaceOnly);
        }
        app.finish().map_err(|e| SimError::Schedule(e.0))?;
        if let Some(frame) = &options.resume_from {
            // the plugins' own state, from the keys their status providers wrote
            let status = match frame.status_json.trim() {
                "" => Value::Object(Default::default()),
                text => serde_json::from_str(text)
                    .map_err(|e| SimError::Resume(format!("the frame's status: {e}")))?,
            };
            app.restore(&status).map_err(SimError::Resume)?;
        }
        if let Some(path) = &options.record {
            let writer = open_recording(&mut app, path, scene, pipeline.as_ref(), seed)?;
            let every = app
                .world
                .get_resource::<RecordEvery>()
                .map(|r| r.0)
                .unwrap_or(100);
            app.world.insert_resource(Recorder {
                writer: Some(writer),
                every,
                error: None,
                last_step: None,
            });
        }
        Ok(Self {
            app,
            pipeline: pipeline.clone(),
            seed,
            stop: options.stop.clone(),
            started: Instant::now(),
        })
    }

    /// Run one step.
    pub fn step(&mut self) {
        self.app.step();
    }

    /// Whether the run has ended.
    pub fn is_finished(&self) -> bool {
        self.pipeline.is_finished(&self.app.world)
    }

    /// Step until the run ends; `on_step` sees the world after every step. Records the first
    /// and the final frame, finishes the recording and returns the summary.
    ///
    /// When [`stop`](Self::stop) is set, the run ends after the current step: the final frame
    /// is recorded, the recording closed (with the reason, see
    /// `RecordingWriter::write_interrupted`), and the summary of what ran is returned, marked
    /// `"interrupted": true` and `"interrupted_by": reason`.
    ///
    /// # Errors
    /// A reported numerical failure; a recording write failure, at once (checked after every
    /// step), as [`SimError::Partial`] with the summary of what ran (what was written stays
    /// readable).
    pub fn run(&mut self, mut on_step: impl FnMut(&World)) -> Result<Value, SimError> {
        self.started = Instant::now();
        record_now(&mut self.app.world);
        let mut interrupted = None;
        loop {
            if let Some(e) = recording_error(&self.app.world) {
                return Err(self.stopped_by(SimError::RecordWrite(e.to_string())));
            }
            if self.is_finished() {
                break;
            }
            if let Some(reason) = self.stop.as_ref().and_then(StopFlag::reason) {
                interrupted = Some(reason);
                break;
            }
            self.step();
            on_step(&self.app.world);
            let failed = self
                .app
                .world
                .get_resource::<Health>()
                .filter(|h| h.is_failed())
                .map(|h| h.messages.join("; "));
            if let Some(why) = failed {
                record_now(&mut self.app.world);
                return Err(SimError::Health(why));
            }
        }
        record_now(&mut self.app.world);
        let mut summary = self.summary();
        if let Some(reason) = &interrupted {
            mark_interrupted(&mut summary, reason);
        }
        if let Err(e) = self.finish_recording(&summary) {
            return Err(partial(e, summary));
        }
        Ok(summary)
    }

    /// The run stops early on `error`: close the recording best-effort and attach the
    /// summary of what ran, marked interrupted.
    fn stopped_by(&mut self, error: SimError) -> SimError {
        // Dropping the writer closes the file best-effort; what was written stays readable.
        drop(self.app.world.remove_resource::<Recorder>());
        let mut summary = self.summary();
        mark_interrupted(&mut summary, "error");
        partial(error, summary)
    }

    /// The JSON summary of the current state (the pipeline's, plus the keys plugins added
    /// to [`SummaryExtras`]).
    pub fn summary(&self) -> Value {
        let run = RunInfo {
            seed: self.seed,
            wall_time_s: self.started.elapsed().as_secs_f64(),
        };
        let mut summary = self.pipeline.summary(&self.app.world, &run);
        if let Value::Object(map) = &mut summary {
            force_keys(&self.app.world, map);
            summary_extras(&self.app.world, map);
        }
        summary
    }

    /// Write the summary into the recording and close it; a summary marked
    /// `"interrupted_by"` (see [`mark_interrupted`]) also writes the recording's interrupted
    /// record.
    ///
    /// # Errors
    /// A recording write failure (also one that happened earlier in the run).
    pub fn finish_recording(&mut self, summary: &Value) -> Result<(), SimError> {
        if let Some(mut rec) = self.app.world.remove_resource::<Recorder>() {
            if let Some(e) = rec.error.take() {
                return Err(SimError::RecordWrite(e));
            }
            if let Some(mut w) = rec.writer.take() {
                if let Some(reason) = summary.get("interrupted_by").and_then(Value::as_str) {
                    w.write_interrupted(reason)?;
                }
                w.write_summary_value(summary)?;
                w.finish()?;
            }
        }
        Ok(())
    }
}

/// Mark `summary` (an object) as the summary of a run stopped early: `"interrupted": true`,
/// `"interrupted_by": reason`.
pub fn mark_interrupted(summary: &mut Value, reason: &str) {
    if let Value::Object(map) = summary {
        map.insert("interrupted".into(), Value::Bool(true));
        map.insert("interrupted_by".into(), Value::String(reason.into()));
    }
}

/// `error` with `summary` attached, the error's message added to it as `"run_error"` (an
/// error that already carries a summary gives up that summary for this one).
pub fn partial(error: SimError, mut summary: Value) -> SimError {
    let error = error.into_cause();
    if let Value::Object(map) = &mut summary {
        map.insert("run_error".into(), Value::String(error.to_string()));
    }
    SimError::Partial {
        error: Box::new(error),
        summary: Box::new(summary),
    }
}

/// A function giving one summary key from the final world (`None`: leave the key out).
pub type SummaryFn = fn(&World) -> Option<Value>;

/// Keys plugins add to the run's summary: (key, function of the final world) (a resource).
#[derive(Resource, Default, Clone)]
pub struct SummaryExtras(pub Vec<(String, SummaryFn)>);

/// Open the recording of `app` at `path`: metadata (scene, seed, schedule, plugins), fibres,
/// walls, shapes, and what the pipeline adds.
fn open_recording(
    app: &mut SimApp,
    path: &Path,
    scene: &Scene,
    pipeline: &dyn Pipeline,
    seed: u64,
) -> Result<RecordingWriter, SimError> {
    let meta = RecordingMetadata {
        scene_text: scene.text.clone(),
        seed,
        version: env!("CARGO_PKG_VERSION").to_string(),
        pipeline: pipeline.name().into(),
        schedule: app.resolved_schedule(),
        dt: app.world.resource::<StepClock>().dt,
        plugins: app
            .plugin_infos()
            .into_iter()
            .map(|(name, params)| PluginInfo { name, params })
            .collect(),
        extra: overrides_metadata(&scene.overrides),
    };
    let mut meta = meta;
    meta.extra
        .insert(FORCES_KEY.to_string(), forces_metadata(&app.world));
    // the header, encoding, compression and writes run on a writer thread of their own
    let mut writer = RecordingWriter::create_background(path, &meta)?;
    if !scene.record.as_ref().is_some_and(|r| r.flush_every_frame) {
        writer.buffer_frames(Some(FrameBuffering::default()));
    }
    let mut fibres: Vec<_> = app
        .world
        .query::<(&FibreId, &Fibre)>()
        .iter(&app.world)
        .map(|(id, f)| (*id, *f))
        .collect();
    fibres.sort_by_key(|(id, _)| *id);
    writer.set_fibres(
        fibres
            .iter()
            .map(|(_, f)| FibreShape {
                center: f.center,
                axis: f.axis,
                radius: f.radius,
                half_length: f.half_length,
            })
            .collect(),
    );
    if let Some(c) = app.world.get_resource::<Container>() {
        writer.set_walls(c.walls());
    }
    let mut shapes: Vec<_> = app
        .world
        .query::<(&ParticleId, &Shape)>()
        .iter(&app.world)
        .map(|(id, s)| (*id, *s))
        .collect();
    shapes.sort_by_key(|r| r.0);
    if shapes.iter().any(|r| r.1.as_superquadric().is_some()) {
        writer.set_semi_axes(
            shapes
                .iter()
                .map(|r| r.1.as_superquadric().map(|s| s.0).unwrap_or_default())
                .collect(),
        );
    }
    // the pipeline's status keys are set here, after the plugins': a plugin's key of the same
    // name would be replaced without a word, so it is refused
    let plugins_keys = app.world.remove_resource::<FrameStatusProviders>();
    pipeline.prepare_recording(&mut app.world, &mut writer);
    if let Some(plugins_keys) = plugins_keys {
        let mut keys = app.world.get_resource_or_init::<FrameStatusProviders>();
        for (key, f) in plugins_keys.0 {
            if key == "container" || keys.0.iter().any(|(k, _)| *k == key) {
                drop(writer);
                let _ = std::fs::remove_file(path);
                return Err(SimError::Schedule(format!(
                    "a plugin's frame-status key `{key}` is {}: rename it",
                    if key == "container" {
                        "the recorder's own (the frame's walls)".to_string()
                    } else {
                        format!("the {} pipeline's own", pipeline.name())
                    }
                )));
            }
            keys.0.push((key, f));
        }
    }
    Ok(writer)
}

/// The recording's `extra` metadata for the overrides applied to the scene: key `overrides`,
/// a JSON list of `PATH=VALUE` strings (nothing when there are none).
fn overrides_metadata(overrides: &[String]) -> std::collections::BTreeMap<String, String> {
    let mut extra = std::collections::BTreeMap::new();
    if !overrides.is_empty() {
        extra.insert(
            OVERRIDES_KEY.to_string(),
            serde_json::to_string(overrides).unwrap_or_default(),
        );
    }
    extra
}

/// The key of [`RecordingMetadata::extra`] that lists the overrides of the run (a JSON list of
/// `PATH=VALUE` strings); the recorded scene text already has them applied.
pub const OVERRIDES_KEY: &str = "overrides";

/// The key of [`RecordingMetadata::extra`] that holds the forces of the run
/// ([`forces_metadata`]): a resume refuses a program whose forces differ.
pub const FORCES_KEY: &str = "forces";

/// The forces registered in `world` as recorded under [`FORCES_KEY`]: a JSON object with
/// `force_contributions` (full type names, in summation order) and `force_kernels` (the
/// external kernels' names, in order).
pub fn forces_metadata(world: &World) -> String {
    let contributions = world
        .get_resource::<ForceRegistry>()
        .map(|r| r.names.clone())
        .unwrap_or_default();
    let kernels: Vec<String> = world
        .get_resource::<ExternalForces>()
        .map(|k| k.names().into_iter().map(String::from).collect())
        .unwrap_or_default();
    serde_json::json!({"force_contributions": contributions, "force_kernels": kernels}).to_string()
}

/// Run `scene` to the end the pipeline's way (one simulation, or e.g. replicates), reporting
/// to `progress`; returns the summary. A set [`RunOptions::stop`] ends the run early with the
/// summary of what ran, marked interrupted (see [`StopFlag`]).
///
/// # Errors
/// [`SimError`] of the run ([`SimError::Partial`] with the summary of what ran when a
/// recording write failed mid-run).
pub fn run_scene(
    scene: &Scene,
    options: &RunOptions,
    progress: &dyn Progress,
) -> Result<Value, SimError> {
    let pipeline = scene.pipeline.clone().ok_or(SimError::NothingToRun)?;
    let mut result = match pipeline.run(scene, options, progress) {
        Some(result) => result,
        None => run_steps(scene, options, progress, pipeline.as_ref()),
    };
    // what `[[fibre_packings]] pack` packed, also where the pipeline ran its own way
    if let (Ok(Value::Object(map)), false) = (&mut result, scene.packed_columns.is_empty()) {
        map.entry("fibre_packings")
            .or_insert_with(|| Value::Array(scene.packed_columns.clone()));
    }
    result
}

/// [`run_scene`] for a pipeline without its own `run`: one simulation, step by step.
fn run_steps(
    scene: &Scene,
    options: &RunOptions,
    progress: &dyn Progress,
    pipeline: &dyn Pipeline,
) -> Result<Value, SimError> {
    if let Some(n) = pipeline.total_steps(scene) {
        progress.set_total(n);
    }
    let mut sim = Simulation::from_scene(scene, options.clone())?;
    let mut last = 0u64;
    sim.run(|w| {
        let step = w.get_resource::<StepClock>().map(|c| c.step).unwrap_or(0);
        progress.advance(step.saturating_sub(last));
        last = step;
        if let Some(m) = pipeline.progress(w) {
            progress.message(m);
        }
    })
}

/// Load, spawn and run a scene file to the end (convenience for tests and examples).
///
/// # Errors
/// Scene errors (as text) or run errors.
pub fn run_scene_file(path: &Path, options: RunOptions) -> Result<Value, String> {
    let scene = crate::scene::load_scene(path, &Default::default()).map_err(|e| e.to_string())?;
    run_scene(&scene, &options, &NoProgress).map_err(|e| e.to_string())
}

/// The summary's `force_contributions` (every registered force contribution in summation
/// order, the pipeline's and the plugins', type names without paths; a pipeline registers its
/// contributions whether or not the scene switches them on: its own keys say which act) and
/// `force_kernels` (the registered external force kernels' names), both `[]` when nothing is
/// registered; a key the pipeline set is kept.
pub fn force_keys(world: &World, map: &mut serde_json::Map<String, Value>) {
    let names: Vec<String> = (world.get_resource::<ForceRegistry>())
        .map(|r| r.names.iter().map(|n| short_name(n)).collect())
        .unwrap_or_default();
    map.entry("force_contributions").or_insert(names.into());
    let kernels: Vec<&str> = (world.get_resource::<ExternalForces>())
        .map(|k| k.names())
        .unwrap_or_default();
    map.entry("force_kernels").or_insert(kernels.into());
}

/// The keys plugins added to [`SummaryExtras`], computed on `world`, into `map` (see
/// [`merge_plugin_keys`]).
pub fn summary_extras(world: &World, map: &mut serde_json::Map<String, Value>) {
    merge_plugin_keys(map, plugin_summary_keys(world));
}

/// The keys plugins added to [`SummaryExtras`], computed on `world`.
pub fn plugin_summary_keys(world: &World) -> serde_json::Map<String, Value> {
    let mut out = serde_json::Map::new();
    if let Some(extra) = world.get_resource::<SummaryExtras>() {
        for (k, f) in &extra.0 {
            if let Some(v) = f(world) {
                out.insert(k.clone(), v);
            }
        }
    }
    out
}

/// Add the plugins' `keys` to the summary `map`. A key the summary already has (the
/// pipeline's or the driver's) is kept, and the plugin's value left out with a line in the
/// summary's `warnings` naming the key.
pub fn merge_plugin_keys(
    map: &mut serde_json::Map<String, Value>,
    keys: serde_json::Map<String, Value>,
) {
    for (k, v) in keys {
        if !map.contains_key(&k) {
            map.insert(k, v);
            continue;
        }
        let line = format!(
            "a plugin's summary key `{k}` is also the summary's own key: the plugin's value is \
             left out (rename the key)"
        );
        match map.entry("warnings").or_insert(Value::Array(Vec::new())) {
            Value::Array(w) => w.push(line.into()),
            other => *other = Value::Array(vec![other.take(), line.into()]),
        }
    }
}
