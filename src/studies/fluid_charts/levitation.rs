//! `magsep chart levitation`: the single-particle results of thesis 002, ch. 2 (Tajfirooz 2021;
//! docs/references.md: E-002-4, E-002-5, E-002-7, D-002-2, D-002-5, V-DS-R1 to V-DS-R11, V-DS-3 to V-DS-5), on the
//! table 2.1 rig (bottom magnet, saturated MnCl₂, PVC-U ρ_p = 1434 kg/m³), integrated with
//! [`SphereInLiquid`] (linearly implicit Euler, Δt = 1 ms, Schiller-Naumann drag):
//!
//! * `levitation_trajectories.svg` (a): y(t) of 1, 2, 4, 6 mm spheres released from rest at
//!   y₀ = −0.9 L, without history (fig. 2.5a) and with history (figs. 2.7/2.8), y_e marked;
//! * `levitation_time.svg` (b): t_l against d (fig. 2.5b), tolerance 0.5 mm, with and without
//!   history, the critical diameters and the reference values D-002-5;
//! * `critical_diameter.svg` (c): the linearised eigenvalues against d and node/spiral from
//!   direct integration (see [`modes`]);
//! * `sink_rise.svg` (d): fig. 2.10, 3 and 5 mm sinking from +0.9 L and rising from −0.9 L;
//! * `force_budget.svg` (e): fig. 2.9, the forces over the weight for 2 and 6 mm.
//!
//! "With history" means the 0.2 s window with the exponential tail (the thesis's fig. 2.10
//! setting; within 0.2 % of full memory in t_l, see `magsep chart history`). A run that has
//! not settled by its time limit reports its limit (a lower bound) and `settled: false`.

#[path = "levitation_modes.rs"]
mod modes;

use std::path::Path;

use magsep_systems::fluid::config::Integrator;
use magsep_systems::fluid::history::HistoryKernel;
use magsep_systems::fluid::levitation::{critical_diameter, levitation_time};
use magsep_systems::fluid::single::{SphereInLiquid, Trajectory};
use rayon::prelude::*;
use serde_json::{Value, json};

pub(crate) use super::runtime;
use crate::chart::{Chart, Figure, Line, Series, Style, write_svg};
use crate::studies::bench::BenchError;

/// Half height L of the table 2.1 rig [m] (the magnet face is at y = −L).
pub(crate) const HALF_HEIGHT: f64 = 0.075;
/// Levitation tolerance of the thesis [m].
pub(crate) const TOLERANCE: f64 = 0.5e-3;
/// Time step of every levitation run [s].
pub(crate) const DT: f64 = 1e-3;
/// History window of the "with history" runs [s] (fig. 2.10).
pub(crate) const WINDOW: f64 = 0.2;

/// Reference levitation times without history (d [mm], t_l [s]), D-002-5 (docs/references.md).
const CHECK_NO_HISTORY: [(f64, f64); 7] = [
    (1.0, 23.1),
    (2.0, 6.44),
    (3.0, 3.05),
    (4.0, 1.69),
    (4.5, 2.23),
    (5.0, 2.15),
    (6.0, 2.98),
];
/// Reference levitation times with history (d [mm], t_l [s]), D-002-5 (docs/references.md).
const CHECK_HISTORY: [(f64, f64); 3] = [(2.0, 11.0), (4.0, 5.3), (6.0, 3.5)];

/// Sizes of the chart (quick or full).
struct Sizes {
    quick: bool,
    /// Diameters of the trajectory panels [m].
    trajectory_diameters: Vec<f64>,
    /// Diameters of the t_l sweep [m].
    sweep_diameters: Vec<f64>,
    /// Longest run [s].
    t_max: f64,
}

impl Sizes {
    fn new(quick: bool) -> Self {
        let mm = |v: &[f64]| v.iter().map(|d| d * 1e-3).collect::<Vec<_>>();
        if quick {
            Self {
                quick,
                trajectory_diameters: mm(&[2.0, 6.0]),
                sweep_diameters: mm(&[2.0, 4.0, 6.0]),
                t_max: 6.0,
            }
        } else {
            Self {
                quick,
                trajectory_diameters: mm(&[1.0, 2.0, 4.0, 6.0]),
                sweep_diameters: (10..=160).map(|k| k as f64 * 0.05e-3).collect(),
                t_max: 400.0,
            }
        }
    }

