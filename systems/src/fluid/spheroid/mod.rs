//! Fluid forces and torques on oblate spheroids: pure kernels ([T002 ch. 3-4] and App. 4.A;
//! \[Sanjeevi2018\], \[Zastawny2012\], \[Tajfirooz2021PRE\]; errata E-002-16, E-002-18,
//! E-002-22a/b, E-002-26 … E-002-29 and D-002-10 … D-002-13 of docs/references.md).
//!
//! A spheroid has semi-axes a, a, c (c = w a, aspect ratio w = c/a <= 1 for the oblate shapes
//! of [T002 ch. 4]); its symmetry axis is body z, `e` in lab coordinates. magsep's vertical is z
//! (the thesis's y), gravity along −z. SI units throughout.
//!
//! * [`correlations`]: the App. 4.A fits (Sanjeevi 2:5, Zastawny 1:5, rotational mode 2) with
//!   the thesis's typos corrected.
//! * [`disc_table`]: the 1:10 database of [T002 Tables 3.3-3.5] (266 points).
//! * [`disc_model`]: interpolants of that database (the run-time model replaces the thesis's
//!   neural network, whose weights are not published); [`disc_validation`]: their held-out
//!   errors.
//! * [`loads`]: [`spheroid_loads`] (drag, lift, pitching torque) and
//!   [`rotational_resistance`].
//! * [`magnetic_torque`](mod@magnetic_torque): the torque of the magnetic static pressure on the
//!   non-spherical surface, closed form and surface quadrature.
//!
//! Choice of correlation by aspect ratio ([T002 App. 4.A]): w >= 0.99 sphere (Schiller-Naumann,
//! Dennis); 0.3 <= w < 0.99 Sanjeevi 2:5 (the thesis uses it for 1:2 and 2:5); 0.15 <= w < 0.3
//! Zastawny 1:5; w < 0.15 the 1:10 database. Rotational resistance: Zastawny 5:2 prolate mode 2
//! for 0.3 <= w < 0.99 (the thesis's choice for 1:2, which it notes over-resists), Zastawny 1:5
//! oblate mode 2 below.

pub mod correlations;
pub mod disc_model;
pub mod disc_table;
pub mod disc_validation;
pub mod loads;
pub mod magnetic_torque;

#[cfg(test)]
mod correlation_tests;
#[cfg(test)]
mod disc_tests;
#[cfg(test)]
mod loads_tests;
#[cfg(test)]
mod magnetic_torque_tests;

pub use loads::{rotational_resistance, spheroid_loads};
pub use magnetic_torque::{magnetic_torque, magnetic_torque_quadrature};

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Which drag/lift/pitching-torque correlation ([T002 App. 4.A] and ch. 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Correlation {
    /// Schiller-Naumann drag; no lift, no pitching torque.
    Sphere,
    /// Sanjeevi et al. (2018), 2:5 oblate ([T002 eq. 4.28-4.32], corrected).
    Sanjeevi25,
    /// Zastawny et al. (2012), 1:5 oblate ([T002 eq. 4.33-4.37], corrected).
    Zastawny15,
    /// The 1:10 database of [T002 Tables 3.3-3.5], interpolated ([`disc_model`]).
    Disc110,
}

impl Correlation {
    /// The thesis's choice for aspect ratio w = c/a: w >= 0.99 Sphere; 0.3 <= w < 0.99
    /// Sanjeevi25; 0.15 <= w < 0.3 Zastawny15; w < 0.15 Disc110 (also for NaN).
    ///
    /// ```
    /// use magsep_systems::fluid::spheroid::Correlation;
    /// assert_eq!(Correlation::for_aspect_ratio(0.5), Correlation::Sanjeevi25);
    /// assert_eq!(Correlation::for_aspect_ratio(0.1), Correlation::Disc110);
    /// ```
    pub fn for_aspect_ratio(w: f64) -> Self {
        if w >= 0.99 {
            Self::Sphere
        } else if w >= 0.3 {
            Self::Sanjeevi25
        } else if w >= 0.15 {
            Self::Zastawny15
        } else {
            Self::Disc110
        }
    }
}

/// Which rotational-resistance fit: Dennis (sphere, [T002 eq. 2.32]), Zastawny 5:2 prolate
/// mode 2 (used for 1:2 and 2:5), Zastawny 1:5 oblate mode 2 (used for 1:5 and 1:10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RotationFit {
    /// Dennis et al. (1980), the sphere law of [`crate::fluid::drag`].
    Sphere,
    /// Zastawny 5:2 prolate, mode 2.
    ZastawnyProlate52,
    /// Zastawny 1:5 oblate, mode 2.
    ZastawnyOblate15,
}

