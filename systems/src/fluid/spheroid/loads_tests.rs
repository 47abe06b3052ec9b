//! Directions, symmetries, magnitudes and guards of [`spheroid_loads`] and
//! [`rotational_resistance`].

use super::correlations::{sanjeevi, zastawny};
use super::disc_model::disc_model;
use super::*;
use std::f64::consts::{FRAC_PI_2, PI};

const CORRELATIONS: [Correlation; 4] = [
    Correlation::Sphere,
    Correlation::Sanjeevi25,
    Correlation::Zastawny15,
    Correlation::Disc110,
];

fn hydro(c: Correlation) -> SpheroidHydro {
    let w = match c {
        Correlation::Sphere => 1.0,
        Correlation::Sanjeevi25 => 0.4,
        Correlation::Zastawny15 => 0.2,
        Correlation::Disc110 => 0.1,
    };
    let h = SpheroidHydro::new(8e-3, w, 1400.0, 1300.0, 5.54e-3);
    assert_eq!(h.correlation, c);
    h
}

/// Axes spread over the sphere (a deterministic spiral).
fn axes(n: usize) -> impl Iterator<Item = DVec3> {
    (0..n).map(move |k| {
        let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
        let a = k as f64 * 2.399_963;
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * a.cos(), r * a.sin(), z)
    })
}

#[test]
fn drag_along_slip_lift_perpendicular_torque_towards_broadside() {
    let slip = DVec3::new(0.2, -0.5, -1.0).normalize() * 0.02;
    let u = slip.normalize();
    for c in CORRELATIONS {
        let h = hydro(c);
        for e in axes(64) {
            let l = spheroid_loads(&h, slip, e);
            assert!(l.drag.cross(u).length() <= 1e-12 * l.drag.length());
            assert!(l.drag.dot(u) > 0.0 && (l.drag - l.drag_stiffness * slip).length() < 1e-18);
            assert!(l.lift.dot(u).abs() <= 1e-12 * l.lift.length().max(1e-30));
            assert!((l.incidence - e.dot(u).abs().asin()).abs() < 1e-12);
            if c == Correlation::Sphere {
                assert!(l.lift == DVec3::ZERO && l.pitching_torque == DVec3::ZERO);
                continue;
            }
            let phi = l.incidence;
            if phi > 0.05 && phi < FRAC_PI_2 - 0.05 {
                assert!(
                    l.lift.length() > 0.0 && l.pitching_torque.length() > 0.0,
                    "{c:?}"
                );
                // flat-plate check: the normal force (drag + lift)·e has the sign of e·û
                assert!((l.drag + l.lift).dot(e) * e.dot(u) > 0.0);
                // a small rotation about the torque raises the incidence (towards broadside)
                let t = l.pitching_torque;
                let e2 = (e + 1e-3 * t.cross(e) / t.length()).normalize();
                assert!(e2.dot(u).abs() > e.dot(u).abs(), "{c:?} {e}");
                // the torque is perpendicular to both e and the slip
                assert!(t.dot(e).abs() < 1e-12 * t.length() && t.dot(u).abs() < 1e-12 * t.length());
            }
        }
    }
}

#[test]
fn lift_and_torque_vanish_edge_on_and_broadside() {
    let slip = DVec3::new(0.0, 0.0, -0.03);
    let edge = DVec3::new(1.0, 1.0, 0.0).normalize();
    for c in CORRELATIONS {
        let h = hydro(c);
        for e in [DVec3::Z, -DVec3::Z, edge] {
            let l = spheroid_loads(&h, slip, e);
            assert_eq!(l.lift, DVec3::ZERO, "{c:?}");
            assert_eq!(l.pitching_torque, DVec3::ZERO);
            assert!(l.drag.z < 0.0);
        }
        // nearly broadside: continuous, tiny
        let e = DVec3::new(1e-7, 0.0, 1.0).normalize();
        let l = spheroid_loads(&h, slip, e);
        let drag = l.drag.length();
        assert!(l.lift.length() < 1e-5 * drag && l.pitching_torque.length() < 1e-5 * drag);
    }
}

