//! Tests of the body-frame kernel: golden values (D-000-2 in docs/references.md, 40-digit mpmath), identities and
//! limits. Comparisons with independent quadrature are in `tests/it/field_reference.rs`.

use super::*;
use crate::field::real::Dual3;

/// `H` (per unit M) in the body frame at `(x, y, z)` for magnetisation `m`.
fn h(p: [f64; 3], m: [f64; 3], r: f64, l: f64) -> ([f64; 3], f64) {
    let parts = hess_parts(p[0], p[1], p[2], r, l);
    (parts.apply(p[0], p[1], m), parts.chi)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// (ρ, φ, z, H_ρ, H_φ, H_z [transverse], B_ρ/μ0, B_z/μ0 [longitudinal]); R = 1, L = 3.
const GOLDEN: &[[f64; 8]] = &[
    [
        0.5,
        0.3,
        0.7,
        -0.4513802587267,
        0.1392616618729,
        5.147189661406e-3,
        5.387829021497e-3,
        0.9437254440432,
    ],
    [
        1.5,
        0.3,
        0.7,
        0.2280799521451,
        0.05841750347535,
        0.01004398149553,
        0.01051355371626,
        -0.04106620548715,
    ],
    [
        0.2,
        1.0,
        2.5,
        -0.1950813189576,
        0.3019698073602,
        0.01917150736769,
        0.03548292716776,
        0.7199190125123,
    ],
    [
        2.0,
        2.0,
        4.0,
        -3.722053926658e-3,
        0.02763037645395,
        -0.01788785205863,
        0.04298447203648,
        0.02144242321135,
    ],
    [
        0.9,
        0.5,
        -2.9,
        -0.3199996800661,
        0.1379310558824,
        -0.2932608419109,
        -0.3341689484796,
        0.6523383772217,
    ],
    [
        3.0,
        0.1,
        0.0,
        0.05921905028688,
        3.962423099787e-3,
        0.0,
        0.0,
        -0.01982603579482,
    ],
    [
        1.05,
        0.7,
        3.05,
        0.07738427729105,
        0.129817654262,
        0.3266751428015,
        0.4271144403806,
        0.1003353027242,
    ],
    [
        0.3,
        2.5,
        -3.5,
        0.1023591922099,
        0.07948953389069,
        0.04272997940715,
        -0.05333622908294,
        0.2605871206125,
    ],
    [
        0.5,
        0.0,
        3.0,
        -0.2466486931277,
        0.0,
        0.1384165435712,
        0.1384165435712,
        0.4932639712126,
    ],
    [
        10.0,
        0.4,
        25.0,
        -4.140744068523e-5,
        3.049203493912e-5,
        7.534758517828e-5,
        8.180520689604e-5,
        1.232577278758e-4,
    ],
];

#[test]
fn golden_values_of_the_thesis_closed_forms() {
    for g in GOLDEN {
        let (rho, phi, z) = (g[0], g[1], g[2]);
        let (s, c) = phi.sin_cos();
        let p = [rho * c, rho * s, z];
        let (ht, _) = h(p, [1.0, 0.0, 0.0], 1.0, 3.0);
        let h_rho = ht[0] * c + ht[1] * s;
        let h_phi = -ht[0] * s + ht[1] * c;
        let (hl, chi) = h(p, [0.0, 0.0, 1.0], 1.0, 3.0);
        let b_rho = hl[0] * c + hl[1] * s;
        let b_z = hl[2] + chi;
        // the table has 13 significant digits: 1e-12 relative (absolute where the value is 0)
        for (got, want) in [
            (h_rho, g[3]),
            (h_phi, g[4]),
            (ht[2], g[5]),
            (b_rho, g[6]),
            (b_z, g[7]),
        ] {
            let tol = 1e-12 * want.abs().max(1e-14);
            assert!(
                (got - want).abs() <= tol.max(2e-16),
                "{g:?}: {got} vs {want}"
            );
        }
    }
    // on the axis: B_z/μ0 (z = 0) and transverse H_x (z = 0)
    let (hl, chi) = h([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0, 3.0);
    assert!(rel(hl[2] + chi, 0.948683298050514) < 1e-14);
    let (ht, _) = h([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 1.0, 3.0);
    assert!(rel(ht[0], -0.474341649025257) < 1e-14);
}

#[test]
fn near_axis_expansion_joins_the_closed_form() {
    // where both are accurate (ρ ~ 0.03..0.08 R) they agree to ~1e-12
    for &(r, l) in &[(1.0, 3.0), (1.0, 0.01), (1.0, 1e4)] {
        for &z in &[0.0, 0.5 * l, l, l + 0.3, -l - 2.0, 5.0 * l + 1.0] {
            // beyond ~2 circumradii the dispatcher uses the multipole expansion instead
            if z.abs() > 2.0 * (r * r + l * l).sqrt() {
                continue;
            }
            for &rho in &[0.03, 0.05, 0.08] {
                let chi = inside_indicator(rho, z, r, l);
                let a: HessParts<f64> = near_axis(rho * rho, z, r, l, chi);
                let b: HessParts<f64> = closed_form(rho, z, r, l, chi);
                let scale = a.b.abs().max(a.pzz.abs()).max(a.u.abs() * r).max(1e-300);
                // the closed form loses ~ (r/a)² (R/ρ) ε to cancellation away from the body
                let rr = (z * z + rho * rho) / (r * r + l * l);
                // and ~√(R/L) more for flat discs (the two end terms nearly cancel)
                let scale = scale * rr.max(1.0) * (1.0 + r / l).sqrt();
                for (x, y) in [
                    (a.pzz, b.pzz),
                    (a.u * rho, b.u * rho),
                    (a.b, b.b),
                    (a.e * rho * rho, b.e * rho * rho),
                ] {
                    assert!(
                        (x - y).abs() <= 2e-12 * scale,
                        "L {l} z {z} ρ {rho}: {x} vs {y}"
                    );
                }
            }
        }
    }
}

#[test]
fn on_axis_closed_forms() {
    // solenoid B_z and eq. 5.26 H_x on the axis, inside and outside, to 1e-14
    let (r, l) = (0.7, 2.0);
    for z in [-5.0, -2.0 - 1e-9, -1.0, 0.0, 0.3, 1.99, 2.5, 40.0] {
        // stable difference g(a) - g(b) = R² (a - b)(a + b) / ((a s_b + b s_a) s_a s_b)
        let (a, b) = (z + l, z - l);
        let (sa, sb) = ((a * a + r * r).sqrt(), (b * b + r * r).sqrt());
        let sol = if a * b > 0.0 {
            0.5 * r * r * (a - b) * (a + b) / ((a * sb + b * sa) * sa * sb)
        } else {
            0.5 * (a / sa - b / sb)
        };
        for rho in [0.0, 1e-12, 1e-8] {
            let (hl, chi) = h([rho, 0.0, z], [0.0, 0.0, 1.0], r, l);
            assert!(
                (hl[2] + chi - sol).abs() <= 1e-14 * sol.abs().max(1e-3),
                "z {z}"
            );
            let (ht, _) = h([rho, 0.0, z], [1.0, 0.0, 0.0], r, l);
            assert!(
                (ht[0] + 0.5 * sol).abs() <= 1e-14 * sol.abs().max(1e-3),
                "z {z}"
            );
            assert!(ht[1].abs() < 1e-15 && ht[2].abs() <= 1e-8 * sol.abs().max(1e-3));
        }
    }
    // eq. 5.27: H_ρ(0,0,0) = -(M/2) L/√(R² + L²)
    let (ht, _) = h([0.0; 3], [1.0, 0.0, 0.0], r, l);
    assert!(rel(ht[0], -0.5 * l / (r * r + l * l).sqrt()) < 1e-15);
}

#[test]
fn psi_rho_rho_equals_the_thesis_p4() {
    // H_ρ = M_t cos φ (R/(2πρ)) [β₊P₄(k₊) - β₋P₄(k₋)] (eq. 5.21, 5.22), against our Laplace form
    use crate::field::cel::cel;
    let (r, l) = (1.0, 3.0);
    for &(rho, z) in &[(0.5, 0.7), (1.5, 0.7), (2.0, 4.0), (0.9, -2.9), (4.0, 0.1)] {
        let sp = rho + r;
        let gamma = (rho - r) / sp;
        let mut sum = 0.0;
        for (xi, sgn) in [(z + l, 1.0), (z - l, -1.0)] {
            let alpha = 1.0 / (xi * xi + sp * sp).sqrt();
            let kc = (xi * xi + (rho - r) * (rho - r)).sqrt() * alpha;
            let p4 = gamma * (1.0 + gamma * gamma) * cel(kc, gamma * gamma, 0.0, 1.0)
                - cel(kc, 1.0, 1.0 + gamma, gamma - 1.0);
            sum += sgn * xi * alpha * p4;
        }
        let want = r / (2.0 * std::f64::consts::PI * rho) * sum;
        let (ht, _) = h([rho, 0.0, z], [1.0, 0.0, 0.0], r, l);
        assert!(
            (ht[0] - want).abs() < 1e-14,
            "{rho} {z}: {} vs {want}",
            ht[0]
        );
    }
}

#[test]
fn infinite_cylinder_limit() {
    // eq. 5.24 (L = 1e6 R): inside H = -M/2 (transverse), outside the 2-D line dipole
    let (r, l) = (1.0, 1e6);
    for &(rho, phi) in &[
        (0.3, 0.4),
        (0.99, 2.0),
        (1.01, 1.0),
        (2.0, 0.3),
        (7.0, -1.2),
    ] {
        let (s, c) = f64::sin_cos(phi);
        let (ht, _) = h([rho * c, rho * s, 0.1], [1.0, 0.0, 0.0], r, l);
        let (hr, hp) = (ht[0] * c + ht[1] * s, -ht[0] * s + ht[1] * c);
        let (wr, wp) = if rho > r {
            (0.5 * r * r / (rho * rho) * c, 0.5 * r * r / (rho * rho) * s)
        } else {
            (-0.5 * c, 0.5 * s)
        };
        assert!(
            (hr - wr).abs() < 1e-9 && (hp - wp).abs() < 1e-9,
            "{rho}: {hr} {wr} {hp} {wp}"
        );
        assert!(ht[2].abs() < 1e-9);
        // longitudinal: B = μ0 M inside, 0 outside
        let (hl, chi) = h([rho * c, rho * s, 0.1], [0.0, 0.0, 1.0], r, l);
        assert!((hl[2] + chi - chi).abs() < 1e-9 && hl[0].abs() < 1e-9);
    }
}

#[test]
fn jump_conditions_across_the_surface() {
    let (r, l) = (1.0, 3.0);
    let d = 1e-10;
    for &(phi, z) in &[(0.3, 0.7), (2.0, -1.5), (4.0, 2.9)] {
        let (s, c) = f64::sin_cos(phi);
        let at = |rho: f64, m: [f64; 3]| h([rho * c, rho * s, z], m, r, l);
        // longitudinal: B_z jumps by μ0 M (inside minus outside); normal B continuous
        let (hi, ci) = at(r - d, [0.0, 0.0, 1.0]);
        let (ho, co) = at(r + d, [0.0, 0.0, 1.0]);
        assert!(
            ((hi[2] + ci) - (ho[2] + co) - 1.0).abs() < 1e-8,
            "{phi} {z}"
        );
        // transverse: H_ρ jumps by -M cos φ (inside minus outside); tangential H continuous
        let (hi, _) = at(r - d, [1.0, 0.0, 0.0]);
        let (ho, _) = at(r + d, [1.0, 0.0, 0.0]);
        let n = |v: [f64; 3]| v[0] * c + v[1] * s;
        let t = |v: [f64; 3]| -v[0] * s + v[1] * c;
        assert!((n(hi) - n(ho) + c).abs() < 1e-8);
        assert!((t(hi) - t(ho)).abs() < 1e-8 && (hi[2] - ho[2]).abs() < 1e-8);
        // exactly on the surface: the mean of the two sides
        let (hs, cs) = at(r, [0.0, 0.0, 1.0]);
        assert_eq!(cs, 0.5);
        let mean = 0.5 * ((hi[2] + ho[2]) + 0.0);
        let _ = mean;
        let (hl_i, cl_i) = at(r - d, [0.0, 0.0, 1.0]);
        let (hl_o, cl_o) = at(r + d, [0.0, 0.0, 1.0]);
        let mean_b = 0.5 * (hl_i[2] + cl_i + hl_o[2] + cl_o);
        assert!(
            (hs[2] + cs - mean_b).abs() < 1e-7,
            "{} vs {mean_b}",
            hs[2] + cs
        );
    }
}

#[test]
fn transverse_hz_vanishes_at_midplane_and_superposition_is_linear() {
    let (r, l) = (0.4, 1.3);
    for &(x, y) in &[(0.1, 0.2), (0.5, -0.3), (2.0, 1.0)] {
        let (ht, _) = h([x, y, 0.0], [0.3, -0.8, 0.0], r, l);
        assert!(ht[2].abs() < 1e-16);
        let p = [x, y, 0.37];
        let (a, _) = h(p, [1.0, 0.0, 0.0], r, l);
        let (b, _) = h(p, [0.0, 1.0, 0.0], r, l);
        let (c, _) = h(p, [0.0, 0.0, 1.0], r, l);
        let m = [0.3, -1.7, 2.2];
        let (t, _) = h(p, m, r, l);
        for i in 0..3 {
            let lin = m[0] * a[i] + m[1] * b[i] + m[2] * c[i];
            assert!((t[i] - lin).abs() < 1e-15 * 4.0);
        }
    }
}

#[test]
fn gradient_is_curl_and_divergence_free_and_matches_differences() {
    let (r, l) = (1.0, 2.0);
    let m = [0.4, -0.3, 0.8];
    for &p in &[
        [1.3, 0.4, 0.5],
        [0.2, 0.1, 2.6],
        [2.5, -1.0, -3.0],
        [1e-4, 2e-4, 2.3],
    ] {
        let pd = Dual3::seed(glam::DVec3::from_array(p));
        let parts = hess_parts(pd[0], pd[1], pd[2], r, l);
        let hd = parts.apply(pd[0], pd[1], m);
        let jac = |i: usize, j: usize| hd[i].d[j];
        let scale = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| jac(i, j).abs())
            .fold(0.0, f64::max);
        let div = jac(0, 0) + jac(1, 1) + jac(2, 2);
        assert!(div.abs() < 1e-12 * scale, "{p:?}: div {div}");
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            assert!((jac(i, j) - jac(j, i)).abs() < 1e-12 * scale, "{p:?}: curl");
        }
        // central differences (step 1e-5, error ~1e-10 relative)
        let hstep = 1e-5;
        for j in 0..3 {
            let mut a = p;
            let mut b = p;
            a[j] += hstep;
            b[j] -= hstep;
            let (fa, _) = h(a, m, r, l);
            let (fb, _) = h(b, m, r, l);
            for i in 0..3 {
                let fd = (fa[i] - fb[i]) / (2.0 * hstep);
                assert!(
                    (fd - jac(i, j)).abs() < 1e-8 * scale,
                    "{p:?} d{i}/d{j}: {fd} vs {}",
                    jac(i, j)
                );
            }
        }
    }
}
