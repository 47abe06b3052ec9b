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
//! order into `NetForce`). The integrator re-evaluates them, and every external force kernel
//! (`SimApp::add_external_force`), at every adaptive sub-step, so the step controller sees
//! the user's force. Any other registered contribution (a user's `ForceContribution`
//! component) is a value of the step start: the integrator consumes it only with
//! `step_control = fixed` (explicit Euler evaluates forces only there) and `SimApp::finish`
//! refuses it with adaptive steps, naming the kernel alternative (see [`brownian_force_use`]).
//! The component copies and the contribution passes run only while something may read them
//! ([`force_components_written`]: by default always; `magsep`'s scene driver keeps the
//! forces in the workspace when the run has no plugin besides the pipeline's, see
//! `magsep_systems::forces::ForceComponents`).
//! The forces plugin's `finish` hook gathers the particles into the dense workspace
//! (resources `BrownianConfig`, `ExternalField`, `StepClock` must exist).

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::brownian::systems::*;
use magsep_systems::forces::{Consumption, ContributionPasses, ForceUse};
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
            (
                compute_field_forces.in_set(ForceSystems::Field),
                compute_dipole_forces.in_set(ForceSystems::Dipole),
                compute_contact_forces.in_set(ForceSystems::Contact),
            )
                .run_if(force_components_written),
        ));
        // the generic clear and sum passes of the contributions serve only readers outside
        // the pipeline when the integrator takes its forces from the workspace
        app.schedule
            .configure_sets(ContributionPasses.run_if(force_components_written));
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

    fn finish(&self, world: &mut World) {
        let control = world
            .get_resource::<BrownianConfig>()
            .map(|c| c.step_control)
            .unwrap_or_default();
        world.insert_resource(brownian_force_use(&control));
    }
}

/// What the brownian integrator consumes with step control `control`: the built-in field,
/// dipole and contact contributions and kernels always; other contributions only with fixed
/// steps.
///
/// ```
/// use magsep_components::brownian::StepControl;
/// use magsep_plugins::brownian::brownian_force_use;
/// use magsep_systems::forces::Consumption;
/// assert_eq!(brownian_force_use(&StepControl::Fixed).contributions, Consumption::Consumed);
/// assert_ne!(brownian_force_use(&StepControl::default()).contributions, Consumption::Consumed);
/// ```
pub fn brownian_force_use(control: &StepControl) -> ForceUse {
    let contributions = match control {
        StepControl::Fixed => Consumption::Consumed,
        StepControl::Adaptive { .. } | StepControl::Multirate { .. } => Consumption::Refused(
            "the brownian pipeline's adaptive stepper re-evaluates forces at every sub-step, \
             and a ForceContribution component is a value computed once per step (it would \
             be frozen over the sub-steps); implement `magsep::systems::forces::ExternalForce` \
             and register it with `SimApp::add_external_force` instead, or use \
             step_control = fixed"
                .into(),
        ),
    };
    ForceUse {
        builtin: vec![
            std::any::type_name::<FieldForce>().into(),
            std::any::type_name::<DipoleForce>().into(),
            std::any::type_name::<ContactForce>().into(),
        ],
        contributions,
        kernels: Consumption::Consumed,
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
