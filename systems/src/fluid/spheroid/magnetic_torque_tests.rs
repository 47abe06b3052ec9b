//! M7: the magnetic-buoyancy torque, closed form against surface quadrature.

use super::*;
use crate::fluid::magnet::MagnetModel;

const CHI: f64 = 7e-4;

fn two_magnets() -> MagnetModel {
    MagnetModel::Two {
        surface_field: 637e3,
        pole_size: 0.2,
        half_height: 0.075,
    }
}

/// Semi-axes (a, c) of a spheroid of aspect ratio w with volume-equivalent diameter d_e.
fn semi_axes(d_e: f64, w: f64) -> (f64, f64) {
    let a = 0.5 * d_e / w.cbrt();
    (a, w * a)
}

fn tilted(deg: f64) -> DVec3 {
    let t = deg.to_radians();
    DVec3::new(t.sin(), 0.0, t.cos())
}

#[test]
fn m7_closed_form_matches_the_quadrature_in_the_two_magnet_field() {
    let m = two_magnets();
    let (a, c) = semi_axes(4e-3, 0.1);
    let y0 = -0.876 * 0.075;
    let e = tilted(30.0);
    let closed = magnetic_torque(a, c, m.static_pressure_curvature(CHI, y0), e);
    let (quad, force) =
        magnetic_torque_quadrature(a, c, e, |z| m.static_pressure(CHI, y0 + z), 800, 400);
    println!("M7: closed {closed}, quadrature {quad}, force {force}");
    assert!((closed.length() / 7.13e-9 - 1.0).abs() < 2e-3, "{closed}");
    assert!(
        (quad - closed).length() < 0.01 * closed.length(),
        "{quad} {closed}"
    );
    // the force is the point buoyancy −V dp_M/dz within 0.05 %
    let v = 4.0 / 3.0 * std::f64::consts::PI * a * a * c;
    let point = -v * m.kelvin_density(CHI, y0);
    assert!(force.x.abs() < 1e-6 * point.abs() && force.y.abs() < 1e-6 * point.abs());
    assert!((force.z / point - 1.0).abs() < 5e-4, "{} {point}", force.z);
    assert!((m.magnetic_buoyancy(CHI, v, y0) - point).abs() < 1e-15);
}

#[test]
fn flat_horizontal_is_the_stable_orientation() {
    let m = two_magnets();
    let (a, c) = semi_axes(4e-3, 0.1);
    for y0 in [-0.07, -0.02, 0.0, 0.05] {
        let p2 = m.static_pressure_curvature(CHI, y0);
        assert!(p2 > 0.0);
        // no torque flat-horizontal (e ∥ ±z) or edge-on vertical (e ⟂ z)
        for e in [DVec3::Z, -DVec3::Z, DVec3::X, DVec3::Y] {
            assert!(magnetic_torque(a, c, p2, e).length() < 1e-25);
        }
        for deg in [1.0, 10.0, 60.0, 120.0, 179.0] {
            let e = tilted(deg);
            for t in [
                magnetic_torque(a, c, p2, e),
                magnetic_torque_quadrature(a, c, e, |z| m.static_pressure(CHI, y0 + z), 120, 60).0,
            ] {
                // a small rotation about the torque brings e closer to ±z
                let e2 = (e + 1e-3 * t.cross(e) / t.length()).normalize();
                assert!(e2.z.abs() > e.z.abs(), "{deg} {t}");
            }
        }
    }
    // a sphere feels none
    let t = magnetic_torque(1e-3, 1e-3, 1e5, tilted(30.0));
    assert_eq!(t, DVec3::ZERO);
}

#[test]
fn quadratic_pressure_is_exact_to_second_order_and_linear_gives_no_torque() {
    let (a, c) = (3e-3, 1e-3);
    let e = DVec3::new(0.2, -0.5, 0.7).normalize();
    let (p0, p1, p2) = (1e3, -4e4, 2e5);
    let (t, f) = magnetic_torque_quadrature(a, c, e, |z| p0 + p1 * z + 0.5 * p2 * z * z, 400, 200);
    let closed = magnetic_torque(a, c, p2, e);
    assert!(
        (t - closed).length() < 1e-4 * closed.length(),
        "{t} {closed}"
    );
    let v = 4.0 / 3.0 * std::f64::consts::PI * a * a * c;
    assert!(
        (f - DVec3::new(0.0, 0.0, -v * p1)).length() < 1e-4 * v * p1.abs(),
        "{f}"
    );
    let (t, _) = magnetic_torque_quadrature(a, c, e, |z| p0 + p1 * z, 100, 50);
    assert!(t.length() < 1e-12 * closed.length(), "{t}");
    // degenerate inputs
    assert_eq!(
        magnetic_torque_quadrature(a, c, e, |z| z, 0, 10),
        (DVec3::ZERO, DVec3::ZERO)
    );
    assert_eq!(
        magnetic_torque_quadrature(a, c, DVec3::ZERO, |z| z, 4, 4),
        (DVec3::ZERO, DVec3::ZERO)
    );
    assert!(magnetic_torque(a, c, f64::NAN, e).is_finite());
}

#[test]
fn pressure_curvature_of_every_magnet_model() {
    let models = [
        MagnetModel::Bottom {
            surface_field: 422e3,
            pole_size: 0.1181,
            half_height: 0.075,
        },
        MagnetModel::Top {
            surface_field: 422e3,
            pole_size: 0.1181,
            half_height: 0.075,
        },
        two_magnets(),
    ];
    for m in models {
        for k in 0..=10 {
            let y = -0.07 + 0.014 * k as f64;
            let h = 1e-4;
            let p = |y: f64| m.static_pressure(CHI, y);
            let fd = (-p(y + 2.0 * h) + 16.0 * p(y + h) - 30.0 * p(y) + 16.0 * p(y - h)
                - p(y - 2.0 * h))
                / (12.0 * h * h);
            let an = m.static_pressure_curvature(CHI, y);
            assert!((an / fd - 1.0).abs() < 1e-6, "{m:?} {y}: {an} {fd}");
            // dp_M/dy is the Kelvin force density
            let d1 = (p(y + h) - p(y - h)) / (2.0 * h);
            let kelvin = m.kelvin_density(CHI, y);
            assert!(
                (d1 - kelvin).abs() < 2e-5 * (kelvin.abs() + 1e-3 * p(y)),
                "{d1} {kelvin}"
            );
        }
    }
    assert_eq!(MagnetModel::None.static_pressure_curvature(CHI, 0.0), 0.0);
    assert_eq!(MagnetModel::None.static_pressure(CHI, 0.0), 0.0);
}
