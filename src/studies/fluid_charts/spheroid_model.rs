//! `magsep chart spheroid-model --out DIR [--quick]`: models of the 1:10 spheroid's drag, lift
//! and pitching-torque coefficients (thesis 002, ch. 3, Tables 3.3-3.5), error against cost.
//!
//! Models: the bilinear, tensor-spline (the run-time model, and the same in ln Re_e instead of
//! ln(1 + Re_e)) and least-squares models of
//! `magsep_systems::fluid::spheroid::disc_model`, and the Table 4.4 correlations applied at
//! w = 0.1 as stand-ins (Zastawny 1:5, Sanjeevi 2:5: what a simulation without the 1:10
//! database would use). Error: the mean (and max) relative error at held-out nodes, leaving
//! one Re column out at a time (the models are refitted without it); the correlations are
//! not fitted to the table, so every node counts as held out. Lift and torque are scored away
//! from 0° and 90°, where they vanish. Cost: ns per evaluation of all three coefficients at
//! random (Re_e, φ) in the table's range, measured in the same run.
//!
//! `spheroid_model.svg`: three panels (drag, lift, torque), error against cost; a JSON
//! summary goes to stdout.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use magsep_systems::fluid::spheroid::correlations::{Coefficients, sanjeevi, zastawny};
use magsep_systems::fluid::spheroid::disc_model::{DiscMethod, DiscModel, Variant};
use magsep_systems::fluid::spheroid::disc_table::re_e;
use magsep_systems::fluid::spheroid::disc_validation::{
    HeldOut, Split, errors_against_table, held_out_variant,
};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde_json::{Value, json};

use super::runtime;
use crate::chart::{Chart, Figure, LegendPosition, Series, Style, write_svg};
use crate::studies::bench::BenchError;

/// ns per evaluation of `f` over `points`, best of `reps` passes.
fn cost(points: &[(f64, f64)], reps: usize, f: &dyn Fn(f64, f64) -> Coefficients) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t = Instant::now();
        let mut acc = 0.0;
        for &(re, phi) in points {
            let c = f(black_box(re), black_box(phi));
            acc += c.drag + c.lift + c.torque;
        }
        black_box(acc);
        best = best.min(t.elapsed().as_secs_f64() * 1e9 / points.len().max(1) as f64);
    }
    best
}

/// One model: name, held-out errors under leave-one-column-out (and every other column for
/// the fitted models), cost.
struct Row {
    name: &'static str,
    loo: HeldOut,
    every_other: Option<HeldOut>,
    rows_loo: Option<HeldOut>,
    ns: f64,
}

/// `magsep chart spheroid-model`.
///
/// # Errors
/// [`BenchError::Runtime`] when the SVG cannot be written, [`BenchError::Stdout`] when the
/// summary cannot be printed.
pub fn chart_spheroid_model(out: &Path, quick: bool) -> Result<(), BenchError> {
    let start = Instant::now();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
    let (lo, hi) = (re_e(0).ln(), re_e(13).ln());
    let n = if quick { 1000 } else { 20_000 };
    let reps = if quick { 3 } else { 10 };
    let points: Vec<(f64, f64)> = (0..n)
        .map(|_| {
            let x: f64 = rng.random_range(lo..hi);
            let phi: f64 = rng.random_range(0.0..std::f64::consts::FRAC_PI_2);
            (x.exp(), phi)
        })
        .collect();
    let cols: Vec<usize> = (0..14).collect();
    let rows_all: Vec<usize> = (0..19).collect();
    let mut rows = Vec::new();
    let log_re = Variant {
        x_shift: 0.0,
        x_power: 0.0,
        ..Variant::default()
    };
    for (name, method, variant) in [
        ("bilinear", DiscMethod::Bilinear, Variant::default()),
        (
            "tensor spline (run-time)",
            DiscMethod::Spline,
            Variant::default(),
        ),
        ("tensor spline in ln Re_e", DiscMethod::Spline, log_re),
        (
            "least squares 6x4",
            DiscMethod::LeastSquares,
            Variant::default(),
        ),
    ] {
        let model = DiscModel::fit_variant(method, variant, &cols, &rows_all);
        rows.push(Row {
            name,
            loo: held_out_variant(method, variant, Split::LeaveOneColumnOut),
            every_other: Some(held_out_variant(method, variant, Split::EveryOtherColumn)),
            rows_loo: Some(held_out_variant(method, variant, Split::LeaveOneRowOut)),
            ns: cost(&points, reps, &|re, phi| model.coefficients(re, phi)),
        });
    }
    for (name, f) in [
        (
            "Zastawny 1:5 at w = 0.1",
            zastawny as fn(f64, f64) -> Coefficients,
        ),
        ("Sanjeevi 2:5 at w = 0.1", sanjeevi),
    ] {
        rows.push(Row {
            name,
            loo: errors_against_table(f),
            every_other: None,
            rows_loo: None,
            ns: cost(&points, reps, &f),
        });
    }
    let names = ["drag C_D", "lift C_L", "pitching torque C_T"];
    let mut fig = Figure::new(
        "1:10 spheroid coefficients: held-out error against cost (leave one Re column out)",
        3,
    );
    for (q, title) in names.iter().enumerate() {
        let mut chart = Chart::new(*title)
            .x_label("cost [ns per evaluation of C_D, C_L, C_T]")
            .y_label("mean relative error at held-out nodes")
            .x_log(true)
            .y_log(true)
            .legend(LegendPosition::Auto);
        for r in &rows {
            chart = chart.series(
                Series::new(r.name, vec![(r.ns, r.loo.mean_relative[q].max(1e-6))])
                    .style(Style::Markers),
            );
        }
        fig = fig.panel(chart);
    }
    std::fs::create_dir_all(out).map_err(runtime)?;
    let path = out.join("spheroid_model.svg");
    write_svg(&path, &fig.to_svg(520.0, 420.0)).map_err(runtime)?;
    let summary_of = |h: &HeldOut| {
        json!({
            "mean_relative": {"drag": h.mean_relative[0], "lift": h.mean_relative[1], "torque": h.mean_relative[2]},
            "max_relative": {"drag": h.max_relative[0], "lift": h.max_relative[1], "torque": h.max_relative[2]},
            "worst_node_deg_re_e": h.worst_node,
            "max_absolute_at_0_and_90_deg": {"lift": h.max_absolute_at_symmetry[1], "torque": h.max_absolute_at_symmetry[2]},
            "nodes": h.nodes,
        })
    };
    let models: Vec<Value> = rows
        .iter()
        .map(|r| {
            json!({
                "model": r.name,
                "ns_per_evaluation": r.ns,
                "leave_one_column_out": summary_of(&r.loo),
                "every_other_column": r.every_other.as_ref().map(summary_of),
                "leave_one_row_out": r.rows_loo.as_ref().map(summary_of),
            })
        })
        .collect();
    let summary = json!({
        "charts": [path.display().to_string()],
        "duration_s": start.elapsed().as_secs_f64(),
        "evaluation_points": n,
        "note": "correlations are scored against every table node (not fitted to it)",
        "models": models,
    });
    crate::studies::bench::say(summary)
}
