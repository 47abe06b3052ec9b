//! `magsep bench brownian` and `magsep chart brownian-cost` (being written).

use std::path::Path;

use crate::bench::BenchError;

/// Benchmarks of the brownian pipeline.
///
/// # Errors
/// Always, until written.
pub fn bench_brownian(_as_json: bool, _quick: bool) -> Result<(), BenchError> {
    Err(BenchError::Runtime("bench brownian: not yet built".into()))
}

/// Error of each mobility against its cost (SVG).
///
/// # Errors
/// Always, until written.
pub fn chart_brownian_cost(_out: &Path, _quick: bool) -> Result<(), BenchError> {
    Err(BenchError::Runtime("chart brownian-cost: not yet built".into()))
}
