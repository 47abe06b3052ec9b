//! The brownian pipeline on the configuration of the LAMMPS peer (`lammps_bd.sh` of the
//! anchor benchmarks), in SI units, so that both run the same work side by side.
//!
//! The peer, in LJ units (σ = 1, k_B T = 1): `ncell³` spheres of diameter σ on a simple cubic
//! lattice at reduced density 0.1 (spacing 10^{1/3} σ), WCA core (LJ 12-6 cut and shifted at
//! 2^{1/6} σ, ε = k_B T), point dipoles |μ*| = 1 cut at 4 σ, `fix brownian/sphere` with
//! γ_t = 1 (D = 1 σ²/τ), dt = 1e-4 τ.
//!
//! Here: R = 75 nm (σ = 2R), T = 298 K, water; the Mie(12, 6) contact with ε = k_B T is the WCA
//! core exactly (the Mie potential is cut and shifted at its minimum 2^{1/6} σ); the moment m
//! with μ0 m²/(4π σ³ k_B T) = 1; dipole cut-off 8 R = 4 σ; dt = 1e-4 σ²/D with the Stokes
//! D = k_B T/(6πηR), so the Brownian displacement per step is the peer's √(2e-4) σ.
//!
//! **What differs** (stated with every ratio): magsep's moments are superparamagnetic, held
//! along the applied field (1 T along x), so there is no rotational dynamics; the peer's
//! dipoles are permanent, start in random directions and rotate (torques and a rotational
//! Brownian update: extra work for the peer, about a quarter of its pair kernel). The pair work
//! (distance test, dipole force within 4 σ, WCA within 1.12 σ) is the same. The peer's box is
//! periodic; magsep's domain is unbounded (the lattice block diffuses by ~1 σ over the timed
//! steps, so the neighbour count is unchanged to a percent).

use crate::studies::bench::BenchError;

/// Sphere radius \[m\] (σ = 2R).
pub const RADIUS: f64 = 75e-9;
/// Temperature \[K\].
pub const TEMPERATURE: f64 = 298.0;
/// Viscosity [Pa s].
pub const VISCOSITY: f64 = 1e-3;
/// Reduced number density ρσ³ of the peer.
pub const REDUCED_DENSITY: f64 = 0.1;
/// Peer's reduced time step dt/τ (τ = σ²/D).
pub const REDUCED_DT: f64 = 1e-4;
/// Dipole cut-off in σ.
pub const CUTOFF_SIGMA: f64 = 4.0;

/// Time step \[s\] and moment [A m²] of the mirror.
pub fn dt_and_moment() -> (f64, f64) {
    let kt = magsep_components::brownian::BOLTZMANN * TEMPERATURE;
    let sigma = 2.0 * RADIUS;
    let d = kt / (6.0 * std::f64::consts::PI * VISCOSITY * RADIUS);
    // μ0 m² / (4π σ³ kT) = 1, μ0/(4π) = 1e-7
    let m = (sigma.powi(3) * kt / 1e-7).sqrt();
    (REDUCED_DT * sigma * sigma / d, m)
}

/// Scene text of the mirror with `ncell³` particles (22 in the peer: 10 648).
///
/// # Errors
/// [`BenchError::Input`] for `ncell` outside 2..=64.
pub fn lammps_mirror_scene(ncell: usize, seed: u64) -> Result<String, BenchError> {
    if !(2..=64).contains(&ncell) {
        return Err(BenchError::Input(format!(
            "lammps mirror: ncell {ncell} outside 2..=64"
        )));
    }
    let spacing = 2.0 * RADIUS * REDUCED_DENSITY.powf(-1.0 / 3.0);
    let (dt, moment) = dt_and_moment();
    let mut points = String::with_capacity(ncell.pow(3) * 64);
    for k in 0..ncell {
        for j in 0..ncell {
            for i in 0..ncell {
                let p = [i, j, k].map(|c| (c as f64 + 0.5) * spacing);
                points.push_str(&format!("[{:?}, {:?}, {:?}], ", p[0], p[1], p[2]));
            }
        }
    }
    Ok(format!(
        "[simulation]\n\
         pipeline = \"brownian\"\n\
         seed = {seed}\n\
         \n\
         [external_field]\n\
         flux_density = [1.0, 0.0, 0.0]\n\
         \n\
         [brownian]\n\
         time_step = {dt:?}\n\
         duration = 1.0\n\
         temperature = {TEMPERATURE:?}\n\
         viscosity = {VISCOSITY:?}\n\
         mobility = \"free_draining\"\n\
         contact = {{ kind = \"mie\", epsilon_kt = 1.0, n = 12.0, m = 6.0 }}\n\
         dipole_cutoff = {cut:?}\n\
         step_control = {{ kind = \"fixed\" }}\n\
         \n\
         [[particles]]\n\
         count = {n}\n\
         shape = {{ kind = \"sphere\", radius = {RADIUS:?} }}\n\
         moment = {{ kind = \"saturated\", moment = {moment:?} }}\n\
         placement = {{ kind = \"points\", positions = [{points}] }}\n",
        cut = 2.0 * CUTOFF_SIGMA,
        n = ncell.pow(3),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mirror_has_the_peers_reduced_parameters() {
        let (dt, m) = dt_and_moment();
        let kt = magsep_components::brownian::BOLTZMANN * TEMPERATURE;
        let sigma = 2.0 * RADIUS;
        let d = kt / (6.0 * std::f64::consts::PI * VISCOSITY * RADIUS);
        // Brownian step √(2 D dt) = √(2e-4) σ
        assert!(((2.0 * d * dt).sqrt() / sigma - 2e-4f64.sqrt()).abs() < 1e-12);
        // reduced dipole strength λ = μ0 m²/(4π σ³ kT) = 1
        let lambda = magsep_systems::field::MU0 * m * m
            / (4.0 * std::f64::consts::PI)
            / (sigma.powi(3) * kt);
        assert!((lambda - 1.0).abs() < 1e-6, "{lambda}");
        let text = lammps_mirror_scene(3, 1).unwrap();
        let scene = crate::scene::parse_scene(&text, &Default::default()).unwrap();
        assert_eq!(scene.particles[0].count, 27);
        assert!(lammps_mirror_scene(1, 1).is_err());
    }
}