    /// Title suffix saying what quick mode reduces.
    fn note(&self) -> &'static str {
        if self.quick {
            " [quick: few diameters, runs capped at 6 s]"
        } else {
            ""
        }
    }
}

/// The table 2.1 rig with a sphere of `d` [m], history off or with the 0.2 s window + tail.
pub(crate) fn rig(d: f64, history: bool) -> SphereInLiquid {
    let mut s = SphereInLiquid::table_2_1(d);
    s.terms.history = history;
    s.history = HistoryKernel::window(WINDOW, DT, true);
    s
}

/// Equilibrium height y_e [m] of `s`.
pub(crate) fn equilibrium(s: &SphereInLiquid) -> Result<f64, BenchError> {
    s.magnet
        .equilibrium_height(&s.liquid, s.gravity, s.density)
        .ok_or_else(|| BenchError::Runtime("no equilibrium height in range".into()))
}

/// A settled run: trajectory sampled every step, t_l [s], whether it settled in time.
pub(crate) struct Settled {
    pub(crate) trajectory: Trajectory,
    pub(crate) levitation_time: f64,
    pub(crate) settled: bool,
}

/// Release `s` from rest at `y0` [m] and run until the last exit from the tolerance band lies
/// in the first 3/4 of the run (doubling from 16 s), at most `t_max` [s].
pub(crate) fn settle(s: &SphereInLiquid, y0: f64, t_max: f64) -> Result<Settled, BenchError> {
    let y_e = equilibrium(s)?;
    let mut t_end = 16.0f64.min(t_max);
    loop {
        let trajectory = s.simulate(y0, 0.0, DT, t_end, 1).map_err(runtime)?;
        let t_l = levitation_time(&trajectory.times, &trajectory.heights, y_e, TOLERANCE);
        let settled = t_l < 0.75 * t_end;
        if settled || t_end >= t_max {
            return Ok(Settled {
                trajectory,
                levitation_time: t_l,
                settled,
            });
        }
        t_end = (2.0 * t_end).min(t_max);
    }
}

/// At most `max` points `(x, y)` (every k-th, always the last).
pub(crate) fn thin(xs: &[f64], ys: &[f64], max: usize) -> Vec<(f64, f64)> {
    let n = xs.len().min(ys.len());
    let k = n.div_ceil(max.max(1)).max(1);
    let mut pts: Vec<(f64, f64)> = (0..n).step_by(k).map(|i| (xs[i], ys[i])).collect();
    if n > 0 && !(n - 1).is_multiple_of(k) {
        pts.push((xs[n - 1], ys[n - 1]));
    }
    pts
}

/// Write `svg` to `out/name`; returns the path as a string.
pub(crate) fn save(out: &Path, name: &str, svg: &str) -> Result<String, BenchError> {
    let path = out.join(name);
    write_svg(&path, svg).map_err(|e| BenchError::Runtime(format!("{}: {e}", path.display())))?;
    Ok(path.display().to_string())
}

/// Round to 4 significant digits for the summary.
pub(crate) fn r4(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let p = 10f64.powi(3 - x.abs().log10().floor() as i32);
    (x * p).round() / p
}

/// `magsep chart levitation --out DIR [--quick]`: the SVGs listed in the module docs and a
/// JSON summary (chart paths and numbers) on stdout.
///
/// # Errors
/// [`BenchError::Runtime`] when a directory or file cannot be written or a run fails.
pub fn chart_levitation(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let sizes = Sizes::new(quick);
    let probe = rig(1e-3, false);
    let y_e = equilibrium(&probe)?;
    let d_crit_xi = critical_diameter(&probe.magnet, &probe.liquid, probe.gravity, 1434.0, true)
        .ok_or_else(|| runtime("no critical diameter"))?;
    let d_crit = critical_diameter(&probe.magnet, &probe.liquid, probe.gravity, 1434.0, false)
        .ok_or_else(|| runtime("no critical diameter"))?;
    let mut charts = Vec::new();
    let (path, trajectories) = trajectory_chart(out, &sizes, y_e)?;
    charts.push(path);
    let (path, sweep) = sweep_chart(out, &sizes, (d_crit_xi, d_crit))?;
    charts.push(path);
    let (path, modes) = modes::critical_chart(out, quick, (d_crit_xi, d_crit))?;
    charts.push(path);
    let (path, sink_rise) = sink_rise_chart(out, &sizes, y_e)?;
    charts.push(path);
    let (path, budget) = modes::budget_chart(out, quick, sizes.t_max)?;
    charts.push(path);
    let summary = json!({
        "chart": "levitation",
        "quick": quick,
        "charts": charts,
        "rig": "table 2.1: bottom magnet, MnCl2 (rho_f 1403, mu 5.54e-3, chi 7e-4), PVC-U rho_p 1434",
        "integrator": "linearly implicit Euler, dt = 1 ms, Schiller-Naumann drag; history = 0.2 s window + tail",
        "equilibrium_height_m": r4(y_e),
        "equilibrium_height_over_L": r4(y_e / HALF_HEIGHT),
        "critical_diameter_mm": {"with_added_mass": r4(d_crit_xi * 1e3), "without_added_mass": r4(d_crit * 1e3)},
        "trajectories": trajectories,
        "levitation_time": sweep,
        "critical_diameter": modes,
        "sink_rise": sink_rise,
        "force_budget": budget,
    });
    crate::studies::bench::say(summary)
}

