//! Registration of force contributions and kernels (they reach every particle, also ones
//! spawned later), the refusal of forces no plugin consumes, and pipeline-group editing with
//! plugin parameters.

use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep_components::forces::KernelForce;
use magsep_components::prelude::*;
use magsep_plugins::app::{SimApp, SimPlugin};
use magsep_plugins::core::CorePlugin;
use magsep_plugins::group::PipelineGroup;
use magsep_systems::forces::{Consumption, ExternalForce, ForceUse, ParticleState};
use magsep_systems::rng::particle_stream;

/// A user force [N].
#[derive(Component, Debug, Default, Clone, Copy, PartialEq)]
struct PushForce(DVec3);

impl ForceContribution for PushForce {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {
        self.0 = DVec3::ZERO;
    }
}

fn spawn(world: &mut World, id: u64) -> Entity {
    world
        .spawn(ParticleBundle {
            id: ParticleId(id),
            position: Position(DVec3::new(id as f64, 0.0, 0.0)),
            orientation: Orientation::default(),
            shape: Shape::Sphere { radius: 0.5 },
            species: Species(0),
            rng: ParticleRng(particle_stream(1, id)),
            net_force: NetForce::default(),
            net_torque: NetTorque::default(),
        })
        .id()
}

/// Declares that forces are consumed (the role of a pipeline's integrator plugin).
#[derive(Clone)]
struct ConsumeAll;

impl SimPlugin for ConsumeAll {
    fn build(&self, app: &mut SimApp) {
        app.world.insert_resource(ForceUse {
            builtin: Vec::new(),
            contributions: Consumption::Consumed,
            kernels: Consumption::Consumed,
        });
    }
}

#[test]
fn contribution_registered_before_spawning_reaches_later_particles() {
    let mut app = SimApp::new();
    app.register_force::<PushForce>();
    let e = spawn(&mut app.world, 0);
    app.world.flush();
    assert_eq!(app.world.get::<PushForce>(e), Some(&PushForce::default()));
    // and it is summed into NetForce
    app.add_plugin(&CorePlugin).add_plugin(&ConsumeAll);
    app.schedule
        .add_systems(push.in_set(magsep_systems::sets::ForceSystems::Custom));
    app.finish().unwrap();
    app.step();
    assert_eq!(app.world.get::<NetForce>(e).unwrap().0, DVec3::X);
}

fn push(mut q: Query<&mut PushForce>) {
    for mut f in &mut q {
        f.0 = DVec3::X;
    }
}

#[test]
fn contribution_registered_after_spawning_reaches_existing_particles_and_keeps_values() {
    let mut app = SimApp::new();
    let a = spawn(&mut app.world, 0);
    let b = spawn(&mut app.world, 1);
    app.world.entity_mut(b).insert(PushForce(DVec3::Y));
    let not_particle = app.world.spawn_empty().id();
    app.register_force::<PushForce>();
    assert_eq!(app.world.get::<PushForce>(a), Some(&PushForce::default()));
    assert_eq!(app.world.get::<PushForce>(b), Some(&PushForce(DVec3::Y)));
    assert!(app.world.get::<PushForce>(not_particle).is_none());
    // a second registration is a no-op (one observer, one accumulation slot)
    app.register_force::<PushForce>();
    assert_eq!(app.forces.names.len(), 1);
    let c = spawn(&mut app.world, 2);
    app.world.flush();
    assert!(app.world.get::<PushForce>(c).is_some());
}

/// F = -k x [N].
struct Trap(f64);

impl ExternalForce for Trap {
    fn force_torque(&self, p: &ParticleState) -> (DVec3, DVec3) {
        (-self.0 * p.position, DVec3::ZERO)
    }
}

#[test]
fn kernel_reaches_later_particles_and_net_force() {
    let mut app = SimApp::new();
    app.add_external_force("trap", Arc::new(Trap(2.0)));
    app.add_plugin(&CorePlugin).add_plugin(&ConsumeAll);
    let e = spawn(&mut app.world, 3);
    app.finish().unwrap();
    app.step();
    let k = app.world.get::<KernelForce>(e).copied().unwrap();
    assert_eq!(k.force, DVec3::new(-6.0, 0.0, 0.0));
    assert_eq!(app.world.get::<NetForce>(e).unwrap().0, k.force);
}

