//! Quasi-static ferrohydrodynamics of a paramagnetic liquid above/between Halbach magnets
//! (thesis 002, ch. 1-2; see docs/references.md).
//!
//! The field of an ideal Halbach array decays exponentially from its strong face with the
//! pole size p (eq. 2.6-2.8; 1-D, `H = H(y) e_y`):
//!
//! * bottom magnet (face at y = −L): `H = H₀ exp(−π(L + y)/p)`, y ≥ −L;
//! * top magnet (face at y = +L): `H = H₀ exp(−π(L − y)/p)`, y ≤ L;
//! * two facing magnets: `H = H₀ (exp(−π(L + y)/p) + exp(−π(L − y)/p))` (magnitudes added,
//!   the thesis's modelling assumption), −L ≤ y ≤ L.
//!
//! A liquid with `M = χ H` feels the Kelvin force density `μ₀ M ∇H`; its static pressure makes
//! the buoyancy of a small body `F_B = (ρ_f g − μ₀ M dH/dy) V e_y = ρ_{f,a} V g e_y` with the
//! local apparent density (eq. 2.12-2.13) `ρ_{f,a}(y) = ρ_f − μ₀ χ H (dH/dy) / g`. The
//! "magnetic buoyancy" is `−μ₀ V χ H dH/dy e_y`. A particle levitates where
//! `ρ_{f,a}(y_e) = ρ_p` (eq. 2.14).
//!
//! Errata implemented here (E-002-5, E-002-6, E-002-7): the equilibrium heights of table 2.2 are replaced by the
//! forms derived from eq. 2.17-2.19 (the printed ones measure from the magnet face, carry 2π
//! for π, and lack e^{2πL/p} for two magnets); the two-magnet resolution (eq. 2.23) uses
//! 2π², not 4π² (only 2π² gives the thesis's own 0.97 ρ_f/L); the critical diameter keeps the
//! added-mass factor ξ of eq. 2.50 unless asked not to (the thesis's quoted 3.2 mm is the
//! criterion without ξ, [T002 §2.5.1.1]).
//!
//! The point value of the force density is used over the particle volume; for an exponential
//! field the exact volume average is larger by `3(κR cosh κR − sinh κR)/(κR)³ ≈ 1 + (κR)²/10`
//! (κ = 2π/p): 0.26 % for a 6 mm sphere in the table 2.1 rig (D-002-1).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Vacuum permeability μ₀ [T m/A] (CODATA 2018).
pub const MU0: f64 = 1.256_637_062_12e-6;

/// A Newtonian, linearly magnetisable liquid.
///
/// ```
/// use magsep_systems::fluid::magnet::Liquid;
/// let mncl2 = Liquid { density: 1403.0, viscosity: 5.54e-3, susceptibility: 7e-4 };
/// assert!((mncl2.kinematic_viscosity() - 3.9487e-6).abs() < 1e-9);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Liquid {
    /// Mass density ρ_f [kg/m³]. Range: > 0.
    pub density: f64,
    /// Dynamic viscosity μ [Pa s]. Range: > 0.
    pub viscosity: f64,
    /// Volume susceptibility χ (SI, dimensionless; 7e-4 for saturated MnCl₂(aq)). Default 0.
    #[serde(default)]
    pub susceptibility: f64,
}

impl Liquid {
    /// Kinematic viscosity ν = μ / ρ_f [m²/s].
    pub fn kinematic_viscosity(&self) -> f64 {
        self.viscosity / self.density
    }
}

/// The magnet arrangement (eq. 2.6-2.8).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum MagnetModel {
    /// No magnet: the apparent density is ρ_f everywhere.
    None,
    /// A magnet below the liquid, strong face at y = −L (eq. 2.6): heavy particles levitate.
    Bottom {
        /// Field strength at the face H₀ [A/m]. Range: >= 0.
        surface_field: f64,
        /// Pole size p (half the magnetisation wavelength) \[m\]. Range: > 0.
        pole_size: f64,
        /// L \[m\]: the face is at y = −L. Range: > 0.
        half_height: f64,
    },
    /// A magnet above the liquid, strong face at y = +L (eq. 2.7): light particles levitate.
    Top {
        /// Field strength at the face H₀ [A/m]. Range: >= 0.
        surface_field: f64,
        /// Pole size p \[m\]. Range: > 0.
        pole_size: f64,
        /// L \[m\]: the face is at y = +L. Range: > 0.
        half_height: f64,
    },
    /// Two facing magnets, faces at y = ±L (eq. 2.8, magnitudes superposed).
    Two {
        /// Field strength at each face from its own magnet H₀ [A/m]. Range: >= 0.
        surface_field: f64,
        /// Pole size p \[m\]. Range: > 0.
        pole_size: f64,
        /// L \[m\]: the faces are at y = ±L. Range: > 0.
        half_height: f64,
    },
}

