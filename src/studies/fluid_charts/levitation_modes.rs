//! Parts (c) and (e) of `magsep chart levitation`: the critical diameter (linearised
//! eigenvalues against node/spiral from direct integration) and the force budget (fig. 2.9).
//!
//! **Direct integration of the node/spiral switch.** A sphere released from rest a small
//! distance δ = 1 mm below y_e, without history and with Stokes drag (the linearisation's
//! assumptions), overshoots y_e if and only if the equilibrium is a spiral: from rest, a node's
//! `A e^{λ₁t} + B e^{λ₂t}` never changes sign. The first overshoot of the linear spiral is
//! `δ exp(−π|Re λ|/Im λ)`; it is detected above 1e-12 δ (round-off of y is ~1e-16 m), which
//! resolves the switch to within about 0.4 % of d_crit. Both criteria are run: with added
//! mass (eq. 2.50, 2.91 mm) and without (the thesis's 3.2 mm), switching `terms.added_mass`.

use std::path::Path;

use glam::DVec3;
use magsep_systems::fluid::drag::{DragLaw, translational_drag};
use magsep_systems::fluid::levitation::LinearLevitation;
use rayon::prelude::*;
use serde_json::{Value, json};

use super::{HALF_HEIGHT, equilibrium, r4, rig, runtime, save, settle};
use crate::chart::{Chart, Figure, LegendPosition, Line, Series, Style};
use crate::studies::bench::BenchError;

/// Release distance below y_e of the node/spiral runs [m].
const DELTA: f64 = 1e-3;
/// Smallest overshoot counted, relative to δ.
const DETECT: f64 = 1e-12;

/// First overshoot over δ of a release from rest at y_e − δ (no history, Stokes drag), 0 if
/// none within `t_end` [s].
fn overshoot(d: f64, added_mass: bool, t_end: f64) -> Result<f64, BenchError> {
    let mut s = rig(d, false);
    s.drag_law = DragLaw::Stokes;
    s.terms.added_mass = added_mass;
    let y_e = equilibrium(&s)?;
    let tr = s
        .simulate(y_e - DELTA, 0.0, super::DT, t_end, 1)
        .map_err(runtime)?;
    let top = tr.heights.iter().fold(f64::NEG_INFINITY, |m, &y| m.max(y));
    Ok(((top - y_e) / DELTA).max(0.0))
}

/// Number of crossings of y_e of a trajectory.
fn crossings(heights: &[f64], y_e: f64) -> usize {
    heights
        .windows(2)
        .filter(|w| (w[0] - y_e).signum() != (w[1] - y_e).signum() && w[1] != y_e)
        .count()
}

