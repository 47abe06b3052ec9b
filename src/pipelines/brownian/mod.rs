//! The `brownian` pipeline: Brownian dynamics of magnetic nanoparticles around magnetised
//! fibres, with capture, replicates run in parallel, replay of the capture curves and resume.

pub mod ensemble;
pub mod flow;
pub mod placement;
pub mod replay;
pub mod scene;
#[cfg(test)]
mod scene_tests;
pub mod stats;
pub mod summary;

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::brownian::brownian_pipeline;
use magsep_plugins::group::PipelineGroup;
use magsep_plugins::record::{ParticleFrame, Recording, RecordingWriter};
use magsep_plugins::recorder::{ColourProvider, FrameStatusProviders};
use serde_json::Value;

use crate::error::{ReplayError, SimError, SpawnError};
use crate::scene::{
    ExecutorChoice, ParseContext, Pipeline, Progress, RunInfo, RunOptions, Scene, SceneError,
    SceneSection, ShapeSpec,
};
pub use ensemble::run_ensemble;
pub use scene::BrownianSection;
pub use summary::{RunResult, StartRegions, run_result, run_summary, summary_of};

/// The brownian pipeline (registered as `brownian`).
#[derive(Debug, Clone, Copy, Default)]
pub struct BrownianPipeline;

impl Pipeline for BrownianPipeline {
    /// One chain of systems, each splitting its own work among rayon's threads: on bevy's
    /// multi-threaded executor the 2-thread LAMMPS-mirror run (10 648 particles) took 10-15 %
    /// more wall and CPU time and ten times the context switches.
    fn executor(&self) -> ExecutorChoice {
        ExecutorChoice::SingleThreaded
    }

    fn name(&self) -> &'static str {
        "brownian"
    }

    fn memory_estimate(&self, scene: &Scene) -> crate::scene::memory::MemoryEstimate {
        use magsep_components::brownian::MobilityChoice;
        let mut estimate = crate::scene::memory::MemoryEstimate::per_particle(scene, 5120.0);
        let Some(section) = scene.section::<BrownianSection>() else {
            return estimate;
        };
        // the dense 3N x 3N RPY mobility (72 N^2 bytes), and its Cholesky factor as much
        // again; auto takes Cholesky up to N = 300, a dense operator above
        let n = scene.total_particles() as f64;
        let dense = 72.0 * n * n;
        let hydro = match section.mobility.unwrap_or_default() {
            MobilityChoice::FreeDraining => 0.0,
            MobilityChoice::Cholesky => 2.0 * dense,
            // pair blocks (~100 per particle at 40 B) and at most a 320³ grid of six fields
            MobilityChoice::SpectralEwald => 4096.0 * n + 6.0 * 16.0 * 320f64.powi(3) / 2.0,
            _ => dense,
        };
        // replicates run in parallel, one world each
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
        let parallel = section.runs().min(threads) as f64;
        let per_run = estimate.bytes - crate::scene::memory::BASE_BYTES + hydro;
        estimate.bytes = crate::scene::memory::BASE_BYTES + parallel * per_run;
        if hydro > 0.0 {
            estimate.key = "brownian.mobility".into();
        }
        estimate.detail = format!(
            "{n} particles at 5 KB, {} of hydrodynamic mobility, times {parallel} replicates \
             in parallel",
            crate::scene::memory::gib(hydro)
        );
        estimate
    }

    fn description(&self) -> &'static str {
        "Brownian dynamics and capture of magnetic nanoparticles around magnetised fibres"
    }

    fn sections(&self) -> &'static [&'static str] {
        // `container` is listed to explain why it does not belong here
        &["brownian", "container"]
    }

    fn particle_keys(&self) -> &'static [&'static str] {
        &["moment", "placement"]
    }

    fn parse(&self, cx: &mut ParseContext<'_>) -> Option<SceneSection> {
        if cx.table.contains_key("container") {
            cx.error(
                "container",
                "the brownian pipeline runs in unbounded fluid around the fibres: remove [container]",
            );
        }
        let section = if cx.table.contains_key("brownian") {
            cx.section::<BrownianSection>("brownian")
        } else {
            cx.error(
                "brownian",
                "missing required table [brownian] (time_step, duration)",
            );
            None
        };
        if let Some(b) = &section {
            scene::validate_section(b, cx.errors);
        }
        let fibres = cx.fibres_valid.then_some(cx.fibres);
        for (i, g) in cx.particles.iter() {
            let p = format!("particles[{i}]");
            match g.shape {
                ShapeSpec::Sphere { radius } => scene::validate_group(
                    &p,
                    g.count,
                    radius,
                    g.moment.as_ref(),
                    g.placement.as_ref(),
                    fibres,
                    cx.errors,
                ),
                _ => cx.errors.push(SceneError::new(
                    format!("{p}.shape.kind"),
                    "the brownian pipeline simulates spheres only",
                )),
            }
        }
        section.map(SceneSection::new)
    }

    fn spawn(&self, scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError> {
        let section = scene
            .section::<BrownianSection>()
            .ok_or_else(|| SpawnError::Other("not a brownian scene".into()))?;
        placement::spawn_brownian(scene, section, world, seed)
    }

    fn plugins(&self, _scene: &Scene) -> PipelineGroup {
        brownian_pipeline()
    }

    fn is_finished(&self, world: &World) -> bool {
        world
            .get_resource::<BrownianConfig>()
            .is_none_or(|c| world.resource::<StepClock>().step >= c.steps)
    }

    fn total_steps(&self, scene: &Scene) -> Option<u64> {
        scene.section::<BrownianSection>().map(|s| s.steps())
    }

    fn summary(&self, world: &World, run: &RunInfo) -> Value {
        run_summary(world, run.seed, run.wall_time_s)
    }

    fn run(
        &self,
        scene: &Scene,
        options: &RunOptions,
        progress: &dyn Progress,
    ) -> Option<Result<Value, SimError>> {
        let section = scene.section::<BrownianSection>()?;
        let runs = section.runs();
        progress.set_total(section.steps() * runs);
        progress.message(format!("{runs} run(s)"));
        Some(run_ensemble(scene, runs, options, &|n| progress.advance(n)))
    }

    fn prepare_recording(&self, world: &mut World, _writer: &mut RecordingWriter) {
        world
            .get_resource_or_init::<FrameStatusProviders>()
            .set("brownian", replay::frame_status);
        world.insert_resource(ColourProvider(replay::capture_colours));
    }

    fn replay(&self, rec: &Recording, scene: &Scene, seed: u64) -> Result<Value, ReplayError> {
        replay::replay_brownian(rec, scene, seed)
    }

    fn apply_frame(&self, world: &mut World, frame: &ParticleFrame) -> Result<(), ReplayError> {
        replay::apply_frame(world, frame)
    }
}
