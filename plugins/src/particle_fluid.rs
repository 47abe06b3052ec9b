//! The `particle_fluid` pipeline: inertial particles in a (magnetised) liquid with one-way
//! coupling to a quiescent or prescribed flow (thesis 002, ch. 1-2).
//!
//! | plugin | set | system | touches |
//! |---|---|---|---|
//! | [`InertialForcesPlugin`] | `Prepare` | `sample_fluid` (non-quiescent flows only) | `FluidSample` |
//! | | `Forces::Field` | `compute_body_forces`, `compute_magnetic_buoyancy` | `GravityForce`, `BuoyancyForce`, `MagneticBuoyancyForce` |
//! | | `Forces::Fluid` | `compute_drag`, `compute_undisturbed_flow`, `compute_history`, `compute_rotational_drag` | `DragForce`, `UndisturbedFlowForce`, `HistoryForce`, `BassetHistory`, `RotationalDragTorque` |
//! | | `Forces::Fluid` (spheroids) | `compute_spheroid_loads`, `compute_spheroid_rotational_drag` | `DragForce`, `LiftForce`, `PitchingTorque`, `RotationalDragTorque` |
//! | | `Forces::Field` (spheroids) | `compute_magnetic_torque` | `MagneticTorque` |
//! | [`InertialIntegratorPlugin`] | `Mobility` | `update_velocities` | `Velocity`, `AngularVelocity`, `HistoryForce`, `Health` |
//! | | `Integrate` | `integrate_positions` | `Position`, `Orientation`, `StepStart` |
//! | | `FinalizeSystems::WriteBack` | `wrap_periodic` | `Position` |
//! | | `FinalizeSystems::Flags` | `track_levitation` | `Levitation` |
//! | [`CollisionPlugin`] | `Constraints` | `resolve_collisions` | `CollisionWorkspace`, `Position`, `Velocity`, `AngularVelocity`, `PendingHistoryReset`, `ParticleFluidStats` |
//! | [`SeparationObservePlugin`] | `Observe` (gated) and the replay schedule | `observe_separation` | `SeparationCurve` |
//!
//! Model no more than a scene needs: the forces plugin registers only the contributions the
//! scene's `ParticleFluidConfig` switches on and that can act (no magnetic buoyancy without a
//! magnet, no flow sampling or undisturbed-flow force in a quiescent liquid, no collision
//! plugin when collisions are off). User forces: the integrator consumes `NetForce`, so every
//! registered contribution (`SimApp::register_force`) and external force kernel
//! (`SimApp::add_external_force`, summed into the built-in `KernelForce`) acts as an explicit
//! force of the step start. Resources that must exist: `ParticleFluidConfig`,
//! `FluidDomain`, `StepClock`; the particles carry `Velocity`, `AngularVelocity`,
//! `InertialBody`, `FluidSample`, `Levitation`.

use bevy_ecs::prelude::*;
use magsep_components::prelude::*;
use magsep_systems::fluid::collide::{
    CollisionWorkspace, init_collision_workspace, resolve_collisions,
};
use magsep_systems::fluid::config::ParticleFluidConfig;
use magsep_systems::fluid::history::{HistoryKernel, HistoryPlan, HistoryState};
use magsep_systems::fluid::observe::{
    SeparationCurve, observe_separation, should_observe_separation,
};
use magsep_systems::fluid::spheroid_systems::{
    SpheroidFluid, compute_magnetic_torque, compute_spheroid_loads,
    compute_spheroid_rotational_drag,
};
use magsep_systems::fluid::systems::*;
use magsep_systems::forces::{Consumption, ForceUse};
use magsep_systems::sets::{ForceSystems, SimSystems};

use crate::app::{SimApp, SimPlugin};
use crate::core::{CorePlugin, FinalizeSystems};
use crate::group::PipelineGroup;
use crate::liquid::LiquidPlugin;
use crate::recorder::RecordPlugin;

fn config(app: &SimApp) -> Option<ParticleFluidConfig> {
    app.world.get_resource::<ParticleFluidConfig>().cloned()
}

/// The Basset plan of `cfg` (`None` when the history is off or the window is invalid).
pub fn basset_plan(cfg: &ParticleFluidConfig) -> Option<HistoryPlan> {
    use magsep_systems::fluid::config::HistoryChoice;
    if !cfg.terms.history {
        return None;
    }
    let kernel = match cfg.history {
        HistoryChoice::Full => HistoryKernel::Full,
        HistoryChoice::Window { window, tail } => HistoryKernel::window(window, cfg.dt, tail),
    };
    HistoryPlan::new(cfg.dt, kernel).ok()
}

/// Body forces, magnetic buoyancy and the fluid forces the scene switches on.
#[derive(Debug, Clone, Copy, Default)]
pub struct InertialForcesPlugin;

