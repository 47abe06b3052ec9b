//! User forces in the particle-fluid pipeline: a kernel and a `ForceContribution` component
//! both act as explicit forces of the step start. A constant extra force F on a sphere
//! settling in the Stokes regime shifts its terminal velocity by F / (3πμd).

use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;
use magsep_plugins::app::{SimApp, SimPlugin};
use magsep_plugins::particle_fluid::{SeparationObservePlugin, particle_fluid_pipeline};
use magsep_plugins::recorder::RecordPlugin;
use magsep_systems::collision::CollisionDomain;
use magsep_systems::fluid::config::{
    ForceTerms, HistoryChoice, Integrator, ParticleFluidConfig, STANDARD_GRAVITY,
};
use magsep_systems::fluid::drag::DragLaw;
use magsep_systems::fluid::flow::FlowModel;
use magsep_systems::fluid::magnet::{Liquid, MagnetModel};
use magsep_systems::fluid::systems::FluidDomain;
use magsep_systems::forces::{ExternalForce, ParticleState};
use magsep_systems::rng::particle_stream;

const D: f64 = 100e-6;
const RHO_P: f64 = 2000.0;
const MU: f64 = 1e-3;
const DT: f64 = 1e-4;
const STEPS: u64 = 300;

fn world() -> SimApp {
    let mut app = SimApp::new();
    let terms = ForceTerms {
        gravity: true,
        buoyancy: true,
        magnetic_buoyancy: false,
        drag: true,
        added_mass: false,
        undisturbed_flow: false,
        history: false,
        rotation: false,
        collisions: false,
        lift: false,
        pitching_torque: false,
        magnetic_torque: false,
    };
    app.world.insert_resource(ParticleFluidConfig {
        dt: DT,
        steps: STEPS,
        gravity: STANDARD_GRAVITY,
        mid_plane: 0.0,
        liquid: Liquid {
            density: 1000.0,
            viscosity: MU,
            susceptibility: 0.0,
        },
        magnet: MagnetModel::None,
        flow: FlowModel::Quiescent,
        terms,
        drag_law: DragLaw::Stokes,
        history: HistoryChoice::Full,
        integrator: Integrator::Implicit,
        levitation_tolerance: 5e-4,
        observe_every: STEPS,
        spheroids: Default::default(),
        solver: None,
    });
    app.world
        .insert_resource(FluidDomain(CollisionDomain::unbounded()));
    app.world.insert_resource(StepClock::new(DT));
    app.world.insert_resource(Health::default());
    app.world.spawn((
        ParticleBundle {
            id: ParticleId(0),
            position: Position(DVec3::ZERO),
            orientation: Orientation::default(),
            shape: Shape::Sphere { radius: 0.5 * D },
            species: Species(0),
            rng: ParticleRng(particle_stream(1, 0)),
            net_force: NetForce::default(),
            net_torque: NetTorque::default(),
        },
        Velocity::default(),
        AngularVelocity::default(),
        InertialBody::sphere(0.5 * D, RHO_P),
        FluidSample::default(),
        Levitation {
            equilibrium_height: f64::NAN,
            last_outside: 0.0,
        },
    ));
    app
}

/// Vertical velocity after `STEPS` steps (18 relaxation times m / (3πμd)) [m/s].
fn terminal_velocity(app: &mut SimApp) -> f64 {
    particle_fluid_pipeline(false)
        .disable::<SeparationObservePlugin>()
        .disable::<RecordPlugin>()
        .build(app);
    app.finish().unwrap();
    for _ in 0..STEPS {
        app.step();
    }
    assert!(app.world.resource::<Health>().messages.is_empty());
    let mut q = app.world.query::<&Velocity>();
    q.single(&app.world).unwrap().0.z
}

/// Half the sphere's apparent weight, upwards [N].
fn lift() -> f64 {
    let v = std::f64::consts::PI / 6.0 * D.powi(3);
    0.5 * (RHO_P - 1000.0) * v * STANDARD_GRAVITY
}

struct Lift;

impl ExternalForce for Lift {
    fn force_torque(&self, _p: &ParticleState) -> (DVec3, DVec3) {
        (DVec3::new(0.0, 0.0, lift()), DVec3::ZERO)
    }
}

#[derive(Component, Debug, Default, Clone, Copy)]
struct LiftForce(DVec3);

impl ForceContribution for LiftForce {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {
        self.0 = DVec3::ZERO;
    }
}

fn compute_lift(mut q: Query<&mut LiftForce>) {
    for mut f in &mut q {
        f.0 = DVec3::new(0.0, 0.0, lift());
    }
}

#[derive(Clone)]
struct LiftPlugin;

impl SimPlugin for LiftPlugin {
    fn build(&self, app: &mut SimApp) {
        app.register_force::<LiftForce>();
        app.schedule
            .add_systems(compute_lift.in_set(magsep_systems::sets::ForceSystems::Custom));
    }
}

#[test]
fn constant_user_force_shifts_the_stokes_terminal_velocity_by_f_over_3_pi_mu_d() {
    let stokes = 3.0 * std::f64::consts::PI * MU * D;
    let v0 = terminal_velocity(&mut world());
    let expected0 = -2.0 * lift() / stokes;
    assert!((v0 / expected0 - 1.0).abs() < 1e-6, "{v0} vs {expected0}");

    let mut app = world();
    app.add_external_force("lift", Arc::new(Lift));
    let v_kernel = terminal_velocity(&mut app);

    let mut app = world();
    app.add_plugin(&LiftPlugin);
    let v_component = terminal_velocity(&mut app);

    let shift = lift() / stokes;
    for (what, v) in [("kernel", v_kernel), ("component", v_component)] {
        assert!(
            ((v - v0) / shift - 1.0).abs() < 1e-6,
            "{what}: shift {} vs F/(3πμd) = {shift}",
            v - v0
        );
    }
}
