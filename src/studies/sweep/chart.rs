//! Charts of a sweep: each numeric collected value against each numeric axis, the mean over
//! replicates with its 95 % confidence interval (Student's t), one series per combination of
//! the other axes' values.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::file::{Sweep, value_cell, value_number};
use super::table::Row;
use crate::chart::{Chart, Series, write_svg};

/// Mean and half-width of the 95 % confidence interval of `ys` (t quantile with n - 1
/// degrees of freedom; 0 for a single value): [`crate::stats::mean_ci95`].
pub fn mean_ci95(ys: &[f64]) -> (f64, f64) {
    let (mean, half) = crate::stats::mean_ci95(ys);
    (mean, half.unwrap_or(0.0))
}

/// A file-name-safe form of `s`.
pub(super) fn slug(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// The axis label: name and unit.
pub(super) fn label(name: &str, unit: Option<&str>) -> String {
    match unit {
        Some(u) => format!("{name} [{u}]"),
        None => name.to_string(),
    }
}

/// The chart of collected value `c` against axis `a`, or `None` when the axis is not
/// numeric or no finished point has a numeric value.
pub fn chart(sweep: &Sweep, rows: &[Row], c: usize, a: usize) -> Option<Chart> {
    let axis = &sweep.axes[a];
    let xs: Option<Vec<f64>> = axis.values.iter().map(value_number).collect();
    let xs = xs?;
    // series key: the value indices of the other axes (not those zipped with `a`)
    let group = (sweep.groups.iter())
        .find(|g| g.contains(&a))
        .cloned()
        .unwrap_or_else(|| vec![a]);
    let others: Vec<usize> = (0..sweep.axes.len())
        .filter(|k| !group.contains(k))
        .collect();
    // the series are named by the first axis of each other group (its zipped partners move
    // with it)
    let named: Vec<bool> = others.iter().map(|&k| leads(sweep, k)).collect();
    let mut series: BTreeMap<Vec<usize>, BTreeMap<usize, Vec<f64>>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.status == "ok") {
        let Some(y) = r.number(c).filter(|y| y.is_finite()) else {
            continue;
        };
        let key: Vec<usize> = others.iter().map(|&k| r.values[k]).collect();
        series
            .entry(key)
            .or_default()
            .entry(r.values[a])
            .or_default()
            .push(y);
    }
    if series.is_empty() {
        return None;
    }
    let (c_name, _) = &sweep.collect[c];
    let over = match sweep.replicates {
        1 => "one replicate, no CI".to_string(),
        n => format!("mean, 95 % CI over {n} replicates"),
    };
    let mut chart = Chart::new(format!("{c_name} against {} ({over})", axis.name))
        .x_label(label(&axis.name, axis.unit.as_deref()))
        .y_label(c_name.clone())
        .x_log(axis.log);
    for (key, by_x) in series {
        let name = if others.is_empty() {
            c_name.clone()
        } else {
            (others.iter().zip(&key).zip(&named))
                .filter(|(_, named)| **named)
                .map(|((&k, &v), _)| {
                    format!(
                        "{}={}",
                        sweep.axes[k].name,
                        value_cell(&sweep.axes[k].values[v])
                    )
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        let (points, errs): (Vec<(f64, f64)>, Vec<f64>) = by_x
            .iter()
            .map(|(&v, ys)| {
                let (m, h) = mean_ci95(ys);
                ((xs[v], m), h)
            })
            .unzip();
        chart = chart.series(Series::new(name, points).y_err(errs));
    }
    Some(chart)
}

/// Whether axis `k` is the first of its zipped group (or in none).
pub(super) fn leads(sweep: &Sweep, k: usize) -> bool {
    (sweep.groups.iter())
        .find(|g| g.contains(&k))
        .is_none_or(|g| g.first() == Some(&k))
}

/// Write every chart into `dir` (`<collected>__vs__<axis>.svg`, against the first axis of each
/// zipped group only: its partners give the same chart); returns the files.
///
/// # Errors
/// A write failure, naming the file.
pub fn write_charts(sweep: &Sweep, rows: &[Row], dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut files = Vec::new();
    for c in 0..sweep.collect.len() {
        for a in (0..sweep.axes.len()).filter(|&a| leads(sweep, a)) {
            let Some(chart) = chart(sweep, rows, c, a) else {
                continue;
            };
            std::fs::create_dir_all(dir)
                .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
            let path = dir.join(format!(
                "{}__vs__{}.svg",
                slug(&sweep.collect[c].0),
                slug(&sweep.axes[a].name)
            ));
            // room for long series names in the legend (about 7 px per character)
            let longest = chart.series.iter().map(|s| s.name.chars().count()).max();
            let width = (720.0 + 7.0 * longest.unwrap_or(0).saturating_sub(30) as f64).min(1400.0);
            write_svg(&path, &chart.to_svg(width, 480.0))
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            files.push(path);
        }
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ci_uses_the_t_quantile() {
        // n = 2: t(0.975, 1) = 12.706; sd of [0, 2] is sqrt(2); half-width 12.706 * 1
        let (m, h) = mean_ci95(&[0.0, 2.0]);
        assert_eq!(m, 1.0);
        assert!((h - 12.706_204_736).abs() < 1e-6, "{h}");
        // large n tends to the normal quantile 1.96
        let ys: Vec<f64> = (0..10_000).map(|i| (i % 2) as f64).collect();
        let (m, h) = mean_ci95(&ys);
        let se = (0.25f64 * 10_000.0 / 9_999.0 / 10_000.0).sqrt();
        assert!((m - 0.5).abs() < 1e-12);
        assert!((h / se - 1.960).abs() < 1e-3, "{}", h / se);
        assert_eq!(mean_ci95(&[3.0]), (3.0, 0.0));
    }
}
