//! Charts and benchmarks of the particle-fluid pipeline (thesis 002, ch. 2): single-particle
//! levitation, the Basset history's accuracy, cost and stability, binary collisions and the
//! many-particle separation error.
//!
//! * `magsep chart levitation`: [`chart_levitation`].
//! * `magsep chart history`: [`chart_history`].
//! * `magsep chart collisions`: [`chart_collisions`].
//! * `magsep chart separation`: [`chart_separation`].
//! * `magsep chart flakes`: [`chart_flakes`] (spheroids, ch. 4).
//! * `magsep chart flake-collisions`: [`chart_flake_collisions`] (1:2 spheroids, ch. 4).
//! * `magsep chart spheroid-model`: [`chart_spheroid_model`] (thesis 002, ch. 3-4: models of
//!   the 1:10 spheroid's coefficients, error against cost).
//! * `magsep bench particle-fluid`: [`bench_particle_fluid`].

mod bench;
mod bench_spheroids;
mod collisions;
mod flake_collisions;
mod flakes;
mod history;
mod levitation;
pub(crate) mod separation;
mod spheroid_model;

pub use bench::{bench_particle_fluid, bench_settling_bed};
pub use collisions::chart_collisions;
pub use flake_collisions::chart_flake_collisions;
pub use flakes::chart_flakes;
pub use history::chart_history;
pub use levitation::chart_levitation;
pub use separation::chart_separation;
pub use spheroid_model::chart_spheroid_model;

use crate::scene::parse_scene;
use crate::sim::{RunOptions, Simulation};
use crate::studies::bench::BenchError;

/// A run-time error of a chart or bench.
pub(crate) fn runtime(e: impl std::fmt::Display) -> BenchError {
    BenchError::Runtime(e.to_string())
}

/// The simulation of scene `text`, on the single-threaded executor (charts run scenes in
/// parallel with rayon instead).
pub(crate) fn simulation(text: &str) -> Result<Simulation, BenchError> {
    let scene = parse_scene(text, &Default::default()).map_err(runtime)?;
    Simulation::from_scene(
        &scene,
        RunOptions {
            single_threaded: true,
            ..Default::default()
        },
    )
    .map_err(runtime)
}
