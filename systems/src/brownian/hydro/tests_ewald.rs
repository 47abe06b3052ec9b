//! Tests of the matrix-free spectral Ewald RPY product ([`super::ewald`]).

use super::ewald::SpectralEwald;
use super::ewald::kernels::{
    SERIES_BELOW, far_rpy, real_laplacian, real_rpy, real_stokeslet, smoothed_laplacian,
    smoothed_stokeslet, wave_stokeslet,
};
use super::tests::{A, ETA, dilute_suspension, normals, random_config};
use super::*;
use glam::DVec3;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn flat(v: &[DVec3]) -> Vec<f64> {
    v.iter().flat_map(|p| [p.x, p.y, p.z]).collect()
}

fn dense_product(pos: &[DVec3], radii: &[f64], f: &[f64]) -> Vec<f64> {
    let m = rpy::DenseSym::rpy(pos, radii, ETA);
    let mut out = vec![0.0; f.len()];
    m.matvec(f, &mut out);
    out
}

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let den: f64 = b.iter().map(|y| y * y).sum();
    (num / den).sqrt()
}

fn ewald_error(pos: &[DVec3], radii: &[f64], tol: f64, cutoff: Option<f64>, seed: u64) -> f64 {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let f = flat(&normals(&mut rng, pos.len()));
    let op = SpectralEwald::with_cutoff(pos, radii, ETA, tol, cutoff).unwrap();
    let mut v = vec![0.0; f.len()];
    op.apply(&f, &mut v);
    rel_err(&v, &dense_product(pos, radii, &f))
}

#[test]
fn product_matches_dense_rpy_to_tolerance() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    // dense-ish polydisperse box with overlaps: 200 particles in a 12a box
    let (pos, radii) = random_config(&mut rng, 200, 12.0 * A, true);
    let overlaps = (0..200)
        .flat_map(|i| (0..i).map(move |j| (i, j)))
        .filter(|&(i, j)| (pos[i] - pos[j]).length() < radii[i] + radii[j])
        .count();
    assert!(overlaps > 10, "{overlaps}");
    let mut last = f64::INFINITY;
    for tol in [1e-2, 1e-4, 1e-6, 1e-8] {
        for rc in [3.0 * A, 5.0 * A] {
            let e = ewald_error(&pos, &radii, tol, Some(rc), 1);
            eprintln!("tol {tol:e} rc {rc:e}: {e:e}");
            assert!(e <= tol, "tol {tol}: error {e}");
        }
        let e = ewald_error(&pos, &radii, tol, Some(4.0 * A), 2);
        assert!(e < last, "error must fall with the tolerance");
        last = e;
    }
}

#[test]
fn fast_spreading_and_gathering_match_the_reference_loops() {
    // the vectorised spreading/gathering against the plain loops, equal and unequal radii
    // (3 and 6 grid fields), on the same prepared grid
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(29);
    for poly in [false, true] {
        let (pos, radii) = random_config(&mut rng, 150, 12.0 * A, poly);
        let f = flat(&normals(&mut rng, pos.len()));
        let op = SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-6, Some(3.0 * A)).unwrap();
        let wave = op.wave().unwrap();
        let mut fast = vec![0.0; f.len()];
        wave.apply_add(&f, &mut fast);
        let reference = wave.apply_reference(&f);
        let e = rel_err(&fast, &reference);
        eprintln!("polydisperse {poly}: fast vs reference {e:e}");
        assert!(e < 1e-13, "polydisperse {poly}: {e}");
        assert!(reference.iter().any(|v| *v != 0.0));
        // every vector level this processor has gives bitwise the same velocities
        use super::ewald::simd::Simd;
        for simd in [Simd::Plain, Simd::Avx2, Simd::Avx512] {
            if simd == Simd::Plain || Simd::detect() == simd || Simd::detect() == Simd::Avx512 {
                let mut v = vec![0.0; f.len()];
                wave.apply_add_with(&f, &mut v, simd);
                assert_eq!(v, fast, "{simd:?}");
            }
        }
    }
}

fn apply(op: &SpectralEwald, f: &[f64]) -> Vec<f64> {
    let mut v = vec![0.0; f.len()];
    op.apply(f, &mut v);
    v
}