impl MagnetModel {
    fn params(&self) -> Option<(f64, f64, f64)> {
        match *self {
            Self::None => None,
            Self::Bottom {
                surface_field,
                pole_size,
                half_height,
            }
            | Self::Top {
                surface_field,
                pole_size,
                half_height,
            }
            | Self::Two {
                surface_field,
                pole_size,
                half_height,
            } => Some((surface_field, pole_size, half_height)),
        }
    }

    /// The interval of y where the model holds \[m\] (outside it the magnet body is).
    pub fn valid_range(&self) -> (f64, f64) {
        match *self {
            Self::None => (f64::NEG_INFINITY, f64::INFINITY),
            Self::Bottom { half_height, .. } => (-half_height, f64::INFINITY),
            Self::Top { half_height, .. } => (f64::NEG_INFINITY, half_height),
            Self::Two { half_height, .. } => (-half_height, half_height),
        }
    }

    /// Field strength H(y) [A/m] and its gradient dH/dy [A/m²].
    ///
    /// ```
    /// use magsep_systems::fluid::magnet::MagnetModel;
    /// let m = MagnetModel::Bottom { surface_field: 422e3, pole_size: 0.1181, half_height: 0.075 };
    /// let (h, dh) = m.field(-0.075);
    /// assert_eq!(h, 422e3);
    /// assert!((dh + std::f64::consts::PI / 0.1181 * h).abs() < 1e-6);
    /// ```
    pub fn field(&self, y: f64) -> (f64, f64) {
        let Some((h0, p, l)) = self.params() else {
            return (0.0, 0.0);
        };
        let k = PI / p;
        match self {
            Self::Bottom { .. } => {
                let h = h0 * (-k * (l + y)).exp();
                (h, -k * h)
            }
            Self::Top { .. } => {
                let h = h0 * (-k * (l - y)).exp();
                (h, k * h)
            }
            _ => {
                let a = h0 * (-k * (l + y)).exp();
                let b = h0 * (-k * (l - y)).exp();
                (a + b, k * (b - a))
            }
        }
    }

    /// `μ₀ χ H dH/dy` [N/m³]: the y component of the Kelvin force density μ₀ M ∇H.
    pub fn kelvin_density(&self, susceptibility: f64, y: f64) -> f64 {
        let (h, dh) = self.field(y);
        MU0 * susceptibility * h * dh
    }

    /// Apparent density ρ_{f,a}(y) = ρ_f − μ₀ χ H (dH/dy) / g [kg/m³] (eq. 2.13), `gravity` g
    /// [m/s²] > 0.
    ///
    /// ```
    /// use magsep_systems::fluid::magnet::{Liquid, MagnetModel, MU0};
    /// let liquid = Liquid { density: 1403.0, viscosity: 5.54e-3, susceptibility: 7e-4 };
    /// let m = MagnetModel::Bottom { surface_field: 422e3, pole_size: 0.1181, half_height: 0.075 };
    /// // at the face the excess is π μ₀ χ H₀² / (p g) (eq. 2.17, 2.20)
    /// let excess = std::f64::consts::PI * MU0 * 7e-4 * 422e3f64.powi(2) / (0.1181 * 9.81);
    /// assert!((m.apparent_density(&liquid, 9.81, -0.075) - 1403.0 - excess).abs() < 1e-9);
    /// ```
    pub fn apparent_density(&self, liquid: &Liquid, gravity: f64, y: f64) -> f64 {
        liquid.density - self.kelvin_density(liquid.susceptibility, y) / gravity
    }

    /// d ρ_{f,a} / dy [kg/m⁴], analytic (all three models have `H dH/dy ∝` exponentials).
    pub fn apparent_density_gradient(&self, liquid: &Liquid, gravity: f64, y: f64) -> f64 {
        let Some((h0, p, l)) = self.params() else {
            return 0.0;
        };
        let k = PI / p;
        let c = MU0 * liquid.susceptibility / gravity;
        // H H' for each model, differentiated once more
        let d_hh = match self {
            Self::Bottom { .. } => 2.0 * k * k * h0 * h0 * (-2.0 * k * (l + y)).exp(),
            Self::Top { .. } => 2.0 * k * k * h0 * h0 * (-2.0 * k * (l - y)).exp(),
            _ => 4.0 * k * k * h0 * h0 * (-2.0 * k * l).exp() * (2.0 * k * y).cosh(),
        };
        -c * d_hh
    }

