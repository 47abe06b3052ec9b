//! The common part of overlapping fibres inside a start box \[m³\], so that the box's volume
//! outside the fibres counts it once ([`super::box_region::box_volume_outside_fibres`], by
//! inclusion–exclusion over the groups of fibres that all overlap one another).
//!
//! Method: the intersection of cylinders `c₀ … c_k` inside the box is V = ∫ A(t) dt along the
//! first cylinder's axis, where A(t) is the area of its cross-section disc at `t` that lies in
//! the box and in every other cylinder (within its radius of its axis and between its end
//! planes). Every one of those sets is convex in the section's plane (a disc, a convex
//! polygon, an ellipse or a strip, half-planes), so along each ray from the disc's centre at
//! angle θ the admissible radii form one interval [r₀, r₁], found in closed form (linear and
//! quadratic inequalities in r), and A(t) = ∫ (r₁² − r₀²)/2 dθ. That angular integrand has
//! kinks where the constraint bounding an end of the interval changes; they are found on a
//! grid of 64 angles and located by bisection, and the integral is split there. Both
//! integrals are adaptive 5-point Gauss–Legendre (tolerances 1e-11 of the disc's area inside,
//! 1e-9 of the first cylinder's volume outside; at most 2·10⁴ bisections each, and at most
//! 10⁵ groups per box: a bound on the cost whatever the input). Checked against Steinmetz's
//! two- and three-cylinder solids (16r³/3 and 8(2 − √2)r³) and against a midpoint grid for a
//! clipped, oblique pair (tests).
//!
//! Hand-written: no crate gives the volume of a boolean of finite cylinders and a box to a
//! known accuracy; a mesh boolean would be a polygonal approximation.

use glam::DVec3;

use super::box_region::Cylinder;

/// Most bisections of one integral (outer along the axis, and each inner over the angle).
const MAX_PIECES: u32 = 20_000;
/// Initial pieces of either integral (the integrands have kinks; the halving test needs
/// pieces that see them).
const START_PIECES: usize = 16;
/// Angles sampled for the kinks of the angular integrand ([`angle_breaks`]).
const ANGLE_GRID: usize = 64;

/// Whether the cylinders `a` and `b` can share a point: their axis segments come closer
/// than the sum of their radii (a necessary condition; the volume decides).
pub(crate) fn may_overlap(a: &Cylinder, b: &Cylinder) -> bool {
    let reach = a.radius + b.radius;
    axis_range_near(a, b, reach).is_some()
}

/// The range of `t` along `a`'s axis segment whose points lie within `reach` of `b`'s axis
/// segment (the distance is convex in t, so the range is one interval), or None.
fn axis_range_near(a: &Cylinder, b: &Cylinder, reach: f64) -> Option<(f64, f64)> {
    let dist = |t: f64| {
        let p = a.center + t * a.axis - b.center;
        let s = p.dot(b.axis).clamp(-b.half_length, b.half_length);
        (p - s * b.axis).length()
    };
    let (mut lo, mut hi) = (-a.half_length, a.half_length);
    // the minimum of the convex distance by golden-section search
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..200 {
        if hi - lo <= 1e-15 * a.half_length.max(f64::MIN_POSITIVE) {
            break;
        }
        let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if dist(m1) <= dist(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let t0 = 0.5 * (lo + hi);
    let closest = dist(t0);
    if closest.is_nan() || closest > reach {
        return None;
    }
    // each end: bisection between the minimum and the segment's end
    let edge = |end: f64| {
        if dist(end) <= reach {
            return end;
        }
        let (mut inside, mut outside) = (t0, end);
        for _ in 0..100 {
            let m = 0.5 * (inside + outside);
            if dist(m) <= reach {
                inside = m;
            } else {
                outside = m;
            }
        }
        outside
    };
    Some((edge(-a.half_length), edge(a.half_length)))
}

/// Most intersections evaluated for one box (groups of two or more fibres): a bound on the
/// cost whatever the input. Past it the remaining groups are left out (their common parts
/// are then counted more than once).
const MAX_GROUPS: usize = 100_000;

/// The inclusion–exclusion terms of the union of the cylinders `cs` inside the box beyond
/// the single volumes: Σ (−1)^|S| V(∩S) over the groups S of two or more of `cs` that all
/// overlap one another, so that the union is Σ V(cᵢ) − this \[m³\]. A group whose
/// intersection is empty ends its branch (every larger group containing it is empty too).
pub(crate) fn shared_volume_in_box(cs: &[Cylinder], lo: DVec3, hi: DVec3) -> f64 {
    let n = cs.len();
    let near: Vec<Vec<bool>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| i != j && may_overlap(&cs[i], &cs[j]))
                .collect()
        })
        .collect();
    let mut budget = MAX_GROUPS;
    let mut total = 0.0;
    // depth-first over the groups in increasing index order
    let mut stack: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
    while let Some(group) = stack.pop() {
        let last = group[group.len() - 1];
        for (j, _) in cs.iter().enumerate().skip(last + 1) {
            if budget == 0 {
                return total;
            }
            if !group.iter().all(|&i| near[i][j]) {
                continue;
            }
            let mut larger = group.clone();
            larger.push(j);
            let members: Vec<Cylinder> = larger.iter().map(|&k| cs[k]).collect();
            budget -= 1;
            let v = intersection_volume_in_box(&members, lo, hi);
            if v > 0.0 {
                total += if larger.len() % 2 == 0 { v } else { -v };
                stack.push(larger);
            }
        }
    }
    total
}

