//! Field of a uniformly magnetised finite circular cylinder in its body frame (axis z, centre
//! at the origin, radius `R`, **half** length `L`): thesis 000 ch. 5, eqs. 5.3-5.6
//! (longitudinal) and 5.19-5.22 (transverse), in the stable Bulirsch `cel` form of D-000-1
//! (docs/references.md), with an exact near-axis branch.
//!
//! ## Formulation
//! A uniform magnetisation `M` gives `H = Hess(Ψ) · M`, where `Ψ(r) = ∫_V dV'/(4π|r - r'|)` is
//! the Newtonian potential of the cylinder (`Φ_m = -M · ∇Ψ`). By symmetry `Hess(Ψ)` needs only
//! four functions of `(ρ, z)`: `Ψ_zz`, `u = Ψ_ρz / ρ`, `b = Ψ_ρ / ρ` and
//! `e = (Ψ_ρρ - Ψ_ρ/ρ) / ρ²`, and then, with `χ = 1` inside, 0 outside,
//!
//! ```text
//! H_x = m_x (b + e x²) + m_y e x y + m_z u x
//! H_y = m_x e x y + m_y (b + e y²) + m_z u y
//! H_z = m_x u x + m_y u y + m_z Ψ_zz,          B = μ0 (H + χ M)
//! ```
//!
//! In the thesis's notation (`ξ± = z ± L`, `α±`, `β±`, `γ`, `k±` of eq. 5.5):
//! `Ψ_ρz = B_ρ/(μ0 M_l)` of eq. 5.3 (`(R/π)[α₊P₁(k₊) - α₋P₁(k₋)]`), `Ψ_zz + χ = B_z/(μ0 M_l)`
//! (`R/(π(ρ+R)) [β₊P₂ - β₋P₂]`), `b = -H_φ/(M_t sin φ)` of eq. 5.21
//! (`-(R/(πρ)) [β₊P₃ - β₋P₃]`), and `Ψ_ρρ = -χ - Ψ_zz - b` (Poisson's equation `∇²Ψ = -χ`)
//! replaces the thesis's `P₄`, which is therefore never evaluated (eq. 5.21's `H_ρ` is
//! `M_t cos φ Ψ_ρρ`; the tests check the identity against `P₄`).
//! `P₁ = cel(k,1,1,-1)`, `P₂ = cel(k,γ²,1,-γ)` (**the thesis's appendix 5.A prints `+γ`, a
//! typo: erratum E-000-15**), `P₃ = cel(k,1,0,1) - γ² cel(k,γ²,0,1)`.
//!
//! ## Delicate places (all handled on purpose; never NaN or inf)
//! * **Axis.** `b` carries `1/ρ` times a difference that vanishes like `ρ`, so the `cel` form
//!   loses `log10(R/ρ)` digits. For `ρ < 0.05 R` the kernel uses the exact expansion of `Ψ` about
//!   the axis, `Ψ = Σ (-1)ⁿ ψ₀⁽²ⁿ⁾(z) ρ²ⁿ / (4ⁿ n!²) - χ ρ²/4`, through `ρ¹⁴` (truncation
//!   `~(ρ/R)¹⁴ < 1e-18`), with `ψ₀'' = (g(ξ₊) - g(ξ₋))/2 - χ`, `g(ξ) = ξ/√(ξ² + R²)`: on the axis it
//!   is the solenoid `B_z` and eq. 5.26's `H_x = -(M/4)[g(ξ₊) - g(ξ₋)]`.
//! * **Lateral surface and end faces** (`ρ = R` or `|z| = L`): the field jumps. Exactly on the
//!   surface the kernel returns the mean of the two one-sided limits (`χ = 1/2`; the `cel`
//!   form with `γ = 0` gives the principal value). Off the surface it is accurate to ~1e-14
//!   down to distances of 1e-10 R.
//! * **Rims** (`ρ = R`, `|z| = L`): `B` diverges like `ln(R/d)/(2π)`. `k±` is clamped at
//!   [`KC_MIN`](super::cel::KC_MIN), so exactly on a rim the value is that at `d ≈ 1e-150 R`.
//! * **Far field**: see [`super::multipole`]; the dispatcher in [`super::source`] switches to
//!   the multipole expansion where it is at least as accurate.

use std::f64::consts::PI;

use super::cel::cel_cylinder_pair;
use super::real::Real;

/// Below `ρ = AXIS_SWITCH · R` the near-axis expansion is used.
pub const AXIS_SWITCH: f64 = 0.05;

