//! The mechanical contraction method (MCM) for random dense packings (thesis 000, ch. 2-3).
//!
//! Kernels on dense arrays in reduced units ([`state`], bodies in [`body`]): contacts
//! ([`contact`]), user force kernels in reduced units ([`external`]), the Verlet
//! list over all periodic images ([`neighbour`]), the move rules ([`moves`]), overlap-removal
//! sweeps ([`removal`], made parallel and deterministic in [`sweep`]), FIRE ([`fire`]) with its sphere-pair force kernel ([`sphere_pairs`]),
//! the compression driver ([`compress`]), random insertion ([`insert`]).
//! The ECS glue is in [`systems`].

pub mod body;
pub mod column;
pub mod compress;
pub mod contact;
pub mod external;
pub mod fire;
pub mod insert;
pub mod moves;
pub mod neighbour;
pub mod removal;
pub mod sphere_pairs;
pub mod state;
pub mod sweep;
pub mod systems;
pub mod walls;
