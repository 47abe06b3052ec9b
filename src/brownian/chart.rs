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

use crate::bench::BenchError;
use crate::chart::{Chart, Figure, LegendPosition, Line, Series, Style, write_svg};
use crate::scene::parse_scene;
use crate::sim::RunOptions;

/// `scenes/brownian_angle.toml` (L/D = 20, R = 75 nm, α = 45°, TOP and SIDE).
pub const ANGLE_SCENE: &str = include_str!("../../scenes/brownian_angle.toml");
/// `scenes/brownian_aspect.toml` (L/D = 5/3, R = 125 nm, α = 45°, TOP and SIDE).
pub const ASPECT_SCENE: &str = include_str!("../../scenes/brownian_aspect.toml");
/// `scenes/brownian_concentrated.toml` (N = 500, R = 75 nm, α = 0, box above the rim).
pub const CONCENTRATED_SCENE: &str = include_str!("../../scenes/brownian_concentrated.toml");

/// Thesis table 6.1: hydrodynamic radius R_h [m] and particle moment μ_s [A m²].
pub const TABLE_6_1: [(f64, f64); 6] = [
    (25e-9, 0.016e-16),
    (50e-9, 0.344e-16),
    (75e-9, 0.870e-16),
    (100e-9, 0.662e-16),
    (125e-9, 5.151e-16),
    (212e-9, 19.35e-16),
];

/// The table 6.1 moment [A m²] of radius `radius` [m] (`None` if it is not in the table).
pub fn table_moment(radius: f64) -> Option<f64> {
    TABLE_6_1
        .iter()
        .find(|(r, _)| (r - radius).abs() < 1e-12)
        .map(|(_, m)| *m)
}

/// What a sweep changes relative to its scene file (everything `None` keeps the file's value).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Variant {
    /// Angle between the fibre axis (z) and the 1 T field [degrees]; the field becomes
    /// `[sin α, 0, cos α]`.
    pub alpha_deg: Option<f64>,
    /// Particle radius [m] (every group), with its table 6.1 moment.
    pub radius: Option<f64>,
    /// Fibre half length [m] (fibre 0).
    pub half_length: Option<f64>,
}

/// Reduced run parameters (everything `None` keeps the file's value).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Reduction {
    /// Outer time step [s].
    pub time_step: Option<f64>,
    /// Simulated time [s].
    pub duration: Option<f64>,
    /// Replicates.
    pub runs: Option<u64>,
    /// Particles per group.
    pub count: Option<u64>,
    /// Mobility (`"free_draining"`, `"auto"`, ...).
    pub mobility: Option<String>,
    /// Adaptive step control: (tolerance, max_displacement), both in particle radii.
    pub adaptive: Option<(f64, f64)>,
    /// Capture-curve sampling interval in steps.
    pub observe_every: Option<u64>,
}

impl Reduction {
    /// The reduction as JSON (for the printed summary and the sweep files).
    pub fn to_json(&self) -> Value {
        json!({
            "time_step_s": self.time_step,
            "duration_s": self.duration,
            "runs": self.runs,
            "particles_per_group": self.count,
            "mobility": self.mobility,
            "adaptive_tolerance_radii": self.adaptive.map(|a| a.0),
            "adaptive_max_displacement_radii": self.adaptive.map(|a| a.1),
        })
    }

    /// One line for a chart subtitle.
    pub fn describe(&self) -> String {
        let mut s = Vec::new();
        if let Some(n) = self.count {
            s.push(format!("N = {n}/region"));
        }
        if let Some(d) = self.duration {
            s.push(format!("t = {d} s"));
        }
        if let Some(dt) = self.time_step {
            s.push(format!("dt = {dt:e} s"));
        }
        if let Some((tol, disp)) = self.adaptive {
            s.push(format!("adaptive (tol {tol} R, max move {disp} R)"));
        }
        if let Some(r) = self.runs {
            s.push(format!("{r} runs"));
        }
        if let Some(m) = &self.mobility {
            s.push(m.replace('_', "-"));
        }
        s.join(", ")
    }
}

