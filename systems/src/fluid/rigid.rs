//! Rigid-body rotation of axisymmetric particles (thesis 002, §4.2.1.1-4.2.1.2: eq. 4.1-4.3,
//! 4.8 and 4.24).
//!
//! **Kinematics.** magsep stores the orientation as a unit quaternion `q` that rotates body
//! vectors into the lab frame (glam's active convention), with the symmetry axis along body z:
//! `e = q ẑ`. The thesis uses the scalar-last quaternion of the *passive* lab → body map
//! `C(q)` (eq. 4.2), whose rows are the body axes; the two are related by `C = R(q)ᵀ`. Its
//! rate equation (4.3) is `dq/dt = ½ q ⊗ (Ω′, 0)` with Ω′ the body-frame angular velocity;
//! [`quaternion_rate`] gives it in glam's layout and [`thesis_quaternion_step`] is the
//! thesis's forward-Euler step followed by the renormalisation (4.24). The pipeline itself
//! rotates with the exact exponential `q ← exp(½ Ω Δt) q` (exact for constant Ω, so first
//! order overall only through the change of Ω, and never leaves the unit sphere).
//!
//! **Dynamics (eq. 4.8).** Euler's equations in the body frame,
//! `I′ dΩ′/dt + Ω′ × I′Ω′ = T′`, with `I′ = diag(I₁, I₁, I₃)` for a spheroid
//! (I₁ = m(a² + c²)/5, I₃ = 2ma²/5). Two spin models ([`SpinModel`]):
//! * **Suppressed** (the thesis, §4.2.1.2: "we neglect the rotation of particles around the
//!   particle symmetry axis"): Ω stays perpendicular to e. With Ω′_z ≡ 0 and I₁ = I₂ the
//!   gyroscopic term vanishes identically, so `I₁ dΩ/dt = T⊥` (the torque's part ⟂ e). This is
//!   the limit I₃ → ∞, which the collision impulse uses too.
//! * **Free**: the full equations. The torque-free part (the gyroscopic term) is integrated
//!   exactly, as a rotation of (Ω′_x, Ω′_y) by λΔt about body z with λ = (I₃ − I₁)Ω′_z/I₁
//!   (the symmetric top's body-frame precession; it conserves kinetic energy and |L|), then the
//!   torques are applied.
//!
//! **Time stepping.** Like the translation ([`super::motion`]): the rotational drag is
//! linearly implicit with its secant stiffness k (`(I₁ + kΔt) ΔΩ = Δt T`), every other torque
//! (pitching, magnetic, user) is explicit at the start of the step; `Explicit` drops k. The
//! explicit variant diverges once `Δt > 2 τ_r`, `τ_r = I₁/k` the rotational relaxation time:
//! for a 1:10 disc τ_r ∝ ρ_p c a²/μ is tiny (tested: [`rotational_relaxation_time`]); the
//! implicit one is stable at any step for the drag. The explicit restoring torques (pitching,
//! magnetic) bound the step by `Δt < 2 k/κ` in the overdamped limit (κ the restoring
//! stiffness [N m/rad]), far above the thesis's steps (stated in the README).

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// How the rotation about the symmetry axis is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpinModel {
    /// No rotation about the symmetry axis (thesis ch. 4; I₃ → ∞).
    #[default]
    Suppressed,
    /// Full Euler equations with the spheroid's inertia tensor.
    Free,
}

/// `dq/dt` for the body-frame angular velocity `omega_body` [rad/s] (thesis eq. 4.3 in glam's
/// body → lab convention: `½ q ⊗ (Ω′, 0)`).
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::fluid::rigid::quaternion_rate;
/// let r = quaternion_rate(DQuat::IDENTITY, DVec3::Z * 2.0);
/// assert_eq!((r.z, r.w), (1.0, 0.0));
/// ```
pub fn quaternion_rate(q: DQuat, omega_body: DVec3) -> DQuat {
    q * DQuat::from_xyzw(omega_body.x, omega_body.y, omega_body.z, 0.0) * 0.5
}

/// The thesis's orientation update: forward Euler of eq. 4.3 with the lab angular velocity
/// `omega` [rad/s], then the renormalisation of eq. 4.24.
pub fn thesis_quaternion_step(q: DQuat, omega: DVec3, dt: f64) -> DQuat {
    let omega_body = q.inverse() * omega;
    let next = q + quaternion_rate(q, omega_body) * dt;
    let n = next.length();
    if n.is_finite() && n > 0.0 {
        next / n
    } else {
        q
    }
}

/// Rotational relaxation time τ_r = I₁/k \[s\] for a transverse moment `inertia` [kg m²] and
/// rotational-drag stiffness `stiffness` [kg m²/s] (infinite without drag).
pub fn rotational_relaxation_time(inertia: f64, stiffness: f64) -> f64 {
    if stiffness > 0.0 {
        inertia / stiffness
    } else {
        f64::INFINITY
    }
}

/// One step of the angular velocity (lab frame) [rad/s] of an axisymmetric body with
/// orientation `orientation` (body → lab; symmetry axis body z), principal moments `(I₁, I₁, I₃)` = `inertia` [kg m²], under the
/// explicit torque `torque` [N m] and a linearly implicit isotropic drag stiffness
/// `stiffness` [kg m²/s] (0: explicit). `dt` \[s\].
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::fluid::rigid::{angular_velocity_step, SpinModel};
/// let i = DVec3::new(2.0, 2.0, 3.0);
/// // suppressed spin: the axial torque is dropped, the transverse one accelerates
/// let w = angular_velocity_step(DVec3::ZERO, DVec3::new(1.0, 0.0, 5.0), DQuat::IDENTITY, i,
///     0.0, 0.5, SpinModel::Suppressed);
/// assert_eq!(w, DVec3::new(0.25, 0.0, 0.0));
/// ```
pub fn angular_velocity_step(
    omega: DVec3,
    torque: DVec3,
    orientation: DQuat,
    inertia: DVec3,
    stiffness: f64,
    dt: f64,
    spin: SpinModel,
) -> DVec3 {
    let i1 = inertia.x;
    match spin {
        SpinModel::Suppressed => {
            let axis = orientation * DVec3::Z;
            let perp = |v: DVec3| v - v.dot(axis) * axis;
            let w = perp(omega);
            perp(w + perp(torque) * (dt / (i1 + stiffness * dt)))
        }
        SpinModel::Free => {
            let i3 = inertia.z;
            let r = orientation;
            let wb = r.inverse() * omega;
            let tb = r.inverse() * torque;
            // torque-free precession, exact
            let lambda = if i1 > 0.0 { (i3 - i1) * wb.z / i1 } else { 0.0 };
            let (s, c) = (lambda * dt).sin_cos();
            let wb = DVec3::new(c * wb.x - s * wb.y, s * wb.x + c * wb.y, wb.z);
            let next = DVec3::new(
                wb.x + tb.x * dt / (i1 + stiffness * dt),
                wb.y + tb.y * dt / (i1 + stiffness * dt),
                wb.z + tb.z * dt / (i3 + stiffness * dt),
            );
            r * next
        }
    }
}

#[cfg(test)]
#[path = "rigid_tests.rs"]
mod tests;
