//! Common-normal Newton-Raphson (thesis 000, eqs. 4.7-4.14, 4.32-4.34), evaluated in body
//! frame b (dot products are rotation invariant, so Phi and its Jacobian are the thesis's).
//!
//! Unknowns q = (s_a, s_b), the surface points in the body frames. With R = R_b^T R_a,
//! c = R_b^T (x_a - x_b), u = R grad F_a(s_a) (normal of a in frame b), m = grad F_b(s_b),
//! (t, b) the Householder frame of m and k = s_b - (R s_a + c) (eq. 4.7 in frame b):
//!
//! Phi = [u.t, u.b, k.t, k.b, F_a(s_a), F_b(s_b)]                          (4.11)
//!
//! dPhi_1/ds_a = (R^T t) o H_a,   dPhi_1/ds_b = (u^T dt/dm) o H_b
//! dPhi_3/ds_a = -(R^T t),        dPhi_3/ds_b = t + (k^T dt/dm) o H_b
//! dPhi_5/ds_a = grad F_a,        dPhi_6/ds_b = grad F_b                   (4.13, 4.34)
//!
//! (same with b for rows 2 and 4; H = diagonal second derivatives, eq. 4.33; o = elementwise).
//! The step solves J dq = -Phi by LU with partial pivoting after scaling rows 1, 2, 5 by
//! 1/|grad F_a| and row 6 by 1/|grad F_b| (this leaves the Newton step unchanged and makes
//! rows 1-2 angles and rows 3-6 lengths). Robustness additions to the thesis: a trust region
//! (each point moves at most half its smallest semi-axis per step) and radial projection back
//! onto the surface when |F| > 1e-3.
//!
//! Convergence (thesis: |dq| < 1e-6). Accepted when the scaled residual is below `tol`
//! (angles) and `tol L` (lengths, L the smallest semi-axis of the pair), or when the step is
//! in the quadratic regime (|dq_n| <= 1e-6 L, |dq_n| <= |dq_(n-1)|/100 and
//! |dq_n|^3/|dq_(n-1)|^2 <= tol L) or below `tol L`. A final step of at most 1e-6 L is then
//! applied with the normals updated to first order (error O(|dq|^2)), so the answer is
//! accurate to about tol^2 without one more evaluation. Near a zero-curvature point (the
//! face centre of a superball with g > 2) the root is degenerate: the points converge only
//! linearly, but the residual, and with it the overlap, converges at once; such a solution is
//! accepted on the residual without its (large, uncertain) last step.

use glam::{DMat3, DVec3};

use super::householder::Frame;
use super::prepared::{Eval, Prepared};

/// Relative pose of body a seen from body b.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PairFrame {
    /// R = R_b^T R_a (a's body frame to b's).
    pub r: DMat3,
    /// a's centre in b's frame.
    pub c: DVec3,
}

/// Residual (unscaled, eq. 4.11) and Jacobian (eq. 4.13) at (s_a, s_b).
pub(crate) struct System {
    pub phi: [f64; 6],
    pub jac: [[f64; 6]; 6],
}

#[inline]
fn put(row: &mut [f64; 6], left: DVec3, right: DVec3) {
    row[..3].copy_from_slice(&left.to_array());
    row[3..].copy_from_slice(&right.to_array());
}

/// Phi and its Jacobian from the evaluations `ea`, `eb` and the frame of m = `eb.grad`.
#[inline]
pub(crate) fn system(
    pair: &PairFrame,
    s_a: DVec3,
    s_b: DVec3,
    ea: &Eval,
    eb: &Eval,
    fr: &Frame,
) -> System {
    let u = pair.r * ea.grad;
    let k = s_b - (pair.r * s_a + pair.c);
    let rt_t = pair.r.transpose() * fr.t;
    let rt_b = pair.r.transpose() * fr.b;
    let phi = [
        u.dot(fr.t),
        u.dot(fr.b),
        k.dot(fr.t),
        k.dot(fr.b),
        ea.f,
        eb.f,
    ];
    let mut jac = [[0.0; 6]; 6];
    put(&mut jac[0], rt_t * ea.hess, fr.dt(u) * eb.hess);
    put(&mut jac[1], rt_b * ea.hess, fr.db(u) * eb.hess);
    put(&mut jac[2], -rt_t, fr.t + fr.dt(k) * eb.hess);
    put(&mut jac[3], -rt_b, fr.b + fr.db(k) * eb.hess);
    put(&mut jac[4], ea.grad, DVec3::ZERO);
    put(&mut jac[5], DVec3::ZERO, eb.grad);
    System { phi, jac }
}