#[test]
fn streamed_direct_product_matches_dense_rpy() {
    use super::ewald::direct::Direct;
    // polydisperse, with overlaps, coincident centres and N not a multiple of the lane count
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
    for (n, edge) in [(1, 4.0), (2, 4.0), (7, 4.0), (203, 12.0), (402, 40.0)] {
        let (mut pos, radii) = random_config(&mut rng, n, edge * A, true);
        if n > 3 {
            pos[3] = pos[1];
        }
        let f = flat(&normals(&mut rng, n));
        let exact = dense_product(&pos, &radii, &f);
        let op = Direct::new(&pos, &radii, ETA);
        let mut v = vec![0.0; f.len()];
        op.apply_with(&f, &mut v, false);
        let e = rel_err(&v, &exact);
        assert!(e < 1e-13, "N = {n}: error {e}");
        if n > 100 {
            assert!(op.pairs() > 0, "N = {n}: no overlaps tested");
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut w = vec![0.0; f.len()];
            op.apply_with(&f, &mut w, true);
            assert_eq!(v, w, "AVX2 and SSE2 paths differ");
        }
    }
}

#[test]
fn streamed_direct_noise_covariance_at_the_benchmark_tolerances() {
    // the step_timing settings (product 1e-4, Krylov 1e-3) at φ ≈ 0.01, polydisperse: the
    // cost model picks the streamed direct sum; its Lanczos covariance against the dense
    // Cholesky one (exact to rounding)
    let n = 120;
    let edge = A * (n as f64 * 4.19 / 0.01).cbrt();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(23);
    let (pos, radii) = random_config(&mut rng, n, edge, true);
    let exact = rpy_matrix(&pos, &radii, ETA);
    let opts = MobilityOptions {
        krylov_tolerance: 1e-3,
        ewald_tolerance: 1e-4,
        ..MobilityOptions::default()
    };
    let mob = Mobility::new_with(MobilityMethod::SpectralEwald, &pos, &radii, ETA, opts).unwrap();
    assert_eq!(mob.ewald_summary().unwrap().grid, 0, "direct sum expected");
    let chol = Mobility::new_with(MobilityMethod::Cholesky, &pos, &radii, ETA, opts).unwrap();
    let e_chol = covariance_error(&chol, &exact).unwrap();
    let e = covariance_error(&mob, &exact).unwrap();
    eprintln!("covariance error: streamed direct + Lanczos {e:e}, Cholesky {e_chol:e}");
    assert!(e_chol < 1e-12, "{e_chol}");
    assert!(e < 2e-3, "{e}");
}

#[test]
fn kernel_split_adds_up_to_the_exact_kernels() {
    let xi = 2.0e6;
    for r in [1e-8, 1e-7, 3e-7, 1e-6, 2e-6] {
        // Stokeslet: real + wave = I/r + r̂r̂/r; Laplacian: real + smoothed = 2(I − 3r̂r̂)/r³
        let (ra, rb) = real_stokeslet(r, xi);
        let (wa, wb) = wave_stokeslet(r, xi, xi);
        assert!(((ra + wa) * r - 1.0).abs() < 1e-12, "{r}");
        assert!(((rb + wb) * r - 1.0).abs() < 1e-12, "{r}");
        let (la, lb) = real_laplacian(r, xi);
        let (ga, gb) = smoothed_laplacian(r, xi);
        let r3 = r * r * r;
        assert!(((la + ga) * r3 - 2.0).abs() < 1e-10, "{r}");
        assert!(((lb + gb) * r3 + 6.0).abs() < 1e-10, "{r}");
        // the fused real-space RPY remainder
        let s = 2.5e-14;
        let (pa, pb) = real_rpy(r, xi, s);
        assert!((pa - (ra + s / 6.0 * la)).abs() <= 1e-12 * pa.abs().max(1.0 / r));
        assert!((pb - (rb + s / 6.0 * lb)).abs() <= 1e-12 * pb.abs().max(1.0 / r));
        // far-field RPY = S + s/6 L
        let (fa, fb) = far_rpy(r, s);
        assert!((fa - (1.0 / r + s / 6.0 * 2.0 / r3)).abs() < 1e-12 * fa);
        assert!((fb - (1.0 / r - s / r3)).abs() < 1e-12 * fa);
    }
    // ξ = 0: the real-space parts are the full kernels
    assert_eq!(real_stokeslet(2.0, 0.0), (0.5, 0.5));
    assert_eq!(real_laplacian(2.0, 0.0), (0.25, -0.75));
}

