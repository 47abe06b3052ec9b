//! Tests and probes of the Lanczos square root ([`super::krylov`]).

use super::ewald::SpectralEwald;
use super::tests::{ETA, dilute_suspension, normals, random_config};
use super::*;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn flat(v: &[DVec3]) -> Vec<f64> {
    v.iter().flat_map(|p| [p.x, p.y, p.z]).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[test]
#[ignore = "probe: cargo test --release -p magsep-systems --lib lanczos_convergence_probe -- --ignored --nocapture"]
fn lanczos_convergence_probe() {
    let n: usize = std::env::var("PROBE_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    let a = 75e-9;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let w = flat(&normals(&mut rng, n));
    let op = SpectralEwald::new(&pos, &radii, ETA, 1e-4).unwrap();
    let reach: f64 = std::env::var("PROBE_REACH")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(precond::REACH);
    let pc = precond::ClusterFactor::with_reach(&pos, &radii, ETA, reach);
    let use_pc = std::env::var("PROBE_PC").is_ok();
    eprintln!(
        "preconditioned {use_pc}, clustered particles {}",
        pc.clustered()
    );
    let matvec = |x: &[f64], o: &mut [f64]| {
        if use_pc {
            let mut t = x.to_vec();
            pc.solve_lt(&mut t);
            op.apply(&t, o);
            pc.solve_l(o);
        } else {
            op.apply(x, o);
        }
    };
    let its = 40;
    let norm_w = dot(&w, &w).sqrt();
    let mut basis = vec![w.iter().map(|x| x / norm_w).collect::<Vec<f64>>()];
    let (mut alpha, mut beta) = (Vec::new(), Vec::new());
    let mut u = vec![0.0; w.len()];
    for k in 0..its {
        matvec(&basis[k], &mut u);
        let a_k = dot(&basis[k], &u);
        alpha.push(a_k);
        for _ in 0..2 {
            for v in &basis {
                let h = dot(v, &u);
                u.iter_mut().zip(v).for_each(|(ui, vi)| *ui -= h * vi);
            }
        }
        let b = dot(&u, &u).sqrt();
        beta.push(b);
        basis.push(u.iter().map(|x| x / b).collect());
    }
    let mut d = alpha.clone();
    let mut e = beta.clone();
    let _ = krylov::tridiagonal_eigen(&mut d, &mut e).unwrap();
    d.sort_by(f64::total_cmp);
    let mu0 = if use_pc {
        1.0
    } else {
        1.0 / (6.0 * std::f64::consts::PI * ETA * a)
    };
    eprintln!(
        "Ritz values / mu0: min {:.4} max {:.4}; top {:?}",
        d[0] / mu0,
        d[its - 1] / mu0,
        d[its - 6..].iter().map(|x| x / mu0).collect::<Vec<_>>()
    );
    let cs: Vec<Vec<f64>> = (1..=its)
        .map(|m| krylov::sqrt_t_e1(&alpha[..m], &beta).unwrap())
        .collect();
    let fin = &cs[its - 1];
    let nf = dot(fin, fin).sqrt();
    let diff = |c: &[f64], r: &[f64]| {
        let s: f64 = (0..r.len())
            .map(|i| (c.get(i).copied().unwrap_or(0.0) - r[i]).powi(2))
            .sum();
        s.sqrt()
    };
    for m in 2..its {
        let change = diff(&cs[m - 2], &cs[m - 1]) / dot(&cs[m - 1], &cs[m - 1]).sqrt();
        let err = diff(&cs[m - 1], fin) / nf;
        eprintln!("m {m}: change {change:.3e} true error {err:.3e}");
    }
}

#[test]
fn cluster_factor_reproduces_the_cluster_blocks() {
    // a dense polydisperse box with overlaps: L Lᵀ equals μ on every cluster block and the
    // self block elsewhere; L⁻¹ and L⁻ᵀ invert L and Lᵀ
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(41);
    let (pos, radii) = random_config(&mut rng, 60, 8.0 * super::tests::A, true);
    let pc = precond::ClusterFactor::new(&pos, &radii, ETA);
    assert!(pc.clustered() > 10, "{}", pc.clustered());
    let exact = rpy_matrix(&pos, &radii, ETA);
    let n3 = 3 * pos.len();
    // columns of L: L e_k; then (L Lᵀ)_rc = Σ_k L_rk L_ck
    let mut l = vec![vec![0.0; n3]; n3];
    for (k, col) in l.iter_mut().enumerate() {
        col[k] = 1.0;
        pc.mul_l(col);
    }
    let scale = exact[(0, 0)];
    let mut checked = 0;
    for r in 0..n3 {
        for c in 0..n3 {
            let llt: f64 = (0..n3).map(|k| l[k][r] * l[k][c]).sum();
            if llt != 0.0 || r / 3 == c / 3 {
                let e = (llt - exact[(r, c)]).abs() / scale;
                assert!(e < 1e-12, "({r}, {c}): {llt} vs {}", exact[(r, c)]);
                checked += 1;
            }
        }
    }
    assert!(checked > n3 * 3, "{checked}");
    let x = flat(&normals(&mut rng, pos.len()));
    for (solve, name) in [
        (precond::ClusterFactor::solve_l as fn(&_, &mut [f64]), "L"),
        (precond::ClusterFactor::solve_lt, "Lt"),
    ] {
        let mut y = x.clone();
        solve(&pc, &mut y);
        // apply L (or Lᵀ) by the columns computed above
        let back: Vec<f64> = (0..n3)
            .map(|r| {
                (0..n3)
                    .map(|k| if name == "L" { l[k][r] } else { l[r][k] } * y[k])
                    .sum()
            })
            .collect();
        let err = back
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-9, "{name}: {err}");
    }
}

#[test]
fn preconditioned_noise_covariance_and_fewer_iterations() {
    // uniformly random (overlapping) positions at φ ≈ 0.05: the Lanczos noise over the
    // matrix-free product, preconditioned by the cluster factor, still has covariance μ, and
    // one draw needs fewer iterations than Lanczos over μ itself at the same tolerance
    let n = 150;
    let edge = super::tests::A * (n as f64 * 4.19 / 0.05).cbrt();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(43);
    let (pos, radii) = random_config(&mut rng, n, edge, false);
    let exact = rpy_matrix(&pos, &radii, ETA);
    let opts = MobilityOptions {
        krylov_tolerance: 1e-6,
        ewald_tolerance: 1e-8,
        ..MobilityOptions::default()
    };
    let mob = Mobility::new_with(MobilityMethod::SpectralEwald, &pos, &radii, ETA, opts).unwrap();
    let e = covariance_error(&mob, &exact).unwrap();
    eprintln!("covariance error {e:e}");
    assert!(e < 1e-5, "{e}");
    let w = normals(&mut rng, n);
    let mut y = vec![DVec3::ZERO; n];
    mob.noise(&w, &mut y).unwrap();
    let op = SpectralEwald::new(&pos, &radii, ETA, 1e-8).unwrap();
    let plain = krylov::lanczos_sqrt(|x, o| op.apply(x, o), &flat(&w), 1e-6, 200).unwrap();
    eprintln!(
        "iterations: preconditioned {}, plain {}",
        mob.krylov_iterations(),
        plain.iterations
    );
    assert!(mob.krylov_iterations() < plain.iterations);
}

#[test]
#[ignore = "probe: cargo test --release -p magsep-systems --lib product_parts_timing -- --ignored --nocapture"]
fn product_parts_timing() {
    use std::time::Instant;
    let (n, a) = (10_000, 75e-9);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let f = flat(&normals(&mut rng, n));
    let t = Instant::now();
    let op = SpectralEwald::new(&pos, &radii, ETA, 1e-4).unwrap();
    let t_op = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let op2 = SpectralEwald::new(&pos, &radii, ETA, 1e-4).unwrap();
    let t_op2 = t.elapsed().as_secs_f64();
    drop(op2);
    let t = Instant::now();
    let pc = precond::ClusterFactor::new(&pos, &radii, ETA);
    let t_pc = t.elapsed().as_secs_f64();
    let mut v = vec![0.0; 3 * n];
    let (mut tr, mut tw, mut ts) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..5 {
        let t = Instant::now();
        op.apply_real(&f, &mut v);
        tr.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        op.wave().unwrap().apply_add(&f, &mut v);
        tw.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let mut x = f.clone();
        pc.solve_lt(&mut x);
        pc.solve_l(&mut x);
        ts.push(t.elapsed().as_secs_f64());
    }
    let direct = SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-4, None).unwrap();
    let mut exact = vec![0.0; 3 * n];
    direct.apply(&f, &mut exact);
    op.apply(&f, &mut v);
    let num: f64 = v.iter().zip(&exact).map(|(a, b)| (a - b) * (a - b)).sum();
    eprintln!(
        "product error against the direct sum {:e}",
        (num / dot(&exact, &exact)).sqrt()
    );
    for x in [&mut tr, &mut tw, &mut ts] {
        x.sort_by(f64::total_cmp);
    }
    eprintln!(
        "threads {}: prepare {t_op:.4} s (cached kernel {t_op2:.4} s), cluster factor {t_pc:.4} s; per product (medians): real {:.4} s, wave {:.4} s, two solves {:.5} s; {:?}",
        rayon::current_num_threads(),
        tr[2],
        tw[2],
        ts[2],
        op.summary()
    );
}

