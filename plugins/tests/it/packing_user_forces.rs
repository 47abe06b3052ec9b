//! User forces in the packing pipeline: an external force kernel acts in the FIRE overlap
//! removal (gravity in a closed box piles the particles up at the bottom, deterministically);
//! a `ForceContribution` component, and kernels with the thesis's single-particle schemes,
//! are refused at `finish` with the kernel/FIRE alternative named.

use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::prelude::*;
use magsep_plugins::app::{SimApp, SimPlugin};
use magsep_plugins::packing::packing_pipeline;
use magsep_plugins::recorder::RecordPlugin;
use magsep_systems::RunSeed;
use magsep_systems::forces::{ExternalForce, ParticleState};
use magsep_systems::packing::insert::random_insertion;
use magsep_systems::packing::state::Body;
use magsep_systems::packing::systems::state_from_si;
use magsep_systems::rng::particle_stream;

const RADIUS: f64 = 0.5e-3;

/// Weight of a particle of density 2500 kg/m³, F = -ρ V g e_z [N].
struct Gravity;

impl ExternalForce for Gravity {
    fn force_torque(&self, p: &ParticleState) -> (DVec3, DVec3) {
        let v = 4.0 / 3.0 * std::f64::consts::PI * p.radius().powi(3);
        (DVec3::new(0.0, 0.0, -2500.0 * v * 9.81), DVec3::ZERO)
    }
}

/// `n` spheres of radius 0.5 mm inserted at random in a closed cubic box at packing fraction
/// 0.05.
fn world(n: usize, scheme: OverlapRemovalScheme) -> SimApp {
    let mut app = SimApp::new();
    let d = 2.0 * RADIUS;
    let shapes = vec![Shape::Sphere { radius: RADIUS }; n];
    let bodies: Vec<Body> = shapes.iter().map(|s| Body::from_shape(s, d)).collect();
    let volume: f64 = bodies.iter().map(|b| b.volume).sum::<f64>() * d.powi(3);
    let edge = (volume / 0.05).cbrt();
    let container = Container::Walled {
        walls: Walls::Box,
        edges: DVec3::splat(edge),
    };
    let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(3, i)).collect();
    let empty = state_from_si(&container, &[], &[], &[], d);
    let state = random_insertion(&bodies, empty, &mut rngs).unwrap();
    for (i, rng) in rngs.into_iter().enumerate() {
        app.world.spawn(ParticleBundle {
            id: ParticleId(i as u64),
            position: Position(state.positions[i] * d),
            orientation: Orientation(state.orientations[i]),
            shape: shapes[i],
            species: Species(0),
            rng: ParticleRng(rng),
            net_force: NetForce::default(),
            net_torque: NetTorque::default(),
        });
    }
    let mut config = PackingConfig::defaults_for(n, d);
    config.scheme = scheme;
    app.world.insert_resource(container);
    app.world.insert_resource(config);
    app.world.insert_resource(StepClock::new(0.0));
    app.world.insert_resource(RunSeed(3));
    app.world.insert_resource(Health::default());
    app
}

/// Mean height over box height and the centres after `steps` compression steps.
fn run(n: usize, steps: usize, gravity: bool) -> (f64, Vec<DVec3>) {
    let mut app = world(n, OverlapRemovalScheme::Fire);
    if gravity {
        app.add_external_force("gravity", Arc::new(Gravity));
    }
    packing_pipeline().disable::<RecordPlugin>().build(&mut app);
    app.finish().unwrap();
    for _ in 0..steps {
        app.step();
    }
    let h = app.world.resource::<Container>().edges().z;
    let mut rows: Vec<(ParticleId, DVec3)> = app
        .world
        .query::<(&ParticleId, &Position)>()
        .iter(&app.world)
        .map(|(i, p)| (*i, p.0))
        .collect();
    rows.sort_by_key(|r| r.0);
    let x: Vec<DVec3> = rows.into_iter().map(|r| r.1).collect();
    let mean = x.iter().map(|p| p.z).sum::<f64>() / x.len() as f64;
    let status = app.world.resource::<PackingStatus>();
    eprintln!(
        "gravity {gravity}: mean z / H = {:.3}, phi = {:.3}, {} accepted / {} failed steps",
        mean / h,
        status.packing_fraction,
        status.compression_steps,
        status.failed_steps
    );
    (mean / h, x)
}

#[test]
fn gravity_kernel_piles_particles_at_the_bottom_deterministically() {
    // 40 spheres fill about one layer of the box floor (edge 7.5 D at phi = 0.05): under
    // gravity the mean height is about one radius plus a few layers' worth, well below the
    // box middle where random insertion puts it without gravity
    let (free, _) = run(40, 5, false);
    let (heavy, x) = run(40, 5, true);
    assert!((free - 0.5).abs() < 0.1, "no gravity: mean z / H = {free}");
    assert!(heavy < 0.25, "gravity: mean z / H = {heavy}");
    let (_, again) = run(40, 5, true);
    assert_eq!(x, again, "not deterministic");
}

/// A user force held as a component [N].
#[derive(Component, Debug, Default, Clone, Copy)]
struct PushForce(DVec3);

impl ForceContribution for PushForce {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {
        self.0 = DVec3::ZERO;
    }
}

#[derive(Clone)]
struct PushPlugin;

impl SimPlugin for PushPlugin {
    fn build(&self, app: &mut SimApp) {
        app.register_force::<PushForce>();
    }
}

#[test]
fn contribution_component_is_refused_naming_the_kernel_api() {
    let mut app = world(10, OverlapRemovalScheme::Fire);
    packing_pipeline().add(PushPlugin).build(&mut app);
    let err = app.finish().unwrap_err().0;
    assert!(
        err.contains("PushForce") && err.contains("add_external_force"),
        "{err}"
    );
}

#[test]
fn kernels_are_refused_by_the_single_particle_schemes() {
    for scheme in [
        OverlapRemovalScheme::Original,
        OverlapRemovalScheme::Revised,
    ] {
        let mut app = world(10, scheme);
        app.add_external_force("gravity", Arc::new(Gravity));
        packing_pipeline().build(&mut app);
        let err = app.finish().unwrap_err().0;
        assert!(err.contains("gravity") && err.contains("fire"), "{err}");
    }
    let mut app = world(10, OverlapRemovalScheme::Fire);
    app.add_external_force("gravity", Arc::new(Gravity));
    packing_pipeline().build(&mut app);
    assert!(app.finish().is_ok());
}
