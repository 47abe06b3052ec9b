//! `magsep chart brownian --out DIR [--quick]`: the capture studies of thesis 000, ch. 6
//! (figs. 6.4-6.13) as SVG charts and JSON summaries.
//!
//! The sweeps are derived from the scene files `scenes/brownian_angle.toml`,
//! `scenes/brownian_aspect.toml` and `scenes/brownian_concentrated.toml` (compiled in): the
//! field direction (angle α between the fibre axis and the field), the fibre's half length and
//! the particle radius and table 6.1 moment are rewritten in the scene text, and so are the run
//! parameters of the [`Reduction`] in use. The thesis's durations (50 s at Δt = 5e-5 s, 30
//! runs of 2 × 100 particles) cost ~1e6 steps per run, far beyond a chart command, so every
//! sweep is reduced; the reductions are printed in the chart subtitles, in each sweep's JSON
//! file and in the JSON printed on stdout.
//!
//! Charts written to DIR:
//! * `brownian_angle_curves.svg`: captured fraction against time for α = 0, 15, ..., 90° in the
//!   TOP and SIDE regions, R = 75 nm and 212 nm (figs. 6.4).
//! * `brownian_final_vs_angle.svg`: final captured fraction (TOP, SIDE, volume-weighted) and
//!   Brownian fraction against α with 95 % intervals for R = 25 (full mode), 75 and 212 nm
//!   (figs. 6.6a, 6.8).
//! * `brownian_aspect.svg`: L/D = 5/3 against 20/3 for R = 125 nm (figs. 6.6b, 6.7).
//! * `brownian_concentrated.svg`: the N = 500 cloud above the rim, longitudinal (α = 0) against
//!   transverse (α = 90°) (figs. 6.12, 6.13).

use std::path::Path;

use rayon::prelude::*;
use serde_json::{Value, json};

use crate::chart::{Chart, Figure, LegendPosition, Line, Series, Style, write_svg};
use crate::studies::bench::BenchError;

use super::brownian_sweep::*;

/// The sweep settings of one mode.
#[derive(Debug, Clone)]
struct Plan {
    angles: Vec<f64>,
    radii: Vec<f64>,
    dilute: Reduction,
    /// The smallest radius (25 nm, slowest to step) runs on fewer angles and runs.
    small: Option<(f64, Vec<f64>, Reduction)>,
    aspect_angles: Vec<f64>,
    aspect: Reduction,
    concentrated: Reduction,
}

fn plan(quick: bool) -> Plan {
    if quick {
        return Plan {
            angles: vec![0.0, 45.0, 90.0],
            radii: vec![75e-9, 212e-9],
            dilute: Reduction::free_draining(1e-3, 1.0, 2, 20, 10),
            small: None,
            aspect_angles: vec![0.0, 90.0],
            aspect: Reduction::free_draining(1e-3, 1.0, 2, 20, 10),
            concentrated: Reduction::free_draining(2e-4, 1.0, 1, 50, 30),
        };
    }
    Plan {
        angles: (0..=6).map(|k| 15.0 * k as f64).collect(),
        radii: vec![75e-9, 212e-9],
        dilute: Reduction::free_draining(1e-3, 10.0, 2, 50, 100),
        // 25 nm particles move ~5 radii per 1 ms step by diffusion alone, so the adaptive
        // stepper bisects every step several times: only the two extreme angles, fewer particles
        small: Some((
            25e-9,
            vec![0.0, 90.0],
            Reduction::free_draining(1e-3, 10.0, 1, 20, 100),
        )),
        aspect_angles: vec![0.0, 45.0, 90.0],
        aspect: Reduction::free_draining(1e-3, 3.0, 2, 50, 50),
        // 2 s, longer than the thesis's 1 s: without HI the cloud needs ~1 s (D-000-11 in docs/references.md);
        // 100 particles: N = 500 with dipoles and Mie contacts did not finish 2 s within
        // 20 min here (captured particles pile up at the rim and the stepper bisects deeply)
        concentrated: Reduction::free_draining(2e-4, 2.0, 1, 100, 50),
    }
}

/// One job of a sweep: its parameters (with the sweep's name) and derived scene text.
struct Job {
    params: Value,
    text: String,
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> BenchError {
    BenchError::Runtime(format!("{}: {e}", path.display()))
}

fn nm(r: f64) -> String {
    format!("{:.0} nm", r * 1e9)
}

fn fraction_series(name: String, pts: &[(f64, (f64, f64, f64))]) -> Series {
    Series::new(name, pts.iter().map(|(x, e)| (*x, e.0)))
        .y_err(pts.iter().map(|(_, e)| 0.5 * (e.2 - e.1)))
        .style(Style::LineMarkers)
}

fn find<'a>(
    results: &'a [(Value, Value)],
    sweep: &str,
    pred: impl Fn(&Value) -> bool,
) -> Option<&'a Value> {
    results
        .iter()
        .find(|(p, _)| p["sweep"] == sweep && pred(p))
        .map(|(_, s)| s)
}