/// Solves `m x = rhs` in place (LU, partial pivoting); false for a zero or non-finite pivot.
/// The rows are pivoted through a permutation instead of being swapped in memory; the
/// arithmetic is that of `solve6_reference` (tests) operation for operation, so the answer is the
/// same bit for bit (tested).
#[inline]
pub(crate) fn solve6(m: &mut [[f64; 6]; 6], rhs: &mut [f64; 6]) -> bool {
    // p[r]: the row of `m` at (pivoted) position r
    let mut p = [0usize, 1, 2, 3, 4, 5];
    for col in 0..6 {
        let mut piv = col;
        let mut best = m[p[col]][col].abs();
        for (r, &pr) in p.iter().enumerate().skip(col + 1) {
            if m[pr][col].abs() > best {
                best = m[pr][col].abs();
                piv = r;
            }
        }
        if !(best.is_finite() && best > 0.0) {
            return false;
        }
        p.swap(col, piv);
        let pc = p[col];
        let pivot_row = m[pc];
        let inv = 1.0 / pivot_row[col];
        for &pr in &p[col + 1..] {
            let f = m[pr][col] * inv;
            if f != 0.0 {
                for (x, q) in m[pr][col..].iter_mut().zip(&pivot_row[col..]) {
                    *x -= f * q;
                }
                rhs[pr] -= f * rhs[pc];
            }
        }
    }
    let mut x = [0.0; 6];
    for col in (0..6).rev() {
        let row = &m[p[col]];
        let mut acc = rhs[p[col]];
        for c in col + 1..6 {
            acc -= row[c] * x[c];
        }
        x[col] = acc / row[col];
    }
    *rhs = x;
    rhs.iter().all(|v| v.is_finite())
}

/// The reference of [`solve6`]: LU with the pivot rows swapped in memory.
#[cfg(test)]
pub(crate) fn solve6_reference(m: &mut [[f64; 6]; 6], rhs: &mut [f64; 6]) -> bool {
    for col in 0..6 {
        let mut piv = col;
        let mut best = m[col][col].abs();
        for (r, row) in m.iter().enumerate().skip(col + 1) {
            if row[col].abs() > best {
                best = row[col].abs();
                piv = r;
            }
        }
        if !(best.is_finite() && best > 0.0) {
            return false;
        }
        m.swap(col, piv);
        rhs.swap(col, piv);
        let inv = 1.0 / m[col][col];
        for r in col + 1..6 {
            let f = m[r][col] * inv;
            if f != 0.0 {
                let pivot_row = m[col];
                for (x, p) in m[r][col..].iter_mut().zip(&pivot_row[col..]) {
                    *x -= f * p;
                }
                rhs[r] -= f * rhs[col];
            }
        }
    }
    for col in (0..6).rev() {
        let mut acc = rhs[col];
        for c in col + 1..6 {
            acc -= m[col][c] * rhs[c];
        }
        rhs[col] = acc / m[col][col];
    }
    rhs.iter().all(|v| v.is_finite())
}

/// Settings of one Newton solve.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NewtonSettings {
    /// Relative tolerance (angles; lengths in units of `scale`).
    pub tol: f64,
    pub max_iter: u32,
    /// Length scale L (smallest semi-axis of the pair).
    pub scale: f64,
}

/// Outcome of a Newton solve.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Newton {
    pub s_a: DVec3,
    pub s_b: DVec3,
    /// grad F_a at s_a (body a).
    pub grad_a: DVec3,
    /// grad F_b at s_b (body b).
    pub grad_b: DVec3,
    pub iterations: u32,
    pub converged: bool,
}

/// Evaluate at `s`, projecting radially onto the surface first if |F| > 1e-3.
#[inline]
fn eval_on(p: &Prepared, s: &mut DVec3) -> Eval {
    let e = p.eval(*s);
    if e.f.abs() > 1e-3 {
        let q = p.project_radial(*s, e.f + 1.0);
        if q != *s && q.is_finite() {
            *s = q;
            return p.eval(q);
        }
    }
    e
}