    /// Magnetic static pressure `p_M(y) = μ₀ ∫₀^H M dH = ½ μ₀ χ H(y)²` \[Pa\] of a liquid of
    /// susceptibility `chi` ([T002 eq. 4.10] with M = χH).
    pub fn static_pressure(&self, chi: f64, y: f64) -> f64 {
        let (h, _) = self.field(y);
        0.5 * MU0 * chi * h * h
    }

    /// d²p_M/dy² [Pa/m²], analytic: `2 μ₀ χ k² H²` for one magnet (k = π/p) and
    /// `4 μ₀ χ k² H₀² e^{−2kL} cosh(2ky)` for two (the cross term of H² is constant); 0 without
    /// a magnet. It sets the magnetic-buoyancy torque on a non-spherical particle.
    ///
    /// ```
    /// use magsep_systems::fluid::magnet::MagnetModel;
    /// let m = MagnetModel::Two { surface_field: 637e3, pole_size: 0.2, half_height: 0.075 };
    /// let (y, h) = (-0.05, 1e-4);
    /// let fd = (m.static_pressure(7e-4, y + h) - 2.0 * m.static_pressure(7e-4, y)
    ///     + m.static_pressure(7e-4, y - h)) / (h * h);
    /// assert!((m.static_pressure_curvature(7e-4, y) / fd - 1.0).abs() < 1e-5);
    /// ```
    pub fn static_pressure_curvature(&self, chi: f64, y: f64) -> f64 {
        let Some((h0, p, l)) = self.params() else {
            return 0.0;
        };
        let k = PI / p;
        match self {
            Self::Two { .. } => {
                4.0 * MU0 * chi * k * k * h0 * h0 * (-2.0 * k * l).exp() * (2.0 * k * y).cosh()
            }
            _ => {
                let (h, _) = self.field(y);
                2.0 * MU0 * chi * k * k * h * h
            }
        }
    }

    /// Magnetic buoyancy force on a body of `volume` \[m³\] at height y: −μ₀ V χ H dH/dy \[N\]
    /// along y.
    pub fn magnetic_buoyancy(&self, susceptibility: f64, volume: f64, y: f64) -> f64 {
        -volume * self.kelvin_density(susceptibility, y)
    }

    /// The sorting range |Δρ_{f,a}|_max [kg/m³]: the largest departure of the apparent
    /// density from ρ_f within the valid range (eq. 2.20-2.21).
    pub fn sorting_range(&self, liquid: &Liquid, gravity: f64) -> f64 {
        let Some((h0, p, l)) = self.params() else {
            return 0.0;
        };
        let a = PI * MU0 * liquid.susceptibility * h0 * h0 / (p * gravity);
        match self {
            Self::Two { .. } => a * (1.0 - (-4.0 * PI * l / p).exp()).abs(),
            _ => a,
        }
    }

    /// The resolution: the largest |dρ_{f,a}/dy| in the valid range [kg/m⁴] (eq. 2.22, and
    /// eq. 2.23 corrected to 2π², at the faces).
    pub fn max_density_gradient(&self, liquid: &Liquid, gravity: f64) -> f64 {
        let (lo, hi) = self.valid_range();
        match self {
            Self::None => 0.0,
            Self::Bottom { .. } => self.apparent_density_gradient(liquid, gravity, lo).abs(),
            Self::Top { .. } => self.apparent_density_gradient(liquid, gravity, hi).abs(),
            Self::Two { .. } => self.apparent_density_gradient(liquid, gravity, hi).abs(),
        }
    }

