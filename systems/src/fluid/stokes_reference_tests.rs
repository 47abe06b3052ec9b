//! Tests of the unsteady-Stokes reference (module `stokes_reference`).

use super::*;

/// Unit sphere (`a = ν = μ = ρ_f = 1`, `ρ_p = 2.5`, `F = 1`): `b = c = 1.5`, `τ = 2/3`.
fn unit() -> StokesRelease {
    StokesRelease::new(1.0, 2.5, 1.0, 1.0, 1.0)
}

/// A 1 mm glass bead in water (SI).
fn bead() -> StokesRelease {
    StokesRelease::gravitational(0.5e-3, 2500.0, 1000.0, 1e-3, 9.81)
}

/// Exact no-history solution `(v, x)`.
fn exponential(p: &StokesRelease, t: f64) -> (f64, f64) {
    let (vi, tau, v0) = (
        p.terminal_velocity(),
        p.relaxation_time(),
        p.initial_velocity,
    );
    let e = (-t / tau).exp();
    (
        vi + (v0 - vi) * e,
        vi * t + (v0 - vi) * tau * (-(-t / tau).exp_m1()),
    )
}

fn gamma_half(k: u32) -> f64 {
    // Γ(k + 1/2)
    (1..=k).fold(PI.sqrt(), |g, j| g * (j as f64 - 0.5))
}

#[test]
fn complex_helpers() {
    let z = Complex::new(-4.0, 1e-30);
    let r = principal_sqrt(z);
    assert!((r.re - 0.5e-30 / 2.0).abs() < 1e-40 && (r.im - 2.0).abs() < 1e-15);
    let w = Complex::new(3.0, -4.0);
    let q = principal_sqrt(w);
    assert!(((q * q) - w).re.abs() < 1e-14 && ((q * q) - w).im.abs() < 1e-14);
    let one = w * w.finv();
    assert!((one.re - 1.0).abs() < 1e-15 && one.im.abs() < 1e-15);
    assert_eq!(
        principal_sqrt(Complex::new(0.0, 0.0)),
        Complex::new(0.0, 0.0)
    );
    // Agrees with num-complex's polar square root away from the cut.
    let p = Complex::new(-1.5, 2.5);
    assert!((principal_sqrt(p) - p.sqrt()).norm() < 1e-15);
    let e = Complex::new(0.0, PI).exp();
    assert!((e.re + 1.0).abs() < 1e-15 && e.im.abs() < 1e-15);
}

#[test]
fn talbot_accuracy_against_the_exponential() {
    let mut chosen = 0.0;
    for nodes in [12, 16, 20, 24, 28, 32, 40] {
        let mut worst: f64 = 0.0;
        for p in [unit(), bead()] {
            for v0 in [0.0, 0.4, -1.0] {
                let q = p
                    .without_history()
                    .with_initial_velocity(v0 * p.terminal_velocity());
                let tau = q.relaxation_time();
                for f in [1e-4, 1e-2, 0.3, 1.0, 3.0, 10.0, 100.0] {
                    let t = f * tau;
                    let (v, x) = exponential(&q, t);
                    let vt = talbot(|s| q.velocity_transform(s), t, nodes);
                    let xt = talbot(|s| q.velocity_transform(s) / s, t, nodes);
                    let sv = v.abs().max(1e-3 * q.terminal_velocity().abs());
                    let sx = x.abs().max(1e-3 * q.terminal_velocity().abs() * t);
                    worst = worst.max((vt - v).abs() / sv).max((xt - x).abs() / sx);
                }
            }
        }
        eprintln!("Talbot N = {nodes}: max rel. error vs exponential {worst:.2e}");
        if nodes == TALBOT_NODES {
            chosen = worst;
        }
    }
    assert!(chosen < 1e-10, "{chosen}");
}

