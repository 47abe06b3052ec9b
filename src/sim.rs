//! The [`Simulation`] builder: scene -> world -> pipeline -> run, with optional recording.

use std::path::{Path, PathBuf};
use std::time::Instant;

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::app::SimApp;
use magsep_plugins::brownian::brownian_pipeline;
use magsep_plugins::group::PipelineGroup;
use magsep_plugins::packing::packing_pipeline;
use magsep_plugins::particle_fluid::particle_fluid_pipeline;
use magsep_plugins::record::{FibreShape, RecordError, RecordingMetadata, RecordingWriter};
use magsep_plugins::recorder::Recorder;

use crate::scene::{RecordEvery, Scene, SpawnError, spawn_scene};
use crate::summary::packing_summary;

/// Errors while building or running a simulation.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scene could not be spawned (e.g. random insertion failed).
    #[error("spawning the scene failed: {0}")]
    Spawn(#[from] SpawnError),
    /// The schedule could not be built (ambiguity, cycle).
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

/// Options of a run beyond the scene.
#[derive(Clone, Default)]
pub struct RunOptions {
    /// Seed overriding `simulation.seed`.
    pub seed: Option<u64>,
    /// Write an MCAP recording here.
    pub record: Option<PathBuf>,
    /// Use this pipeline instead of the scene's built-in one (custom plugins).
    pub pipeline: Option<PipelineGroup>,
    /// Run the schedule on one thread.
    pub single_threaded: bool,
    /// Continue from this recorded frame (brownian pipeline; see `magsep replay --resume`).
    pub resume_from: Option<magsep_plugins::record::ParticleFrame>,
}

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
    /// Pipeline name.
    pub pipeline: String,
    /// Seed of the run.
    pub seed: u64,
    started: Instant,
}

