//! A user force in the brownian pipeline: gravity and buoyancy on the nanoparticles
//! (`F = (ρ_p − ρ_f) V g`, along −z), added by a plugin in `ForceSystems::Custom`.
//!
//! The brownian integrator re-evaluates its built-in contributions (field, dipole, contact) at
//! every adaptive sub-step and holds other registered contributions, like this one, fixed over
//! the step. Run: `cargo run --release --example brownian_sedimentation`.

use bevy_ecs::prelude::*;
use glam::DVec3;
use magsep::plugins::brownian::brownian_pipeline;
use magsep::prelude::*;
use magsep::scene::parse_scene;

/// Gravity minus buoyancy [N].
#[derive(Component, Debug, Default, Clone, Copy)]
pub struct SedimentationForce(pub DVec3);

impl ForceContribution for SedimentationForce {
    fn force(&self) -> DVec3 {
        self.0
    }
    fn clear(&mut self) {
        self.0 = DVec3::ZERO;
    }
}

/// Density difference particle − fluid [kg/m³].
#[derive(Resource, Debug, Clone, Copy)]
pub struct DensityExcess(pub f64);

/// Forces::Custom: `(ρ_p − ρ_f) (4/3) π a³ g`, downwards.
pub fn compute_sedimentation(
    excess: Res<DensityExcess>,
    mut q: Query<(&Shape, &mut SedimentationForce)>,
) {
    for (shape, mut f) in &mut q {
        let v = 4.0 / 3.0 * std::f64::consts::PI * shape.radius().powi(3);
        f.0 = DVec3::new(0.0, 0.0, -excess.0 * v * 9.81);
    }
}

/// Adds the force to every particle and registers it.
#[derive(Debug, Clone, Copy)]
pub struct SedimentationPlugin {
    /// Density difference [kg/m³].
    pub excess: f64,
}

impl SimPlugin for SedimentationPlugin {
    fn build(&self, app: &mut SimApp) {
        app.world.insert_resource(DensityExcess(self.excess));
        app.insert_on_particles(SedimentationForce::default());
        app.register_force::<SedimentationForce>();
        app.schedule
            .add_systems(compute_sedimentation.in_set(ForceSystems::Custom));
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
    let pipeline = brownian_pipeline().add(SedimentationPlugin { excess: 1000.0 });
    let mut sim = Simulation::from_scene(
        &scene,
        RunOptions {
            pipeline: Some(pipeline),
            ..Default::default()
        },
    )?;
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