#[test]
fn magnitudes_follow_the_stated_formulas() {
    let phi: f64 = 0.6;
    let e = DVec3::new(phi.cos(), 0.0, -phi.sin()); // e·û = sin φ for û = −z
    let speed = 0.013;
    let slip = DVec3::new(0.0, 0.0, -speed);
    for c in [
        Correlation::Sanjeevi25,
        Correlation::Zastawny15,
        Correlation::Disc110,
    ] {
        let h = hydro(c);
        let l = spheroid_loads(&h, slip, e);
        let d = h.equivalent_diameter;
        let re = h.fluid_density * speed * d / h.viscosity;
        assert!((l.reynolds - re).abs() < 1e-12 * re && (l.incidence - phi).abs() < 1e-12);
        let k = match c {
            Correlation::Sanjeevi25 => sanjeevi(re, phi),
            Correlation::Zastawny15 => zastawny(re, phi),
            _ => disc_model().coefficients(re, phi),
        };
        let q = PI / 8.0 * h.fluid_density * d * d * speed * speed;
        assert!(
            (l.drag.length() / (q * k.drag) - 1.0).abs() < 1e-12,
            "{c:?}"
        );
        assert!(
            (l.lift.length() / (q * k.lift) - 1.0).abs() < 1e-12,
            "{c:?}"
        );
        let d3 = if c == Correlation::Disc110 {
            d * d * h.major_diameter
        } else {
            d * d * d
        };
        let t = 0.5 * k.torque * h.fluid_density * PI / 8.0 * d3 * speed * speed;
        assert!(
            (l.pitching_torque.length() / t - 1.0).abs() < 1e-12,
            "{c:?}"
        );
    }
}

#[test]
fn drag_and_lift_scale_with_the_density_choice_torque_does_not() {
    let slip = DVec3::new(0.01, 0.0, -0.02);
    let e = DVec3::new(0.3, 0.4, 0.8).normalize();
    for c in [
        Correlation::Sanjeevi25,
        Correlation::Zastawny15,
        Correlation::Disc110,
    ] {
        let fluid = hydro(c);
        let particle = SpheroidHydro {
            drag_density: DragDensity::Particle,
            ..fluid
        };
        let (a, b) = (
            spheroid_loads(&fluid, slip, e),
            spheroid_loads(&particle, slip, e),
        );
        let ratio = fluid.particle_density / fluid.fluid_density;
        assert!((b.drag - ratio * a.drag).length() < 1e-12 * a.drag.length());
        assert!((b.lift - ratio * a.lift).length() < 1e-12 * a.lift.length());
        assert_eq!(a.pitching_torque, b.pitching_torque);
        assert_eq!(a.reynolds, b.reynolds);
    }
    // the sphere's Schiller-Naumann drag
    let h = hydro(Correlation::Sphere);
    let l = spheroid_loads(&h, slip, DVec3::Z);
    let (f, k, _) = crate::fluid::drag::translational_drag(
        crate::fluid::drag::DragLaw::SchillerNaumann,
        h.fluid_density,
        h.viscosity,
        h.equivalent_diameter,
        slip,
    );
    assert_eq!((l.drag, l.drag_stiffness), (f, k));
}

#[test]
fn degenerate_inputs_give_finite_loads() {
    let bad = [
        DVec3::ZERO,
        DVec3::splat(f64::NAN),
        DVec3::new(f64::INFINITY, 0.0, 0.0),
        DVec3::new(1e-300, 0.0, 0.0),
        DVec3::new(1e3, -2e3, 5e2),
    ];
    for c in CORRELATIONS {
        let h = hydro(c);
        for slip in bad {
            for axis in bad.iter().copied().chain([DVec3::Z, DVec3::X]) {
                let l = spheroid_loads(&h, slip, axis);
                assert!(
                    l.drag.is_finite() && l.lift.is_finite(),
                    "{c:?} {slip} {axis}"
                );
                assert!(l.pitching_torque.is_finite() && l.drag_stiffness.is_finite());
                assert!(l.reynolds.is_finite() && l.incidence.is_finite());
            }
            let (t, k) = rotational_resistance(&h, slip);
            assert!(t.is_finite() && k.is_finite());
        }
        // zero slip: zero loads
        assert_eq!(
            spheroid_loads(&h, DVec3::ZERO, DVec3::Z),
            HydroLoads::default()
        );
    }
}

#[test]
fn rotational_resistance_resists_and_has_a_finite_stiffness_at_rest() {
    for c in CORRELATIONS {
        let h = hydro(c);
        let (t0, k0) = rotational_resistance(&h, DVec3::ZERO);
        assert!(t0 == DVec3::ZERO && k0 > 0.0, "{c:?} {k0}");
        let mut last = 0.0;
        for w in [1e-4, 1e-2, 1.0, 1e2, 1e4] {
            let rel = DVec3::new(1.0, -2.0, 0.5).normalize() * w;
            let (t, k) = rotational_resistance(&h, rel);
            assert!(t.dot(rel) > 0.0 && (t - k * rel).length() <= 1e-12 * t.length());
            // the torque grows with the rate
            assert!(t.length() > last);
            last = t.length();
        }
    }
}
