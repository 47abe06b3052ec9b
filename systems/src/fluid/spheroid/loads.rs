//! Drag, lift and pitching torque of an oblate spheroid in a uniform slip, and its rotational
//! resistance ([T002 eq. 4.6, 4.7, 4.9, 4.11] with corrections; App. 4.A).
//!
//! With `u_r = u − v`, `û = u_r/|u_r|`, `e` the symmetry axis (lab, unit) and ρ the
//! [`DragDensity`](super::DragDensity) choice:
//!
//! * `F_D = (π/8) C_D ρ d_e² |u_r| u_r`, `F_L = (π/8) C_L ρ d_e² |u_r|² e_PL`. Erratum E-002-26:
//!   [T002 eq. 4.6] prints 1/8 for π/8 (½ C ρ A with A = π d²/4) and ρ_p where the physics has ρ_f;
//!   the density is a switch, ρ_f by default.
//! * `T_P = ½ C_T ρ_f (π/8) d_ref³ |u_r|² e_PT` with `d_ref³ = d_e³` for Sanjeevi and Zastawny and
//!   `d_e² d_major` for the 1:10 database: its torque coefficient is `c_T = |T| / (¼ρ_f u² A d)`
//!   with the equatorial A and d, re-based by `w^{−2/3}` only (eq. 3.9 and §3.A), so the literal
//!   torque carries one d_major (erratum E-002-16, D-002-12). (The alternative d_e³ would make it
//!   smaller by w^{1/3} = 0.46; the thesis does not settle it.)
//! * Incidence and directions (corrected, erratum E-002-27; eq. 4.7 and 4.11 are the
//!   elongated-particle forms, which for the short axis of an oblate body give the complement of
//!   the incidence, the wrong lift sign, and a "torque" in the plane of e and û): `φ = arcsin|e·û|`
//!   (0 edge-on, π/2 broadside), `e_⊥ = e − (e·û)û`, `e_PL = sgn(e·û) e_⊥/|e_⊥|`,
//!   `e_PT = sgn(e·û) (e × û)/|e × û|`, C_L, C_T >= 0. The torque turns e towards ±û, i.e. the body
//!   towards broadside (the stable orientation).
//! * Reynolds number `Re = ρ_f |u_r| d_e / μ` (for the 1:10 database `Re_e`, the same thing).
//! * Sphere: Schiller-Naumann (density free, so the switch does not apply), no lift, no torque.
//!
//! Guards: zero slip, or a non-finite slip, gives zero loads; lift and torque are zero when |e_⊥|
//! or |e·û| < 1e-12 (φ = 0 or 90°, where they vanish anyway) or when e is not finite. The drag is
//! computed from `C_D Re` (finite as Re → 0) so the secant stiffness is finite at any slip.
//!
//! Rotational resistance ([T002 eq. 4.9, 4.38]; sphere eq. 2.31-2.32; ρ_f and Re_r per errata
//! E-002-28, E-002-29): `T_R = (1/64) ρ_f C_R |Δ| Δ d_e⁵`, `Δ = ½ω − Ω`, `Re_r = ρ_f d_e² |Δ| / μ`,
//! with C_R from Zastawny mode 2 or Dennis for the sphere
//! ([`crate::fluid::drag::rotational_drag`]). The secant stiffness is `(1/64) d_e³ μ (C_R Re_r)`.

use super::correlations::{
    ZASTAWNY_ROT_OBLATE15, ZASTAWNY_ROT_PROLATE52, continued, rotation_continued,
};
use super::disc_model::disc_coefficients;
use super::{Correlation, HydroLoads, RotationFit, SpheroidHydro};
use crate::fluid::drag::{DragLaw, rotational_drag, translational_drag};
use glam::DVec3;
use std::f64::consts::PI;

/// Below this |e·û| or |e_⊥| lift and torque are set to zero.
pub const DIRECTION_GUARD: f64 = 1e-12;

/// `(C_D Re, C_L Re, C_T)` of the correlation at Re and φ (0 for the sphere's lift and torque;
/// the sphere's drag is handled by the caller).
pub fn coefficients_times_re(correlation: Correlation, re: f64, phi: f64) -> (f64, f64, f64) {
    match correlation {
        Correlation::Sphere => (0.0, 0.0, 0.0),
        Correlation::Disc110 => disc_coefficients(re, phi),
        c => continued(c, re, phi),
    }
}

