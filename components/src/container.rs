//! The simulation container (a resource).

use bevy_ecs::prelude::Resource;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The region particles live in.
///
/// ```
/// use magsep_components::container::Container;
/// use glam::DVec3;
/// let c = Container::PeriodicBox { edges: DVec3::splat(2.0) };
/// assert_eq!(c.volume(), 8.0);
/// ```
#[derive(Resource, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Container {
    /// A box periodic in x, y and z, spanning `[0, edges)` on each axis.
    PeriodicBox {
        /// Edge lengths [m].
        edges: DVec3,
    },
    /// Unbounded fluid (the Brownian pipeline around fibres): no walls, no periodicity.
    Unbounded,
}

impl Container {
    /// Volume [m^3].
    pub fn volume(&self) -> f64 {
        match self {
            Container::PeriodicBox { edges } => edges.x * edges.y * edges.z,
            Container::Unbounded => f64::INFINITY,
        }
    }

    /// Edge lengths of the periodic box [m] (zero when unbounded).
    pub fn edges(&self) -> DVec3 {
        match self {
            Container::PeriodicBox { edges } => *edges,
            Container::Unbounded => DVec3::ZERO,
        }
    }
}
