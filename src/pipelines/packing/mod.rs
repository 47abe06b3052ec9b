//! The `packing` pipeline: random dense packings by mechanical contraction (MCM schemes or
//! FIRE) in periodic boxes or hard containers.

pub mod geometry;
pub mod scene;
pub mod summary;

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_plugins::app::SimApp;
use magsep_plugins::group::PipelineGroup;
use magsep_plugins::packing::{PackingObservePlugin, packing_pipeline};
use magsep_plugins::record::{Recording, RecordingWriter};
use magsep_plugins::recorder::{FrameStatus, FrameStatusProviders};
use magsep_systems::packing::systems::McmWorkspace;
use magsep_systems::rng::rng_state_words;
use serde_json::Value;

use crate::error::{ReplayError, SpawnError};
use crate::replay::{last_frame, load_frame, recorded_wall_time};
use crate::scene::{ParseContext, Pipeline, RunInfo, Scene, SceneSection};
pub use scene::{ContainerSpec, PackingScene, PackingSection, packing_config};
pub use summary::{PACKING_SUMMARY_KEYS, packing_summary};

/// The packing pipeline (registered as `packing`).
#[derive(Debug, Clone, Copy, Default)]
pub struct PackingPipeline;

impl Pipeline for PackingPipeline {
    fn name(&self) -> &'static str {
        "packing"
    }

    fn memory_estimate(&self, scene: &Scene) -> crate::scene::memory::MemoryEstimate {
        // particles (twice the measured 1.6 KB each) and the neighbour grid: about one cell
        // of 16 bytes per particle diameter cubed of the start box, V_p / phi0 per particle
        let phi0 = scene::packing_config(scene).initial_packing_fraction;
        let per_cell = 16.0 * std::f64::consts::FRAC_PI_6 / phi0;
        crate::scene::memory::MemoryEstimate::per_particle(scene, 4096.0 + per_cell)
    }

    fn uses_fibres(&self) -> bool {
        false
    }

    fn description(&self) -> &'static str {
        "random dense packings by mechanical contraction"
    }

    fn sections(&self) -> &'static [&'static str] {
        &["container", "packing"]
    }

    fn parse(&self, cx: &mut ParseContext<'_>) -> Option<SceneSection> {
        scene::parse(cx).map(SceneSection::new)
    }

    fn spawn(&self, scene: &Scene, world: &mut World, seed: u64) -> Result<(), SpawnError> {
        scene::spawn_packing_particles(scene, world, seed)
    }

    fn plugins(&self, _scene: &Scene) -> PipelineGroup {
        packing_pipeline()
    }

    fn is_finished(&self, world: &World) -> bool {
        world
            .get_resource::<PackingStatus>()
            .map(|s| s.stopped.is_some())
            .unwrap_or(true)
    }

    fn progress(&self, world: &World) -> Option<String> {
        world.get_resource::<PackingStatus>().map(|s| {
            format!(
                "phi {:.4}  steps {}  failed {}  moves {}",
                s.packing_fraction, s.compression_steps, s.failed_steps, s.attempts
            )
        })
    }

    fn summary(&self, world: &World, run: &RunInfo) -> Value {
        packing_summary(world, run.seed, run.wall_time_s)
    }

    fn failure(&self, summary: &Value) -> Option<String> {
        (summary["stop_reason"] == "budget_too_small").then(|| {
            "no compression step succeeded: the volume step is too large for the attempt budget (see warnings)".into()
        })
    }

    fn prepare_recording(&self, world: &mut World, _writer: &mut RecordingWriter) {
        let mut p = world.get_resource_or_init::<FrameStatusProviders>();
        p.set("packing", |w| {
            w.get_resource::<PackingStatus>()
                .and_then(|s| serde_json::to_value(s).ok())
        });
        p.set("driver_rng", |w| {
            w.get_resource::<McmWorkspace>()
                .map(|ws| serde_json::json!(rng_state_words(&ws.rng)))
        });
    }

    fn replay(&self, rec: &Recording, scene: &Scene, seed: u64) -> Result<Value, ReplayError> {
        let frame = last_frame(rec)?;
        let mut app = SimApp::new();
        app.world.insert_resource(packing_config(scene));
        load_frame(&mut app.world, frame, Some(&scene.shapes()))?;
        let status: FrameStatus =
            serde_json::from_str(&frame.status_json).map_err(|e| ReplayError::BadFrame {
                step: frame.step,
                detail: format!("status_json: {e}"),
            })?;
        if let Some(s) =
            status
                .get::<PackingStatus>("packing")
                .map_err(|e| ReplayError::BadFrame {
                    step: frame.step,
                    detail: format!("status_json.packing: {e}"),
                })?
        {
            app.world.insert_resource(s);
        }
        app.add_plugin(&PackingObservePlugin);
        app.finish().map_err(|e| ReplayError::BadFrame {
            step: frame.step,
            detail: e.0,
        })?;
        app.observe_now();
        Ok(packing_summary(&app.world, seed, recorded_wall_time(rec)))
    }
}
