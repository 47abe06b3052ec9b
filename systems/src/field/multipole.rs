//! Exterior multipole expansion of a uniformly magnetised cylinder (body frame: axis z).
//!
//! Outside the circumscribed sphere (`r > a = √(L² + R²)`) the Newtonian potential of the
//! cylinder is `Ψ = Σ_n q_n P_n(cos θ) / r^(n+1)` (even `n` only: the body is symmetric under
//! `z → -z`), with
//!
//! ```text
//! q_n = (V/4π) Σ_k (-1)^k n! / (4^k k!² (n-2k)!) · L^(n-2k)/(n-2k+1) · R^(2k)/(k+1),
//! ```
//!
//! the volume average of the solid harmonic `r^n P_n(cos θ)` (`⟨z^2j⟩ = L^2j/(2j+1)`,
//! `⟨ρ^2k⟩ = R^2k/(k+1)`). The field is `H = Hess(Ψ) · M`; `n = 0` alone is the point dipole
//! `m = M V` of the thesis's eqs. 5.31/5.35.
//!
//! **Error bound.** `|q_n| ≤ (V/4π) aⁿ` and `|Hess(Pₙ/r^(n+1)) · M̂| ≤ (n+1)(n+2) / r^(n+3)`,
//! while the dipole field is at least `|M| V/(4π r³)`, so truncating after order `N` has a
//! relative error at most [`truncation_bound`]`(N, a/r) = Σ_{n>N, even} (n+1)(n+2)(n+3) (a/r)ⁿ`
//! (the extra factor `n+3` covers the gradient as well). [`order_for`] picks the smallest order
//! within a tolerance. The tests check the bound against the closed form.

use super::real::Real;

/// Highest order used (even).
pub const MAX_ORDER: usize = 80;

/// Coefficients `q_n` (n = 0, 2, ..., [`MAX_ORDER`]) of a cylinder [m^(n+3)].
pub fn coefficients(radius: f64, half_length: f64) -> Vec<f64> {
    let v = 2.0 * std::f64::consts::PI * radius * radius * half_length;
    let mut out = Vec::with_capacity(MAX_ORDER / 2 + 1);
    let fact = |n: usize| (1..=n).fold(1.0f64, |a, i| a * i as f64);
    for n in (0..=MAX_ORDER).step_by(2) {
        let mut q = 0.0;
        for k in 0..=n / 2 {
            let c = fact(n) / (4f64.powi(k as i32) * fact(k).powi(2) * fact(n - 2 * k));
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            q += sign * c * half_length.powi((n - 2 * k) as i32) * radius.powi(2 * k as i32)
                / (((n - 2 * k + 1) * (k + 1)) as f64);
        }
        out.push(q * v / (4.0 * std::f64::consts::PI));
    }
    out
}

/// Relative truncation error bound of the expansion through order `order` at `x = a/r < 1`.
pub fn truncation_bound(order: usize, x: f64) -> f64 {
    if x >= 1.0 {
        return f64::INFINITY;
    }
    let mut sum = 0.0;
    let mut n = order + 2;
    let mut xn = x.powi(n as i32);
    loop {
        let nf = n as f64;
        let term = (nf + 1.0) * (nf + 2.0) * (nf + 3.0) * xn;
        sum += term;
        if term < 1e-18 * sum || xn == 0.0 {
            return sum;
        }
        n += 2;
        xn *= x * x;
        if n > 10_000 {
            return f64::INFINITY;
        }
    }
}

/// A closed-form majorant of [`truncation_bound`]: with `m = order + 2`,
/// `(m+2k+1)(m+2k+2)(m+2k+3) ≤ (m+1)(m+2)(m+3)(k+1)³ ≤ 6 (m+1)(m+2)(m+3) C(k+3, 3)`, so the
/// bound is at most `6 (m+1)(m+2)(m+3) xᵐ / (1 - x²)⁴`.
pub fn truncation_majorant(order: usize, x: f64) -> f64 {
    if x >= 1.0 {
        return f64::INFINITY;
    }
    let m = (order + 2) as f64;
    6.0 * (m + 1.0) * (m + 2.0) * (m + 3.0) * x.powf(m) / (1.0 - x * x).powi(4)
}

/// Smallest even order up to `max_order` whose [`truncation_majorant`] at `x = a/r` is within
/// `tol`, if any (an incremental loop: a few flops per order).
pub fn order_for(x: f64, tol: f64, max_order: usize) -> Option<usize> {
    if x.is_nan() || x >= 1.0 || tol.is_nan() || tol <= 0.0 {
        return None;
    }
    let y = x * x;
    let c = 6.0 / (1.0 - y).powi(4);
    let mut xm = y; // x^m, m = order + 2
    for order in (0..=max_order.min(MAX_ORDER)).step_by(2) {
        let m = (order + 2) as f64;
        if c * (m + 1.0) * (m + 2.0) * (m + 3.0) * xm <= tol {
            return Some(order);
        }
        xm *= y;
    }
    None
}

/// Highest order used for speed at a loose tolerance: up to here the expansion is cheaper than
/// the closed form; beyond it is only used where the closed form is the less accurate.
pub const FAST_ORDER: usize = 16;

