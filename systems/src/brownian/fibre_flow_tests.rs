use super::*;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const A: f64 = 200e-6;

fn long_fibre() -> FlowFibre {
    FlowFibre {
        center: DVec3::new(1e-3, -2e-3, 0.5e-3),
        axis: DVec3::Z,
        radius: A,
        half_length: 100.0 * A,
    }
}

/// Potential flow past a cylinder along z, far velocity (u0, 0): conj(dW/dz) with
/// W = u0 (z + a²/z), written with complex numbers.
fn analytic(u0: f64, x: f64, y: f64) -> DVec3 {
    use num_complex::Complex64;
    let z = Complex64::new(x, y);
    let dw = u0 * (1.0 - A * A / (z * z));
    DVec3::new(dw.re, -dw.im, 0.0)
}

#[test]
fn one_fibre_is_the_potential_flow_past_a_cylinder() {
    let f = long_fibre();
    let flow = FibreFlow::new(vec![f]);
    let u = DVec3::new(3e-2, 0.0, 0.0);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    for _ in 0..500 {
        let rho = A * rng.random_range(1.0..NEAR);
        let th = rng.random_range(0.0..std::f64::consts::TAU);
        let s = rng.random_range(-90.0 * A..90.0 * A);
        let x = f.center + DVec3::new(rho * th.cos(), rho * th.sin(), s);
        let want = analytic(u.x, rho * th.cos(), rho * th.sin());
        let got = flow.velocity(u, x);
        assert!((got - want).length() < 1e-12 * u.x, "{got} {want}");
    }
    // the surface: no normal flow; 2U at the sides; rest at the stagnation lines
    for k in 0..64 {
        let th = k as f64 / 64.0 * std::f64::consts::TAU;
        let n = DVec3::new(th.cos(), th.sin(), 0.0);
        let v = flow.velocity(u, f.center + A * (1.0 + 1e-12) * n);
        assert!(v.dot(n).abs() < 1e-9 * u.x, "{}", v.dot(n));
    }
    let side = flow.velocity(u, f.center + A * (1.0 + 1e-12) * DVec3::Y);
    assert!((side - 2.0 * u).length() < 1e-9 * u.x);
    let front = flow.velocity(u, f.center - A * (1.0 + 1e-12) * DVec3::X);
    assert!(front.length() < 1e-9 * u.x);
    // flow along the axis passes unchanged
    let along = DVec3::new(0.0, 0.0, 1e-2);
    assert_eq!(flow.velocity(along, f.center + 1.5 * A * DVec3::X), along);
}

#[test]
fn the_flow_is_divergence_free_where_it_is_not_truncated() {
    let f = FlowFibre {
        axis: DVec3::new(1.0, 2.0, -0.5).normalize(),
        ..long_fibre()
    };
    let flow = FibreFlow::new(vec![f]);
    let u = DVec3::new(1e-2, -2e-2, 0.7e-2);
    let e1 = f.axis.any_orthonormal_vector();
    let e2 = f.axis.cross(e1);
    let h = 1e-4 * A;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
    for _ in 0..200 {
        let rho = A * rng.random_range(1.2..NEAR - 0.2);
        let th = rng.random_range(0.0..std::f64::consts::TAU);
        let s = rng.random_range(-80.0 * A..80.0 * A);
        let x = f.center + rho * (th.cos() * e1 + th.sin() * e2) + s * f.axis;
        let mut div = 0.0;
        for d in [DVec3::X, DVec3::Y, DVec3::Z] {
            div += (flow.velocity(u, x + h * d) - flow.velocity(u, x - h * d)).dot(d) / (2.0 * h);
        }
        // |∇u| ~ |u| / a: the finite differences resolve divergence to ~1e-7 of it
        assert!(div.abs() < 1e-6 * u.length() / A, "{div}");
    }
}

