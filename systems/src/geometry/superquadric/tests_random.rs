//! Statistical acceptance test (target V-PK-5): on 10^4 random pairs the sign of
//! the overlap agrees with a dense, independent sampling test and Newton rarely fails.
//!
//! Dense test: directions from a's centre that can reach b's bounding sphere (a cone) are
//! sampled on a Fibonacci cap, projected radially onto a's surface, and the points are tested
//! with b's inside function; then the same with a and b swapped. Separated bodies have no
//! surface point inside each other, so "none inside" is certain for gaps; an overlap of depth
//! delta is only seen if the samples are denser than delta, so pairs with |overlap| below the
//! largest local sample spacing (|p| dtheta / cos psi, psi between ray and normal) among the
//! points inside the other body's bounding sphere are skipped and counted.

use super::prepared::Prepared;
use super::tests::{quat, rng, unit};
use super::*;
use glam::{DQuat, DVec3};
use rand::RngExt;
use rand_xoshiro::Xoshiro256PlusPlus;

/// Whether a sampled surface point of `a` lies inside `b`, and the largest local spacing of
/// the samples that lie inside b's bounding sphere.
fn sampled_inside(
    a: &Superquadric,
    xa: DVec3,
    qa: DQuat,
    b: &Superquadric,
    xb: DVec3,
    qb: DQuat,
    m: usize,
) -> (bool, f64) {
    let (pa, pb): (Prepared, Prepared) = (a.prepared(), b.prepared());
    let rb = b.bounding_radius();
    let d = xb - xa;
    let dist = d.length();
    let axis = qa.conjugate() * d.try_normalize().unwrap_or(DVec3::Z);
    let cos_t = if dist > rb {
        (1.0 - (rb / dist).powi(2)).sqrt()
    } else {
        -1.0
    };
    let solid = 2.0 * std::f64::consts::PI * (1.0 - cos_t);
    let dtheta = 1.1 * (solid / m as f64).sqrt();
    let rot = DQuat::from_rotation_arc(DVec3::Z, axis);
    let ga = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut inside = false;
    let mut h: f64 = 0.0;
    for i in 0..m {
        let z = 1.0 - (1.0 - cos_t) * (i as f64 + 0.5) / m as f64;
        let rr = (1.0 - z * z).max(0.0).sqrt();
        let t = ga * i as f64;
        let w = rot * DVec3::new(rr * t.cos(), rr * t.sin(), z);
        let p = pa.project_radial(w, pa.inside(w) + 1.0);
        let lab = xa + qa * p;
        if (lab - xb).length() > rb {
            continue;
        }
        let n = pa.eval(p).grad.normalize();
        let cos_psi = n.dot(p.normalize()).max(1e-3);
        h = h.max(p.length() * dtheta / cos_psi);
        if pb.inside(qb.conjugate() * (lab - xb)) < 0.0 {
            inside = true;
        }
    }
    (inside, h)
}

fn random_shape(r: &mut Xoshiro256PlusPlus) -> Superquadric {
    let g = |r: &mut Xoshiro256PlusPlus| {
        if r.random::<f64>() < 0.8 {
            2.0 + 3.0 * r.random::<f64>()
        } else {
            5.0 + 5.0 * r.random::<f64>()
        }
    };
    let a = |r: &mut Xoshiro256PlusPlus| 0.5 + r.random::<f64>();
    match r.random_range(0..4) {
        0 => Superquadric::superball(a(r), g(r)),
        1 => Superquadric {
            semi_axes: DVec3::new(a(r), a(r), a(r)),
            exponents: DVec3::splat(g(r)),
        },
        2 => Superquadric {
            semi_axes: DVec3::new(a(r), a(r), a(r)),
            exponents: DVec3::new(2.0, 2.0, 2.0),
        },
        _ => Superquadric {
            semi_axes: DVec3::new(a(r), a(r), a(r)),
            exponents: DVec3::new(g(r), g(r), g(r)),
        },
    }
}

#[test]
fn random_pairs_agree_with_dense_sampling_and_rarely_fall_back() {
    let mut r = rng(2024);
    let pairs = 10_000;
    let m = 2500;
    let (mut agree, mut disagree, mut skipped) = (0usize, 0usize, 0usize);
    let (mut newton_runs, mut fallbacks, mut overlapping) = (0usize, 0usize, 0usize);
    let opts = ContactOptions::default();
    for i in 0..pairs {
        let (a, b) = (random_shape(&mut r), random_shape(&mut r));
        let (qa, qb) = (quat(&mut r), quat(&mut r));
        let u = unit(&mut r);
        let reach = a.support_value(qa.conjugate() * u) + b.support_value(qb.conjugate() * u);
        let scale = a.semi_axes.min_element().min(b.semi_axes.min_element());
        let d = u * (reach + scale * (0.35 * r.random::<f64>() - 0.3));
        let xa = DVec3::new(0.5, -0.25, 1.0);
        let c = contact(&a, xa, qa, &b, xa + d, qb, &opts, None);
        assert!(c.overlap.is_finite(), "{i}: {c:?}");
        if matches!(c.status, ContactStatus::Converged | ContactStatus::Fallback) {
            newton_runs += 1;
        }
        if c.status == ContactStatus::Fallback {
            fallbacks += 1;
            eprintln!("fallback {i}: {a:?} {b:?} qa {qa} qb {qb} d {d}: {c:?}");
        }
        let (in_b, ha) = sampled_inside(&a, xa, qa, &b, xa + d, qb, m);
        let (in_a, hb) = sampled_inside(&b, xa + d, qb, &a, xa, qa, m);
        if c.overlap.abs() < ha.max(hb) {
            skipped += 1;
            continue;
        }
        let dense = in_a || in_b;
        if dense == (c.overlap > 0.0) {
            agree += 1;
            overlapping += usize::from(dense);
        } else {
            disagree += 1;
            eprintln!("disagreement {i}: {a:?} {b:?} qa {qa} qb {qb} d {d}: {c:?}, dense {dense}");
        }
    }
    let tested = agree + disagree;
    let agreement = agree as f64 / tested as f64;
    let failure = fallbacks as f64 / newton_runs.max(1) as f64;
    eprintln!(
        "random pairs: {pairs}, tested {tested} ({overlapping} overlapping), skipped {skipped} \
         (|overlap| below sampling resolution), agreement {:.4} %, Newton runs {newton_runs}, \
         fallbacks {fallbacks} (rate {:.4} %)",
        100.0 * agreement,
        100.0 * failure
    );
    assert!(tested >= pairs / 2, "too many pairs skipped: {skipped}");
    assert!(agreement > 0.999, "sign agreement {agreement}");
    assert!(failure < 0.001, "Newton failure rate {failure}");
}
