//! `magsep chart history`: accuracy, cost and stability of the Basset-history method family
//! (full-memory product integration; window + ten-exponential tail of van Hinsberg et al.;
//! truncated window) and of the two velocity updates ([T002 §2.3.2.1]; D-002-2, D-002-3 in
//! docs/references.md):
//!
//! * `history_accuracy_cost.svg` (a): a 100 µm PVC-U sphere (ρ_p = 1434 kg/m³) released from
//!   rest in quiescent MnCl₂ (no magnet, Stokes drag): the maximum velocity error against the
//!   exact unsteady-Stokes solution ([`StokesRelease`], Talbot inversion) up to 300 τ_ν
//!   (τ_ν = a²/ν), relative to v_∞ and relative to v for t ≥ 0.1 τ_ν, against the wall time of
//!   the run; one series per window setting (t_win/τ_ν = 0.3, 1, 3, 10 with tail, full memory,
//!   3 without tail), points Δt/τ_ν = 0.1 … 0.001;
//! * `history_window_levitation.svg` (b): the 5 mm rising sphere of fig. 2.10d: error of t_l
//!   and of the trajectory against the full memory, for windows of 0.01-1 s with and without
//!   the tail;
//! * `history_cost_per_step.svg` (c) and `history_cost_per_step.json`: wall time per step at
//!   step n for full memory (grows like n) and the 389-step window + tail (flat), see
//!   [`maps`];
//! * `history_stability.svg` (d): stable or divergent runs of 0.05-2 mm spheres against Δt,
//!   explicit (the thesis's forward Euler) with and without history and the linearly
//!   implicit step, with the theoretical boundaries, see [`maps`].

#[path = "history_maps.rs"]
mod maps;

use std::path::Path;
use std::time::Instant;

use magsep_systems::fluid::history::HistoryKernel;
use magsep_systems::fluid::levitation::levitation_time;
use magsep_systems::fluid::single::{SphereInLiquid, Trajectory};
use magsep_systems::fluid::stokes_reference::StokesRelease;
use serde_json::{Value, json};

use super::levitation::{DT, HALF_HEIGHT, TOLERANCE, equilibrium, r4, rig, runtime, save};
use crate::chart::{Chart, Figure, LegendPosition, Line, Series};
use crate::studies::bench::BenchError;

/// Sphere radius of the unsteady-Stokes comparison [m].
const RADIUS: f64 = 50e-6;
/// Its density [kg/m³] (PVC-U).
const DENSITY: f64 = 1434.0;

/// One window setting of part (a): t_win/τ_ν (None: full memory) and the tail.
#[derive(Debug, Clone, Copy)]
struct Setting {
    window_tau: Option<f64>,
    tail: bool,
}

impl Setting {
    fn label(&self) -> String {
        match self.window_tau {
            None => "full memory".into(),
            Some(w) if self.tail => format!("window {w} tau_nu + tail"),
            Some(w) => format!("window {w} tau_nu, no tail"),
        }
    }

    fn kernel(&self, tau: f64, dt: f64) -> HistoryKernel {
        match self.window_tau {
            None => HistoryKernel::Full,
            Some(w) => HistoryKernel::window(w * tau, dt, self.tail),
        }
    }
}

/// The sphere of part (a): MnCl₂ without magnet, Stokes drag, released from rest.
fn stokes_sphere(history: HistoryKernel) -> SphereInLiquid {
    SphereInLiquid::stokes_release(RADIUS, DENSITY, history)
}

/// `f()` timed: repeated until `min_time` [s] has passed (at most 20 times); the minimum
/// wall time and the last result.
fn timed<T>(
    min_time: f64,
    mut f: impl FnMut() -> Result<T, BenchError>,
) -> Result<(f64, T), BenchError> {
    let (mut best, mut total, mut reps) = (f64::INFINITY, 0.0, 0);
    loop {
        let start = Instant::now();
        let out = f()?;
        let el = start.elapsed().as_secs_f64();
        best = best.min(el);
        total += el;
        reps += 1;
        if total >= min_time || reps >= 20 {
            return Ok((best, out));
        }
    }
}

