//! The prepared-shape contact ([`contact_prepared`]) against the reference [`contact`]: equal
//! bit for bit on random shapes, poses, options and warm starts, including invalid input.

use super::tests::{quat, rng, unit};
use super::*;
use glam::{DQuat, DVec3};
use rand::RngExt;

fn bits(r: &ContactResult) -> Vec<u64> {
    let mut v = vec![r.overlap.to_bits(), r.iterations as u64, r.status as u64];
    for x in [r.normal, r.rc_a, r.rc_b] {
        v.extend(x.to_array().map(f64::to_bits));
    }
    match r.warm {
        Some(w) => {
            v.extend(w.s_a.to_array().map(f64::to_bits));
            v.extend(w.s_b.to_array().map(f64::to_bits));
        }
        None => v.push(u64::MAX),
    }
    v
}

fn random_shape(r: &mut rand_xoshiro::Xoshiro256PlusPlus) -> Superquadric {
    let gs = [2.0, 2.5, 3.0, 4.0, 8.0];
    match r.random_range(0..4) {
        0 => Superquadric::superball(0.5, gs[r.random_range(0..gs.len())]),
        1 => Superquadric {
            semi_axes: DVec3::new(
                r.random_range(0.2..1.0),
                r.random_range(0.2..1.0),
                r.random_range(0.2..1.0),
            ),
            exponents: DVec3::splat(gs[r.random_range(0..gs.len())]),
        },
        2 => Superquadric {
            semi_axes: DVec3::new(0.5, 0.4, 0.7),
            exponents: DVec3::new(2.0, 3.0, 5.0),
        },
        _ => Superquadric::superball(0.5, 3.0),
    }
}

#[test]
fn prepared_contact_equals_reference_bitwise() {
    let mut r = rng(71);
    let options = [
        ContactOptions::default(),
        ContactOptions {
            gap_cutoff: 0.05,
            ..ContactOptions::default()
        },
        ContactOptions {
            polish: false,
            ..ContactOptions::default()
        },
        ContactOptions {
            gap_cutoff: f64::INFINITY,
            ..ContactOptions::default()
        },
    ];
    let mut statuses = std::collections::HashSet::new();
    let mut skipped_rejects = 0;
    for case in 0..3000 {
        let (a, b) = (random_shape(&mut r), random_shape(&mut r));
        let (pa, pb) = (PreparedShape::new(&a), PreparedShape::new(&b));
        let opts = options[case % options.len()];
        let reach = a.semi_axes.length() + b.semi_axes.length();
        let mut xb = unit(&mut r) * r.random_range(0.3..1.2) * reach;
        let (qa, mut qb) = (quat(&mut r), quat(&mut r));
        let mut warm: Option<WarmStart> = None;
        // a short trajectory: the warm start of each call is the last answer's
        for _ in 0..4 {
            let fast = contact_prepared(&pa, DVec3::ZERO, qa, &pb, xb, qb, &opts, warm.as_ref());
            let reference = contact(&a, DVec3::ZERO, qa, &b, xb, qb, &opts, warm.as_ref());
            assert_eq!(
                bits(&fast),
                bits(&reference),
                "case {case}: {fast:?} vs {reference:?}"
            );
            statuses.insert(fast.status);
            // without the centre-line reject: the same answer unless that reject ended the
            // call (then a gap beyond the cut-off either way)
            let within =
                contact_prepared_within(&pa, DVec3::ZERO, qa, &pb, xb, qb, &opts, warm.as_ref());
            if bits(&within) != bits(&fast) {
                // only where the centre-line reject ended the call: a gap beyond the cut-off
                // either way
                let l = a.semi_axes.min_element().min(b.semi_axes.min_element());
                let cutoff = opts.gap_cutoff.max(opts.newton_band * l);
                let rejected = opts.polish && cutoff.is_finite() && fast.iterations == 0;
                assert!(
                    rejected
                        && fast.status == ContactStatus::SeparatedGjk
                        && within.overlap < -cutoff + 1e-9 * reach,
                    "case {case}: {within:?} vs {fast:?}"
                );
                skipped_rejects += 1;
            }
            if fast.warm.is_some() {
                warm = fast.warm;
            }
            xb += 0.02 * unit(&mut r);
            qb = (DQuat::from_scaled_axis(0.02 * unit(&mut r)) * qb).normalize();
        }
    }
    // the cases reach every branch of the fast path's prefix and the solver behind it
    for st in [
        ContactStatus::Converged,
        ContactStatus::FarApart,
        ContactStatus::SeparatedGjk,
        ContactStatus::GjkEpa,
    ] {
        assert!(statuses.contains(&st), "{st:?} never reached: {statuses:?}");
    }
    assert!(skipped_rejects > 20, "{skipped_rejects}");
}

