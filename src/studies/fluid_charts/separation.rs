//! `magsep chart separation --out DIR [--quick]`: the many-particle density separation runs of
//! thesis 002, §2.5.3 (figs. 2.16, 2.18), from the shipped scenes `scenes/mds_case*.toml`
//! (compiled in), all one-way coupled (the two-way coupled runs are `magsep chart coupling`; here the thesis's case
//! 1A runs as its case 1C).
//!
//! Full mode runs the scenes as shipped (table 2.4 particle counts, 5 s); `--quick` shrinks the
//! channel's periods by 3 (the particle count by 9 at the same volume fraction; case 2 by 6)
//! and the duration to 2.5 s. The thesis's numbers are statistical (target V-DS-7: compare ensembles
//! of seeds), so full mode runs seeds 1-3 of every case but case 2 (seed 1: 70 685 particles);
//! the charts show the seed-averaged e_m(t) and the summary lists every seed's time to 0.02 with
//! their mean and standard deviation. Charts:
//! * `separation_cases.svg`: e_m(t) of cases 1A(=1C), 1B (no history), 1D (no collisions) and
//!   4 (impurity 0.5) (fig. 2.16a), and 1A, 2 (2 mm), 3 (Φ = 0.04), 4 (fig. 2.18);
//! * `separation_groups.svg`: e_m(t) per density group of case 1A (fig. 2.16b).

use std::path::Path;

use rayon::prelude::*;
use serde_json::{Value, json};

use super::runtime;
use crate::chart::{Chart, Figure, LegendPosition, Line, Series, Style, write_svg};
use crate::studies::bench::BenchError;
use magsep_systems::fluid::observe::SeparationCurve;

/// The shipped cases: (name, scene, thesis time to e_m = 0.02 [s] where stated).
const CASES: [(&str, &str, Option<f64>); 6] = [
    (
        "1A (=1C)",
        include_str!("../../../scenes/mds_case1a.toml"),
        Some(3.0),
    ),
    (
        "1B",
        include_str!("../../../scenes/mds_case1b.toml"),
        Some(1.5),
    ),
    (
        "1D",
        include_str!("../../../scenes/mds_case1d.toml"),
        Some(2.5),
    ),
    ("2", include_str!("../../../scenes/mds_case2.toml"), None),
    ("3", include_str!("../../../scenes/mds_case3.toml"), None),
    (
        "4",
        include_str!("../../../scenes/mds_case4.toml"),
        Some(4.0),
    ),
];

/// The period of the shipped channel [m] (4π L / 3).
const SIDE: &str = "0.3141592653589793";

/// The scene text of a case, reduced in quick mode.
fn reduced(text: &str, quick: bool, small: bool) -> String {
    if !quick {
        return text.to_string();
    }
    let factor = if small { 6.0 } else { 3.0 };
    let side = std::f64::consts::PI * 0.1 / factor;
    text.replace(&format!("[{SIDE}, {SIDE}]"), &format!("[{side}, {side}]"))
        .replace("duration = 5.0 ", "duration = 2.5 ")
}

/// Run a scene to its end: its separation curve and summary.
pub(crate) fn run_case(text: &str) -> Result<(SeparationCurve, Value), BenchError> {
    let mut sim = super::simulation(text)?;
    let summary = sim.run(|_| {}).map_err(runtime)?;
    let curve = sim
        .app
        .world
        .get_resource::<SeparationCurve>()
        .cloned()
        .unwrap_or_default();
    Ok((curve, summary))
}

/// Seeds per case in full mode (case 2: one).
const SEEDS: u64 = 3;

/// The mean of the runs' curves (they share the sample times: same step and sampling).
fn mean_curve(runs: &[&(SeparationCurve, Value)]) -> SeparationCurve {
    let mut mean = runs[0].0.clone();
    let n = runs.len() as f64;
    let len = runs.iter().map(|r| r.0.total.len()).min().unwrap_or(0);
    mean.times.truncate(len);
    mean.total = (0..len)
        .map(|i| runs.iter().map(|r| r.0.total[i]).sum::<f64>() / n)
        .collect();
    for (g, e) in mean.groups.iter_mut().enumerate() {
        *e = (0..len)
            .map(|i| runs.iter().map(|r| r.0.groups[g][i]).sum::<f64>() / n)
            .collect();
    }
    mean
}

/// The JSON fields of the seeds' times to e_m = 0.02 [s]: their mean and sample standard
/// deviation (`null` for one seed: a spread of one value is undefined, not 0) and every seed's.
fn time_fields(times: &[f64]) -> Value {
    let (mean, sd) = crate::studies::stats::mean_sd(times);
    json!({"time_to_0.02": mean, "time_to_0.02_sd": sd, "time_to_0.02_per_seed": times})
}

fn points(c: &SeparationCurve, values: &[f64]) -> Vec<(f64, f64)> {
    c.times
        .iter()
        .copied()
        .zip(values.iter().copied())
        .collect()
}

