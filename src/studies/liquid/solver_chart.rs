//! `magsep chart liquid-solver --out DIR [--quick]`: the channel solver's accuracy against its
//! cost, and where its time step fails.
//!
//! * `liquid_solver_accuracy.svg`: the relative error of the Tollmien-Schlichting growth rate
//!   (Re = 7500, α = 1; reference: the Orr-Sommerfeld eigenvalue at nz = 129, which matches
//!   Orszag (1971) to his 8 digits) against the wall time of the run, for a sweep of the
//!   wall-normal resolution at a small step and of the time step at a fine resolution. The
//!   spatial error falls spectrally until the time error (second order) takes over.
//! * `liquid_solver_stability.svg`: the disturbance energy after t = 20 (relative to its
//!   start) against the convective Courant number `Δt max(|u|/Δx + |w|/Δz)`: the explicit
//!   Runge-Kutta treatment of the nonlinear term is stable up to a CFL of order 1 and fails
//!   (non-finite values) beyond it.

use std::path::Path;

use num_complex::Complex64 as C;
use serde_json::json;

use crate::chart::{Chart, Figure, LegendPosition, Series, Style, write_svg};
use crate::studies::bench::BenchError;
use crate::studies::fluid_charts::runtime;
use magsep_systems::fluid::channel::grid::ChannelGrid;
use magsep_systems::fluid::channel::orr_sommerfeld::{orr_sommerfeld, ts_growth};
use magsep_systems::fluid::channel::{ChannelParams, ChannelSolver};

/// Energy growth and CFL of a Poiseuille flow (Re = 7500) carrying a 1 % Tollmien-Schlichting
/// wave on a 16 × 4 × 33 grid after `t_end` with step `dt`: (CFL, E(t)/E(0) or NaN).
fn stability(dt: f64, t_end: f64) -> Result<(f64, f64), BenchError> {
    let (alpha, re, nz) = (1.0, 7500.0, 33);
    let nu = 1.0 / re;
    let g =
        ChannelGrid::new([16, 4, nz], [2.0 * std::f64::consts::PI, 1.0, 2.0]).map_err(runtime)?;
    let mut p = ChannelParams::new(g, nu, dt);
    p.mean_pressure_gradient = [2.0 * nu, 0.0];
    let mut s = ChannelSolver::new(p).map_err(runtime)?;
    let (_, vh) = orr_sommerfeld(alpha, re, nz, C::new(0.2499, 0.0022)).map_err(runtime)?;
    let n = g.len();
    let (mut u, mut w) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..nz {
        let z = g.z(k);
        for i in 0..g.nx {
            let e = C::from_polar(0.01, alpha * g.x(i));
            for j in 0..g.ny {
                u[g.index(i, j, k)] = z * (2.0 - z);
                w[g.index(i, j, k)] = (vh[k] * e).re;
            }
        }
    }
    s.set_velocity([&u, &vec![0.0; n], &w]).map_err(runtime)?;
    let energy = |s: &ChannelSolver| -> f64 {
        let v = s.velocity();
        v[2].iter().map(|x| x * x).sum()
    };
    let (e0, cfl) = (energy(&s), s.cfl());
    let steps = (t_end / dt).round().max(1.0) as usize;
    for _ in 0..steps {
        s.step();
        if !energy(&s).is_finite() {
            return Ok((cfl, f64::NAN));
        }
    }
    Ok((cfl, energy(&s) / e0))
}

/// Write the charts and print a JSON summary.
///
/// # Errors
/// [`BenchError::Runtime`] if a run or writing fails.
pub fn chart_liquid_solver(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let t_end = if quick { 10.0 } else { 20.0 };
    let levels: &[usize] = if quick {
        &[25, 33, 49]
    } else {
        &[25, 33, 41, 49, 65, 97]
    };
    let steps: &[f64] = if quick {
        &[0.2, 0.1]
    } else {
        &[0.4, 0.2, 0.1, 0.05, 0.02]
    };
    let mut rows = Vec::new();
    let mut by_nz = Vec::new();
    for &nz in levels {
        let r = ts_growth(nz, 0.01, t_end).map_err(runtime)?;
        by_nz.push((r.wall_time_s, r.relative_error.max(1e-16)));
        rows.push(json!({"sweep": "nz", "nz": nz, "dt": 0.01, "relative_error": r.relative_error, "wall_time_s": r.wall_time_s}));
    }
    let mut by_dt = Vec::new();
    for &dt in steps {
        let r = ts_growth(65, dt, t_end).map_err(runtime)?;
        by_dt.push((r.wall_time_s, r.relative_error.max(1e-16)));
        rows.push(json!({"sweep": "dt", "nz": 65, "dt": dt, "relative_error": r.relative_error, "wall_time_s": r.wall_time_s}));
    }
    let accuracy = Chart::new(format!(
        "Tollmien-Schlichting growth rate (Re = 7500, alpha = 1, t = {t_end})"
    ))
    .x_label("wall time of the run [s]")
    .y_label("relative error of the growth rate")
    .x_log(true)
    .y_log(true)
    .legend(LegendPosition::TopRight)
    .series(Series::new("nz = 25 ... 97 levels, dt = 0.01", by_nz).style(Style::LineMarkers))
    .series(Series::new("dt = 0.4 ... 0.02, nz = 65", by_dt).style(Style::LineMarkers));
    let p1 = out.join("liquid_solver_accuracy.svg");
    write_svg(&p1, &accuracy.to_svg(640.0, 420.0)).map_err(runtime)?;
    let dts: &[f64] = if quick {
        &[0.05, 0.2, 0.8]
    } else {
        &[0.02, 0.05, 0.1, 0.2, 0.4, 0.6, 0.8, 1.2]
    };
    let mut stable = Vec::new();
    let mut failed = Vec::new();
    let mut srows = Vec::new();
    for &dt in dts {
        let (cfl, growth) = stability(dt, t_end)?;
        if growth.is_finite() && growth < 1e6 {
            stable.push((cfl, growth));
        } else {
            failed.push((cfl, 1e6));
        }
        srows.push(json!({"dt": dt, "cfl": cfl, "energy_ratio": if growth.is_finite() { json!(growth) } else { json!(null) }}));
    }
    let stability_chart = Chart::new("Stability of the time step (1 % TS wave on Poiseuille flow)")
        .x_label("convective CFL at the start")
        .y_label("E(t) / E(0) of the wall-normal velocity")
        .y_log(true)
        .legend(LegendPosition::TopLeft)
        .series(Series::new("stable", stable).style(Style::Markers))
        .series(Series::new("failed (non-finite or blown up)", failed).style(Style::Markers));
    let p2 = out.join("liquid_solver_stability.svg");
    let fig = Figure::new("Channel solver: stability", 1).panel(stability_chart);
    write_svg(&p2, &fig.to_svg(640.0, 420.0)).map_err(runtime)?;
    crate::studies::bench::say(json!({
        "charts": [p1.display().to_string(), p2.display().to_string()],
        "quick": quick,
        "accuracy": rows,
        "stability": srows,
    }))
}