/// (a) y(t) without and with history.
fn trajectory_chart(out: &Path, sizes: &Sizes, y_e: f64) -> Result<(String, Value), BenchError> {
    let y0 = -0.9 * HALF_HEIGHT;
    let runs: Vec<(f64, bool)> = [false, true]
        .iter()
        .flat_map(|&h| sizes.trajectory_diameters.iter().map(move |&d| (d, h)))
        .collect();
    let results: Vec<Result<Settled, BenchError>> = runs
        .par_iter()
        .map(|&(d, h)| settle(&rig(d, h), y0, sizes.t_max.min(60.0)))
        .collect();
    let mut panels = Vec::new();
    let mut rows = Vec::new();
    for (p, history) in [false, true].into_iter().enumerate() {
        let label = if history {
            "with history (0.2 s window + tail)"
        } else {
            "without history (fig. 2.5a)"
        };
        let mut chart = Chart::new(format!("y(t) from y0 = -0.9 L, {label}"))
            .x_label("t [s]")
            .y_label("y [mm]");
        let mut t_last: f64 = 0.0;
        for (k, &d) in sizes.trajectory_diameters.iter().enumerate() {
            let run = results[p * sizes.trajectory_diameters.len() + k]
                .as_ref()
                .map_err(|e| runtime(e.to_string()))?;
            let tr = &run.trajectory;
            // show up to twice the levitation time (at least 5 s) of the slowest shown
            let t_show = (2.0 * run.levitation_time).max(5.0);
            let n = tr.times.partition_point(|&t| t <= t_show);
            let ys: Vec<f64> = tr.heights[..n].iter().map(|y| y * 1e3).collect();
            t_last = t_last.max(tr.times[n.saturating_sub(1)]);
            chart = chart.series(
                Series::new(
                    format!("{:.0} mm: t_l = {:.2} s", d * 1e3, run.levitation_time),
                    thin(&tr.times[..n], &ys, 900),
                )
                .style(Style::Line),
            );
            let max_over = tr.heights.iter().fold(f64::NEG_INFINITY, |m, &y| m.max(y)) - y_e;
            rows.push(json!({
                "d_mm": d * 1e3, "history": history,
                "levitation_time_s": r4(run.levitation_time), "settled": run.settled,
                "max_overshoot_mm": r4(max_over.max(0.0) * 1e3),
                "max_reynolds": r4(tr.max_reynolds),
            }));
        }
        chart = chart.line(
            Line::new(
                format!("y_e = {:.3} L", y_e / HALF_HEIGHT),
                [(0.0, y_e * 1e3), (t_last, y_e * 1e3)],
            )
            .dashed(true),
        );
        panels.push(chart);
    }
    let mut fig = Figure::new(
        format!(
            "Levitation of PVC-U spheres above a bottom magnet (table 2.1 rig, dt = 1 ms){}",
            sizes.note()
        ),
        2,
    );
    for p in panels {
        fig = fig.panel(p);
    }
    let path = save(
        out,
        "levitation_trajectories.svg",
        &fig.to_svg(620.0, 440.0),
    )?;
    Ok((path, Value::Array(rows)))
}

