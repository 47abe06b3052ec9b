//! Tests of the matrix-free spectral Ewald RPY product ([`super::ewald`]).

use super::ewald::SpectralEwald;
use super::tests::{A, ETA, normals, random_config};
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
#[ignore = "timing probe"]
fn timing_probe() {
    use super::ewald::{near::Near, params::Params, wave::Wave};
    use std::time::Instant;
    for &(n, tol) in &[(1000usize, 1e-3), (10_000, 1e-3)] {
        let a = 75e-9;
        let edge = a * (n as f64 * 4.19 / 0.01).cbrt();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let (pos, _) = random_config(&mut rng, n, edge, false);
        let radii = vec![a; n];
        let f = flat(&normals(&mut rng, n));
        for k in [4.0, 6.0, 8.0, 12.0, 16.0, 24.0] {
            let p = Params::with_cutoff(tol, Some(k * a), &pos, &radii);
            let t = Instant::now();
            let near = Near::new(&p, &pos, &radii, ETA);
            let t_np = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let wave = Wave::new(&p, &pos, &radii, 1.0);
            let t_wp = t.elapsed().as_secs_f64();
            let mut v = vec![0.0; 3 * n];
            let t = Instant::now();
            near.apply(&f, &mut v);
            let t_na = t.elapsed().as_secs_f64();
            let t = Instant::now();
            wave.apply_add(&f, &mut v);
            let t_wa = t.elapsed().as_secs_f64();
            eprintln!(
                "N {n} rc {k}a: n {} P {} pairs {} | near prep {t_np:.4} apply {t_na:.4} | wave prep {t_wp:.4} apply {t_wa:.4}",
                p.fft_n,
                p.support,
                near.pairs()
            );
        }
    }
}
