//! Field kernel in the world frame: far field and multipole error bounds, gradients, poses,
//! superposition, and a stability sweep over the delicate places.

use glam::{DMat3, DVec3};
use magsep_systems::field::cylinder::{closed_form, hess_parts, inside_indicator};
use magsep_systems::field::multipole::{self, truncation_bound};
use magsep_systems::field::{
    CylinderSource, Dual3, EXACT, MU0, MomentModel, dipole_force, total_field_gradient,
};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn unit(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 0.1 && l < 1.0 {
            return v / l;
        }
    }
}

/// Closed-form `H` (body frame, no multipole) per unit magnetisation vector `m`.
fn closed(p: DVec3, m: DVec3, r: f64, l: f64) -> DVec3 {
    let parts = hess_parts(p.x, p.y, p.z, r, l);
    DVec3::from_array(parts.apply(p.x, p.y, m.to_array()))
}

#[test]
fn multipole_error_is_within_its_bound_and_beats_the_closed_form_far_away() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    for (r, l) in [(1.0, 3.0), (1.0, 0.2), (1.0, 20.0)] {
        let q = multipole::coefficients(r, l);
        let a = (r * r + l * l).sqrt();
        for dist in [2.5, 4.0, 8.0] {
            for _ in 0..20 {
                let p = unit(&mut rng) * dist * a;
                let m = unit(&mut rng);
                let exact = closed(p, m, r, l);
                // the dipole field scale |M| V / (4π r³) used by the bound
                let scale = q[0] / (dist * a).powi(3);
                for order in [0, 2, 4, 8, 16] {
                    let h =
                        DVec3::from_array(multipole::field(&q, order, p.to_array(), m.to_array()));
                    let err = (h - exact).length() / scale;
                    let bound = truncation_bound(order, 1.0 / dist);
                    // + the closed form's own rounding (~1e-13 here)
                    assert!(
                        err <= bound + 1e-12,
                        "L {l} r/a {dist} order {order}: {err} > {bound}"
                    );
                }
            }
        }
    }
}

#[test]
fn far_field_tends_to_the_point_dipole_with_quadratic_error() {
    // thesis eqs. 5.31/5.35: m = M π R² 2L; deviation O((a/r)²)
    let (r, l) = (1.0f64, 3.0f64);
    let a = (r * r + l * l).sqrt();
    let v = 2.0 * std::f64::consts::PI * r * r * l;
    let m = DVec3::new(0.6, 0.0, 0.8);
    let dir = DVec3::new(0.3, 0.5, 0.81).normalize();
    let mut ratios = vec![];
    for dist in [10.0, 30.0, 100.0] {
        let p = dir * dist * a;
        let exact = closed(p, m, r, l);
        let rr = p.length();
        let rh = p / rr;
        let dip = (rh * 3.0 * m.dot(rh) - m) * v / (4.0 * std::f64::consts::PI * rr.powi(3));
        let err = (exact - dip).length() / dip.length();
        ratios.push(err * dist * dist);
    }
    // err (r/a)² is roughly constant (0.1..3) and the error shrinks 100-fold per decade
    for w in &ratios {
        assert!(*w > 0.05 && *w < 5.0, "{ratios:?}");
    }
    assert!((ratios[0] / ratios[2] - 1.0).abs() < 0.2, "{ratios:?}");
}

#[test]
fn gradient_far_away_matches_the_analytic_dipole_gradient() {
    let (r, l) = (0.5, 1.0);
    let mag = DVec3::new(1e5, -3e5, 6e5);
    let src = CylinderSource::new(
        DVec3::new(0.1, 0.2, -0.3),
        DVec3::new(1.0, 1.0, 0.0),
        r,
        l,
        mag,
    );
    let v = 2.0 * std::f64::consts::PI * r * r * l;
    let mom = mag * v;
    let d = DVec3::new(300.0, -200.0, 500.0);
    let g = src.field_gradient(src.center + d, EXACT);
    // ∂_j B_i of μ0/(4π) (3 (m·r̂) r̂ - m)/r³
    let rr = d.length();
    let c = MU0 / (4.0 * std::f64::consts::PI);
    for j in 0..3 {
        for i in 0..3 {
            let mr = mom.dot(d);
            let dij = if i == j { 1.0 } else { 0.0 };
            let want = c
                * (3.0 * (mom[j] * d[i] + mr * dij + mom[i] * d[j]) / rr.powi(5)
                    - 15.0 * mr * d[i] * d[j] / rr.powi(7));
            let got = g.grad_b.col(j)[i];
            let scale = c * mom.length() / rr.powi(4);
            // quadrupole correction ~ 20 (a/r)² ~ 3e-5
            assert!((got - want).abs() < 1e-4 * scale, "{i}{j}: {got} vs {want}");
        }
    }
}

#[test]
fn gradient_matches_central_differences_in_any_pose_and_is_symmetric() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
    for _ in 0..10 {
        let axis = unit(&mut rng);
        let src = CylinderSource::new(
            DVec3::new(0.3, -0.1, 0.2),
            axis,
            0.7,
            1.9,
            unit(&mut rng) * 8e5,
        );
        for _ in 0..10 {
            let p = src.center + unit(&mut rng) * rng.random_range(0.8..6.0);
            if src.distance(p) < 0.05 {
                continue;
            }
            let g = src.field_gradient(p, EXACT);
            let f = src.field(p, EXACT);
            assert!((g.b - f.b).length() <= 1e-14 * f.b.length());
            let scale = g
                .grad_b
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()));
            let h = 1e-6;
            for j in 0..3 {
                let mut e = DVec3::ZERO;
                e[j] = h;
                let fd = (src.field(p + e, EXACT).b - src.field(p - e, EXACT).b) / (2.0 * h);
                assert!(
                    (fd - g.grad_b.col(j)).length() < 1e-7 * scale,
                    "{fd} vs {}",
                    g.grad_b.col(j)
                );
            }
            // curl B = 0 and div B = 0 outside
            let m = g.grad_b;
            let asym = (m - m.transpose())
                .to_cols_array()
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(
                asym < 1e-9 * scale && (m.x_axis.x + m.y_axis.y + m.z_axis.z).abs() < 1e-9 * scale
            );
        }
    }
}

