//! # magsep
//!
//! Particles in magnetic separation: random fibre packings by mechanical contraction, exact
//! fields of magnetised fibres, Brownian capture, density separation. This crate is the facade:
//! the [`prelude`], scene loading ([`scene`]), the [`Simulation`] builder, summaries, replay,
//! charts and the `magsep` CLI.
//!
//! ```no_run
//! use magsep::prelude::*;
//! let summary = magsep::sim::run_scene_file("scenes/spheres_500.toml".as_ref(), RunOptions::default()).unwrap();
//! println!("{}", summary["packing_fraction"]);
//! ```

#![warn(missing_docs)]

pub mod chart;
pub mod cli;
pub mod error;
pub mod fieldtool;
pub mod input;
pub mod names;
pub mod pipelines;
pub mod replay;
pub mod scene;
pub mod sim;
pub mod stats;
pub mod studies;

pub use pipelines::{brownian, packing, particle_fluid};
pub use scene::{Pipeline, Registry};
pub use sim::{RunOptions, SimError, Simulation};

/// Everything a user usually needs.
pub mod prelude {
    pub use crate::pipelines::brownian::BrownianPipeline;
    pub use crate::pipelines::packing::PackingPipeline;
    pub use crate::pipelines::particle_fluid::ParticleFluidPipeline;
    pub use crate::scene::{ParseContext, Pipeline, Registry, RunInfo, Scene, SceneSection};
    pub use crate::sim::{
        RunOptions, SimError, Simulation, SimulationBuilder, StopFlag, SummaryExtras,
    };
    pub use magsep_components::prelude::*;
    pub use magsep_plugins::app::{SimApp, SimPlugin};
    pub use magsep_plugins::brownian::{
        BrownianForcesPlugin, BrownianIntegratorPlugin, CaptureObservePlugin, brownian_pipeline,
    };
    pub use magsep_plugins::core::{CorePlugin, FinalizeSystems};
    pub use magsep_plugins::group::PipelineGroup;
    pub use magsep_plugins::packing::{
        McmCompressionPlugin, McmOverlapRemovalPlugin, PackingObservePlugin, packing_pipeline,
    };
    pub use magsep_plugins::particle_fluid::{
        CollisionPlugin, InertialForcesPlugin, InertialIntegratorPlugin, SeparationObservePlugin,
        particle_fluid_pipeline,
    };
    pub use magsep_plugins::recorder::RecordPlugin;
    pub use magsep_systems::sets::{ForceSystems, ObserveSchedule, SimSchedule, SimSystems};
}

/// The crates underneath, re-exported (use these paths to get matching versions).
pub use bevy_ecs;
pub use glam;
pub use magsep_components as components;
pub use magsep_plugins as plugins;
pub use magsep_systems as systems;
pub use serde_json;
pub use toml;