fn close(v: &Value, x: f64) -> bool {
    v.as_f64()
        .is_some_and(|y| (y - x).abs() < 1e-9 * x.abs().max(1e-9))
}

/// `magsep chart brownian --out DIR [--quick]`.
///
/// # Errors
/// [`BenchError::Runtime`] when a run fails or a file cannot be written.
pub fn chart_brownian(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out).map_err(|e| io_err(out, e))?;
    let p = plan(quick);
    let mut jobs = Vec::new();
    let mut angle_sets: Vec<(f64, Vec<f64>, Reduction)> = Vec::new();
    if let Some(s) = &p.small {
        angle_sets.push(s.clone());
    }
    for &r in &p.radii {
        angle_sets.push((r, p.angles.clone(), p.dilute.clone()));
    }
    for (r, angles, red) in &angle_sets {
        for &a in angles {
            let v = Variant {
                alpha_deg: Some(a),
                radius: Some(*r),
                half_length: None,
            };
            jobs.push(Job {
                params: json!({"sweep": "angle", "alpha_deg": a, "radius_m": r, "aspect_ratio": 20.0, "reduction": red.to_json()}),
                text: derive_scene(ANGLE_SCENE, &v, red)?,
            });
        }
    }
    for &(ld, h) in &[(5.0 / 3.0, 0.5e-3), (20.0 / 3.0, 2e-3)] {
        for &a in &p.aspect_angles {
            let v = Variant {
                alpha_deg: Some(a),
                radius: None,
                half_length: Some(h),
            };
            jobs.push(Job {
                params: json!({"sweep": "aspect", "alpha_deg": a, "radius_m": 125e-9, "aspect_ratio": ld}),
                text: derive_scene(ASPECT_SCENE, &v, &p.aspect)?,
            });
        }
    }
    for a in [0.0, 90.0] {
        let v = Variant {
            alpha_deg: Some(a),
            ..Variant::default()
        };
        jobs.push(Job {
            params: json!({"sweep": "concentrated", "alpha_deg": a, "radius_m": 75e-9, "aspect_ratio": 20.0}),
            text: derive_scene(CONCENTRATED_SCENE, &v, &p.concentrated)?,
        });
    }
    let started = std::time::Instant::now();
    let results: Vec<(Value, Value)> = jobs
        .par_iter()
        .map(|j| {
            let t = std::time::Instant::now();
            let s = run_scene_text(&j.text, None)?;
            eprintln!(
                "chart brownian: {} done in {:.1} s",
                j.params,
                t.elapsed().as_secs_f64()
            );
            Ok((j.params.clone(), s))
        })
        .collect::<Result<_, BenchError>>()?;
    let sweeps = [
        ("angle", &p.dilute, "scenes/brownian_angle.toml"),
        ("aspect", &p.aspect, "scenes/brownian_aspect.toml"),
        (
            "concentrated",
            &p.concentrated,
            "scenes/brownian_concentrated.toml",
        ),
    ];
    for (name, red, scene) in sweeps {
        let rows: Vec<Value> = results
            .iter()
            .filter(|(p, _)| p["sweep"] == name)
            .map(|(p, s)| json!({"params": p, "summary": s}))
            .collect();
        let path = out.join(format!("brownian_{name}.json"));
        let doc =
            json!({"scene": scene, "reduction": red.to_json(), "quick": quick, "results": rows});
        let text = serde_json::to_string_pretty(&doc).map_err(|e| io_err(&path, e))?;
        std::fs::write(&path, text).map_err(|e| io_err(&path, e))?;
    }

    let mut report = json!({
        "chart": "brownian",
        "quick": quick,
        "wall_time_s": started.elapsed().as_secs_f64(),
        "reductions": {
            "thesis": {"time_step_s": 5e-5, "duration_s": 50.0, "runs": 30, "particles_per_group": 100, "mobility": "RPY (TEA-HI)"},
            "angle": p.dilute.to_json(),
            "angle_small_radius": p.small.as_ref().map(|(r, a, red)| json!({"radius_m": r, "angles_deg": a, "reduction": red.to_json()})),
            "aspect": p.aspect.to_json(),
            "concentrated": p.concentrated.to_json(),
            "concentrated_thesis": {"time_step_s": 1e-6, "duration_s": 1.0, "runs": 10, "particles": 500},
        },
    });

    // (a) capture curves against time
    let mut fig_a = Figure::new(
        format!(
            "Captured fraction vs time, L/D = 20 (thesis fig. 6.4); reduced: {}",
            p.dilute.describe()
        ),
        2,
    );
    for &r in &p.radii {
        {
            for (g, region) in [(0usize, "TOP"), (1, "SIDE")] {
                let mut c = Chart::new(format!("{region}, R = {}", nm(r)))
                    .x_label("time [s]")
                    .y_label("captured fraction")
                    .y_range(0.0, 1.0)
                    .legend(LegendPosition::Outside);
                for &a in &p.angles {
                    if let Some(s) = find(&results, "angle", |q| {
                        close(&q["alpha_deg"], a) && close(&q["radius_m"], r)
                    }) {
                        let pts: Vec<(f64, f64)> =
                            curve_of(s, Some(g)).iter().map(|q| (q.0, q.1)).collect();
                        c = c.series(Series::new(format!("α = {a:.0}°"), pts).style(Style::Line));
                    }
                }
                fig_a = fig_a.panel(c);
            }
        }
    }
    let path = out.join("brownian_angle_curves.svg");
    write_svg(&path, &fig_a.to_svg(520.0, 360.0)).map_err(|e| io_err(&path, e))?;

    // (b) final fraction against α
    let mut finals = Vec::new();
    let mut panels: Vec<Chart> = ["TOP", "SIDE", "volume-weighted (TOP+SIDE)"]
        .iter()
        .map(|t| {
            Chart::new(format!("final captured fraction, {t}"))
                .x_label("α [deg]")
                .y_label("captured fraction (95 % CI)")
                .y_range(0.0, 1.05)
        })
        .collect();
    let mut brown = Chart::new("Brownian fraction (eq. 6.24), volume-weighted")
        .x_label("α [deg]")
        .y_label("Brownian fraction")
        .y_range(0.0, 1.05);
    for (r, angles, _) in &angle_sets {
        let (r, angles) = (*r, angles.clone());
        let mut per_group = [Vec::new(), Vec::new(), Vec::new()];
        let mut brown_pts = Vec::new();
        for a in angles {
            let Some(s) = find(&results, "angle", |q| {
                close(&q["alpha_deg"], a) && close(&q["radius_m"], r)
            }) else {
                continue;
            };
            let top = final_fraction(s, Some(0), "captured_fraction");
            let side = final_fraction(s, Some(1), "captured_fraction");
            let all = final_fraction(s, None, "captured_fraction");
            let b = final_fraction(s, None, "brownian_fraction");
            per_group[0].push((a, top));
            per_group[1].push((a, side));
            per_group[2].push((a, all));
            brown_pts.push((a, b));
            finals.push(json!({
                "radius_nm": r * 1e9, "alpha_deg": a,
                "top": top.0, "side": side.0, "volume_weighted": all.0,
                "volume_weighted_ci95": [all.1, all.2],
                "brownian_volume_weighted": b.0,
                "brownian_top": final_fraction(s, Some(0), "brownian_fraction").0,
                "brownian_side": final_fraction(s, Some(1), "brownian_fraction").0,
            }));
        }
        // the mean over the angles run (null, not 0, when none was)
        let mean = |v: &[(f64, (f64, f64, f64))]| {
            crate::studies::stats::mean(&v.iter().map(|x| x.1.0).collect::<Vec<_>>())
        };
        report[format!("angle_average_R{:.0}nm", r * 1e9)] = json!({
            "captured_volume_weighted": mean(&per_group[2]),
            "brownian_volume_weighted": mean(&brown_pts),
        });
        for (k, pts) in per_group.iter().enumerate() {
            panels[k] = panels[k]
                .clone()
                .series(fraction_series(format!("R = {}", nm(r)), pts));
        }
        brown = brown.series(fraction_series(format!("R = {}", nm(r)), &brown_pts));
    }
    report["final_vs_angle"] = Value::Array(finals);
    let small = p
        .small
        .as_ref()
        .map(|(r, _, red)| format!("; R = {}: {}", nm(*r), red.describe()))
        .unwrap_or_default();
    let mut fig_b = Figure::new(
        format!(
            "Final capture vs α, L/D = 20, t = {} s (thesis figs. 6.6a, 6.8; thesis: 50 s); reduced: {}{small}",
            p.dilute.duration.unwrap_or(f64::NAN),
            p.dilute.describe()
        ),
        2,
    );
    for c in panels {
        fig_b = fig_b.panel(
            c.line(Line::new("0.8 (thesis, α = 90°)", vec![(0.0, 0.8), (90.0, 0.8)]).dashed(true)),
        );
    }
    fig_b = fig_b.panel(brown.line(Line::new("0.1", vec![(0.0, 0.1), (90.0, 0.1)]).dashed(true)));
    let path = out.join("brownian_final_vs_angle.svg");
    write_svg(&path, &fig_b.to_svg(520.0, 360.0)).map_err(|e| io_err(&path, e))?;

    // (c) aspect ratio
    let mut aspect_rows = Vec::new();
    let mut aspect_panels: Vec<Chart> = ["TOP", "SIDE", "volume-weighted"]
        .iter()
        .map(|t| {
            Chart::new(format!("R = 125 nm, {t}"))
                .x_label("α [deg]")
                .y_label("final captured fraction (95 % CI)")
                .y_range(0.0, 1.05)
        })
        .collect();
    for (ld, label) in [(5.0 / 3.0, "L/D = 5/3"), (20.0 / 3.0, "L/D = 20/3")] {
        let mut per_group = [Vec::new(), Vec::new(), Vec::new()];
        for &a in &p.aspect_angles {
            let Some(s) = find(&results, "aspect", |q| {
                close(&q["alpha_deg"], a) && close(&q["aspect_ratio"], ld)
            }) else {
                continue;
            };
            let e = [
                final_fraction(s, Some(0), "captured_fraction"),
                final_fraction(s, Some(1), "captured_fraction"),
                final_fraction(s, None, "captured_fraction"),
            ];
            for (pts, e) in per_group.iter_mut().zip(e) {
                pts.push((a, e));
            }
            aspect_rows.push(json!({"aspect_ratio": ld, "alpha_deg": a, "top": e[0].0, "side": e[1].0, "volume_weighted": e[2].0}));
        }
        for (k, pts) in per_group.iter().enumerate() {
            aspect_panels[k] = aspect_panels[k]
                .clone()
                .series(fraction_series(label.into(), pts));
        }
    }
    report["aspect"] = Value::Array(aspect_rows);
    let mut fig_c = Figure::new(
        format!(
            "Aspect ratio, R = 125 nm (thesis figs. 6.6b, 6.7); reduced: {}",
            p.aspect.describe()
        ),
        3,
    );
    for c in aspect_panels {
        fig_c = fig_c.panel(c);
    }
    let path = out.join("brownian_aspect.svg");
    write_svg(&path, &fig_c.to_svg(420.0, 340.0)).map_err(|e| io_err(&path, e))?;

    // (d) concentrated
    let mut conc = Chart::new("N-particle cloud 100 µm above the rim, R = 75 nm, L/D = 20")
        .x_label("time [s]")
        .y_label("captured fraction")
        .y_range(0.0, 1.05);
    let mut conc_rows = Vec::new();
    for (a, label) in [(0.0, "longitudinal α = 0"), (90.0, "transverse α = 90°")] {
        let Some(s) = find(&results, "concentrated", |q| close(&q["alpha_deg"], a)) else {
            continue;
        };
        let c = curve_of(s, None);
        conc = conc.series(Series::new(label, c.iter().map(|q| (q.0, q.1))).style(Style::Line));
        conc = conc.line(Line::new("", c.iter().map(|q| (q.0, q.2))).dashed(true));
        conc = conc.line(Line::new("", c.iter().map(|q| (q.0, q.3))).dashed(true));
        conc_rows.push(json!({
            "alpha_deg": a,
            "particles": s["particles"],
            "mobility": s["mobility"]["method"],
            "lag_s_first_5pct": time_to(&c, 0.05),
            "t50_s": time_to(&c, 0.5),
            "t90_s": time_to(&c, 0.9),
            "t100_s": time_to(&c, 1.0),
            "final": c.last().map(|q| q.1),
        }));
    }
    if let [l, t] = conc_rows.as_slice() {
        let ratio = |k: &str| match (t[k].as_f64(), l[k].as_f64()) {
            (Some(a), Some(b)) if b > 0.0 => Some(a / b),
            _ => None,
        };
        report["concentrated_transverse_over_longitudinal"] =
            json!({"t50": ratio("t50_s"), "t90": ratio("t90_s")});
    }
    report["concentrated"] = Value::Array(conc_rows);
    let fig_d = Figure::new(
        format!(
            "Concentrated cloud (thesis figs. 6.12-6.13: N = 500, dt = 1e-6 s, 10 runs); reduced: {} (dashed: 95 % CI)",
            p.concentrated.describe()
        ),
        1,
    )
    .panel(conc);
    let path = out.join("brownian_concentrated.svg");
    write_svg(&path, &fig_d.to_svg(720.0, 440.0)).map_err(|e| io_err(&path, e))?;

    report["wall_time_s"] = json!(started.elapsed().as_secs_f64());
    crate::studies::bench::say(serde_json::to_string_pretty(&report).unwrap_or_default())
}
