//! Particle shapes (data). Geometry kernels (volume, inertia, distances) live in
//! `magsep_systems::geometry`.

use bevy_ecs::prelude::Component;
use serde::{Deserialize, Serialize};

/// Shape of a particle, in its body frame (symmetry axis along body z).
#[derive(Component, Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Radius R [m].
        radius: f64,
    },
    /// A cylinder of length `2 * half_length` capped by two hemispheres: all points within
    /// `radius` of the axis segment. Aspect ratio (L + D) / D = 1 + half_length / radius.
    Spherocylinder {
        /// Radius R of the cylinder and the caps [m].
        radius: f64,
        /// Half the length of the cylindrical part, L/2 [m].
        half_length: f64,
    },
}

impl Shape {
    /// Radius R [m] (of the sphere, or of the rod's cylinder and caps).
    pub fn radius(&self) -> f64 {
        match *self {
            Shape::Sphere { radius } | Shape::Spherocylinder { radius, .. } => radius,
        }
    }

    /// Half length of the axis segment [m]; zero for a sphere.
    pub fn half_length(&self) -> f64 {
        match *self {
            Shape::Sphere { .. } => 0.0,
            Shape::Spherocylinder { half_length, .. } => half_length,
        }
    }

    /// Aspect ratio (L + D) / D (thesis 000, eq. 2.1); 1 for a sphere.
    pub fn aspect_ratio(&self) -> f64 {
        1.0 + self.half_length() / self.radius()
    }
}
