//! Charts and benchmarks of the particle-fluid pipeline (thesis 002, ch. 2): single-particle
//! levitation, the Basset history's accuracy, cost and stability, binary collisions and the
//! many-particle separation error.
//!
//! * `magsep chart levitation`: [`chart_levitation`].
//! * `magsep chart history`: [`chart_history`].
//! * `magsep chart collisions`: [`chart_collisions`].
//! * `magsep chart separation`: [`chart_separation`].
//! * `magsep bench particle-fluid`: [`bench_particle_fluid`].

mod bench;
mod collisions;
mod history;
mod levitation;
mod separation;

pub use bench::bench_particle_fluid;
pub use collisions::chart_collisions;
pub use history::chart_history;
pub use levitation::chart_levitation;
pub use separation::chart_separation;