#[test]
fn smoothed_kernel_series_join_the_closed_forms() {
    let alpha = 1.0e6;
    let r = SERIES_BELOW / alpha;
    for f in [smoothed_stokeslet, smoothed_laplacian] {
        let (a0, b0) = f(r * (1.0 - 1e-9), alpha);
        let (a1, b1) = f(r * (1.0 + 1e-9), alpha);
        let scale = a0.abs();
        assert!((a0 - a1).abs() < 1e-9 * scale, "{a0} {a1}");
        assert!((b0 - b1).abs() < 1e-9 * scale, "{b0} {b1}");
    }
    // values at the origin: S∗G(0) = 8α/(3√π) I, L∗G(0) = −16α³/(3√π) I
    let sp = std::f64::consts::PI.sqrt();
    assert!((smoothed_stokeslet(0.0, alpha).0 - 8.0 * alpha / (3.0 * sp)).abs() < 1e-9 * alpha);
    let l0 = smoothed_laplacian(0.0, alpha).0;
    assert!((l0 + 16.0 * alpha.powi(3) / (3.0 * sp)).abs() < 1e-9 * l0.abs());
}

#[test]
fn dilute_cluster_and_small_systems_match_dense() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    // a dilute cluster: 60 particles spread over 24 radii, plus a dense group 30 radii away
    let (mut pos, mut radii) = random_config(&mut rng, 60, 16.0 * A, true);
    let (p2, r2) = random_config(&mut rng, 10, 4.0 * A, true);
    pos.extend(p2.iter().map(|p| *p + DVec3::splat(20.0 * A)));
    radii.extend(r2);
    for tol in [1e-3, 1e-6] {
        let e = ewald_error(&pos, &radii, tol, Some(8.0 * A), 4);
        assert!(e <= tol, "cluster tol {tol}: {e}");
    }
    // N = 1: the self mobility exactly (grid and direct)
    let one = [DVec3::new(1e-7, -2e-7, 3e-7)];
    let f = [1e-15, 2e-15, -3e-15];
    let mu = 1.0 / (6.0 * std::f64::consts::PI * ETA * A);
    for cutoff in [None, Some(3.0 * A)] {
        let op = SpectralEwald::with_cutoff(&one, &[A], ETA, 1e-8, cutoff).unwrap();
        let v = apply(&op, &f);
        for k in 0..3 {
            assert!(
                (v[k] - mu * f[k]).abs() <= 1e-8 * mu * 3e-15,
                "{cutoff:?} {v:?}"
            );
        }
    }
    // N = 2: overlapping, touching and separated pairs against the exact blocks
    for d in [0.3 * A, 1.7 * A, 2.0 * A, 3.0 * A, 9.0 * A] {
        let pos = [DVec3::ZERO, DVec3::new(d, 0.4 * d, -0.2 * d)];
        let radii = [A, 0.7 * A];
        let direct = ewald_error(&pos, &radii, 1e-6, None, 5);
        assert!(direct < 1e-14, "direct d = {d}: {direct}");
        let grid = ewald_error(&pos, &radii, 1e-8, Some(3.0 * A), 5);
        assert!(grid < 1e-8, "grid d = {d}: {grid}");
    }
}

