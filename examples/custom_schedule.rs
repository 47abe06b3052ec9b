//! (c) Build a custom schedule from the public sets and systems.
//!
//! No pipeline at all: a `SimSchedule` with the chained sets, a registered force contribution
//! (constant drift force), the library's fixed-order accumulator, a user-written overdamped
//! integrator x += mu F dt in `Integrate`, and the library's clock in `Finalize`.
//! Run: `cargo run --example custom_schedule`.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep::prelude::*;
use magsep::systems::clock::advance_clock;
use magsep::systems::forces::ForceRegistry;
use magsep::systems::sets::new_sim_schedule;

/// A constant force [N].
#[derive(Component, Debug, Default, Clone, Copy)]
pub struct DriftForce(pub DVec3);

impl ForceContribution for DriftForce {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {}
}

/// Mobility mu [m/(N s)].
#[derive(Resource, Debug, Clone, Copy)]
pub struct Mobility(pub f64);

/// Integrate: x += mu F dt.
pub fn integrate_overdamped(
    clock: Res<StepClock>,
    mu: Res<Mobility>,
    mut q: Query<(&NetForce, &mut Position)>,
) {
    for (f, mut p) in &mut q {
        p.0 += mu.0 * f.0 * clock.dt;
    }
}

/// Runs `steps` steps; returns (final position, expected position).
pub fn demo(steps: u64) -> (DVec3, DVec3) {
    let mut world = World::new();
    world.insert_resource(StepClock::new(1e-3));
    world.insert_resource(Mobility(2.0));
    let e = world
        .spawn((
            Position(DVec3::ZERO),
            DriftForce(DVec3::new(1.0, 0.0, -0.5)),
            NetForce::default(),
            NetTorque::default(),
        ))
        .id();
    let mut schedule = new_sim_schedule();
    let mut registry = ForceRegistry::default();
    registry.register::<DriftForce>(&mut schedule);
    schedule.add_systems((
        integrate_overdamped.in_set(SimSystems::Integrate),
        advance_clock.in_set(SimSystems::Finalize),
    ));
    schedule.initialize(&mut world).expect("no ambiguity");
    for _ in 0..steps {
        schedule.run(&mut world);
    }
    let expected = DVec3::new(1.0, 0.0, -0.5) * 2.0 * 1e-3 * steps as f64;
    (world.get::<Position>(e).expect("entity").0, expected)
}

fn main() {
    let (x, want) = demo(100);
    println!("after 100 steps: x = {x}, expected {want}");
}
