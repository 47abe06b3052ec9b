//! The results table of a sweep (`results.csv`): one row per point.

use serde_json::Value;

use super::file::{Sweep, value_cell};
use super::run::Outcome;

/// One point's row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Point index.
    pub index: usize,
    /// Index into each axis' values.
    pub values: Vec<usize>,
    /// Replicate index.
    pub replicate: u64,
    /// Seed of the run (empty: the scene has none at the seed key).
    pub seed: Option<u64>,
    /// The collected values (`None`: not in the summary, or no summary).
    pub collected: Vec<Option<Value>>,
    /// `ok`, `error` or `missing`.
    pub status: &'static str,
    /// The error message of a failed point.
    pub error: String,
}

impl Row {
    /// Collected value `k` as a number, if it is one.
    pub fn number(&self, k: usize) -> Option<f64> {
        self.collected.get(k)?.as_ref()?.as_f64()
    }
}

/// The rows of every point of `sweep` from their `outcomes` (indexed by point, see
/// [`super::run::outcomes`]).
pub fn gather(sweep: &Sweep, outcomes: &[Outcome]) -> Vec<Row> {
    (outcomes.iter().enumerate())
        .map(|(index, outcome)| {
            let point = sweep.point(index);
            let (status, summary, error) = match outcome {
                Outcome::Ok(s) => ("ok", Some(s), String::new()),
                Outcome::Failed { error, summary } => ("error", summary.as_ref(), error.clone()),
                Outcome::Missing => ("missing", None, String::new()),
            };
            let collected = (sweep.collect.iter())
                .map(|(_, p)| summary.and_then(|s| p.lookup_json(s)).cloned())
                .collect();
            Row {
                index,
                values: point.values.clone(),
                replicate: point.replicate,
                seed: sweep.seed_of(&point),
                collected,
                status,
                error,
            }
        })
        .collect()
}

/// A collected value as a CSV cell: numbers and strings as they are, other JSON as text,
/// empty when absent.
fn json_cell(v: Option<&Value>) -> String {
    match v {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => s.clone(),
        Some(other) => other.to_string(),
    }
}

/// `results.csv` of `rows` as text: `index`, one column per axis, `replicate`, `seed`, one
/// column per collected value, `status`, `error`.
///
/// # Errors
/// A CSV writer failure (as text).
pub fn csv_text(sweep: &Sweep, rows: &[Row]) -> Result<String, String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["index".to_string()];
    header.extend(sweep.axes.iter().map(|a| a.name.clone()));
    header.extend(["replicate".into(), "seed".into()]);
    header.extend(sweep.collect.iter().map(|(c, _)| c.clone()));
    header.extend(["status".into(), "error".into()]);
    w.write_record(&header).map_err(|e| e.to_string())?;
    for r in rows {
        let mut cells = vec![r.index.to_string()];
        cells.extend((sweep.axes.iter().zip(&r.values)).map(|(a, &v)| value_cell(&a.values[v])));
        cells.push(r.replicate.to_string());
        cells.push(r.seed.map(|s| s.to_string()).unwrap_or_default());
        cells.extend(r.collected.iter().map(|v| json_cell(v.as_ref())));
        cells.push(r.status.to_string());
        cells.push(r.error.clone());
        w.write_record(&cells).map_err(|e| e.to_string())?;
    }
    let bytes = w.into_inner().map_err(|e| e.to_string())?;
    String::from_utf8(bytes).map_err(|e| e.to_string())
}

/// Counts of a table: (ok, error, missing).
pub fn counts(rows: &[Row]) -> (usize, usize, usize) {
    let n = |s: &str| rows.iter().filter(|r| r.status == s).count();
    (n("ok"), n("error"), n("missing"))
}

/// Collected values absent from the summaries of finished points: (collect name, count).
pub fn absent_values(sweep: &Sweep, rows: &[Row]) -> Vec<(String, usize)> {
    (sweep.collect.iter().enumerate())
        .filter_map(|(k, (name, _))| {
            let n = (rows.iter())
                .filter(|r| r.status == "ok" && r.collected[k].is_none())
                .count();
            (n > 0).then(|| (name.clone(), n))
        })
        .collect()
}