/// The four functions of `(ρ, z)` that make up `Hess(Ψ)` (see the module docs), plus `χ`.
#[derive(Debug, Clone, Copy)]
pub struct HessParts<T> {
    /// `Ψ_zz`.
    pub pzz: T,
    /// `Ψ_ρz / ρ`.
    pub u: T,
    /// `Ψ_ρ / ρ`.
    pub b: T,
    /// `(Ψ_ρρ - Ψ_ρ/ρ) / ρ²`.
    pub e: T,
    /// 1 inside, 0 outside, 1/2 on the surface.
    pub chi: f64,
}

impl<T: Real> HessParts<T> {
    /// `H = Hess(Ψ) · m` at body-frame `(x, y)` (the parts already hold the `z` dependence).
    #[inline]
    pub fn apply(&self, x: T, y: T, m: [f64; 3]) -> [T; 3] {
        let exy = self.e * x * y;
        let ux = self.u * x;
        let uy = self.u * y;
        [
            (self.b + self.e * x * x) * m[0] + exy * m[1] + ux * m[2],
            exy * m[0] + (self.b + self.e * y * y) * m[1] + uy * m[2],
            ux * m[0] + uy * m[1] + self.pzz * m[2],
        ]
    }
}

/// `χ` of a point: 1 inside, 0 outside, 1/2 exactly on the surface.
#[inline]
pub fn inside_indicator(rho: f64, z: f64, radius: f64, half_length: f64) -> f64 {
    let (dr, dz) = (rho - radius, z.abs() - half_length);
    if dr > 0.0 || dz > 0.0 {
        0.0
    } else if dr < 0.0 && dz < 0.0 {
        1.0
    } else {
        0.5
    }
}

/// `Hess(Ψ)` parts at body-frame point `(x, y, z)` (closed form or near-axis expansion).
#[inline]
pub fn hess_parts<T: Real>(x: T, y: T, z: T, radius: f64, half_length: f64) -> HessParts<T> {
    let rho2 = x * x + y * y;
    let rho_v = rho2.val().sqrt();
    let chi = inside_indicator(rho_v, z.val(), radius, half_length);
    if rho_v < AXIS_SWITCH * radius {
        near_axis(rho2, z, radius, half_length, chi)
    } else {
        closed_form(rho2.sqrt(), z, radius, half_length, chi)
    }
}

/// The `cel` closed form (valid off the axis).
#[inline]
pub fn closed_form<T: Real>(rho: T, z: T, radius: f64, half_length: f64, chi: f64) -> HessParts<T> {
    let sp = rho + radius;
    let dm = rho - radius;
    let gamma = dm / sp;
    let xi = [z + half_length, z - half_length];
    let alpha = [
        (xi[0] * xi[0] + sp * sp).sqrt().recip(),
        (xi[1] * xi[1] + sp * sp).sqrt().recip(),
    ];
    let kc = [
        (xi[0] * xi[0] + dm * dm).sqrt() * alpha[0],
        (xi[1] * xi[1] + dm * dm).sqrt() * alpha[1],
    ];
    let [[p1a, xa, p2a, ya], [p1b, xb, p2b, yb]] = cel_cylinder_pair(kc, gamma);
    let (beta_a, beta_b) = (xi[0] * alpha[0], xi[1] * alpha[1]);
    let g2 = gamma * gamma;
    let psi_rz = alpha[0] * p1a - alpha[1] * p1b;
    let bz = beta_a * p2a - beta_b * p2b;
    let p3 = beta_a * (xa - g2 * ya) - beta_b * (xb - g2 * yb);
    let psi_rz = psi_rz * (radius / PI);
    let pzz = bz * radius / (sp * PI) - chi;
    let b = -(p3 * radius / (rho * PI));
    let a = -(pzz + b) - chi;
    let rho2 = rho * rho;
    HessParts {
        pzz,
        u: psi_rz / rho,
        b,
        e: (a - b) / rho2,
        chi,
    }
}

/// Terms of the near-axis expansion: `Ψ` through `ρ^(2 AXIS_TERMS + 2)`.
const AXIS_TERMS: usize = 6;
/// Jet length: `g` and its derivatives through order `2 AXIS_TERMS`.
const JET: usize = 2 * AXIS_TERMS + 1;