impl RotationFit {
    /// w >= 0.99 Sphere; 0.3 <= w < 0.99 ZastawnyProlate52; w < 0.3 (and NaN)
    /// ZastawnyOblate15.
    pub fn for_aspect_ratio(w: f64) -> Self {
        if w >= 0.99 {
            Self::Sphere
        } else if w >= 0.3 {
            Self::ZastawnyProlate52
        } else {
            Self::ZastawnyOblate15
        }
    }
}

/// Which density multiplies the drag and lift ([T002 eq. 4.6] prints ρ_p; physically ρ_f).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DragDensity {
    /// ρ_f (physical; default).
    #[default]
    Fluid,
    /// ρ_p (as printed in [T002 eq. 4.6, 4.25]).
    Particle,
}

/// Everything the hydrodynamic kernels need about one spheroid and its liquid.
///
/// ```
/// use magsep_systems::fluid::spheroid::{Correlation, SpheroidHydro};
/// let h = SpheroidHydro::new(8.6e-3, 0.1, 1400.0, 1450.0, 5.54e-3);
/// assert_eq!(h.correlation, Correlation::Disc110);
/// assert!((h.equivalent_diameter - 8.6e-3 * 0.1f64.cbrt()).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpheroidHydro {
    /// Drag, lift and pitching-torque correlation.
    pub correlation: Correlation,
    /// Rotational-resistance fit.
    pub rotation: RotationFit,
    /// Volume-equivalent diameter d_e = d_major w^{1/3} \[m\].
    pub equivalent_diameter: f64,
    /// Major (equatorial) diameter d_major = 2a \[m\].
    pub major_diameter: f64,
    /// Liquid density ρ_f [kg/m³].
    pub fluid_density: f64,
    /// Particle density ρ_p [kg/m³].
    pub particle_density: f64,
    /// Dynamic viscosity μ [Pa s].
    pub viscosity: f64,
    /// Density in the drag and lift (default ρ_f).
    #[serde(default)]
    pub drag_density: DragDensity,
}

impl SpheroidHydro {
    /// The thesis's choices for a spheroid of major diameter `major_diameter` \[m\] and aspect
    /// ratio `w` (drag density ρ_f).
    pub fn new(
        major_diameter: f64,
        w: f64,
        fluid_density: f64,
        particle_density: f64,
        viscosity: f64,
    ) -> Self {
        Self {
            correlation: Correlation::for_aspect_ratio(w),
            rotation: RotationFit::for_aspect_ratio(w),
            equivalent_diameter: major_diameter * w.cbrt(),
            major_diameter,
            fluid_density,
            particle_density,
            viscosity,
            drag_density: DragDensity::Fluid,
        }
    }

    /// Semi-axes (a, c) \[m\]: a = d_major/2, c = a w with w = (d_e/d_major)³ (for
    /// [`magnetic_torque()`]).
    ///
    /// ```
    /// use magsep_systems::fluid::spheroid::SpheroidHydro;
    /// let (a, c) = SpheroidHydro::new(8e-3, 0.1, 1400.0, 1450.0, 5.54e-3).semi_axes();
    /// assert!((a - 4e-3).abs() < 1e-15 && (c - 4e-4).abs() < 1e-15);
    /// ```
    pub fn semi_axes(&self) -> (f64, f64) {
        let a = 0.5 * self.major_diameter;
        let w = (self.equivalent_diameter / self.major_diameter).powi(3);
        (a, a * w)
    }

    /// The density multiplying drag and lift.
    pub fn force_density(&self) -> f64 {
        match self.drag_density {
            DragDensity::Fluid => self.fluid_density,
            DragDensity::Particle => self.particle_density,
        }
    }
}

/// The hydrodynamic loads of [`spheroid_loads`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct HydroLoads {
    /// Drag \[N\], along the slip u − v.
    pub drag: DVec3,
    /// Secant stiffness |F_D|/|u − v| [kg/s] for the linearly implicit integrator.
    pub drag_stiffness: f64,
    /// Lift \[N\], perpendicular to the slip (corrected direction).
    pub lift: DVec3,
    /// Pitching torque [N m] (corrected direction: turns the particle towards broadside).
    pub pitching_torque: DVec3,
    /// Reynolds number ρ_f |u − v| d_e / μ.
    pub reynolds: f64,
    /// Incidence φ \[rad\]: 0 = edge-on, π/2 = broadside.
    pub incidence: f64,
}
