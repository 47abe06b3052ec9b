//! `magsep chart coupling --out DIR [--quick]`: what the two-way coupled liquid changes.
//!
//! * `coupling_settling.svg`: a sphere settling at Re ≈ 4e-5 (see [`super::settling`]):
//!   terminal velocity over the Stokes value against d/Δ, without and with the
//!   self-induced-velocity correction.
//! * `coupling_separation.svg`: e_m(t) of the thesis's sphere cases 1A, 3 and 4 one-way
//!   (`scenes/mds_case*.toml`) against two-way (`scenes/mds_case*_coupled.toml`), and of the
//!   1:10 flakes of chapter 4's case 5 (`scenes/flakes_case5.toml` against
//!   `flakes_case5_coupled.toml`).
//!
//! Full mode runs the scenes as shipped (seed 1; the summary states the seed); `--quick`
//! shrinks the sphere channel's periods by 3 (particle count by 9, grid 12 × 12 × 33), runs
//! 2 s and only the settling grids up to d/Δ = 1.5.

use std::path::Path;

use rayon::prelude::*;
use serde_json::{Value, json};

use super::settling::{SettlingRow, settle};
use crate::chart::{Chart, Figure, LegendPosition, Line, Series, Style, write_svg};
use crate::studies::bench::BenchError;
use crate::studies::fluid_charts::runtime;
use crate::studies::fluid_charts::separation::run_case;
use magsep_systems::fluid::observe::SeparationCurve;

/// (name, one-way scene, two-way scene, thesis time to e_m = 0.02 \[s\] where stated).
const CASES: [(&str, &str, &str, Option<f64>); 4] = [
    (
        "1A",
        include_str!("../../../scenes/mds_case1a.toml"),
        include_str!("../../../scenes/mds_case1a_coupled.toml"),
        Some(3.0),
    ),
    (
        "3",
        include_str!("../../../scenes/mds_case3.toml"),
        include_str!("../../../scenes/mds_case3_coupled.toml"),
        None,
    ),
    (
        "4",
        include_str!("../../../scenes/mds_case4.toml"),
        include_str!("../../../scenes/mds_case4_coupled.toml"),
        Some(4.0),
    ),
    (
        "flakes 5 (w = 0.1)",
        include_str!("../../../scenes/flakes_case5.toml"),
        include_str!("../../../scenes/flakes_case5_coupled.toml"),
        None,
    ),
];

/// The sphere channel's period \[m\] (4π L / 3).
const SIDE: &str = "0.3141592653589793";

fn reduced(text: &str, quick: bool) -> String {
    if !quick {
        return text.to_string();
    }
    let side = std::f64::consts::PI * 0.1 / 3.0;
    text.replace(&format!("[{SIDE}, {SIDE}]"), &format!("[{side}, {side}]"))
        .replace("grid = [32, 32, 33]", "grid = [12, 12, 33]")
        .replace("duration = 5.0 ", "duration = 2.0 ")
        .replace("duration = 6.0 ", "duration = 2.0 ")
}

fn curve_points(c: &SeparationCurve) -> Vec<(f64, f64)> {
    c.times
        .iter()
        .copied()
        .zip(c.total.iter().copied())
        .collect()
}

/// Write the charts and print a JSON summary.
///
/// # Errors
/// [`BenchError::Runtime`] if a run or writing fails.
pub fn chart_coupling(out: &Path, quick: bool) -> Result<(), BenchError> {
    std::fs::create_dir_all(out)
        .map_err(|e| BenchError::Runtime(format!("{}: {e}", out.display())))?;
    // 1. settling
    let grids: &[usize] = if quick {
        &[8, 16, 24]
    } else {
        &[8, 16, 32, 48, 64]
    };
    let jobs: Vec<(usize, bool)> = grids
        .iter()
        .flat_map(|&n| [(n, false), (n, true)])
        .collect();
    let rows: Vec<SettlingRow> = jobs
        .par_iter()
        .map(|&(n, c)| settle(n, 16.0, c, 0.3))
        .collect::<Result<_, _>>()?;
    let series = |corrected: bool| {
        rows.iter()
            .filter(|r| r.corrected == corrected)
            .map(|r| (r.diameter_over_spacing, r.ratio))
            .collect::<Vec<_>>()
    };
    let x_max = rows
        .iter()
        .map(|r| r.diameter_over_spacing)
        .fold(0.0, f64::max);
    let settling = Chart::new(
        "Settling sphere, two-way coupled (Re = 4e-5, box of 16 d; corrected: own disturbance removed)",
    )
    .x_label("d / grid spacing")
    .y_label("v / v_Stokes")
    .legend(LegendPosition::Auto)
    .line(Line::new("Stokes", vec![(0.0, 1.0), (x_max, 1.0)]).dashed(true))
    .series(Series::new("point particle (thesis)", series(false)).style(Style::LineMarkers))
    .series(Series::new("corrected", series(true)).style(Style::LineMarkers));
    let p1 = out.join("coupling_settling.svg");
    write_svg(&p1, &settling.to_svg(640.0, 420.0)).map_err(runtime)?;
    // 2. separation, one-way against two-way (two runs at a time)
    let jobs: Vec<(usize, bool)> = (0..CASES.len())
        .flat_map(|k| [(k, false), (k, true)])
        .collect();
    let runs: Vec<(SeparationCurve, Value)> = jobs
        .par_iter()
        .map(|&(k, coupled)| {
            let (_, one, two, _) = CASES[k];
            run_case(&reduced(if coupled { two } else { one }, quick))
        })
        .collect::<Result<_, _>>()?;
    let mut fig = Figure::new(
        format!(
            "Separation error, one-way against two-way coupled (seed 1){}",
            if quick {
                " (quick: periods / 3, 2 s)"
            } else {
                ""
            }
        ),
        2,
    );
    let mut cases = Vec::new();
    for (k, (name, _, _, thesis)) in CASES.iter().enumerate() {
        let (one, two) = (&runs[2 * k], &runs[2 * k + 1]);
        let end = one.0.times.last().copied().unwrap_or(1.0);
        let chart = Chart::new(format!("case {name}"))
            .x_label("t [s]")
            .y_label("e_m")
            .y_log(true)
            .legend(LegendPosition::TopRight)
            .line(Line::new("e_m = 0.02", vec![(0.0, 0.02), (end, 0.02)]).dashed(true))
            .series(Series::new("one-way", curve_points(&one.0)).style(Style::Line))
            .series(Series::new("two-way", curve_points(&two.0)).style(Style::Line));
        fig = fig.panel(chart);
        let at = |c: &SeparationCurve, t: f64| {
            c.times
                .iter()
                .position(|s| *s >= t)
                .and_then(|i| c.total.get(i).copied())
        };
        cases.push(json!({
            "case": name, "seed": 1, "particles": one.1["particles"],
            "time_to_0.02_one_way": one.0.time_to(0.02),
            "time_to_0.02_two_way": two.0.time_to(0.02),
            "thesis_time_to_0.02": thesis,
            "e_m_3s_one_way": at(&one.0, 3.0), "e_m_3s_two_way": at(&two.0, 3.0),
            "liquid": two.1["liquid_solver"],
            "wall_time_s_one_way": one.1["wall_time_s"], "wall_time_s_two_way": two.1["wall_time_s"],
        }));
    }
    let p2 = out.join("coupling_separation.svg");
    write_svg(&p2, &fig.to_svg(560.0, 400.0)).map_err(runtime)?;
    crate::studies::bench::say(json!({
        "charts": [p1.display().to_string(), p2.display().to_string()],
        "quick": quick,
        "settling": rows,
        "cases": cases,
    }))
}
