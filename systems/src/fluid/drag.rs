//! Steady translational and rotational drag of a sphere (thesis 002, eq. 2.26 and
//! eq. 2.31-2.32; erratum E-002-9a).
//!
//! Translational (Schiller & Naumann 1933): `F_D = 3πμd (1 + 0.15 Re^0.687) (u − v)`,
//! `Re = d|u − v|/ν` (the thesis writes it as `ρ_p V (u − v)/τ_t (…)` with
//! `τ_t = ρ_p d²/(18μ)`, the same thing). Valid to Re ≈ 800; `Stokes` drops the correction.
//!
//! Rotational (Dennis et al. 1980): `T = C_T ½ ρ_f R⁵ |Δ| Δ`, `Δ = ½ω − Ω`,
//! `Re_r = d²|Δ|/ν`, `C_T = 64π/Re_r` (Re_r ≤ 32) or `12.9/√Re_r + 128.4/Re_r`
//! (32 < Re_r < 1000; used beyond 1000 too, where no data exist). Erratum E-002-9a:
//! eq. 2.31 prints ρ_p and a leading minus that makes the torque anti-damping; with ρ_f and
//! Δ = ½ω − Ω the low-Re limit is the exact Stokes torque 8πμR³Δ.
//!
//! Both laws return the secant stiffness `|F|/|u − v|` (`|T|/|Δ|`) for the linearly
//! implicit integrator: `F(v_{n+1}) ≈ k (u − v_{n+1})` with k frozen at the start of the step,
//! which is unconditionally stable for these monotone laws.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The steady drag law.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DragLaw {
    /// Schiller-Naumann: `3πμd (1 + 0.15 Re^0.687)` (the thesis's choice).
    #[default]
    SchillerNaumann,
    /// Stokes: `3πμd` (creeping flow; for validation against exact unsteady Stokes flow).
    Stokes,
}

/// Drag on a sphere of diameter `d` [m] with slip `slip = u − v` [m/s] in a liquid of
/// `density` [kg/m³] and `viscosity` [Pa s]: (force [N], secant stiffness [kg/s], Re).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::fluid::drag::{translational_drag, DragLaw};
/// let (f, k, re) = translational_drag(DragLaw::Stokes, 1000.0, 1e-3, 1e-3, DVec3::X * 1e-3);
/// assert!((k - 3.0 * std::f64::consts::PI * 1e-6).abs() < 1e-18);
/// // Re = ρ d |u − v| / μ = 1000 · 1e-3 · 1e-3 / 1e-3 = 1
/// assert!((f.x - k * 1e-3).abs() < 1e-20 && (re - 1.0).abs() < 1e-12);
/// ```
pub fn translational_drag(
    law: DragLaw,
    density: f64,
    viscosity: f64,
    d: f64,
    slip: DVec3,
) -> (DVec3, f64, f64) {
    let re = density * d * slip.length() / viscosity;
    let correction = match law {
        DragLaw::SchillerNaumann => 1.0 + 0.15 * re.powf(0.687),
        DragLaw::Stokes => 1.0,
    };
    let k = 3.0 * PI * viscosity * d * correction;
    (k * slip, k, re)
}

/// Rotational drag coefficient C_T of Dennis et al. at rotational Reynolds number `re_r`.
pub fn rotational_drag_coefficient(re_r: f64) -> f64 {
    if re_r <= 32.0 {
        64.0 * PI / re_r
    } else {
        12.9 / re_r.sqrt() + 128.4 / re_r
    }
}

/// Torque on a sphere of diameter `d` [m] with `delta = ½ω − Ω` [rad/s]: (torque [N m],
/// secant stiffness [kg m²/s], Re_r).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::fluid::drag::rotational_drag;
/// // creeping limit: 8 π μ R³ Δ
/// let (t, k, _) = rotational_drag(1000.0, 1e-3, 2e-3, DVec3::Z * 0.1);
/// let stokes = 8.0 * std::f64::consts::PI * 1e-3 * 1e-9;
/// assert!((k / stokes - 1.0).abs() < 1e-12 && (t.z / (stokes * 0.1) - 1.0).abs() < 1e-12);
/// ```
pub fn rotational_drag(density: f64, viscosity: f64, d: f64, delta: DVec3) -> (DVec3, f64, f64) {
    let r = 0.5 * d;
    let w = delta.length();
    let re_r = density * d * d * w / viscosity;
    // secant stiffness C_T ½ ρ_f R⁵ |Δ|, continued to the Stokes value at Δ = 0
    let k = if re_r <= 32.0 {
        8.0 * PI * viscosity * r.powi(3)
    } else {
        rotational_drag_coefficient(re_r) * 0.5 * density * r.powi(5) * w
    };
    (k * delta, k, re_r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schiller_naumann_matches_the_thesis_form() {
        // ρ_p V (u − v)/τ_t (1 + 0.15 Re^0.687), τ_t = ρ_p d²/(18μ)
        let (rho_f, mu, d, rho_p) = (1403.0, 5.54e-3, 4e-3, 1434.0);
        for speed in [1e-4, 1e-2, 0.05, 0.2] {
            let slip = DVec3::new(0.3, -1.0, 0.2).normalize() * speed;
            let (f, _, re) = translational_drag(DragLaw::SchillerNaumann, rho_f, mu, d, slip);
            let v = PI * d.powi(3) / 6.0;
            let tau = rho_p * d * d / (18.0 * mu);
            let thesis = rho_p * v / tau * (1.0 + 0.15 * re.powf(0.687)) * slip;
            assert!((f - thesis).length() <= 1e-13 * thesis.length());
            assert!((re - rho_f * d * speed / mu).abs() < 1e-12 * re);
        }
    }

    #[test]
    fn rotational_law_is_nearly_continuous_and_damping() {
        let below = rotational_drag_coefficient(32.0);
        let above = rotational_drag_coefficient(32.0 + 1e-9);
        assert!((below - above).abs() / below < 2e-3, "{below} {above}");
        // the torque always drives Ω towards ω/2 (damping), in every regime
        for w in [1e-3, 1.0, 100.0, 1e4] {
            let delta = DVec3::new(1.0, 2.0, -0.5).normalize() * w;
            let (t, k, _) = rotational_drag(1403.0, 5.54e-3, 5e-3, delta);
            assert!(t.dot(delta) > 0.0 && k > 0.0);
        }
    }
}
