//! Deterministic tests of the superquadric kernels: special functions, bounding radius,
//! support map, Householder frame and the Jacobian against finite differences (contact tests
//! are in `tests_contact.rs`).

use super::householder::Frame;
use super::mass::bounding_radius_numeric;
use super::newton::{PairFrame, System, system};
use super::*;
use glam::{DMat3, DQuat, DVec3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

pub(crate) fn rng(seed: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

pub(crate) fn unit(r: &mut Xoshiro256PlusPlus) -> DVec3 {
    loop {
        let v = DVec3::new(
            r.random::<f64>() * 2.0 - 1.0,
            r.random::<f64>() * 2.0 - 1.0,
            r.random::<f64>() * 2.0 - 1.0,
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

pub(crate) fn quat(r: &mut Xoshiro256PlusPlus) -> DQuat {
    loop {
        let v = [0; 4].map(|_| r.random::<f64>() * 2.0 - 1.0);
        let q = DQuat::from_xyzw(v[0], v[1], v[2], v[3]);
        let l = q.length();
        if l > 0.1 && l <= 1.0 {
            return q / l;
        }
    }
}

/// Fibonacci directions on the unit sphere.
pub(super) fn fibonacci(n: usize) -> Vec<DVec3> {
    let ga = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = ga * i as f64;
            DVec3::new(r * t.cos(), r * t.sin(), z)
        })
        .collect()
}

#[test]
fn gamma_matches_known_values() {
    let pi = std::f64::consts::PI;
    let cases = [
        (0.5, pi.sqrt()),
        (1.0, 1.0),
        (1.5, 0.5 * pi.sqrt()),
        (1.0 / 3.0, 2.678_938_534_707_747_6),
        (1.25, 0.906_402_477_055_477),
        (4.0, 6.0),
        (3.5, 15.0 / 8.0 * pi.sqrt()),
    ];
    for (x, want) in cases {
        let got = ln_gamma(x).exp();
        assert!(
            (got - want).abs() <= 1e-14 * want,
            "Gamma({x}) = {got}, want {want}"
        );
    }
    assert!(ln_gamma(-1.0).is_nan() && ln_gamma(f64::NAN).is_nan());
}

#[test]
fn bounding_radius_is_tight_upper_bound() {
    // equal exponents: the numerical dual reproduces eqs. 4.38/4.39
    for &g in &[2.0, 2.0001, 2.5, 3.0, 5.0, 10.0, 100.0] {
        for &a in &[
            DVec3::ONE,
            DVec3::new(1.0, 0.5, 2.5),
            DVec3::new(3.0, 3.0, 1.0),
        ] {
            let closed = superquadric_bounding_radius(a, DVec3::splat(g));
            let num = bounding_radius_numeric(a, DVec3::splat(g));
            assert!(
                num >= closed && num - closed <= 1e-12 * closed,
                "g={g} a={a}"
            );
        }
    }
    // unequal exponents: above every sampled surface point, and tight
    let cases = [
        (DVec3::new(1.0, 0.7, 1.5), DVec3::new(3.0, 5.0, 2.5)),
        (DVec3::new(1.0, 2.0, 1.5), DVec3::new(2.0, 4.0, 7.0)),
        (DVec3::new(1.0, 1.0, 1.0), DVec3::new(2.0, 2.0, 10.0)),
        (DVec3::new(2.0, 1.0, 0.5), DVec3::new(10.0, 2.5, 2.0)),
    ];
    for (a, g) in cases {
        let s = Superquadric {
            semi_axes: a,
            exponents: g,
        };
        let r = s.bounding_radius();
        let mut best = (0.0f64, DVec3::ZERO);
        for d in fibonacci(20_000) {
            let p = s.project_radial(d);
            if p.length() > best.0 {
                best = (p.length(), d);
            }
        }
        // local refinement of the sampled maximum by a shrinking pattern search
        let (mut rmax, mut d0) = best;
        let mut step = 0.02;
        while step > 1e-9 {
            let mut moved = false;
            for e in [
                DVec3::X,
                DVec3::Y,
                DVec3::Z,
                -DVec3::X,
                -DVec3::Y,
                -DVec3::Z,
            ] {
                let d = (d0 + step * e).normalize();
                let l = s.project_radial(d).length();
                if l > rmax {
                    (rmax, d0, moved) = (l, d, true);
                }
            }
            if !moved {
                step *= 0.5;
            }
        }
        assert!(rmax <= r, "a={a} g={g}: sampled {rmax} > bound {r}");
        assert!(
            r - rmax <= 1e-9 * r,
            "a={a} g={g}: bound {r} not tight ({rmax})"
        );
    }
}

#[test]
fn support_map_is_on_surface_normal_aligned_and_maximal() {
    let mut r = rng(11);
    let shapes = [
        Superquadric::superball(1.0, 2.0),
        Superquadric::superball(1.3, 10.0),
        Superquadric {
            semi_axes: DVec3::new(1.0, 2.0, 0.7),
            exponents: DVec3::splat(3.5),
        },
        Superquadric {
            semi_axes: DVec3::new(1.0, 0.7, 1.5),
            exponents: DVec3::new(3.0, 5.0, 2.5),
        },
        Superquadric {
            semi_axes: DVec3::new(2.0, 1.0, 1.0),
            exponents: DVec3::new(2.0, 10.0, 4.0),
        },
    ];
    let samples = fibonacci(4000);
    for s in shapes {
        let surf: Vec<DVec3> = samples.iter().map(|&d| s.project_radial(d)).collect();
        for i in 0..200 {
            let mut w = unit(&mut r) * (0.1 + 10.0 * r.random::<f64>());
            if i % 10 == 0 {
                w.y = 0.0; // zero components
            }
            let p = s.support(w);
            assert!(s.inside(p).abs() < 1e-13, "{s:?} {w}: F = {}", s.inside(p));
            let n = s.gradient(p).normalize();
            assert!(
                n.cross(w.normalize()).length() < 1e-9,
                "{s:?} {w}: normal {n}"
            );
            let h = w.dot(p);
            let best = surf.iter().map(|q| w.dot(*q)).fold(f64::MIN, f64::max);
            assert!(best <= h + 1e-12 * w.length(), "{s:?} {w}: not maximal");
        }
        assert_eq!(s.support(DVec3::ZERO), DVec3::ZERO);
    }
}

#[test]
fn householder_frame_is_orthonormal_for_every_normal() {
    let mut r = rng(3);
    let mut ns: Vec<DVec3> = (0..500).map(|_| unit(&mut r) * 3.0).collect();
    ns.extend([
        -DVec3::X,
        DVec3::X,
        -DVec3::Y,
        DVec3::Z,
        DVec3::new(-1.0, 1e-12, 0.0),
    ]);
    for m in ns {
        for axis in 0..3 {
            let f = Frame::with_axis(m, axis).unwrap();
            let mh = m.normalize();
            for (x, y) in [(f.t, f.b), (f.t, mh), (f.b, mh)] {
                assert!(x.dot(y).abs() < 1e-14, "m={m} axis={axis}");
            }
            assert!((f.t.length() - 1.0).abs() < 1e-14 && (f.b.length() - 1.0).abs() < 1e-14);
        }
    }
    assert!(Frame::new(DVec3::ZERO).is_none());
}

/// Phi at q with the Householder axis fixed.
fn phi_at(
    sa: &Superquadric,
    sb: &Superquadric,
    pair: &PairFrame,
    q: [f64; 6],
    axis: usize,
) -> [f64; 6] {
    let (pa, pb) = (sa.prepared(), sb.prepared());
    let s_a = DVec3::new(q[0], q[1], q[2]);
    let s_b = DVec3::new(q[3], q[4], q[5]);
    let (ea, eb) = (pa.eval(s_a), pb.eval(s_b));
    let fr = Frame::with_axis(eb.grad, axis).unwrap();
    let mut sys = System::zero();
    system(&mut sys, pair, s_a, s_b, &ea, &eb, &fr);
    sys.phi
}

#[test]
fn analytic_jacobian_matches_central_differences() {
    let mut r = rng(5);
    let mut worst: f64 = 0.0;
    let mut count = 0;
    for trial in 0..400 {
        let g_a = [2.0, 2.5, 3.0, 4.0, 7.0][trial % 5];
        let sa = Superquadric {
            semi_axes: DVec3::new(1.0, 0.6 + r.random::<f64>(), 0.8 + r.random::<f64>()),
            exponents: DVec3::new(g_a, g_a + r.random::<f64>(), 2.0 + 3.0 * r.random::<f64>()),
        };
        let sb = Superquadric {
            semi_axes: DVec3::new(0.7 + r.random::<f64>(), 1.0, 1.2),
            exponents: DVec3::splat([2.0, 3.0, 4.0, 6.0][trial % 4]),
        };
        let pair = PairFrame {
            r: DMat3::from_quat(quat(&mut r)),
            c: unit(&mut r) * 2.0,
        };
        let s_a = sa.project_radial(unit(&mut r)) * (0.9 + 0.2 * r.random::<f64>());
        let mut s_b = unit(&mut r);
        // near n_y = 0 and n_z = 0 (and exactly 0 where the derivative is smooth there)
        match trial % 6 {
            1 => s_b.y = 1e-3,
            2 => s_b.z = -1e-3,
            // exactly 0 only where d^2F/dy^2 ~ |y|^(g-2) is smooth (g = 2 or g >= 4)
            3 if sb.exponents.y == 2.0 || sb.exponents.y >= 4.0 => s_b.y = 0.0,
            4 => {
                s_b.y = 2e-3;
                s_b.z = 0.0;
            }
            _ => {}
        }
        // near the surface (points far inside make Phi ~ 1 and its derivatives tiny, which
        // only measures the round-off of the differences)
        let s_b = sb.project_radial(s_b) * (0.9 + 0.2 * r.random::<f64>());
        let q = [s_a.x, s_a.y, s_a.z, s_b.x, s_b.y, s_b.z];
        let (pa, pb) = (sa.prepared(), sb.prepared());
        let (ea, eb) = (pa.eval(s_a), pb.eval(s_b));
        for axis in 0..3 {
            // the solver reflects along the largest normal component; any axis whose component
            // is not tiny gives a smooth frame (the sign of m_k picks the reflection)
            if eb.grad[axis].abs() < 0.1 * eb.grad.length() {
                continue;
            }
            let fr = Frame::with_axis(eb.grad, axis).unwrap();
            let mut sys = System::zero();
            system(&mut sys, &pair, s_a, s_b, &ea, &eb, &fr);
            let jac = sys.jac;
            let h = 1e-6;
            let mut fd = [[0.0; 6]; 6];
            for c in 0..6 {
                let (mut qp, mut qm) = (q, q);
                qp[c] += h;
                qm[c] -= h;
                let (fp, fm) = (
                    phi_at(&sa, &sb, &pair, qp, axis),
                    phi_at(&sa, &sb, &pair, qm, axis),
                );
                for row in 0..6 {
                    fd[row][c] = (fp[row] - fm[row]) / (2.0 * h);
                }
            }
            for row in 0..6 {
                let norm = jac[row].iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                for c in 0..6 {
                    let e = (fd[row][c] - jac[row][c]).abs() / norm;
                    worst = worst.max(e);
                    assert!(
                        e < 1e-6,
                        "trial {trial} axis {axis} J[{row}][{c}] = {} vs fd {} (row max {norm}, s_b {s_b}, g {})",
                        jac[row][c],
                        fd[row][c],
                        sb.exponents
                    );
                }
            }
            count += 1;
        }
    }
    eprintln!(
        "Jacobian vs central differences: {count} cases, worst row-relative error {worst:.2e}"
    );
}
