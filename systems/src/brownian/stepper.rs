//! Time stepping of the overdamped Langevin equation: the Ermak-McCammon update (thesis 000,
//! eq. 6.11) `x(t+h) = x + h μ F(x) + sqrt(2 k_B T) B ΔW`, `B Bᵀ = μ`, `ΔW ~ N(0, h I)`, as a
//! fixed explicit step or with step-doubling error control on a Brownian tree.
//!
//! **Why adaptive.** With the thesis's steps the explicit update is far beyond its stability
//! limit once particles touch: `D h U''/k_BT` at a Mie(30, 15) contact is 16-9600 at
//! `h = 5e-5 s`, and a dipole contact force moves a particle by up to 6 radii per step
//! (D-000-10 in docs/references.md). Explicit Euler needs that number below 2.
//!
//! **The adaptive scheme** (Gaines and Lyons, SIAM J. Appl. Math. 57, 1455 (1997): variable
//! steps on a Brownian tree). Each step `dt` starts with one Wiener increment `W` per particle.
//! An interval `(h, W)` is tried as one step and as two half steps whose increments come from
//! the Brownian bridge, `W_L = W/2 + (sqrt(h)/2) ξ`, `W_R = W − W_L` (ξ standard normal, drawn
//! from the particle's own stream). The two results differ by `(h/2) |v(x) − v(x_mid)|`
//! (the noise cancels exactly), the local error of the one-step result. The two-half-step result
//! is accepted when every particle's difference is below `tolerance · a_i` and no half step
//! moves a particle by more than `max_displacement · a_i` (no tunnelling through a neighbour or
//! a fibre); otherwise both halves are tried again recursively, to `max_depth`. Because the
//! bridge refines the *same* Brownian path, the result converges to the path's solution as
//! the tolerance shrinks and the statistics of the noise are exact at every depth. The bridge
//! draws come from each particle's own stream, so a fixed and an adaptive run of one seed share
//! the Wiener increments of the first step only (later increments follow the draws of the
//! refinements).
//!
//! The mobility's square root `B` is frozen over one `dt` (it is built once per step from the
//! start configuration); the drift `μ F(x)` is re-evaluated at every sub-step (with the
//! user's external force kernels at the sub-step's time, see [`Dynamics::at_time`]). With hydrodynamic
//! interactions this is first order in `dt`, like the thesis's scheme.
//!
//! Random numbers are drawn per particle in tree order, so the result does not depend on the
//! thread count.

use glam::DVec3;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;

use magsep_components::brownian::{BrownianStats, StepControl};

/// What the stepper needs from the physics.
pub trait Dynamics {
    /// Radii a_i \[m\] (the unit of the error and displacement tests).
    fn radii(&self) -> &[f64];
    /// Which particles move.
    fn mobile(&self) -> &[bool];
    /// Deterministic velocities `μ F(x)` [m/s] (zero for fixed particles), at the time set
    /// by the last [`Dynamics::at_time`].
    fn drift(&mut self, x: &[DVec3], v: &mut [DVec3]);
    /// The next [`Dynamics::drift`] is evaluated at fraction `t` ∈ [0, 1] of the step (for
    /// time-dependent forces). Default: ignored.
    fn at_time(&mut self, _t: f64) {}
    /// Brownian displacements `sqrt(2 k_B T) B w` \[m\] for Wiener increments `w` [s^½]
    /// (zero for fixed particles). Must be linear in `w`.
    fn noise(&mut self, w: &[DVec3], out: &mut [DVec3]);
    /// Project a trial configuration reached from `from` onto the constraints (hard cores).
    fn constrain(&mut self, _from: &[DVec3], _x: &mut [DVec3]) {}
    /// An accepted (sub-)step from `from` to `x` ending at fraction `t` of the step: capture
    /// and quarantine. May fix particles (change [`Dynamics::mobile`]).
    fn accept(&mut self, _from: &[DVec3], _x: &mut [DVec3], _t: f64) {}
    /// [`Dynamics::accept`] for a sub-step in which only the particles `moved` (ascending)
    /// changed position (`x[i] == from[i]` for the others, which were checked when they last
    /// moved). The default checks everyone.
    fn accept_moved(&mut self, from: &[DVec3], x: &mut [DVec3], _moved: &[usize], t: f64) {
        self.accept(from, x, t);
    }
}

/// Draw one standard-normal vector.
#[inline]
pub fn normal3(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    DVec3::new(
        StandardNormal.sample(rng),
        StandardNormal.sample(rng),
        StandardNormal.sample(rng),
    )
}

/// Wiener increments over `h` for the mobile particles (zero for the others).
/// Each particle draws from its own stream, so the increments do not depend on the thread
/// count (parallel from 512 particles).
pub fn wiener_increments(mobile: &[bool], h: f64, rngs: &mut [Xoshiro256PlusPlus]) -> Vec<DVec3> {
    let s = h.sqrt();
    let draw = |(&m, rng): (&bool, &mut Xoshiro256PlusPlus)| {
        if m { normal3(rng) * s } else { DVec3::ZERO }
    };
    if mobile.len() < 512 {
        mobile.iter().zip(rngs.iter_mut()).map(draw).collect()
    } else {
        mobile
            .par_iter()
            .zip(rngs.par_iter_mut())
            .with_min_len(256)
            .map(draw)
            .collect()
    }
}

/// Particles per task of the per-particle loops of the stepper and the dynamics (fixed: the
/// split never changes a result, every particle's update is its own).
pub const PARTICLE_CHUNK: usize = 512;

