//! `magsep chart flake-collisions --out DIR [--quick]`: binary collisions of 1:2 oblate
//! spheroids in the thesis's rig (thesis 002, §4.3.2, figs. 4.10-4.12), derived from
//! `scenes/flakes_binary_i006.toml` (compiled in): a sinking PVC-U p1 (1436 kg/m³) and a rising
//! POM p4 (1407 kg/m³), both 5 × 2.5 mm and released broadside; the impact factor I (lateral
//! centre distance over d_major) is rewritten along x, and each particle is also run alone.
//! Hard-ellipsoid collisions with e = 0.1 and μ = 0.05, the Basset history reset at each
//! collision, one-way coupled.
//!
//! The delay of a particle is t_l(pair)/t_l(alone) − 1, for the thesis's history rule at a
//! collision (`reset`, eq. 2.29: every contact, a grazing one too, discards the history before
//! it) and for `keep`. Charts:
//! * `flake_collisions_delays.svg`: the delays against I, with the thesis's experimental means
//!   for 1:2 spheroids (−7 % sinking, +33 % rising, over I in [0, 1]);
//! * `flake_collisions_trajectories.svg`: heights and tilts of both particles against time for
//!   I = 0.06 and 0.32 (the thesis's experiments show the rising particle turning past 90° at
//!   I = 0.06; its simulation, with the 5:2 prolate rotational resistance kept here, turns
//!   less than 90°).

use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;
use serde_json::{Value, json};

use super::runtime;
use crate::chart::{Chart, Figure, LegendPosition, Series, Style, write_svg};
use crate::studies::bench::BenchError;
use magsep_components::prelude::*;

const SCENE: &str = include_str!("../../../scenes/flakes_binary_i006.toml");
/// L of the rig [m].
const HALF_HEIGHT: f64 = 0.075;
/// Chart points (x, y).
type Points = Vec<(f64, f64)>;

/// The thesis's mean experimental delays of 1:2 spheroids (sinking, rising).
const THESIS_MEAN: (f64, f64) = (-0.07, 0.33);

struct RunOut {
    times: Vec<f64>,
    heights: Vec<Vec<f64>>,
    tilts: Vec<Vec<f64>>,
    levitation: Vec<Option<f64>>,
    summary: Value,
}

fn run(text: &str) -> Result<RunOut, BenchError> {
    let mut sim = super::simulation(text)?;
    let mut out = RunOut {
        times: Vec::new(),
        heights: Vec::new(),
        tilts: Vec::new(),
        levitation: Vec::new(),
        summary: Value::Null,
    };
    let mut step = 0u64;
    let summary = sim
        .run(|w| {
            step += 1;
            if !step.is_multiple_of(10) {
                return;
            }
            let mut rows: Vec<(ParticleId, f64, f64)> = w
                .iter_entities()
                .filter_map(|e| {
                    let axis = e.get::<Orientation>()?.0 * DVec3::Z;
                    Some((
                        *e.get::<ParticleId>()?,
                        e.get::<Position>()?.0.z,
                        axis.z.clamp(-1.0, 1.0).acos().to_degrees(),
                    ))
                })
                .collect();
            rows.sort_by_key(|r| r.0);
            out.heights.resize(rows.len(), Vec::new());
            out.tilts.resize(rows.len(), Vec::new());
            for (k, r) in rows.iter().enumerate() {
                out.heights[k].push((r.1 - HALF_HEIGHT) / HALF_HEIGHT);
                out.tilts[k].push(r.2);
            }
            out.times.push(w.resource::<StepClock>().time());
        })
        .map_err(runtime)?;
    out.levitation = summary["particle_details"]
        .as_array()
        .map(|a| a.iter().map(|p| p["levitation_time"].as_f64()).collect())
        .unwrap_or_default();
    out.summary = summary;
    Ok(out)
}

/// The scene for impact factor `impact` over `duration`, keeping only group `only` if given.
fn variant(impact: f64, rule: &str, duration: f64, only: Option<usize>) -> String {
    let s = SCENE
        .replace("duration = 12.0 ", &format!("duration = {duration} "))
        .replace(
            "friction = 0.05",
            &format!("friction = 0.05\nhistory = \"{rule}\""),
        )
        .replace(
            "[[0.0753, 0.075, 0.0075]]",
            &format!("[[{}, 0.075, 0.0075]]", 0.075 + impact * 5e-3),
        );
    match only {
        Some(k) => super::collisions::only_group(&s, k),
        None => s,
    }
}

fn delay(pair: Option<f64>, alone: Option<f64>) -> Option<f64> {
    Some(pair? / alone? - 1.0)
}

/// The JSON mean delays of history rule `rule` over the impact factors whose delay is defined
/// (`sinking`, `rising`: (I, delay) points; `runs`: the impact factors run). Each mean is
/// `null` when no delay is defined, never 0, and `pairs_used` says how many pairs it averages
/// out of `pairs_run` (a pair whose particle never levitates has no delay).
fn mean_delay(rule: &str, sinking: &[(f64, f64)], rising: &[(f64, f64)], runs: usize) -> Value {
    let mean =
        |v: &[(f64, f64)]| crate::studies::stats::mean(&v.iter().map(|p| p.1).collect::<Vec<_>>());
    json!({
        "history": rule, "sinking": mean(sinking), "rising": mean(rising),
        "pairs_used": {"sinking": sinking.len(), "rising": rising.len()},
        "pairs_run": runs,
    })
}

