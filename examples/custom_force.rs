//! (a) A user plugin that adds a force to a pipeline: a harmonic trap as an external force
//! kernel.
//!
//! `Trap` pulls every particle towards the box centre, F = -k (x - c). A kernel is a function
//! of the particle's state (position [m], orientation, shape, time [s]) returning force [N]
//! and torque [N m]; every pipeline evaluates it wherever it needs forces: the brownian
//! stepper at every adaptive sub-step, the packing's FIRE minimiser at every iteration, the
//! particle-fluid integrator once per step. Its value at the step start is also the built-in
//! contribution `KernelForce`, summed into `NetForce`. Run: `cargo run --example custom_force`.

use std::sync::Arc;

use glam::DVec3;
use magsep::components::forces::KernelForce;
use magsep::prelude::*;
use magsep::scene::parse_scene;
use magsep::systems::forces::{ExternalForce, ParticleState};

/// Harmonic trap F = -k (x - c).
#[derive(Debug, Clone, Copy)]
pub struct Trap {
    /// Stiffness k [N/m].
    pub stiffness: f64,
    /// Centre c [m].
    pub centre: DVec3,
}

impl ExternalForce for Trap {
    fn force_torque(&self, p: &ParticleState) -> (DVec3, DVec3) {
        (-self.stiffness * (p.position - self.centre), DVec3::ZERO)
    }
}

/// Registers a [`Trap`] at the centre of the scene's container.
#[derive(Debug, Clone, Copy)]
pub struct TrapPlugin {
    /// Stiffness [N/m].
    pub stiffness: f64,
}

impl SimPlugin for TrapPlugin {
    fn build(&self, app: &mut SimApp) {
        let centre = app
            .world
            .get_resource::<Container>()
            .map_or(DVec3::ZERO, |c| c.edges() * 0.5);
        app.add_external_force(
            "trap",
            Arc::new(Trap {
                stiffness: self.stiffness,
                centre,
            }),
        );
    }

    fn params(&self) -> serde_json::Value {
        serde_json::json!({ "stiffness": self.stiffness })
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

/// Runs three packing steps and returns (net force, trap contribution) of particle 0 [N].
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
    // equals the stored kernel contribution (the only one registered). The FIRE minimiser
    // re-evaluated the kernel at every iteration of the overlap removal.
    let world = &mut sim.app.world;
    let mut q = world.query::<(&ParticleId, &NetForce, &KernelForce)>();
    let (_, net, trap) = q
        .iter(world)
        .find(|(id, _, _)| id.0 == 0)
        .expect("particle 0");
    (net.0, trap.force)
}

fn main() {
    let (net, trap) = demo();
    println!("particle 0: NetForce {net}, trap contribution {trap}");
}
