//! Fast validation tests of the channel solver: laminar Poiseuille flow, decaying Stokes
//! modes, forced steady states, divergence.

use super::grid::ChannelGrid;
use super::solver::ChannelParams;
use super::stepper::ChannelSolver;
use std::f64::consts::PI;

/// Deterministic pseudo-random numbers in [-1, 1) (xorshift64*).
pub(crate) struct Rng(pub(crate) u64);
impl Rng {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let v = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (v >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// A field from a function of the node position.
pub(crate) fn field(g: &ChannelGrid, f: impl Fn(f64, f64, f64) -> f64) -> Vec<f64> {
    let mut v = vec![0.0; g.len()];
    for k in 0..g.nz {
        for i in 0..g.nx {
            for j in 0..g.ny {
                v[g.index(i, j, k)] = f(g.x(i), g.y(j), g.z(k));
            }
        }
    }
    v
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn poiseuille_from_rest_and_exact_start() {
    let (nu, h, gx) = (1.0e-3, 0.5, 4.0e-3);
    let g = ChannelGrid::new([4, 4, 17], [1.0, 1.0, h]).unwrap();
    let mut p = ChannelParams::new(g, nu, 2.0);
    p.mean_pressure_gradient = [gx, 0.0];
    let exact = |z: f64| gx / (2.0 * nu) * z * (h - z);
    let umax = exact(0.5 * h);
    let mut s = ChannelSolver::new(p).unwrap();
    // slowest decay rate ν π²/h² ≈ 0.039/s: t = 1000 s gives e^-39
    for _ in 0..500 {
        s.step();
    }
    let ex = field(&g, |_, _, z| exact(z));
    let err = max_abs_diff(s.velocity()[0], &ex) / umax;
    println!("Poiseuille from rest: max rel error {err:.2e}");
    assert!(err < 1e-12, "{err}");
    assert!(
        s.velocity()[1]
            .iter()
            .chain(s.velocity()[2])
            .all(|v| v.abs() < 1e-14 * umax)
    );
    // wall shear balances the pressure gradient: ν U'(0) − ν U'(h) = G h
    let ws = s.wall_shear();
    let bal = ((ws[0][0] - ws[1][0]) - gx * h).abs() / (gx * h);
    println!("Poiseuille wall-shear balance rel error {bal:.2e}");
    assert!(bal < 1e-12);
    // vorticity ω_y = ∂U/∂z
    let oy = field(&g, |_, _, z| gx / (2.0 * nu) * (h - 2.0 * z));
    let verr = max_abs_diff(s.vorticity()[1], &oy) / (umax / h);
    assert!(verr < 1e-11, "{verr}");
    // exact start stays
    let mut s = ChannelSolver::new(p).unwrap();
    let zero = vec![0.0; g.len()];
    s.set_velocity([&ex, &zero, &zero]).unwrap();
    let e0 = max_abs_diff(s.velocity()[0], &ex) / umax;
    for _ in 0..50 {
        s.step();
    }
    let e1 = max_abs_diff(s.velocity()[0], &ex) / umax;
    println!("Poiseuille exact start: rel error {e0:.2e} after set, {e1:.2e} after 50 steps");
    assert!(e0 < 1e-14 && e1 < 1e-13, "{e0} {e1}");
    let mv = s.mean_velocity();
    let mean_exact = gx * h * h / (12.0 * nu);
    assert!((mv.x - mean_exact).abs() < 1e-13 * mean_exact, "{mv}");
}

/// Decaying Stokes modes `u = A sin(k·x_h) sin(nπz/h)` (a horizontal velocity normal to the
/// horizontal wavevector): exact NS solutions decaying at `ν (k² + (nπ/h)²)`. Returns the max
/// relative error at `t_end` for the given step count.
fn stokes_mode_error(steps: usize, t_end: f64) -> f64 {
    let (nu, lx, ly, h) = (0.01, 2.0, 1.0, 1.0);
    let g = ChannelGrid::new([8, 8, 25], [lx, ly, h]).unwrap();
    let mut s = ChannelSolver::new(ChannelParams::new(g, nu, t_end / steps as f64)).unwrap();
    let (ky, kx) = (2.0 * PI / ly, 2.0 * PI / lx);
    // u_x varies along y with n = 1, u_y varies along x with n = 2
    let ux = |y: f64, z: f64, t: f64| {
        (ky * y).sin() * (PI * z / h).sin() * (-nu * (ky * ky + (PI / h).powi(2)) * t).exp()
    };
    let uy = |x: f64, z: f64, t: f64| {
        0.5 * (kx * x).cos()
            * (2.0 * PI * z / h).sin()
            * (-nu * (kx * kx + (2.0 * PI / h).powi(2)) * t).exp()
    };
    // separate runs: together the two modes interact through the nonlinear term
    let zero = vec![0.0; g.len()];
    let u0 = field(&g, |_, y, z| ux(y, z, 0.0));
    s.set_velocity([&u0, &zero, &zero]).unwrap();
    for _ in 0..steps {
        s.step();
    }
    let t = s.time();
    let e1 = max_abs_diff(s.velocity()[0], &field(&g, |_, y, z| ux(y, z, t)));
    let v0 = field(&g, |x, _, z| uy(x, z, 0.0));
    let mut s = ChannelSolver::new(*s.params()).unwrap();
    s.set_velocity([&zero, &v0, &zero]).unwrap();
    for _ in 0..steps {
        s.step();
    }
    let e2 = max_abs_diff(s.velocity()[1], &field(&g, |x, _, z| uy(x, z, t)));
    e1.max(e2)
}

#[test]
fn stokes_modes_decay_at_the_exact_rate_second_order() {
    let t_end = 5.0;
    let e: Vec<f64> = [10, 20, 40]
        .iter()
        .map(|n| stokes_mode_error(*n, t_end))
        .collect();
    println!(
        "Stokes modes: errors {e:?}, ratios {:.3} {:.3}",
        e[0] / e[1],
        e[1] / e[2]
    );
    assert!(e[2] < 1e-4, "{e:?}");
    for r in [e[0] / e[1], e[1] / e[2]] {
        assert!((3.6..4.4).contains(&r), "order: {r}");
    }
}

/// Steady state of `ν ∇²u + f = 0` with `f = F sin(k y) x̂ + F cos(k' x) ŷ`: the z-vorticity
/// equation's sign is checked through the body-force term.
#[test]
fn forced_steady_states_match_closed_form() {
    let (nu, lx, ly, h, f0) = (0.05, 2.0, 1.0, 1.0, 0.3);
    let g = ChannelGrid::new([8, 8, 25], [lx, ly, h]).unwrap();
    let p = ChannelParams::new(g, nu, 0.1);
    let (kx, ky) = (2.0 * PI / lx, 2.0 * PI / ly);
    let prof = |k: f64, z: f64| {
        f0 / (nu * k * k) * (1.0 - (k * (z - 0.5 * h)).cosh() / (0.5 * k * h).cosh())
    };
    let fx = field(&g, |_, y, _| f0 * (ky * y).sin());
    let fy = field(&g, |x, _, _| f0 * (kx * x).cos());
    let ux = field(&g, |_, y, z| (ky * y).sin() * prof(ky, z));
    let uy = field(&g, |x, _, z| (kx * x).cos() * prof(kx, z));
    let scale = f0 / (nu * ky * ky);
    let mut e = 0.0f64;
    // separate runs: together the two flows interact through the nonlinear term
    for c in 0..2 {
        let mut s = ChannelSolver::new(p).unwrap();
        // Crank-Nicolson damps the stiffest modes slowly at large ν Δt/Δz², hence Δt = 0.1 s
        for _ in 0..800 {
            s.body_force_mut()[c].copy_from_slice(if c == 0 { &fx } else { &fy });
            s.step();
        }
        let ex = if c == 0 { &ux } else { &uy };
        e = e.max(max_abs_diff(s.velocity()[c], ex) / scale);
        // the self-interaction u × ω of this flow is a gradient; only the collocation
        // (z-aliasing) error of the product leaves a trace in the other components
        let zero = vec![0.0; g.len()];
        let other =
            max_abs_diff(s.velocity()[1 - c], &zero).max(max_abs_diff(s.velocity()[2], &zero));
        println!(
            "forced steady state {c}: spurious components {:.2e}",
            other / scale
        );
        assert!(other < 1e-10 * scale);
    }
    println!("forced steady state: max rel error {e:.2e}");
    assert!(e < 1e-10, "{e}");
}

/// A random projected field under a random body force stays divergence-free to rounding.
#[test]
fn divergence_stays_at_round_off() {
    let g = ChannelGrid::new([16, 12, 17], [1.0, 0.8, 0.5]).unwrap();
    let mut s = ChannelSolver::new(ChannelParams::new(g, 1e-3, 2e-4)).unwrap();
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let u: Vec<Vec<f64>> = (0..3)
        .map(|_| (0..g.len()).map(|_| rng.next()).collect())
        .collect();
    s.set_velocity([&u[0], &u[1], &u[2]]).unwrap();
    let f: Vec<Vec<f64>> = (0..3)
        .map(|_| (0..g.len()).map(|_| rng.next()).collect())
        .collect();
    let umax = |s: &ChannelSolver| {
        s.velocity()
            .iter()
            .flat_map(|c| c.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    // derivative scale: velocity over the finest spacing
    let dzmin = g.z(1);
    let d0 = s.divergence_max() / (umax(&s) / dzmin);
    for _ in 0..10 {
        let [a, b, c] = s.body_force_mut();
        a.copy_from_slice(&f[0]);
        b.copy_from_slice(&f[1]);
        c.copy_from_slice(&f[2]);
        s.step();
    }
    let d1 = s.divergence_max() / (umax(&s) / dzmin);
    println!(
        "divergence relative to max|u|/dz_min: {d0:.2e} after projection, {d1:.2e} after 10 steps"
    );
    assert!(d0 < 1e-12 && d1 < 1e-12, "{d0} {d1}");
    assert!(s.velocity().iter().all(|c| c.iter().all(|v| v.is_finite())));
}

/// The least-damped even Stokes mode of the clamped z-velocity: `w = W(z) cos(k x) e^{−σt}`,
/// `W = cos(p ζ)/cos(p a) − cosh(k ζ)/cosh(k a)` with `ζ = z − a`, `a = h/2`,
/// `p tan(p a) = −k tanh(k a)` and `σ = ν (k² + p²)`: an exact solution of the Navier-Stokes
/// equations (its nonlinear term is a gradient only to first order, so the amplitude is
/// small). Returns the max error relative to the amplitude at `t_end`.
fn stokes_w_mode_error(steps: usize, t_end: f64) -> f64 {
    let (nu, lx, h) = (0.02, 2.0, 1.0);
    let g = ChannelGrid::new([8, 4, 33], [lx, 1.0, h]).unwrap();
    let mut s = ChannelSolver::new(ChannelParams::new(g, nu, t_end / steps as f64)).unwrap();
    let (k, a) = (2.0 * PI / lx, 0.5 * h);
    let f = |p: f64| p * (p * a).tan() + k * (k * a).tanh();
    let (mut lo, mut hi) = (PI / (2.0 * a) + 1e-12, PI / a - 1e-12);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 { lo = mid } else { hi = mid }
    }
    let p = 0.5 * (lo + hi);
    let sigma = nu * (k * k + p * p);
    let amp = 1e-6;
    let ww = |z: f64| {
        amp * ((p * (z - a)).cos() / (p * a).cos() - (k * (z - a)).cosh() / (k * a).cosh())
    };
    let dw = |z: f64| {
        amp * (-p * (p * (z - a)).sin() / (p * a).cos() - k * (k * (z - a)).sinh() / (k * a).cosh())
    };
    let u0 = field(&g, |x, _, z| -dw(z) * (k * x).sin() / k);
    let w0 = field(&g, |x, _, z| ww(z) * (k * x).cos());
    s.set_velocity([&u0, &vec![0.0; g.len()], &w0]).unwrap();
    for _ in 0..steps {
        s.step();
    }
    let decay = (-sigma * s.time()).exp();
    let w1 = field(&g, |x, _, z| ww(z) * (k * x).cos() * decay);
    let u1 = field(&g, |x, _, z| -dw(z) * (k * x).sin() / k * decay);
    let wmax = w0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    max_abs_diff(s.velocity()[2], &w1).max(max_abs_diff(s.velocity()[0], &u1)) / wmax
}

#[test]
fn stokes_w_mode_decays_at_the_exact_rate_second_order() {
    let t_end = 4.0;
    let e: Vec<f64> = [10, 20, 40]
        .iter()
        .map(|n| stokes_w_mode_error(*n, t_end))
        .collect();
    println!(
        "Stokes w-mode: rel errors {e:?}, ratios {:.3} {:.3}",
        e[0] / e[1],
        e[1] / e[2]
    );
    assert!(e[2] < 1e-3, "{e:?}");
    for r in [e[0] / e[1], e[1] / e[2]] {
        assert!((3.6..4.4).contains(&r), "order: {r}");
    }
}
