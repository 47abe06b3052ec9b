//! Tests of the wall kernels against independent geometry.

use std::f64::consts::{PI, TAU};

use glam::{DMat3, DQuat, DVec3};
use rand::RngExt;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::*;
use crate::rng::particle_stream;

fn unit(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    let z = 2.0 * rng.random::<f64>() - 1.0;
    let phi = TAU * rng.random::<f64>();
    let s = (1.0 - z * z).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

fn uniform(rng: &mut Xoshiro256PlusPlus, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.random::<f64>()
}

/// Independent signed distance (positive inside) of `p` to `wall`, written out per wall.
fn distance_by_hand(kind: WallKind, e: DVec3, wall: WallId, p: DVec3) -> f64 {
    match (kind, wall) {
        (WallKind::Cylinder { radius }, _) => {
            let (x, y) = (p.x - radius, p.y - radius);
            radius - (x * x + y * y).sqrt()
        }
        (WallKind::Wedge { .. }, WallId::WedgeBottom) => p.y,
        (WallKind::Wedge { .. }, WallId::WedgeBack) => e.x - p.x,
        (WallKind::Wedge { alpha }, WallId::WedgeSlope) => p.x * alpha.sin() - p.y * alpha.cos(),
        (_, WallId::Low { axis }) => p[axis as usize],
        (_, WallId::High { axis }) => e[axis as usize] - p[axis as usize],
        _ => unreachable!(),
    }
}

/// Containers exercised by the tests (kind, edges).
fn containers(rng: &mut Xoshiro256PlusPlus) -> Vec<(WallKind, DVec3)> {
    let mut v = Vec::new();
    for r in [0.6, 0.9, 1.5, 3.0] {
        v.push((WallKind::Cylinder { radius: r }, cylinder_edges(r, 6.0)));
    }
    for deg in [9.0f64, 15.0, 30.0, 45.0] {
        let alpha = deg.to_radians();
        let l = uniform(rng, 3.0, 8.0);
        v.push((WallKind::Wedge { alpha }, wedge_edges(alpha, l, 5.0)));
    }
    v.push((WallKind::Slab, DVec3::new(4.0, 5.0, 2.5)));
    v.push((WallKind::Box, DVec3::new(3.0, 4.0, 2.5)));
    v
}

/// A random centre inside the container (near its walls for the big ones).
fn random_centre(rng: &mut Xoshiro256PlusPlus, kind: WallKind, e: DVec3) -> DVec3 {
    random_admissible_point(kind, e, 0.0, rng).unwrap()
}

#[test]
fn virtual_rod_overlap_equals_cap_depth_for_every_wall() {
    let mut rng = particle_stream(11, 0);
    let mut max_err: f64 = 0.0;
    let mut exact_per_wall = std::collections::HashMap::<WallId, usize>::new();
    let mut bounded = 0;
    let mut too_deep = 0;
    let mut v = Vec::new();
    for (kind, e) in containers(&mut rng) {
        for _ in 0..6000 {
            let x = random_centre(&mut rng, kind, e);
            let u = unit(&mut rng);
            let radius = uniform(&mut rng, 0.2, 0.55);
            let h = if rng.random::<f64>() < 0.15 {
                0.0
            } else {
                uniform(&mut rng, 0.05, 1.5)
            };
            v.clear();
            virtual_rods(kind, e, x, u, radius, h, &mut v);
            for vr in &v {
                let ends = [x + h * u, x - h * u];
                let depth = ends.map(|p| radius - distance_by_hand(kind, e, vr.wall, p));
                // which end made it: the one whose depth it carries
                let k = if (depth[0] - vr.depth).abs() <= (depth[1] - vr.depth).abs() {
                    0
                } else {
                    1
                };
                assert!((depth[k] - vr.depth).abs() < 1e-12 && depth[k] > 0.0);
                // tangent to the wall from outside, axis in the wall (cylinder: along z)
                let dv = distance_by_hand(kind, e, vr.wall, vr.centre);
                assert!((dv + radius).abs() < 1e-12, "{dv} {radius}");
                let n = wall_normal(kind, e, vr.wall, vr.centre);
                assert!(vr.axis.dot(n).abs() < 1e-12 && (vr.axis.length() - 1.0).abs() < 1e-12);
                assert_eq!((vr.radius, vr.half_length), (radius, h));
                let overlap = vr.contact(x, u, radius, h).overlap;
                if depth[k] > 2.0 * radius {
                    // the end point lies beyond the virtual axis: no pair of rods overlaps
                    // by more than 2R (documented limit; MCM overlaps are << R)
                    assert!(overlap <= 2.0 * radius + 1e-12);
                    too_deep += 1;
                    continue;
                }
                if depth[k] >= depth[1 - k] {
                    max_err = max_err.max((overlap - depth[k]).abs());
                    *exact_per_wall.entry(vr.wall).or_default() += 1;
                } else {
                    // the shallower of two penetrating ends: between its depth and the deeper
                    assert!(overlap >= depth[k] - 1e-12, "{overlap} < {}", depth[k]);
                    assert!(
                        overlap <= depth[1 - k] + 1e-12,
                        "{overlap} > {}",
                        depth[1 - k]
                    );
                    bounded += 1;
                }
            }
        }
    }
    eprintln!(
        "virtual rods: max |overlap - depth| = {max_err:.2e}; exact cases {exact_per_wall:?}; shallow-end cases {bounded}; deeper than 2R (skipped) {too_deep}"
    );
    assert!(max_err < 1e-12, "{max_err}");
    for w in [
        WallId::Cylinder,
        WallId::WedgeBottom,
        WallId::WedgeBack,
        WallId::WedgeSlope,
        WallId::Low { axis: 0 },
        WallId::High { axis: 1 },
        WallId::Low { axis: 2 },
        WallId::High { axis: 2 },
    ] {
        assert!(exact_per_wall.get(&w).copied().unwrap_or(0) > 300, "{w:?}");
    }
    assert!(bounded > 100);
}

#[test]
fn virtual_rods_follow_the_thesis_criteria_and_axes() {
    let alpha = 15f64.to_radians();
    let (k, e) = (WallKind::Wedge { alpha }, wedge_edges(alpha, 6.0, 4.0));
    let mut v = Vec::new();
    // a sphere in the corner of back and bottom: two virtual spheres
    let p = DVec3::new(5.7, 0.2, 1.0);
    virtual_rods(k, e, p, DVec3::Z, 0.5, 0.0, &mut v);
    assert_eq!(v.len(), 2);
    assert_eq!((v[0].wall, v[0].axis), (WallId::WedgeBottom, DVec3::X));
    assert!((v[0].centre - DVec3::new(5.7, -0.5, 1.0)).length() < 1e-14); // (p_x, -R, p_z)
    assert_eq!((v[1].wall, v[1].axis), (WallId::WedgeBack, DVec3::Y));
    assert!((v[1].centre - DVec3::new(6.5, 0.2, 1.0)).length() < 1e-14); // (l_w + R, p_y, p_z)
    // slope criterion p_y > p_x tan(a) - R / cos(a) ([T000 §2.2.4])
    let mut rng = particle_stream(3, 1);
    for _ in 0..2000 {
        let p = random_centre(&mut rng, k, e);
        v.clear();
        virtual_rods(k, e, p, DVec3::X, 0.5, 0.0, &mut v);
        let thesis = p.y > p.x * alpha.tan() - 0.5 / alpha.cos();
        let slope: Vec<_> = v.iter().filter(|r| r.wall == WallId::WedgeSlope).collect();
        assert_eq!(slope.len(), usize::from(thesis));
        if let Some(r) = slope.first() {
            assert!((r.axis - DVec3::new(alpha.cos(), alpha.sin(), 0.0)).length() < 1e-15);
        }
    }
    // cylinder: thesis criterion p_x^2 + p_y^2 > (R_cyl - R)^2 in the axis frame ([T000 §2.2.4])
    let (k, e) = (WallKind::Cylinder { radius: 1.2 }, cylinder_edges(1.2, 5.0));
    let mut rng = particle_stream(3, 2);
    for _ in 0..2000 {
        let (x, u, h) = (random_centre(&mut rng, k, e), unit(&mut rng), 0.7);
        v.clear();
        virtual_rods(k, e, x, u, 0.5, h, &mut v);
        let crit = |p: DVec3| (p.x - 1.2).powi(2) + (p.y - 1.2).powi(2) > 0.7f64.powi(2);
        assert_eq!(
            v.len(),
            usize::from(crit(x + h * u)) + usize::from(crit(x - h * u))
        );
    }
    // nothing for a particle well inside; nothing at all without walls
    v.clear();
    virtual_rods(k, e, DVec3::new(1.2, 1.2, 2.0), DVec3::Z, 0.5, 2.0, &mut v);
    virtual_rods(
        WallKind::Periodic,
        e,
        DVec3::ZERO,
        DVec3::Z,
        0.5,
        2.0,
        &mut v,
    );
    assert!(v.is_empty());
}

fn capsule(u: DVec3, h: f64, r: f64) -> impl Fn(DVec3) -> DVec3 {
    move |d: DVec3| {
        let s = if u.dot(d) >= 0.0 { h } else { -h };
        s * u + r * d
    }
}

#[test]
fn convex_rule_matches_capsules_and_spheres() {
    let mut rng = particle_stream(12, 0);
    let mut max_err: f64 = 0.0;
    let mut two_sided = 0;
    let mut out = Vec::new();
    for (kind, e) in containers(&mut rng) {
        for _ in 0..3000 {
            let x = random_centre(&mut rng, kind, e);
            let u = unit(&mut rng);
            let r = uniform(&mut rng, 0.2, 0.55);
            let h = if rng.random::<f64>() < 0.2 {
                0.0
            } else {
                uniform(&mut rng, 0.05, 1.5)
            };
            let support = capsule(u, h, r);
            let ends = [x + h * u, x - h * u];
            let mut expect = f64::NEG_INFINITY;
            out.clear();
            convex_wall_contacts(kind, e, x, &support, 0.0, &mut out);
            for &w in wall_ids(kind) {
                let d = ends.map(|p| r - distance_by_hand(kind, e, w, p));
                let deepest = d[0].max(d[1]);
                expect = expect.max(deepest);
                let here: Vec<_> = out.iter().filter(|c| c.wall == w).collect();
                if deepest > 1e-9 {
                    assert!(!here.is_empty(), "{kind:?} {w:?} missing contact {deepest}");
                    max_err = max_err.max((here[0].overlap - deepest).abs());
                    let c = here[0];
                    let p = x + c.rc;
                    assert!((c.normal - wall_normal(kind, e, w, p)).length() < 1e-9);
                    assert!((distance_by_hand(kind, e, w, p) + c.overlap).abs() < 1e-12);
                }
                if let WallKind::Cylinder { .. } = kind {
                    // two contacts when both caps penetrate and the particle leaves the
                    // contact zone between them; one when rho is monotone along the axis
                    // (only one end is a local maximum)
                    let (a, b) = (ends[0], ends[1]);
                    let along: Vec<f64> = (0..=200)
                        .map(|i| a + (b - a) * (i as f64 / 200.0))
                        .map(|p| r - distance_by_hand(kind, e, w, p))
                        .collect();
                    let mid_depth = along.iter().copied().fold(f64::INFINITY, f64::min);
                    let monotone = along.windows(2).all(|p| p[1] >= p[0])
                        || along.windows(2).all(|p| p[1] <= p[0]);
                    if d[0] > 1e-6 && d[1] > 1e-6 && mid_depth < -1e-3 {
                        assert_eq!(
                            here.len(),
                            2,
                            "{d:?} {mid_depth} {kind:?} x={x} u={u} r={r} h={h} {here:?}"
                        );
                        let mut got = [here[0].overlap, here[1].overlap];
                        got.sort_by(f64::total_cmp);
                        let mut want = d;
                        want.sort_by(f64::total_cmp);
                        max_err = max_err.max((got[0] - want[0]).abs());
                        two_sided += 1;
                    } else if monotone || d[0].min(d[1]) < -1e-6 {
                        assert!(here.len() <= 1, "{d:?} {mid_depth}");
                    }
                }
            }
            let pd = penetration_depth(kind, e, x, &support);
            max_err = max_err.max((pd - expect).abs());
        }
    }
    eprintln!(
        "convex rule vs capsule/sphere: max error {max_err:.2e}; two-sided cylinder contacts {two_sided}"
    );
    assert!(max_err < 1e-12, "{max_err}");
    assert!(two_sided > 20, "{two_sided}");
}

/// Support map of an ellipsoid with semi-axes `a` (body frame) rotated by `q`.
fn ellipsoid(a: DVec3, q: DQuat) -> impl Fn(DVec3) -> DVec3 {
    move |d: DVec3| {
        let db = q.inverse() * d;
        let a2d = a * a * db;
        q * (a2d / db.dot(a2d).sqrt())
    }
}

#[test]
fn convex_rule_matches_sampled_ellipsoid_surfaces() {
    let mut rng = particle_stream(13, 0);
    let (nt, np) = (300, 600);
    let mut max_gap: f64 = 0.0;
    let mut cases = 0;
    let cyl = |r: f64| (WallKind::Cylinder { radius: r }, cylinder_edges(r, 8.0));
    let alpha = 20f64.to_radians();
    let kinds = [
        cyl(0.8),
        cyl(1.3),
        cyl(3.0),
        (WallKind::Wedge { alpha }, wedge_edges(alpha, 5.0, 4.0)),
        (WallKind::Box, DVec3::new(3.0, 3.5, 4.0)),
    ];
    for (kind, e) in kinds {
        for _ in 0..12 {
            let a = DVec3::new(
                uniform(&mut rng, 0.2, 1.0),
                uniform(&mut rng, 0.2, 0.6),
                uniform(&mut rng, 0.15, 0.5),
            );
            let q = DQuat::from_scaled_axis(unit(&mut rng) * uniform(&mut rng, 0.0, PI));
            let x = random_centre(&mut rng, kind, e);
            let support = ellipsoid(a, q);
            let rot = DMat3::from_quat(q);
            let mut sampled = f64::NEG_INFINITY;
            for i in 0..nt {
                let th = PI * (i as f64 + 0.5) / nt as f64;
                for j in 0..np {
                    let ph = TAU * j as f64 / np as f64;
                    let b = DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * a;
                    let p = x + rot * b;
                    for &w in wall_ids(kind) {
                        sampled = sampled.max(-distance_by_hand(kind, e, w, p));
                    }
                }
            }
            let depth = penetration_depth(kind, e, x, &support);
            // the exact maximum bounds every sample; sampling misses at most ~ a (dtheta)^2
            assert!(
                depth >= sampled - 1e-12,
                "{kind:?}: {depth} < sampled {sampled}"
            );
            max_gap = max_gap.max(depth - sampled);
            assert!(
                depth - sampled < 2e-4,
                "{kind:?}: {depth} vs sampled {sampled}"
            );
            cases += 1;
        }
    }
    eprintln!("ellipsoids: {cases} cases, max (exact - sampled) = {max_gap:.2e}");
}

#[test]
fn cylinder_iteration_converges_for_particles_near_the_axis() {
    // slow contraction (curvature radius ~ rho): an ellipsoid nearly centred in a narrow
    // cylinder, compared with a fine 1-D scan of the horizontal support points
    let (kind, e) = (WallKind::Cylinder { radius: 0.7 }, cylinder_edges(0.7, 5.0));
    let mut rng = particle_stream(14, 0);
    let mut max_err: f64 = 0.0;
    for _ in 0..50 {
        let a = DVec3::new(0.6, 0.5, 0.45);
        let q = DQuat::from_scaled_axis(unit(&mut rng) * uniform(&mut rng, 0.0, PI));
        let x = DVec3::new(0.7, 0.7, 1.0) + (unit(&mut rng) * DVec3::new(1.0, 1.0, 0.0)) * 0.01;
        let support = ellipsoid(a, q);
        let scan = (0..200_000)
            .map(|k| TAU * k as f64 / 200_000.0)
            .map(|t| {
                let p = x + support(DVec3::new(t.cos(), t.sin(), 0.0));
                (p.x - 0.7).hypot(p.y - 0.7) - 0.7
            })
            .fold(f64::NEG_INFINITY, f64::max);
        let depth = penetration_depth(kind, e, x, &support);
        assert!(depth >= scan - 1e-12);
        max_err = max_err.max(depth - scan);
    }
    eprintln!("near-axis ellipsoids: max (iteration - scan) = {max_err:.2e}");
    assert!(max_err < 1e-8, "{max_err}");
}

#[test]
fn admissible_agrees_with_penetration_and_insertion_is_uniform() {
    let mut rng = particle_stream(15, 0);
    for (kind, e) in containers(&mut rng) {
        let b = bounding_box(kind, e);
        for _ in 0..3000 {
            let p = DVec3::new(
                uniform(&mut rng, -0.5, b.x + 0.5),
                uniform(&mut rng, -0.5, b.y + 0.5),
                uniform(&mut rng, -0.5, b.z + 0.5),
            );
            let r = uniform(&mut rng, 0.0, 0.6);
            let sphere = |d: DVec3| r * d;
            let pen = penetration_depth(kind, e, p, &sphere);
            assert_eq!(
                admissible(kind, e, p, r),
                pen <= 0.0,
                "{kind:?} {p} {r} {pen}"
            );
            // rods inserted by their end caps are inside (convexity)
            let (u, h) = (unit(&mut rng), uniform(&mut rng, 0.0, 1.0));
            if admissible(kind, e, p + h * u, r) && admissible(kind, e, p - h * u, r) {
                assert!(penetration_depth(kind, e, p, &capsule(u, h, r)) <= 1e-12);
            }
        }
        // Monte Carlo volume of the admissible set at zero clearance = container volume
        let n = 40_000;
        let inside = (0..n)
            .filter(|_| {
                let p = DVec3::new(
                    rng.random::<f64>(),
                    rng.random::<f64>(),
                    rng.random::<f64>(),
                ) * b;
                admissible(kind, e, p, 0.0)
            })
            .count() as f64;
        let f = container_volume(kind, e) / (b.x * b.y * b.z);
        let sigma = (f * (1.0 - f) / n as f64).sqrt();
        assert!(
            (inside / n as f64 - f).abs() < 5.0 * sigma + 1e-12,
            "{kind:?}"
        );
    }
    // uniformity: P(rho < R/2) = 1/4 in a cylinder; P(x < l/2) = 1/4 in a wedge
    let (k, e) = (WallKind::Cylinder { radius: 2.0 }, cylinder_edges(2.0, 3.0));
    let n = 20_000;
    let hits = (0..n)
        .map(|_| random_admissible_point(k, e, 0.0, &mut rng).unwrap())
        .filter(|p| (p.x - 2.0).hypot(p.y - 2.0) < 1.0)
        .count() as f64;
    assert!((hits / n as f64 - 0.25).abs() < 5.0 * (0.1875 / n as f64).sqrt());
    let alpha = 0.4;
    let (k, e) = (WallKind::Wedge { alpha }, wedge_edges(alpha, 4.0, 3.0));
    let hits = (0..n)
        .map(|_| random_admissible_point(k, e, 0.0, &mut rng).unwrap())
        .filter(|p| p.x < 2.0)
        .count() as f64;
    assert!((hits / n as f64 - 0.25).abs() < 5.0 * (0.1875 / n as f64).sqrt());
    // empty admissible sets
    let in_r = 0.5 * 4.0 * (1.0 + alpha.tan() - 1.0 / alpha.cos());
    assert!(random_admissible_point(k, e, in_r + 1e-9, &mut rng).is_none());
    assert!(random_admissible_point(k, e, in_r - 1e-2, &mut rng).is_some());
    assert!(random_admissible_point(WallKind::Box, DVec3::splat(1.0), 0.5, &mut rng).is_none());
}

#[test]
fn wedge_minimum_matches_the_spec_table() {
    // D-000-17, R = 1/2: (Lambda, [(l, phi) for alpha = 9, 15, 30, 45 deg])
    let table: [(f64, [(f64, f64); 4]); 5] = [
        (
            1.0,
            [
                (6.853, 0.141),
                (4.298, 0.212),
                (2.366, 0.324),
                (1.707, 0.359),
            ],
        ),
        (
            1.25,
            [
                (7.100, 0.180),
                (4.539, 0.261),
                (2.583, 0.374),
                (1.884, 0.406),
            ],
        ),
        (
            2.0,
            [
                (7.841, 0.269),
                (5.264, 0.353),
                (3.232, 0.434),
                (2.414, 0.449),
            ],
        ),
        (
            3.0,
            [
                (8.829, 0.339),
                (6.230, 0.403),
                (4.098, 0.432),
                (3.121, 0.430),
            ],
        ),
        (
            5.0,
            [
                (10.804, 0.397),
                (8.162, 0.411),
                (5.830, 0.374),
                (4.536, 0.356),
            ],
        ),
    ];
    let mut max_l: f64 = 0.0;
    let mut max_phi: f64 = 0.0;
    for (lambda, row) in table {
        for (deg, (l, phi)) in [9.0f64, 15.0, 30.0, 45.0].into_iter().zip(row) {
            let a = deg.to_radians();
            let cyl = lambda - 1.0; // L = (Lambda - 1) D
            max_l = max_l.max((wedge_min_length(0.5, cyl, a) - l).abs());
            max_phi = max_phi.max((wedge_min_packing_fraction(0.5, cyl, a) - phi).abs());
        }
    }
    eprintln!("wedge table: max |dl| = {max_l:.1e}, max |dphi| = {max_phi:.1e}");
    // printed to 3 decimals; l(Lambda = 3, 9 deg) = 8.82848 is printed 8.829 (a last-digit
    // slip in the table), every other entry rounds exactly
    assert!(max_l <= 1e-3 && max_phi <= 5e-4 + 1e-12);
    // spheres in the minimum wedge: the inscribed sphere touches all three planes
    let a = 0.3;
    let l = wedge_min_length(0.5, 0.0, a);
    let c = DVec3::new(l - 0.5, 0.5, 1.0);
    let k = WallKind::Wedge { alpha: a };
    let d = min_wall_distance(k, wedge_edges(a, l, 2.0), c);
    assert!((d - 0.5).abs() < 1e-12, "{d}");
}

#[test]
fn container_tables_and_serde() {
    let e = DVec3::new(2.0, 3.0, 4.0);
    assert_eq!(container_volume(WallKind::Box, e), 24.0);
    assert_eq!(container_volume(WallKind::Wedge { alpha: 0.5 }, e), 12.0);
    assert_eq!(planes(WallKind::Box, e).len(), 6);
    assert_eq!(planes(WallKind::Cylinder { radius: 1.0 }, e).len(), 0);
    for (kind, n) in [
        (WallKind::Periodic, 0),
        (WallKind::Cylinder { radius: 1.0 }, 1),
        (WallKind::Wedge { alpha: 0.2 }, 3),
        (WallKind::Slab, 2),
        (WallKind::Box, 6),
    ] {
        assert_eq!(wall_ids(kind).len(), n);
        // a walled axis (normal of a plane) is never periodic
        let per = periodic_axes(kind);
        for p in planes(kind, DVec3::ONE).iter() {
            for (n, periodic) in p.normal.to_array().into_iter().zip(per) {
                assert!(n == 0.0 || !periodic, "{kind:?}");
            }
        }
        let json = serde_json::to_string(&kind).unwrap();
        assert_eq!(serde_json::from_str::<WallKind>(&json).unwrap(), kind);
    }
    assert_eq!(
        serde_json::to_string(&WallKind::Cylinder { radius: 1.5 }).unwrap(),
        r#"{"kind":"cylinder","radius":1.5}"#
    );
    // outward normals point out of the container
    let alpha = 0.6;
    let e = wedge_edges(alpha, 3.0, 2.0);
    let inside = DVec3::new(2.0, 0.3, 1.0);
    for p in planes(WallKind::Wedge { alpha }, e).iter() {
        assert!(p.distance(inside) > 0.0 && p.distance(inside + 10.0 * p.normal) < 0.0);
    }
}

#[test]
fn margin_reports_near_contacts_and_containers_are_tabulated() {
    let sphere = |d: DVec3| 0.5 * d;
    let mut c = Vec::new();
    let (k, e) = (WallKind::Slab, DVec3::new(3.0, 3.0, 4.0));
    let x = DVec3::new(1.0, 1.0, 0.55); // gap 0.05 to the floor
    convex_wall_contacts(k, e, x, &sphere, 0.01, &mut c);
    assert!(c.is_empty());
    convex_wall_contacts(k, e, x, &sphere, 0.1, &mut c);
    assert_eq!(c.len(), 1);
    assert!((c[0].overlap + 0.05).abs() < 1e-15);
    let (k, e) = (WallKind::Cylinder { radius: 2.0 }, cylinder_edges(2.0, 4.0));
    let x = DVec3::new(3.45, 2.0, 1.0); // rho 1.45: gap 0.05
    c.clear();
    convex_wall_contacts(k, e, x, &sphere, 0.01, &mut c);
    assert!(c.is_empty());
    convex_wall_contacts(k, e, x, &sphere, 0.1, &mut c);
    assert_eq!(c.len(), 1);
    assert!((c[0].overlap + 0.05).abs() < 1e-14 && (c[0].normal - DVec3::X).length() < 1e-15);
    assert_eq!(
        penetration_depth(WallKind::Periodic, e, x, &sphere),
        f64::NEG_INFINITY
    );
    let table = [
        (WallKind::Periodic, [true; 3], [true; 3]),
        (
            WallKind::Cylinder { radius: 1.0 },
            [false, false, true],
            [false, false, true],
        ),
        (
            WallKind::Wedge { alpha: 0.3 },
            [false, false, true],
            [false, false, true],
        ),
        (WallKind::Slab, [true, true, false], [false, false, true]),
        (WallKind::Box, [false; 3], [true; 3]),
    ];
    for (kind, per, comp) in table {
        assert_eq!((periodic_axes(kind), compressed_axes(kind)), (per, comp));
    }
}