fn table_mut<'a>(v: &'a mut toml::Value, key: &str) -> Result<&'a mut toml::Table, BenchError> {
    v.get_mut(key)
        .and_then(toml::Value::as_table_mut)
        .ok_or_else(|| BenchError::Runtime(format!("scene has no [{key}] table")))
}

/// The scene text `base` with `variant` and `reduction` applied (comments are dropped).
///
/// # Errors
/// [`BenchError::Runtime`] if `base` is not TOML or lacks the tables a sweep rewrites.
pub fn derive_scene(
    base: &str,
    variant: &Variant,
    reduction: &Reduction,
) -> Result<String, BenchError> {
    let mut doc: toml::Value =
        toml::from_str(base).map_err(|e| BenchError::Runtime(format!("scene: {e}")))?;
    if let Some(a) = variant.alpha_deg {
        let (s, c) = a.to_radians().sin_cos();
        let clean = |x: f64| if x.abs() < 1e-12 { 0.0 } else { x };
        let f = table_mut(&mut doc, "external_field")?;
        f.insert(
            "flux_density".into(),
            toml::Value::Array(vec![clean(s).into(), 0.0.into(), clean(c).into()]),
        );
    }
    if let Some(h) = variant.half_length {
        let fibres = doc
            .get_mut("fibres")
            .and_then(toml::Value::as_array_mut)
            .and_then(|a| a.first_mut())
            .and_then(toml::Value::as_table_mut)
            .ok_or_else(|| BenchError::Runtime("scene has no [[fibres]]".into()))?;
        fibres.insert("half_length".into(), h.into());
    }
    let groups = doc
        .get_mut("particles")
        .and_then(toml::Value::as_array_mut)
        .ok_or_else(|| BenchError::Runtime("scene has no [[particles]]".into()))?;
    for g in groups.iter_mut() {
        let g = g
            .as_table_mut()
            .ok_or_else(|| BenchError::Runtime("[[particles]] entry is not a table".into()))?;
        if let Some(r) = variant.radius {
            let m = table_moment(r).ok_or_else(|| {
                BenchError::Runtime(format!("radius {r} m is not in table 6.1"))
            })?;
            let mut shape = toml::Table::new();
            shape.insert("kind".into(), "sphere".into());
            shape.insert("radius".into(), r.into());
            g.insert("shape".into(), toml::Value::Table(shape));
            let mut moment = toml::Table::new();
            moment.insert("kind".into(), "saturated".into());
            moment.insert("moment".into(), m.into());
            g.insert("moment".into(), toml::Value::Table(moment));
        }
        if let Some(n) = reduction.count {
            g.insert("count".into(), (n as i64).into());
        }
    }
    let b = table_mut(&mut doc, "brownian")?;
    if let Some(dt) = reduction.time_step {
        b.insert("time_step".into(), dt.into());
    }
    if let Some(d) = reduction.duration {
        b.insert("duration".into(), d.into());
    }
    if let Some(r) = reduction.runs {
        b.insert("runs".into(), (r as i64).into());
    }
    if let Some(m) = &reduction.mobility {
        b.insert("mobility".into(), m.as_str().into());
    }
    if let Some(e) = reduction.observe_every {
        b.insert("observe_every".into(), (e as i64).into());
    }
    if let Some((tol, disp)) = reduction.adaptive {
        let mut sc = toml::Table::new();
        sc.insert("kind".into(), "adaptive".into());
        sc.insert("tolerance".into(), tol.into());
        sc.insert("max_displacement".into(), disp.into());
        sc.insert("max_depth".into(), 24.into());
        b.insert("step_control".into(), toml::Value::Table(sc));
    }
    toml::to_string(&doc).map_err(|e| BenchError::Runtime(format!("scene: {e}")))
}

