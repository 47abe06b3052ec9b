//! A user force in the brownian pipeline: gravity and buoyancy on the nanoparticles
//! (`F = (ρ_p − ρ_f) V g`, along −z), as an external force kernel.
//!
//! The brownian stepper evaluates kernels at every adaptive sub-step, with the sub-step's
//! positions, so the step controller sees them (a plain force component would be frozen over
//! the step, and the pipeline refuses one under adaptive steps). Run:
//! `cargo run --release --example brownian_sedimentation`.

use std::sync::Arc;

use glam::DVec3;
use magsep::prelude::*;
use magsep::scene::parse_scene;
use magsep::systems::forces::{ExternalForce, ParticleState};

/// Gravity minus buoyancy on a sphere: `(ρ_p − ρ_f) (4/3) π a³ g`, downwards [N].
pub struct Sedimentation {
    /// Density difference particle − fluid [kg/m³].
    pub excess: f64,
}

impl ExternalForce for Sedimentation {
    fn force_torque(&self, p: &ParticleState) -> (DVec3, DVec3) {
        let v = 4.0 / 3.0 * std::f64::consts::PI * p.shape.radius().powi(3);
        (DVec3::new(0.0, 0.0, -self.excess * v * 9.81), DVec3::ZERO)
    }
}

/// Registers the kernel.
#[derive(Debug, Clone, Copy)]
pub struct SedimentationPlugin {
    /// Density difference [kg/m³].
    pub excess: f64,
}

impl SimPlugin for SedimentationPlugin {
    fn build(&self, app: &mut SimApp) {
        app.add_external_force(
            "sedimentation",
            Arc::new(Sedimentation {
                excess: self.excess,
            }),
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scene = parse_scene(
        r#"
[simulation]
pipeline = "brownian"
[brownian]
time_step = 1e-3
duration = 1.0
mobility = "free_draining"
dipole_cutoff = 0
[[particles]]
count = 2000
shape = { kind = "sphere", radius = 212e-9 }
placement = { kind = "box", min = [0.0, 0.0, 0.0], max = [1e-3, 1e-3, 1e-3] }
"#,
        &Default::default(),
    )?;
    // polystyrene-magnetite beads in water: ρ_p − ρ_f ≈ 1000 kg/m³ (5 g/cm³ cores are diluted)
    let mut sim = Simulation::builder(&scene)
        .add_plugin(SedimentationPlugin { excess: 1000.0 })
        .build()?;
    let z0: f64 = mean_z(&mut sim);
    sim.run(|_| {})?;
    let z1 = mean_z(&mut sim);
    let a: f64 = 212e-9;
    let f = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * a.powi(3) * 9.81;
    let stokes = f / (6.0 * std::f64::consts::PI * 1e-3 * a);
    println!(
        "mean settling over 1 s: {:.3e} m (Stokes velocity {:.3e} m/s)",
        z0 - z1,
        stokes
    );
    Ok(())
}

fn mean_z(sim: &mut Simulation) -> f64 {
    let z: Vec<f64> = sim
        .app
        .world
        .query::<&Position>()
        .iter(&sim.app.world)
        .map(|p| p.0.z)
        .collect();
    z.iter().sum::<f64>() / z.len() as f64
}
