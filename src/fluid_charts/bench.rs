//! Placeholder (being written).

use crate::bench::BenchError;

/// Not yet written.
///
/// # Errors
/// Always [`BenchError::Input`] until written.
pub fn bench_particle_fluid(as_json: bool, quick: bool) -> Result<(), BenchError> {
    let _ = quick;
    let _ = as_json;
    Err(BenchError::Input("not yet available".into()))
}
