//! Magnetised fibres (entities) and the applied field (a resource). SI units.

use bevy_ecs::prelude::*;
use glam::DVec3;

/// Stable index of a fibre (scene order).
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FibreId(pub u64);

/// A uniformly magnetised finite circular cylinder.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct Fibre {
    /// Centre \[m\].
    pub center: DVec3,
    /// Unit axis.
    pub axis: DVec3,
    /// Radius R \[m\].
    pub radius: f64,
    /// Half length L \[m\].
    pub half_length: f64,
    /// Magnetisation M [A/m] (resolved: fixed, or Stoner-Wohlfarth against the applied field).
    pub magnetisation: DVec3,
}

/// The uniform applied field and the accuracy asked of the fibres' fields.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct ExternalField {
    /// Flux density B_ext \[T\].
    pub flux_density: DVec3,
    /// Relative tolerance of each fibre's field (1e-15: exact).
    pub tolerance: f64,
}
