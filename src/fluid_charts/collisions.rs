//! Placeholder (being written).

use crate::bench::BenchError;

/// Not yet written.
///
/// # Errors
/// Always [`BenchError::Input`] until written.
pub fn chart_collisions(out: &std::path::Path, quick: bool) -> Result<(), BenchError> {
    let _ = quick;
    let _ = out;
    Err(BenchError::Input("not yet available".into()))
}