#[test]
#[ignore = "probe: cargo test --release -p magsep-systems --lib cutoff_cost_probe -- --ignored --nocapture"]
fn cutoff_cost_probe() {
    // one step's cost (prepare with a cached kernel + 16 products) against the cut-off, N = 10⁴
    use std::time::Instant;
    let (n, a) = (10_000, 75e-9);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let f = flat(&normals(&mut rng, n));
    let rc0 = SpectralEwald::new(&pos, &radii, ETA, 1e-4)
        .unwrap()
        .summary()
        .cutoff;
    let mut v = vec![0.0; 3 * n];
    for round in 0..2 {
        for k in [-1, 0, 1, 2] {
            let rc = rc0 * 1.25f64.powi(k);
            let _ = SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-4, Some(rc)).unwrap();
            let t = Instant::now();
            let op = SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-4, Some(rc)).unwrap();
            let tp = t.elapsed().as_secs_f64();
            let t = Instant::now();
            for _ in 0..4 {
                op.apply(&f, &mut v);
            }
            let ta = t.elapsed().as_secs_f64() / 4.0;
            eprintln!(
                "round {round} rc/rc0 {:.3}: prepare {tp:.3} s, product {ta:.4} s, step (16 products) {:.3} s; {:?}",
                rc / rc0,
                tp + 16.0 * ta,
                op.summary()
            );
        }
    }
}