#[test]
fn free_space_no_images_and_translation_invariance() {
    // two particles 40 radii apart: far-field RPY (a periodic sum would add images)
    let d = DVec3::new(40.0 * A, 0.0, 0.0);
    let pos = [DVec3::ZERO, d];
    let radii = [A, 1.3 * A];
    let op = SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-8, Some(6.0 * A)).unwrap();
    assert!(op.summary().grid > 0 && op.summary().cutoff < d.length());
    let v = apply(&op, &[0.0, 0.0, 0.0, 1e-15, 0.0, 0.0]);
    let r = d.length();
    let s = A * A + (1.3 * A) * (1.3 * A);
    let pre = 1.0 / (8.0 * std::f64::consts::PI * ETA);
    let expect = pre / r * (2.0 - 2.0 * s / (3.0 * r * r)) * 1e-15; // iso + dyad, parallel
    assert!(
        (v[0] - expect).abs() < 1e-7 * expect,
        "{} vs {expect}",
        v[0]
    );
    assert!(v[1].abs() < 1e-9 * expect && v[2].abs() < 1e-9 * expect);
    // translating everything by a non-grid-aligned vector changes nothing but rounding
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(8);
    let (pos, radii) = random_config(&mut rng, 120, 20.0 * A, true);
    let f = flat(&normals(&mut rng, 120));
    let shift = DVec3::new(1.234_567e-5, -7.654_321e-6, 3.3e-6);
    let moved: Vec<DVec3> = pos.iter().map(|p| *p + shift).collect();
    let a = apply(
        &SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-6, Some(4.0 * A)).unwrap(),
        &f,
    );
    let b = apply(
        &SpectralEwald::with_cutoff(&moved, &radii, ETA, 1e-6, Some(4.0 * A)).unwrap(),
        &f,
    );
    let e = rel_err(&a, &b);
    assert!(e < 1e-6, "{e}");
}

#[test]
fn product_is_symmetric_and_noise_covariance_matches() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
    let (pos, radii) = random_config(&mut rng, 12, 5.0 * A, true);
    let op = SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-6, Some(3.0 * A)).unwrap();
    assert!(op.summary().grid > 0);
    let x = flat(&normals(&mut rng, 12));
    let y = flat(&normals(&mut rng, 12));
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
    let (mx, my) = (apply(&op, &x), apply(&op, &y));
    let asym = (dot(&x, &my) - dot(&mx, &y)).abs() / dot(&x, &mx).abs();
    assert!(asym < 1e-7, "{asym}");
    // Lanczos columns over the matrix-free product: B Bᵀ against the dense RPY mobility
    let n3 = 36;
    let exact = rpy_matrix(&pos, &radii, ETA);
    let mut b = faer::Mat::<f64>::zeros(n3, n3);
    for k in 0..n3 {
        let mut e = vec![0.0; n3];
        e[k] = 1.0;
        let res = krylov::lanczos_sqrt(|u, o| op.apply(u, o), &e, 1e-7, 200).unwrap();
        for r in 0..n3 {
            b[(r, k)] = res.y[r];
        }
    }
    let bbt = &b * b.transpose();
    let cov = (&bbt - &exact).norm_l2() / exact.norm_l2();
    assert!(cov < 1e-5, "covariance error {cov}");
    // and through Mobility (the cost model's choice) with covariance_error
    let opts = MobilityOptions {
        krylov_tolerance: 1e-8,
        ewald_tolerance: 1e-8,
        ..MobilityOptions::default()
    };
    let mob = Mobility::new_with(MobilityMethod::SpectralEwald, &pos, &radii, ETA, opts).unwrap();
    assert!(covariance_error(&mob, &exact).unwrap() < 1e-6);
}

#[test]
fn bitwise_identical_for_one_and_two_threads() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
    let (pos, radii) = random_config(&mut rng, 300, 30.0 * A, true);
    let f = flat(&normals(&mut rng, 300));
    let w = normals(&mut rng, 300);
    let run = || {
        let a = apply(
            &SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-5, Some(5.0 * A)).unwrap(),
            &f,
        );
        let mob = Mobility::new(MobilityMethod::SpectralEwald, &pos, &radii, ETA, 1e-4).unwrap();
        let mut y = vec![DVec3::ZERO; 300];
        mob.noise(&w, &mut y).unwrap();
        (a, y)
    };
    let results: Vec<_> = [1, 2]
        .iter()
        .map(|&k| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(k)
                .build()
                .unwrap()
                .install(run)
        })
        .collect();
    assert_eq!(results[0], results[1]);
}