/// Max |v − v_exact|/|v_∞| over all checked samples and max |v − v_exact|/|v_exact| for
/// t ≥ 0.1 τ_ν; samples checked: the first 100 and ~400 geometrically spaced ones.
fn release_errors(tr: &Trajectory, exact: &StokesRelease, tau: f64) -> (f64, f64) {
    let n = tr.times.len();
    let v_inf = exact.terminal_velocity().abs();
    let mut idx: Vec<usize> = (1..n.min(100)).collect();
    let ratio = (n as f64).powf(1.0 / 400.0);
    let mut f = 100.0f64;
    while (f as usize) < n {
        idx.push(f as usize);
        f *= ratio;
    }
    idx.push(n - 1);
    idx.sort_unstable();
    idx.dedup();
    let (mut global, mut local) = (0.0f64, 0.0f64);
    for k in idx {
        let (t, v) = (tr.times[k], tr.velocities[k]);
        let ve = exact.velocity(t);
        if !(v.is_finite() && ve.is_finite()) {
            return (f64::INFINITY, f64::INFINITY);
        }
        global = global.max((v - ve).abs() / v_inf);
        if t >= 0.1 * tau {
            local = local.max(((v - ve) / ve).abs());
        }
    }
    (global, local)
}

/// `magsep chart history --out DIR [--quick]`: the SVGs listed in the module docs and a JSON
/// summary on stdout.
///
/// # Errors
/// [`BenchError::Runtime`] when a directory or file cannot be written or a run fails.
pub fn chart_history(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let started = Instant::now();
    let mut charts = Vec::new();
    let (path, accuracy) = accuracy_chart(out, quick)?;
    charts.push(path);
    let (path, window) = window_chart(out, quick)?;
    charts.push(path);
    let (paths, cost) = maps::cost_chart(out, quick)?;
    charts.extend(paths);
    let (path, stability) = maps::stability_chart(out, quick)?;
    charts.push(path);
    let summary = json!({
        "chart": "history",
        "quick": quick,
        "charts": charts,
        "accuracy_vs_cost": accuracy,
        "window_levitation": window,
        "cost_per_step": cost,
        "stability": stability,
        "wall_time_s": r4(started.elapsed().as_secs_f64()),
    });
    crate::studies::bench::say(summary)
}