/// Parse and run a scene text for its `[brownian] runs` replicates; the ensemble summary.
///
/// # Errors
/// [`BenchError::Runtime`] on an invalid scene or a failed run.
pub fn run_scene_text(text: &str, seed: Option<u64>) -> Result<Value, BenchError> {
    let scene =
        parse_scene(text, &Default::default()).map_err(|e| BenchError::Runtime(e.to_string()))?;
    let runs = scene.brownian.as_ref().map(|b| b.runs()).unwrap_or(1);
    let options = RunOptions {
        seed,
        ..RunOptions::default()
    };
    crate::brownian::run_ensemble(&scene, runs, &options, &|_| {})
        .map_err(|e| BenchError::Runtime(e.to_string()))
}

/// A capture curve of a summary (`group` or all particles): (t, fraction, lo, hi).
pub fn curve_of(summary: &Value, group: Option<usize>) -> Vec<(f64, f64, f64, f64)> {
    let c = match group {
        Some(g) => &summary["groups"][g]["capture_curve"],
        None => &summary["capture_curve"],
    };
    let col = |k: &str| -> Vec<f64> {
        c[k].as_array()
            .map(|a| a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect())
            .unwrap_or_default()
    };
    let (t, f, lo, hi) = (
        col("time_s"),
        col("captured_fraction"),
        col("lo"),
        col("hi"),
    );
    (0..t.len().min(f.len()))
        .map(|i| {
            (
                t[i],
                f[i],
                lo.get(i).copied().unwrap_or(f[i]),
                hi.get(i).copied().unwrap_or(f[i]),
            )
        })
        .collect()
}

/// First time [s] at which a capture curve reaches `level` (`None` if never).
pub fn time_to(curve: &[(f64, f64, f64, f64)], level: f64) -> Option<f64> {
    curve.iter().find(|p| p.1 >= level - 1e-12).map(|p| p.0)
}

/// (mean, lo, hi) of a group's final captured fraction, or of the volume-weighted overall
/// fraction when `group` is `None` (its interval is the volume-weighted mean of the group
/// intervals, i.e. conservative: as if the groups' errors were fully correlated).
pub fn final_fraction(summary: &Value, group: Option<usize>, key: &str) -> (f64, f64, f64) {
    let get = |e: &Value| {
        (
            e["mean"].as_f64().unwrap_or(f64::NAN),
            e["lo"].as_f64().unwrap_or(f64::NAN),
            e["hi"].as_f64().unwrap_or(f64::NAN),
        )
    };
    if let Some(g) = group {
        return get(&summary["groups"][g][key]);
    }
    let groups = summary["groups"].as_array().cloned().unwrap_or_default();
    let mut acc = (0.0, 0.0, 0.0, 0.0);
    for g in &groups {
        let w = g["region_volume_m3"].as_f64().unwrap_or(0.0);
        let (m, lo, hi) = get(&g[key]);
        acc = (acc.0 + w, acc.1 + w * m, acc.2 + w * lo, acc.3 + w * hi);
    }
    if acc.0 > 0.0 {
        (acc.1 / acc.0, acc.2 / acc.0, acc.3 / acc.0)
    } else {
        get(&summary[key])
    }
}

/// The sweep settings of one mode.
#[derive(Debug, Clone)]
struct Plan {
    angles: Vec<f64>,
    radii: Vec<f64>,
    dilute: Reduction,
    aspect_angles: Vec<f64>,
    aspect: Reduction,
    concentrated: Reduction,
}

