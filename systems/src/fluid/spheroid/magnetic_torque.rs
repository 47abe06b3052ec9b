//! Magnetic-buoyancy torque on a non-magnetic spheroid in a paramagnetic liquid
//! ([T002 eq. 4.9-4.10]; docs/references.md).
//!
//! The liquid's magnetic static pressure `p_M(z) = μ₀ ∫₀^H M dH = ½ μ₀ χ H(z)²` (linear
//! liquid, M = χH) acts on the particle surface with the traction `−p_M N` (N outward), so
//!
//! `T_MB = −∮ r × p_M N dS = −∫_V r × ∇p_M dV`, `F_MB = −∮ p_M N dS = −∫_V ∇p_M dV`,
//!
//! r relative to the centre. Erratum E-002-28: [T002 eq. 4.9] prints the integrand `r × (p I · N)`
//! without the minus sign, which would destabilise the flat-horizontal orientation. The linear
//! part of p_M gives the point buoyancy `−V dp_M/dz e_z` and no torque (as gravity's
//! hydrostatic pressure); to second order in the particle size, with the second-moment tensor
//! `∫ r rᵀ dV = (V/5)(a² I + (c² − a²) e eᵀ)` of a spheroid with semi-axes a, a, c and symmetry
//! axis e,
//!
//! `T_MB ≈ (V/5)(a² − c²) p_M'' (e·e_z)(e × e_z)`, `V = (4π/3) a² c`.
//!
//! For an oblate body (a > c) in a field with p_M'' > 0 (every magnet model of
//! [`crate::fluid::magnet`]) it turns e towards ±e_z: the flat face horizontal is stable. The
//! next order is `O((κa)²)` relative, κ = 2π/p (0.02 % for the rig of [T002 Table 4.2] and a
//! 4 mm particle). The thesis evaluates the integral by a first-order surface quadrature; the
//! midpoint rule of [`magnetic_torque_quadrature`] is the reference for the closed form
//! (D-002-9, D-002-13: 7.128e-9 N m closed form against 7.131e-9 N m by 800 × 400 points for a
//! tilted 1:10 disc in the two-magnet rig; the force matches the point buoyancy to 0.05 %).

use glam::{DQuat, DVec3};
use std::f64::consts::PI;

/// The second-order magnetic-buoyancy torque \[N m\] on a spheroid with semi-axes `a`, `a`, `c`
/// \[m\] and symmetry axis `axis` (normalised here) where `p_curvature` = d²p_M/dz² [Pa/m²].
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::fluid::spheroid::magnetic_torque;
/// // tilted disc, p'' > 0: the torque turns the axis back to vertical
/// let e = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
/// let t = magnetic_torque(4e-3, 4e-4, 1e5, e);
/// // a small rotation about the torque raises the axis towards e_z
/// assert!((e + 1e3 * t.cross(e)).normalize().z > e.z);
/// ```
pub fn magnetic_torque(a: f64, c: f64, p_curvature: f64, axis: DVec3) -> DVec3 {
    let e = axis.normalize_or_zero();
    let v = 4.0 / 3.0 * PI * a * a * c;
    let t = v / 5.0 * (a * a - c * c) * p_curvature * e.z * e.cross(DVec3::Z);
    if t.is_finite() { t } else { DVec3::ZERO }
}

/// The torque and force `(−∮ r × p N dS, −∮ p N dS)` on the spheroid (semi-axes `a`, `a`, `c`,
/// symmetry axis `axis`) for the pressure profile `pressure(z)`, z relative to the centre, by
/// the midpoint rule on `n_theta` × `n_phi` cells of the polar parametrisation (second order;
/// zeros if either count is 0).
pub fn magnetic_torque_quadrature(
    a: f64,
    c: f64,
    axis: DVec3,
    pressure: impl Fn(f64) -> f64,
    n_theta: usize,
    n_phi: usize,
) -> (DVec3, DVec3) {
    if n_theta == 0 || n_phi == 0 {
        return (DVec3::ZERO, DVec3::ZERO);
    }
    let e = axis.normalize_or_zero();
    if e == DVec3::ZERO {
        return (DVec3::ZERO, DVec3::ZERO);
    }
    let rot = DQuat::from_rotation_arc(DVec3::Z, e);
    let (dt, dp) = (PI / n_theta as f64, 2.0 * PI / n_phi as f64);
    let (mut torque, mut force) = (DVec3::ZERO, DVec3::ZERO);
    for i in 0..n_theta {
        let th = (i as f64 + 0.5) * dt;
        let (st, ct) = th.sin_cos();
        for k in 0..n_phi {
            let (sp, cp) = ((k as f64 + 0.5) * dp).sin_cos();
            // body frame: r and the vector area element ∂r/∂θ × ∂r/∂φ (outward)
            let r = DVec3::new(a * st * cp, a * st * sp, c * ct);
            let n = DVec3::new(a * c * st * st * cp, a * c * st * st * sp, a * a * st * ct);
            let (r, n) = (rot * r, rot * n * (dt * dp));
            let p = pressure(r.z);
            torque -= p * r.cross(n);
            force -= p * n;
        }
    }
    let fin = |v: DVec3| if v.is_finite() { v } else { DVec3::ZERO };
    (fin(torque), fin(force))
}
