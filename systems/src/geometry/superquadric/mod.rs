//! Superquadric geometry and contact detection (thesis 000, ch. 4 and App. 4.A-4.C; see
//! docs/references.md).
//!
//! Shape (eq. 4.3/4.4): F(x) = |x/a1|^g1 + |y/a2|^g2 + |z/a3|^g3 - 1, F < 0 inside, with
//! g_i >= 2 (strictly convex; superballs, supercuboids, ellipsoids at g = 2). Gradient
//! n = (g_i a_i^-g_i x_i |x_i|^(g_i-2))_i (eq. 4.6); the Hessian is diagonal (eq. 4.33).
//! Volume, inertia and bounding radius: see [`superquadric_volume`],
//! [`superquadric_inertia`], [`superquadric_bounding_radius`] (eqs. 4.21, 4.29-4.31,
//! 4.38-4.39).
//!
//! Contact ([T000 §4.4.1]): the common normal of two bodies a, b with surface points s_a, s_b
//! (body frames) solves Phi(q) = [n_a.t_b, n_a.b_b, k.t_b, k.b_b, F_a, F_b] = 0 (eq. 4.11),
//! k = (x_b + R_b s_b) - (x_a + R_a s_a) (eq. 4.7), by Newton-Raphson with the analytic
//! Jacobian (eqs. 4.13, 4.34). The overlap is delta = -k.n^_a (= +|k| when overlapping,
//! -|k| = -gap when separated): the minimum over unit u of h_a(u) + h_b(-u) - d.u (h the
//! support functions, d = x_b - x_a), i.e. the penetration depth / minus the distance.
//!
//! Decisions and deviations from the thesis:
//! - Starting points ([T000 §4.4.1-4.4.2]): instead of point-sampled surfaces and a k-d tree, GJK
//!   (separated) or EPA (penetrating) of parry3d-f64 on the analytic support maps gives a
//!   normal n; the seeds are the support points of a along n and of b along -n, which lie
//!   exactly on the surfaces with anti-parallel normals. The support-function value in that
//!   direction is an upper bound of the overlap and serves as the GJK/EPA-only answer.
//! - Householder frame (eqs. 4.14-4.15): reflected along the coordinate axis most aligned
//!   with the normal (with its sign) instead of always e_x, removing the singularity at
//!   n = -|n| e_x; the Jacobian of t and b is used in closed form with the prefactor
//!   2 n_y/|h|^2 multiplied in (no 0/0 at n_y = 0 or n_z = 0). Erratum E-000-10 (h_x/h_x = 1)
//!   is thereby moot.
//! - Erratum E-000-7: the bounding radius is a maximisation; eq. 4.38 is singular at g = 2, where
//!   max a_i is used; unequal exponents use a 1-D Lagrange dual that is an upper bound.
//! - Convergence (thesis: |dq| < 1e-6, 50 iterations): scaled residual <= 1e-12 (angles and
//!   lengths relative to the smallest semi-axis) or a quadratically converging step, within
//!   50 iterations, with a trust region and radial projection onto the surfaces; the last
//!   small step is applied with first-order normals, so results are accurate to ~1e-13 of
//!   the smallest semi-axis (see `newton.rs`). Acceptance ([T000 §4.4.1] and D-000-20):
//!   |k x n_a| small, n_a.n_b < 0, overlap within the inscribed/circumscribed sphere bounds,
//!   not above the seed's support-function bound and n_a.d >= 0 (true of the global solution
//!   for centrally symmetric bodies); this rejects far-side solutions.
//! - Failure mode of [T000 §4.4.1] (non-convergence): a non-converged or rejected Newton solve is retried once from the
//!   centre line and then reported as [`ContactStatus::Fallback`] carrying the GJK/EPA
//!   answer. It is never silently turned into "no contact" as in the thesis ([T000 §4.4.1]).
//! - Failure mode of [T000 §4.4.2] (bounding spheres too loose): the exact bounding sphere is only the
//!   cheap reject. Next (finite cutoff only) the separating-axis bound along the centre line,
//!   h_a(u) + h_b(-u) - |d| with u = d/|d| (two support evaluations), ends pairs whose gap
//!   is certainly beyond the cutoff before any warm start, GJK or Newton (the listed but
//!   clearly separated pairs of a packing). GJK decides between separated and penetrating. By default it stops as soon
//!   as the gap is known to exceed the Newton band (or `gap_cutoff`), or to be below it
//!   (Newton then computes the gap), so separated pairs are cheap. EPA runs only for
//!   penetrating pairs without a warm start. A separated result of Newton is certified
//!   globally: its gap |k| is the distance of two surface points (an upper bound of the
//!   distance) and equals the separating-axis bound -g(n) (a lower bound).
//! - Warm starts ([`WarmStart`], the two body-frame points of the last call for the pair)
//!   skip GJK/EPA and converge in 2-3 evaluations after an MCM-sized move.
//! - Sign convention: delta > 0 is overlap (the thesis's k.n_i <= 0, [T000 §4.4.1]); the reported
//!   normal is a's outward unit normal, pointing towards b.
//!
//! The shapes implement parry3d-f64's `SupportMap`, so the GJK/EPA routines accept them:
//!
//! ```
//! use glam::{DQuat, DVec3};
//! use magsep_systems::geometry::superquadric::Superquadric;
//! use parry3d_f64::math::Pose;
//! use parry3d_f64::query::details::contact_support_map_support_map;
//! let s = Superquadric::superball(1.0, 2.0);
//! let pos12 = Pose::from_parts(DVec3::new(1.5, 0.0, 0.0), DQuat::IDENTITY);
//! let c = contact_support_map_support_map(&pos12, &s, &s, 0.0).unwrap();
//! assert!((c.dist + 0.5).abs() < 1e-6);
//! ```

mod cached;
mod contact;
mod householder;
mod mass;
mod newton;
mod prepared;
mod seed;
mod shape;

#[cfg(test)]
pub(crate) mod tests;
#[cfg(test)]
mod tests_cached;
#[cfg(test)]
mod tests_contact;
#[cfg(test)]
mod tests_random;

pub use cached::{PreparedShape, contact_prepared, contact_prepared_within, overlap_upper_bound};
pub use contact::{
    ContactOptions, ContactResult, ContactStatus, GjkEpaContact, WarmStart, contact,
    gjk_epa_contact,
};
pub use mass::{ln_gamma, superquadric_bounding_radius, superquadric_inertia, superquadric_volume};
pub use shape::{MAX_EXPONENT, Superquadric};
