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
//!
//! Chord closing (not in the thesis; a cost saving). From a warm start after a small move the
//! solve takes one full step and then, at the next point, needs only that last small step.
//! That step is first computed with the previous iteration's LU factors (a chord step: the
//! residual is evaluated, the Jacobian is not rebuilt or factored). It ends the solve when it
//! passes the quadratic test above and its own error, about 2 K prev step with the convergence
//! constant K ~ step / prev^2, i.e. ~2 step^2 / prev, is below tol L; otherwise the full
//! iteration follows as before. The answer agrees with full steps within the tolerance
//! (tested); a packing's warm-started solves after moves of ~1e-5 D close this way.

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

impl System {
    /// All zeros (to be filled by [`system`]).
    pub(crate) fn zero() -> Self {
        Self {
            phi: [0.0; 6],
            jac: [[0.0; 6]; 6],
        }
    }
}

#[inline]
fn put(row: &mut [f64; 6], left: DVec3, right: DVec3) {
    row[..3].copy_from_slice(&left.to_array());
    row[3..].copy_from_slice(&right.to_array());
}

/// Phi (eq. 4.11) at (s_a, s_b), with u (a's normal in frame b) and k.
#[inline]
fn residual(
    pair: &PairFrame,
    s_a: DVec3,
    s_b: DVec3,
    ea: &Eval,
    eb: &Eval,
    fr: &Frame,
) -> ([f64; 6], DVec3, DVec3) {
    let u = pair.r * ea.grad;
    let k = s_b - (pair.r * s_a + pair.c);
    let phi = [
        u.dot(fr.t),
        u.dot(fr.b),
        k.dot(fr.t),
        k.dot(fr.b),
        ea.f,
        eb.f,
    ];
    (phi, u, k)
}

/// Phi and its Jacobian from the evaluations `ea`, `eb` and the frame of m = `eb.grad`, into
/// `sys`.
#[inline]
pub(crate) fn system(
    sys: &mut System,
    pair: &PairFrame,
    s_a: DVec3,
    s_b: DVec3,
    ea: &Eval,
    eb: &Eval,
    fr: &Frame,
) {
    let (phi, u, k) = residual(pair, s_a, s_b, ea, eb, fr);
    let rt_t = pair.r.transpose() * fr.t;
    let rt_b = pair.r.transpose() * fr.b;
    let jac = &mut sys.jac;
    put(&mut jac[0], rt_t * ea.hess, fr.dt(u) * eb.hess);
    put(&mut jac[1], rt_b * ea.hess, fr.db(u) * eb.hess);
    put(&mut jac[2], -rt_t, fr.t + fr.dt(k) * eb.hess);
    put(&mut jac[3], -rt_b, fr.b + fr.db(k) * eb.hess);
    put(&mut jac[4], ea.grad, DVec3::ZERO);
    put(&mut jac[5], DVec3::ZERO, eb.grad);
    sys.phi = phi;
}

/// Solves `m x = rhs` (LU, partial pivoting) by [`lu_factor`]; false for a zero or
/// non-finite pivot or a non-finite answer. The arithmetic is that of `solve6_reference`
/// operation for operation, so the answer is the same bit for bit (tested).
#[cfg(test)]
pub(crate) fn solve6(m: &mut [[f64; 6]; 6], rhs: &mut [f64; 6]) -> bool {
    lu_factor(m, rhs).is_some() && rhs.iter().all(|v| v.is_finite())
}

