//! (a) A user plugin that registers a force contribution and a system computing it.
//!
//! `TrapForce` pulls every particle towards the box centre, F = -k (x - c). The plugin
//! registers the contribution (so `Accumulate` sums it into `NetForce` in a fixed order) and
//! adds `compute_trap_force` to `ForceSystems::Custom`. Run: `cargo run --example custom_force`.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep::prelude::*;
use magsep::scene::parse_scene;

/// Harmonic trap towards the box centre [N].
#[derive(Component, Debug, Default, Clone, Copy)]
pub struct TrapForce(pub DVec3);

impl ForceContribution for TrapForce {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {
        self.0 = DVec3::ZERO;
    }
}

/// Trap stiffness k [N/m].
#[derive(Resource, Debug, Clone, Copy)]
pub struct TrapStiffness(pub f64);

/// Forces::Custom: F = -k (x - centre).
pub fn compute_trap_force(
    k: Res<TrapStiffness>,
    container: Res<Container>,
    mut q: Query<(&Position, &mut TrapForce)>,
) {
    let centre = container.edges() * 0.5;
    for (p, mut f) in &mut q {
        f.0 = -k.0 * (p.0 - centre);
    }
}

/// Inserts the stiffness, adds `TrapForce` to every particle, registers the contribution.
#[derive(Debug, Clone, Copy)]
pub struct TrapPlugin {
    /// Stiffness [N/m].
    pub stiffness: f64,
}

impl SimPlugin for TrapPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.insert_resource(TrapStiffness(self.stiffness));
        app.insert_on_particles(TrapForce::default());
        app.register_force::<TrapForce>();
        app.schedule
            .add_systems(compute_trap_force.in_set(ForceSystems::Custom));
    }
}

const SCENE: &str = r#"
[simulation]
pipeline = "packing"
seed = 3
[container]
kind = "periodic_box"
[[particles]]
count = 20
shape = { kind = "sphere", radius = 0.5 }
"#;

/// Runs three steps and returns (net force, expected trap force) of particle 0.
pub fn demo() -> (DVec3, DVec3) {
    let scene = parse_scene(SCENE, &Default::default()).expect("valid scene");
    let pipeline = packing_pipeline().add(TrapPlugin { stiffness: 2.0 });
    let mut sim = Simulation::from_scene(
        &scene,
        RunOptions {
            pipeline: Some(pipeline),
            ..Default::default()
        },
    )
    .expect("builds");
    for _ in 0..3 {
        sim.step();
    }
    // Forces and Accumulate ran before this step's Constraints moved the particle, so NetForce
    // equals the stored contribution (the only one registered).
    let world = &mut sim.app.world;
    let mut q = world.query::<(&ParticleId, &NetForce, &TrapForce)>();
    let (_, net, trap) = q
        .iter(world)
        .find(|(id, _, _)| id.0 == 0)
        .expect("particle 0");
    (net.0, trap.0)
}

fn main() {
    let (net, trap) = demo();
    println!("particle 0: NetForce {net}, TrapForce contribution {trap}");
}