impl Simulation {
    /// Spawn `scene`, build its pipeline and open the recording.
    ///
    /// # Errors
    /// [`SimError`] when spawning, building the schedule or opening the recording fails.
    pub fn from_scene(scene: &Scene, options: RunOptions) -> Result<Self, SimError> {
        let Some(simulation) = &scene.simulation else {
            return Err(SimError::NothingToRun);
        };
        let seed = options.seed.unwrap_or(simulation.seed);
        let mut app = SimApp::new();
        if options.single_threaded {
            app.schedule
                .set_executor(bevy_ecs::schedule::SingleThreadedExecutor::new());
        }
        spawn_scene(scene, &mut app.world, seed)?;
        if let Some(frame) = &options.resume_from {
            crate::brownian::replay::apply_frame(&mut app.world, frame)
                .map_err(|e| SimError::Resume(e.to_string()))?;
        }
        let brownian = scene.brownian_section().is_some();
        let pipeline = if brownian {
            "brownian"
        } else if scene.particle_fluid.is_some() {
            "particle_fluid"
        } else {
            "packing"
        };
        let group = options.pipeline.clone().unwrap_or_else(|| match pipeline {
            "brownian" => brownian_pipeline(),
            "particle_fluid" => particle_fluid_pipeline(
                scene
                    .particle_fluid
                    .as_ref()
                    .is_some_and(|pf| pf.section.terms.collisions),
            ),
            _ => packing_pipeline(),
        });
        group.build(&mut app);
        app.finish().map_err(|e| SimError::Schedule(e.0))?;
        if let Some(cfg) = app
            .world
            .get_resource::<magsep_systems::fluid::config::ParticleFluidConfig>()
            .cloned()
        {
            let mut rows: Vec<(ParticleId, f64)> = app
                .world
                .query::<(&ParticleId, &InertialBody)>()
                .iter(&app.world)
                .map(|(id, b)| (*id, b.density))
                .collect();
            rows.sort_by_key(|r| r.0);
            app.world
                .insert_resource(magsep_plugins::recorder::ParticleColours(
                    rows.iter()
                        .map(|r| crate::particle_fluid::view::density_colour(&cfg, r.1))
                        .collect(),
                ));
        }
        if let Some(path) = &options.record {
            let meta = RecordingMetadata {
                scene_text: scene.text.clone(),
                seed,
                version: env!("CARGO_PKG_VERSION").to_string(),
                pipeline: pipeline.into(),
                schedule: app.resolved_schedule(),
                dt: app.world.resource::<StepClock>().dt,
            };
            let mut writer = RecordingWriter::create(path, &meta)?;
            // the fibres as spawned (stable order by FibreId)
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
            writer.set_walls(app.world.resource::<Container>().walls());
            if let Some(cfg) = app
                .world
                .get_resource::<magsep_systems::fluid::config::ParticleFluidConfig>()
            {
                let edges = app.world.resource::<Container>().edges();
                writer.set_backdrop(crate::particle_fluid::view::magnet_backdrop(cfg, edges));
            }
            let mut shapes: Vec<_> = app
                .world
                .query::<(&ParticleId, &Shape)>()
                .iter(&app.world)
                .map(|(id, s)| (*id, *s))
                .collect();
            shapes.sort_by_key(|r| r.0);
            if shapes.iter().any(|r| r.1.is_superquadric()) {
                writer.set_semi_axes(
                    shapes
                        .iter()
                        .map(|r| match r.1 {
                            Shape::Superquadric { semi_axes, .. } => semi_axes,
                            _ => glam::DVec3::ZERO,
                        })
                        .collect(),
                );
            }
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
            pipeline: pipeline.into(),
            seed,
            started: Instant::now(),
        })
    }

    /// Run one step.
    pub fn step(&mut self) {
        self.app.step();
    }

    /// Whether the run has ended.
    pub fn is_finished(&self) -> bool {
        if let Some(c) = self.app.world.get_resource::<BrownianConfig>() {
            return self.app.world.resource::<StepClock>().step >= c.steps;
        }
        if let Some(c) = self
            .app
            .world
            .get_resource::<magsep_systems::fluid::config::ParticleFluidConfig>()
        {
            return self.app.world.resource::<StepClock>().step >= c.steps;
        }
        self.app
            .world
            .get_resource::<PackingStatus>()
            .map(|s| s.stopped.is_some())
            .unwrap_or(true)
    }

    /// Step until the run ends; `on_step` sees the world after every step. Finishes the
    /// recording and returns the summary.
    ///
    /// # Errors
    /// A recording write failure or a reported numerical failure.
    pub fn run(&mut self, mut on_step: impl FnMut(&World)) -> Result<serde_json::Value, SimError> {
        self.started = Instant::now();
        while !self.is_finished() {
            self.step();
            on_step(&self.app.world);
            if let Some(h) = self.app.world.get_resource::<Health>()
                && h.is_failed()
            {
                return Err(SimError::Health(h.messages.join("; ")));
            }
        }
        let summary = self.summary();
        self.finish_recording(&summary)?;
        Ok(summary)
    }

    /// The JSON summary of the current state.
    pub fn summary(&self) -> serde_json::Value {
        if self.pipeline == "particle_fluid" {
            return crate::particle_fluid::run_summary(
                &self.app.world,
                self.seed,
                self.started.elapsed().as_secs_f64(),
            );
        }
        if self.pipeline == "brownian" {
            return crate::brownian::run_summary(
                &self.app.world,
                self.seed,
                self.started.elapsed().as_secs_f64(),
            );
        }
        packing_summary(
            &self.app.world,
            self.seed,
            self.started.elapsed().as_secs_f64(),
        )
    }

    /// Write the summary into the recording and close it.
    ///
    /// # Errors
    /// A recording write failure.
    pub fn finish_recording(&mut self, summary: &serde_json::Value) -> Result<(), SimError> {
        if let Some(mut rec) = self.app.world.remove_resource::<Recorder>() {
            if let Some(e) = rec.error.take() {
                return Err(SimError::Record(RecordError::InvalidInput { detail: e }));
            }
            if let Some(mut w) = rec.writer.take() {
                w.write_summary(&summary.to_string())?;
                w.finish()?;
            }
        }
        Ok(())
    }
}

/// Load, spawn and run a scene file to the end (convenience for tests and examples).
///
/// # Errors
/// Scene errors (as text) or run errors.
pub fn run_scene_file(path: &Path, options: RunOptions) -> Result<serde_json::Value, String> {
    let scene = crate::scene::load_scene(path, &Default::default()).map_err(|e| e.to_string())?;
    let mut sim = Simulation::from_scene(&scene, options).map_err(|e| e.to_string())?;
    sim.run(|_| {}).map_err(|e| e.to_string())
}
