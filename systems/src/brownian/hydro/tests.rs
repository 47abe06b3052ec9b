//! Tests of the hydrodynamic mobilities (RPY, Cholesky, TEA-HI, Krylov).

use super::*;
use glam::{DMat3, DVec3};
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::PI;

pub(super) const ETA: f64 = 1.0e-3;
pub(super) const A: f64 = 1.0e-7;

pub(super) fn mu0(a: f64) -> f64 {
    1.0 / (6.0 * PI * ETA * a)
}

fn max_abs_diff(a: DMat3, b: DMat3) -> f64 {
    (a - b)
        .to_cols_array()
        .iter()
        .fold(0.0, |m, x| m.max(x.abs()))
}

/// Thesis eq. 6.10 written out independently.
fn eq_6_10(r: DVec3, a: f64) -> DMat3 {
    let d = r.length();
    let rr = DMat3::from_cols(r * r.x, r * r.y, r * r.z) / (d * d);
    let (c1, c2) = if d > 2.0 * a {
        (
            0.75 * a / d + 0.5 * a.powi(3) / d.powi(3),
            0.75 * a / d - 1.5 * a.powi(3) / d.powi(3),
        )
    } else {
        (1.0 - 9.0 * d / (32.0 * a), 3.0 * d / (32.0 * a))
    };
    (DMat3::IDENTITY * c1 + rr * c2) * mu0(a)
}

/// `n` equal spheres of radius `a` \[m\] placed at random (overlaps allowed) in a cube sized
/// for a volume fraction of 1 %, as the timing and profile probes use them: positions, radii.
pub(super) fn dilute_suspension(
    rng: &mut Xoshiro256PlusPlus,
    n: usize,
    a: f64,
) -> (Vec<DVec3>, Vec<f64>) {
    let edge = a * (n as f64 * 4.0 / 3.0 * std::f64::consts::PI / 0.01).cbrt();
    let (pos, _) = random_config(rng, n, edge, false);
    (pos, vec![a; n])
}

pub(super) fn random_config(
    rng: &mut Xoshiro256PlusPlus,
    n: usize,
    box_len: f64,
    poly: bool,
) -> (Vec<DVec3>, Vec<f64>) {
    let pos = (0..n)
        .map(|_| {
            DVec3::new(
                rng.random_range(0.0..box_len),
                rng.random_range(0.0..box_len),
                rng.random_range(0.0..box_len),
            )
        })
        .collect();
    let radii = (0..n)
        .map(|_| {
            if poly {
                A * rng.random_range(0.5..1.5)
            } else {
                A
            }
        })
        .collect();
    (pos, radii)
}

pub(super) fn normals(rng: &mut Xoshiro256PlusPlus, n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|_| {
            DVec3::new(
                StandardNormal.sample(rng),
                StandardNormal.sample(rng),
                StandardNormal.sample(rng),
            )
        })
        .collect()
}

#[test]
fn rpy_continuous_at_regime_boundaries() {
    // relative step 1e-13 across each boundary; slopes are O(1/a), so jumps must be < 1e-12
    let dir = DVec3::new(0.3, -0.5, 0.8).normalize();
    for &(ai, aj) in &[(1.0, 1.0), (1.0, 2.0), (0.7, 1.9), (1.5, 0.2)] {
        let (ai, aj) = (ai * A, aj * A);
        let scale = mu0(ai.min(aj));
        let mut boundaries = vec![ai + aj];
        if (ai - aj).abs() > 0.0 {
            boundaries.push((ai - aj).abs());
        }
        for b in boundaries {
            let inside = rpy_block(dir * b, ai, aj, ETA);
            let outside = rpy_block(dir * (b * (1.0 + 1e-13)), ai, aj, ETA);
            let jump = max_abs_diff(inside, outside) / scale;
            assert!(
                jump < 1e-12,
                "jump {jump:e} at r = {b:e} for a = ({ai:e}, {aj:e})"
            );
        }
    }
    // r = 0, equal radii: the fully-overlapping limit I/(6πηa) without NaN
    let m = rpy_block(DVec3::ZERO, A, A, ETA);
    assert!(max_abs_diff(m, DMat3::IDENTITY * mu0(A)) < 1e-15 * mu0(A));
}

