//! A single sphere settling at small Reynolds number in the two-way coupled liquid: the
//! terminal velocity against the grid resolution, with and without the self-induced-velocity
//! correction (the point-particle model's self-disturbance; see
//! `magsep_systems::fluid::channel::self_induced`).
//!
//! Set-up: a 2 mm sphere of 1010 kg/m³ in a liquid of 1000 kg/m³ and 1 Pa s (Stokes drag law,
//! no history, no rotation) at the centre of a channel of 16 d × 16 d × 16 d (periodic in x and
//! y, walls at z = 0 and 16 d), released at rest; Stokes velocity
//! `v_St = Δρ g d²/(18 μ) = 21.8 µm/s`, Re ≈ 4e-5. The filter box is the sphere's bounding
//! cube (σ = d). The grid has `nx = ny = n` points and `nz ≈ π n/2 + 1` Chebyshev levels, so
//! the spacing at mid-height equals the horizontal one and d/Δ = n/16. The run lasts 0.3 s:
//! the particle relaxes in 0.2 ms and the disturbance over the filter in σ²/ν = 4 ms; the
//! slower far field (walls 8 diameters away, periodic images) hinders the settling by about
//! 10 %, which the correction (unbounded Stokes) rightly does not remove: in a box of 32
//! diameters the corrected velocity moves towards the Stokes value.

use glam::DVec3;
use magsep_components::prelude::*;
use serde::Serialize;

use crate::studies::bench::BenchError;
use crate::studies::fluid_charts::{runtime, simulation};

/// Particle diameter \[m\].
pub const DIAMETER: f64 = 2e-3;
/// Densities [kg/m³] and viscosity [Pa s].
const RHO_P: f64 = 1010.0;
const RHO_F: f64 = 1000.0;
const MU: f64 = 1.0;

/// The Stokes terminal velocity [m/s] of the set-up.
pub fn stokes_velocity() -> f64 {
    (RHO_P - RHO_F) * 9.81 * DIAMETER * DIAMETER / (18.0 * MU)
}

/// One settling run.
#[derive(Debug, Clone, Serialize)]
pub struct SettlingRow {
    /// Grid `[nx, ny, nz]`.
    pub grid: [usize; 3],
    /// Particle diameter over the horizontal grid spacing.
    pub diameter_over_spacing: f64,
    /// Edge of the cubic domain in particle diameters.
    pub size: f64,
    /// Whether the self-induced velocity was subtracted.
    pub corrected: bool,
    /// Settling velocity at the end [m/s] (positive downwards).
    pub velocity: f64,
    /// `velocity / v_St`.
    pub ratio: f64,
    /// Wall time of the run \[s\].
    pub wall_time_s: f64,
}

/// Chebyshev levels for `n` horizontal points (mid-height spacing ≈ horizontal spacing),
/// odd so that the channel's middle is a level.
pub fn levels_for(n: usize) -> usize {
    let nz = (std::f64::consts::FRAC_PI_2 * n as f64).round() as usize + 1;
    nz | 1
}

/// The scene of a run on an `n × n × levels_for(n)` grid in a cube of `size` diameters.
pub fn settling_scene(n: usize, size: f64, corrected: bool, duration: f64) -> String {
    let l = size * DIAMETER;
    let nz = levels_for(n);
    format!(
        r#"[simulation]
pipeline = "particle_fluid"
seed = 1

[particle_fluid]
time_step = 2e-3
duration = {duration}
drag_law = "stokes"
terms = {{ history = false, rotation = false, collisions = false }}

[liquid]
density = {RHO_F}
viscosity = {MU}
solver = {{ kind = "channel", grid = [{n}, {n}, {nz}], coupling = "two_way_force", self_induced_correction = {corrected} }}

[container]
kind = "channel"
side = [{l}, {l}]
height = {l}

[[particles]]
count = 1
shape = {{ kind = "sphere", radius = {r} }}
density = {RHO_P}
placement = {{ kind = "points", positions = [[{c}, {c}, {c}]] }}
"#,
        r = 0.5 * DIAMETER,
        c = 0.5 * l,
    )
}

/// Run the settling sphere on an `n`-point grid in a cube of `size` diameters (16 in the
/// chart).
///
/// # Errors
/// [`BenchError::Runtime`] when the scene or the run fails.
pub fn settle(
    n: usize,
    size: f64,
    corrected: bool,
    duration: f64,
) -> Result<SettlingRow, BenchError> {
    let mut sim = simulation(&settling_scene(n, size, corrected, duration))?;
    let start = std::time::Instant::now();
    sim.run(|_| {}).map_err(runtime)?;
    let wall_time_s = start.elapsed().as_secs_f64();
    let v = sim
        .app
        .world
        .query::<&Velocity>()
        .iter(&sim.app.world)
        .next()
        .map(|v| v.0)
        .unwrap_or(DVec3::NAN);
    let velocity = -v.z;
    Ok(SettlingRow {
        grid: [n, n, levels_for(n)],
        diameter_over_spacing: n as f64 / size,
        size,
        corrected,
        velocity,
        ratio: velocity / stokes_velocity(),
        wall_time_s,
    })
}