#[test]
fn talbot_converges_in_nodes_with_history() {
    for nodes in [16, 20, 28] {
        let mut worst: f64 = 0.0;
        for p in [unit(), bead(), unit().with_initial_velocity(0.3)] {
            for f in [1e-3, 0.1, 1.0, 30.0, 3000.0] {
                let t = f * p.viscous_time();
                let a = talbot(|s| p.velocity_transform(s), t, nodes);
                let b = talbot(|s| p.velocity_transform(s), t, 24);
                worst = worst.max((a - b).abs() / a.abs());
            }
        }
        eprintln!("Talbot N = {nodes} vs N = 24 with history: max rel. diff {worst:.2e}");
    }
    for p in [unit(), bead(), unit().with_initial_velocity(0.3)] {
        for f in [1e-3, 0.1, 1.0, 30.0, 3000.0] {
            let t = f * p.viscous_time();
            let a = talbot(|s| p.velocity_transform(s), t, TALBOT_NODES);
            let b = talbot(|s| p.velocity_transform(s), t, TALBOT_NODES + 8);
            assert!((a - b).abs() < 1e-10 * a.abs(), "{f}: {a} {b}");
        }
    }
}

#[test]
fn without_history_matches_the_exact_exponential() {
    for p in [unit(), bead()] {
        for v0 in [0.0, 0.5, -2.0] {
            let q = p
                .without_history()
                .with_initial_velocity(v0 * p.terminal_velocity());
            for k in 0..40 {
                let t = q.relaxation_time() * 1e-3 * 1.3f64.powi(k);
                let (v, x) = exponential(&q, t);
                let floor = 1e-6 * q.terminal_velocity().abs();
                assert!(
                    (q.velocity(t) - v).abs() <= 1e-9 * v.abs().max(floor),
                    "t={t}"
                );
                assert!(
                    (q.position(t) - x).abs() <= 1e-9 * x.abs().max(floor * t),
                    "t={t}"
                );
            }
        }
    }
}

#[test]
fn small_time_series() {
    // v = (F/M)[t − b t^{3/2}/Γ(5/2) + (b²−c) t²/2 + (2bc−b³) t^{5/2}/Γ(7/2)] + O(t³)
    let p = unit();
    let m = p.effective_mass();
    let b = p.history_coefficient() * PI.sqrt() / m;
    let c = p.drag_coefficient() / m;
    let a = p.force / m;
    let terms = |t: f64| {
        [
            a * t,
            -a * b * t.powf(1.5) / gamma_half(2),
            a * (b * b - c) * t * t / 2.0,
            a * (2.0 * b * c - b * b * b) * t.powf(2.5) / gamma_half(3),
        ]
    };
    // remainder after L terms ∝ t^{(L+2)/2}
    let (t1, t2) = (4e-3, 1e-3);
    for l in 1..=4 {
        let rem = |t: f64| p.velocity(t) - terms(t)[..l].iter().sum::<f64>();
        let order = (rem(t1) / rem(t2)).abs().ln() / (t1 / t2).ln();
        let expect = (l + 2) as f64 / 2.0;
        eprintln!("small-t series, {l} terms: remainder order {order:.4} (expected {expect})");
        assert!((order - expect).abs() < 0.06, "{l}: {order}");
    }
    // leading history correction: v ≈ (F/M)(t − (4/3)(c_H/M) t^{3/2})
    assert!((b / gamma_half(2) - 4.0 / 3.0 * p.history_coefficient() / m).abs() < 1e-14);
    // initial velocity: v0 [1 − b √t/Γ(3/2) + (b² − c) t + (2bc − b³) t^{3/2}/Γ(5/2)] + O(t²)
    let q = p.with_initial_velocity(0.7);
    let v0_terms = |t: f64| {
        let v0 = 0.7;
        [
            v0,
            -v0 * b * t.sqrt() / gamma_half(1),
            v0 * (b * b - c) * t,
            v0 * (2.0 * b * c - b * b * b) * t.powf(1.5) / gamma_half(2),
        ]
    };
    for l in 1..=4 {
        let lf = [1, 2, 2, 3][l - 1];
        let rem = |t: f64| {
            q.velocity(t)
                - terms(t)[..lf].iter().sum::<f64>()
                - v0_terms(t)[..l].iter().sum::<f64>()
        };
        let order = (rem(t1) / rem(t2)).abs().ln() / (t1 / t2).ln();
        let expect = l as f64 / 2.0;
        eprintln!(
            "small-t series with v0, {l} terms: remainder order {order:.4} (expected {expect})"
        );
        assert!((order - expect).abs() < 0.06, "{l}: {order}");
    }
}