/// Write the charts and print a JSON summary.
///
/// # Errors
/// [`BenchError::Runtime`] if a run or writing fails.
pub fn chart_flake_collisions(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let duration = if quick { 20.0 } else { 40.0 };
    let impacts: Vec<f64> = if quick {
        vec![0.06, 0.32]
    } else {
        vec![0.0, 0.06, 0.15, 0.32, 0.45, 0.6, 0.8, 1.0]
    };
    let alone: Vec<RunOut> = [0usize, 1]
        .par_iter()
        .map(|&k| run(&variant(0.06, "reset", duration, Some(k))))
        .collect::<Result<_, _>>()?;
    let rules = ["reset", "keep"];
    let jobs: Vec<(f64, &str)> = rules
        .iter()
        .flat_map(|r| impacts.iter().map(move |&i| (i, *r)))
        .collect();
    let pairs: Vec<RunOut> = jobs
        .par_iter()
        .map(|(i, r)| run(&variant(*i, r, duration, None)))
        .collect::<Result<_, _>>()?;
    let (t_sink, t_rise) = (alone[0].levitation[0], alone[1].levitation[0]);
    let mut rows = Vec::new();
    // per rule: (sinking, rising) delay points
    let mut curves: Vec<(Points, Points)> = vec![Default::default(); 2];
    for ((impact, rule), p) in jobs.iter().zip(&pairs) {
        let (a, b) = (p.levitation[0], p.levitation[1]);
        let (da, db) = (delay(a, t_sink), delay(b, t_rise));
        let curve = &mut curves[usize::from(*rule == "keep")];
        if let Some(d) = da {
            curve.0.push((*impact, d));
        }
        if let Some(d) = db {
            curve.1.push((*impact, d));
        }
        let max_tilt = |k: usize| p.tilts[k].iter().copied().fold(0.0, f64::max);
        rows.push(json!({
            "impact_factor": impact, "history": rule,
            "levitation_time_sinking": a, "levitation_time_rising": b,
            "delay_sinking": da, "delay_rising": db,
            "max_tilt_sinking_deg": max_tilt(0), "max_tilt_rising_deg": max_tilt(1),
            "collisions": p.summary["collisions"],
        }));
    }
    let mut delays = Chart::new("levitation delay of 1:2 spheroids against the impact factor")
        .x_label("I = lateral distance / d_major")
        .y_label("t_l(pair) / t_l(alone) - 1")
        .legend(LegendPosition::TopRight);
    for (rule, (sink, rise)) in rules.iter().zip(&curves) {
        delays = delays
            .series(
                Series::new(format!("sinking PVC-U, history {rule}"), sink.clone())
                    .style(Style::LineMarkers),
            )
            .series(
                Series::new(format!("rising POM, history {rule}"), rise.clone())
                    .style(Style::LineMarkers),
            );
    }
    let delays = delays
        .series(
            Series::new(
                "thesis mean, sinking (experiment)",
                vec![(0.5, THESIS_MEAN.0)],
            )
            .style(Style::Markers),
        )
        .series(
            Series::new(
                "thesis mean, rising (experiment)",
                vec![(0.5, THESIS_MEAN.1)],
            )
            .style(Style::Markers),
        );
    let p1 = out.join("flake_collisions_delays.svg");
    write_svg(&p1, &delays.to_svg(640.0, 420.0)).map_err(runtime)?;
    let mut fig = Figure::new(
        "Binary collisions of 1:2 spheroids (thesis 002, figs. 4.10-4.12)",
        2,
    );
    for ((i, rule), p) in jobs.iter().zip(&pairs) {
        if *rule != "reset" || (!(i - 0.06).abs().lt(&1e-9) && !(i - 0.32).abs().lt(&1e-9)) {
            continue;
        }
        let pts = |v: &[f64]| -> Vec<(f64, f64)> {
            p.times.iter().copied().zip(v.iter().copied()).collect()
        };
        let h = Chart::new(format!("I = {i}: heights"))
            .x_label("t [s]")
            .y_label("y / L")
            .legend(LegendPosition::TopRight)
            .series(Series::new("sinking", pts(&p.heights[0])).style(Style::Line))
            .series(Series::new("rising", pts(&p.heights[1])).style(Style::Line));
        let t = Chart::new(format!("I = {i}: tilt of the symmetry axis"))
            .x_label("t [s]")
            .y_label("tilt [deg]")
            .legend(LegendPosition::TopRight)
            .series(Series::new("sinking", pts(&p.tilts[0])).style(Style::Line))
            .series(Series::new("rising", pts(&p.tilts[1])).style(Style::Line));
        fig = fig.panel(h).panel(t);
    }
    let p2 = out.join("flake_collisions_trajectories.svg");
    write_svg(&p2, &fig.to_svg(520.0, 360.0)).map_err(runtime)?;
    crate::studies::bench::say(json!({
        "charts": [p1.display().to_string(), p2.display().to_string()],
        "quick": quick,
        "alone": {"sinking": t_sink, "rising": t_rise},
        "pairs": rows,
        "mean_delay": rules.iter().zip(&curves)
            .map(|(r, (a, b))| mean_delay(r, a, b, impacts.len()))
            .collect::<Vec<_>>(),
        "thesis_mean_delay": {"sinking": THESIS_MEAN.0, "rising": THESIS_MEAN.1},
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_delay_of_no_pairs_is_null_and_counts_are_given() {
        let none = mean_delay("reset", &[], &[], 2);
        assert!(
            none["sinking"].is_null() && none["rising"].is_null(),
            "{none}"
        );
        assert_eq!(none["pairs_used"], json!({"sinking": 0, "rising": 0}));
        assert_eq!(none["pairs_run"], json!(2));
        let some = mean_delay("keep", &[(0.06, 0.1), (0.32, 0.3)], &[(0.06, -0.2)], 2);
        assert!((some["sinking"].as_f64().unwrap() - 0.2).abs() < 1e-15);
        assert_eq!(some["rising"], json!(-0.2));
        assert_eq!(some["pairs_used"], json!({"sinking": 2, "rising": 1}));
    }
}