/// Newton-Raphson from (s_a, s_b).
pub(crate) fn solve(
    pa: &Prepared,
    pb: &Prepared,
    pair: &PairFrame,
    mut s_a: DVec3,
    mut s_b: DVec3,
    set: &NewtonSettings,
) -> Newton {
    let l = set.scale;
    let (rho_a, rho_b) = (0.5 * pa.a.min_element(), 0.5 * pb.a.min_element());
    let mut prev_step = f64::INFINITY;
    let mut out = Newton {
        s_a,
        s_b,
        grad_a: DVec3::ZERO,
        grad_b: DVec3::ZERO,
        iterations: 0,
        converged: false,
    };
    for it in 0..set.max_iter {
        out.iterations = it + 1;
        let ea = eval_on(pa, &mut s_a);
        let eb = eval_on(pb, &mut s_b);
        let Some(fr) = Frame::new(eb.grad) else {
            break;
        };
        let na = ea.grad.length();
        let nb = eb.grad.length();
        if na.is_nan() || na <= 0.0 {
            break;
        }
        let mut sys = system(pair, s_a, s_b, &ea, &eb, &fr);
        let scale = [1.0 / na, 1.0 / na, 1.0, 1.0, 1.0 / na, 1.0 / nb];
        let mut res_ang: f64 = 0.0;
        let mut res_len: f64 = 0.0;
        for (r, (phi, row)) in sys.phi.iter_mut().zip(sys.jac.iter_mut()).enumerate() {
            *phi *= scale[r];
            for x in row.iter_mut() {
                *x *= scale[r];
            }
            if r < 2 {
                res_ang = res_ang.max(phi.abs());
            } else {
                res_len = res_len.max(phi.abs());
            }
        }
        out.s_a = s_a;
        out.s_b = s_b;
        out.grad_a = ea.grad;
        out.grad_b = eb.grad;
        let small_residual = res_ang <= set.tol && res_len <= set.tol * l;
        let mut rhs = sys.phi.map(|v| -v);
        if !solve6(&mut sys.jac, &mut rhs) {
            // a singular system with a small residual is a (degenerate) solution
            out.converged = small_residual;
            return out;
        }
        let da = DVec3::new(rhs[0], rhs[1], rhs[2]);
        let db = DVec3::new(rhs[3], rhs[4], rhs[5]);
        let step = (da.length_squared() + db.length_squared()).sqrt();
        let quadratic = it > 0
            && step <= 1e-6 * l
            && step <= 0.01 * prev_step
            && step * step * step <= set.tol * l * prev_step * prev_step;
        if (small_residual || quadratic || step <= set.tol * l) && step <= 1e-6 * l {
            // take the last (small) step with the normals updated to first order: error
            // O(step^2), so the answer is accurate to about tol^2 rather than tol
            out.s_a = s_a + da;
            out.s_b = s_b + db;
            out.grad_a = ea.grad + ea.hess * da;
            out.grad_b = eb.grad + eb.hess * db;
            out.converged = true;
            return out;
        }
        if small_residual {
            // degenerate root (zero curvature): the points are uncertain, the answer is not
            out.converged = true;
            return out;
        }
        let alpha = 1.0f64
            .min(rho_a / da.length().max(1e-300))
            .min(rho_b / db.length().max(1e-300));
        s_a += alpha * da;
        s_b += alpha * db;
        if !(s_a.is_finite() && s_b.is_finite()) {
            break;
        }
        prev_step = step;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{solve6, solve6_reference};

    /// The permuted LU is the row-swapping reference bit for bit, on random and on
    /// structured (Newton-like: zero blocks, ties, singular) matrices.
    #[test]
    fn permuted_lu_equals_the_reference_bit_for_bit() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut solved = 0;
        for case in 0..20_000 {
            let mut m = [[0.0; 6]; 6];
            for row in m.iter_mut() {
                for x in row.iter_mut() {
                    *x = next();
                }
            }
            match case % 4 {
                // the F rows of the Newton system: one half zero
                1 => {
                    m[4][3..].fill(0.0);
                    m[5][..3].fill(0.0);
                }
                // ties between pivot candidates
                2 => m[3][0] = -m[1][0],
                // singular: two equal rows
                3 if case % 8 == 3 => m[2] = m[0],
                _ => {}
            }
            let mut rhs = [next(), next(), next(), next(), next(), next()];
            let (mut m2, mut rhs2) = (m, rhs);
            let ok = solve6(&mut m, &mut rhs);
            let ok2 = solve6_reference(&mut m2, &mut rhs2);
            assert_eq!(ok, ok2, "case {case}");
            if ok {
                solved += 1;
                assert_eq!(rhs.map(f64::to_bits), rhs2.map(f64::to_bits), "case {case}");
            }
        }
        assert!(solved > 15_000, "{solved}");
    }
}
