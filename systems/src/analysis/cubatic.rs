//! Per-axis nematic order S_{2,j} and cubatic order S_4 of particles with three body axes
//! (superballs; thesis 000, §4.5, eqs. 4.16, 4.17, after Batten et al. \[Batten2010\]).
//!
//! With u_ij = body axis j (x, y, z) of particle i in the lab frame:
//!
//! S_{2,j} = max_n (1/N) sum_i (3/2 (u_ij . n)^2 - 1/2)                        (4.16)
//!
//! is the largest eigenvalue of Q_j = (1/N) sum_i (3/2 u_ij u_ij^T - 1/2 I), i.e. the
//! nematic order of the j axes alone (1: all j axes parallel).
//!
//! S_4 = max_n 1/(14 N) sum_{i,j} (35 (u_ij . n)^4 - 30 (u_ij . n)^2 + 3)           (4.17)
//!
//! Because the body axes of a particle are orthonormal, sum_j (u_ij . n)^2 = 1 for unit n,
//! and (4.17) reduces to S_4(n) = 5/2 T(n) - 3/2 with the quartic form
//! T(n) = (1/N) sum_{i,j} (u_ij . n)^4 = M[n, n, n, n], M = (1/N) sum u (x) u (x) u (x) u.
//! A perfect cubic crystal gives T = 1 along a crystal axis (S_4 = 1); isotropic
//! orientations give E T = 3/5 for every n (S_4 = 0 in expectation; a finite sample's
//! maximum sits at a floor of about 0.04 for N = 750, D-000-16).
//!
//! Maximisation (reconstruction: the thesis takes "a large number of random trial vectors"):
//! M is accumulated once (O(N)); T is evaluated at 5000 deterministic trial directions on the
//! half sphere (a Fibonacci lattice, spacing about 0.035 rad; T(n) = T(-n)), and the 12 best
//! are refined by Riemannian Newton steps on the sphere (gradient 4 B n, Hessian 12 B with
//! B = M[., ., n, n]; tangent Hessian 12 P B P - 4 T P). Every step is accepted only if T
//! increases; otherwise the power step n <- grad T / |grad T| is taken, which never
//! decreases T because T is convex (T(n') >= T(n) + grad T(n).(n' - n) >= T(n) since n'
//! maximises grad T(n).m over the unit ball). The result is therefore never below the best
//! trial direction and converges quadratically at a nondegenerate maximum.

use glam::{DMat3, DQuat, DVec3};

use super::order::nematic_order;

/// Number of trial directions of [`cubatic_order`].
pub const CUBATIC_TRIALS: usize = 5000;

/// Body axes (x, y, z) of orientation `q` in the lab frame.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::analysis::cubatic::body_axes;
/// let a = body_axes(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2));
/// assert!((a[0] - DVec3::Y).length() < 1e-15 && (a[2] - DVec3::Z).length() < 1e-15);
/// ```
pub fn body_axes(q: DQuat) -> [DVec3; 3] {
    [q * DVec3::X, q * DVec3::Y, q * DVec3::Z]
}

/// S_{2,j} for the body axes j = x, y, z (eq. 4.16); zeros for no particles.
///
/// ```
/// use glam::DQuat;
/// use magsep_systems::analysis::cubatic::per_axis_nematic;
/// let s = per_axis_nematic(&[DQuat::from_rotation_x(0.3); 10]);
/// assert!(s.iter().all(|s| (s - 1.0).abs() < 1e-12));
/// ```
pub fn per_axis_nematic(orientations: &[DQuat]) -> [f64; 3] {
    std::array::from_fn(|j| {
        let axes: Vec<DVec3> = orientations.iter().map(|q| body_axes(*q)[j]).collect();
        nematic_order(&axes)
    })
}

/// Eq. 4.17 evaluated directly along the unit direction `n` (0 for no particles).
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::analysis::cubatic::cubatic_order_along;
/// let q = [DQuat::IDENTITY];
/// assert!((cubatic_order_along(&q, DVec3::X) - 1.0).abs() < 1e-15);
/// let diag = DVec3::new(1.0, 1.0, 0.0).normalize();
/// assert!((cubatic_order_along(&q, diag) + 0.25).abs() < 1e-15);
/// ```
pub fn cubatic_order_along(orientations: &[DQuat], n: DVec3) -> f64 {
    if orientations.is_empty() {
        return 0.0;
    }
    let sum: f64 = orientations
        .iter()
        .flat_map(|q| body_axes(*q))
        .map(|u| {
            let c2 = u.dot(n).powi(2);
            35.0 * c2 * c2 - 30.0 * c2 + 3.0
        })
        .sum();
    sum / (14.0 * orientations.len() as f64)
}

