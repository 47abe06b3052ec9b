//! The `packing` pipeline: mechanical contraction (thesis 000, ch. 2-3).
//!
//! | plugin | set | system | touches |
//! |---|---|---|---|
//! | [`McmCompressionPlugin`] | `Prepare` | `begin_compression_step` | `McmWorkspace`, `PackingStatus` |
//! | | `FinalizeSystems::Settle` | `settle_compression_step` | `McmWorkspace`, `PackingStatus` |
//! | | `FinalizeSystems::WriteBack` | `write_back_particles` | `McmWorkspace`, `Container`, `Position`, `Orientation` |
//! | [`McmOverlapRemovalPlugin`] | `Constraints` | `remove_overlaps_mcm` | `McmWorkspace`, `PackingStatus` |
//! | [`PackingObservePlugin`] | `Observe` (gated) and the replay schedule | `observe_packing` | reads particles, writes `PackingObservables` |
//!
//! The compression plugin's `finish` hook gathers the spawned particles into the dense
//! `McmWorkspace` (resources `PackingConfig`, `Container`, `RunSeed` must exist).

use bevy_ecs::prelude::*;
use magsep_systems::packing::systems::*;
use magsep_systems::sets::SimSystems;

use crate::app::{SimApp, SimPlugin};
use crate::core::{CorePlugin, FinalizeSystems};
use crate::group::PipelineGroup;
use crate::recorder::RecordPlugin;

/// Compression steps with revert and refinement of the volume step.
#[derive(Debug, Clone, Copy, Default)]
pub struct McmCompressionPlugin;

impl SimPlugin for McmCompressionPlugin {
    fn build(&self, app: &mut SimApp) {
        app.schedule.add_systems((
            begin_compression_step.in_set(SimSystems::Prepare),
            settle_compression_step.in_set(FinalizeSystems::Settle),
            write_back_particles.in_set(FinalizeSystems::WriteBack),
        ));
    }

    fn finish(&self, world: &mut World) {
        init_mcm_workspace(world);
    }
}

/// Overlap removal by the MCM move rules.
#[derive(Debug, Clone, Copy, Default)]
pub struct McmOverlapRemovalPlugin;

impl SimPlugin for McmOverlapRemovalPlugin {
    fn build(&self, app: &mut SimApp) {
        app.schedule
            .add_systems(remove_overlaps_mcm.in_set(SimSystems::Constraints));
    }
}

/// Packing fraction, contact number and nematic order.
#[derive(Debug, Clone, Copy, Default)]
pub struct PackingObservePlugin;

impl SimPlugin for PackingObservePlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<PackingObservables>();
        app.schedule.add_systems(
            observe_packing
                .run_if(should_observe)
                .in_set(SimSystems::Observe),
        );
        app.observe.add_systems(observe_packing);
    }
}

/// The packing pipeline: core, compression, overlap removal, observation, recording (the
/// recorder does nothing unless a `Recorder` resource holds a writer).
pub fn packing_pipeline() -> PipelineGroup {
    PipelineGroup::new()
        .add(CorePlugin)
        .add(McmCompressionPlugin)
        .add(McmOverlapRemovalPlugin)
        .add(PackingObservePlugin)
        .add(RecordPlugin)
}
