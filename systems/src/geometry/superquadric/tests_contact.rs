//! Deterministic contact tests: analytic limits (spheres, aligned superballs), ellipsoids
//! against an independent support-function minimisation, symmetry, degenerate inputs, warm
//! starts and the GJK/EPA-only mode.

use super::tests::{fibonacci, quat, rng, unit};
use super::*;
use glam::{DQuat, DVec3};
use rand::RngExt;

fn run(
    a: &Superquadric,
    xa: DVec3,
    qa: DQuat,
    b: &Superquadric,
    xb: DVec3,
    qb: DQuat,
) -> ContactResult {
    contact(a, xa, qa, b, xb, qb, &ContactOptions::default(), None)
}

#[test]
fn sphere_limit_is_exact() {
    let mut r = rng(7);
    for i in 0..2000 {
        let ra = 0.5 + r.random::<f64>();
        let rb = 0.5 + r.random::<f64>();
        let (a, b) = (
            Superquadric::superball(ra, 2.0),
            Superquadric::superball(rb, 2.0),
        );
        let xa = unit(&mut r) * 3.0 * r.random::<f64>();
        let dist =
            (ra + rb) * (0.5 + 0.6 * r.random::<f64>()) + if i % 7 == 0 { 0.0 } else { 1e-3 };
        let d = unit(&mut r) * dist;
        let c = run(&a, xa, quat(&mut r), &b, xa + d, quat(&mut r));
        let want = ra + rb - d.length();
        if (c.overlap - want).abs() >= 1e-12 {
            eprintln!("DEBUG {i} {ra} {rb} {c:?}");
        }
        assert!(
            (c.overlap - want).abs() < 1e-12,
            "{i}: {} vs {want}",
            c.overlap
        );
        assert!(
            (c.normal - d.normalize()).length() < 1e-12,
            "{i}: normal {}",
            c.normal
        );
        if want >= 0.0 {
            assert_eq!(c.status, ContactStatus::Converged, "{i}: {c:?}");
            assert!(
                (c.rc_a - ra * c.normal).length() < 1e-12
                    && (c.rc_b + rb * c.normal).length() < 1e-12
            );
        } else {
            // a sphere is its own bounding sphere: every gap is decided exactly there
            assert_eq!(c.status, ContactStatus::FarApart, "{i}: {c:?}");
        }
    }
}

#[test]
fn aligned_superballs_along_principal_axes() {
    let mut worst: f64 = 0.0;
    for &g in &[2.0, 2.5, 4.0, 8.0] {
        for &a in &[1.0, 0.3] {
            let s = Superquadric::superball(a, g);
            for axis in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Z] {
                for &delta in &[-0.4, -0.05, -1e-4, 0.0, 1e-4, 0.05, 0.3, 0.9] {
                    let dx = 2.0 * a - delta * a;
                    let xa = DVec3::new(0.3, -1.0, 2.0);
                    let opts = ContactOptions {
                        newton_band: f64::INFINITY, // polish every gap
                        ..ContactOptions::default()
                    };
                    let xb = xa + axis * dx;
                    let c = contact(
                        &s,
                        xa,
                        DQuat::IDENTITY,
                        &s,
                        xb,
                        DQuat::IDENTITY,
                        &opts,
                        None,
                    );
                    let want = 2.0 * a - dx;
                    if c.status == ContactStatus::FarApart {
                        let outside = dx >= 2.0 * s.bounding_radius() - 1e-12;
                        assert!(outside && c.overlap >= want - 1e-12, "{c:?}");
                        continue;
                    }
                    let err = (c.overlap - want).abs();
                    worst = worst.max(err / a);
                    assert_eq!(
                        c.status,
                        ContactStatus::Converged,
                        "g={g} {axis} {delta}: {c:?}"
                    );
                    assert!(
                        err < 1e-9 * a,
                        "g={g} a={a} {axis} delta={delta}: {} vs {want}",
                        c.overlap
                    );
                    assert!(
                        (c.normal - axis).length() < 1e-6,
                        "g={g} {axis} {delta}: {}",
                        c.normal
                    );
                }
            }
        }
    }
    eprintln!("aligned superballs: worst |overlap error| / a = {worst:.2e}");
}

