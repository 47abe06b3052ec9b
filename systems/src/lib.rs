//! # magsep-systems
//!
//! Pure kernels (plain functions on `f64`/`DVec3`, no `World`) and the thin ECS systems that
//! call them, plus the schedule labels and sets (docs/architecture.md §1-2).
//!
//! * [`sets`]: [`sets::SimSchedule`], the chained [`sets::SimSystems`] and [`sets::ForceSystems`].
//! * [`forces`]: fixed-order accumulation of per-contribution force components.
//! * [`geometry`]: volumes, inertia, segment distances.
//! * [`field`]: magnetic fields, gradients and forces of magnetised cylinders.
//! * [`brownian`]: Brownian dynamics of magnetic nanoparticles (thesis 000, ch. 6).
//! * [`fluid`]: inertial particles in magnetised liquids: magnetic buoyancy, Maxey-Riley with
//!   Basset history (thesis 002, ch. 1-2).
//! * [`collision`]: hard-particle impulse collisions with restitution and Coulomb friction.
//! * [`packing`]: the mechanical contraction method.
//! * [`analysis`]: contact numbers and order parameters.
//! * [`rng`]: per-particle random streams.
//! * [`buckets`]: the stable counting sort of the cell lists.
//! * [`par`]: per-entity loops that go parallel only with enough entities.

#![warn(missing_docs)]

pub mod analysis;
pub mod brownian;
pub mod buckets;
pub mod clock;
pub mod collision;
pub mod field;
pub mod fluid;
pub mod forces;
pub mod geometry;
pub mod packing;
pub mod par;
pub mod rng;
pub mod sets;

use bevy_ecs::prelude::Resource;

/// Seed of the run (a resource).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunSeed(pub u64);

/// Errors of the systems crate.
#[derive(Debug, thiserror::Error)]
pub enum SystemsError {
    /// Random insertion could not place a particle.
    #[error(transparent)]
    Insertion(#[from] packing::insert::InsertionError),
}