/// The cubatic order parameter and its director.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubaticOrder {
    /// S_4 (eq. 4.17): 1 for a perfect cubic crystal, about 0 for isotropic orientations.
    pub s4: f64,
    /// Unit direction n that maximises eq. 4.17 (sign arbitrary).
    pub director: DVec3,
}

/// Fourth moment tensor M_abcd = (1/N) sum u_a u_b u_c u_d over all body axes.
struct Moments([[[[f64; 3]; 3]; 3]; 3]);

impl Moments {
    fn new(orientations: &[DQuat]) -> Self {
        let mut m = [[[[0.0; 3]; 3]; 3]; 3];
        for u in orientations.iter().flat_map(|q| body_axes(*q)) {
            let u = u.to_array();
            for (a, ma) in m.iter_mut().enumerate() {
                for (b, mb) in ma.iter_mut().enumerate() {
                    let ab = u[a] * u[b];
                    for (c, mc) in mb.iter_mut().enumerate() {
                        let abc = ab * u[c];
                        for (d, md) in mc.iter_mut().enumerate() {
                            *md += abc * u[d];
                        }
                    }
                }
            }
        }
        let inv = 1.0 / orientations.len().max(1) as f64;
        for v in m.iter_mut().flatten().flatten().flatten() {
            *v *= inv;
        }
        Self(m)
    }

    /// B = M[., ., n, n] (so T = n.B n, grad T = 4 B n, Hessian 12 B).
    fn contract(&self, n: DVec3) -> DMat3 {
        let n = n.to_array();
        let mut b = [[0.0; 3]; 3];
        for (a, ba) in b.iter_mut().enumerate() {
            for (bb, v) in ba.iter_mut().enumerate() {
                let mut s = 0.0;
                for (c, nc) in n.iter().enumerate() {
                    for (d, nd) in n.iter().enumerate() {
                        s += self.0[a][bb][c][d] * nc * nd;
                    }
                }
                *v = s;
            }
        }
        DMat3::from_cols_array_2d(&b)
    }

    fn t(&self, n: DVec3) -> f64 {
        n.dot(self.contract(n) * n)
    }
}