/// (c) eigenvalues and node/spiral against d.
pub(super) fn critical_chart(
    out: &Path,
    quick: bool,
    (d_crit_xi, d_crit): (f64, f64),
) -> Result<(String, Value), BenchError> {
    let probe = rig(1e-3, false);
    let lin = |d: f64, xi: bool| {
        LinearLevitation::new(&probe.magnet, &probe.liquid, probe.gravity, d, 1434.0, xi)
            .ok_or_else(|| runtime("no linearisation"))
    };
    // eigenvalues on 0.5-8 mm
    let n_eig = if quick { 40 } else { 300 };
    let mut re1 = Vec::new();
    let mut re2 = Vec::new();
    let mut im = Vec::new();
    let mut im_noxi = Vec::new();
    for k in 0..=n_eig {
        let d = 0.5e-3 + 7.5e-3 * k as f64 / n_eig as f64;
        let [a, b] = lin(d, true)?.eigenvalues();
        re1.push((d * 1e3, a.0));
        re2.push((d * 1e3, b.0));
        im.push((d * 1e3, a.1.abs()));
        im_noxi.push((d * 1e3, lin(d, false)?.eigenvalues()[0].1.abs()));
    }
    // direct integration around the switch
    let (lo, hi, n_dir, t_end) = if quick {
        (2.5e-3, 3.7e-3, 7, 6.0)
    } else {
        (2.5e-3, 3.7e-3, 121, 40.0)
    };
    let ds: Vec<f64> = (0..n_dir)
        .map(|k| lo + (hi - lo) * k as f64 / (n_dir - 1) as f64)
        .collect();
    let mut panels_rows = Vec::new();
    let mut ratio_panel = Chart::new("First overshoot from rest at y_e - 1 mm vs exp(-pi|Re|/Im)")
        .x_label("d [mm]")
        .y_label("overshoot / 1 mm [-]")
        .y_log(true)
        .y_range(1e-15, 1.0)
        .legend(LegendPosition::BottomRight)
        .line(Line::new("threshold", [(lo * 1e3, DETECT), (hi * 1e3, DETECT)]).color("#999999"));
    let mut class_panel = Chart::new("Node (0) or spiral (1): linear theory vs integration")
        .x_label("d [mm]")
        .y_label("spiral [-]")
        .y_range(-0.2, 1.5);
    for (xi, d_c, name) in [
        (true, d_crit_xi, "added mass"),
        (false, d_crit, "no added mass"),
    ] {
        let measured: Vec<Result<f64, BenchError>> =
            ds.par_iter().map(|&d| overshoot(d, xi, t_end)).collect();
        let measured = measured.into_iter().collect::<Result<Vec<_>, _>>()?;
        let theory: Vec<(f64, f64)> = ds
            .iter()
            .map(|&d| {
                let [a, _] = lin(d, xi)
                    .map(|l| l.eigenvalues())
                    .unwrap_or([(0.0, 0.0); 2]);
                let r = if a.1 > 0.0 {
                    (-std::f64::consts::PI * a.0.abs() / a.1).exp()
                } else {
                    0.0
                };
                (d * 1e3, r)
            })
            .collect();
        let spiral: Vec<bool> = measured.iter().map(|&r| r > DETECT).collect();
        // the switch: the first diameter from which every larger one is a spiral
        let first = spiral.iter().rposition(|s| !s).map_or(0, |k| k + 1);
        let switch = ds.get(first).copied().unwrap_or(f64::NAN);
        let below = first.checked_sub(1).map(|k| ds[k]).unwrap_or(f64::NAN);
        let largest_node = measured[..first].iter().fold(0.0f64, |a, &r| a.max(r));
        ratio_panel = ratio_panel
            .series(
                Series::new(
                    format!("integration, {name}"),
                    ds.iter().zip(&measured).map(|(d, r)| (d * 1e3, *r)),
                )
                .style(Style::Markers),
            )
            .line(Line::new(format!("linear theory, {name}"), theory).dashed(!xi));
        let offset = if xi { 0.0 } else { 0.05 };
        class_panel = class_panel
            .series(
                Series::new(
                    format!("integration, {name}"),
                    ds.iter()
                        .zip(&spiral)
                        .map(|(d, &s)| (d * 1e3, f64::from(u8::from(s)) + offset)),
                )
                .style(Style::Markers),
            )
            .line(
                Line::new(
                    format!("linear, {name}: {:.3} mm", d_c * 1e3),
                    [
                        (lo * 1e3, offset),
                        (d_c * 1e3, offset),
                        (d_c * 1e3, 1.0 + offset),
                        (hi * 1e3, 1.0 + offset),
                    ],
                )
                .dashed(!xi),
            );
        panels_rows.push(json!({
            "criterion": name,
            "linear_d_crit_mm": r4(d_c * 1e3),
            "integration_last_node_mm": r4(below * 1e3),
            "integration_first_spiral_mm": r4(switch * 1e3),
            "relative_difference": r4(switch / d_c - 1.0),
            "detection_threshold_over_delta": DETECT,
            "largest_overshoot_over_delta_below_switch": largest_node,
        }));
    }
    // the thesis's node/spiral result (V-DS-R3, [T002 §2.5.1.1]) from y0 = -0.9 L (Schiller-Naumann): crossings of y_e
    let v3_ds: &[f64] = if quick {
        &[2e-3, 6e-3]
    } else {
        &[1e-3, 2e-3, 4e-3, 6e-3]
    };
    let v3: Vec<Result<Value, BenchError>> = v3_ds
        .par_iter()
        .map(|&d| {
            let s = rig(d, false);
            let y_e = equilibrium(&s)?;
            let tr = s
                .simulate(-0.9 * HALF_HEIGHT, 0.0, super::DT, t_end, 1)
                .map_err(runtime)?;
            let linear = lin(d, true)?.approach();
            Ok(json!({"d_mm": d * 1e3, "crossings_of_y_e": crossings(&tr.heights, y_e), "linear": linear}))
        })
        .collect();
    let v3 = v3.into_iter().collect::<Result<Vec<_>, _>>()?;
    let eig_panel = Chart::new("Eigenvalues of the linearisation (eq. 2.49), with added mass")
        .x_label("d [mm]")
        .y_label("lambda [1/s]")
        .series(Series::new("Re lambda_1", re1).style(Style::Line))
        .series(Series::new("Re lambda_2", re2).style(Style::Line))
        .series(Series::new("|Im lambda|", im).style(Style::Line))
        .series(Series::new("|Im lambda|, without added mass", im_noxi).style(Style::Dashed))
        .y_range(-6.0, 4.0)
        .line(
            Line::new(
                format!("d_crit = {:.2} mm, added mass", d_crit_xi * 1e3),
                [(d_crit_xi * 1e3, -6.0), (d_crit_xi * 1e3, 4.0)],
            )
            .dashed(true),
        )
        .line(Line::new(
            format!("d_crit = {:.2} mm, no added mass", d_crit * 1e3),
            [(d_crit * 1e3, -6.0), (d_crit * 1e3, 4.0)],
        ));
    let note = if quick {
        " [quick: 7 diameters, runs of 6 s]"
    } else {
        ""
    };
    let fig = Figure::new(
        format!("Critical diameter of the table 2.1 rig: node vs spiral (no history){note}"),
        3,
    )
    .panel(eig_panel)
    .panel(ratio_panel)
    .panel(class_panel);
    let path = save(out, "critical_diameter.svg", &fig.to_svg(560.0, 440.0))?;
    Ok((
        path,
        json!({"switch": panels_rows, "from_minus_0.9_L": v3, "release_offset_m": DELTA}),
    ))
}