/// LU factorisation with partial pivoting of `m` in place (LAPACK's layout), solving
/// `m x = rhs` on the way (`rhs` becomes x): step `c` exchanges rows c and p\[c\], the unit
/// lower factor's multipliers are stored below the diagonal, U above it and the reciprocals of
/// U's diagonal on it (the back substitutions multiply instead of dividing: six divisions in a
/// row were their latency). Returns the exchanges p, None for a zero or non-finite pivot (rhs
/// then undefined). The arithmetic is `solve6_reference`'s operation for operation, so the
/// answer is the same bit for bit (tested); [`lu_solve`] repeats it on another right-hand side.
///
/// Hand-written rather than a linear-algebra crate's: it is the hot kernel of every contact
/// solve. Every index is a constant (the loops unroll into straight-line code that keeps the
/// matrix in registers and on fixed stack slots), and the pivot search and the row exchange
/// are selects, not branches on the pivot row or a `swap` at a computed index (in a
/// microbenchmark of random 6 x 6 systems, factor and solve took ~200 ns that way and
/// ~130 ns this way; in the packing, whose pivot rows vary less, the gain is smaller).
#[inline]
pub(crate) fn lu_factor(m: &mut [[f64; 6]; 6], rhs: &mut [f64; 6]) -> Option<[u8; 6]> {
    let mut p = [0u8; 6];
    macro_rules! step {
        ($col:literal) => {{
            let mut piv = $col;
            let mut best = m[$col][$col].abs();
            for r in 0..6 {
                if r > $col {
                    let v = m[r][$col].abs();
                    let better = v > best;
                    best = if better { v } else { best };
                    piv = if better { r } else { piv };
                }
            }
            if !(best.is_finite() && best > 0.0) {
                return None;
            }
            for r in 0..6 {
                if r > $col {
                    let sw = piv == r;
                    for c in 0..6 {
                        let (a, b) = (m[$col][c], m[r][c]);
                        m[$col][c] = if sw { b } else { a };
                        m[r][c] = if sw { a } else { b };
                    }
                    let (a, b) = (rhs[$col], rhs[r]);
                    rhs[$col] = if sw { b } else { a };
                    rhs[r] = if sw { a } else { b };
                }
            }
            p[$col] = piv as u8;
            let pivot_row = m[$col];
            let inv = 1.0 / pivot_row[$col];
            m[$col][$col] = inv;
            for r in 0..6 {
                if r > $col {
                    let f = m[r][$col] * inv;
                    for c in 0..6 {
                        if c > $col {
                            m[r][c] -= f * pivot_row[c];
                        }
                    }
                    rhs[r] -= f * rhs[$col];
                    m[r][$col] = f;
                }
            }
        }};
    }
    step!(0);
    step!(1);
    step!(2);
    step!(3);
    step!(4);
    step!(5);
    back_substitute(m, rhs);
    Some(p)
}

/// Solve U x = y in place with the factors of [`lu_factor`] (U's reciprocal diagonal).
#[inline(always)]
fn back_substitute(m: &[[f64; 6]; 6], y: &mut [f64; 6]) {
    for col in (0..6).rev() {
        let mut acc = y[col];
        for c in 0..6 {
            if c > col {
                acc -= m[col][c] * y[c];
            }
        }
        y[col] = acc * m[col][col];
    }
}