/// Unit vectors of a Fibonacci lattice on the half sphere z > 0.
fn half_sphere_lattice(k: usize, m: usize) -> DVec3 {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let z = (k as f64 + 0.5) / m as f64;
    let r = (1.0 - z * z).sqrt();
    let phi = golden * k as f64;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Monotone Newton / power ascent of T on the unit sphere from `n`.
fn refine(m: &Moments, mut n: DVec3) -> (DVec3, f64) {
    let mut t = m.t(n);
    for _ in 0..50 {
        let b = m.contract(n);
        let g = 4.0 * (b * n);
        let grad = g - g.dot(n) * n;
        if grad.length() < 1e-15 {
            break;
        }
        // tangent basis and the 2x2 Riemannian Hessian 12 P B P - 4 T P
        let e1 = n.any_orthonormal_vector();
        let e2 = n.cross(e1);
        let h11 = 12.0 * e1.dot(b * e1) - 4.0 * t;
        let h22 = 12.0 * e2.dot(b * e2) - 4.0 * t;
        let h12 = 12.0 * e1.dot(b * e2);
        let (g1, g2) = (grad.dot(e1), grad.dot(e2));
        let det = h11 * h22 - h12 * h12;
        let mut next = None;
        if h11 < 0.0 && det > 0.0 {
            // negative definite: Newton step xi = -H^-1 g, capped
            let x1 = -(h22 * g1 - h12 * g2) / det;
            let x2 = -(h11 * g2 - h12 * g1) / det;
            let xi = x1 * e1 + x2 * e2;
            let xi = if xi.length() > 0.3 {
                xi * (0.3 / xi.length())
            } else {
                xi
            };
            let cand = (n + xi).normalize();
            let tc = m.t(cand);
            if tc >= t {
                next = Some((cand, tc));
            }
        }
        let (cand, tc) = next.unwrap_or_else(|| {
            let p = g.normalize();
            (p, m.t(p))
        });
        if tc < t {
            break; // round-off level: converged
        }
        let step = (cand - n).length();
        (n, t) = (cand, tc);
        if step < 1e-13 {
            break;
        }
    }
    (n, t)
}

/// Cubatic order S_4 (eq. 4.17) of `orientations`: [`cubatic_director`]`(..).s4`.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::analysis::cubatic::cubatic_order;
/// // a perfect cubic crystal: every particle in the same orientation up to 90-degree turns
/// let q0 = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
/// let turn = |i: usize| DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2 * i as f64);
/// let qs: Vec<DQuat> = (0..20).map(|i| q0 * turn(i)).collect();
/// assert!((cubatic_order(&qs) - 1.0).abs() < 1e-12);
/// ```
pub fn cubatic_order(orientations: &[DQuat]) -> f64 {
    cubatic_director(orientations).s4
}

/// Finite-size floor of S_4: its mean over `sets` samples of `n` isotropic orientations
/// (streams of `seed`). Isotropic orientations have S_4 = 0 in expectation, but the maximum over
/// directions is biased upwards by about `1/√n` (0.040 at n = 750, 0.13 at n = 60), so a
/// measured S_4 means order only above this floor.
///
/// ```
/// use magsep_systems::analysis::cubatic::isotropic_floor;
/// let (small, large) = (isotropic_floor(60, 8, 1), isotropic_floor(750, 8, 1));
/// assert!(small > 2.0 * large && large > 0.0);
/// ```
pub fn isotropic_floor(n: usize, sets: usize, seed: u64) -> f64 {
    if n == 0 || sets == 0 {
        return 0.0;
    }
    let total: f64 = (0..sets)
        .map(|k| {
            let mut rng = crate::rng::particle_stream(seed, k as u64);
            let qs: Vec<DQuat> = (0..n)
                .map(|_| crate::packing::insert::random_orientation(&mut rng))
                .collect();
            cubatic_order(&qs)
        })
        .sum();
    total / sets as f64
}

/// Cubatic order S_4 (eq. 4.17) maximised over [`CUBATIC_TRIALS`] trial directions and
/// refined on the sphere (module header), with its director. `s4` is 0 and the director z
/// for no particles.
///
/// ```
/// use glam::{DQuat, DVec3};
/// use magsep_systems::analysis::cubatic::cubatic_director;
/// let q0 = DQuat::from_rotation_y(0.4);
/// let c = cubatic_director(&[q0; 5]);
/// assert!((c.s4 - 1.0).abs() < 1e-12);
/// assert!([q0 * DVec3::X, DVec3::Y, q0 * DVec3::Z].iter().any(|a| a.dot(c.director).abs() > 1.0 - 1e-12));
/// ```
pub fn cubatic_director(orientations: &[DQuat]) -> CubaticOrder {
    if orientations.is_empty() {
        return CubaticOrder {
            s4: 0.0,
            director: DVec3::Z,
        };
    }
    let m = Moments::new(orientations);
    let mut trials: Vec<(f64, DVec3)> = (0..CUBATIC_TRIALS)
        .map(|k| {
            let n = half_sphere_lattice(k, CUBATIC_TRIALS);
            (m.t(n), n)
        })
        .collect();
    trials.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (mut best_n, mut best_t) = (trials[0].1, trials[0].0);
    for &(_, n) in trials.iter().take(12) {
        let (n, t) = refine(&m, n);
        if t > best_t {
            (best_n, best_t) = (n, t);
        }
    }
    CubaticOrder {
        s4: 2.5 * best_t - 1.5,
        director: best_n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::particle_stream;
    use rand::RngExt;
    use rand_xoshiro::Xoshiro256PlusPlus;
    use std::f64::consts::FRAC_PI_2;

    /// Uniform random rotation (Shoemake's subgroup algorithm).
    fn random_rotation(rng: &mut Xoshiro256PlusPlus) -> DQuat {
        let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let (t2, t3) = (std::f64::consts::TAU * u2, std::f64::consts::TAU * u3);
        DQuat::from_xyzw(a * t2.sin(), a * t2.cos(), b * t3.sin(), b * t3.cos())
    }

    #[test]
    fn reduced_form_matches_eq_4_17() {
        let mut rng = particle_stream(21, 0);
        let qs: Vec<DQuat> = (0..50).map(|_| random_rotation(&mut rng)).collect();
        let m = Moments::new(&qs);
        let mut max_err: f64 = 0.0;
        for k in 0..200 {
            let n = half_sphere_lattice(k, 200);
            max_err = max_err.max((2.5 * m.t(n) - 1.5 - cubatic_order_along(&qs, n)).abs());
        }
        assert!(max_err < 1e-13, "{max_err}");
    }

    #[test]
    fn perfect_cubic_crystals_give_one() {
        let mut rng = particle_stream(22, 0);
        let turns = [
            DQuat::IDENTITY,
            DQuat::from_rotation_x(FRAC_PI_2),
            DQuat::from_rotation_y(FRAC_PI_2),
            DQuat::from_rotation_z(FRAC_PI_2),
            DQuat::from_rotation_x(-FRAC_PI_2),
            DQuat::from_rotation_z(std::f64::consts::PI),
        ];
        let mut max_err: f64 = 0.0;
        for _ in 0..10 {
            let q0 = random_rotation(&mut rng);
            let qs: Vec<DQuat> = (0..300)
                .map(|_| {
                    let a = turns[(rng.random::<f64>() * 6.0) as usize];
                    let b = turns[(rng.random::<f64>() * 6.0) as usize];
                    q0 * a * b
                })
                .collect();
            let c = cubatic_director(&qs);
            max_err = max_err.max((c.s4 - 1.0).abs());
            // the director is a crystal axis
            let axes = body_axes(q0);
            assert!(axes.iter().any(|a| a.dot(c.director).abs() > 1.0 - 1e-10));
            // identical orientations: every body axis perfectly nematic as well
            let same = vec![q0; 50];
            let s2 = per_axis_nematic(&same);
            assert!(s2.iter().all(|s| (s - 1.0).abs() < 1e-12), "{s2:?}");
            max_err = max_err.max((cubatic_order(&same) - 1.0).abs());
        }
        eprintln!("cubic crystals: max |S4 - 1| = {max_err:.1e}");
        assert!(max_err < 1e-12);
    }

    #[test]
    fn isotropic_orientations_sit_at_the_finite_size_floor() {
        let mut rng = particle_stream(23, 0);
        let mut mean = 0.0;
        let mut max: f64 = 0.0;
        let sets = 10;
        for _ in 0..sets {
            let qs: Vec<DQuat> = (0..750).map(|_| random_rotation(&mut rng)).collect();
            let c = cubatic_director(&qs);
            // never below the best trial or any direct evaluation
            assert!(c.s4 >= cubatic_order_along(&qs, DVec3::Z) - 1e-12);
            assert!((c.s4 - cubatic_order_along(&qs, c.director)).abs() < 1e-12);
            mean += c.s4 / sets as f64;
            max = max.max(c.s4);
            let s2 = per_axis_nematic(&qs);
            assert!(s2.iter().all(|s| *s < 0.1), "{s2:?}");
        }
        eprintln!("isotropic N = 750: mean S4 = {mean:.4}, max {max:.4}");
        assert!((0.02..0.07).contains(&mean) && max < 0.1, "{mean} {max}");
    }

    #[test]
    fn refinement_reaches_the_maximum_of_a_uniaxial_family() {
        // z axes along a common director d, x axes spread evenly about it: S_2,z = 1,
        // S_2,x = S_2,y = 1/4 exactly, and S_4 = 1 along d
        let d = DVec3::new(0.3, -0.5, 0.8).normalize();
        let base = DQuat::from_rotation_arc(DVec3::Z, d);
        let n = 64;
        let qs: Vec<DQuat> = (0..n)
            .map(|k| base * DQuat::from_rotation_z(std::f64::consts::PI * k as f64 / n as f64))
            .collect();
        let s2 = per_axis_nematic(&qs);
        assert!((s2[0] - 0.25).abs() < 1e-12 && (s2[1] - 0.25).abs() < 1e-12);
        assert!((s2[2] - 1.0).abs() < 1e-12);
        let c = cubatic_director(&qs);
        assert!((c.s4 - 1.0).abs() < 1e-12 && c.director.dot(d).abs() > 1.0 - 1e-12);
    }
}