#[test]
fn bad_input_is_an_error() {
    let pos = [DVec3::ZERO, DVec3::X * 3e-7];
    let radii = [A, A];
    for tol in [0.0, -1e-6, f64::NAN, f64::INFINITY, 0.5, 1e-13] {
        let opts = MobilityOptions {
            ewald_tolerance: tol,
            ..MobilityOptions::default()
        };
        assert!(matches!(
            Mobility::new_with(MobilityMethod::SpectralEwald, &pos, &radii, ETA, opts),
            Err(HydroError::InvalidInput(_))
        ));
    }
    let bad = [DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0)];
    assert!(Mobility::new(MobilityMethod::SpectralEwald, &bad, &radii, ETA, 1e-6).is_err());
    assert!(Mobility::new(MobilityMethod::SpectralEwald, &pos, &[A, 0.0], ETA, 1e-6).is_err());
    // empty system
    let mob = Mobility::new(MobilityMethod::SpectralEwald, &[], &[], ETA, 1e-6).unwrap();
    mob.apply(&[], &mut []);
    assert_eq!(
        serde_json::to_string(&MobilityMethod::SpectralEwald).unwrap(),
        "\"spectral_ewald\""
    );
}

/// Direct O(N²) RPY product without storing the matrix.
fn streamed_product(pos: &[DVec3], radii: &[f64], f: &[f64]) -> Vec<f64> {
    use rayon::prelude::*;
    let mut out = vec![0.0; f.len()];
    out.par_chunks_mut(3).enumerate().for_each(|(i, o)| {
        let mut acc =
            DVec3::new(f[3 * i], f[3 * i + 1], f[3 * i + 2]) * rpy::self_mobility(radii[i], ETA);
        for j in (0..pos.len()).filter(|&j| j != i) {
            let fj = DVec3::new(f[3 * j], f[3 * j + 1], f[3 * j + 2]);
            acc += rpy_block(pos[i] - pos[j], radii[i], radii[j], ETA) * fj;
        }
        o.copy_from_slice(&[acc.x, acc.y, acc.z]);
    });
    out
}

#[test]
#[ignore = "release tier: N = 10^4 against a streamed direct sum (~10 s)"]
fn large_n_product_matches_direct_sum() {
    let n = 10_000;
    let a = 75e-9;
    let edge = a * (n as f64 * 4.19 / 0.01).cbrt();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(21);
    let pos: Vec<DVec3> = random_config(&mut rng, n, edge, false).0;
    let radii: Vec<f64> = (0..n)
        .map(|i| a * (0.8 + 0.4 * (i % 7) as f64 / 6.0))
        .collect();
    let f = flat(&normals(&mut rng, n));
    let exact = streamed_product(&pos, &radii, &f);
    for tol in [1e-3, 1e-6] {
        let op = SpectralEwald::new(&pos, &radii, ETA, tol).unwrap();
        let e = rel_err(&apply(&op, &f), &exact);
        eprintln!("N = {n}, tol {tol:e}: {:?}, error {e:e}", op.summary());
        assert!(e <= tol, "{e}");
    }
}

#[test]
#[ignore = "timing probe: cargo test --release -p magsep-systems --lib step_timing -- --ignored --nocapture"]
fn step_timing() {
    use std::time::Instant;
    let a = 75e-9;
    let cases: &[(MobilityMethod, usize)] = &[
        (MobilityMethod::SpectralEwald, 1000),
        (MobilityMethod::SpectralEwald, 10_000),
        (MobilityMethod::Krylov, 1000),
        (MobilityMethod::Tea, 1000),
        (MobilityMethod::Cholesky, 1000),
    ];
    for &(method, n) in cases {
        let (pos, radii, w, f, opts) = step_inputs(n, a);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut best = f64::INFINITY;
                let mut line = String::new();
                for _ in 0..2 {
                    let t = Instant::now();
                    let mob = Mobility::new_with(method, &pos, &radii, ETA, opts).unwrap();
                    let tp = t.elapsed().as_secs_f64();
                    let mut y = vec![DVec3::ZERO; n];
                    mob.noise(&w, &mut y).unwrap();
                    let tn = t.elapsed().as_secs_f64() - tp;
                    mob.apply(&f, &mut y);
                    let total = t.elapsed().as_secs_f64();
                    if total < best {
                        best = total;
                        line = format!(
                            "{method:?} N {n} threads {threads}: prepare {tp:.4} s noise {tn:.4} s total {total:.4} s = {:.2} steps/s, krylov its {}, {:?}",
                            1.0 / total,
                            mob.krylov_iterations(),
                            mob.ewald_summary()
                        );
                    }
                }
                eprintln!("{line}");
            });
        }
    }
}

