//! The simulation schedule: chained sets, ambiguity detection as an error for every shipped
//! pipeline, fixed-order force accumulation, and the three ways to extend (examples a-c).

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep::prelude::*;
use magsep::scene::parse_scene;
use magsep::systems::forces::ForceRegistry;
use magsep::systems::sets::new_sim_schedule;

#[path = "../../examples/custom_force.rs"]
#[allow(dead_code)]
mod custom_force;
#[path = "../../examples/custom_schedule.rs"]
#[allow(dead_code)]
mod custom_schedule;
#[path = "../../examples/replace_plugin.rs"]
#[allow(dead_code)]
mod replace_plugin;

const SMALL: &str = r#"
[simulation]
pipeline = "packing"
seed = 1
[container]
kind = "periodic_box"
[[particles]]
count = 30
shape = { kind = "sphere", radius = 0.5 }
[[particles]]
count = 10
shape = { kind = "spherocylinder", radius = 0.25, cylinder_length = 1.0 }
"#;

#[test]
fn every_shipped_pipeline_builds_with_ambiguity_detection_as_error() {
    let scene = parse_scene(SMALL, &Default::default()).unwrap();
    // the packing pipeline, and the packing pipeline with recording
    let sim = Simulation::from_scene(&scene, RunOptions::default())
        .expect("packing pipeline has no ambiguity");
    let schedule = sim.app.resolved_schedule();
    for set in [
        "Prepare",
        "Constraints",
        "Settle",
        "WriteBack",
        "Clock",
        "Observe",
        "Record",
    ] {
        assert!(
            schedule.contains_key(set),
            "set {set} missing in {schedule:?}"
        );
    }
}

#[derive(Resource, Default)]
struct Counter(u64);
fn bump_a(mut c: ResMut<Counter>) {
    c.0 += 1;
}
fn bump_b(mut c: ResMut<Counter>) {
    c.0 *= 2;
}

#[test]
fn an_ambiguous_pair_of_systems_is_a_build_error() {
    let scene = parse_scene(SMALL, &Default::default()).unwrap();
    struct Ambiguous;
    impl SimPlugin for Ambiguous {
        fn build(&self, app: &mut SimApp) {
            app.world.init_resource::<Counter>();
            app.schedule.add_systems((
                bump_a.in_set(SimSystems::Observe),
                bump_b.in_set(SimSystems::Observe),
            ));
        }
    }
    let pipeline = packing_pipeline().add(Ambiguous);
    let err = Simulation::from_scene(
        &scene,
        RunOptions {
            pipeline: Some(pipeline),
            ..Default::default()
        },
    )
    .err()
    .expect("must fail");
    assert!(err.to_string().to_lowercase().contains("ambigu"), "{err}");
    // ordering them fixes it
    struct Ordered;
    impl SimPlugin for Ordered {
        fn build(&self, app: &mut SimApp) {
            app.world.init_resource::<Counter>();
            app.schedule
                .add_systems((bump_a, bump_b).chain().in_set(SimSystems::Observe));
        }
    }
    let pipeline = packing_pipeline().add(Ordered);
    Simulation::from_scene(
        &scene,
        RunOptions {
            pipeline: Some(pipeline),
            ..Default::default()
        },
    )
    .expect("ordered is fine");
}

#[derive(Component, Default)]
struct ForceA(DVec3);
impl ForceContribution for ForceA {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {}
}
#[derive(Component, Default)]
struct ForceB(DVec3);
impl ForceContribution for ForceB {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {}
}

#[test]
fn contributions_are_summed_in_registration_order() {
    // values whose float sum depends on the order: (a + b) differs from (b + a) only if the
    // accumulator started from a non-zero value, so check against a + b computed explicitly
    let a = DVec3::new(1e16, 1.0, -3.3);
    let b = DVec3::new(1.0, 1e-17, 3.3);
    let mut world = World::new();
    let e = world
        .spawn((
            ForceA(a),
            ForceB(b),
            NetForce(DVec3::splat(7.0)),
            NetTorque::default(),
        ))
        .id();
    let mut schedule = new_sim_schedule();
    let mut reg = ForceRegistry::default();
    reg.register::<ForceA>(&mut schedule);
    reg.register::<ForceB>(&mut schedule);
    reg.register::<ForceA>(&mut schedule); // duplicate registration is ignored
    assert_eq!(reg.names.len(), 2);
    schedule.initialize(&mut world).expect("no ambiguity");
    schedule.run(&mut world);
    let want = (DVec3::ZERO + a) + b;
    assert_eq!(world.get::<NetForce>(e).unwrap().0, want);
}

#[test]
fn example_a_plugin_registers_a_force_contribution() {
    let (net, trap) = custom_force::demo();
    assert!(trap.length() > 0.0);
    assert_eq!(net, trap);
}

#[test]
fn example_b_disabled_plugin_replaced_by_user_plugin() {
    let (summary, runs, constraints) = replace_plugin::demo();
    assert!(
        constraints
            .iter()
            .any(|s| s.contains("remove_overlaps_aggressive")),
        "{constraints:?}"
    );
    assert!(
        !constraints
            .iter()
            .any(|s| s.contains("remove_overlaps_mcm")),
        "{constraints:?}"
    );
    assert!(runs > 0);
    assert!(
        summary["packing_fraction"].as_f64().unwrap() > 0.3,
        "{summary}"
    );
}

#[test]
fn example_c_custom_schedule_integrates_exactly() {
    let (x, want) = custom_schedule::demo(100);
    assert!((x - want).length() < 1e-15, "{x} vs {want}");
}
