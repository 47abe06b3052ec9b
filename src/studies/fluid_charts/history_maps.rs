//! Parts (c) and (d) of `magsep chart history`: the cost of one history step against the
//! step number, and the stability map of the explicit and implicit velocity updates.
//!
//! **Stability.** Spheres of the table 2.1 rig (d = 0.05-2 mm, PVC-U) released from rest at
//! y = −0.5 L with every term on (history: 0.05 s window + tail), run for max(1 s, 100 Δt).
//! A run diverges when |v| exceeds 100 × the Stokes speed of the largest net static force
//! (at the magnet face or the top) or turns non-finite. Theory (D-002-2, docs/references.md), with
//! `τ_eff = (ρ_p + ½ρ_f) d²/(18μ)` and `r = 18√(ρ_f μ Δt/π)/((ρ_p + ½ρ_f) d)`: explicit drag
//! is stable for Δt < 2τ_eff; the explicit history adds the bound `0.76 r < 1 − Δt/(2τ_eff)`.

use std::f64::consts::PI;
use std::path::Path;

use magsep_systems::fluid::config::Integrator;
use magsep_systems::fluid::history::HistoryKernel;
use rayon::prelude::*;
use serde_json::{Value, json};

use super::super::bench::{BENCH_DT, BENCH_WINDOW, history_step_time, kernel_name};
use super::{HALF_HEIGHT, r4, runtime, save};
use crate::chart::{Chart, Figure, Line, Series, Style};
use crate::studies::bench::BenchError;

/// (c) wall time per step at step n, full memory vs the 389-step window + tail.
pub(super) fn cost_chart(out: &Path, quick: bool) -> Result<(Vec<String>, Value), BenchError> {
    let sizes: Vec<usize> = if quick {
        vec![100, 1_000, 10_000]
    } else {
        vec![
            100, 300, 1_000, 3_000, 10_000, 30_000, 100_000, 300_000, 1_000_000,
        ]
    };
    let (budget, min_time) = if quick { (1e6, 0.002) } else { (3e8, 0.1) };
    let mut chart = Chart::new(format!(
        "Basset history: wall time of one step at step n (dt = {} ms, one particle){}",
        BENCH_DT * 1e3,
        if quick { " [quick: n <= 1e4]" } else { "" }
    ))
    .x_label("step number n [-]")
    .y_label("wall time per step [s]")
    .x_log(true)
    .y_log(true);
    let mut rows = Vec::new();
    let mut full_last = (0.0, 0.0);
    for kernel in [HistoryKernel::Full, BENCH_WINDOW] {
        let mut pts = Vec::new();
        for &n in &sizes {
            let t = history_step_time(kernel, n, 1, budget, min_time)?;
            pts.push((n as f64, t.seconds_per_particle_step));
            if kernel == HistoryKernel::Full {
                full_last = (n as f64, t.seconds_per_particle_step);
            }
            rows.push(
                json!({"name": "history_step", "kernel": kernel_name(kernel), "n": n,
                             "threads": 1, "seconds_per_step": t.seconds_per_particle_step,
                             "timed_steps": t.timed_steps, "repetitions": t.repetitions}),
            );
        }
        let name = match kernel {
            HistoryKernel::Full => "full memory".to_string(),
            _ => "window 389 steps (0.35 s) + tail".to_string(),
        };
        chart = chart.series(Series::new(name, pts));
    }
    // O(n) guide through the largest full-memory point
    let (n1, t1) = full_last;
    if n1 > 0.0 {
        chart = chart.line(
            Line::new(
                "O(n)",
                sizes.iter().map(|&n| (n as f64, t1 * n as f64 / n1)),
            )
            .dashed(true),
        );
    }
    let svg = save(
        out,
        "history_cost_per_step.svg",
        &chart.to_svg(760.0, 500.0),
    )?;
    let json_path = out.join("history_cost_per_step.json");
    let text = rows
        .iter()
        .map(|r| r.to_string())
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&json_path, text + "\n")
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", json_path.display())))?;
    Ok((
        vec![svg, json_path.display().to_string()],
        Value::Array(rows),
    ))
}

/// τ_eff = (ρ_p + ½ρ_f) d²/(18μ) [s] on the table 2.1 rig.
fn tau_eff(d: f64) -> f64 {
    (1434.0 + 0.5 * 1403.0) * d * d / (18.0 * 5.54e-3)
}

/// r = 18√(ρ_f μ Δt/π)/((ρ_p + ½ρ_f) d).
fn history_factor(d: f64, dt: f64) -> f64 {
    18.0 * (1403.0 * 5.54e-3 * dt / PI).sqrt() / ((1434.0 + 0.5 * 1403.0) * d)
}

/// The largest stable explicit Δt with history: the root of 0.76 r = 1 − Δt/(2τ_eff).
fn history_bound(d: f64) -> f64 {
    let f = |dt: f64| 0.76 * history_factor(d, dt) - 1.0 + dt / (2.0 * tau_eff(d));
    let (mut lo, mut hi) = (0.0, 2.0 * tau_eff(d));
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Whether the run of a `d` sphere at step `dt` diverges.
fn diverges(d: f64, dt: f64, integrator: Integrator, history: bool) -> Result<bool, BenchError> {
    let mut s = super::rig(d, history);
    s.integrator = integrator;
    s.history = HistoryKernel::window(0.05, dt, true);
    let f_max = s
        .static_force(-HALF_HEIGHT)
        .abs()
        .max(s.static_force(HALF_HEIGHT).abs());
    let v_stokes = f_max / (3.0 * PI * s.liquid.viscosity * d);
    let t_end = (100.0 * dt).max(1.0);
    let tr = s
        .simulate(-0.5 * HALF_HEIGHT, 0.0, dt, t_end, 1)
        .map_err(runtime)?;
    Ok(tr
        .velocities
        .iter()
        .any(|v| !v.is_finite() || v.abs() > 100.0 * v_stokes))
}

/// `n` log-spaced values from `a` to `b`.
fn logspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| (a.ln() + (b.ln() - a.ln()) * k as f64 / (n - 1).max(1) as f64).exp())
        .collect()
}