#[test]
#[ignore = "profile probe (callgrind): the preparation of ewald_product_profile alone"]
fn ewald_prepare_profile() {
    // the same configuration and tolerance as `ewald_product_profile`, without the products:
    // the difference of the two counts is the cost of two products
    let (n, a) = (10_000, 75e-9);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let _ = normals(&mut rng, n);
    let op = SpectralEwald::new(&pos, &radii, ETA, 1e-4).unwrap();
    eprintln!("{:?}", op.summary());
}

#[test]
#[ignore = "probe: cargo test --release -p magsep-systems --lib support_error_probe -- --ignored --nocapture"]
fn support_error_probe() {
    // product error against the dense product (200 polydisperse particles with overlaps, as
    // `product_matches_dense_rpy_to_tolerance`) and, at N = 10⁴ (τ = 1e-4, the chosen
    // cut-off), against the direct sum, for supports ⌈2w/h⌉ + extra
    let rel = |a: &[f64], b: &[f64]| {
        let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
        (dot(&d, &d) / dot(b, b)).sqrt()
    };
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let (pos, radii) = random_config(&mut rng, 200, 12.0 * super::tests::A, true);
    let f = flat(&normals(
        &mut Xoshiro256PlusPlus::seed_from_u64(1),
        pos.len(),
    ));
    let mut exact = vec![0.0; f.len()];
    rpy::DenseSym::rpy(&pos, &radii, ETA).matvec(&f, &mut exact);
    let mut v = vec![0.0; f.len()];
    for extra in [0, 1, 2] {
        for tol in [1e-2, 1e-4, 1e-6, 1e-8] {
            for rc in [3.0, 4.0, 5.0] {
                let rc = rc * super::tests::A;
                let op =
                    SpectralEwald::with_cutoff_support(&pos, &radii, ETA, tol, Some(rc), extra)
                        .unwrap();
                op.apply(&f, &mut v);
                eprintln!(
                    "extra {extra} tol {tol:e} rc/a {:.0} support {}: error {:.3e} = tol/{:.1}",
                    rc / super::tests::A,
                    op.summary().support,
                    rel(&v, &exact),
                    tol / rel(&v, &exact)
                );
            }
        }
    }
    let (n, a) = (10_000, 75e-9);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let f = flat(&normals(&mut rng, n));
    let direct = SpectralEwald::with_cutoff(&pos, &radii, ETA, 1e-4, None).unwrap();
    let mut exact = vec![0.0; 3 * n];
    direct.apply(&f, &mut exact);
    let rc = SpectralEwald::new(&pos, &radii, ETA, 1e-4)
        .unwrap()
        .summary()
        .cutoff;
    let mut v = vec![0.0; 3 * n];
    for extra in [0, 1, 2] {
        let op =
            SpectralEwald::with_cutoff_support(&pos, &radii, ETA, 1e-4, Some(rc), extra).unwrap();
        op.apply(&f, &mut v);
        eprintln!(
            "N = 10^4, tol 1e-4, extra {extra}: error {:.3e}; {:?}",
            rel(&v, &exact),
            op.summary()
        );
    }
}