#[test]
fn rpy_monodisperse_limit_is_thesis_eq_6_10() {
    let dir = DVec3::new(1.0, 2.0, -2.0).normalize();
    for k in 1..=60 {
        let r = dir * (A * 0.1 * f64::from(k)); // 0.1a … 6a, both branches
        let got = rpy_block(r, A, A, ETA);
        let want = eq_6_10(r, A);
        assert!(
            max_abs_diff(got, want) < 1e-13 * mu0(A),
            "r = {}",
            r.length() / A
        );
        // symmetric block
        assert!(max_abs_diff(got, got.transpose()) == 0.0);
    }
}

#[test]
fn rpy_far_field_is_oseen() {
    let dir = DVec3::new(0.0, 0.6, 0.8);
    let mut prev = f64::INFINITY;
    for &x in &[1e2, 1e3, 1e4] {
        let r = dir * (x * A);
        let d = r.length();
        let oseen = (DMat3::IDENTITY + DMat3::from_cols(dir * dir.x, dir * dir.y, dir * dir.z))
            * (1.0 / (8.0 * PI * ETA * d));
        let rel =
            max_abs_diff(rpy_block(r, 0.6 * A, 1.3 * A, ETA), oseen) / (1.0 / (8.0 * PI * ETA * d));
        // correction is (a_i²+a_j²)/r² relative
        assert!(rel < 2.1 / (x * x), "x = {x}: {rel:e}");
        assert!(rel < prev);
        prev = rel;
    }
}

#[test]
fn rpy_matrix_spd_for_overlapping_polydisperse_configs() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let mut min_ratio = f64::INFINITY;
    for _ in 0..30 {
        // 20 particles in a (3a)³ box: nearly all pairs overlap, many fully
        let (pos, radii) = random_config(&mut rng, 20, 3.0 * A, true);
        let m = rpy_matrix(&pos, &radii, ETA);
        for r in 0..60 {
            for c in 0..60 {
                assert_eq!(m[(r, c)], m[(c, r)], "not exactly symmetric");
            }
        }
        assert!(m.llt(faer::Side::Lower).is_ok());
        let ev = m.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        let lmin = ev.iter().copied().fold(f64::INFINITY, f64::min);
        min_ratio = min_ratio.min(lmin / mu0(A));
        assert!(lmin > 0.0, "smallest eigenvalue {lmin:e}");
    }
    // measured: smallest eigenvalue ≈ 1e-3 μ0 over the 30 sets (printed with --nocapture)
    println!("min eigenvalue / mu0 = {min_ratio:e}");
}

#[test]
fn two_sphere_settling_matches_closed_forms() {
    for &x in &[2.0, 2.5, 4.0, 10.0] {
        let r = x * A;
        let pos = [DVec3::ZERO, DVec3::new(r, 0.0, 0.0)];
        let mob = Mobility::new(MobilityMethod::Cholesky, &pos, &[A; 2], ETA, 1e-6).unwrap();
        let f = 1e-14;
        let mut v = [DVec3::ZERO; 2];
        mob.apply(&[DVec3::new(f, 0.0, 0.0); 2], &mut v);
        let par = f * mu0(A) * (1.0 + 1.5 / x - 1.0 / x.powi(3));
        assert!((v[0].x - par).abs() < 1e-13 * par && (v[1].x - par).abs() < 1e-13 * par);
        mob.apply(&[DVec3::new(0.0, 0.0, f); 2], &mut v);
        let perp = f * mu0(A) * (1.0 + 0.75 / x + 0.5 / x.powi(3));
        assert!((v[0].z - perp).abs() < 1e-13 * perp && (v[1].z - perp).abs() < 1e-13 * perp);
        assert!(v[0].x.abs() < 1e-30 && v[0].y.abs() < 1e-30);
    }
}