/// (e) fig. 2.9: drag, history, added mass and net static force over the weight.
pub(super) fn budget_chart(
    out: &Path,
    quick: bool,
    t_max: f64,
) -> Result<(String, Value), BenchError> {
    let mut fig = Figure::new(
        format!(
            "Force budget / weight, released at -0.9 L with history (fig. 2.9){}",
            if quick {
                " [quick: runs capped at 6 s]"
            } else {
                ""
            }
        ),
        2,
    );
    let mut rows = Vec::new();
    for d in [2e-3, 6e-3] {
        let s = rig(d, true);
        let run = settle(&s, -0.9 * HALF_HEIGHT, t_max.min(60.0))?;
        let tr = &run.trajectory;
        let dt = super::DT;
        let v_p = s.volume();
        let weight = s.density * v_p * s.gravity;
        let n = tr.velocities.len().saturating_sub(1);
        let (mut t, mut drag, mut hist, mut am, mut stat) =
            (vec![], vec![], vec![], vec![], vec![]);
        let mut residual: f64 = 0.0;
        for k in 0..n {
            let (v0, v1) = (tr.velocities[k], tr.velocities[k + 1]);
            let a = (v1 - v0) / dt;
            let (_, stiff, _) = translational_drag(
                s.drag_law,
                s.liquid.density,
                s.liquid.viscosity,
                d,
                DVec3::new(0.0, -v0, 0.0),
            );
            // the forces the linearly implicit step applied on [t_k, t_k+1]
            let f_d = -stiff * v1;
            let f_h = tr.history_force[k + 1];
            let f_am = -0.5 * s.liquid.density * v_p * a;
            let f_s = s.static_force(tr.heights[k]);
            residual = residual.max((s.density * v_p * a - (f_d + f_h + f_am + f_s)).abs());
            t.push(tr.times[k + 1]);
            drag.push(f_d / weight);
            hist.push(f_h / weight);
            am.push(f_am / weight);
            stat.push(f_s / weight);
        }
        let t_show = (1.5 * run.levitation_time).max(2.0);
        let m = t.partition_point(|&x| x <= t_show);
        let peak = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let impulse = |v: &[f64]| v.iter().map(|x| x.abs() * dt).sum::<f64>();
        let mut chart = Chart::new(format!(
            "{:.0} mm (t_l = {:.2} s)",
            d * 1e3,
            run.levitation_time
        ))
        .x_label("t [s]")
        .x_log(true)
        .y_label("F / (rho_p V g) [-]");
        for (name, v) in [
            ("drag", &drag),
            ("history", &hist),
            ("added mass -1/2 rho_f V dv/dt", &am),
            ("buoyancy + magnetic - weight", &stat),
        ] {
            chart =
                chart.series(Series::new(name, thin_log(&t[..m], &v[..m], 600)).style(Style::Line));
        }
        fig = fig.panel(chart);
        rows.push(json!({
            "d_mm": d * 1e3,
            "levitation_time_s": r4(run.levitation_time),
            "peak_over_weight": {
                "drag": r4(peak(&drag)), "history": r4(peak(&hist)),
                "added_mass": r4(peak(&am)), "net_static": r4(peak(&stat)),
            },
            "peak_history_over_peak_drag": r4(peak(&hist) / peak(&drag)),
            "integral_abs_over_weight_s": {
                "drag": r4(impulse(&drag)), "history": r4(impulse(&hist)),
                "added_mass": r4(impulse(&am)), "net_static": r4(impulse(&stat)),
            },
            "integral_history_over_integral_drag": r4(impulse(&hist) / impulse(&drag)),
            "max_budget_residual_over_weight": residual / weight,
        }));
    }
    let path = save(out, "force_budget.svg", &fig.to_svg(620.0, 440.0))?;
    Ok((path, Value::Array(rows)))
}

/// At most about `max` points `(x, y)` geometrically spaced in the index (for a log x axis
/// over uniformly sampled data), always with the first and last.
fn thin_log(xs: &[f64], ys: &[f64], max: usize) -> Vec<(f64, f64)> {
    let n = xs.len().min(ys.len());
    if n == 0 {
        return Vec::new();
    }
    let ratio = (n as f64).powf(1.0 / max.max(2) as f64);
    let mut pts = Vec::new();
    let (mut i, mut f) = (0usize, 1.0f64);
    while i < n {
        pts.push((xs[i], ys[i]));
        f *= ratio;
        i = (f.floor() as usize - 1).max(i + 1);
    }
    if pts.last().map(|p| p.0) != Some(xs[n - 1]) {
        pts.push((xs[n - 1], ys[n - 1]));
    }
    pts
}
