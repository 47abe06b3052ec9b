//! The sweeps of the resting-contact solve for isotropic inverse inertias
//! ([`InverseInertia::Scalar`](super::InverseInertia::Scalar): spheres), on a compact copy of
//! the bodies (velocity, angular velocity, inverse mass and inverse inertia of a particle in one
//! 64-byte record) and without the per-use dispatch on the inertia kind.
//!
//! The arithmetic is that of the general sweeps (`Sim::relax` in the `resting` submodule, kept
//! as the reference and used for tensor and principal inertias), operation for operation, so the
//! result is bitwise the same; a test checks it on a settling bed.

use glam::DVec3;

use super::resting::Contact;

pub(super) mod blocked;

/// Scratch buffers of the fast kernels (kept between steps).
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    /// Bodies of the fast resting sweeps.
    pub(super) bodies: Vec<Body>,
    /// Per resting contact, its convergence threshold [m/s].
    pub(super) scale: Vec<f64>,
    /// Evaluation counter of the projection's fast sweeps.
    pub(super) stamp: u64,
    /// Per particle, the stamp of its last projection move.
    pub(super) moved: Vec<u64>,
    /// Per candidate slot, the stamp of the last evaluation that found the pair apart.
    pub(super) pair_apart: Vec<u64>,
    /// Per particle and wall, the stamp of the last evaluation that found them apart.
    pub(super) wall_apart: Vec<u64>,
    /// Blocks and vectors of the NNCG solve.
    pub(super) blocked: blocked::Layout,
}

/// One particle in the fast sweeps.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
pub(super) struct Body {
    pub(super) v: DVec3,
    pub(super) w: DVec3,
    pub(super) inv_mass: f64,
    pub(super) inv_inertia: f64,
}

/// The fast sweeps over `contacts` (already warm-started and in sweep order). `bodies` holds the
/// particles, `scale[k]` is contact `k`'s `resting_tolerance · (r_i + r_j)/h` (walls: `2 r_i`);
/// `n` is the number of particles (a partner `j ≥ n` is a wall). Returns the sweeps done and the
/// residual, like the reference loop in `solve_resting`.
pub(super) fn sweeps(
    contacts: &mut [Contact],
    bodies: &mut [Body],
    scale: &[f64],
    n: usize,
    mu: f64,
    max_sweeps: usize,
) -> (usize, f64) {
    let mut sweeps = 0;
    let mut residual = 0.0;
    let m = contacts.len();
    while sweeps < max_sweeps {
        let backward = sweeps % 2 == 1;
        sweeps += 1;
        let (mut worst, mut worst_ratio) = (0.0f64, 0.0f64);
        for k in 0..m {
            let k = if backward { m - 1 - k } else { k };
            let c = &mut contacts[k];
            let dv = if (c.j as usize) < n {
                relax_pair(c, bodies, mu)
            } else {
                relax_wall(c, bodies, mu)
            };
            worst = worst.max(dv);
            worst_ratio = worst_ratio.max(dv / scale[k]);
        }
        residual = worst;
        if worst_ratio < 1.0 || worst_ratio.is_nan() {
            break;
        }
    }
    (sweeps, residual)
}

/// `Sim::relax` for a particle pair.
#[inline(always)]
fn relax_pair(c: &mut Contact, bodies: &mut [Body], mu: f64) -> f64 {
    let (i, j) = (c.i as usize, c.j as usize);
    let (mut a, mut b) = (bodies[i], bodies[j]);
    let nrm = c.normal;
    let velocity = |a: &Body, b: &Body| (b.v + b.w.cross(c.r_b)) - (a.v + a.w.cross(c.r_a));
    let push = |a: &mut Body, b: &mut Body, p: DVec3| {
        let dw = c.r_a.cross(p) * a.inv_inertia;
        a.v -= p * a.inv_mass;
        a.w -= dw;
        let dw = c.r_b.cross(p) * b.inv_inertia;
        b.v += p * b.inv_mass;
        b.w += dw;
    };
    let vn = velocity(&a, &b).dot(nrm);
    let target = (c.lambda_n - c.m_n * (vn + c.bias)).max(0.0);
    let dn = target - c.lambda_n;
    c.lambda_n = target;
    push(&mut a, &mut b, nrm * dn);
    let mut dv = (dn / c.m_n).abs();
    let v = velocity(&a, &b);
    let vt = v - nrm * v.dot(nrm);
    let slip = vt.length();
    if slip > 0.0 {
        let t = vt / slip;
        let ra = c.r_a.cross(t);
        let rb = c.r_b.cross(t);
        let mut kt = a.inv_mass + ra.dot(ra * a.inv_inertia);
        kt += b.inv_mass + rb.dot(rb * b.inv_inertia);
        if kt > 0.0 {
            let lt = (c.lambda_t - vt / kt).clamp_length_max(mu * c.lambda_n);
            let dp = lt - c.lambda_t;
            c.lambda_t = lt;
            push(&mut a, &mut b, dp);
            dv = dv.max(dp.length() * kt);
        }
    }
    bodies[i] = a;
    bodies[j] = b;
    dv
}

/// `Sim::relax` for a particle–wall contact (the wall is body *b*, immovable).
#[inline(always)]
fn relax_wall(c: &mut Contact, bodies: &mut [Body], mu: f64) -> f64 {
    let i = c.i as usize;
    let mut a = bodies[i];
    let nrm = c.normal;
    let velocity = |a: &Body| DVec3::ZERO - (a.v + a.w.cross(c.r_a));
    let push = |a: &mut Body, p: DVec3| {
        let dw = c.r_a.cross(p) * a.inv_inertia;
        a.v -= p * a.inv_mass;
        a.w -= dw;
    };
    let vn = velocity(&a).dot(nrm);
    let target = (c.lambda_n - c.m_n * (vn + c.bias)).max(0.0);
    let dn = target - c.lambda_n;
    c.lambda_n = target;
    push(&mut a, nrm * dn);
    let mut dv = (dn / c.m_n).abs();
    let v = velocity(&a);
    let vt = v - nrm * v.dot(nrm);
    let slip = vt.length();
    if slip > 0.0 {
        let t = vt / slip;
        let ra = c.r_a.cross(t);
        let kt = a.inv_mass + ra.dot(ra * a.inv_inertia);
        if kt > 0.0 {
            let lt = (c.lambda_t - vt / kt).clamp_length_max(mu * c.lambda_n);
            let dp = lt - c.lambda_t;
            c.lambda_t = lt;
            push(&mut a, dp);
            dv = dv.max(dp.length() * kt);
        }
    }
    bodies[i] = a;
    dv
}
