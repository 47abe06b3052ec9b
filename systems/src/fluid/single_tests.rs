//! Validation of the time stepping against physics: the exact unsteady-Stokes release, the
//! full-memory history, the thesis's levitation numbers, and where explicit stepping fails.

use super::*;
use crate::fluid::history::{HistoryPlan, HistoryState};
use crate::fluid::levitation::levitation_time;
use crate::fluid::stokes_reference::StokesRelease;

/// A sphere released from rest in quiescent fluid under gravity, Stokes drag, no magnet.
fn stokes_sphere(
    a: f64,
    rho_p: f64,
    history: HistoryKernel,
    integrator: Integrator,
) -> SphereInLiquid {
    SphereInLiquid {
        integrator,
        ..SphereInLiquid::stokes_release(a, rho_p, history)
    }
}

/// Errors against the exact solution: (max |Δv|/|v| for t >= t_rel, max |Δv|/v_∞ over all t,
/// max relative error of the deficit v_∞ − v for t >= 100 τ_ν).
fn errors_against_exact(
    rho_p: f64,
    dt_tau: f64,
    window_tau: f64,
    t_end_tau: f64,
    t_rel: f64,
) -> (f64, f64, f64) {
    let a = 50e-6;
    let exact = StokesRelease::gravitational(a, rho_p, 1403.0, 5.54e-3, -9.81);
    let tau = exact.viscous_time();
    let dt = dt_tau * tau;
    let s = stokes_sphere(
        a,
        rho_p,
        HistoryKernel::window(window_tau * tau, dt, true),
        Integrator::Implicit,
    );
    let t = s.simulate(0.0, 0.0, dt, t_end_tau * tau, 1).unwrap();
    let v_inf = exact.terminal_velocity();
    let (mut local, mut global, mut deficit) = (0.0f64, 0.0f64, 0.0f64);
    // log-spaced checks plus every 97th sample (exact inversion is not free)
    for (k, (&ti, &vi)) in t.times.iter().zip(&t.velocities).enumerate().skip(1) {
        if !(k % 97 == 0 || k < 200 || k.is_power_of_two()) {
            continue;
        }
        let ve = exact.velocity(ti);
        global = global.max(((vi - ve) / v_inf).abs());
        if ti >= t_rel * tau {
            local = local.max(((vi - ve) / ve).abs());
        }
        if ti >= 100.0 * tau {
            deficit = deficit.max(((vi - ve) / (v_inf - ve)).abs());
        }
    }
    (local, global, deficit)
}

#[test]
fn windowed_history_follows_the_exact_unsteady_stokes_release() {
    // fast version: 200 viscous times, relative errors from t = 0.2 τ_ν (release tier: 1000
    // viscous times; the first steps carry the O(√Δt) start-up error of the
    // product integration, bounded by the error relative to v_∞)
    for rho_p in [1434.0, 3000.0, 700.0] {
        let (local, global, deficit) = errors_against_exact(rho_p, 2e-3, 5.0, 200.0, 0.2);
        assert!(
            local < 5e-3 && global < 5e-3 && deficit < 1e-2,
            "{rho_p}: {local:.2e} {global:.2e} {deficit:.2e}"
        );
    }
}

#[test]
#[ignore = "validation tier (release): 10^6 steps"]
fn windowed_history_follows_the_exact_release_to_1000_viscous_times() {
    for rho_p in [3000.0, 700.0] {
        let (local, global, deficit) = errors_against_exact(rho_p, 1e-3, 10.0, 1000.0, 0.1);
        eprintln!(
            "rho_p {rho_p}: rel. error (t >= 0.1 tau) {local:.2e}, / v_inf {global:.2e}, of the t^-1/2 deficit {deficit:.2e}"
        );
        assert!(local < 5e-3 && global < 1e-3 && deficit < 1e-2);
    }
}