#[test]
fn large_time_basset_tail() {
    for p in [unit(), bead(), unit().with_initial_velocity(0.2)] {
        let vi = p.terminal_velocity();
        let tau = p.relaxation_time();
        let beta = p.history_coefficient() * PI.sqrt() / p.drag_coefficient();
        // β = a/√ν
        assert!((beta - p.radius / (p.viscosity / p.fluid_density).sqrt()).abs() < 1e-12 * beta);
        let one = |t: f64| vi * beta / (PI * t).sqrt();
        let two = |t: f64| {
            one(t)
                - (vi * (beta.powi(3) - 2.0 * beta * tau) + tau * p.initial_velocity * beta)
                    / (2.0 * PI.sqrt())
                    * t.powf(-1.5)
        };
        let mut rel1 = Vec::new();
        for f in [1e3, 1e4] {
            let t = f * p.viscous_time();
            let deficit = vi - p.velocity(t);
            rel1.push((deficit / one(t) - 1.0).abs());
            let rel2 = (deficit / two(t) - 1.0).abs();
            // local slope of the deficit: −1/2
            let slope = ((vi - p.velocity(1.1 * t)) / deficit).ln() / 1.1f64.ln();
            eprintln!(
                "t = {f:.0e} a²/ν: deficit/one-term − 1 = {:.2e}, two-term {rel2:.2e}, slope {slope:.5}",
                rel1.last().unwrap()
            );
            assert!(rel2 < 1e-5, "{rel2}");
            assert!((slope + 0.5).abs() < 3e-3, "{slope}");
        }
        // the one-term asymptote's relative error falls like 1/t
        let ratio = rel1[0] / rel1[1];
        assert!((ratio.log10() - 1.0).abs() < 0.05, "{ratio}");
    }
}

#[test]
fn position_is_the_integral_of_velocity() {
    for p in [unit(), bead().with_initial_velocity(-0.01)] {
        for f in [1e-2, 0.3, 1.0, 5.0, 50.0] {
            let t = f * p.relaxation_time();
            let h = 1e-3 * t;
            let fd = (p.position(t + h) - p.position(t - h)) / (2.0 * h);
            let v = p.velocity(t);
            assert!(
                (fd - v).abs() < 1e-6 * v.abs().max(1e-3 * p.terminal_velocity().abs()),
                "{f}: {fd} {v}"
            );
        }
        // x(t) → v_∞ t − 2v_∞β√(t/π) + v_∞(β² − τ) + τ v0 + O(t^{−1/2})
        let (vi, tau) = (p.terminal_velocity(), p.relaxation_time());
        let beta = p.history_coefficient() * PI.sqrt() / p.drag_coefficient();
        let mut errs = Vec::new();
        for f in [1e3, 1e5] {
            let t = f * p.viscous_time();
            let asym = vi * t - 2.0 * vi * beta * (t / PI).sqrt()
                + vi * (beta * beta - tau)
                + tau * p.initial_velocity;
            errs.push((p.position(t) - asym).abs());
        }
        // O(t^{−1/2}): a factor 10 over a factor 100 in time
        let ratio = errs[0] / errs[1];
        eprintln!(
            "position asymptote errors {:.2e} {:.2e} (ratio {ratio:.2})",
            errs[0], errs[1]
        );
        assert!((ratio.log10() - 1.0).abs() < 0.1, "{ratio}");
    }
}