/// Solve `m x = rhs` with the factors and exchanges of [`lu_factor`] (rhs becomes x), in its
/// arithmetic (the exchanges as selects at constant indices); false for a non-finite answer.
#[inline]
pub(crate) fn lu_solve(m: &[[f64; 6]; 6], p: &[u8; 6], rhs: &mut [f64; 6]) -> bool {
    let mut y = *rhs;
    for col in 0..6 {
        for r in 0..6 {
            if r > col {
                let sw = p[col] as usize == r;
                let (a, b) = (y[col], y[r]);
                y[col] = if sw { b } else { a };
                y[r] = if sw { a } else { b };
            }
        }
    }
    for col in 0..6 {
        for r in 0..6 {
            if r > col {
                y[r] -= m[r][col] * y[col];
            }
        }
    }
    back_substitute(m, &mut y);
    *rhs = y;
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
            let pivot_row = m[col];
            for (x, p) in m[r][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            rhs[r] -= f * rhs[col];
        }
    }
    for col in (0..6).rev() {
        let mut acc = rhs[col];
        for c in col + 1..6 {
            acc -= m[col][c] * rhs[c];
        }
        rhs[col] = acc * (1.0 / m[col][col]);
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
    /// Close with a chord step when it is accurate enough ([`chord_ends`]); false: full
    /// Newton steps only (tests).
    pub chord: bool,
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

/// Take the last (small) step (`da`, `db`) from (s_a, s_b) with the normals updated to first
/// order: error O(step^2), so the answer is accurate to about tol^2 rather than tol.
#[inline]
fn finish(out: &mut Newton, s_a: DVec3, s_b: DVec3, da: DVec3, db: DVec3, ea: &Eval, eb: &Eval) {
    out.s_a = s_a + da;
    out.s_b = s_b + db;
    out.grad_a = ea.grad + ea.hess * da;
    out.grad_b = eb.grad + eb.hess * db;
    out.converged = true;
}

/// Whether a chord step of length `step` (solved with the factors of the Jacobian one full
/// step of length `prev` back) may close the solve. It must pass the full step's quadratic
/// test, and its own error must be below tol L: a chord step differs from the Newton step
/// by about |J^-1 (J_now - J_then)| step ~ 2 K prev step, with the convergence constant
/// K ~ step / prev^2 measured by the same two steps, so by ~ 2 step^2 / prev.
#[inline]
fn chord_ends(step: f64, prev: f64, tol: f64, l: f64) -> bool {
    step <= 1e-6 * l
        && step <= 0.01 * prev
        && step * step * step <= tol * l * prev * prev
        && 2.0 * step * step <= tol * l * prev
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
    // the last full iteration's system, factored in place, with its permutation and row
    // scales (for a closing chord step)
    let mut sys = System::zero();
    let mut chord: Option<([u8; 6], [f64; 6])> = None;
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
        out.s_a = s_a;
        out.s_b = s_b;
        out.grad_a = ea.grad;
        out.grad_b = eb.grad;
        if let Some((perm, lu_scale)) = chord.as_ref().filter(|_| set.chord) {
            // a chord step (the last Jacobian's factors) that ends the solve
            let (phi, ..) = residual(pair, s_a, s_b, &ea, &eb, &fr);
            let mut rhs: [f64; 6] = std::array::from_fn(|r| -(phi[r] * lu_scale[r]));
            if lu_solve(&sys.jac, perm, &mut rhs) {
                let da = DVec3::new(rhs[0], rhs[1], rhs[2]);
                let db = DVec3::new(rhs[3], rhs[4], rhs[5]);
                let step = (da.length_squared() + db.length_squared()).sqrt();
                if chord_ends(step, prev_step, set.tol, l) {
                    finish(&mut out, s_a, s_b, da, db, &ea, &eb);
                    return out;
                }
            }
        }
        system(&mut sys, pair, s_a, s_b, &ea, &eb, &fr);
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
        let small_residual = res_ang <= set.tol && res_len <= set.tol * l;
        let mut rhs = sys.phi.map(|v| -v);
        let perm = lu_factor(&mut sys.jac, &mut rhs);
        if !(perm.is_some() && rhs.iter().all(|v| v.is_finite())) {
            // a singular system with a small residual is a (degenerate) solution
            out.converged = small_residual;
            return out;
        }
        chord = perm.map(|p| (p, scale));
        let da = DVec3::new(rhs[0], rhs[1], rhs[2]);
        let db = DVec3::new(rhs[3], rhs[4], rhs[5]);
        let (la, lb) = (da.length_squared(), db.length_squared());
        let step = (la + lb).sqrt();
        let quadratic = it > 0
            && step <= 1e-6 * l
            && step <= 0.01 * prev_step
            && step * step * step <= set.tol * l * prev_step * prev_step;
        if (small_residual || quadratic || step <= set.tol * l) && step <= 1e-6 * l {
            finish(&mut out, s_a, s_b, da, db, &ea, &eb);
            return out;
        }
        if small_residual {
            // degenerate root (zero curvature): the points are uncertain, the answer is not
            out.converged = true;
            return out;
        }
        if la <= rho_a * rho_a && lb <= rho_b * rho_b {
            // inside the trust region: the full step (alpha = 1 exactly), without the square
            // roots and divisions of the damping factor on the iteration's critical path
            s_a += da;
            s_b += db;
        } else {
            let alpha = 1.0f64
                .min(rho_a / da.length().max(1e-300))
                .min(rho_b / db.length().max(1e-300));
            if alpha < 1.0 {
                // a damped step: the chord's error estimate assumes the full step
                chord = None;
            }
            s_a += alpha * da;
            s_b += alpha * db;
        }
        if !(s_a.is_finite() && s_b.is_finite()) {
            break;
        }
        prev_step = step;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{lu_factor, lu_solve, solve6, solve6_reference};

    /// After a packing-sized move (1e-5 D) the warm-started solve closes with a chord step,
    /// and agrees with full Newton steps within the tolerance.
    #[test]
    fn chord_closing_agrees_with_full_newton_steps() {
        use super::super::tests::{quat, rng, unit};
        use super::super::{ContactOptions, Superquadric, contact};
        use super::{NewtonSettings, PairFrame, solve};
        use glam::{DMat3, DQuat, DVec3};
        use rand::RngExt;
        let mut r = rng(31);
        let (mut compared, mut differ) = (0, 0);
        for _ in 0..300 {
            let a = Superquadric::superball(0.5, 2.0 + 4.0 * r.random::<f64>());
            let b = Superquadric {
                semi_axes: DVec3::new(0.5, 0.4, 0.6),
                exponents: DVec3::splat(2.0 + 4.0 * r.random::<f64>()),
            };
            let (qa, qb) = (quat(&mut r), quat(&mut r));
            let u = unit(&mut r);
            let d = u
                * (a.support_value(qa.conjugate() * u) + b.support_value(qb.conjugate() * u))
                * 0.999;
            let o = ContactOptions::default();
            let Some(w) = contact(&a, DVec3::ZERO, qa, &b, d, qb, &o, None).warm else {
                continue;
            };
            let l = 0.4;
            let dq = DQuat::from_scaled_axis(unit(&mut r) * 1e-5);
            let (d2, qb2) = (d + unit(&mut r) * 1e-5, (dq * qb).normalize());
            let pair = PairFrame {
                r: DMat3::from_quat(qb2.conjugate() * qa),
                c: qb2.conjugate() * -d2,
            };
            let set = |chord| NewtonSettings {
                tol: 1e-12,
                max_iter: 50,
                scale: l,
                chord,
            };
            let (pa, pb) = (a.prepared(), b.prepared());
            let fast = solve(&pa, &pb, &pair, w.s_a, w.s_b, &set(true));
            let full = solve(&pa, &pb, &pair, w.s_a, w.s_b, &set(false));
            assert!(fast.converged && full.converged);
            assert_eq!((fast.iterations, full.iterations), (2, 2));
            // the overlap and the normals within the tolerance (lengths tol L, angles tol), as
            // the chord test promises (the points themselves are ill-determined along a
            // flat face, where Newton converges only linearly in them)
            let overlap = |nw: &super::Newton| {
                let u = (pair.r * nw.grad_a).normalize();
                -(nw.s_b - (pair.r * nw.s_a + pair.c)).dot(u)
            };
            let (of, ou) = (overlap(&fast), overlap(&full));
            assert!((of - ou).abs() < 1e-12 * l, "{of} {ou}: {fast:?} {full:?}");
            let n = |g: DVec3| g.normalize();
            assert!((n(fast.grad_a) - n(full.grad_a)).length() < 1e-12);
            assert!((n(fast.grad_b) - n(full.grad_b)).length() < 1e-12);
            compared += 1;
            differ += usize::from(fast.s_a != full.s_a || fast.s_b != full.s_b);
        }
        // the chord step ran (it rounds differently from the full step)
        assert!(compared > 100 && differ > 50, "{compared} {differ}");
    }

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
            let (mut m3, mut rhs3) = (m, rhs);
            let ok = solve6(&mut m, &mut rhs);
            let ok2 = solve6_reference(&mut m2, &mut rhs2);
            assert_eq!(ok, ok2, "case {case}");
            if ok {
                solved += 1;
                assert_eq!(rhs.map(f64::to_bits), rhs2.map(f64::to_bits), "case {case}");
                // the factors solve another right-hand side (a chord step) the same way
                let mut other = [0.0; 6];
                let p = lu_factor(&mut m3, &mut other).expect("factored above");
                assert!(lu_solve(&m3, &p, &mut rhs3), "case {case}");
                assert_eq!(
                    rhs3.map(f64::to_bits),
                    rhs2.map(f64::to_bits),
                    "case {case}"
                );
            }
        }
        assert!(solved > 15_000, "{solved}");
    }
}