/// (d) stability map.
pub(super) fn stability_chart(out: &Path, quick: bool) -> Result<(String, Value), BenchError> {
    let (nd, nt) = if quick { (5, 4) } else { (21, 16) };
    let ds = logspace(0.05e-3, 2e-3, nd);
    let dts = logspace(1e-4, 1e-1, nt);
    let cases = [
        (
            Integrator::Explicit,
            true,
            "explicit (thesis), with history",
        ),
        (Integrator::Explicit, false, "explicit, without history"),
        (
            Integrator::Implicit,
            true,
            "linearly implicit, with history",
        ),
    ];
    let d_mm = |d: f64| d * 1e3;
    let theory_hist = Line::from_fn("0.76 r = 1 - dt/(2 tau_eff)", 0.05, 2.0, 200, true, |x| {
        history_bound(x * 1e-3)
    });
    let theory_drag = Line::from_fn("dt = 2 tau_eff", 0.05, 2.0, 200, true, |x| {
        2.0 * tau_eff(x * 1e-3)
    })
    .dashed(true);
    let mut fig = Figure::new(
        format!(
            "Stability of the velocity update: 0.05-2 mm PVC-U spheres, runs of max(1 s, 100 dt){}",
            if quick { " [quick: 5 x 4 grid]" } else { "" }
        ),
        3,
    );
    let mut summary = Vec::new();
    for (integrator, history, name) in cases {
        let grid: Vec<(f64, f64)> = ds
            .iter()
            .flat_map(|&d| dts.iter().map(move |&dt| (d, dt)))
            .collect();
        let res: Vec<Result<bool, BenchError>> = grid
            .par_iter()
            .map(|&(d, dt)| diverges(d, dt, integrator, history))
            .collect();
        let res = res.into_iter().collect::<Result<Vec<_>, _>>()?;
        let stable: Vec<(f64, f64)> = grid
            .iter()
            .zip(&res)
            .filter(|(_, bad)| !**bad)
            .map(|(&(d, dt), _)| (d_mm(d), dt))
            .collect();
        let divergent: Vec<(f64, f64)> = grid
            .iter()
            .zip(&res)
            .filter(|(_, bad)| **bad)
            .map(|(&(d, dt), _)| (d_mm(d), dt))
            .collect();
        // per diameter: the largest stable step below the first divergent one
        let per_d: Vec<Value> = ds
            .iter()
            .enumerate()
            .map(|(i, &d)| {
                let row = &res[i * nt..(i + 1) * nt];
                let first_bad = row.iter().position(|&b| b);
                let last_good = first_bad.and_then(|k| k.checked_sub(1)).map(|k| dts[k]);
                let theory = if integrator == Integrator::Implicit {
                    f64::INFINITY
                } else if history {
                    history_bound(d)
                } else {
                    2.0 * tau_eff(d)
                };
                // the theoretical boundary lies between the last stable and the first
                // divergent grid step (or beyond the grid on the right side)
                let lo_ok = last_good.is_none_or(|g| g <= theory) || first_bad.is_none();
                let hi_ok = first_bad.is_none_or(|k| dts[k] >= theory);
                let bracketed = match first_bad {
                    None => theory >= dts[nt - 1],
                    Some(_) => lo_ok && hi_ok,
                };
                json!({
                    "d_mm": r4(d * 1e3),
                    "largest_stable_dt_s": match first_bad { None => Some(r4(dts[nt - 1])), Some(_) => last_good.map(r4) },
                    "first_divergent_dt_s": first_bad.map(|k| r4(dts[k])),
                    "stable_above_first_divergent": first_bad.map(|k| row[k..].iter().filter(|&&b| !b).count()),
                    "theory_history_dt_s": r4(history_bound(d)),
                    "theory_drag_dt_s": r4(2.0 * tau_eff(d)),
                    "theory_bracketed_by_grid": bracketed,
                })
            })
            .collect();
        let bracketed = per_d
            .iter()
            .filter(|r| r["theory_bracketed_by_grid"] == json!(true))
            .count();
        summary.push(json!({"case": name, "divergent_runs": divergent.len(),
                            "diameters_with_theory_bracketed": bracketed,
                            "runs": grid.len(), "per_diameter": per_d}));
        let chart = Chart::new(name)
            .x_label("d [mm]")
            .y_label("dt [s]")
            .x_log(true)
            .y_log(true)
            .x_range(0.04, 2.5)
            .y_range(7e-5, 0.14)
            .series(
                Series::new("stable", stable)
                    .style(Style::Markers)
                    .color("#009E73"),
            )
            .series(
                Series::new("divergent", divergent)
                    .style(Style::Markers)
                    .color("#D55E00"),
            )
            .line(theory_hist.clone())
            .line(theory_drag.clone());
        fig = fig.panel(chart);
    }
    let path = save(out, "history_stability.svg", &fig.to_svg(640.0, 460.0))?;
    Ok((
        path,
        json!({"criterion": "|v| > 100 x Stokes speed of the largest net static force, or non-finite",
               "cases": summary}),
    ))
}