/// `x[i] += v[i] dt + b[i]` for every particle, in parallel from [`PARTICLE_CHUNK`] particles
/// (each update is the same expression whatever the split, so bitwise thread-count
/// independent).
pub fn euler_update(x: &mut [DVec3], v: &[DVec3], b: &[DVec3], dt: f64) {
    let update = |((xi, vi), bi): ((&mut DVec3, &DVec3), &DVec3)| *xi += *vi * dt + *bi;
    if x.len() < 2 * PARTICLE_CHUNK {
        x.iter_mut().zip(v).zip(b).for_each(update);
    } else {
        x.par_iter_mut()
            .zip(v.par_iter())
            .zip(b.par_iter())
            .with_min_len(PARTICLE_CHUNK)
            .for_each(update);
    }
}

/// Advance `x` by one step `dt` \[s\]. `v0` is the drift at `x` if the caller has it (the ECS
/// pipeline computes it from the accumulated forces).
pub fn advance<D: Dynamics>(
    dynamics: &mut D,
    x: &mut Vec<DVec3>,
    v0: Option<Vec<DVec3>>,
    dt: f64,
    control: &StepControl,
    rngs: &mut [Xoshiro256PlusPlus],
    stats: &mut BrownianStats,
) {
    let n = x.len();
    let mut v = v0.unwrap_or_else(|| {
        let mut v = vec![DVec3::ZERO; n];
        dynamics.at_time(0.0);
        dynamics.drift(x, &mut v);
        stats.force_evaluations += 1;
        v
    });
    let w = wiener_increments(dynamics.mobile(), dt, rngs);
    let mut b = vec![DVec3::ZERO; n];
    let Some((tolerance, max_displacement, max_depth)) = control.adaptive_parameters() else {
        dynamics.noise(&w, &mut b);
        let from = x.clone();
        euler_update(x, &v, &b, dt);
        dynamics.constrain(&from, x);
        dynamics.accept(&from, x, 1.0);
        stats.substeps += 1;
        stats.particle_substeps += dynamics.mobile().iter().filter(|&&m| m).count() as u64;
        return;
    };
    let mut bl = vec![DVec3::ZERO; n];
    let mut br = vec![DVec3::ZERO; n];
    let mut vm = vec![DVec3::ZERO; n];
    // intervals (length, increment, depth, end fraction), left-most on top
    let mut stack = vec![(dt, w, 0u32, 1.0f64)];
    while let Some((h, w, depth, t_end)) = stack.pop() {
        let s = 0.5 * h.sqrt();
        let mobile = dynamics.mobile().to_vec();
        let wl: Vec<DVec3> = w
            .iter()
            .zip(rngs.iter_mut())
            .zip(&mobile)
            .map(|((&wi, rng), &m)| {
                if m {
                    wi * 0.5 + normal3(rng) * s
                } else {
                    DVec3::ZERO
                }
            })
            .collect();
        let wr: Vec<DVec3> = w.iter().zip(&wl).map(|(a, l)| *a - *l).collect();
        dynamics.noise(&wl, &mut bl);
        dynamics.noise(&wr, &mut br);
        let mut xm: Vec<DVec3> = (0..n).map(|i| x[i] + v[i] * (0.5 * h) + bl[i]).collect();
        dynamics.constrain(x, &mut xm);
        dynamics.at_time(t_end - 0.5 * h / dt);
        dynamics.drift(&xm, &mut vm);
        stats.force_evaluations += 1;
        let mut x2: Vec<DVec3> = (0..n).map(|i| xm[i] + vm[i] * (0.5 * h) + br[i]).collect();
        dynamics.constrain(&xm, &mut x2);
        let mut xf: Vec<DVec3> = (0..n).map(|i| x[i] + v[i] * h + bl[i] + br[i]).collect();
        dynamics.constrain(x, &mut xf);
        let radii = dynamics.radii();
        let mut err = 0.0f64;
        let mut disp = 0.0f64;
        for i in 0..n {
            if !mobile[i] {
                continue;
            }
            let inv = 1.0 / radii[i];
            err = err.max((xf[i] - x2[i]).length() * inv);
            disp = disp
                .max((xm[i] - x[i]).length() * inv)
                .max((x2[i] - xm[i]).length() * inv);
        }
        let ok = err <= tolerance && disp <= max_displacement && err.is_finite();
        if ok || depth + 1 >= max_depth {
            if !ok {
                stats.depth_limit_hits += 1;
            }
            stats.max_depth_reached = stats.max_depth_reached.max(depth + 1);
            stats.substeps += 2;
            stats.particle_substeps += 2 * mobile.iter().filter(|&&m| m).count() as u64;
            // the two half steps are accepted one after the other (capture on each)
            let from = x.clone();
            let mut xm = xm;
            dynamics.accept(&from, &mut xm, t_end - 0.5 * h / dt);
            let fixed_now: Vec<bool> = dynamics.mobile().iter().map(|m| !m).collect();
            for i in 0..n {
                if fixed_now[i] && mobile[i] {
                    x2[i] = xm[i]; // captured at mid-step: stays there
                }
            }
            dynamics.accept(&xm, &mut x2, t_end);
            *x = x2;
            if !stack.is_empty() {
                dynamics.at_time(t_end);
                dynamics.drift(x, &mut v);
                stats.force_evaluations += 1;
            }
        } else {
            stats.rejections += 1;
            let half = 0.5 * h / dt;
            stack.push((0.5 * h, wr, depth + 1, t_end));
            stack.push((0.5 * h, wl, depth + 1, t_end - half));
        }
    }
}

pub mod multirate;

#[cfg(test)]
mod tests;
