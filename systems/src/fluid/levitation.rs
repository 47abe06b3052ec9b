//! Linear stability of magneto-Archimedes levitation and the levitation time (thesis 002,
//! §2.5.1, eq. 2.45-2.50; errata E-002-4, E-002-5, E-002-7 in docs/references.md).
//!
//! Linearised about y_e without history and with Stokes drag, a sphere obeys
//! `m_eff ÿ = −k ẏ − κ (y − y_e)` with `m_eff = (ρ_p + ½ρ_f) V` (or `ρ_p V` without added
//! mass), `k = 3πμd` and `κ = V g |dρ_{f,a}/dy|(y_e)`. The equilibrium is a stable node
//! (monotone approach) when `k² ≥ 4 m_eff κ`, a stable spiral (overshoot) otherwise. The
//! critical diameter solves `k² = 4 m_eff κ`:
//! `d⁴ = 81 μ² / (c_m g |dρ_{f,a}/dy|)`, `c_m = ρ_p + ½ρ_f` (or ρ_p). For one magnet this is
//! eq. 2.50 with |ρ_p − ρ_f| (the printed table 2.2 swaps the signs); the thesis's quoted
//! 3.2 mm is the criterion without added mass ([T002 §2.5.1.1]), eq. 2.50 gives 2.9 mm (erratum E-002-7).
//!
//! Levitation time ([T002 §2.5.1.1]): `t_l = max{t : |y(t) − y_e| = tol}`, tol = 0.5 mm in the thesis.

use super::magnet::{Liquid, MagnetModel};

/// Nature of the approach to equilibrium.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Approach {
    /// Real eigenvalues: monotone approach.
    Node,
    /// Complex eigenvalues: overshoot and damped oscillation.
    Spiral,
}

/// The linearised levitation of a sphere about its equilibrium height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearLevitation {
    /// Equilibrium height y_e [m].
    pub equilibrium_height: f64,
    /// Effective mass [kg].
    pub mass: f64,
    /// Stokes damping k = 3πμd [kg/s].
    pub damping: f64,
    /// Restoring stiffness κ [N/m].
    pub stiffness: f64,
}

impl LinearLevitation {
    /// Linearise for a sphere of `diameter` [m] and `density` [kg/m³]; `None` without an
    /// equilibrium in range or a non-restoring gradient.
    ///
    /// ```
    /// use magsep_systems::fluid::levitation::{Approach, LinearLevitation};
    /// use magsep_systems::fluid::magnet::{Liquid, MagnetModel};
    /// let liquid = Liquid { density: 1403.0, viscosity: 5.54e-3, susceptibility: 7e-4 };
    /// let m = MagnetModel::Bottom { surface_field: 422e3, pole_size: 0.1181, half_height: 0.075 };
    /// let small = LinearLevitation::new(&m, &liquid, 9.81, 2e-3, 1434.0, true).unwrap();
    /// let large = LinearLevitation::new(&m, &liquid, 9.81, 6e-3, 1434.0, true).unwrap();
    /// assert_eq!(small.approach(), Approach::Node);
    /// assert_eq!(large.approach(), Approach::Spiral);
    /// ```
    pub fn new(
        magnet: &MagnetModel,
        liquid: &Liquid,
        gravity: f64,
        diameter: f64,
        density: f64,
        added_mass: bool,
    ) -> Option<Self> {
        let y_e = magnet.equilibrium_height(liquid, gravity, density)?;
        let volume = std::f64::consts::PI * diameter.powi(3) / 6.0;
        let slope = magnet.apparent_density_gradient(liquid, gravity, y_e);
        // restoring only if the apparent density falls with height
        (slope < 0.0).then(|| Self {
            equilibrium_height: y_e,
            mass: volume * mass_density(liquid, density, added_mass),
            damping: 3.0 * std::f64::consts::PI * liquid.viscosity * diameter,
            stiffness: volume * gravity * (-slope),
        })
    }