/// Write the charts and print a JSON summary.
///
/// # Errors
/// [`BenchError::Runtime`] if a run or writing fails.
pub fn chart_separation(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    let jobs: Vec<(usize, u64)> = CASES
        .iter()
        .enumerate()
        .flat_map(|(k, (name, _, _))| {
            let seeds = if quick || *name == "2" { 1 } else { SEEDS };
            (1..=seeds).map(move |seed| (k, seed))
        })
        .collect();
    let runs: Vec<(SeparationCurve, Value)> = jobs
        .par_iter()
        .map(|&(k, seed)| {
            let (name, text, _) = CASES[k];
            let text = reduced(text, quick, name == "2");
            // the shipped scenes set `seed = 1`; without it every seed would run the same case
            if !text.contains("seed = 1\n") {
                return Err(BenchError::Runtime(format!(
                    "case {name}: the scene sets no `seed = 1` to vary"
                )));
            }
            run_case(&text.replacen("seed = 1\n", &format!("seed = {seed}\n"), 1))
        })
        .collect::<Result<_, _>>()?;
    // per case: the seed-averaged curve and every seed's run
    let results: Vec<(SeparationCurve, Vec<&(SeparationCurve, Value)>)> = (0..CASES.len())
        .map(|k| {
            let mine: Vec<&(SeparationCurve, Value)> = jobs
                .iter()
                .zip(&runs)
                .filter(|(j, _)| j.0 == k)
                .map(|(_, r)| r)
                .collect();
            (mean_curve(&mine), mine)
        })
        .collect();
    let note = if quick {
        " (quick: periods / 3, case 2 / 6, 2.5 s)"
    } else {
        " (table 2.4 counts; mean of 3 seeds, case 2: 1)"
    };
    let level = Line::new(
        "e_m = 0.02",
        vec![(0.0, 0.02), (if quick { 2.5 } else { 5.0 }, 0.02)],
    )
    .dashed(true);
    let panel = |title: &str, which: &[&str]| {
        let mut c = Chart::new(title)
            .x_label("t [s]")
            .y_label("e_m")
            .y_log(true)
            .legend(LegendPosition::TopRight)
            .line(level.clone());
        for (k, (name, _, _)) in CASES.iter().enumerate() {
            if which.contains(name) {
                let curve = &results[k].0;
                c = c.series(
                    Series::new(format!("case {name}"), points(curve, &curve.total))
                        .style(Style::Line),
                );
            }
        }
        c
    };
    let fig = Figure::new(format!("Separation error, one-way coupled{note}"), 2)
        .panel(panel(
            "history and collisions (fig. 2.16a)",
            &["1A (=1C)", "1B", "1D", "4"],
        ))
        .panel(panel(
            "size, volume fraction, impurity (fig. 2.18)",
            &["1A (=1C)", "2", "3", "4"],
        ));
    let path = out.join("separation_cases.svg");
    write_svg(&path, &fig.to_svg(560.0, 400.0)).map_err(runtime)?;
    let base = &results[0].0;
    let mut groups = Chart::new(format!(
        "Case 1A (=1C): e_m per density group (fig. 2.16b){note}"
    ))
    .x_label("t [s]")
    .y_label("e_m of the group")
    .y_log(true)
    .legend(LegendPosition::TopRight);
    let rho_f = 1400.0;
    for (rho, e) in base.group_densities.iter().zip(&base.groups) {
        if *rho < rho_f {
            continue; // the light groups mirror the heavy ones
        }
        groups = groups.series(
            Series::new(
                format!("|1 - rho_p/rho_f| = {:.3}", (rho / rho_f - 1.0).abs()),
                points(base, e),
            )
            .style(Style::Line),
        );
    }
    let path_g = out.join("separation_groups.svg");
    write_svg(&path_g, &groups.to_svg(640.0, 420.0)).map_err(runtime)?;
    let cases: Vec<Value> = CASES
        .iter()
        .zip(&results)
        .map(|((name, _, thesis), (curve, seeds))| {
            let times: Vec<f64> = seeds.iter().map(|r| r.0.time_to(0.02)).collect();
            let mut row = json!({
                "case": name, "particles": seeds[0].1["particles"], "seeds": seeds.len(),
                "thesis_time_to_0.02": thesis, "final_error": curve.total.last(),
                "collisions": seeds.iter().map(|r| r.1["collisions"].clone()).collect::<Vec<_>>(),
                "wall_time_s": seeds.iter().map(|r| r.1["wall_time_s"].clone()).collect::<Vec<_>>(),
            });
            if let (Some(row), Value::Object(t)) = (row.as_object_mut(), time_fields(&times)) {
                row.extend(t);
            }
            row
        })
        .collect();
    crate::studies::bench::say(
        json!({"charts": [path.display().to_string(), path_g.display().to_string()], "quick": quick, "cases": cases}),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_seed_has_no_standard_deviation() {
        let one = time_fields(&[1.25]);
        assert_eq!(one["time_to_0.02"], json!(1.25));
        assert!(one["time_to_0.02_sd"].is_null(), "{one}");
        let two = time_fields(&[1.0, 3.0]);
        assert!((two["time_to_0.02_sd"].as_f64().unwrap() - 2f64.sqrt()).abs() < 1e-15);
        // a seed that never reached 0.02 (NaN) leaves the mean undefined: null
        assert!(time_fields(&[1.0, f64::NAN])["time_to_0.02"].is_null());
    }
}