    /// Equilibrium height y_e \[m\] of a particle of density `particle_density` [kg/m³] from the
    /// closed forms (derived from eq. 2.17-2.19; the printed table 2.2 is wrong, erratum E-002-5).
    /// `None` when the particle does not levitate in the valid range.
    ///
    /// ```
    /// use magsep_systems::fluid::magnet::{Liquid, MagnetModel};
    /// // PVC-U in the table 2.1 rig: -0.344 L (thesis -0.35 L)
    /// let liquid = Liquid { density: 1403.0, viscosity: 5.54e-3, susceptibility: 7e-4 };
    /// let m = MagnetModel::Bottom { surface_field: 422e3, pole_size: 0.1181, half_height: 0.075 };
    /// let y = m.equilibrium_height(&liquid, 9.81, 1434.0).unwrap();
    /// assert!((y / 0.075 + 0.344).abs() < 1e-3);
    /// ```
    pub fn equilibrium_height(
        &self,
        liquid: &Liquid,
        gravity: f64,
        particle_density: f64,
    ) -> Option<f64> {
        let (h0, p, l) = self.params()?;
        let a = PI * MU0 * liquid.susceptibility * h0 * h0 / (p * gravity);
        let d = particle_density - liquid.density;
        let y = match self {
            Self::Bottom { .. } if d > 0.0 => -l - p / (2.0 * PI) * (d / a).ln(),
            Self::Top { .. } if d < 0.0 => l + p / (2.0 * PI) * (-d / a).ln(),
            Self::Two { .. } => {
                p / (2.0 * PI) * (-d * (2.0 * PI * l / p).exp() / (2.0 * a)).asinh()
            }
            _ => return None,
        };
        let (lo, hi) = self.valid_range();
        (y.is_finite() && y >= lo && y <= hi).then_some(y)
    }

