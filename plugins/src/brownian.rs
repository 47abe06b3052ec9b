//! The `brownian` pipeline: Brownian dynamics of magnetic nanoparticles around magnetised
//! fibres (thesis 000, ch. 6).
//!
//! | plugin | set | system | touches |
//! |---|---|---|---|
//! | [`BrownianForcesPlugin`] | `Prepare` | `prepare_brownian_step` | `BrownianWorkspace` |
//! | | `Forces::Field` | `compute_field_forces` | `FieldForce`, `MagneticMoment` |
//! | | `Forces::Dipole` | `compute_dipole_forces` | `DipoleForce` |
//! | | `Forces::Contact` | `compute_contact_forces` | `ContactForce` |
//! | [`BrownianIntegratorPlugin`] | `Mobility` | `prepare_mobility` | `BrownianWorkspace`, `BrownianStats`, `Health` |
//! | | `Integrate` | `integrate_brownian` | `BrownianWorkspace`, `BrownianStats`, `Health` |
//! | | `FinalizeSystems::WriteBack` | `write_back_brownian` | `Position`, `Captured`, `ParticleRng` |
//! | [`CaptureObservePlugin`] | `Observe` (gated) | `observe_capture` | `CaptureCurve` |
//!
//! Contributions `FieldForce`, `DipoleForce`, `ContactForce` are registered (summed in that
//! order into `NetForce`). The integrator re-evaluates the three built-in contributions at
//! every sub-step and holds any other registered contribution (a user's `Forces::Custom`
//! plugin) fixed over the step. The forces plugin's `finish` hook gathers the particles into
//! the dense workspace (resources `BrownianConfig`, `ExternalField`, `StepClock` must exist).

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::brownian::systems::*;
use magsep_systems::sets::{ForceSystems, SimSystems};

use crate::app::{SimApp, SimPlugin};
use crate::core::{CorePlugin, FinalizeSystems};
use crate::group::PipelineGroup;
use crate::recorder::RecordPlugin;

/// Moments, cell lists and the three force contributions.
#[derive(Debug, Clone, Copy, Default)]
pub struct BrownianForcesPlugin;

impl SimPlugin for BrownianForcesPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<BrownianStats>();
        app.register_force::<FieldForce>();
        app.register_force::<DipoleForce>();
        app.register_force::<ContactForce>();
        app.schedule.add_systems((
            prepare_brownian_step.in_set(SimSystems::Prepare),
            compute_field_forces.in_set(ForceSystems::Field),
            compute_dipole_forces.in_set(ForceSystems::Dipole),
            compute_contact_forces.in_set(ForceSystems::Contact),
        ));
    }

    fn finish(&self, world: &mut World) {
        init_brownian_workspace(world);
    }
}

/// Mobility, the (adaptive) Ermak-McCammon step with capture and hard cores, write-back.
#[derive(Debug, Clone, Copy, Default)]
pub struct BrownianIntegratorPlugin;

impl SimPlugin for BrownianIntegratorPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<BrownianStats>();
        app.schedule.add_systems((
            prepare_mobility.in_set(SimSystems::Mobility),
            integrate_brownian.in_set(SimSystems::Integrate),
            write_back_brownian.in_set(FinalizeSystems::WriteBack),
        ));
    }
}

/// The capture curve (sampled every `observe_every` steps).
#[derive(Debug, Clone, Copy, Default)]
pub struct CaptureObservePlugin;

impl SimPlugin for CaptureObservePlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<CaptureCurve>();
        app.schedule.add_systems(
            observe_capture
                .run_if(should_sample)
                .in_set(SimSystems::Observe),
        );
    }
}

/// The brownian pipeline: core, forces, integrator, capture curve, recording.
///
/// ```
/// use magsep_plugins::brownian::{brownian_pipeline, CaptureObservePlugin};
/// let group = brownian_pipeline();
/// assert!(group.contains::<CaptureObservePlugin>());
/// ```
pub fn brownian_pipeline() -> PipelineGroup {
    PipelineGroup::new()
        .add(CorePlugin)
        .add(BrownianForcesPlugin)
        .add(BrownianIntegratorPlugin)
        .add(CaptureObservePlugin)
        .add(RecordPlugin)
}