    /// Eigenvalues (re, im) of the linearised system [1/s] (eq. 2.49), the one with the
    /// larger real part first.
    pub fn eigenvalues(&self) -> [(f64, f64); 2] {
        let a = -self.damping / (2.0 * self.mass);
        let disc = a * a - self.stiffness / self.mass;
        if disc >= 0.0 {
            let s = disc.sqrt();
            [(a + s, 0.0), (a - s, 0.0)]
        } else {
            let s = (-disc).sqrt();
            [(a, s), (a, -s)]
        }
    }

    /// Node or spiral.
    pub fn approach(&self) -> Approach {
        if self.damping * self.damping >= 4.0 * self.mass * self.stiffness {
            Approach::Node
        } else {
            Approach::Spiral
        }
    }
}

fn mass_density(liquid: &Liquid, density: f64, added_mass: bool) -> f64 {
    if added_mass {
        density + 0.5 * liquid.density
    } else {
        density
    }
}

/// Critical diameter [m] between monotone and oscillating approach for particles of
/// `density` (`added_mass = false`: the thesis's 3.2 mm criterion). `None` without an
/// equilibrium.
///
/// ```
/// use magsep_systems::fluid::levitation::critical_diameter;
/// use magsep_systems::fluid::magnet::{Liquid, MagnetModel};
/// let liquid = Liquid { density: 1403.0, viscosity: 5.54e-3, susceptibility: 7e-4 };
/// let m = MagnetModel::Bottom { surface_field: 422e3, pole_size: 0.1181, half_height: 0.075 };
/// let with_xi = critical_diameter(&m, &liquid, 9.81, 1434.0, true).unwrap();
/// let without = critical_diameter(&m, &liquid, 9.81, 1434.0, false).unwrap();
/// assert!((with_xi - 2.91e-3).abs() < 0.01e-3 && (without - 3.22e-3).abs() < 0.01e-3);
/// ```
pub fn critical_diameter(
    magnet: &MagnetModel,
    liquid: &Liquid,
    gravity: f64,
    density: f64,
    added_mass: bool,
) -> Option<f64> {
    let y_e = magnet.equilibrium_height(liquid, gravity, density)?;
    let slope = magnet.apparent_density_gradient(liquid, gravity, y_e).abs();
    let c_m = mass_density(liquid, density, added_mass);
    let d4 = 81.0 * liquid.viscosity.powi(2) / (c_m * gravity * slope);
    (d4.is_finite() && d4 > 0.0).then(|| d4.powf(0.25))
}

/// Levitation time [s] from a sampled trajectory: the last time the particle is farther than
/// `tolerance` [m] from `equilibrium` (linear interpolation of the crossing). Zero if it never
/// leaves the band; the last sample time if it never enters it for good (not settled).
///
/// ```
/// use magsep_systems::fluid::levitation::levitation_time;
/// let t = [0.0, 1.0, 2.0, 3.0];
/// let y = [-1.0, -0.2, 0.05, 0.0];
/// assert!((levitation_time(&t, &y, 0.0, 0.1) - (1.0 + 0.1 / 0.25)).abs() < 1e-12);
/// ```
pub fn levitation_time(times: &[f64], heights: &[f64], equilibrium: f64, tolerance: f64) -> f64 {
    let outside = |y: f64| (y - equilibrium).abs() > tolerance;
    let Some(last) = heights.iter().rposition(|&y| outside(y)) else {
        return 0.0;
    };
    if last + 1 >= heights.len() {
        return times[last];
    }
    // crossing between sample `last` (outside) and `last + 1` (inside)
    let (y0, y1) = (heights[last] - equilibrium, heights[last + 1] - equilibrium);
    let target = tolerance * y0.signum();
    let f = if (y1 - y0).abs() > 0.0 {
        ((target - y0) / (y1 - y0)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    times[last] + f * (times[last + 1] - times[last])
}
