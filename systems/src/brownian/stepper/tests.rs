use super::*;
use crate::rng::particle_stream;

/// Independent particles in a potential `U(x)` per component, free-draining mobility `mu`.
struct Independent<F: Fn(DVec3) -> DVec3> {
    radii: Vec<f64>,
    mobile: Vec<bool>,
    mu: f64,
    kt: f64,
    force: F,
}

impl<F: Fn(DVec3) -> DVec3> Dynamics for Independent<F> {
    fn radii(&self) -> &[f64] {
        &self.radii
    }
    fn mobile(&self) -> &[bool] {
        &self.mobile
    }
    fn drift(&mut self, x: &[DVec3], v: &mut [DVec3]) {
        for (vi, xi) in v.iter_mut().zip(x) {
            *vi = (self.force)(*xi) * self.mu;
        }
    }
    fn noise(&mut self, w: &[DVec3], out: &mut [DVec3]) {
        let s = (2.0 * self.kt * self.mu).sqrt();
        for (o, wi) in out.iter_mut().zip(w) {
            *o = *wi * s;
        }
    }
}

fn particles<F: Fn(DVec3) -> DVec3>(n: usize, force: F) -> Independent<F> {
    Independent {
        radii: vec![1.0; n],
        mobile: vec![true; n],
        mu: 1.0,
        kt: 1.0,
        force,
    }
}

fn adaptive(tolerance: f64, max_displacement: f64) -> StepControl {
    StepControl::Adaptive {
        tolerance,
        max_displacement,
        max_depth: 30,
    }
}

fn msd(control: StepControl, n: usize, steps: usize, dt: f64) -> (f64, BrownianStats) {
    let mut d = particles(n, |_| DVec3::ZERO);
    let mut x = vec![DVec3::ZERO; n];
    let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(9, i)).collect();
    let mut stats = BrownianStats::default();
    for _ in 0..steps {
        advance(&mut d, &mut x, None, dt, &control, &mut rngs, &mut stats);
    }
    let m = x.iter().map(|p| p.length_squared()).sum::<f64>() / n as f64;
    (m, stats)
}

#[test]
fn free_particle_msd_is_6dt_fixed_and_adaptive() {
    // D = kT mu = 1; MSD = 6 D t. 4e4 particles: relative standard error sqrt(2/3/4e4) = 0.4 %.
    let (n, steps, dt) = (40_000, 5, 0.2);
    let t = steps as f64 * dt;
    let (m, _) = msd(StepControl::Fixed, n, steps, dt);
    assert!((m / (6.0 * t) - 1.0).abs() < 0.02, "fixed: {m}");
    // a small displacement cap forces deep bisection of the same path: statistics unchanged
    let (m, stats) = msd(adaptive(1e-3, 0.3), n, steps, dt);
    assert!(
        stats.rejections > 0 && stats.max_depth_reached >= 4,
        "{stats:?}"
    );
    assert!((m / (6.0 * t) - 1.0).abs() < 0.02, "adaptive: {m}");
}

#[test]
fn bisection_refines_the_same_path() {
    // no drift: the end point is the sum of the bridge increments, i.e. the top-level W
    let n = 50;
    let mut x_fixed = vec![DVec3::ZERO; n];
    let mut x_adapt = vec![DVec3::ZERO; n];
    let mut stats = BrownianStats::default();
    for (x, control) in [
        (&mut x_fixed, StepControl::Fixed),
        (&mut x_adapt, adaptive(1e-3, 0.05)),
    ] {
        let mut d = particles(n, |_| DVec3::ZERO);
        let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(1, i)).collect();
        advance(&mut d, x, None, 1.0, &control, &mut rngs, &mut stats);
    }
    assert!(stats.max_depth_reached >= 6);
    for (a, b) in x_fixed.iter().zip(&x_adapt) {
        assert!((*a - *b).length() < 1e-12 * (1.0 + a.length()), "{a} {b}");
    }
}

#[test]
fn stiff_trap_fixed_step_diverges_adaptive_is_stable_with_boltzmann_variance() {
    // U = k x²/2 with mu k dt = 5: explicit Euler multiplies x by (1 − 5) = −4 per step.
    let k = 5.0;
    let n = 4000;
    let run = |control: StepControl| {
        let mut d = particles(n, move |x| -x * k);
        let mut x = vec![DVec3::splat(0.1); n];
        let mut rngs: Vec<_> = (0..n as u64).map(|i| particle_stream(3, i)).collect();
        let mut stats = BrownianStats::default();
        for _ in 0..40 {
            advance(&mut d, &mut x, None, 1.0, &control, &mut rngs, &mut stats);
        }
        let var = x.iter().map(|p| p.length_squared()).sum::<f64>() / (3.0 * n as f64);
        (var, stats)
    };
    let (var_fixed, _) = run(StepControl::Fixed);
    assert!(
        var_fixed.is_nan() || var_fixed >= 1e6,
        "fixed step should blow up, variance {var_fixed}"
    );
    let (var, stats) = run(adaptive(1e-3, 0.5));
    // Boltzmann: <x²> = kT / k = 0.2 per component (Euler's own bias ~ mu k h / 2 is small at
    // the accepted sub-steps); standard error sqrt(2/12000) = 1.3 %
    assert!(
        (var / 0.2 - 1.0).abs() < 0.05,
        "adaptive variance {var}, {stats:?}"
    );
    assert!(stats.depth_limit_hits == 0);
}

#[test]
fn deterministic_error_decreases_with_tolerance() {
    // dx/dt = −x³ from x0 = 3 (stiff early): x(t) = x0 / sqrt(1 + 2 x0² t)
    let exact = 3.0 / (1.0f64 + 2.0 * 9.0 * 1.0).sqrt();
    let mut last = f64::INFINITY;
    for tol in [1e-2, 1e-3, 1e-4, 1e-5] {
        let mut d = particles(1, |x| -x * x * x);
        d.kt = 0.0;
        let mut x = vec![DVec3::new(3.0, 0.0, 0.0)];
        let mut rngs = vec![particle_stream(0, 0)];
        let mut stats = BrownianStats::default();
        advance(
            &mut d,
            &mut x,
            None,
            1.0,
            &adaptive(tol, 10.0),
            &mut rngs,
            &mut stats,
        );
        let e = (x[0].x - exact).abs();
        assert!(e < last, "tol {tol}: error {e} >= {last}");
        eprintln!("tol {tol}: error {e}, substeps {}", stats.substeps);
        // Euler: local error ~ h², so the global error ~ h ~ sqrt(tol)
        assert!(e < 0.5 * tol.sqrt(), "tol {tol}: error {e}");
        last = e;
    }
}