/// `H = Hess(Ψ) · m` from the expansion through `order` (even) at a body-frame point outside
/// the circumscribed sphere. `q` from [`coefficients`].
pub fn field<T: Real>(q: &[f64], order: usize, p: [T; 3], m: [f64; 3]) -> [T; 3] {
    let [x, y, z] = p;
    let r = (x * x + y * y + z * z).sqrt();
    let ir = r.recip();
    let u = z * ir;
    let top = order + 3;
    // Legendre P, P', P'' at u up to degree order + 2
    let mut pl = [T::cst(0.0); MAX_ORDER + 4];
    let mut dp = pl;
    let mut ddp = pl;
    pl[0] = T::cst(1.0);
    pl[1] = u;
    dp[1] = T::cst(1.0);
    for k in 1..top - 1 {
        let kf = k as f64;
        pl[k + 1] = (u * pl[k] * (2.0 * kf + 1.0) - pl[k - 1] * kf) / (kf + 1.0);
        dp[k + 1] = dp[k - 1] + pl[k] * (2.0 * kf + 1.0);
        ddp[k + 1] = ddp[k - 1] + dp[k] * (2.0 * kf + 1.0);
    }
    let ir2 = ir * ir;
    // r^-(m+2) for m = 1: r^-3
    let mut irm2 = ir2 * ir;
    let zero = T::cst(0.0);
    let mut h = [zero; 3];
    for (i, &qn) in q.iter().enumerate().take(order / 2 + 1) {
        let m_deg = 2 * i + 1;
        let mf = m_deg as f64;
        let a = dp[m_deg] * irm2;
        let w = (u * ddp[m_deg] + dp[m_deg] * (mf + 2.0)) * irm2 * ir2;
        let az = -(u * dp[m_deg] * mf + pl[m_deg] * (mf * (mf + 1.0))) * irm2 * ir;
        let hzz = pl[m_deg + 1] * (mf * (mf + 1.0)) * irm2;
        let (hxx, hyy) = (x * x * w - a, y * y * w - a);
        let hxy = x * y * w;
        let (hxz, hyz) = (-(x * az), -(y * az));
        h[0] = h[0] + (hxx * m[0] + hxy * m[1] + hxz * m[2]) * qn;
        h[1] = h[1] + (hxy * m[0] + hyy * m[1] + hyz * m[2]) * qn;
        h[2] = h[2] + (hxz * m[0] + hyz * m[1] + hzz * m[2]) * qn;
        irm2 = irm2 * ir2;
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_match_hand_values() {
        let (r, l) = (0.7, 2.3);
        let v = 2.0 * std::f64::consts::PI * r * r * l;
        let q = coefficients(r, l);
        let s = v / (4.0 * std::f64::consts::PI);
        assert!((q[0] - s).abs() < 1e-15 * s);
        // q2 = s (<z²> - <ρ²>/2) = s (L²/3 - R²/4)
        assert!((q[1] - s * (l * l / 3.0 - r * r / 4.0)).abs() < 1e-14 * s * l * l);
        // q4 = s (8<z⁴> - 24<z²><ρ²> + 3<ρ⁴>)/8
        let q4 = s * (8.0 * l.powi(4) / 5.0 - 24.0 * l * l / 3.0 * r * r / 2.0 + r.powi(4)) / 8.0;
        assert!((q[2] - q4).abs() < 1e-13 * s * l.powi(4));
    }

    #[test]
    fn dipole_term_is_the_point_dipole_and_harmonic() {
        let q = coefficients(1.0, 3.0);
        let p = [4.0, -7.0, 9.0];
        let m = [0.3, -0.2, 0.9];
        let h = field(&q, 0, p, m);
        let r = (16.0f64 + 49.0 + 81.0).sqrt();
        let rh = [p[0] / r, p[1] / r, p[2] / r];
        let mr: f64 = (0..3).map(|i| m[i] * rh[i]).sum();
        for i in 0..3 {
            let want = q[0] * (3.0 * mr * rh[i] - m[i]) / r.powi(3);
            assert!((h[i] - want).abs() < 1e-15 * q[0] / r.powi(3));
        }
        // div H = 0 outside for every order (trace of the Hessian is zero)
        use crate::field::Dual3;
        let pd = Dual3::seed(glam::DVec3::from_array(p));
        for order in [0, 4, 12] {
            let hd = field(&q, order, pd, m);
            let div = hd[0].d.x + hd[1].d.y + hd[2].d.z;
            let scale = hd[0].d.abs().max_element();
            assert!(div.abs() < 1e-13 * scale, "order {order}: div {div}");
            let curl = hd[0].d.y - hd[1].d.x;
            assert!(curl.abs() < 1e-13 * scale);
        }
    }

    #[test]
    fn order_selection_is_monotone() {
        assert_eq!(order_for(1.2, 1e-3, MAX_ORDER), None);
        assert_eq!(order_for(1e-6, 1e-3, MAX_ORDER), Some(0));
        let mut last = 0;
        for x in [0.01, 0.05, 0.1, 0.2] {
            let n = order_for(x, 1e-12, MAX_ORDER).unwrap_or(MAX_ORDER + 2);
            assert!(n >= last);
            last = n;
        }
        assert!(truncation_bound(4, 0.1) < truncation_bound(2, 0.1));
        // the majorant bounds the series, and the chosen order is the smallest that meets tol
        for x in [0.01, 0.1, 0.3, 0.6, 0.9] {
            for n in [0, 2, 10, 40] {
                assert!(truncation_majorant(n, x) >= truncation_bound(n, x));
            }
            for tol in [1e-3, 1e-9, 1e-15] {
                if let Some(n) = order_for(x, tol, MAX_ORDER) {
                    assert!(truncation_majorant(n, x) <= tol, "{x} {tol} {n}");
                    assert!(
                        n == 0 || truncation_majorant(n - 2, x) > tol,
                        "{x} {tol} {n}"
                    );
                }
            }
        }
    }
}
