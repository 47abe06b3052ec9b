//! The particle equation of motion (thesis 002, eq. 2.24-2.26 and 2.30, corrected; see
//! docs/references.md) and its time stepping.
//!
//! ```text
//! (m + ½ρ_f V) dv/dt = F_G + F_B + F_MB + F_D + F_H + (ρ_f V + ½ρ_f V) Du/Dt + F_c
//! I dΩ/dt = T_R + T_c,                dx/dt = v
//! ```
//!
//! (the added mass ½ρ_f V (Du/Dt − dv/dt) split into its two parts). Time stepping:
//!
//! * **Implicit** (default): linearly implicit Euler.
//!   `(M + (k + c_H c₀) Δt) (v_{n+1} − v_n) = Δt F_n` where `F_n` is the sum of every
//!   contribution at the start of the step (the drag at v_n, the history of completed steps
//!   seen from t_{n+1}), k the drag's secant stiffness and `c_H c₀ = c_H 2/√Δt` the newest
//!   history weight. The thesis's explicit scheme is unstable once
//!   `r = 18 √(ρ_f μ Δt/π)/((ρ_p + ½ρ_f) d) ≳ 1.3` (history, D-002-2) or `Δt > 2τ_eff` (drag);
//!   this one is not (tested). First order in Δt; the history quadrature is O(Δt^{3/2}).
//! * **Explicit**: forward Euler `M (v_{n+1} − v_n) = Δt F_n` with the history at t_n.
//!
//! Positions then move with the new velocity, `x_{n+1} = x_n + Δt v_{n+1}` (semi-implicit
//! Euler: the levitation oscillator does not gain energy), and so do orientations
//! (`q ← exp(½ Ω Δt) q`).

use glam::{DQuat, DVec3};

/// Effective translational mass [kg]: m, plus ½ρ_f V with added mass.
pub fn effective_mass(mass: f64, volume: f64, fluid_density: f64, added_mass: bool) -> f64 {
    if added_mass {
        mass + 0.5 * fluid_density * volume
    } else {
        mass
    }
}

/// One linearly implicit step of `M dv/dt = F − s (v − v_n)`: returns v_{n+1} [m/s]. With
/// `stiffness = 0` this is forward Euler.
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::fluid::motion::velocity_step;
/// // pure drag relaxation m dv/dt = -k v with k dt / m = 100: implicit Euler does not blow up
/// let v = velocity_step(DVec3::X, -100.0 * DVec3::X, 1.0, 100.0, 1.0);
/// assert!((v.x - 1.0 / 101.0).abs() < 1e-15);
/// ```
pub fn velocity_step(v: DVec3, force: DVec3, mass: f64, stiffness: f64, dt: f64) -> DVec3 {
    v + force * (dt / (mass + stiffness * dt))
}

/// Rotate orientation `q` by angular velocity `omega` [rad/s] over `dt` [s] (exact for
/// constant Ω), renormalised.
pub fn rotate(q: DQuat, omega: DVec3, dt: f64) -> DQuat {
    let angle = omega.length() * dt;
    if angle == 0.0 {
        return q;
    }
    (DQuat::from_axis_angle(omega.normalize(), angle) * q).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_is_exact_and_stays_normalised() {
        let omega = DVec3::new(0.0, 0.0, 2.0);
        let mut q = DQuat::IDENTITY;
        for _ in 0..1000 {
            q = rotate(q, omega, 1e-3);
        }
        let x = q * DVec3::X;
        assert!((x - DVec3::new(2f64.cos(), 2f64.sin(), 0.0)).length() < 1e-12);
        assert!((q.length() - 1.0).abs() < 1e-14);
    }

    #[test]
    fn implicit_step_converges_to_the_exact_relaxation_with_first_order() {
        // m dv/dt = F - k v: v(t) = F/k (1 - e^{-kt/m})
        let (m, k, f, t_end): (f64, f64, f64, f64) = (2.0, 3.0, 1.5, 1.0);
        let exact = f / k * (1.0 - (-k * t_end / m).exp());
        let mut errs = Vec::new();
        for n in [100, 200, 400] {
            let dt = t_end / n as f64;
            let mut v = DVec3::ZERO;
            for _ in 0..n {
                v = velocity_step(v, DVec3::X * (f - k * v.x), m, k, dt);
            }
            errs.push((v.x - exact).abs());
        }
        let order = (errs[0] / errs[2]).log2() / 2.0;
        assert!((order - 1.0).abs() < 0.05, "order {order}");
    }
}
