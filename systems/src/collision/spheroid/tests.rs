//! Contact geometry against brute force (surface sampling for separated pairs, a sampled
//! separating-axis search for overlapping ones).

use glam::{DQuat, DVec3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::*;
use crate::collision::toi::Plane;

type Rng = Xoshiro256PlusPlus;

pub(super) fn unit(rng: &mut Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

pub(super) fn random_rotation(rng: &mut Rng) -> DQuat {
    DQuat::from_axis_angle(unit(rng), rng.random_range(0.0..std::f64::consts::TAU))
}

/// Surface point of a posed spheroid at polar angle `th` and azimuth `ph` (body frame).
fn surface(p: &PosedSpheroid, q: DQuat, th: f64, ph: f64) -> DVec3 {
    let (a, c) = (p.shape.equatorial, p.shape.polar);
    p.centre
        + q * DVec3::new(
            a * th.sin() * ph.cos(),
            a * th.sin() * ph.sin(),
            c * th.cos(),
        )
}

/// Brute-force minimum distance between two separated spheroid surfaces: a grid search over
/// both parametrisations, zoomed around the best pair. Returns (distance, unit a→b vector).
fn brute_distance(pa: &PosedSpheroid, qa: DQuat, pb: &PosedSpheroid, qb: DQuat) -> (f64, DVec3) {
    use std::f64::consts::PI;
    let n = 28usize;
    // windows (centre, half-width) of θ and φ of each body
    let mut win = [
        (PI / 2.0, PI / 2.0),
        (PI, PI),
        (PI / 2.0, PI / 2.0),
        (PI, PI),
    ];
    let mut best = (f64::INFINITY, DVec3::ZERO, [0.0; 4]);
    for _ in 0..14 {
        let grid = |(c, w): (f64, f64), k: usize| c - w + 2.0 * w * k as f64 / (n - 1) as f64;
        let pts_a: Vec<(DVec3, f64, f64)> = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (th, ph) = (grid(win[0], i), grid(win[1], j));
                (surface(pa, qa, th, ph), th, ph)
            })
            .collect();
        let pts_b: Vec<(DVec3, f64, f64)> = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (th, ph) = (grid(win[2], i), grid(win[3], j));
                (surface(pb, qb, th, ph), th, ph)
            })
            .collect();
        for &(x, t1, p1) in &pts_a {
            for &(y, t2, p2) in &pts_b {
                let dd = (y - x).length();
                if dd < best.0 {
                    best = (dd, y - x, [t1, p1, t2, p2]);
                }
            }
        }
        for (w, centre) in win.iter_mut().zip(best.2) {
            *w = (centre, w.1 * 0.35);
        }
    }
    (best.0, best.1.normalize())
}

/// Brute-force maximum of the separating-axis function over sampled unit directions (zoomed).
pub(super) fn brute_axis(pa: &PosedSpheroid, pb: &PosedSpheroid) -> (f64, DVec3) {
    let d = pb.centre - pa.centre;
    let f = |u: DVec3| u.dot(d) - pa.support_value(u) - pb.support_value(u);
    let mut best = (f64::NEG_INFINITY, DVec3::Z);
    let m = 20_000;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    for k in 0..m {
        let z = 1.0 - 2.0 * (k as f64 + 0.5) / m as f64;
        let r = (1.0 - z * z).sqrt();
        let u = DVec3::new(
            r * (golden * k as f64).cos(),
            r * (golden * k as f64).sin(),
            z,
        );
        let v = f(u);
        if v > best.0 {
            best = (v, u);
        }
    }
    let mut step = 0.03;
    for _ in 0..60 {
        let (t1, t2) = best.1.any_orthonormal_pair();
        let mut improved = false;
        for i in -2..=2 {
            for j in -2..=2 {
                let u = (best.1 + t1 * (i as f64 * step) + t2 * (j as f64 * step)).normalize();
                let v = f(u);
                if v > best.0 {
                    best = (v, u);
                    improved = true;
                }
            }
        }
        if !improved {
            step *= 0.5;
        }
    }
    best
}