/// Volume \[m³\] of the intersection of the solid cylinders `cs` (at least one) inside the
/// box `lo`..`hi` \[m\] (see the module header).
pub(crate) fn intersection_volume_in_box(cs: &[Cylinder], lo: DVec3, hi: DVec3) -> f64 {
    let Some((first, others)) = cs.split_first() else {
        return 0.0;
    };
    let (e, r) = (first.axis, first.radius);
    // the axis range that can meet the box and every other cylinder
    let (mut a, mut b) = (-first.half_length, first.half_length);
    for other in others {
        match axis_range_near(first, other, r + other.radius) {
            Some((t0, t1)) => (a, b) = (a.max(t0), b.min(t1)),
            None => return 0.0,
        }
    }
    // the box lies in the ball about its middle of radius its half diagonal: the axis points
    // within r of that ball
    let reach = r + 0.5 * (hi - lo).length();
    let d = first.center - 0.5 * (lo + hi);
    let along = d.dot(e);
    let across2 = d.length_squared() - along * along;
    if across2 > reach * reach {
        return 0.0;
    }
    let half = (reach * reach - across2).max(0.0).sqrt();
    (a, b) = (a.max(-along - half), b.min(-along + half));
    if a.is_nan() || b.is_nan() || b <= a {
        return 0.0;
    }
    let (u, v) = e.any_orthonormal_pair();
    let disc_area = std::f64::consts::PI * r * r;
    let area = |t: f64| {
        let p0 = first.center + t * e;
        let ray =
            |theta: f64| ray_interval(p0, theta.cos() * u + theta.sin() * v, r, others, lo, hi);
        let slice = |theta: f64| ray(theta).map_or(0.0, |(r0, r1, _)| 0.5 * (r1 * r1 - r0 * r0));
        let breaks = angle_breaks(&|theta| ray(theta).map_or(u64::MAX, |(_, _, k)| k));
        let tol = 1e-11 * disc_area;
        breaks
            .windows(2)
            .filter(|w| w[1] > w[0])
            .map(|w| {
                integrate(
                    &slice,
                    (w[0], w[1]),
                    tol * (w[1] - w[0]) / std::f64::consts::TAU,
                )
            })
            .sum::<f64>()
    };
    let full = disc_area * 2.0 * first.half_length;
    integrate(&area, (a, b), 1e-9 * full).clamp(0.0, full)
}