fn plan(quick: bool) -> Plan {
    let adaptive = Some((1e-2, 5.0));
    if quick {
        return Plan {
            angles: vec![0.0, 45.0, 90.0],
            radii: vec![75e-9, 212e-9],
            dilute: Reduction {
                time_step: Some(1e-3),
                duration: Some(1.0),
                runs: Some(2),
                count: Some(20),
                mobility: Some("free_draining".into()),
                adaptive,
                observe_every: Some(10),
            },
            aspect_angles: vec![0.0, 90.0],
            aspect: Reduction {
                time_step: Some(1e-3),
                duration: Some(1.0),
                runs: Some(2),
                count: Some(20),
                mobility: Some("free_draining".into()),
                adaptive,
                observe_every: Some(10),
            },
            concentrated: Reduction {
                time_step: Some(1e-4),
                duration: Some(0.3),
                runs: Some(1),
                count: Some(50),
                mobility: Some("free_draining".into()),
                adaptive,
                observe_every: Some(30),
            },
        };
    }
    Plan {
        angles: (0..=6).map(|k| 15.0 * k as f64).collect(),
        radii: vec![25e-9, 75e-9, 212e-9],
        dilute: Reduction {
            time_step: Some(1e-3),
            duration: Some(10.0),
            runs: Some(4),
            count: Some(50),
            mobility: Some("free_draining".into()),
            adaptive,
            observe_every: Some(100),
        },
        aspect_angles: vec![0.0, 30.0, 60.0, 90.0],
        aspect: Reduction {
            time_step: Some(1e-3),
            duration: Some(10.0),
            runs: Some(4),
            count: Some(50),
            mobility: Some("free_draining".into()),
            adaptive,
            observe_every: Some(100),
        },
        concentrated: Reduction {
            time_step: Some(1e-4),
            duration: Some(1.0),
            runs: Some(2),
            count: None,
            mobility: None,
            adaptive,
            observe_every: Some(50),
        },
    }
}

/// One job of a sweep: its name, parameters and derived scene text.
struct Job {
    sweep: &'static str,
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

fn find<'a>(results: &'a [(Value, Value)], sweep: &str, pred: impl Fn(&Value) -> bool) -> Option<&'a Value> {
    results
        .iter()
        .find(|(p, _)| p["sweep"] == sweep && pred(p))
        .map(|(_, s)| s)
}

fn close(v: &Value, x: f64) -> bool {
    v.as_f64().is_some_and(|y| (y - x).abs() < 1e-9 * x.abs().max(1e-9))
}

/// `magsep chart brownian --out DIR [--quick]`.
///
/// # Errors
/// [`BenchError::Runtime`] when a run fails or a file cannot be written.
pub fn chart_brownian(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out).map_err(|e| io_err(out, e))?;
    let p = plan(quick);
    let mut jobs = Vec::new();
    for &r in &p.radii {
        for &a in &p.angles {
            let v = Variant {
                alpha_deg: Some(a),
                radius: Some(r),
                half_length: None,
            };
            jobs.push(Job {
                sweep: "angle",
                params: json!({"sweep": "angle", "alpha_deg": a, "radius_m": r, "aspect_ratio": 20.0}),
                text: derive_scene(ANGLE_SCENE, &v, &p.dilute)?,
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
                sweep: "aspect",
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
            sweep: "concentrated",
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
        ("concentrated", &p.concentrated, "scenes/brownian_concentrated.toml"),
    ];
    for (name, red, scene) in sweeps {
        let rows: Vec<Value> = results
            .iter()
            .filter(|(p, _)| p["sweep"] == name)
            .map(|(p, s)| json!({"params": p, "summary": s}))
            .collect();
        let path = out.join(format!("brownian_{name}.json"));
        let doc = json!({"scene": scene, "reduction": red.to_json(), "quick": quick, "results": rows});
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
        if quick || r > 30e-9 {
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
    for &r in &p.radii {
        let mut per_group = vec![Vec::new(), Vec::new(), Vec::new()];
        let mut brown_pts = Vec::new();
        for &a in &p.angles {
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
        let mean = |v: &[(f64, (f64, f64, f64))]| {
            v.iter().map(|x| x.1.0).sum::<f64>() / v.len().max(1) as f64
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
    let mut fig_b = Figure::new(
        format!(
            "Final capture vs α, L/D = 20, t = {} s (thesis figs. 6.6a, 6.8; thesis: 50 s); reduced: {}",
            p.dilute.duration.unwrap_or(f64::NAN),
            p.dilute.describe()
        ),
        2,
    );
    for c in panels {
        fig_b = fig_b.panel(c.line(Line::new("0.8 (thesis, α = 90°)", vec![(0.0, 0.8), (90.0, 0.8)]).dashed(true)));
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
        let mut per_group = vec![Vec::new(), Vec::new(), Vec::new()];
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
            for k in 0..3 {
                per_group[k].push((a, e[k]));
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
    println!(
        "{}",
        serde_json::to_string_pretty(&report).unwrap_or_default()
    );
    Ok(())
}
