//! Groundwork for positively split Ewald noise ([`super::ewald`], "Towards PSE"): the
//! spectral Ewald operator's two parts add up to the dense RPY matrix and, for equal radii and
//! ξa ≤ 0.3, are both positive semidefinite.

use super::ewald::SpectralEwald;
use super::tests::{A, ETA, random_config};
use super::*;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// Dense 3N×3N matrix of a linear map given by its product.
fn dense_of(n3: usize, apply: impl Fn(&[f64], &mut [f64])) -> faer::Mat<f64> {
    let mut m = faer::Mat::<f64>::zeros(n3, n3);
    let (mut e, mut col) = (vec![0.0; n3], vec![0.0; n3]);
    for k in 0..n3 {
        e.fill(0.0);
        e[k] = 1.0;
        col.fill(0.0);
        apply(&e, &mut col);
        for (r, v) in col.iter().enumerate() {
            m[(r, k)] = *v;
        }
    }
    m
}

/// Smallest eigenvalue of a symmetric matrix in units of the self mobility 1/(6πηa).
fn min_eigenvalue(m: &faer::Mat<f64>) -> f64 {
    let scale = 1.0 / (6.0 * std::f64::consts::PI * ETA * A);
    let ev = m.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
    ev.iter().fold(f64::INFINITY, |a, b| a.min(*b)) / scale
}

/// μ_real + μ_wave = μ_RPY (to the Ewald tolerance); at ξa = 0.29 both parts are symmetric
/// positive semidefinite, at ξa = 1.5 > √3/2 the wave part is not (the split PSE needs
/// exists only for small ξa).
#[test]
fn split_parts_add_up_to_dense_rpy_and_are_positive_for_small_xi_a() {
    let n = 30;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    // a compact cluster of equal spheres (box 8a, overlaps allowed): the pair part at
    // ξa = 1.6 then has a clearly negative eigenvalue
    let (pos, _) = random_config(&mut rng, n, 8.0 * A, false);
    let radii = vec![A; n];
    let exact = rpy::DenseSym::rpy(&pos, &radii, ETA).to_faer();
    for (cutoff, positive) in [(10.5 * A, true), (2.0 * A, false)] {
        let op = SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-3, Some(cutoff)).unwrap();
        let s = op.summary();
        assert!(s.grid > 0, "{s:?}");
        assert_eq!(s.xi * A <= 0.3, positive, "{s:?}");
        let real = dense_of(3 * n, |x, o| op.apply_real(x, o));
        let wave = dense_of(3 * n, |x, o| op.wave().unwrap().apply_add(x, o));
        let err = (&real + &wave - &exact).norm_l2() / exact.norm_l2();
        assert!(err < 1e-3, "{err}");
        for (name, m) in [("real", &real), ("wave", &wave)] {
            let sym = (m - m.transpose()).norm_l2() / m.norm_l2();
            assert!(sym < 1e-12, "{name} not symmetric: {sym}");
        }
        let (min_real, min_wave) = (min_eigenvalue(&real), min_eigenvalue(&wave));
        eprintln!(
            "xi a = {}: smallest eigenvalues real {min_real:e}, wave {min_wave:e}",
            s.xi * A
        );
        if positive {
            assert!(min_real > -1e-6, "real: {min_real}");
            assert!(min_wave > -1e-6, "wave: {min_wave}");
        } else {
            assert!(min_wave < -1e-3, "wave: {min_wave}");
        }
    }
}