/// Independent solution of the integrated equation of motion
/// `M(v − v0) = F t − k x − c_H ∫_0^t v(τ)(t − τ)^{−1/2} dτ`
/// (the time integral of the BBO equation, jump term included), by the product trapezoidal
/// rule (`v` piecewise linear, kernel integrated exactly) and the trapezoidal `x`, `n` steps
/// to `t_end`. Returns `v(t_end)`.
fn volterra_velocity(p: &StokesRelease, t_end: f64, n: usize) -> f64 {
    let h = t_end / n as f64;
    let (m, k, c_h, f, v0) = (
        p.effective_mass(),
        p.drag_coefficient(),
        p.history_coefficient(),
        p.force,
        p.initial_velocity,
    );
    // weights of v_k (older end, α_j) and v_{k+1} (newer end, β_j) for the interval at lag j
    let (mut alpha, mut beta) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for j in 0..n {
        let jf = j as f64;
        let p0 = 2.0 * h.sqrt() / ((jf + 1.0).sqrt() + jf.sqrt());
        let p1 = 2.0 / 3.0 * h.powf(1.5) * (3.0 * jf * jf + 3.0 * jf + 1.0)
            / ((jf + 1.0).powf(1.5) + jf.powf(1.5));
        alpha.push((p1 - jf * h * p0) / h);
        beta.push(((jf + 1.0) * h * p0 - p1) / h);
    }
    let mut v = vec![v0];
    let mut x = 0.0;
    for step in 1..=n {
        let mut known = 0.0;
        for kk in 0..step {
            let j = step - 1 - kk;
            known += alpha[j] * v[kk];
            if kk + 1 < step {
                known += beta[j] * v[kk + 1];
            }
        }
        let t = step as f64 * h;
        let prev = v[step - 1];
        let vn = (m * v0 + f * t - k * (x + 0.5 * h * prev) - c_h * known)
            / (m + 0.5 * k * h + c_h * beta[0]);
        x += 0.5 * h * (prev + vn);
        v.push(vn);
    }
    v[n]
}

#[test]
fn agrees_with_an_independent_time_stepping_solution() {
    for p in [unit(), unit().with_initial_velocity(0.1), bead()] {
        for f in [0.2, 1.0, 4.0] {
            let t = f * p.relaxation_time();
            let v = [400, 800, 1600].map(|n| volterra_velocity(&p, t, n));
            let order = ((v[0] - v[1]) / (v[1] - v[2])).abs().log2();
            let extrapolated = v[2] + (v[2] - v[1]) / (2f64.powf(order) - 1.0);
            let exact = p.velocity(t);
            let rel = (extrapolated - exact).abs() / exact.abs();
            let raw = (v[2] - exact).abs() / exact.abs();
            eprintln!(
                "v0={} t={f}τ: observed order {order:.3}, finest rel. error {raw:.2e}, Richardson {rel:.2e}",
                p.initial_velocity
            );
            assert!(rel < 1e-5, "{rel}");
            assert!(raw < 1e-3, "{raw}");
        }
    }
}

#[test]
fn special_times() {
    let p = unit().with_initial_velocity(0.25);
    assert_eq!(p.velocity(0.0), 0.25);
    assert_eq!(p.velocity(-1.0), 0.25);
    assert_eq!(p.position(-1.0), 0.0);
    assert_eq!(p.velocity(f64::INFINITY), p.terminal_velocity());
    assert!(p.velocity(f64::NAN).is_nan() && p.position(f64::NAN).is_nan());
    assert_eq!(p.position(f64::INFINITY), f64::INFINITY);
    // history slows the approach to v_∞ compared with no history
    for f in [0.5, 5.0, 50.0] {
        let t = f * p.relaxation_time();
        let q = unit();
        assert!(q.velocity(t) < q.without_history().velocity(t));
    }
}