#[test]
fn without_history_the_step_is_first_order_exact_relaxation() {
    // no history: v = v_∞(1 − e^{−t/τ}) exactly; implicit Euler converges with order 1
    let a = 50e-6;
    let exact = StokesRelease::gravitational(a, 1434.0, 1403.0, 5.54e-3, -9.81).without_history();
    let tau = exact.relaxation_time();
    let mut terms = ForceTerms {
        magnetic_buoyancy: false,
        history: false,
        ..ForceTerms::default()
    };
    terms.history = false;
    let mut errs = Vec::new();
    for dt_tau in [0.02, 0.01, 0.005] {
        let mut s = stokes_sphere(a, 1434.0, HistoryKernel::Full, Integrator::Implicit);
        s.terms = terms;
        let t = s.simulate(0.0, 0.0, dt_tau * tau, 2.0 * tau, 1).unwrap();
        let v = *t.velocities.last().unwrap();
        errs.push(((v - exact.velocity(2.0 * tau)) / exact.velocity(2.0 * tau)).abs());
    }
    let order = (errs[0] / errs[2]).log2() / 2.0;
    assert!((order - 1.0).abs() < 0.05, "{errs:?}");
}

#[test]
fn window_matches_full_memory_in_levitation_time_and_thesis_ratios_hold() {
    // V-DS-5: windowed vs full memory within 1 % in t_l; t_l(no history)/t_l(history) for
    // the 5 mm PVC-U particle: 0.53 ± 0.05 rising, 0.64 ± 0.05 sinking (V-DS-R9, V-DS-R10)
    let mut s = SphereInLiquid::table_2_1(5e-3);
    let y_e = s
        .magnet
        .equilibrium_height(&s.liquid, s.gravity, s.density)
        .unwrap();
    let tl = |s: &SphereInLiquid, y0: f64, t_end: f64| {
        let t = s.simulate(y0, 0.0, 1e-3, t_end, 1).unwrap();
        levitation_time(&t.times, &t.heights, y_e, 0.5e-3)
    };
    for (y0, ratio, name) in [
        (-0.9 * 0.075, 0.53, "rising"),
        (0.9 * 0.075, 0.64, "sinking"),
    ] {
        s.terms.history = true;
        s.history = HistoryKernel::window(0.2, 1e-3, true);
        let window = tl(&s, y0, 12.0);
        s.history = HistoryKernel::Full;
        let full = tl(&s, y0, 12.0);
        s.terms.history = false;
        let none = tl(&s, y0, 12.0);
        assert!(
            (window / full - 1.0).abs() < 0.01,
            "{name}: window {window}, full {full}"
        );
        assert!(
            (none / window - ratio).abs() < 0.05,
            "{name}: {none} / {window}"
        );
    }
}

#[test]
fn levitation_times_against_diameter_have_their_minimum_near_4_mm() {
    // V-DS-4, D-002-5: 23.1 / 6.44 / 1.69 / 2.98 s at 1 / 2 / 4 / 6 mm (no history, y0 = −0.9 L)
    let expect = [(1e-3, 23.1), (2e-3, 6.44), (4e-3, 1.69), (6e-3, 2.98)];
    let mut times = Vec::new();
    for (d, t_ref) in expect {
        let mut s = SphereInLiquid::table_2_1(d);
        s.terms.history = false;
        let y_e = s
            .magnet
            .equilibrium_height(&s.liquid, s.gravity, s.density)
            .unwrap();
        let t = s.simulate(-0.9 * 0.075, 0.0, 1e-3, 40.0, 1).unwrap();
        let tl = levitation_time(&t.times, &t.heights, y_e, 0.5e-3);
        assert!((tl / t_ref - 1.0).abs() < 0.02, "d = {d}: {tl} vs {t_ref}");
        times.push(tl);
    }
    assert!(times[2] < times[1] && times[2] < times[3]);
}

