//! Closest points of two line segments (the axes of two spherocylinders).
//!
//! Segment i: x_i + s u_i, s in [-h_i, h_i]; segment j: x_j + t u_j, t in [-h_j, h_j], with
//! unit axes u. The squared distance |r + t u_j - s u_i|^2 (r = x_j - x_i) is a convex
//! quadratic in (s, t): its minimum is the interior stationary point when that lies in the
//! rectangle [-h_i, h_i] x [-h_j, h_j], and otherwise on one of the four edges, where a
//! clamped projection is exact. This is exact to round-off for every pair, including nearly
//! parallel ones, where the "clamp, project, clamp" shortcut (D-000-21) and a mid-point rule are off
//! by up to angle x length. Exactly parallel segments with overlapping projections (a line
//! contact) take the middle of the overlap, so the contact point is symmetric.

use glam::DVec3;

/// Result of [`segment_closest`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentClosest {
    /// Vector from i's closest axis point to j's closest axis point [m].
    pub k: DVec3,
    /// Position of i's closest point along u_i from x_i (l_ij of the thesis) [m].
    pub s: f64,
    /// Position of j's closest point along u_j from x_j [m].
    pub t: f64,
}

/// Closest points of segments i and j; `r` = x_j - x_i (already the periodic image wanted).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::geometry::segment_closest;
/// // two crossed unit segments one apart along y
/// let c = segment_closest(DVec3::X, 1.0, DVec3::new(0.0, 1.0, 0.0), DVec3::Z, 1.0);
/// assert!((c.k.length() - 1.0).abs() < 1e-15 && c.s == 0.0 && c.t == 0.0);
/// ```
#[inline]
pub fn segment_closest(u_i: DVec3, h_i: f64, r: DVec3, u_j: DVec3, h_j: f64) -> SegmentClosest {
    let a = u_i.dot(r);
    let b = u_j.dot(r);
    let c = u_i.dot(u_j);
    let den = 1.0 - c * c;
    let at = |s: f64, t: f64| SegmentClosest {
        k: r + t * u_j - s * u_i,
        s,
        t,
    };
    if den > 1e-12 {
        // interior stationary point of |r + t u_j - s u_i|^2
        let s0 = (a - b * c) / den;
        let t0 = (a * c - b) / den;
        if s0.abs() <= h_i && t0.abs() <= h_j {
            return at(s0, t0);
        }
    }
    // Otherwise the minimum lies on the boundary of [-h_i, h_i] x [-h_j, h_j]: the best of the
    // four edges, each minimised exactly (a clamped projection of a convex 1-D quadratic).
    let mut best = at(h_i, (h_i * c - b).clamp(-h_j, h_j));
    let mut best_d2 = best.k.length_squared();
    for cand in [
        at(-h_i, (-h_i * c - b).clamp(-h_j, h_j)),
        at((a + h_j * c).clamp(-h_i, h_i), h_j),
        at((a - h_j * c).clamp(-h_i, h_i), -h_j),
    ] {
        let d2 = cand.k.length_squared();
        if d2 < best_d2 {
            best = cand;
            best_d2 = d2;
        }
    }
    if den <= 1e-12 {
        // (anti)parallel: a line contact; prefer the middle of the overlap of the projections
        // when it is as close (to round-off), so the contact point is symmetric
        let lo = (-h_i).max(a - h_j);
        let hi = h_i.min(a + h_j);
        if lo <= hi {
            let sm = 0.5 * (lo + hi);
            let mid = at(sm, (sm * c - b).clamp(-h_j, h_j));
            if mid.k.length_squared() <= best_d2 * (1.0 + 1e-14) + 1e-300 {
                return mid;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn unit(rng: &mut impl Rng) -> DVec3 {
        loop {
            let v = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let n = v.length();
            if n > 1e-3 && n < 1.0 {
                return v / n;
            }
        }
    }

    /// Brute force: dense sampling of s, then the exact best t for each s (1-D convex
    /// problem: clamp of the projection), refined by golden-section search in s.
    fn brute(u_i: DVec3, h_i: f64, r: DVec3, u_j: DVec3, h_j: f64) -> f64 {
        let d = |s: f64| {
            let p = s * u_i - r; // point of i relative to x_j
            let t = p.dot(u_j).clamp(-h_j, h_j);
            (p - t * u_j).length()
        };
        let n = 2000;
        let mut best = (f64::INFINITY, 0.0);
        for k in 0..=n {
            let s = -h_i + 2.0 * h_i * k as f64 / n as f64;
            let v = d(s);
            if v < best.0 {
                best = (v, s);
            }
        }
        // golden section around the best sample (d is convex in s)
        let step = 2.0 * h_i / n as f64;
        let (mut lo, mut hi) = ((best.1 - step).max(-h_i), (best.1 + step).min(h_i));
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..200 {
            let m1 = hi - g * (hi - lo);
            let m2 = lo + g * (hi - lo);
            if d(m1) < d(m2) { hi = m2 } else { lo = m1 }
        }
        d(0.5 * (lo + hi)).min(best.0)
    }

    #[test]
    fn segment_distance_matches_brute_force_on_random_and_parallel_pairs() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let mut worst: f64 = 0.0;
        for case in 0..10_000 {
            let u_i = unit(&mut rng);
            let mut u_j = unit(&mut rng);
            match case % 5 {
                0 => u_j = u_i,                                       // parallel
                1 => u_j = -u_i,                                      // anti-parallel
                2 => u_j = (u_i + 1e-9 * unit(&mut rng)).normalize(), // nearly parallel
                _ => {}
            }
            let h_i = rng.random_range(0.0..3.0);
            let h_j = rng.random_range(0.0..3.0);
            let mut r = DVec3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
            );
            if case % 10 == 0 {
                r = u_i * rng.random_range(-4.0..4.0); // coincident axes
                u_j = if case % 20 == 0 { u_i } else { -u_i };
            }
            let c = segment_closest(u_i, h_i, r, u_j, h_j);
            // the returned points lie on the segments and realise the returned distance
            assert!(c.s.abs() <= h_i + 1e-15 && c.t.abs() <= h_j + 1e-15);
            let direct = (r + c.t * u_j - c.s * u_i).length();
            assert!((direct - c.k.length()).abs() < 1e-12);
            let b = brute(u_i, h_i, r, u_j, h_j);
            let err = c.k.length() - b;
            worst = worst.max(err.abs());
            assert!(
                err.abs() < 1e-9,
                "case {case}: {} vs brute {b}",
                c.k.length()
            );
        }
        assert!(worst < 1e-9);
    }

    #[test]
    fn segment_distance_agrees_with_parry_capsules() {
        use parry3d_f64::math::{Pose, Vector};
        use parry3d_f64::query;
        use parry3d_f64::shape::Capsule;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        for _ in 0..1000 {
            let (u_i, u_j) = (unit(&mut rng), unit(&mut rng));
            let (h_i, h_j) = (rng.random_range(0.1..2.0), rng.random_range(0.1..2.0));
            let r = DVec3::new(
                rng.random_range(-4.0..4.0),
                rng.random_range(-4.0..4.0),
                rng.random_range(-4.0..4.0),
            );
            let ours = segment_closest(u_i, h_i, r, u_j, h_j).k.length();
            let rad = 0.1;
            let ci = Capsule::new(Vector::from(-h_i * u_i), Vector::from(h_i * u_i), rad);
            let cj = Capsule::new(
                Vector::from(r - h_j * u_j),
                Vector::from(r + h_j * u_j),
                rad,
            );
            let d = query::distance(&Pose::IDENTITY, &ci, &Pose::IDENTITY, &cj)
                .unwrap()
                .distance;
            let theirs = d + 2.0 * rad;
            if d > 1e-6 {
                assert!((ours - theirs).abs() < 1e-6, "{ours} vs parry {theirs}");
            }
        }
    }
}