fn random_pair(rng: &mut Rng, overlap: bool) -> (PosedSpheroid, DQuat, PosedSpheroid, DQuat) {
    let ws = [1.0, 0.5, 0.2, 0.1];
    let sa = Spheroid::new(1.0, ws[rng.random_range(0..4)]);
    let sb = Spheroid::new(rng.random_range(0.5..1.5), 0.0);
    let sb = Spheroid::new(sb.equatorial, sb.equatorial * ws[rng.random_range(0..4)]);
    let (qa, qb) = (random_rotation(rng), random_rotation(rng));
    let dir = unit(rng);
    let pa = PosedSpheroid::new(sa, DVec3::ZERO, qa);
    // place b along dir at the touching distance (bisection on the exact kernel), then shift
    let touching = {
        let (mut lo, mut hi) = (0.0, sa.bounding_radius() + sb.bounding_radius());
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            let pb = PosedSpheroid::new(sb, dir * mid, qb);
            if spheroid_contact(&pa, &pb, None).unwrap().geometry.gap > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    };
    let shift = if overlap {
        -rng.random_range(0.0..0.02)
    } else {
        rng.random_range(0.001..0.4)
    };
    let pb = PosedSpheroid::new(sb, dir * (touching + shift), qb);
    (pa, qa, pb, qb)
}

#[test]
fn separated_pairs_match_brute_force_surface_sampling() {
    let mut rng = Rng::seed_from_u64(5);
    let (mut worst_d, mut worst_angle) = (0.0f64, 0.0f64);
    for _ in 0..40 {
        let (pa, qa, pb, qb) = random_pair(&mut rng, false);
        let c = spheroid_contact(&pa, &pb, None).unwrap();
        assert!(c.converged);
        let (dist, dir) = brute_distance(&pa, qa, &pb, qb);
        let d_major = 2.0 * pa.shape.bounding_radius().max(pb.shape.bounding_radius());
        let err = (c.geometry.gap - dist).abs() / d_major;
        let angle = c
            .geometry
            .normal
            .dot(dir)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        worst_d = worst_d.max(err);
        worst_angle = worst_angle.max(angle);
        assert!(
            err < 1e-3,
            "distance error {err}: {} vs {dist}",
            c.geometry.gap
        );
        assert!(angle < 0.5, "normal off by {angle}°");
        // the witness points lie on the surfaces and span the gap along the normal
        let pa_w = pa.centre + c.witness_a;
        let pb_w = pb.centre + c.witness_b;
        assert!(((pb_w - pa_w) - c.geometry.normal * c.geometry.gap).length() < 1e-9);
        assert!((pa.centre + c.geometry.r_a - (pb.centre + c.geometry.r_b)).length() < 1e-12);
    }
    println!("worst distance error {worst_d:.2e} d_major, worst normal angle {worst_angle:.2e}°");
}

#[test]
fn overlapping_pairs_match_the_sampled_separating_axis() {
    let mut rng = Rng::seed_from_u64(6);
    let (mut worst_d, mut worst_angle) = (0.0f64, 0.0f64);
    for _ in 0..200 {
        let (pa, _, pb, _) = random_pair(&mut rng, true);
        let c = spheroid_contact(&pa, &pb, None).unwrap();
        let (f, u) = brute_axis(&pa, &pb);
        let d_major = 2.0 * pa.shape.bounding_radius().max(pb.shape.bounding_radius());
        let err = (c.geometry.gap - f).abs() / d_major;
        let angle = c
            .geometry
            .normal
            .dot(u)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        worst_d = worst_d.max(err);
        worst_angle = worst_angle.max(angle);
        assert!(c.geometry.gap <= 1e-12, "{}", c.geometry.gap);
        assert!(err < 1e-3, "depth error {err}: {} vs {f}", c.geometry.gap);
        assert!(angle < 0.5, "normal off by {angle}°");
    }
    println!("worst depth error {worst_d:.2e} d_major, worst normal angle {worst_angle:.2e}°");
}