#[test]
fn the_perturbation_is_continuous_and_ends_at_the_cutoff() {
    let f = long_fibre();
    let u = DVec3::new(1e-2, 0.0, 0.0);
    let at = |rho: f64, s: f64| f.perturbation(u, f.center + DVec3::new(0.0, rho, s));
    for r in [NEAR, CUTOFF] {
        let (a, b) = (at(r * A * (1.0 - 1e-9), 0.0), at(r * A * (1.0 + 1e-9), 0.0));
        assert!((a - b).length() < 1e-9 * u.x, "{a} {b}");
        let end = f.half_length;
        let (a, b) = (
            at(0.0, end + r * A * (1.0 - 1e-9)),
            at(0.0, end + r * A * (1.0 + 1e-9)),
        );
        assert!((a - b).length() < 1e-9 * u.x, "{a} {b}");
    }
    assert_eq!(at(CUTOFF * A, 0.0), DVec3::ZERO);
    assert_eq!(at(0.0, f.half_length + CUTOFF * A), DVec3::ZERO);
    assert!(at(0.5 * CUTOFF * A + 0.5 * NEAR * A, 0.0).length() > 0.0);
    assert!(at(0.0, f.half_length + 0.5 * (CUTOFF + NEAR) * A).length() > 0.0);
}

#[test]
fn no_streamline_ends_on_a_short_fibre_and_the_liquid_inside_is_still() {
    // a short tilted fibre in a flow at an angle: on its side and on the half spheres over its
    // faces the liquid moves along the surface; inside the body it is at rest
    let f = FlowFibre {
        center: DVec3::new(0.3e-3, 0.1e-3, -0.2e-3),
        axis: DVec3::new(0.3, -0.4, 1.0).normalize(),
        radius: A,
        half_length: 3.0 * A,
    };
    let flow = FibreFlow::new(vec![f]);
    let u = DVec3::new(0.2e-2, 1e-2, -3e-2);
    let e1 = f.axis.any_orthonormal_vector();
    let e2 = f.axis.cross(e1);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    for _ in 0..400 {
        let th = rng.random_range(0.0..std::f64::consts::TAU);
        let radial = th.cos() * e1 + th.sin() * e2;
        // the side
        let s = rng.random_range(-f.half_length..f.half_length);
        let v = flow.velocity(u, f.center + s * f.axis + A * (1.0 + 1e-12) * radial);
        assert!(v.dot(radial).abs() < 1e-9 * u.length(), "{}", v.dot(radial));
        // a half sphere
        let end = f.center + f.half_length * f.axis;
        let ph = rng.random_range(0.0..std::f64::consts::FRAC_PI_2);
        let n = ph.cos() * f.axis + ph.sin() * radial;
        let v = flow.velocity(u, end + A * (1.0 + 1e-12) * n);
        assert!(v.dot(n).abs() < 1e-9 * u.length(), "{}", v.dot(n));
        // inside, on the side and in front of a face
        assert_eq!(
            flow.velocity(u, f.center + s * f.axis + 0.9 * A * radial),
            DVec3::ZERO
        );
        assert_eq!(flow.velocity(u, end + 0.9 * A * n), DVec3::ZERO);
    }
}

#[test]
fn the_grid_gives_the_direct_sum_bit_for_bit() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(21);
    let fibres: Vec<FlowFibre> = (0..60)
        .map(|_| FlowFibre {
            center: DVec3::new(
                rng.random_range(0.0..8e-3),
                rng.random_range(0.0..8e-3),
                rng.random_range(0.0..10e-3),
            ),
            axis: DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize(),
            radius: A * rng.random_range(0.5..1.5),
            half_length: rng.random_range(1e-3..3.5e-3),
        })
        .collect();
    let flow = FibreFlow::new(fibres);
    let u = DVec3::new(0.0, 0.0, 5e-2);
    let mut nonzero = 0;
    for _ in 0..5000 {
        let x = DVec3::new(
            rng.random_range(-2e-3..10e-3),
            rng.random_range(-2e-3..10e-3),
            rng.random_range(-3e-3..13e-3),
        );
        let (g, d) = (flow.perturbation(u, x), flow.perturbation_direct(u, x));
        assert_eq!(g, d);
        nonzero += usize::from(d != DVec3::ZERO);
    }
    assert!(nonzero > 1000, "{nonzero}");
    // far outside, and with no fibres at all: nothing
    assert_eq!(flow.perturbation(u, DVec3::splat(1.0)), DVec3::ZERO);
    assert_eq!(FibreFlow::new(Vec::new()).velocity(u, DVec3::ZERO), u);
}