#[test]
fn prepared_contact_equals_reference_on_invalid_input() {
    let good = Superquadric::superball(0.5, 3.0);
    let bad = Superquadric::superball(0.5, 1.5);
    let o = ContactOptions::default();
    let x = DVec3::new(0.9, 0.0, 0.0);
    let poses = [
        (x, DQuat::IDENTITY),
        (DVec3::splat(f64::NAN), DQuat::IDENTITY),
        (x, DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0)),
        (x * 100.0, DQuat::IDENTITY),
        (DVec3::ZERO, DQuat::IDENTITY),
    ];
    for (a, b) in [(good, bad), (bad, good), (good, good)] {
        for &(xb, qb) in &poses {
            let fast = contact_prepared(
                &PreparedShape::new(&a),
                DVec3::ZERO,
                DQuat::IDENTITY,
                &PreparedShape::new(&b),
                xb,
                qb,
                &o,
                None,
            );
            let reference = contact(&a, DVec3::ZERO, DQuat::IDENTITY, &b, xb, qb, &o, None);
            assert_eq!(bits(&fast), bits(&reference), "{a:?} {b:?} {xb} {qb}");
        }
    }
}

/// The overlap bound against its reference, the converged solve: never below the solved
/// overlap (beyond round-off), on random shapes and poses with and without warm starts, and
/// tight (second order in the move) when the warm start is the last solution of a pair that
/// moved by an MCM-sized step.
#[test]
fn overlap_bound_is_above_the_solved_overlap_and_tight_after_small_moves() {
    let mut r = rng(72);
    let opts = ContactOptions::default();
    let (mut checked, mut tight) = (0, 0);
    for case in 0..3000 {
        let (a, b) = (random_shape(&mut r), random_shape(&mut r));
        let (pa, pb) = (PreparedShape::new(&a), PreparedShape::new(&b));
        let reach = a.semi_axes.length() + b.semi_axes.length();
        let mut xb = unit(&mut r) * r.random_range(0.3..1.2) * reach;
        let (qa, mut qb) = (quat(&mut r), quat(&mut r));
        let mut warm: Option<WarmStart> = None;
        for step in 0..4 {
            let c = contact(&a, DVec3::ZERO, qa, &b, xb, qb, &opts, None);
            let bound = overlap_upper_bound(&pa, DVec3::ZERO, qa, &pb, xb, qb, warm.as_ref());
            if c.status == ContactStatus::Converged {
                checked += 1;
                assert!(bound >= c.overlap - 1e-12, "case {case}: {bound} < {c:?}");
                if step > 0 && warm.is_some() && bound - c.overlap < 1e-8 {
                    tight += 1;
                }
            }
            let w = contact(&a, DVec3::ZERO, qa, &b, xb, qb, &opts, warm.as_ref()).warm;
            if w.is_some() {
                warm = w;
            }
            xb += 1e-5 * unit(&mut r);
            qb = (DQuat::from_scaled_axis(1e-5 * unit(&mut r)) * qb).normalize();
        }
    }
    assert!(checked > 2000 && tight > 1000, "{checked} {tight}");
    // no information for invalid input
    let bad = PreparedShape::new(&Superquadric::superball(0.5, 1.5));
    let good = PreparedShape::new(&Superquadric::superball(0.5, 3.0));
    let x = DVec3::new(0.9, 0.0, 0.0);
    let q = DQuat::IDENTITY;
    assert_eq!(
        overlap_upper_bound(&bad, DVec3::ZERO, q, &good, x, q, None),
        f64::INFINITY
    );
    let nan = DVec3::splat(f64::NAN);
    assert_eq!(
        overlap_upper_bound(&good, DVec3::ZERO, q, &good, nan, q, None),
        f64::INFINITY
    );
}