impl SimPlugin for InertialForcesPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<ParticleFluidStats>();
        let Some(cfg) = config(app) else {
            return;
        };
        let t = cfg.terms;
        if t.gravity || t.buoyancy {
            app.register_force::<GravityForce>()
                .register_force::<BuoyancyForce>()
                .insert_on_particles(GravityForce::default())
                .insert_on_particles(BuoyancyForce::default());
            app.schedule
                .add_systems(compute_body_forces.in_set(ForceSystems::Field));
        }
        if cfg.magnetic_on() {
            app.register_force::<MagneticBuoyancyForce>()
                .insert_on_particles(MagneticBuoyancyForce::default());
            app.schedule
                .add_systems(compute_magnetic_buoyancy.in_set(ForceSystems::Field));
        }
        if !cfg.flow.is_quiescent() {
            app.schedule.add_systems(
                sample_fluid
                    .run_if(flow_is_not_quiescent)
                    .in_set(SimSystems::Prepare),
            );
        }
        if t.drag {
            app.register_force::<DragForce>()
                .insert_on_particles(DragForce::default());
            app.schedule
                .add_systems(compute_drag.in_set(ForceSystems::Fluid));
        }
        if cfg.undisturbed_on() {
            app.register_force::<UndisturbedFlowForce>()
                .insert_on_particles(UndisturbedFlowForce::default());
            app.schedule
                .add_systems(compute_undisturbed_flow.in_set(ForceSystems::Fluid));
        }
        if let Some(plan) = basset_plan(&cfg) {
            app.world.insert_resource(BassetPlan(plan));
            app.register_force::<HistoryForce>()
                .insert_on_particles(HistoryForce::default())
                .insert_on_particles(PendingHistoryReset::default());
            // the history starts at t = 0 with the initial slip as its step change (eq. 2.27)
            let rows: Vec<(Entity, HistoryState)> = app
                .world
                .query::<(Entity, &Velocity, &FluidSample)>()
                .iter(&app.world)
                .map(|(e, v, s)| (e, HistoryState::new(s.velocity - v.0, 0.0)))
                .collect();
            for (e, h) in rows {
                app.world.entity_mut(e).insert(BassetHistory(h));
            }
            app.schedule
                .add_systems(compute_history.in_set(ForceSystems::Fluid));
        }
        if t.rotation {
            app.register_force::<RotationalDragTorque>()
                .insert_on_particles(RotationalDragTorque::default());
            app.schedule
                .add_systems(compute_rotational_drag.in_set(ForceSystems::Fluid));
        }
        let spheroids = app
            .world
            .query::<&SpheroidFluid>()
            .iter(&app.world)
            .next()
            .is_some();
        if spheroids {
            spheroid_terms(app, &cfg);
        }
    }
}

/// The spheroid systems (thesis 002, ch. 4): shape-specific drag, lift and pitching torque,
/// rotational resistance and the magnetic torque, for the terms that are on.
fn spheroid_terms(app: &mut SimApp, cfg: &ParticleFluidConfig) {
    let t = cfg.terms;
    if t.lift {
        app.register_force::<LiftForce>();
    }
    if t.pitching_torque {
        app.register_force::<PitchingTorque>();
    }
    if t.drag || t.lift || t.pitching_torque {
        app.schedule.add_systems(
            compute_spheroid_loads
                .after(compute_drag)
                .in_set(ForceSystems::Fluid),
        );
    }
    if t.rotation {
        app.schedule
            .add_systems(compute_spheroid_rotational_drag.in_set(ForceSystems::Fluid));
    }
    if t.magnetic_torque && cfg.magnet_torque_can_act() {
        app.register_force::<MagneticTorque>();
        app.schedule
            .add_systems(compute_magnetic_torque.in_set(ForceSystems::Field));
    }
}

/// Velocities, positions, periodic wrap and levitation bookkeeping. Consumes `NetForce`, so
/// every registered contribution and kernel acts (explicitly, evaluated at the step start).
#[derive(Debug, Clone, Copy, Default)]
pub struct InertialIntegratorPlugin;

impl SimPlugin for InertialIntegratorPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.insert_resource(ForceUse {
            builtin: Vec::new(),
            contributions: Consumption::Consumed,
            kernels: Consumption::Consumed,
        });
        app.insert_on_particles(StepStart::default())
            .insert_on_particles(StepStartOrientation::default());
        app.schedule.add_systems((
            update_velocities.in_set(SimSystems::Mobility),
            integrate_positions.in_set(SimSystems::Integrate),
            wrap_periodic.in_set(FinalizeSystems::WriteBack),
            track_levitation.in_set(FinalizeSystems::Flags),
        ));
    }
}

/// Hard-particle collisions with restitution and Coulomb friction (event-driven, time of
/// impact). The `CollisionWorkspace` resource holds the model; without one a default
/// (thesis ch. 2 wet restitution) is used.
#[derive(Debug, Clone, Copy, Default)]
pub struct CollisionPlugin;

impl SimPlugin for CollisionPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<CollisionWorkspace>();
        app.world.init_resource::<ParticleFluidStats>();
        app.insert_on_particles(PendingHistoryReset::default());
        app.schedule
            .add_systems(resolve_collisions.in_set(SimSystems::Constraints));
    }

    fn finish(&self, world: &mut World) {
        init_collision_workspace(world);
    }
}

/// The separation error e_m against time (also re-run on recorded frames by replay).
#[derive(Debug, Clone, Copy, Default)]
pub struct SeparationObservePlugin;

impl SimPlugin for SeparationObservePlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.init_resource::<SeparationCurve>();
        app.schedule.add_systems(
            observe_separation
                .run_if(should_observe_separation)
                .in_set(SimSystems::Observe),
        );
        app.observe.add_systems(observe_separation);
    }
}

/// The particle-fluid pipeline for `cfg`: core, forces, integrator, the simulated liquid
/// (when the scene has one), collisions (if on),
/// separation error, recording.
///
/// ```
/// use magsep_plugins::particle_fluid::{particle_fluid_pipeline, CollisionPlugin};
/// let group = particle_fluid_pipeline(false);
/// assert!(!group.contains::<CollisionPlugin>());
/// ```
pub fn particle_fluid_pipeline(collisions: bool) -> PipelineGroup {
    let group = PipelineGroup::new()
        .add(CorePlugin)
        .add(InertialForcesPlugin)
        .add(InertialIntegratorPlugin)
        .add(LiquidPlugin);
    let group = if collisions {
        group.add(CollisionPlugin)
    } else {
        group
    };
    group.add(SeparationObservePlugin).add(RecordPlugin)
}