/// (b) t_l against d without and with history.
fn sweep_chart(
    out: &Path,
    sizes: &Sizes,
    (d_crit_xi, d_crit): (f64, f64),
) -> Result<(String, Value), BenchError> {
    let y0 = -0.9 * HALF_HEIGHT;
    let ds = &sizes.sweep_diameters;
    let runs: Vec<(f64, bool)> = [false, true]
        .iter()
        .flat_map(|&h| ds.iter().map(move |&d| (d, h)))
        .collect();
    let times: Vec<Result<(f64, bool), BenchError>> = runs
        .par_iter()
        .map(|&(d, h)| settle(&rig(d, h), y0, sizes.t_max).map(|r| (r.levitation_time, r.settled)))
        .collect();
    let times = times.into_iter().collect::<Result<Vec<_>, _>>()?;
    let (none, hist) = times.split_at(ds.len());
    // the D-002-5 points, ours with the implicit step and with explicit Euler (as D-002-5)
    let check: Vec<Result<Value, BenchError>> = CHECK_NO_HISTORY
        .par_iter()
        .filter(|(d, _)| !sizes.quick || *d == 2.0 || *d == 4.0)
        .map(|&(d_mm, spec)| {
            let s = rig(d_mm * 1e-3, false);
            let implicit = settle(&s, y0, sizes.t_max)?;
            let mut e = s.clone();
            e.integrator = Integrator::Explicit;
            let explicit = settle(&e, y0, sizes.t_max)?;
            let h = settle(&rig(d_mm * 1e-3, true), y0, sizes.t_max)?;
            let spec_h = CHECK_HISTORY.iter().find(|c| c.0 == d_mm).map(|c| c.1);
            Ok(json!({
                "d_mm": d_mm, "spec_no_history_s": spec,
                "ours_no_history_s": r4(implicit.levitation_time),
                "ours_no_history_explicit_s": r4(explicit.levitation_time),
                "relative_difference": r4(implicit.levitation_time / spec - 1.0),
                "spec_history_s": spec_h, "ours_history_s": r4(h.levitation_time),
                "settled": implicit.settled && explicit.settled && h.settled,
            }))
        })
        .collect();
    let check = check.into_iter().collect::<Result<Vec<_>, _>>()?;
    let pts = |v: &[(f64, bool)]| -> Vec<(f64, f64)> {
        ds.iter().zip(v).map(|(d, r)| (d * 1e3, r.0)).collect()
    };
    let (lo, hi) = times.iter().fold((f64::INFINITY, 0.0f64), |a, r| {
        (a.0.min(r.0.max(0.1)), a.1.max(r.0))
    });
    let vline = |name: String, d: f64| Line::new(name, [(d * 1e3, lo), (d * 1e3, hi)]);
    let chart = Chart::new(format!(
        "Levitation time (|y - y_e| <= 0.5 mm) from y0 = -0.9 L (fig. 2.5b){}",
        sizes.note()
    ))
    .x_label("d [mm]")
    .y_label("t_l [s]")
    .y_log(true)
    .series(Series::new("no history", pts(none)).style(Style::Line))
    .series(Series::new("history (0.2 s window + tail)", pts(hist)).style(Style::Line))
    .series(
        Series::new("D-002-5, no history", CHECK_NO_HISTORY.iter().copied()).style(Style::Markers),
    )
    .series(Series::new("D-002-5, history", CHECK_HISTORY.iter().copied()).style(Style::Markers))
    .line(
        vline(
            format!("d_crit = {:.2} mm (with added mass)", d_crit_xi * 1e3),
            d_crit_xi,
        )
        .dashed(true),
    )
    .line(vline(
        format!("d_crit = {:.2} mm (without, thesis)", d_crit * 1e3),
        d_crit,
    ));
    let path = save(out, "levitation_time.svg", &chart.to_svg(900.0, 560.0))?;
    let summary = json!({
        "diameters_mm": ds.iter().map(|d| r4(d * 1e3)).collect::<Vec<_>>(),
        "no_history_s": none.iter().map(|r| r4(r.0)).collect::<Vec<_>>(),
        "history_s": hist.iter().map(|r| r4(r.0)).collect::<Vec<_>>(),
        "all_settled": times.iter().all(|r| r.1),
        "minimum_no_history": refine_minimum(ds, none, false, sizes)?,
        "minimum_history": refine_minimum(ds, hist, true, sizes)?,
        "spec_minimum": "near 4-4.5 mm (V-DS-R4, V-DS-4)",
        "check": check,
    });
    Ok((path, summary))
}