#[test]
fn explicit_history_weights_diverge_for_small_particles_and_the_implicit_step_does_not() {
    // D-002-2: explicit history diverges once 0.76 r > 1 − Δt/(2τ_eff); for MnCl2 at 1 ms that
    // is d ≲ 0.38 mm. The implicit newest weight stays stable down to at least 0.07 mm.
    let run = |d: f64, integrator: Integrator| {
        let mut s = SphereInLiquid::table_2_1(d);
        s.integrator = integrator;
        s.history = HistoryKernel::window(0.05, 1e-3, true);
        let t = s.simulate(-0.5 * 0.075, 0.0, 1e-3, 0.5, 1).unwrap();
        t.velocities.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let terminal = |d: f64| {
        // |v| never exceeds a few times the Stokes settling speed of the net weight at the face
        let s = SphereInLiquid::table_2_1(d);
        s.static_force(-0.075).abs() / (3.0 * std::f64::consts::PI * s.liquid.viscosity * d)
    };
    for d in [0.3e-3, 0.2e-3] {
        assert!(
            {
                let v = run(d, Integrator::Explicit);
                v.is_nan() || v >= 1e3 * terminal(d)
            },
            "explicit should blow up at d = {d}"
        );
    }
    for d in [0.42e-3, 0.5e-3] {
        assert!(
            run(d, Integrator::Explicit) < 2.0 * terminal(d),
            "explicit stable at d = {d}"
        );
    }
    for d in [0.07e-3, 0.2e-3, 0.3e-3, 1e-3] {
        assert!(
            run(d, Integrator::Implicit) < 2.0 * terminal(d),
            "implicit unstable at d = {d}"
        );
    }
}

#[test]
fn large_time_steps_break_explicit_drag_but_not_the_implicit_step() {
    // 0.1 mm sphere: 2 τ_eff = 0.4 ms; steps of 1 and 5 ms
    let d = 0.1e-3;
    for dt in [1e-3, 5e-3] {
        let mut s = SphereInLiquid::table_2_1(d);
        s.terms.history = false;
        s.integrator = Integrator::Explicit;
        let t = s.simulate(-0.5 * 0.075, 0.0, dt, 0.5, 1).unwrap();
        assert!(
            !t.velocities.last().unwrap().abs().is_finite()
                || t.velocities.last().unwrap().abs() > 1.0
        );
        s.integrator = Integrator::Implicit;
        s.terms.history = true;
        let t = s.simulate(-0.5 * 0.075, 0.0, dt, 0.5, 1).unwrap();
        let v = *t.velocities.last().unwrap();
        let stokes =
            s.static_force(-0.5 * 0.075) / (3.0 * std::f64::consts::PI * s.liquid.viscosity * d);
        assert!((v / stokes - 1.0).abs() < 0.05, "dt {dt}: {v} vs {stokes}");
    }
}

#[test]
fn the_thesis_reset_leaves_a_memory_of_the_pre_collision_slip() {
    // eq. 2.29 keeps the jump (v(t_c⁻) − v(t_c⁺))/√(t − t_c) but drops what came before, so
    // once the particle is at rest, I(t) √(t − t_c) → −w(t_c⁻): a force c_H w(t_c⁻)/√(t − t_c)
    // that decays only like t^(−1/2). Keeping the whole history, the memory of the approach
    // and of the jump cancel and I(t) decays like t^(−3/2)·…, much faster.
    let dt = 1e-3;
    let plan = HistoryPlan::new(dt, HistoryKernel::window(0.2, dt, true)).unwrap();
    let w_before = DVec3::new(0.0, 0.0, -0.02); // slip just before the collision
    let (mut reset, mut keep) = (
        HistoryState::new(DVec3::ZERO, 0.0),
        HistoryState::new(DVec3::ZERO, 0.0),
    );
    // accelerate from rest to the pre-collision slip over 1 s
    for n in 1..=1000 {
        let w = w_before * (n as f64 / 1000.0);
        reset.push(&plan, w);
        keep.push(&plan, w);
    }
    // the collision stops the particle at t_c = 1 s (slip 0 afterwards)
    let t_c = 1.0;
    reset.reset_at_collision(&plan, t_c, DVec3::ZERO - w_before, DVec3::ZERO, t_c);
    keep.push(&plan, DVec3::ZERO);
    for _ in 0..(99_000 - 1) {
        reset.push(&plan, DVec3::ZERO);
        keep.push(&plan, DVec3::ZERO);
    }
    let t = 100.0;
    let scaled_reset = reset.current_integral(&plan, t) * (t - t_c).sqrt();
    let scaled_keep = keep.current_integral(&plan, t) * (t - t_c).sqrt();
    assert!((scaled_reset + w_before).length() < 1e-9, "{scaled_reset}");
    assert!(
        scaled_keep.length() < 0.02 * w_before.length(),
        "{scaled_keep}"
    );
}