/// (a) error against cost for the window settings and time steps.
fn accuracy_chart(out: &Path, quick: bool) -> Result<(String, Value), BenchError> {
    let exact = StokesRelease::gravitational(RADIUS, DENSITY, 1403.0, 5.54e-3, -9.81);
    let tau = exact.viscous_time();
    let (steps_tau, t_end_tau, min_time): (&[f64], f64, f64) = if quick {
        (&[1e-1, 1e-2], 30.0, 0.0)
    } else {
        (&[1e-1, 3e-2, 1e-2, 3e-3, 1e-3], 300.0, 0.1)
    };
    let settings: Vec<Setting> = if quick {
        vec![
            Setting {
                window_tau: Some(1.0),
                tail: true,
            },
            Setting {
                window_tau: None,
                tail: true,
            },
            Setting {
                window_tau: Some(1.0),
                tail: false,
            },
        ]
    } else {
        let mut v: Vec<Setting> = [0.3, 1.0, 3.0, 10.0]
            .iter()
            .map(|&w| Setting {
                window_tau: Some(w),
                tail: true,
            })
            .collect();
        v.push(Setting {
            window_tau: None,
            tail: true,
        });
        v.push(Setting {
            window_tau: Some(3.0),
            tail: false,
        });
        v
    };
    let mut global_panel = Chart::new("Max |v - v_exact| / v_inf up to 300 tau_nu")
        .x_label("wall time of the run [s]")
        .y_label("error / v_inf [-]")
        .x_log(true)
        .y_log(true)
        .legend(LegendPosition::BottomLeft);
    let mut local_panel = Chart::new("Max |v - v_exact| / v for t >= 0.1 tau_nu")
        .x_label("wall time of the run [s]")
        .y_label("relative error [-]")
        .x_log(true)
        .y_log(true)
        .legend(LegendPosition::BottomLeft);
    let mut rows = Vec::new();
    for setting in &settings {
        let (mut g_pts, mut l_pts) = (Vec::new(), Vec::new());
        for &h in steps_tau {
            let dt = h * tau;
            let s = stokes_sphere(setting.kernel(tau, dt));
            let (cost, tr) = timed(min_time, || {
                s.simulate(0.0, 0.0, dt, t_end_tau * tau, 1)
                    .map_err(runtime)
            })?;
            let (global, local) = release_errors(&tr, &exact, tau);
            g_pts.push((cost, global));
            l_pts.push((cost, local));
            rows.push(json!({
                "setting": setting.label(), "dt_over_tau": h,
                "steps": tr.times.len() - 1, "wall_time_s": cost,
                "error_over_v_inf": global, "relative_error_t_ge_0.1_tau": local,
            }));
        }
        global_panel = global_panel.series(Series::new(setting.label(), g_pts));
        local_panel = local_panel.series(Series::new(setting.label(), l_pts));
    }
    let note = if quick {
        " [quick: 30 tau_nu, 2 steps, 3 settings]"
    } else {
        ""
    };
    let fig = Figure::new(
        format!(
            "100 um PVC-U sphere released in MnCl2 (tau_nu = {:.2e} s): error vs cost; dt/tau_nu = {}{note}",
            tau,
            steps_tau
                .iter()
                .map(|h| format!("{h}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        2,
    )
    .panel(global_panel)
    .panel(local_panel);
    let path = save(out, "history_accuracy_cost.svg", &fig.to_svg(640.0, 480.0))?;
    Ok((
        path,
        json!({"radius_m": RADIUS, "density": DENSITY, "viscous_time_s": tau,
               "terminal_velocity_m_s": exact.terminal_velocity(),
               "t_end_over_tau": t_end_tau, "points": rows}),
    ))
}

/// (b) the 5 mm rising sphere: t_l and trajectory error against the window length.
fn window_chart(out: &Path, quick: bool) -> Result<(String, Value), BenchError> {
    let (windows, t_end): (&[f64], f64) = if quick {
        (&[0.05, 0.2], 5.0)
    } else {
        (&[0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0], 12.0)
    };
    let y0 = -0.9 * HALF_HEIGHT;
    let run = |history: Option<HistoryKernel>| -> Result<(Trajectory, f64), BenchError> {
        let mut s = rig(5e-3, history.is_some());
        if let Some(k) = history {
            s.history = k;
        }
        let y_e = equilibrium(&s)?;
        let tr = s.simulate(y0, 0.0, DT, t_end, 1).map_err(runtime)?;
        let t_l = levitation_time(&tr.times, &tr.heights, y_e, TOLERANCE);
        Ok((tr, t_l))
    };
    let (full, t_full) = run(Some(HistoryKernel::Full))?;
    let (_, t_none) = run(None)?;
    let mut tl_panel = Chart::new("|t_l - t_l(full)| / t_l(full)")
        .x_label("t_win [s]")
        .y_label("relative error of t_l [-]")
        .x_log(true)
        .y_log(true);
    let mut y_panel = Chart::new("max |y - y(full)| over the run")
        .x_label("t_win [s]")
        .y_label("trajectory error [m]")
        .x_log(true)
        .y_log(true);
    let mut rows = Vec::new();
    for tail in [true, false] {
        let (mut tl_pts, mut y_pts) = (Vec::new(), Vec::new());
        for &w in windows {
            let (tr, t_l) = run(Some(HistoryKernel::window(w, DT, tail)))?;
            let dy = tr
                .heights
                .iter()
                .zip(&full.heights)
                .fold(0.0f64, |a, (y, yf)| a.max((y - yf).abs()));
            let rel = (t_l / t_full - 1.0).abs();
            tl_pts.push((w, rel));
            y_pts.push((w, dy));
            rows.push(
                json!({"window_s": w, "tail": tail, "levitation_time_s": r4(t_l),
                             "relative_error": rel, "max_trajectory_error_m": dy}),
            );
        }
        let name = if tail {
            "window + tail"
        } else {
            "window, no tail"
        };
        tl_panel = tl_panel.series(Series::new(name, tl_pts));
        y_panel = y_panel.series(Series::new(name, y_pts));
    }
    let no_history = (t_none / t_full - 1.0).abs();
    tl_panel = tl_panel.line(
        Line::new(
            format!("no history: {:.0} %", 100.0 * no_history),
            [
                (windows[0], no_history),
                (windows[windows.len() - 1], no_history),
            ],
        )
        .dashed(true),
    );
    tl_panel = tl_panel.line(
        Line::new(
            "V-DS-5: 1 %",
            [(windows[0], 0.01), (windows[windows.len() - 1], 0.01)],
        )
        .color("#999999"),
    );
    let note = if quick {
        " [quick: 2 windows, 5 s]"
    } else {
        ""
    };
    let fig = Figure::new(
        format!(
            "5 mm PVC-U rising from -0.9 L (fig. 2.10d), dt = 1 ms: window vs full memory (t_l = {t_full:.3} s){note}"
        ),
        2,
    )
    .panel(tl_panel)
    .panel(y_panel);
    let path = save(
        out,
        "history_window_levitation.svg",
        &fig.to_svg(600.0, 440.0),
    )?;
    Ok((
        path,
        json!({"full_memory_levitation_time_s": r4(t_full),
               "no_history_levitation_time_s": r4(t_none), "t_end_s": t_end, "windows": rows}),
    ))
}
