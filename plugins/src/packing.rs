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
//!
//! User forces: the MCM moves particles by geometric rules and never reads `NetForce`, so a
//! `ForceContribution` component is refused at `SimApp::finish`. External force kernels
//! (`SimApp::add_external_force`) act with the FIRE scheme, which adds them to the overlap
//! forces at every iteration (units and scaling: `magsep_systems::packing::external`); the
//! thesis's `original` and `revised` schemes have no forces and refuse them (see
//! [`packing_force_use`]).

use bevy_ecs::prelude::*;
use magsep_components::packing::{OverlapRemovalScheme, PackingConfig};
use magsep_systems::forces::{Consumption, ForceUse};
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

/// Overlap removal by the MCM move rules (FIRE: with the external force kernels).
#[derive(Debug, Clone, Copy, Default)]
pub struct McmOverlapRemovalPlugin;

impl SimPlugin for McmOverlapRemovalPlugin {
    fn build(&self, app: &mut SimApp) {
        app.schedule
            .add_systems(remove_overlaps_mcm.in_set(SimSystems::Constraints));
    }

    fn finish(&self, world: &mut World) {
        let scheme = world
            .get_resource::<PackingConfig>()
            .map_or(OverlapRemovalScheme::Fire, |c| c.scheme);
        world.insert_resource(packing_force_use(scheme));
    }
}

/// What the packing's overlap removal with `scheme` consumes: kernels with FIRE, never a
/// `ForceContribution` component.
///
/// ```
/// use magsep_components::packing::OverlapRemovalScheme;
/// use magsep_plugins::packing::packing_force_use;
/// use magsep_systems::forces::Consumption;
/// assert_eq!(packing_force_use(OverlapRemovalScheme::Fire).kernels, Consumption::Consumed);
/// assert_ne!(packing_force_use(OverlapRemovalScheme::Revised).kernels, Consumption::Consumed);
/// ```
pub fn packing_force_use(scheme: OverlapRemovalScheme) -> ForceUse {
    let kernels = match scheme {
        OverlapRemovalScheme::Fire => Consumption::Consumed,
        OverlapRemovalScheme::Original | OverlapRemovalScheme::Revised => {
            Consumption::Refused(format!(
                "the packing scheme {scheme:?} (the thesis's single-particle MCM moves) has no \
                 forces; use scheme = \"fire\", which minimises the overlap energy together \
                 with the kernels' potential"
            ))
        }
    };
    ForceUse {
        builtin: Vec::new(),
        contributions: Consumption::Refused(
            "the packing pipeline moves particles by geometric rules and never reads \
             NetForce; implement `magsep::systems::forces::ExternalForce` and register it \
             with `SimApp::add_external_force` (acts with scheme = \"fire\")"
                .into(),
        ),
        kernels,
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