/// Taylor coefficients `g_j` (`g⁽ʲ⁾ = j! g_j`, j < [`JET`]) of `g(ξ) = ξ/√(ξ² + R²)`.
fn g_jet<T: Real>(xi: T, radius: f64) -> [T; JET] {
    // w = (ξ + t)² + R² = w0 + w1 t + t²; h = w^(-1/2): n w0 h_n = Σ_k (α k - n + k) w_k h_(n-k)
    let w0 = xi * xi + radius * radius;
    let w1 = xi * 2.0;
    let mut h = [T::cst(0.0); JET];
    h[0] = w0.sqrt().recip();
    let alpha = -0.5;
    for n in 1..JET {
        let nf = n as f64;
        // k = 1: (α - (n - 1)) w1 h_(n-1); k = 2: (2α - (n - 2)) w2 h_(n-2), w2 = 1
        let mut acc = w1 * h[n - 1] * (alpha - (nf - 1.0));
        if n >= 2 {
            acc = acc + h[n - 2] * (2.0 * alpha - (nf - 2.0));
        }
        h[n] = acc / (w0 * nf);
    }
    // g = (ξ + t) h
    let mut g = [T::cst(0.0); JET];
    g[0] = xi * h[0];
    for n in 1..JET {
        g[n] = xi * h[n] + h[n - 1];
    }
    g
}

/// The expansion about the axis (see the module docs): with `c_n = (-1)ⁿ ψ₀⁽²ⁿ⁾/(4ⁿ n!²)`,
/// `Ψ_zz = Σ c_n'' ρ²ⁿ`, `u = Σ 2n c_n' ρ²ⁿ⁻²`, `b = Σ 2n c_n ρ²ⁿ⁻² - χ/2`,
/// `e = Σ 4n(n-1) c_n ρ²ⁿ⁻⁴`, each through [`AXIS_TERMS`] terms.
pub fn near_axis<T: Real>(rho2: T, z: T, radius: f64, half_length: f64, chi: f64) -> HessParts<T> {
    let (xp, xm) = (z + half_length, z - half_length);
    let gp = g_jet(xp, radius);
    let gm = g_jet(xm, radius);
    // psi[j] = ψ0^(j) for j = 2..=2K+2: (g^(j-2)(ξ+) - g^(j-2)(ξ-)) / 2, g^(i) = i! g_i
    let mut psi = [T::cst(0.0); JET + 2];
    let mut fact = 1.0;
    for i in 0..JET {
        if i > 0 {
            fact *= i as f64;
        }
        psi[i + 2] = (gp[i] - gm[i]) * (fact * 0.5);
    }
    // the leading term without cancellation beyond the ends (ξ₊ ξ₋ > 0):
    // g(a) - g(b) = R² (a - b)(a + b) / ((a s_b + b s_a) s_a s_b), s = √(ξ² + R²)
    if (xp * xm).val() > 0.0 {
        let (sp, sm) = (
            (xp * xp + radius * radius).sqrt(),
            (xm * xm + radius * radius).sqrt(),
        );
        psi[2] = (xp + xm) * (radius * radius * half_length) / ((xp * sm + xm * sp) * sp * sm);
    }
    psi[2] = psi[2] - chi;
    // c_n / ψ0^(2n) = (-1)^n / (4^n n!²)
    let mut coef = [0.0; AXIS_TERMS + 2];
    coef[0] = 1.0;
    for n in 1..AXIS_TERMS + 2 {
        coef[n] = -coef[n - 1] / (4.0 * (n * n) as f64);
    }
    let zero = T::cst(0.0);
    let (mut pzz, mut u, mut b, mut e) = (zero, zero, zero, zero);
    // Horner in ρ² from the highest term down
    for n in (0..=AXIS_TERMS).rev() {
        let nf = n as f64;
        pzz = pzz * rho2 + psi[2 * n + 2] * coef[n];
        if n >= 1 {
            u = u * rho2 + psi[2 * n + 1] * (coef[n] * 2.0 * nf);
            b = b * rho2 + psi[2 * n] * (coef[n] * 2.0 * nf);
        }
        // e's term n + 1 (ρ^(2n-2)) for n + 1 >= 2
        let m = n + 1;
        if m >= 2 {
            let mf = m as f64;
            e = e * rho2 + psi[2 * m] * (coef[m] * 4.0 * mf * (mf - 1.0));
        }
    }
    HessParts {
        pzz,
        u,
        b: b - chi * 0.5,
        e,
        chi,
    }
}

#[cfg(test)]
#[path = "cylinder_tests.rs"]
mod tests;
