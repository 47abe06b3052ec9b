//! Timing hook for the cost of one spheroid–spheroid contact query (for `magsep bench`).
//!
//! The pairs are deterministic: random orientations and directions from a seeded
//! xoshiro256++ generator, two equal spheroids of aspect ratio `w` (equatorial semi-axis 1 mm)
//! placed along the direction `d̂` so that the separating-axis function along `d̂` is
//! `0.01 a` (the pair is apart by at least that, a near-contact configuration as in a dense
//! bed). Each pair is queried cold (no warm start) and then warm (after a move of `10⁻³ a`,
//! starting from the first normal), as in the time-of-impact loop.

use std::time::Instant;

use glam::{DQuat, DVec3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::{PosedSpheroid, Spheroid, spheroid_contact};

/// Result of [`time_contact_queries`].
///
/// ```
/// use magsep_systems::collision::spheroid::time_contact_queries;
/// let t = time_contact_queries(200, 0.1, 1);
/// assert_eq!(t.queries, 200);
/// assert!(t.cold_seconds_per_query > 0.0 && t.not_converged == 0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactQueryTiming {
    /// Pairs queried (each once cold and once warm).
    pub queries: usize,
    /// Mean wall time of a query without a warm start \[s\].
    pub cold_seconds_per_query: f64,
    /// Mean wall time of a warm-started query \[s\].
    pub warm_seconds_per_query: f64,
    /// Mean Newton iterations of a cold query.
    pub cold_iterations: f64,
    /// Queries (cold or warm) that did not converge or failed.
    pub not_converged: usize,
}

/// Times `n` spheroid–spheroid contact queries ([`super::spheroid_contact`]) for equal spheroids
/// of aspect ratio `aspect_ratio = c/a` (clamped to [1e-3, 1e3]; 1 is a sphere) from the seed
/// `seed`. See the module header for the configurations.
pub fn time_contact_queries(n: usize, aspect_ratio: f64, seed: u64) -> ContactQueryTiming {
    let w = if aspect_ratio.is_finite() {
        aspect_ratio.clamp(1e-3, 1e3)
    } else {
        1.0
    };
    let a = 1e-3;
    let shape = Spheroid::new(a, w * a);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let unit = |rng: &mut Xoshiro256PlusPlus| loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    };
    let pairs: Vec<(PosedSpheroid, PosedSpheroid, DVec3)> = (0..n)
        .map(|_| {
            let qa = DQuat::from_axis_angle(unit(&mut rng), rng.random_range(0.0..6.3));
            let qb = DQuat::from_axis_angle(unit(&mut rng), rng.random_range(0.0..6.3));
            let dir = unit(&mut rng);
            let pa = PosedSpheroid::new(shape, DVec3::ZERO, qa);
            let mut pb = PosedSpheroid::new(shape, DVec3::ZERO, qb);
            pb.centre = dir * (pa.support_value(dir) + pb.support_value(dir) + 0.01 * a);
            (pa, pb, unit(&mut rng) * (1e-3 * a))
        })
        .collect();
    let mut not_converged = 0;
    let mut iterations = 0u64;
    let mut normals = Vec::with_capacity(n);
    let start = Instant::now();
    for (pa, pb, _) in &pairs {
        match spheroid_contact(pa, pb, None) {
            Some(c) => {
                not_converged += usize::from(!c.converged);
                iterations += u64::from(c.iterations);
                normals.push(Some(c.geometry.normal));
            }
            None => {
                not_converged += 1;
                normals.push(None);
            }
        }
    }
    let cold = start.elapsed().as_secs_f64();
    let start = Instant::now();
    for ((pa, pb, shift), warm) in pairs.iter().zip(&normals) {
        let mut moved = *pb;
        moved.centre += *shift;
        match spheroid_contact(pa, &moved, *warm) {
            Some(c) => not_converged += usize::from(!c.converged),
            None => not_converged += 1,
        }
    }
    let warm = start.elapsed().as_secs_f64();
    let per = |t: f64| if n > 0 { t / n as f64 } else { 0.0 };
    ContactQueryTiming {
        queries: n,
        cold_seconds_per_query: per(cold),
        warm_seconds_per_query: per(warm),
        cold_iterations: if n > 0 {
            iterations as f64 / n as f64
        } else {
            0.0
        },
        not_converged,
    }
}