/// The radii `r` in [0, `radius`] of the points `p0 + r d` inside the box and inside every
/// cylinder of `others` (one interval, the sets being convex), or None when empty; with the
/// interval, which constraints bound it (a key that changes where the integrand over the
/// angle has a kink).
fn ray_interval(
    p0: DVec3,
    d: DVec3,
    radius: f64,
    others: &[Cylinder],
    lo: DVec3,
    hi: DVec3,
) -> Option<(f64, f64, u64)> {
    // (value, constraint id) of the lower and the upper end
    let (mut r0, mut r1) = ((0.0f64, 0u64), (radius, 1u64));
    let raise = |r0: &mut (f64, u64), v: f64, id: u64| {
        if v > r0.0 {
            *r0 = (v, id);
        }
    };
    let lower = |r1: &mut (f64, u64), v: f64, id: u64| {
        if v < r1.0 {
            *r1 = (v, id);
        }
    };
    // lo_k <= p0_k + r d_k <= hi_k
    for k in 0..3 {
        if d[k] == 0.0 {
            if p0[k] < lo[k] || p0[k] > hi[k] {
                return None;
            }
        } else {
            let (s0, s1) = ((lo[k] - p0[k]) / d[k], (hi[k] - p0[k]) / d[k]);
            let id = 2 + 2 * k as u64;
            raise(&mut r0, s0.min(s1), id);
            lower(&mut r1, s0.max(s1), id + 1);
        }
    }
    for (m, c) in others.iter().enumerate() {
        let id = 8 + 4 * m as u64;
        let w = p0 - c.center;
        // between the end planes: -L <= (w + r d).e <= L
        let (alpha, beta) = (w.dot(c.axis), d.dot(c.axis));
        if beta == 0.0 {
            if alpha.abs() > c.half_length {
                return None;
            }
        } else {
            let (s0, s1) = (
                (-c.half_length - alpha) / beta,
                (c.half_length - alpha) / beta,
            );
            raise(&mut r0, s0.min(s1), id);
            lower(&mut r1, s0.max(s1), id + 1);
        }
        // within the radius of the axis: |w⊥ + r d⊥|² <= R²
        let (wp, dp) = (w - alpha * c.axis, d - beta * c.axis);
        let (qa, qb, qc) = (dp.dot(dp), wp.dot(dp), wp.dot(wp) - c.radius * c.radius);
        if qa <= 1e-24 {
            if qc > 0.0 {
                return None;
            }
        } else {
            let disc = qb * qb - qa * qc;
            if disc < 0.0 {
                return None;
            }
            let sq = disc.sqrt();
            raise(&mut r0, (-qb - sq) / qa, id + 2);
            lower(&mut r1, (-qb + sq) / qa, id + 3);
        }
        if r1.0 <= r0.0 {
            return None;
        }
    }
    (r1.0 > r0.0).then_some((r0.0, r1.0, r0.1 << 32 | r1.1))
}

/// Angles at which to split the angular integral: where the key of [`ray_interval`] changes
/// between neighbours of a grid of [`ANGLE_GRID`] angles, each located by bisection (between
/// two such angles the integrand is analytic, unless the key changes and changes back within
/// one grid step).
fn angle_breaks(key: &impl Fn(f64) -> u64) -> Vec<f64> {
    let h = std::f64::consts::TAU / ANGLE_GRID as f64;
    let mut breaks = vec![0.0];
    let mut prev = key(0.0);
    for k in 1..=ANGLE_GRID {
        let theta = k as f64 * h;
        let next = key(theta);
        if next != prev {
            let (mut a, mut b) = (theta - h, theta);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if key(m) == prev {
                    a = m;
                } else {
                    b = m;
                }
            }
            breaks.push(0.5 * (a + b));
        }
        prev = next;
    }
    breaks.push(std::f64::consts::TAU);
    breaks
}

