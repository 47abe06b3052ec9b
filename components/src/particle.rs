//! Particle components.

use bevy_ecs::prelude::{Bundle, Component};
use glam::{DQuat, DVec3};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

use crate::forces::{NetForce, NetTorque};
use crate::shape::Shape;

/// Stable particle identity: the order of particles in every reduction, record and RNG stream.
#[derive(
    Component, Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
pub struct ParticleId(pub u64);

/// Centre of mass \[m\].
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Position(pub DVec3);

/// Orientation: rotation from the body frame to the lab frame. The body z axis is the
/// symmetry axis of axisymmetric shapes (the rod axis of a spherocylinder).
#[derive(Component, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Orientation(pub DQuat);

impl Default for Orientation {
    fn default() -> Self {
        Self(DQuat::IDENTITY)
    }
}

impl Orientation {
    /// The body z axis in the lab frame.
    pub fn axis(&self) -> DVec3 {
        self.0 * DVec3::Z
    }
}

/// Index of the scene's `[[particles]]` entry this particle came from.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Species(pub u32);

/// Per-particle random stream, derived from (seed, [`ParticleId`]); its state is recorded so a
/// resumed run continues bitwise.
#[derive(Component, Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ParticleRng(pub Xoshiro256PlusPlus);

/// Everything a particle entity carries.
#[derive(Bundle, Debug, Clone)]
pub struct ParticleBundle {
    /// Stable identity.
    pub id: ParticleId,
    /// Centre of mass \[m\].
    pub position: Position,
    /// Orientation.
    pub orientation: Orientation,
    /// Shape and size.
    pub shape: Shape,
    /// Scene entry index.
    pub species: Species,
    /// Random stream.
    pub rng: ParticleRng,
    /// Accumulated force \[N\].
    pub net_force: NetForce,
    /// Accumulated torque [N m].
    pub net_torque: NetTorque,
}
