//! `magsep chart brownian` (being written).

use std::path::Path;

use crate::bench::BenchError;

/// Captured fraction against time (SVG).
///
/// # Errors
/// Always, until written.
pub fn chart_brownian(_out: &Path, _quick: bool) -> Result<(), BenchError> {
    Err(BenchError::Runtime("chart brownian: not yet built".into()))
}