#[test]
#[ignore = "probe: cargo test --release -p magsep-systems --lib prepare_parts_timing -- --ignored --nocapture"]
fn prepare_parts_timing() {
    // the parts of one N = 10⁴ preparation (kernel cached), medians of 5, 1 and 2 threads
    use super::ewald::near::Near;
    use super::ewald::params::Params;
    use super::ewald::wave::Wave;
    use std::time::Instant;
    let (n, a) = (10_000, 75e-9);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (pos, radii) = dilute_suspension(&mut rng, n, a);
    let _ = SpectralEwald::new(&pos, &radii, ETA, 1e-4).unwrap();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut t = vec![Vec::new(); 5];
            for _ in 0..5 {
                let c = Instant::now();
                let p = Params::choose(1e-4, &pos, &radii, 12.0).unwrap();
                t[0].push(c.elapsed().as_secs_f64());
                let c = Instant::now();
                let near = Near::new(&p, &pos, &radii, ETA);
                t[1].push(c.elapsed().as_secs_f64());
                let c = Instant::now();
                let wave = Wave::new(&p, &pos, &radii, 1.0);
                t[2].push(c.elapsed().as_secs_f64());
                let c = Instant::now();
                let pc = precond::ClusterFactor::new(&pos, &radii, ETA);
                t[3].push(c.elapsed().as_secs_f64());
                let c = Instant::now();
                drop((near, wave, pc));
                t[4].push(c.elapsed().as_secs_f64());
            }
            for v in &mut t {
                v.sort_by(f64::total_cmp);
            }
            eprintln!(
                "threads {threads}: params {:.4} s, near {:.4} s, wave {:.4} s, cluster factor {:.4} s, drop {:.4} s",
                t[0][2], t[1][2], t[2][2], t[3][2], t[4][2]
            );
        });
    }
}