#[test]
fn forces_nobody_consumes_are_refused_with_a_reason() {
    let mut app = SimApp::new();
    app.register_force::<PushForce>();
    let err = app.finish().unwrap_err().0;
    assert!(
        err.contains("PushForce") && err.contains("ForceUse"),
        "{err}"
    );

    let mut app = SimApp::new();
    app.add_external_force("trap", Arc::new(Trap(1.0)));
    let err = app.finish().unwrap_err().0;
    assert!(err.contains("trap"), "{err}");

    let mut app = SimApp::new();
    app.add_plugin(&CorePlugin);
    assert!(
        app.finish().is_ok(),
        "nothing registered: nothing to refuse"
    );
}

/// A plugin with a parameter (several configured instances in one group).
#[derive(Clone, Debug)]
struct Gain(f64);

impl SimPlugin for Gain {
    fn build(&self, _app: &mut SimApp) {}
    fn params(&self) -> serde_json::Value {
        serde_json::json!({ "gain": self.0 })
    }
}

#[derive(Clone, Debug)]
struct Marker;

impl SimPlugin for Marker {
    fn build(&self, _app: &mut SimApp) {}
}

#[test]
fn group_holds_configured_instances_and_edits_them() {
    let group = PipelineGroup::new()
        .add(CorePlugin)
        .add(Gain(1.0))
        .add_labelled("second gain", Gain(2.0))
        .add(Marker);
    assert_eq!(
        group.labels(),
        ["CorePlugin", "Gain", "second gain", "Marker"]
    );
    let gains: Vec<f64> = group.get_all::<Gain>().iter().map(|g| g.0).collect();
    assert_eq!(gains, [1.0, 2.0]);

    // set: replace the first Gain by a configured instance, in place
    let group = group.set(Gain(5.0));
    let gains: Vec<f64> = group.get_all::<Gain>().iter().map(|g| g.0).collect();
    assert_eq!(gains, [5.0, 2.0]);
    // by label
    let group = group.set_labelled("second gain", Gain(7.0)).unwrap();
    let gains: Vec<f64> = group.get_all::<Gain>().iter().map(|g| g.0).collect();
    assert_eq!(gains, [5.0, 7.0]);
    assert!(group.clone().set_labelled("nope", Gain(0.0)).is_err());

    // add_before / add_after
    let group = group.add_before::<Marker, _>(Gain(3.0)).unwrap();
    let group = group.add_after::<CorePlugin, _>(Gain(0.5)).unwrap();
    let gains: Vec<f64> = group.get_all::<Gain>().iter().map(|g| g.0).collect();
    assert_eq!(gains, [0.5, 5.0, 7.0, 3.0]);
    assert_eq!(group.labels()[1], "Gain#3");
    let missing = PipelineGroup::new().add_before::<Marker, _>(Gain(1.0));
    assert!(missing.is_err());

    // replace::<Old>(new)
    let group = group.replace::<Marker, _>(Gain(9.0)).unwrap();
    assert!(!group.contains::<Marker>());
    assert_eq!(group.labels().last().map(String::as_str), Some("Gain#4"));
    assert!(group.clone().replace::<Marker, _>(Gain(1.0)).is_err());

    // disable by index and label
    let group = group.set_enabled(1, false);
    let group = group.set_enabled_labelled("second gain", false).unwrap();
    let gains: Vec<f64> = group.get_all::<Gain>().iter().map(|g| g.0).collect();
    assert_eq!(gains, [5.0, 3.0, 9.0]);

    // the app records name and parameters of every plugin built
    let mut app = SimApp::new();
    group.build(&mut app);
    let infos = app.plugin_infos();
    let names: Vec<&str> = infos.iter().map(|i| i.0.as_str()).collect();
    assert_eq!(names, ["CorePlugin", "Gain", "Gain#2", "Gain#4"]);
    assert_eq!(infos[0].1, serde_json::Value::Null);
    assert_eq!(infos[1].1, serde_json::json!({ "gain": 5.0 }));
    assert_eq!(infos[3].1, serde_json::json!({ "gain": 9.0 }));
}