/// ∫ f over `range` in [`START_PIECES`] pieces, each by adaptive 5-point Gauss–Legendre to
/// its share of `tol` (at most [`MAX_PIECES`] bisections in all).
fn integrate(f: &impl Fn(f64) -> f64, (a, b): (f64, f64), tol: f64) -> f64 {
    let mut budget = MAX_PIECES;
    let h = (b - a) / START_PIECES as f64;
    (0..START_PIECES)
        .map(|k| {
            let (x0, x1) = (a + k as f64 * h, a + (k + 1) as f64 * h);
            let whole = super::box_region::gauss5(f, x0, x1);
            let piece_tol = tol / START_PIECES as f64;
            super::box_region::adaptive(f, (x0, x1), whole, piece_tol, 40, &mut budget)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cyl(center: [f64; 3], axis: [f64; 3], radius: f64, half_length: f64) -> Cylinder {
        Cylinder {
            center: DVec3::from_array(center),
            axis: DVec3::from_array(axis).normalize(),
            radius,
            half_length,
        }
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// Two and three perpendicular cylinders of one radius through a point, long and inside
    /// a large box: Steinmetz's solids 16r³/3 and 8(2 − √2)r³; one cylinder alone is πr²·2L.
    #[test]
    fn steinmetz_solids() {
        let r = 2e-6;
        let (lo, hi) = (DVec3::splat(-1e-4), DVec3::splat(1e-4));
        let x = cyl([0.0; 3], [1.0, 0.0, 0.0], r, 5e-5);
        let y = cyl([0.0; 3], [0.0, 1.0, 0.0], r, 5e-5);
        let z = cyl([0.0; 3], [0.0, 0.0, 1.0], r, 5e-5);
        let one = intersection_volume_in_box(&[x], lo, hi);
        assert!(
            rel(one, std::f64::consts::PI * r * r * 1e-4) < 1e-10,
            "{one}"
        );
        let two = intersection_volume_in_box(&[x, y], lo, hi);
        assert!(rel(two, 16.0 * r.powi(3) / 3.0) < 1e-8, "{two}");
        let three = intersection_volume_in_box(&[x, y, z], lo, hi);
        assert!(
            rel(three, 8.0 * (2.0 - 2f64.sqrt()) * r.powi(3)) < 1e-8,
            "{three}"
        );
        // the order of the cylinders does not matter
        let again = intersection_volume_in_box(&[z, x, y], lo, hi);
        assert!(rel(again, three) < 1e-8);
    }

    /// The shared terms of three perpendicular cylinders: three Steinmetz pairs counted
    /// twice and the triple solid once, so the union is 3·πr²·2L − 3·16r³/3 + 8(2 − √2)r³.
    #[test]
    fn the_shared_terms_follow_inclusion_exclusion() {
        let r = 1e-3;
        let (lo, hi) = (DVec3::splat(-1.0), DVec3::splat(1.0));
        let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let cs: Vec<Cylinder> = axes.iter().map(|&e| cyl([0.0; 3], e, r, 0.1)).collect();
        let shared = shared_volume_in_box(&cs, lo, hi);
        let expected = 3.0 * 16.0 * r.powi(3) / 3.0 - 8.0 * (2.0 - 2f64.sqrt()) * r.powi(3);
        assert!(rel(shared, expected) < 1e-8, "{shared} against {expected}");
        // a fourth cylinder far away adds nothing
        let mut more = cs.clone();
        more.push(cyl([0.5, 0.5, 0.5], [1.0, 1.0, 0.0], r, 0.1));
        assert!(rel(shared_volume_in_box(&more, lo, hi), expected) < 1e-8);
    }

    /// Disjoint or far apart: nothing, and the cheap test says so.
    #[test]
    fn apart_cylinders_share_nothing() {
        let (lo, hi) = (DVec3::splat(-1.0), DVec3::splat(1.0));
        let a = cyl([0.0; 3], [1.0, 0.0, 0.0], 0.1, 0.5);
        let b = cyl([0.0, 0.0, 0.25], [0.0, 1.0, 0.0], 0.1, 0.5);
        assert!(!may_overlap(&a, &b));
        assert_eq!(intersection_volume_in_box(&[a, b], lo, hi), 0.0);
        // crossing axes, but past b's end
        let c = cyl([0.0, 0.8, 0.0], [0.0, 1.0, 0.0], 0.1, 0.5);
        assert!(!may_overlap(&a, &c));
        let d = cyl([0.0, 0.5, 0.0], [0.0, 1.0, 0.0], 0.1, 0.5);
        assert!(may_overlap(&a, &d));
        // half of b's length reaches a: half the Steinmetz solid
        let half = intersection_volume_in_box(&[a, d], lo, hi);
        assert!(rel(half, 8.0 * 0.1f64.powi(3) / 3.0) < 1e-8, "{half}");
    }

    /// An oblique pair cut by the box's faces against a midpoint grid of 160³ cells over the
    /// pair's common bounding region (grid error ~1e-3 of the volume).
    #[test]
    fn a_clipped_oblique_pair_matches_a_grid() {
        let a = cyl([0.1, 0.0, 0.0], [1.0, 0.3, 0.1], 0.3, 1.0);
        let b = cyl([0.0, 0.05, 0.0], [0.2, 1.0, -0.4], 0.25, 1.0);
        let (lo, hi) = (DVec3::new(-0.2, -0.15, -0.1), DVec3::new(0.5, 0.4, 0.3));
        let v = intersection_volume_in_box(&[a, b], lo, hi);
        let both = |p: DVec3| a.distance(p) == 0.0 && b.distance(p) == 0.0;
        let grid = crate::scene::box_region::tests::grid_volume(lo, hi, 160, both);
        assert!(
            v > 0.0 && rel(v, grid) < 5e-3,
            "quadrature {v}, grid {grid}"
        );
    }
}