#[test]
fn pose_rotation_and_superposition() {
    // a fibre along x equals the z kernel with rotated coordinates
    let (r, l) = (0.4, 2.0);
    let mag = DVec3::new(3e5, 1e5, -2e5);
    let src = CylinderSource::new(DVec3::new(1.0, 2.0, 3.0), DVec3::X, r, l, mag);
    let rot = DMat3::from_cols(DVec3::Y, DVec3::Z, DVec3::X); // body (e1, e2, e3) -> world
    for p in [
        DVec3::new(1.5, 2.1, 3.7),
        DVec3::new(-0.4, 2.0, 3.0),
        DVec3::new(4.0, 4.0, 4.0),
    ] {
        let d = rot.transpose() * (p - src.center);
        let hb = closed(d, rot.transpose() * mag, r, l);
        let hw = src.field(p, EXACT).h;
        assert!((rot * hb - hw).length() < 1e-13 * hw.length(), "{p}");
    }
    // two fibres + external field = the sum; force on a dipole
    let s2 = CylinderSource::new(
        DVec3::ZERO,
        DVec3::new(0.0, 1.0, 1.0),
        0.3,
        1.0,
        DVec3::Z * 9.85e5,
    );
    let bext = DVec3::new(1.0, 0.0, 0.0);
    let p = DVec3::new(0.8, 0.9, 1.4);
    let tot = total_field_gradient(&[src.clone(), s2.clone()], bext, p, EXACT);
    let sum = src.field(p, EXACT).b + s2.field(p, EXACT).b + bext;
    assert!((tot.b - sum).length() < 1e-15 * sum.length());
    let law = MomentModel::Saturated { moment: 1e-16 };
    let f = dipole_force(&tot, &law, 4.1e-21);
    // F = m ∇|B| by central differences of |B|
    let h = 1e-6;
    for j in 0..3 {
        let mut e = DVec3::ZERO;
        e[j] = h;
        let bp = total_field_gradient(&[src.clone(), s2.clone()], bext, p + e, EXACT)
            .b
            .length();
        let bm = total_field_gradient(&[src.clone(), s2.clone()], bext, p - e, EXACT)
            .b
            .length();
        let fd = 1e-16 * (bp - bm) / (2.0 * h);
        assert!(
            (fd - f[j]).abs() < 1e-7 * f.length(),
            "{j}: {fd} vs {}",
            f[j]
        );
    }
}

#[test]
fn stability_sweep_over_the_delicate_places() {
    // no NaN or inf anywhere; field and gradient finite, including exactly on the surface,
    // the rims, the axis, far away and at extreme aspect ratios
    let mut worst_axis: f64 = 0.0;
    for &l in &[1e-3, 1e-1, 1.0, 30.0, 1e6] {
        let r = 1.0;
        let m = DVec3::new(0.5, 0.3, 0.8);
        let src = CylinderSource::new(DVec3::ZERO, DVec3::Z, r, l, m);
        let mut pts = vec![];
        for e in [0.0, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 1.0] {
            for z in [0.0, 0.5 * l, l, l + 1e-9, l + 0.5, 3.0 * l + 2.0] {
                pts.push(DVec3::new(e, 0.0, z)); // axis distance
                pts.push(DVec3::new(r + e, 0.0, z)); // lateral surface, outside
                pts.push(DVec3::new(r - e, 0.0, z)); // inside
                pts.push(DVec3::new(0.0, r + e, l + e)); // near the rim
            }
        }
        pts.push(DVec3::new(r, 0.0, l)); // exactly on the rim
        pts.push(DVec3::new(r, 0.0, 0.0)); // exactly on the lateral surface
        pts.push(DVec3::new(0.3 * r, 0.0, l)); // exactly on an end face
        for d in [1e3, 1e6, 1e9] {
            pts.push(DVec3::new(0.3, -0.2, 0.9).normalize() * d * (r + l));
        }
        for p in pts {
            let f = src.field(p, EXACT);
            let g = src.field_gradient(p, EXACT);
            assert!(f.b.is_finite() && f.h.is_finite(), "L {l} {p}: {f:?}");
            assert!(g.b.is_finite() && g.grad_b.is_finite(), "L {l} {p}: {g:?}");
        }
        // on-axis continuity of the transverse field across the branch switch (ρ = 0.05 R)
        for z in [0.3 * l, l + 0.4] {
            let chi = inside_indicator(0.05, z, r, l);
            let a = hess_parts(0.05 - 1e-12, 0.0, z, r, l);
            let b = closed_form(0.05 + 1e-12, z, r, l, chi);
            worst_axis = worst_axis.max((a.b - b.b).abs() / a.b.abs().max(a.pzz.abs()));
        }
    }
    assert!(worst_axis < 1e-10, "{worst_axis}");
    let _ = Dual3::var(0.0, 0);
}
