//! Curves of a sweep (`[[curves]]` in the sweep file): a summary array `y` against a summary
//! array `x` (a capture curve against time, say), averaged over the replicates of each
//! combination of axis values point by point, with the 95 % confidence interval of the mean.
//!
//! Outputs: `curves/<name>.csv` (one row per combination and x: the axis values, x, mean,
//! half-width of the interval, replicates) and `charts/curve__<name>.svg` (the mean as a solid
//! line, the interval's bounds dashed in the same colour, one colour per combination).
//! Replicates whose `x` differs from the combination's first (another length or other values)
//! or whose arrays are absent or not numbers are left out and counted.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use super::chart::{label, leads, mean_ci95, slug};
use super::file::{Curve, Sweep, value_cell};
use super::run::Outcome;
use crate::chart::{Chart, PALETTE, Series, Style, write_svg};

/// The replicates of one combination of axis values.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Replicates {
    /// The common x values.
    pub x: Vec<f64>,
    /// One y array per replicate, each as long as `x`.
    pub ys: Vec<Vec<f64>>,
}

/// A curve gathered from a sweep directory: the replicates of each combination (keyed by the
/// value index of every axis) and the number of finished points left out.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Gathered {
    /// Replicates by combination.
    pub combos: BTreeMap<Vec<usize>, Replicates>,
    /// Finished points whose arrays were absent, not numbers, of unequal length, or on
    /// another x than their combination's first replicate.
    pub left_out: usize,
}

fn numbers(v: Option<&Value>) -> Option<Vec<f64>> {
    v?.as_array()?.iter().map(Value::as_f64).collect()
}

/// Gather `curve` from the finished points of `sweep` (`outcomes[i]`: point i's outcome).
pub fn gather(sweep: &Sweep, outcomes: &[Outcome], curve: &Curve) -> Gathered {
    let mut g = Gathered::default();
    for (index, outcome) in outcomes.iter().enumerate() {
        let Outcome::Ok(summary) = outcome else {
            continue;
        };
        let x = numbers(curve.x.1.lookup_json(summary));
        let y = numbers(curve.y.1.lookup_json(summary));
        let (Some(x), Some(y)) = (x, y) else {
            g.left_out += 1;
            continue;
        };
        if x.len() != y.len() {
            g.left_out += 1;
            continue;
        }
        let combo = g.combos.entry(sweep.point(index).values).or_default();
        if combo.ys.is_empty() {
            combo.x = x;
        } else if combo.x != x {
            g.left_out += 1;
            continue;
        }
        combo.ys.push(y);
    }
    g
}

/// Mean, 95 % half-width and count at every x of `r`.
pub fn statistics(r: &Replicates) -> Vec<(f64, f64, f64, usize)> {
    (0..r.x.len())
        .map(|i| {
            let ys: Vec<f64> = r.ys.iter().map(|y| y[i]).collect();
            let (m, h) = mean_ci95(&ys);
            (r.x[i], m, h, ys.len())
        })
        .collect()
}

/// The CSV text of a gathered curve.
///
/// # Errors
/// A CSV encoding failure.
pub fn csv_text(sweep: &Sweep, curve: &Curve, g: &Gathered) -> Result<String, String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = sweep.axes.iter().map(|a| a.name.clone()).collect();
    header.extend([curve.x.0.clone(), "mean".into(), "ci95".into(), "n".into()]);
    w.write_record(&header).map_err(|e| e.to_string())?;
    for (key, r) in &g.combos {
        for (x, m, h, n) in statistics(r) {
            let mut cells: Vec<String> = (sweep.axes.iter().zip(key))
                .map(|(a, &v)| value_cell(&a.values[v]))
                .collect();
            cells.extend([x.to_string(), m.to_string(), h.to_string(), n.to_string()]);
            w.write_record(&cells).map_err(|e| e.to_string())?;
        }
    }
    let bytes = w.into_inner().map_err(|e| e.to_string())?;
    String::from_utf8(bytes).map_err(|e| e.to_string())
}

/// The chart of a gathered curve (`None` when no combination has a replicate).
pub fn chart(sweep: &Sweep, curve: &Curve, g: &Gathered) -> Option<Chart> {
    if g.combos.is_empty() {
        return None;
    }
    let mut chart = Chart::new(format!(
        "{} (mean and 95 % CI over up to {} replicates)",
        curve.name, sweep.replicates
    ))
    .x_label(label(&curve.x.0, curve.x_unit.as_deref()))
    .y_label(curve.y.0.clone());
    for (k, (key, r)) in g.combos.iter().enumerate() {
        let name: Vec<String> = (0..sweep.axes.len())
            .filter(|&a| leads(sweep, a))
            .map(|a| {
                let axis = &sweep.axes[a];
                format!("{}={}", axis.name, value_cell(&axis.values[key[a]]))
            })
            .collect();
        let name = if name.is_empty() {
            curve.name.clone()
        } else {
            name.join(", ")
        };
        let colour = PALETTE[k % PALETTE.len()];
        let stats = statistics(r);
        let mean = stats.iter().map(|&(x, m, _, _)| (x, m));
        let lo = stats.iter().map(|&(x, m, h, _)| (x, m - h));
        let hi = stats.iter().map(|&(x, m, h, _)| (x, m + h));
        chart = chart
            .series(Series::new(name, mean).style(Style::Line).color(colour))
            .series(Series::new("", lo).style(Style::Dashed).color(colour))
            .series(Series::new("", hi).style(Style::Dashed).color(colour));
    }
    Some(chart)
}

/// Points left out of each curve, by curve name.
pub type LeftOut = Vec<(String, usize)>;

/// Write every curve's CSV into `out/curves` and chart into `out/charts` from the points'
/// `outcomes` (indexed by point); returns the files and the number of points left out of
/// each curve (by name).
///
/// # Errors
/// A write failure, naming the file.
pub fn write_curves(
    sweep: &Sweep,
    outcomes: &[Outcome],
    out: &Path,
) -> Result<(Vec<PathBuf>, LeftOut), String> {
    let mut files = Vec::new();
    let mut left_out = Vec::new();
    for curve in &sweep.curves {
        let g = gather(sweep, outcomes, curve);
        left_out.push((curve.name.clone(), g.left_out));
        let dir = out.join("curves");
        std::fs::create_dir_all(&dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let path = dir.join(format!("{}.csv", slug(&curve.name)));
        super::run::write_atomic(&path, &csv_text(sweep, curve, &g)?)?;
        files.push(path);
        if let Some(chart) = chart(sweep, curve, &g) {
            let dir = out.join("charts");
            std::fs::create_dir_all(&dir)
                .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
            let path = dir.join(format!("curve__{}.svg", slug(&curve.name)));
            write_svg(&path, &chart.to_svg(900.0, 520.0))
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            files.push(path);
        }
    }
    Ok((files, left_out))
}