/// (d) fig. 2.10: 3 and 5 mm, sinking and rising, with and without history.
fn sink_rise_chart(out: &Path, sizes: &Sizes, y_e: f64) -> Result<(String, Value), BenchError> {
    let cases: Vec<(f64, f64, &str)> = [3e-3, 5e-3]
        .iter()
        .flat_map(|&d| {
            [
                (d, 0.9 * HALF_HEIGHT, "sinking"),
                (d, -0.9 * HALF_HEIGHT, "rising"),
            ]
        })
        .collect();
    let runs: Vec<(usize, bool)> = (0..cases.len())
        .flat_map(|c| [(c, false), (c, true)])
        .collect();
    let results: Vec<Result<Settled, BenchError>> = runs
        .par_iter()
        .map(|&(c, h)| settle(&rig(cases[c].0, h), cases[c].1, sizes.t_max.min(60.0)))
        .collect();
    let results = results.into_iter().collect::<Result<Vec<_>, _>>()?;
    let mut fig = Figure::new(
        format!(
            "Sinking (from +0.9 L) and rising (from -0.9 L) PVC-U spheres, history = 0.2 s window + tail (fig. 2.10){}",
            sizes.note()
        ),
        2,
    );
    let mut rows = Vec::new();
    for (c, &(d, y0, what)) in cases.iter().enumerate() {
        let (none, hist) = (&results[2 * c], &results[2 * c + 1]);
        let t_show = (1.3 * none.levitation_time.max(hist.levitation_time)).max(3.0);
        let mut chart = Chart::new(format!("{:.0} mm, {what}", d * 1e3))
            .x_label("t [s]")
            .y_label("y [mm]");
        for (run, name) in [(none, "no history"), (hist, "history")] {
            let tr = &run.trajectory;
            let n = tr.times.partition_point(|&t| t <= t_show);
            let ys: Vec<f64> = tr.heights[..n].iter().map(|y| y * 1e3).collect();
            chart = chart.series(
                Series::new(
                    format!("{name}: t_l = {:.2} s", run.levitation_time),
                    thin(&tr.times[..n], &ys, 900),
                )
                .style(Style::Line),
            );
        }
        chart = chart.line(Line::new("y_e", [(0.0, y_e * 1e3), (t_show, y_e * 1e3)]).dashed(true));
        fig = fig.panel(chart);
        let spec_ratio = match what {
            "rising" => 0.53,
            _ => 0.64,
        };
        rows.push(json!({
            "d_mm": d * 1e3, "case": what, "y0_over_L": r4(y0 / HALF_HEIGHT),
            "no_history_s": r4(none.levitation_time), "history_s": r4(hist.levitation_time),
            "ratio_no_history_over_history": r4(none.levitation_time / hist.levitation_time),
            "spec_ratio": if d == 5e-3 { Some(spec_ratio) } else { None },
            "settled": none.settled && hist.settled,
        }));
    }
    let path = save(out, "sink_rise.svg", &fig.to_svg(560.0, 400.0))?;
    Ok((path, Value::Array(rows)))
}

/// The smallest settled t_l of a sweep, refined (full mode) on 41 diameters between the grid
/// neighbours of the grid minimum.
fn refine_minimum(
    ds: &[f64],
    v: &[(f64, bool)],
    history: bool,
    sizes: &Sizes,
) -> Result<Value, BenchError> {
    let Some((k, grid_t)) = v
        .iter()
        .enumerate()
        .filter(|(_, r)| r.1)
        .map(|(k, r)| (k, r.0))
        .min_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return Ok(json!({"settled_points": 0}));
    };
    let mut best = (ds[k], grid_t);
    if !sizes.quick && k > 0 && k + 1 < ds.len() {
        let (lo, hi) = (ds[k - 1], ds[k + 1]);
        let fine: Vec<f64> = (0..=40).map(|j| lo + (hi - lo) * j as f64 / 40.0).collect();
        let y0 = -0.9 * HALF_HEIGHT;
        let runs: Vec<Result<Settled, BenchError>> = fine
            .par_iter()
            .map(|&d| settle(&rig(d, history), y0, sizes.t_max))
            .collect();
        for (d, r) in fine.iter().zip(runs) {
            let r = r?;
            if r.settled && r.levitation_time < best.1 {
                best = (*d, r.levitation_time);
            }
        }
    }
    Ok(json!({
        "grid_d_mm": r4(ds[k] * 1e3), "grid_levitation_time_s": r4(grid_t),
        "refined_d_mm": r4(best.0 * 1e3), "refined_levitation_time_s": r4(best.1),
    }))
}