/// Drag, lift and pitching torque on the spheroid with slip `slip = u − v` [m/s] and symmetry
/// axis `axis` (unit, lab; normalised here).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::fluid::spheroid::{spheroid_loads, SpheroidHydro};
/// let h = SpheroidHydro::new(8.6e-3, 0.1, 1400.0, 1450.0, 5.54e-3);
/// // a disc falling broadside: drag only, along the slip
/// let l = spheroid_loads(&h, DVec3::Z * 0.01, DVec3::Z);
/// assert!(l.drag.z > 0.0 && l.lift == DVec3::ZERO && l.pitching_torque == DVec3::ZERO);
/// assert!((l.incidence - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
/// ```
pub fn spheroid_loads(h: &SpheroidHydro, slip: DVec3, axis: DVec3) -> HydroLoads {
    let speed = slip.length();
    let (d_e, mu, rho_f) = (h.equivalent_diameter, h.viscosity, h.fluid_density);
    if !(speed > 0.0 && speed.is_finite()) {
        return HydroLoads::default();
    }
    let re = rho_f * speed * d_e / mu;
    let u_hat = slip / speed;
    let e = axis.normalize_or_zero();
    let cos_in = e.dot(u_hat);
    let incidence = if cos_in.is_finite() {
        cos_in.abs().min(1.0).asin()
    } else {
        0.0
    };
    if h.correlation == Correlation::Sphere {
        let (drag, k, _) = translational_drag(DragLaw::SchillerNaumann, rho_f, mu, d_e, slip);
        return HydroLoads {
            drag,
            drag_stiffness: k,
            reynolds: re,
            incidence,
            ..Default::default()
        };
    }
    let (cd_re, cl_re, ct) = coefficients_times_re(h.correlation, re, incidence);
    // (π/8) C ρ d² |u|² = (π/8) (C Re) (ρ/ρ_f) μ d |u|
    let rho_ratio = h.force_density() / rho_f;
    let k = PI / 8.0 * cd_re * rho_ratio * mu * d_e;
    let k = if k.is_finite() && k >= 0.0 { k } else { 0.0 };
    let mut out = HydroLoads {
        drag: k * slip,
        drag_stiffness: k,
        reynolds: re,
        incidence,
        ..Default::default()
    };
    let e_perp = e - cos_in * u_hat;
    let n_perp = e_perp.length();
    if !(cos_in.abs() >= DIRECTION_GUARD && n_perp >= DIRECTION_GUARD) {
        return out;
    }
    let sign = cos_in.signum();
    let lift = PI / 8.0 * cl_re * rho_ratio * mu * d_e * speed;
    let cross = e.cross(u_hat);
    let n_cross = cross.length();
    let d_ref3 = match h.correlation {
        Correlation::Disc110 => d_e * d_e * h.major_diameter,
        _ => d_e * d_e * d_e,
    };
    let torque = 0.5 * ct * rho_f * PI / 8.0 * d_ref3 * speed * speed;
    if lift.is_finite() {
        out.lift = lift * sign * e_perp / n_perp;
    }
    if torque.is_finite() && n_cross >= DIRECTION_GUARD {
        out.pitching_torque = torque * sign * cross / n_cross;
    }
    out
}

/// Rotational resistance for `rel = ½ω − Ω` (lab) [rad/s]: (torque [N m], secant stiffness
/// |T|/|rel| [kg m²/s]). Zero for a non-finite `rel`.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::fluid::spheroid::{rotational_resistance, SpheroidHydro};
/// let h = SpheroidHydro::new(8.6e-3, 0.1, 1400.0, 1450.0, 5.54e-3);
/// let (t, k) = rotational_resistance(&h, DVec3::X * 2.0);
/// assert!(t.x > 0.0 && (t.x - 2.0 * k).abs() < 1e-18);
/// ```
pub fn rotational_resistance(h: &SpheroidHydro, rel: DVec3) -> (DVec3, f64) {
    let w = rel.length();
    if !w.is_finite() {
        return (DVec3::ZERO, 0.0);
    }
    let (d_e, mu, rho_f) = (h.equivalent_diameter, h.viscosity, h.fluid_density);
    let k = match h.rotation {
        RotationFit::Sphere => rotational_drag(rho_f, mu, d_e, rel).1,
        fit => {
            let r = if fit == RotationFit::ZastawnyProlate52 {
                &ZASTAWNY_ROT_PROLATE52
            } else {
                &ZASTAWNY_ROT_OBLATE15
            };
            let re_r = rho_f * d_e * d_e * w / mu;
            d_e.powi(3) * mu * rotation_continued(r, re_r) / 64.0
        }
    };
    let k = if k.is_finite() && k >= 0.0 { k } else { 0.0 };
    (k * rel, k)
}