#[test]
#[ignore = "timing probe: cargo test --release -p magsep-systems --lib direct_product_timing -- --ignored --nocapture"]
fn direct_product_timing() {
    use super::ewald::direct::Direct;
    use super::ewald::near::Near;
    use super::ewald::params::Params;
    use std::time::Instant;
    // N = 1000 at φ = 0.01: stored pair blocks (Near with ξ = 0) against the streamed product,
    // each prepared once and applied 14 times (one step), interleaved 5 times
    let (n, a) = (1000, 75e-9);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let f = flat(&normals(&mut rng, n));
    let params = Params::with_cutoff(1e-4, None, &pos, &radii);
    let mut v = vec![0.0; 3 * n];
    let (mut ts, mut td) = (Vec::new(), Vec::new());
    for _ in 0..5 {
        let t = Instant::now();
        let near = Near::new(&params, &pos, &radii, ETA);
        for _ in 0..14 {
            near.apply(&f, &mut v);
        }
        ts.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let direct = Direct::new(&pos, &radii, ETA);
        for _ in 0..14 {
            direct.apply(&f, &mut v);
        }
        td.push(t.elapsed().as_secs_f64());
    }
    ts.sort_by(f64::total_cmp);
    td.sort_by(f64::total_cmp);
    eprintln!(
        "N {n}, 14 products, threads {}: stored {:.4} s, streamed {:.4} s (medians), ratio {:.2}",
        rayon::current_num_threads(),
        ts[2],
        td[2],
        ts[2] / td[2]
    );
}

#[test]
#[ignore = "profile probe (callgrind): N = 10^4 spectral Ewald, prepare + 2 products"]
fn ewald_product_profile() {
    let (n, a) = (10_000, 75e-9);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let f = flat(&normals(&mut rng, n));
    let op = SpectralEwald::new(&pos, &radii, ETA, 1e-4).unwrap();
    let mut v = vec![0.0; 3 * n];
    for _ in 0..2 {
        op.apply(&f, &mut v);
    }
    eprintln!("{:?} {}", op.summary(), v[0]);
}

/// The timing and profile probes' BD step inputs (seed 7): a 1 % suspension of `n` spheres
/// of radius `a` [m], unit normal noise, forces of 1e-14 N scale and the tolerances.
fn step_inputs(n: usize, a: f64) -> StepInputs {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let w = normals(&mut rng, n);
    let f: Vec<DVec3> = normals(&mut rng, n).iter().map(|v| *v * 1e-14).collect();
    let opts = MobilityOptions {
        krylov_tolerance: 1e-3,
        ewald_tolerance: 1e-4,
        ..MobilityOptions::default()
    };
    (pos, radii, w, f, opts)
}

/// Positions, radii, noise, forces and options of [`step_inputs`].
type StepInputs = (
    Vec<DVec3>,
    Vec<f64>,
    Vec<DVec3>,
    Vec<DVec3>,
    MobilityOptions,
);

/// One BD step of the N = 10⁴ benchmark (prepare with the kernel cached, noise, drift).
fn one_step(pos: &[DVec3], radii: &[f64], w: &[DVec3], f: &[DVec3], opts: MobilityOptions) {
    let mob = Mobility::new_with(MobilityMethod::SpectralEwald, pos, radii, ETA, opts).unwrap();
    let mut y = vec![DVec3::ZERO; pos.len()];
    mob.noise(w, &mut y).unwrap();
    mob.apply(f, &mut y);
    eprintln!(
        "krylov its {}, {:?}",
        mob.krylov_iterations(),
        mob.ewald_summary()
    );
}

#[test]
#[ignore = "profile probe (callgrind): ewald_prepare_profile + one N = 10^4 step, kernel cached"]
fn ewald_step_profile() {
    // the instruction count minus that of `ewald_prepare_profile` (the same set-up) is one step
    let (n, a) = (10_000, 75e-9);
    let (pos, radii, w, f, opts) = step_inputs(n, a);
    // warms the kernel cache (a simulation computes it once)
    let _ = SpectralEwald::new(&pos, &radii, ETA, opts.ewald_tolerance).unwrap();
    one_step(&pos, &radii, &w, &f, opts);
}