#[test]
fn spheres_and_planes_are_exact() {
    let s = Spheroid::sphere(0.5);
    let a = PosedSpheroid::new(s, DVec3::ZERO, DQuat::IDENTITY);
    let b = PosedSpheroid::new(
        Spheroid::sphere(0.25),
        DVec3::new(0.3, 0.4, 1.2),
        DQuat::IDENTITY,
    );
    let c = spheroid_contact(&a, &b, None).unwrap();
    let d = b.centre.length();
    assert!((c.geometry.gap - (d - 0.75)).abs() < 1e-14);
    assert!((c.geometry.normal - b.centre / d).length() < 1e-14);
    // spheroid–plane closed form against sampling: a tilted 1:10 disc
    let mut rng = Rng::seed_from_u64(2);
    for _ in 0..100 {
        let q = random_rotation(&mut rng);
        let p = PosedSpheroid::new(Spheroid::new(1.0, 0.1), DVec3::new(0.0, 0.0, 0.7), q);
        let plane = Plane::new(DVec3::new(0.0, 0.0, -0.1), DVec3::new(0.1, 0.2, 1.0));
        let c = spheroid_plane_contact(&p, &plane);
        let mut lowest = f64::INFINITY;
        for i in 0..=400 {
            for j in 0..400 {
                let th = std::f64::consts::PI * i as f64 / 400.0;
                let ph = std::f64::consts::TAU * j as f64 / 400.0;
                lowest = lowest.min(plane.signed_distance(surface(&p, q, th, ph)));
            }
        }
        assert!((c.gap - lowest).abs() < 1e-4, "{} vs {lowest}", c.gap);
        assert!((plane.signed_distance(p.centre + c.r_a) - c.gap).abs() < 1e-12);
        assert_eq!(c.normal, -plane.normal);
    }
}

#[test]
fn invalid_input_gives_none_not_a_panic() {
    let good = PosedSpheroid::new(Spheroid::new(1.0, 0.1), DVec3::ZERO, DQuat::IDENTITY);
    let mut bad = good;
    bad.centre = DVec3::NAN;
    assert!(spheroid_contact(&good, &bad, None).is_none());
    let flat = PosedSpheroid::new(Spheroid::new(1.0, 0.0), DVec3::X, DQuat::IDENTITY);
    assert!(spheroid_contact(&good, &flat, None).is_none());
    // coincident centres and a NaN warm start still give an answer
    let c = spheroid_contact(&good, &good, Some(DVec3::NAN)).unwrap();
    assert!((c.geometry.gap + 0.2).abs() < 1e-9, "{}", c.geometry.gap);
}

#[test]
fn warm_start_converges_in_few_iterations() {
    let mut rng = Rng::seed_from_u64(9);
    for _ in 0..100 {
        let (pa, _, mut pb, _) = random_pair(&mut rng, false);
        let c = spheroid_contact(&pa, &pb, None).unwrap();
        pb.centre += unit(&mut rng) * 1e-4;
        let c2 = spheroid_contact(&pa, &pb, Some(c.geometry.normal)).unwrap();
        assert!(c2.converged && c2.iterations <= 6, "{}", c2.iterations);
    }
}

#[test]
fn contact_query_timing_hook_reports_converged_queries() {
    for w in [1.0, 0.5, 0.2, 0.1] {
        let t = time_contact_queries(2000, w, 3);
        println!(
            "w = {w}: cold {:.0} ns ({:.1} iterations), warm {:.0} ns, not converged {}",
            t.cold_seconds_per_query * 1e9,
            t.cold_iterations,
            t.warm_seconds_per_query * 1e9,
            t.not_converged
        );
        assert_eq!(t.not_converged, 0);
        assert!(t.cold_seconds_per_query > 0.0 && t.warm_seconds_per_query > 0.0);
    }
}
