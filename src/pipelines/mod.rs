//! The built-in pipelines, each one self-contained unit (scene sections, spawning, plugins,
//! summary, replay), and their registration: `Registry::default()` holds exactly these.

pub mod brownian;
pub mod packing;
pub mod particle_fluid;

use crate::scene::Registry;

impl Default for Registry {
    /// The built-in pipelines: one registration line each.
    fn default() -> Self {
        Registry::empty()
            .with_pipeline(packing::PackingPipeline)
            .with_pipeline(brownian::BrownianPipeline)
            .with_pipeline(particle_fluid::ParticleFluidPipeline)
    }
}