    /// Equilibrium height \[m\] by root finding on ρ_{f,a}(y) − ρ_p over the valid range
    /// (bisection to 1e-14 relative; independent of the closed forms). `None` if there is no
    /// sign change (no levitation in range). For unbounded ranges the search extends 50 pole
    /// sizes from the face.
    pub fn equilibrium_height_by_root(
        &self,
        liquid: &Liquid,
        gravity: f64,
        particle_density: f64,
    ) -> Option<f64> {
        let (_, p, _) = self.params()?;
        let (lo, hi) = self.valid_range();
        let lo = if lo.is_finite() { lo } else { hi - 50.0 * p };
        let hi = if hi.is_finite() { hi } else { lo + 50.0 * p };
        let f = |y: f64| self.apparent_density(liquid, gravity, y) - particle_density;
        let (mut a, mut b) = (lo, hi);
        let (fa, fb) = (f(a), f(b));
        if fa == 0.0 {
            return Some(a);
        }
        if fb == 0.0 {
            return Some(b);
        }
        if fa.signum() == fb.signum() {
            return None;
        }
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            let fm = f(m);
            if fm == 0.0 || (b - a) < 1e-14 * (a.abs() + b.abs()).max(1e-300) {
                return Some(m);
            }
            if fm.signum() == fa.signum() {
                a = m;
            } else {
                b = m;
            }
        }
        Some(0.5 * (a + b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table_2_3() -> (Liquid, MagnetModel) {
        (
            Liquid {
                density: 1400.0,
                viscosity: 5.54e-3,
                susceptibility: 7e-4,
            },
            MagnetModel::Two {
                surface_field: 637e3,
                pole_size: 0.2,
                half_height: 0.075,
            },
        )
    }

    fn table_2_1() -> (Liquid, MagnetModel) {
        (
            Liquid {
                density: 1403.0,
                viscosity: 5.54e-3,
                susceptibility: 7e-4,
            },
            MagnetModel::Bottom {
                surface_field: 422e3,
                pole_size: 0.1181,
                half_height: 0.075,
            },
        )
    }

    #[test]
    fn table_2_3_sorting_range_and_resolution() {
        let (liquid, m) = table_2_3();
        let range = m.sorting_range(&liquid, 9.81) / liquid.density;
        let grad = m.max_density_gradient(&liquid, 9.81) * 0.075 / liquid.density;
        assert!((range - 0.4046).abs() < 1e-3, "{range}");
        assert!((grad - 0.9705).abs() < 1e-3, "{grad}");
        // the sorting range is the departure at the faces, found independently by scanning
        let scan = (0..=2000)
            .map(|k| -0.075 + 0.15 * k as f64 / 2000.0)
            .map(|y| (m.apparent_density(&liquid, 9.81, y) - liquid.density).abs())
            .fold(0.0, f64::max);
        assert!((scan / liquid.density - range).abs() < 1e-12);
    }

    #[test]
    fn field_gradients_match_finite_differences_to_1e_10() {
        for (liquid, m) in [table_2_1(), table_2_3()] {
            let top = MagnetModel::Top {
                surface_field: 422e3,
                pole_size: 0.1181,
                half_height: 0.075,
            };
            for model in [m, top] {
                for k in 0..=20 {
                    let y = -0.07 + 0.14 * k as f64 / 20.0;
                    let (_, dh) = model.field(y);
                    let fd = d4(|y| model.field(y).0, y);
                    assert!((dh - fd).abs() <= 1e-10 * dh.abs().max(1.0), "{dh} {fd}");
                    let rho = |y: f64| model.apparent_density(&liquid, 9.81, y);
                    let g = model.apparent_density_gradient(&liquid, 9.81, y);
                    let fd = d4(rho, y);
                    assert!((g - fd).abs() <= 1e-8 * g.abs().max(1e-3), "{g} {fd}");
                    // apparent density against ½ μ₀ χ d(H²)/dy, differentiated numerically
                    let kelvin =
                        0.5 * MU0 * liquid.susceptibility * d4(|y| model.field(y).0.powi(2), y);
                    let direct = liquid.density - kelvin / 9.81;
                    assert!((rho(y) - direct).abs() <= 1e-10 * liquid.density);
                }
            }
        }
    }

    /// Fourth-order central difference.
    fn d4(f: impl Fn(f64) -> f64, y: f64) -> f64 {
        let h = 1e-4;
        (-f(y + 2.0 * h) + 8.0 * f(y + h) - 8.0 * f(y - h) + f(y - 2.0 * h)) / (12.0 * h)
    }

    #[test]
    fn equilibrium_heights_closed_form_equal_root_finding() {
        let (liquid, m) = table_2_1();
        let y = m.equilibrium_height(&liquid, 9.81, 1434.0).unwrap();
        let r = m.equilibrium_height_by_root(&liquid, 9.81, 1434.0).unwrap();
        assert!(
            (y - r).abs() < 1e-12 && (y / 0.075 + 0.344).abs() < 0.01,
            "{y} {r}"
        );
        let pom = m.equilibrium_height(&liquid, 9.81, 1406.0).unwrap();
        assert!((pom / 0.075 - 0.241).abs() < 1e-3, "{pom}");
        // lighter than the liquid: no levitation above a bottom magnet
        assert!(m.equilibrium_height(&liquid, 9.81, 1300.0).is_none());
        assert!(
            m.equilibrium_height_by_root(&liquid, 9.81, 1300.0)
                .is_none()
        );
        // the ten density groups of the many-particle runs (D-002-7)
        let (liquid, two) = table_2_3();
        // ratios 0.7 + 0.6 k / 9 (ten evenly spaced groups)
        for (k, expect) in [0.876, 0.774, 0.641, 0.456, 0.178].into_iter().enumerate() {
            let ratio = 0.7 + 0.6 * k as f64 / 9.0;
            for sign in [1.0, -1.0] {
                let rho = liquid.density * if sign > 0.0 { ratio } else { 2.0 - ratio };
                let y = two.equilibrium_height(&liquid, 9.81, rho).unwrap();
                let r = two.equilibrium_height_by_root(&liquid, 9.81, rho).unwrap();
                assert!((y - r).abs() < 1e-12);
                assert!((y / 0.075 - sign * expect).abs() < 2e-3, "{ratio} {y}");
            }
        }
        // top magnet: light particles levitate, mirror image of the bottom magnet
        let top = MagnetModel::Top {
            surface_field: 422e3,
            pole_size: 0.1181,
            half_height: 0.075,
        };
        let (liquid, _) = table_2_1();
        let y = top
            .equilibrium_height(&liquid, 9.81, 2.0 * 1403.0 - 1434.0)
            .unwrap();
        let r = top
            .equilibrium_height_by_root(&liquid, 9.81, 2.0 * 1403.0 - 1434.0)
            .unwrap();
        assert!((y - r).abs() < 1e-12 && (y / 0.075 - 0.344).abs() < 0.01);
    }

    #[test]
    fn printed_table_2_2_would_be_wrong() {
        // the printed form (2π, measured from the face) puts PVC-U at -0.17 L, not -0.35 L
        let (liquid, m) = table_2_1();
        let (p, h0) = (0.1181, 422e3);
        let printed = -p / (2.0 * PI)
            * ((1434.0 - 1403.0) * p * 9.81 / (2.0 * PI * MU0 * 7e-4 * h0 * h0)).ln();
        let ours = m.equilibrium_height(&liquid, 9.81, 1434.0).unwrap();
        assert!((printed / 0.075 - ours / 0.075).abs() > 0.1);
    }
}