/// Independent ellipsoid reference: overlap = min over unit u of |A_a u| + |A_b u| - d.u with
/// the closed-form ellipsoid support function |diag(a) R^T u| (dense grid + pattern search).
fn ellipsoid_reference(aa: DVec3, qa: DQuat, ab: DVec3, qb: DQuat, d: DVec3) -> (f64, DVec3) {
    let f = |u: DVec3| {
        (aa * (qa.conjugate() * u)).length() + (ab * (qb.conjugate() * u)).length() - d.dot(u)
    };
    let mut best = (f64::INFINITY, DVec3::X);
    for u in fibonacci(20_000) {
        let v = f(u);
        if v < best.0 {
            best = (v, u);
        }
    }
    let (mut fmin, mut u0) = best;
    let mut step = 0.03;
    while step > 1e-11 {
        let e1 = u0.any_orthonormal_vector();
        let e2 = u0.cross(e1);
        let mut moved = false;
        for e in [e1, -e1, e2, -e2] {
            let u = (u0 + step * e).normalize();
            let v = f(u);
            if v < fmin {
                (fmin, u0, moved) = (v, u, true);
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    (fmin, u0)
}

#[test]
fn ellipsoid_pairs_match_independent_minimisation() {
    let mut r = rng(13);
    let mut worst = (0.0f64, 0.0f64);
    for i in 0..150 {
        let aa = DVec3::new(
            0.5 + r.random::<f64>(),
            0.5 + r.random::<f64>(),
            0.5 + r.random::<f64>(),
        );
        let ab = DVec3::new(
            0.5 + r.random::<f64>(),
            0.5 + r.random::<f64>(),
            0.5 + r.random::<f64>(),
        );
        let (qa, qb) = (quat(&mut r), quat(&mut r));
        let u = unit(&mut r);
        let reach = (aa * (qa.conjugate() * u)).length() + (ab * (qb.conjugate() * u)).length();
        let d = u * reach * (0.6 + 0.6 * r.random::<f64>());
        let ea = Superquadric {
            semi_axes: aa,
            exponents: DVec3::splat(2.0),
        };
        let eb = Superquadric {
            semi_axes: ab,
            exponents: DVec3::splat(2.0),
        };
        let opts = ContactOptions {
            newton_band: f64::INFINITY,
            ..ContactOptions::default()
        };
        let xa = DVec3::new(1.0, 2.0, 3.0);
        let c = contact(&ea, xa, qa, &eb, xa + d, qb, &opts, None);
        let (want, n) = ellipsoid_reference(aa, qa, ab, qb, d);
        if c.status == ContactStatus::FarApart {
            assert!(c.overlap >= want && want < 0.0, "{i}: {c:?} vs {want}");
            continue;
        }
        assert_eq!(c.status, ContactStatus::Converged, "{i}");
        let (e_o, e_n) = ((c.overlap - want).abs(), c.normal.angle_between(n));
        worst = (worst.0.max(e_o), worst.1.max(e_n));
        assert!(e_o < 1e-9, "{i}: overlap {} vs reference {want}", c.overlap);
        assert!(e_n < 1e-6, "{i}: normal {} vs reference {n}", c.normal);
    }
    eprintln!(
        "ellipsoids vs reference: worst overlap error {:.2e}, normal angle {:.2e}",
        worst.0, worst.1
    );
}

#[test]
fn contact_is_symmetric() {
    let mut r = rng(17);
    for i in 0..500 {
        let a = Superquadric {
            semi_axes: DVec3::new(1.0, 0.5 + r.random::<f64>(), 0.5 + r.random::<f64>()),
            exponents: DVec3::splat(2.0 + 6.0 * r.random::<f64>()),
        };
        let b = Superquadric {
            semi_axes: DVec3::new(0.5 + r.random::<f64>(), 1.0, 1.5),
            exponents: DVec3::new(
                2.0 + 3.0 * r.random::<f64>(),
                3.0,
                2.0 + 8.0 * r.random::<f64>(),
            ),
        };
        let (qa, qb) = (quat(&mut r), quat(&mut r));
        let d = unit(&mut r) * (0.8 + 1.6 * r.random::<f64>());
        let xa = DVec3::new(-1.0, 0.5, 0.0);
        let ab = run(&a, xa, qa, &b, xa + d, qb);
        let ba = run(&b, xa + d, qb, &a, xa, qa);
        assert_eq!(ab.status, ba.status, "{i}");
        if ab.status != ContactStatus::Converged {
            continue;
        }
        assert!(
            (ab.overlap - ba.overlap).abs() < 1e-10,
            "{i}: {} vs {}",
            ab.overlap,
            ba.overlap
        );
        assert!(
            (ab.normal + ba.normal).length() < 1e-8,
            "{i}: {} vs {}",
            ab.normal,
            ba.normal
        );
        assert!((ab.rc_a - ba.rc_b).length() < 1e-6 && (ab.rc_b - ba.rc_a).length() < 1e-6);
    }
}

#[test]
fn degenerate_configurations_give_finite_answers() {
    let shapes = [
        Superquadric::superball(1.0, 2.0),
        Superquadric::superball(1.0, 10.0),
        Superquadric {
            semi_axes: DVec3::new(1.0, 3.0, 0.5),
            exponents: DVec3::new(2.0, 10.0, 4.0),
        },
        Superquadric::superball(0.2, 3.0),
    ];
    let mut r = rng(19);
    for a in &shapes {
        for b in &shapes {
            for k in 0..40 {
                let (qa, qb) = if k % 4 == 1 || k % 4 == 3 {
                    (quat(&mut r), quat(&mut r))
                } else {
                    (DQuat::IDENTITY, DQuat::IDENTITY)
                };
                let d = match k % 4 {
                    0 | 1 => DVec3::ZERO,                            // coincident centres
                    2 => DVec3::X * (a.semi_axes.x + b.semi_axes.x), // touching, aligned
                    _ => unit(&mut r) * 0.05, // deep: the small one inside the big one
                };
                let c = run(a, DVec3::ONE, qa, b, DVec3::ONE + d, qb);
                assert!(
                    c.overlap.is_finite() && c.normal.is_finite(),
                    "{a:?} {b:?} {k}: {c:?}"
                );
                assert!((c.normal.length() - 1.0).abs() < 1e-9, "{c:?}");
                assert!(c.rc_a.is_finite() && c.rc_b.is_finite());
                assert!(!c.is_fallback(), "{a:?} {b:?} {k}: {c:?}");
                if k % 4 == 2 {
                    assert!(c.overlap.abs() < 1e-9, "touching: {c:?}");
                } else {
                    assert!(c.overlap > 0.0);
                }
            }
        }
    }
    // coincident identical spheres: the overlap is the diameter in any direction
    let s = Superquadric::superball(1.0, 2.0);
    let c = run(
        &s,
        DVec3::ZERO,
        DQuat::IDENTITY,
        &s,
        DVec3::ZERO,
        DQuat::IDENTITY,
    );
    assert!((c.overlap - 2.0).abs() < 1e-12);
    // invalid input is flagged, not a panic
    let bad = Superquadric::superball(f64::NAN, 2.0);
    assert_eq!(
        run(
            &bad,
            DVec3::ZERO,
            DQuat::IDENTITY,
            &s,
            DVec3::X,
            DQuat::IDENTITY
        )
        .status,
        ContactStatus::InvalidInput
    );
    let c = run(
        &s,
        DVec3::splat(f64::INFINITY),
        DQuat::IDENTITY,
        &s,
        DVec3::X,
        DQuat::IDENTITY,
    );
    assert!(c.is_fallback());
    let c = run(
        &s,
        DVec3::ZERO,
        DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0),
        &s,
        DVec3::X,
        DQuat::IDENTITY,
    );
    assert!(c.is_fallback());
}

#[test]
fn warm_start_converges_in_few_iterations() {
    let mut r = rng(23);
    let mut total = 0u32;
    let mut n = 0u32;
    for _ in 0..300 {
        let a = Superquadric {
            semi_axes: DVec3::new(1.0, 0.8, 1.3),
            exponents: DVec3::splat(2.0 + 4.0 * r.random::<f64>()),
        };
        let b = Superquadric::superball(0.9, 2.0 + 6.0 * r.random::<f64>());
        let (qa, qb) = (quat(&mut r), quat(&mut r));
        let u = unit(&mut r);
        let d =
            u * (a.support_value(qa.conjugate() * u) + b.support_value(qb.conjugate() * u)) * 0.97;
        let first = run(&a, DVec3::ZERO, qa, &b, d, qb);
        if first.warm.is_none() {
            continue; // separated beyond the Newton band: nothing cached
        }
        // a small MCM-like move of b: 1e-3 translation and rotation
        let dq = DQuat::from_scaled_axis(unit(&mut r) * 1e-3);
        let (d2, qb2) = (d + unit(&mut r) * 1e-3, (dq * qb).normalize());
        let opts = ContactOptions {
            newton_band: f64::INFINITY,
            ..ContactOptions::default()
        };
        let cold = contact(&a, DVec3::ZERO, qa, &b, d2, qb2, &opts, None);
        let warm = contact(&a, DVec3::ZERO, qa, &b, d2, qb2, &opts, first.warm.as_ref());
        assert_eq!(warm.status, ContactStatus::Converged);
        assert!(
            (warm.overlap - cold.overlap).abs() < 1e-11,
            "{} vs {}",
            warm.overlap,
            cold.overlap
        );
        assert!(
            warm.iterations <= 4,
            "warm start took {} iterations: first {first:?} warm {warm:?}",
            warm.iterations
        );
        total += warm.iterations;
        n += 1;
    }
    eprintln!(
        "warm start: mean {:.2} Newton evaluations",
        total as f64 / n as f64
    );
}

#[test]
fn gjk_epa_alone_is_close_and_polish_is_better() {
    let a = Superquadric::superball(1.0, 4.0);
    let b = Superquadric {
        semi_axes: DVec3::new(1.0, 0.6, 1.4),
        exponents: DVec3::splat(3.0),
    };
    let (qa, qb) = (DQuat::from_rotation_y(0.3), DQuat::from_rotation_z(0.7));
    let d = DVec3::new(1.6, 0.4, 0.3);
    let exact = run(&a, DVec3::ZERO, qa, &b, d, qb);
    let opts = ContactOptions {
        polish: false,
        ..ContactOptions::default()
    };
    let rough = contact(&a, DVec3::ZERO, qa, &b, d, qb, &opts, None);
    let raw = gjk_epa_contact(&a, DVec3::ZERO, qa, &b, d, qb).unwrap();
    assert_eq!(exact.status, ContactStatus::Converged);
    assert_eq!(rough.status, ContactStatus::GjkEpa);
    assert!(
        rough.overlap >= exact.overlap - 1e-12,
        "support value is an upper bound"
    );
    assert!((rough.overlap - exact.overlap).abs() < 1e-4);
    assert!(
        (raw.overlap - exact.overlap).abs() < 1e-3 && raw.normal.angle_between(exact.normal) < 1e-2
    );
}

#[test]
fn results_scale_with_the_bodies_and_survive_extreme_exponents() {
    let mut r = rng(29);
    for i in 0..200 {
        let a = Superquadric {
            semi_axes: DVec3::new(1.0, 0.6 + r.random::<f64>(), 1.3),
            exponents: DVec3::splat(2.0 + 8.0 * r.random::<f64>()),
        };
        let b = Superquadric {
            semi_axes: DVec3::new(0.8, 1.0, 0.5 + r.random::<f64>()),
            exponents: DVec3::new(2.0, 3.0 + 5.0 * r.random::<f64>(), 4.0),
        };
        let (qa, qb) = (quat(&mut r), quat(&mut r));
        let u = unit(&mut r);
        let reach = a.support_value(qa.conjugate() * u) + b.support_value(qb.conjugate() * u);
        let d = u * reach * (0.9 + 0.12 * r.random::<f64>());
        let opts = ContactOptions {
            newton_band: f64::INFINITY,
            ..ContactOptions::default()
        };
        let one = contact(&a, DVec3::ZERO, qa, &b, d, qb, &opts, None);
        assert_eq!(one.status, ContactStatus::Converged, "{i}");
        // SI nanoparticles (1e-8 m) and large bodies (1e4): the same answer, scaled
        for scale in [1e-8, 1e4] {
            let sa = Superquadric {
                semi_axes: a.semi_axes * scale,
                ..a
            };
            let sb = Superquadric {
                semi_axes: b.semi_axes * scale,
                ..b
            };
            let x0 = DVec3::new(3.0, -1.0, 2.0) * scale;
            let c = contact(&sa, x0, qa, &sb, x0 + d * scale, qb, &opts, None);
            assert_eq!(c.status, ContactStatus::Converged, "{i} scale {scale}");
            assert!(
                (c.overlap / scale - one.overlap).abs() < 1e-10,
                "{i} {scale}: {c:?} vs {one:?}"
            );
            assert!(c.normal.angle_between(one.normal) < 1e-6, "{i} {scale}");
        }
    }
    // exponents at the ends of the accepted range, and barely above 2
    for g in [2.0 + 1e-9, 2.0001, 50.0, MAX_EXPONENT] {
        let s = Superquadric::superball(1.0, g);
        for k in 0..50 {
            let (qa, qb) = (quat(&mut r), quat(&mut r));
            let d = unit(&mut r) * (1.6 + 0.02 * k as f64);
            let c = contact(
                &s,
                DVec3::ZERO,
                qa,
                &s,
                d,
                qb,
                &ContactOptions::default(),
                None,
            );
            assert!(
                c.overlap.is_finite() && c.normal.is_finite() && !c.is_fallback(),
                "g={g}: {c:?}"
            );
        }
    }
}
