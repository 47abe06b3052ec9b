//! The `particle_fluid` pipeline: inertial particles in a magnetised liquid (magnetic density
//! separation), one-way coupled to a prescribed flow, with the Basset history force and
//! hard-particle collisions.

pub mod replay;
pub mod scene;
pub mod spawn;
pub mod summary;
mod validate;
pub mod view;

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::group::PipelineGroup;
use magsep_plugins::particle_fluid::particle_fluid_pipeline;
use magsep_plugins::record::{Recording, RecordingWriter};
use magsep_plugins::recorder::ParticleColours;
use magsep_systems::fluid::config::ParticleFluidConfig;
use serde_json::Value;

use crate::error::{ReplayError, SpawnError};
use crate::scene::{ParseContext, Pipeline, RunInfo, Scene, SceneSection};
pub use scene::{FluidContainerSpec, ParticleFluidScene};
pub use summary::{explicit_stability, run_summary, separation_json};

/// The particle-fluid pipeline (registered as `particle_fluid`).
#[derive(Debug, Clone, Copy, Default)]
pub struct ParticleFluidPipeline;

impl Pipeline for ParticleFluidPipeline {
    fn name(&self) -> &'static str {
        "particle_fluid"
    }

    fn memory_estimate(&self, scene: &Scene) -> crate::scene::memory::MemoryEstimate {
        use magsep_systems::fluid::config::HistoryChoice;
        let base = crate::scene::memory::MemoryEstimate::per_particle(scene, 4096.0);
        let Some(pf) = scene.section::<ParticleFluidScene>() else {
            return base;
        };
        // the Basset history keeps 2 x 64 bytes per particle and past step: measured 61
        // bytes at a 200-step window, doubled
        let s = &pf.section;
        let steps = match s.history {
            _ if !s.terms.history => 0.0,
            HistoryChoice::Full => (s.duration / s.time_step).ceil(),
            HistoryChoice::Window { window, .. } => (window / s.time_step).ceil(),
        };
        let per_particle = 4096.0 + 128.0 * steps;
        let mut estimate = crate::scene::memory::MemoryEstimate::per_particle(scene, per_particle);
        if steps * 128.0 > 4096.0 {
            estimate.key = "particle_fluid.history".into();
            estimate.detail = format!(
                "{} particles, each with {steps} past steps of Basset history",
                scene.total_particles()
            );
        }
        estimate
    }

    fn uses_fibres(&self) -> bool {
        false
    }

    fn description(&self) -> &'static str {
        "inertial particles levitating and colliding in a magnetised liquid"
    }

    fn sections(&self) -> &'static [&'static str] {
        &[
            "particle_fluid",
            "liquid",
            "magnet",
            "collisions",
            "container",
        ]
    }

    fn particle_keys(&self) -> &'static [&'static str] {
        &[
            "placement",
            "density",
            "density_ratios",
            "velocity",
            "orientation",
            "volume_fraction",
        ]
    }

    fn parse(&self, cx: &mut ParseContext<'_>) -> Option<SceneSection> {
        let section = cx.required("particle_fluid", "particle_fluid");
        let liquid = cx.required("liquid", "particle_fluid");
        let magnet = cx.section("magnet");
        let collisions = cx.section("collisions");
        let container = cx.section::<FluidContainerSpec>("container");
        let bad_container = cx.table.contains_key("container") && container.is_none();
        let (section, liquid) = (section?, liquid?);
        if bad_container {
            return None;
        }
        let pf = ParticleFluidScene {
            section,
            liquid,
            magnet,
            collisions: collisions.unwrap_or_default(),
            container: container.unwrap_or(FluidContainerSpec::Unbounded {}),
        };
        scene::validate(&pf, cx.particles, cx.errors);
        Some(SceneSection::new(pf))
    }

    fn spawn(&self, scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError> {
        let pf = scene
            .section::<ParticleFluidScene>()
            .ok_or_else(|| SpawnError::Other("not a particle_fluid scene".into()))?;
        spawn::spawn_particle_fluid(scene, pf, world, seed)
    }

    fn plugins(&self, scene: &Scene) -> PipelineGroup {
        particle_fluid_pipeline(
            scene
                .section::<ParticleFluidScene>()
                .is_some_and(|pf| pf.section.terms.collisions),
        )
    }

    fn is_finished(&self, world: &World) -> bool {
        world
            .get_resource::<ParticleFluidConfig>()
            .is_none_or(|c| world.resource::<StepClock>().step >= c.steps)
    }

    fn total_steps(&self, scene: &Scene) -> Option<u64> {
        scene
            .section::<ParticleFluidScene>()
            .map(|pf| pf.config().steps)
    }

    fn summary(&self, world: &World, run: &RunInfo) -> Value {
        run_summary(world, run.seed, run.wall_time_s)
    }

    fn prepare_recording(&self, world: &mut World, writer: &mut RecordingWriter) {
        let Some(cfg) = world.get_resource::<ParticleFluidConfig>().cloned() else {
            return;
        };
        let mut rows: Vec<(ParticleId, f64)> = world
            .query::<(&ParticleId, &InertialBody)>()
            .iter(world)
            .map(|(id, b)| (*id, b.density))
            .collect();
        rows.sort_by_key(|r| r.0);
        world.insert_resource(ParticleColours(
            rows.iter()
                .map(|r| view::density_colour(&cfg, r.1))
                .collect(),
        ));
        let edges = world.resource::<Container>().edges();
        writer.set_backdrop(view::magnet_backdrop(&cfg, edges));
    }

    fn replay(&self, rec: &Recording, scene: &Scene, seed: u64) -> Result<Value, ReplayError> {
        replay::replay_particle_fluid(rec, scene, seed)
    }
}
