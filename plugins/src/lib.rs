//! # magsep-plugins
//!
//! Plugin wiring over the simulation schedule (which system runs in which set), the pipelines
//! as plugin groups, and MCAP record/replay.
//!
//! * [`app`]: [`app::SimApp`] and the [`app::SimPlugin`] trait.
//! * [`group`]: [`group::PipelineGroup`]: add, disable, replace, configure plugins (by type,
//!   label or index).
//! * [`core`]: clock and health.
//! * [`packing`]: the `packing` pipeline.
//! * [`brownian`]: the `brownian` pipeline.
//! * [`particle_fluid`]: the `particle_fluid` pipeline (inertial particles in magnetised liquids).
//! * [`recorder`] and [`record`]: recordings.

#![warn(missing_docs)]

pub mod app;
pub mod brownian;
pub mod core;
pub mod group;
pub mod liquid;
pub mod packing;
pub mod particle_fluid;
pub use magsep_record as record;
pub mod recorder;

pub use app::{SimApp, SimPlugin};
pub use group::PipelineGroup;
